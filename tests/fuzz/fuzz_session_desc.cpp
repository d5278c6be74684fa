// Fuzz target: the wire's session rules (fgsr_session_desc_normalize) and the pool layout derived
// from them (fgsr_pool_layout_for), on arbitrary description bytes. Checks the properties that
// protocol.h and wire.h promise for an accepted description (sizes, alignment, disjoint planes,
// pool limits, idempotence), and that a refusal writes a NUL-terminated reason within the buffer
// it is given (the reason buffers are heap blocks of exactly that size, so ASan sees an overrun).
#include "fuzz_support.hpp"

#include <fgsr/wire.h>

#include <cstring>
#include <memory>

namespace {

bool aligned(uint64_t v) {
    return v % FGSR_PLANE_ALIGNMENT == 0;
}

void check_plane(const fgsr_plane& p, uint32_t w, uint32_t h, uint32_t bpp, uint64_t stride) {
    FGSR_FUZZ_CHECK(aligned(p.offset));
    FGSR_FUZZ_CHECK(p.row_pitch >= uint64_t(w) * bpp);
    FGSR_FUZZ_CHECK(p.size >= uint64_t(p.row_pitch) * h);
    FGSR_FUZZ_CHECK(p.offset + p.size <= stride);
}

bool disjoint(const fgsr_plane& a, const fgsr_plane& b) {
    return a.size == 0 || b.size == 0 || a.offset + a.size <= b.offset || b.offset + b.size <= a.offset;
}

void check_layout(const fgsr_session_desc& d, const fgsr_pool_layout& l) {
    FGSR_FUZZ_CHECK(l.input_slot_count == d.input_slots && l.output_slot_count == d.output_slots);
    FGSR_FUZZ_CHECK(l.ring_capacity == d.ring_capacity);
    FGSR_FUZZ_CHECK(aligned(l.input_slot_stride) && aligned(l.output_slot_stride));
    FGSR_FUZZ_CHECK(l.input_pool_size == l.input_slot_stride * l.input_slot_count);
    FGSR_FUZZ_CHECK(l.output_pool_size == l.output_slot_stride * l.output_slot_count);
    FGSR_FUZZ_CHECK(l.input_pool_size <= FGSR_MAX_POOL_SIZE && l.output_pool_size <= FGSR_MAX_POOL_SIZE);
    // protocol.h: FGSR_MAX_FRAME_SIDE bounds input and output frames alike.
    FGSR_FUZZ_CHECK(l.output_width >= 1 && l.output_width <= FGSR_MAX_FRAME_SIDE);
    FGSR_FUZZ_CHECK(l.output_height >= 1 && l.output_height <= FGSR_MAX_FRAME_SIDE);
    FGSR_FUZZ_CHECK(l.color.format == d.color_format && l.mv.format == d.mv_format && l.depth.format == 0 &&
                    l.output.format == d.output_format);
    check_plane(l.color, d.width, d.height, fgsr_color_format_bytes(d.color_format), l.input_slot_stride);
    check_plane(l.output, l.output_width, l.output_height, fgsr_color_format_bytes(d.output_format),
                l.output_slot_stride);
    if (d.flags & FGSR_SESSION_NO_DEPTH)
        FGSR_FUZZ_CHECK(l.depth.offset == 0 && l.depth.size == 0 && l.depth.row_pitch == 0);
    else
        check_plane(l.depth, d.width, d.height, 4, l.input_slot_stride);
    if (d.flags & FGSR_SESSION_NO_MVS)
        FGSR_FUZZ_CHECK(l.mv.offset == 0 && l.mv.size == 0 && l.mv.row_pitch == 0);
    else
        check_plane(l.mv, d.width, d.height, fgsr_mv_format_bytes(d.mv_format), l.input_slot_stride);
    FGSR_FUZZ_CHECK(disjoint(l.color, l.depth) && disjoint(l.color, l.mv) && disjoint(l.depth, l.mv));
    const fgsr_rings_layout r = fgsr_rings_layout_for(d.ring_capacity);
    FGSR_FUZZ_CHECK(l.rings_size == r.total_size);
    FGSR_FUZZ_CHECK(r.release_entries + uint64_t(d.ring_capacity) * sizeof(fgsr_release_entry) <=
                    r.total_size);
    FGSR_FUZZ_CHECK(l.reserved == 0);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fgsr_session_desc in;
    std::memset(&in, 0, sizeof(in));
    std::memcpy(&in, data, size < sizeof(in) ? size : sizeof(in));
    // The reason buffer's size comes from the byte after the description (0..255).
    const size_t reason_size = size > sizeof(in) ? data[sizeof(in)] : 256;
    std::unique_ptr<char[]> reason(reason_size > 0 ? new char[reason_size] : nullptr);
    fgsr_session_desc out;
    const fgsr_status s = fgsr_session_desc_normalize(&in, &out, reason.get(), reason_size);
    if (s != FGSR_STATUS_OK) {
        FGSR_FUZZ_CHECK(s == FGSR_STATUS_INVALID_ARGUMENT);
        if (reason_size > 0) FGSR_FUZZ_CHECK(std::memchr(reason.get(), '\0', reason_size) != nullptr);
        if (reason_size > 1) FGSR_FUZZ_CHECK(reason[0] != '\0');
        return 0;
    }
    FGSR_FUZZ_CHECK(out.struct_size == sizeof(fgsr_session_desc));
    check_layout(out, fgsr_pool_layout_for(&out));
    // What the daemon receives is the client's normalised description: normalising is idempotent.
    fgsr_session_desc twice;
    char small[8];
    FGSR_FUZZ_CHECK(fgsr_session_desc_normalize(&out, &twice, small, sizeof(small)) == FGSR_STATUS_OK);
    FGSR_FUZZ_CHECK(std::memcmp(&out, &twice, sizeof(out)) == 0);
    return 0;
}
