// Fuzz target: ring entries through fgsrd's session (ServiceSession::poll, begin, execute, finish)
// over real shared memory, as a hostile client writes it. A session is made without an engine
// (its frames complete with DEVICE_ERROR), so every input runs the daemon's own ring protocol:
// copy, validate, slot ownership, completion publishing. The input is the session's shape (4
// bytes) followed by chunks that overwrite the rings memory between polls, as a client flipping
// bytes while frames run would. Checks: every violation names a reason; the daemon never holds
// more input slots than exist, never publishes more completions than the ring holds, and (with
// no engine, so no output is ever written) never names an output slot in a completion.
#include "fuzz_support.hpp"

#include "session.hpp"

#include <fgsr/wire.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <sys/mman.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 4) return 0;
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = 8 + data[0] % 24;
    d.height = 8 + data[1] % 24;
    d.color_format = d.output_format = FGSR_COLOR_RGBA8_SRGB;
    d.scale = 1.f;
    d.modes = FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
    d.input_slots = 1 + data[2] % 4;
    d.output_slots = 1 + (data[2] >> 2) % 4;
    d.ring_capacity = 4u << (data[3] % 3);
    d.queue_policy = (data[3] >> 4) & 1 ? FGSR_QUEUE_MAILBOX : FGSR_QUEUE_FIFO;
    data += 4;
    size -= 4;
    int32_t status = -1;
    std::string reason;
    auto s = fgsrd::ServiceSession::create(nullptr, 1, d, false, status, reason);
    FGSR_FUZZ_CHECK(s != nullptr); // the shape above is always valid
    const fgsr_pool_layout& l = s->layout();
    void* m = mmap(nullptr, l.rings_size, PROT_READ | PROT_WRITE, MAP_SHARED, s->fds()[FGSR_FD_RINGS], 0);
    FGSR_FUZZ_CHECK(m != MAP_FAILED);
    auto* rings = static_cast<uint8_t*>(m);
    const fgsr_rings_layout rl = fgsr_rings_layout_for(l.ring_capacity);
    auto* completion = reinterpret_cast<fgsr_ring_header*>(rings + rl.completion_header);
    uint64_t last_head = 0; // the completion head the daemon last published (the client may overwrite it)
    // Chunks: 2 bytes of position in the rings, 1 byte of length, then that many bytes.
    while (size >= 3) {
        const size_t at = (size_t(data[0]) | size_t(data[1]) << 8) % l.rings_size;
        const size_t n = std::min<size_t>({data[2], size - 3, l.rings_size - at});
        std::memcpy(rings + at, data + 3, n);
        data += 3 + n;
        size -= 3 + n;
        if (auto why = s->poll()) {
            FGSR_FUZZ_CHECK(!why->empty());
            break;
        }
        bool stop = false;
        for (int round = 0; round < 8 && s->ready() && !stop; ++round) {
            auto begun = s->begin();
            if (begun.violation) {
                FGSR_FUZZ_CHECK(!begun.violation->empty());
                stop = true;
                break;
            }
            if (!begun.job) continue;
            s->execute(*begun.job);
            if (auto why = s->finish(*begun.job)) {
                FGSR_FUZZ_CHECK(!why->empty());
                stop = true;
                break;
            }
            // Written by the daemon just now: its own head, and this frame's entries (drops that
            // begin() published before them may already be overwritten by the client).
            const uint64_t head = fgsr_ring_load_head(completion);
            const uint64_t count = begun.job->completions.size();
            FGSR_FUZZ_CHECK(count >= 1 && count <= l.ring_capacity);
            FGSR_FUZZ_CHECK(head >= last_head + count);
            for (uint64_t p = head - count; p < head; ++p) {
                const auto* e = reinterpret_cast<const fgsr_completion_entry*>(rings + rl.completion_entries) +
                                fgsr_ring_index(p, l.ring_capacity);
                FGSR_FUZZ_CHECK(e->input_slot < l.input_slot_count);
                FGSR_FUZZ_CHECK(e->output_slot == FGSR_NO_SLOT);
            }
            last_head = head;
        }
        if (stop) break;
    }
    munmap(m, l.rings_size);
    return 0;
}
