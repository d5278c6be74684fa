// libfgsr_client, frames: the session's side of the rings. Acquiring a free input slot,
// submitting it (validated here, pushed on the submit ring), draining and validating completions
// (fgsr_session::pump), waiting for completions (a bounded spin on the completion ring, then the
// complete eventfd), releasing output slots.
#include "client_internal.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/ipc/spin.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <poll.h>
#include <unistd.h>

using namespace fgsr::client;
using fgsr::monotonic_ns;

// Copies every new completion out of the ring, validates it, applies input releases, queues it.
fgsr_status fgsr_session::pump() {
    if (broken != FGSR_STATUS_OK) return broken;
    // Clear the eventfd before reading the ring: a push after the drain signals again.
    pollfd p{fds[FGSR_FD_COMPLETE_EVENT].get(), POLLIN, 0};
    if (::poll(&p, 1, 0) == 1 && (p.revents & POLLIN)) {
        uint64_t v;
        if (::read(p.fd, &v, sizeof(v)) < 0 && errno != EAGAIN && errno != EINTR)
            return fail(FGSR_STATUS_INTERNAL);
    }
    uint64_t head = 0;
    const auto drained =
        fgsr::ipc::drain(rings.completion, completion_tail, head, [&](const fgsr_completion_entry& e) {
            auto it = outstanding.find(e.sequence);
            if (it == outstanding.end()) return false;
            if (e.status < FGSR_STATUS_OK || e.status >= FGSR_STATUS_COUNT_) return false;
            if (e.output_slot != FGSR_NO_SLOT) {
                if (e.output_slot >= layout.output_slot_count || output_held[e.output_slot] ||
                    e.status != FGSR_STATUS_OK)
                    return false;
                output_held[e.output_slot] = true;
            }
            if (e.output_index >= 2 * FGSR_MAX_ALPHAS + 1 || e.telemetry.pass_count > FGSR_MAX_PASSES)
                return false;
            ++it->second.outputs_seen;
            if ((e.flags & FGSR_COMPLETION_INPUT_RELEASED) != 0) {
                if (e.input_slot != it->second.input_slot || !(e.flags & FGSR_COMPLETION_LAST)) return false;
                inputs[e.input_slot] = InputState::free;
            }
            if ((e.flags & FGSR_COMPLETION_LAST) != 0) {
                if (!(e.flags & FGSR_COMPLETION_INPUT_RELEASED)) return false;
                outstanding.erase(it);
            }
            ready.push_back(e);
            return true;
        });
    if (drained != fgsr::ipc::Drain::done) return fail(FGSR_STATUS_PROTOCOL_ERROR);
    return FGSR_STATUS_OK;
}

// Waits until the complete eventfd is readable (OK), the deadline passes (TIMEOUT) or the
// daemon hangs up (DISCONNECTED).
fgsr_status fgsr_session::wait_event(uint64_t deadline_ns, bool for_input) {
    if (wait_spin_ns > 0) {
        const uint64_t now = monotonic_ns();
        // Any change of the head ends the spin; pump() validates what is there (a head the daemon
        // corrupted is an overrun: PROTOCOL_ERROR).
        const auto published = [&] { return fgsr_ring_available(rings.completion.header, completion_tail) != 0; };
        if (deadline_ns > now && fgsr::ipc::spin_until(published, std::min(wait_spin_ns, deadline_ns - now)))
            return FGSR_STATUS_OK;
    }
    for (;;) {
        pollfd p[2] = {{fds[FGSR_FD_COMPLETE_EVENT].get(), POLLIN, 0}, {conn->sock.get(), 0, 0}};
        const int r = ::poll(p, 2, ms_left(deadline_ns));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return fail(FGSR_STATUS_INTERNAL);
        if (p[0].revents & POLLIN) return FGSR_STATUS_OK;
        if (p[1].revents & (POLLHUP | POLLERR | POLLNVAL)) {
            // Completions pushed before the daemon went away are still returned first (and the
            // input slots they released handed out).
            if (pump() == FGSR_STATUS_OK && (for_input ? input_free() : !ready.empty()))
                return FGSR_STATUS_OK;
            std::lock_guard<std::mutex> lock(conn->mutex);
            conn->dead = true;
            return fail(FGSR_STATUS_DISCONNECTED);
        }
        if (r == 0) return FGSR_STATUS_TIMEOUT;
    }
}

