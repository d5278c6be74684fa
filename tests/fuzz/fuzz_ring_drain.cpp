// Fuzz target: the ring loops of fgsr_ipc (fgsr/ipc/ring.hpp) on arbitrary ring memory and
// positions, as a misbehaving peer could leave them. The rings memfd is a heap block of exactly
// fgsr_rings_layout_for(capacity).total_size bytes with everything but the headers' head and tail
// words and the entry arrays poisoned, so ASan reports any access outside the ring's own parts.
// Input: [log2 capacity][ring 0..2][stop after][consumer tail: 8][producer head: 8][peer tail: 8]
// then bytes that fill the rings memory (repeated). Checks: an overrun consumes nothing; otherwise
// exactly the published entries (or up to the stop) are handed over, each equal to its slot, and
// the published tail follows; the producer never pushes into a full or inconsistent ring.
#include "fuzz_support.hpp"

#include <fgsr/ipc/ring.hpp>

#include <fuzzer/FuzzedDataProvider.h>

#include <sanitizer/asan_interface.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>
#include <tuple>
#include <vector>

namespace {

template <class Entry>
void exercise(fgsr::ipc::Ring<Entry> ring, uint64_t tail, uint64_t head_published, uint32_t stop_after,
              uint64_t peer_tail) {
    fgsr_ring_publish(ring.header, head_published);
    const uint64_t tail_before = tail;
    uint64_t head = 0;
    uint32_t calls = 0;
    const auto result = fgsr::ipc::drain(ring, tail, head, [&](const Entry& e) {
        // The entry at position tail_before + calls, computed here rather than with fgsr_ring_slot.
        const Entry* slot = ring.entries + (tail_before + calls) % ring.capacity;
        FGSR_FUZZ_CHECK(std::memcmp(&e, slot, sizeof(Entry)) == 0);
        return calls++ < stop_after;
    });
    const uint64_t available = head_published - tail_before;
    FGSR_FUZZ_CHECK(head == head_published);
    if (available > ring.capacity) {
        FGSR_FUZZ_CHECK(result == fgsr::ipc::Drain::overrun);
        FGSR_FUZZ_CHECK(calls == 0 && tail == tail_before);
    } else if (result == fgsr::ipc::Drain::done) {
        FGSR_FUZZ_CHECK(calls == available && tail == head_published);
    } else {
        FGSR_FUZZ_CHECK(result == fgsr::ipc::Drain::stopped);
        FGSR_FUZZ_CHECK(calls == stop_after + 1 && calls <= available);
    }
    FGSR_FUZZ_CHECK(tail == tail_before + calls);
    FGSR_FUZZ_CHECK(fgsr_ring_load_tail(ring.header) == (calls > 0 ? tail : peer_tail));

    // The producer side of the same ring against a peer's arbitrary tail.
    fgsr_ring_consume(ring.header, peer_tail);
    uint64_t producer_head = head_published;
    const int64_t free_space = ring.free_space(producer_head);
    const uint64_t used = producer_head - peer_tail;
    FGSR_FUZZ_CHECK(free_space < 0 ? used > ring.capacity : uint64_t(free_space) == ring.capacity - used);
    if (free_space > 0) {
        Entry e;
        std::memset(&e, 0xa5, sizeof(e));
        ring.push(producer_head, e);
        FGSR_FUZZ_CHECK(producer_head == head_published + 1);
        FGSR_FUZZ_CHECK(fgsr_ring_load_head(ring.header) == producer_head);
        const Entry* slot = ring.entries + head_published % ring.capacity;
        FGSR_FUZZ_CHECK(std::memcmp(slot, &e, sizeof(Entry)) == 0);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    FuzzedDataProvider in(data, size);
    const uint32_t capacity = 1u << (in.ConsumeIntegral<uint8_t>() % 13); // 1..4096 (FGSR_MAX_RING_CAPACITY)
    const uint8_t which = in.ConsumeIntegral<uint8_t>() % 3;
    const uint32_t stop_after = in.ConsumeIntegral<uint8_t>();
    const uint64_t tail = in.ConsumeIntegral<uint64_t>();
    // Heads near the tail are the interesting ones: a small signed offset unless the top bit is set.
    const uint64_t head_raw = in.ConsumeIntegral<uint64_t>();
    const uint64_t head = (head_raw >> 63) ? head_raw : tail + uint64_t(int64_t(int16_t(head_raw)));
    const uint64_t peer_raw = in.ConsumeIntegral<uint64_t>();
    const uint64_t peer_tail = (peer_raw >> 63) ? peer_raw : head - uint64_t(int64_t(int16_t(peer_raw)));
    const std::vector<uint8_t> fill = in.ConsumeRemainingBytes<uint8_t>();

    const fgsr_rings_layout layout = fgsr_rings_layout_for(capacity);
    const size_t bytes = size_t(layout.total_size);
    std::unique_ptr<std::byte[]> memory(new std::byte[bytes]);
    // The fill, repeated (a doubling copy: rings of 4096 entries are megabytes).
    std::memset(memory.get(), 0, bytes);
    size_t filled = std::min(fill.size(), bytes);
    if (filled > 0) std::memcpy(memory.get(), fill.data(), filled);
    while (filled > 0 && filled < bytes) {
        const size_t n = std::min(filled, bytes - filled);
        std::memcpy(memory.get() + filled, memory.get(), n);
        filled += n;
    }
    fgsr::ipc::Rings rings = fgsr::ipc::Rings::at(memory.get(), capacity);
    // Only the head and tail words of each header and the entry arrays may be touched: the rest
    // of the block (header padding, alignment gaps, the page-rounded end) is poisoned, so that an
    // access to the wrong section, which stays inside the block, is reported too.
    ASAN_POISON_MEMORY_REGION(memory.get(), bytes);
    const auto open = [&](uint64_t offset, uint64_t size) {
        ASAN_UNPOISON_MEMORY_REGION(memory.get() + offset, size);
    };
    for (auto [header, entries, entry_size] :
         {std::tuple{layout.submit_header, layout.submit_entries, sizeof(fgsr_submit_entry)},
          std::tuple{layout.completion_header, layout.completion_entries, sizeof(fgsr_completion_entry)},
          std::tuple{layout.release_header, layout.release_entries, sizeof(fgsr_release_entry)}}) {
        open(header + offsetof(fgsr_ring_header, head), sizeof(uint64_t));
        open(header + offsetof(fgsr_ring_header, tail), sizeof(uint64_t));
        open(entries, uint64_t(capacity) * entry_size);
    }
    fgsr_ring_consume(rings.submit.header, peer_tail);
    fgsr_ring_consume(rings.completion.header, peer_tail);
    fgsr_ring_consume(rings.release.header, peer_tail);
    if (which == 0) exercise(rings.submit, tail, head, stop_after, peer_tail);
    if (which == 1) exercise(rings.completion, tail, head, stop_after, peer_tail);
    if (which == 2) exercise(rings.release, tail, head, stop_after, peer_tail);
    return 0;
}
