// Recording a session as an fgsr capture (docs/CAPTURE_FORMAT.md) through fgsr_capture_format, the
// same writer save_fgsr uses. Frames are written synchronously at submit (one EXR each); the manifest
// is rewritten at finish (stop, session destroy), so a directory with a manifest is complete.
#include "client_internal.hpp"

#include <fgsr/capture/fgsr_format.hpp>

#include <cstring>
#include <system_error>
#include <vector>

namespace fgsr::client {

namespace {

// The protocol's enum values equal fgsr_core's (static_asserts in fgsr/core/types.hpp).

// Copies a plane of `rows` rows of `row_bytes` bytes, `pitch` apart, into a tightly packed buffer.
void pack_plane(std::vector<std::byte>& out, const std::byte* src, uint32_t pitch, size_t row_bytes,
                uint32_t rows) {
    out.resize(row_bytes * rows);
    for (uint32_t y = 0; y < rows; ++y)
        std::memcpy(out.data() + y * row_bytes, src + size_t(y) * pitch, row_bytes);
}

class CaptureRecorder final : public Recorder {
  public:
    CaptureRecorder(std::filesystem::path dir, capture::FgsrManifest m)
        : dir_(std::move(dir)), manifest_(std::move(m)) {}

    fgsr_status add(const fgsr_pool_layout& l, const std::byte* slot, const fgsr_submit_entry& e) override {
        const FrameFormat& f = manifest_.format;
        pack_plane(color_, slot + l.color.offset, l.color.row_pitch,
                   size_t(f.width) * bytes_per_pixel(f.color_format), f.height);
        if (l.depth.size != 0) {
            pack_plane(depth_, slot + l.depth.offset, l.depth.row_pitch, size_t(f.width) * 4, f.height);
        } else if (depth_.empty()) { // colour-only session: the capture records constant depth 1
            const float one = 1.f;
            depth_.resize(size_t(f.width) * f.height * 4);
            for (size_t i = 0; i < depth_.size(); i += 4) std::memcpy(depth_.data() + i, &one, 4);
        }
        const bool has_mv = (e.flags & FGSR_SUBMIT_HAS_MV) != 0;
        if (has_mv)
            pack_plane(mv_, slot + l.mv.offset, l.mv.row_pitch,
                       size_t(f.width) * bytes_per_pixel(f.mv_format), f.height);
        FrameView view{color_, depth_,
                       has_mv ? std::span<const std::byte>(mv_) : std::span<const std::byte>()};
        view.jitter_x = e.jitter_x;
        view.jitter_y = e.jitter_y;
        view.reset = (e.flags & FGSR_SUBMIT_RESET) != 0;
        const std::string rel = "frames/" + capture::fgsr_file_name(manifest_.frames.size());
        auto w = capture::write_fgsr_frame(dir_ / rel, f, view);
        if (!w) {
            error_ = w.error().message;
            return FGSR_STATUS_UNSUPPORTED;
        }
        manifest_.frames.push_back({rel, has_mv, e.jitter_x, e.jitter_y, (e.flags & FGSR_SUBMIT_RESET) != 0});
        return FGSR_STATUS_OK;
    }

    fgsr_status finish() override {
        if (manifest_.frames.empty()) return FGSR_STATUS_OK; // nothing recorded: no capture
        auto w = capture::write_fgsr_manifest(dir_, manifest_);
        if (!w) {
            error_ = w.error().message;
            return FGSR_STATUS_UNSUPPORTED;
        }
        return FGSR_STATUS_OK;
    }

    const std::string& error() const override { return error_; }

  private:
    std::filesystem::path dir_;
    capture::FgsrManifest manifest_;
    std::vector<std::byte> color_, depth_, mv_;
    std::string error_;
};

} // namespace

std::unique_ptr<Recorder> make_recorder(const std::string& dir, const std::string& name,
                                        const fgsr_session_desc& desc, std::string& reason) {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(dir) / "frames", ec);
    if (ec) {
        reason = "cannot create " + dir + "/frames: " + ec.message();
        return nullptr;
    }
    capture::FgsrManifest m;
    m.name = name.empty() ? "session" : name;
    m.source = "fgsr-client";
    m.format.width = desc.width;
    m.format.height = desc.height;
    m.format.color_format = ColorFormat(desc.color_format);
    m.format.mv_format = MvFormat(desc.mv_format);
    m.format.conventions.depth_kind = DepthKind(desc.depth_kind);
    m.format.conventions.near_plane = desc.near_plane;
    m.format.conventions.far_plane = desc.far_plane;
    m.format.conventions.mv_units = MvUnits(desc.mv_units);
    m.format.conventions.mv_direction = MvDirection(desc.mv_direction);
    m.format.conventions.mv_y_up = (desc.flags & FGSR_SESSION_MV_Y_UP) != 0;
    m.ground_truth_kind = capture::GroundTruth::consecutive;
    return std::make_unique<CaptureRecorder>(dir, std::move(m));
}

} // namespace fgsr::client