extern "C" {

fgsr_status fgsr_acquire_input(fgsr_session* session, uint32_t timeout_ms, fgsr_input_slot* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
        bool polled = false; // the one poll at the deadline (below)
        for (;;) {
            fgsr_status st = session->pump();
            if (st != FGSR_STATUS_OK) return st;
            for (uint32_t i = 0; i < session->layout.input_slot_count; ++i) {
                if (session->inputs[i] != InputState::free) continue;
                session->inputs[i] = InputState::acquired;
                std::byte* slot = session->input.data() + uint64_t(i) * session->layout.input_slot_stride;
                *out = fgsr_input_slot{};
                out->index = i;
                out->color = slot + session->layout.color.offset;
                // A plane the session declared absent (FGSR_SESSION_NO_DEPTH / NO_MVS) is NULL.
                out->depth = session->layout.depth.size ? slot + session->layout.depth.offset : nullptr;
                out->mv = session->layout.mv.size ? slot + session->layout.mv.offset : nullptr;
                return FGSR_STATUS_OK;
            }
            // At the deadline wait_event still polls once (with a zero timeout), so that a call
            // with timeout 0 (a layer's, every frame) sees the daemon hang up. Without it, a daemon
            // killed with every slot in flight left such a caller on NO_SLOT for good.
            if (ms_left(deadline) == 0) {
                if (polled) return FGSR_STATUS_NO_SLOT;
                polled = true;
            }
            st = session->wait_event(deadline, true);
            if (st == FGSR_STATUS_TIMEOUT) return FGSR_STATUS_NO_SLOT;
            if (st != FGSR_STATUS_OK) return st;
        }
    });
}

