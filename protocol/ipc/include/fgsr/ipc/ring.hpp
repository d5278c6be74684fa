// The two loops of the wire's SPSC rings (fgsr/wire.h), once for both sides: a producer pushes
// copies of entries and publishes its private head; a consumer copies each entry out before the
// caller sees it and publishes its private tail. Positions are the caller's private copies, never
// read back from shared memory.
#pragma once

#include <fgsr/wire.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace fgsr::ipc {

// One ring of `Entry` in a mapped rings memfd.
template <class Entry> struct Ring {
    fgsr_ring_header* header = nullptr;
    Entry* entries = nullptr;
    uint32_t capacity = 0;

    // The ring whose header and entries start at `header_offset` / `entries_offset` of `base`.
    static Ring at(std::byte* base, uint64_t header_offset, uint64_t entries_offset, uint32_t capacity) {
        return {reinterpret_cast<fgsr_ring_header*>(base + header_offset),
                reinterpret_cast<Entry*>(base + entries_offset), capacity};
    }

    // Entries the producer may still push beyond `head`; negative when the consumer misbehaved.
    int64_t free_space(uint64_t head) const { return fgsr_ring_free_space(header, head, capacity); }

    // Producer: copies `e` to position `head`, advances `head` and publishes it. The caller made
    // sure free_space(head) > 0.
    void push(uint64_t& head, const Entry& e) {
        std::memcpy(fgsr_ring_slot(entries, sizeof(Entry), head, capacity), &e, sizeof(Entry));
        fgsr_ring_publish(header, ++head);
    }
};

// The three rings of a mapped rings memfd of `capacity` entries per ring (fgsr_rings_layout_for).
struct Rings {
    Ring<fgsr_submit_entry> submit;
    Ring<fgsr_completion_entry> completion;
    Ring<fgsr_release_entry> release;

    static Rings at(std::byte* base, uint32_t capacity) {
        const fgsr_rings_layout l = fgsr_rings_layout_for(capacity);
        return {Ring<fgsr_submit_entry>::at(base, l.submit_header, l.submit_entries, capacity),
                Ring<fgsr_completion_entry>::at(base, l.completion_header, l.completion_entries, capacity),
                Ring<fgsr_release_entry>::at(base, l.release_header, l.release_entries, capacity)};
    }
};

enum class Drain {
    done,    // every published entry was consumed
    overrun, // the producer's head is more than the capacity ahead of `tail` (nothing consumed)
    stopped, // `f` returned false (the entries up to and including that one were consumed)
};

// Consumer: copies each published entry beyond `tail` into private memory, consumes it (advances
// and publishes `tail`), then hands the copy to `f(const Entry&) -> bool` (false stops). `head`
// receives the head that was read.
template <class Entry, class F> Drain drain(Ring<Entry>& ring, uint64_t& tail, uint64_t& head, F&& f) {
    const uint64_t available = fgsr_ring_available(ring.header, tail);
    head = tail + available;
    if (available > ring.capacity) return Drain::overrun;
    while (tail != head) {
        Entry e;
        std::memcpy(&e, fgsr_ring_slot(ring.entries, sizeof(Entry), tail, ring.capacity), sizeof(Entry));
        fgsr_ring_consume(ring.header, ++tail);
        if (!f(static_cast<const Entry&>(e))) return Drain::stopped;
    }
    return Drain::done;
}

} // namespace fgsr::ipc
