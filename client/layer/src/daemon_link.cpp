// The layer's connection and colour-only session to fgsrd (daemon_link.hpp).
#include "daemon_link.hpp"

#include "report.hpp"

namespace fgsr::layer {

DaemonLink::~DaemonLink() {
    close();
}

void DaemonLink::close() {
    if (session_) fgsr_session_destroy(session_);
    session_ = nullptr;
    if (connection_) fgsr_disconnect(connection_);
    connection_ = nullptr;
    depth_cleared_.clear();
}

void DaemonLink::fail(fgsr_status status, const char* what, uint64_t now_ns) {
    if (connection_)
        log_line(std::string("fgsrd ") + what + ": " + fgsr_status_string(status) +
                 "; presenting the application's frames alone, reconnecting every 2 s");
    close();
    unavailable_logged_ = true; // the line above (or the connect failure) said it
    retry_at_ns_ = now_ns + kRetryNs;
}

bool DaemonLink::ensure(const SessionShape& shape, uint64_t now_ns) {
    if (session_ && shape == shape_) return true;
    if (session_) { // size, format, mode or multiplier changed: a new session
        fgsr_session_destroy(session_);
        session_ = nullptr;
        depth_cleared_.clear();
    }
    if (connection_ && connected_socket_ != shape.socket_path) close();
    if (now_ns < retry_at_ns_) return false;
    if (!connection_) {
        fgsr_connect_info ci{};
        ci.struct_size = sizeof(ci);
        ci.timeout_ms = 1000;
        ci.socket_path = shape.socket_path.empty() ? nullptr : shape.socket_path.c_str();
        ci.client_name = "VK_LAYER_FGSR_frame_generation";
        const fgsr_status st = fgsr_connect(&ci, &connection_);
        if (st != FGSR_STATUS_OK) {
            connection_ = nullptr;
            if (!unavailable_logged_)
                log_line(std::string("no fgsrd (") + fgsr_status_string(st) + ", socket " +
                         (shape.socket_path.empty() ? "default" : shape.socket_path) +
                         "); presenting the application's frames alone, retrying every 2 s");
            unavailable_logged_ = true;
            retry_at_ns_ = now_ns + kRetryNs;
            return false;
        }
        connected_socket_ = shape.socket_path;
        fgsr_daemon_info info{};
        fgsr_daemon_info_get(connection_, &info);
        info.device[sizeof(info.device) - 1] = 0;
        log_line(std::string("connected to fgsrd (") + info.device + ")");
        unavailable_logged_ = false;
    }
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = shape.width;
    d.height = shape.height;
    d.color_format = shape.format;
    d.output_format = shape.format;
    d.mv_format = FGSR_MV_RG16F;
    d.depth_kind = FGSR_DEPTH_LINEAR;
    d.mv_units = FGSR_MV_PIXELS;
    d.mv_direction = FGSR_MV_TO_PREVIOUS;
    d.scale = 1.0f;
    d.modes = shape.mode == Mode::interpolate ? FGSR_MODE_INTERPOLATE : FGSR_MODE_EXTRAPOLATE;
#if defined(FGSR_SESSION_NO_MVS) && defined(FGSR_SESSION_NO_DEPTH)
    d.flags = FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH;
#endif
#if defined(FGSR_SESSION_FAST_MOTION)
    static_assert(FGSR_PROTOCOL_MINOR >= kFastMotionMinor, "the flag came with minor 5");
    if (shape.motion == Motion::fast) {
        fgsr_daemon_info info{};
        fgsr_daemon_info_get(connection_, &info);
        if (asks_fast_motion(shape.motion, info.minor)) {
            d.flags |= FGSR_SESSION_FAST_MOTION;
        } else if (!old_daemon_logged_) {
            log_line("fgsrd speaks protocol minor " + std::to_string(info.minor) +
                     ", before fast motion estimation (" + std::to_string(kFastMotionMinor) +
                     "): its full estimation is used");
            old_daemon_logged_ = true;
        }
    }
#endif
    // Mailbox: when the layer falls behind, the daemon works on the newest frame only.
    d.queue_policy = FGSR_QUEUE_MAILBOX;
    d.input_slots = 3;
    d.output_slots = 4; // >= multiplier - 1 outputs of one submit
    const fgsr_status st = fgsr_session_create(connection_, &d, &session_);
    if (st != FGSR_STATUS_OK) {
        session_ = nullptr;
        if (st == FGSR_STATUS_DISCONNECTED || st == FGSR_STATUS_PROTOCOL_ERROR) {
            fail(st, "session creation failed", now_ns);
        } else {
            log_line(std::string("fgsrd refused a ") + std::to_string(shape.width) + "x" +
                     std::to_string(shape.height) + " session: " + fgsr_status_string(st) +
                     "; passing through");
            retry_at_ns_ = now_ns + kRetryNs;
        }
        return false;
    }
    fgsr_session_layout(session_, &layout_);
    // Sizes from the other process: the colour plane must hold the frame we write.
    const uint64_t row = uint64_t(shape.width) * FGSR_COLOR_FORMAT_BYTES(shape.format);
    const bool sane = layout_.color.row_pitch >= row &&
                      layout_.color.size >= uint64_t(layout_.color.row_pitch) * shape.height &&
                      layout_.output.row_pitch >= row &&
                      layout_.output.size >= uint64_t(layout_.output.row_pitch) * shape.height &&
                      layout_.output_width == shape.width && layout_.output_height == shape.height;
    if (!sane) {
        log_line("fgsrd's session layout does not fit the frame; passing through");
        fgsr_session_destroy(session_);
        session_ = nullptr;
        retry_at_ns_ = now_ns + kRetryNs;
        return false;
    }
    shape_ = shape;
    depth_cleared_.assign(layout_.input_slot_count, false);
    return true;
}

} // namespace fgsr::layer