fgsr_status fgsr_submit(fgsr_session* session, const fgsr_submit_info* info, uint64_t* out_sequence) {
    if (!session || !info || info->struct_size < sizeof(fgsr_submit_info))
        return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        if (session->broken != FGSR_STATUS_OK) return session->broken;
        const fgsr_session_desc& d = session->desc;
        if (info->input_slot >= session->layout.input_slot_count ||
            session->inputs[info->input_slot] != InputState::acquired)
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (info->flags & ~(FGSR_SUBMIT_RESET | FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR))
            return FGSR_STATUS_INVALID_ARGUMENT;
        if ((info->flags & FGSR_SUBMIT_HAS_MV) && (d.flags & FGSR_SESSION_NO_MVS))
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (info->interp_count > FGSR_MAX_ALPHAS || info->extrap_count > FGSR_MAX_ALPHAS)
            return FGSR_STATUS_INVALID_ARGUMENT;
        if ((info->interp_count && (!(d.modes & FGSR_MODE_INTERPOLATE) || !info->interp_alphas)) ||
            (info->extrap_count && (!(d.modes & FGSR_MODE_EXTRAPOLATE) || !info->extrap_alphas)) ||
            ((info->flags & FGSR_SUBMIT_WANT_SR) && !(d.modes & FGSR_MODE_SR)))
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (!std::isfinite(info->jitter_x) || !std::isfinite(info->jitter_y))
            return FGSR_STATUS_INVALID_ARGUMENT;
        fgsr_submit_entry e{};
        for (uint32_t i = 0; i < info->interp_count; ++i) {
            const float a = info->interp_alphas[i];
            if (!std::isfinite(a) || a <= 0.f || a >= 1.f) return FGSR_STATUS_INVALID_ARGUMENT;
            e.interp_alphas[i] = a;
        }
        for (uint32_t i = 0; i < info->extrap_count; ++i) {
            const float a = info->extrap_alphas[i];
            if (!std::isfinite(a) || a <= 0.f || a > 1.f) return FGSR_STATUS_INVALID_ARGUMENT;
            e.extrap_alphas[i] = a;
        }
        // The daemon consumes submits in order; the ring holds at most one entry per input slot,
        // so a full ring means the daemon misbehaves or lags far behind.
        const int64_t room = session->rings.submit.free_space(session->submit_head);
        if (room < 0) return session->fail(FGSR_STATUS_PROTOCOL_ERROR);
        if (room == 0) return FGSR_STATUS_NO_SLOT;

        e.sequence = session->next_sequence;
        e.input_slot = info->input_slot;
        e.flags = info->flags;
        e.jitter_x = info->jitter_x;
        e.jitter_y = info->jitter_y;
        e.interp_count = info->interp_count;
        e.extrap_count = info->extrap_count;
        e.present_time_ns = info->present_time_ns;
        e.user_data = info->user_data;
        if (session->recorder) {
            const std::byte* slot =
                session->input.data() + uint64_t(info->input_slot) * session->layout.input_slot_stride;
            if (session->recorder->add(session->layout, slot, e) != FGSR_STATUS_OK) {
                log_line("recording stopped: %s", session->recorder->error().c_str());
                session->recorder.reset();
            }
        }
        e.submit_time_ns = monotonic_ns();
        session->rings.submit.push(session->submit_head, e);
        session->inputs[info->input_slot] = InputState::submitted;
        session->outstanding[e.sequence] = Outstanding{info->input_slot, 0};
        ++session->next_sequence;
        const uint64_t one = 1;
        if (::write(session->fds[FGSR_FD_SUBMIT_EVENT].get(), &one, sizeof(one)) < 0 && errno != EAGAIN)
            return session->fail(FGSR_STATUS_DISCONNECTED);
        if (out_sequence) *out_sequence = e.sequence;
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_wait(fgsr_session* session, uint32_t timeout_ms, fgsr_output* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
        bool polled = false; // the one poll at the deadline (below)
        for (;;) {
            if (session->ready.empty()) {
                const fgsr_status st = session->pump();
                if (st != FGSR_STATUS_OK) return st;
            }
            if (!session->ready.empty()) {
                const fgsr_completion_entry e = session->ready.front();
                session->ready.pop_front();
                const fgsr_pool_layout& l = session->layout;
                *out = fgsr_output{};
                out->sequence = e.sequence;
                out->status = e.status;
                out->output_slot = e.output_slot;
                out->output_index = e.output_index;
                out->user_data = e.user_data;
                out->telemetry = e.telemetry;
                out->flags = e.flags;
                if (e.output_slot != FGSR_NO_SLOT) {
                    out->width = l.output_width;
                    out->height = l.output_height;
                    out->row_pitch = l.output.row_pitch;
                    out->format = l.output.format;
                    out->pixels = session->output.data() + uint64_t(e.output_slot) * l.output_slot_stride +
                                  l.output.offset;
                }
                return FGSR_STATUS_OK;
            }
            // As in fgsr_acquire_input: at the deadline wait_event still polls once for a hang-up.
            if (ms_left(deadline) == 0) {
                if (polled) return FGSR_STATUS_TIMEOUT;
                polled = true;
            }
            const fgsr_status st = session->wait_event(deadline);
            if (st != FGSR_STATUS_OK) return st;
        }
    });
}

fgsr_status fgsr_release_output(fgsr_session* session, uint32_t output_slot) {
    if (!session) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        if (output_slot >= session->layout.output_slot_count || !session->output_held[output_slot])
            return FGSR_STATUS_INVALID_ARGUMENT;
        session->output_held[output_slot] = false;
        if (session->broken != FGSR_STATUS_OK) return session->broken;
        if (session->rings.release.free_space(session->release_head) <= 0)
            return session->fail(FGSR_STATUS_PROTOCOL_ERROR); // cannot fill up: see ring_capacity
        fgsr_release_entry r{};
        r.output_slot = output_slot;
        session->rings.release.push(session->release_head, r);
        const uint64_t one = 1;
        if (::write(session->fds[FGSR_FD_SUBMIT_EVENT].get(), &one, sizeof(one)) < 0 && errno != EAGAIN)
            return session->fail(FGSR_STATUS_DISCONNECTED);
        return FGSR_STATUS_OK;
    });
}

} // extern "C"
