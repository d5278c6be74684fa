#include "log.hpp"
#include "server_internal.hpp"

#include <fgsr/core/clock.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sys/epoll.h>

namespace fgsrd::detail {

void copy_reason(char* dst, size_t cap, const std::string& s) {
    const size_t n = std::min(cap - 1, s.size());
    std::memcpy(dst, s.data(), n);
    dst[n] = 0;
}

// The memory a session will hold, before anything is allocated: its shared pools, the engine's
// buffers (per input and per output pixel) and the host images of the outputs of one submit.
// The per-pixel figures are fitted to the RSS of fgsrd on lavapipe after running 512x512, 1024x1024
// and 2048x2048 sessions with eight outputs per submit (docs/RELIABILITY.md, "Limits"), and err
// on the high side (2048x2048: 2000 MiB estimated, 1567 MiB measured).
static uint64_t session_memory_estimate(const fgsr_session_desc& d, const fgsr_pool_layout& l) {
    const uint64_t in_px = uint64_t(d.width) * d.height;
    const uint64_t out_px =
        uint64_t(std::ceil(double(d.width) * d.scale)) * uint64_t(std::ceil(double(d.height) * d.scale));
    constexpr uint64_t kEngineBytesPerInputPixel = 128, kEngineBytesPerOutputPixel = 32,
                       kBytesPerOutputImagePixel = 16;
    return l.input_pool_size + l.output_pool_size + l.rings_size + in_px * kEngineBytesPerInputPixel +
           out_px * (kEngineBytesPerOutputPixel + uint64_t(d.output_slots) * kBytesPerOutputImagePixel);
}

bool Server::refuse_session(Client& c, uint32_t sequence, int32_t status, const std::string& reason) {
    log::info("client {} ({}): session refused: {}: {}", c.id, c.name, fgsr_status_string(status), reason);
    fgsr_create_session_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), sequence);
    r.epoch = epoch_;
    r.status = status;
    copy_reason(r.reason, sizeof(r.reason), reason);
    if (send_reply(c, &r, sizeof(r))) return true;
    drop_client(c.id, nullptr);
    return false;
}

bool Server::create_session(Client& c, const CreateRequest& request) {
    const fgsr_session_desc& desc = request.desc;
    const uint32_t sequence = request.sequence;
    auto refuse = [&](int32_t status, const std::string& reason) {
        return refuse_session(c, sequence, status, reason);
    };
    fgsr_session_desc d;
    char why[128];
    if (fgsr_session_desc_normalize(&desc, &d, why, sizeof(why)) != FGSR_STATUS_OK)
        return refuse(FGSR_STATUS_INVALID_ARGUMENT, why);
    const fgsr_pool_layout layout = fgsr_pool_layout_for(&d);
    const uint64_t in_px = uint64_t(d.width) * d.height;
    const uint64_t out_px =
        uint64_t(std::ceil(double(d.width) * d.scale)) * uint64_t(std::ceil(double(d.height) * d.scale));
    const uint64_t pixels = std::max(in_px, out_px);
    const uint64_t memory = session_memory_estimate(d, layout);
    const auto mib = [](uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
    if (c.sessions.size() + c.creating >= opt_.max_sessions_per_client)
        return refuse(FGSR_STATUS_BUSY, "too many sessions on this connection");
    if (sessions_of(c.uid) >= opt_.max_sessions_per_uid)
        return refuse(FGSR_STATUS_BUSY, "too many sessions for uid " + std::to_string(c.uid));
    if (pixels > opt_.max_session_pixels)
        return refuse(FGSR_STATUS_UNSUPPORTED, "--max-session-pixels " +
                                                   std::to_string(opt_.max_session_pixels) + ": frames of " +
                                                   std::to_string(pixels) + " pixels");
    if (memory > opt_.max_session_memory)
        return refuse(FGSR_STATUS_UNSUPPORTED, "--max-session-memory " + mib(opt_.max_session_memory) +
                                                   ": needs about " + mib(memory));
    if (memory_ + memory > opt_.max_total_memory)
        return refuse(FGSR_STATUS_BUSY, "--max-total-memory " + mib(opt_.max_total_memory) + ": " +
                                            mib(memory_) + " held, needs " + mib(memory));
    const int lane_index = pixels > opt_.interactive_pixels ? kBulk : kInteractive;
    Lane* l = lane(lane_index);
    const uint32_t id = next_session_++;
    if (next_session_ == 0) next_session_ = 1;
    memory_ += memory;
    ++c.creating;
    const uint64_t client_id = c.id;
    const bool zero_copy = opt_.zero_copy;
    l->post([this, l, client_id, sequence, id, lane_index, memory, desc, zero_copy](fgsr::Engine* engine) {
        auto made = std::make_shared<std::unique_ptr<ServiceSession>>();
        int32_t status = FGSR_STATUS_UNSUPPORTED;
        std::string reason;
        if (engine)
            *made = ServiceSession::create(engine, id, desc, zero_copy, status, reason);
        else
            reason = "no engine for large sessions: " + l->engine_error();
        return Lane::Continuation([this, client_id, sequence, id, lane_index, memory, made, status, reason] {
            session_created(client_id, sequence, id, lane_index, memory, made, status, reason);
        });
    });
    return true;
}

void Server::session_created(uint64_t client_id, uint32_t sequence, uint32_t id, int lane_index,
                             uint64_t memory, std::shared_ptr<std::unique_ptr<ServiceSession>> made,
                             int32_t status, const std::string& reason) {
    auto cit = clients_.find(client_id);
    if (cit != clients_.end()) --cit->second->creating;
    if (cit == clients_.end() || !*made) {
        memory_ -= memory;
        if (*made) // the client went away meanwhile: destroy it where it was made
            lane(lane_index)->post([made](fgsr::Engine*) {
                made->reset();
                return Lane::Continuation{};
            });
        if (cit != clients_.end()) refuse_session(*cit->second, sequence, status, reason);
        return;
    }
    Client& c = *cit->second;
    ServiceSession& s = **made;
    const fgsr_session_desc& d = s.desc();
    // Registered before the reply, so that a failed reply tears it down like any other session.
    session_owner_[id] = SessionRef{client_id, lane_index, lanes_[size_t(lane_index)].vclock, memory, 0};
    if (hub_) {
        hub_->session_opened(id, TelemetryHub::SessionMeta{c.application, c.name, uint32_t(c.pid)}, d, s.layout());
        s.set_completion_observer(
            [hub = hub_.get(), id](const fgsr_completion_entry& entry) { hub->completion(id, entry); });
    }
    c.sessions[id] = std::move(*made);
    fgsr_create_session_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), sequence);
    r.epoch = epoch_;
    r.status = FGSR_STATUS_OK;
    r.session_id = id;
    r.layout = s.layout();
    const auto fds = s.fds();
    if (!send_reply(c, &r, sizeof(r), fds.data(), fds.size())) {
        drop_client(c.id, nullptr);
        return;
    }
    s.close_shared_fds();
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLET; // a wake-up per client write; the counter is never read
    ev.data.u64 = tag(kSession, id);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, s.submit_event_fd(), &ev);
    const char* input = !(d.flags & FGSR_SESSION_NO_MVS)       ? ""
                        : (d.flags & FGSR_SESSION_FAST_MOTION) ? ", colour only, fast motion"
                                                               : ", colour only";
    log::info("client {} ({}): session {} {}x{} x{} on the {} lane ({}{})", c.id, c.name, id, d.width,
              d.height, d.scale, lane_index == kBulk ? "bulk" : "interactive",
              s.zero_copy() ? "zero-copy input" : "staging copies", input);
}

bool Server::signal(Client& c, ServiceSession& s) {
    if (!s.signal_pending() || s.signal_complete()) return true;
    violation(c, 0,
              "session " + std::to_string(s.id()) +
                  ": its complete eventfd blocked the daemon's write (O_NONBLOCK cleared and counter full)");
    return false;
}

void Server::schedule() {
    // Poll every session (rings copied and validated, activity noted), in id order.
    std::vector<uint32_t> ids;
    ids.reserve(session_owner_.size());
    for (const auto& [sid, ref] : session_owner_) ids.push_back(sid);
    const uint64_t now = monotonic_ns();
    for (uint32_t sid : ids) {
        auto ref = session_owner_.find(sid);
        if (ref == session_owner_.end()) continue; // its client was dropped meanwhile
        Client& c = *clients_.at(ref->second.client);
        ServiceSession& s = *c.sessions.at(sid);
        if (auto why = s.poll()) {
            violation(c, 0, "session " + std::to_string(sid) + ": " + *why);
            continue;
        }
        if (s.ring_activity() != ref->second.activity) {
            ref->second.activity = s.ring_activity();
            c.active_ns = now;
        }
    }
    for (int l = 0; l < int(lanes_.size()); ++l) start_frame(l);
}

void Server::start_frame(int lane_index) {
    LaneState& ls = lanes_[size_t(lane_index)];
    while (ls.lane && !ls.frame_in_flight) {
        // The ready session of this lane with the least virtual time (engine time used since it
        // was created, from the lane's clock then); one that was idle restarts at the lane's clock.
        // Ties: round robin after the last one served.
        uint32_t best = 0;
        uint64_t best_key = UINT64_MAX;
        bool best_after = false;
        for (const auto& [sid, ref] : session_owner_) {
            if (ref.lane != lane_index) continue;
            const ServiceSession& s = *clients_.at(ref.client)->sessions.at(sid);
            if (!s.ready()) continue;
            const uint64_t key = std::max(ref.vstart + s.engine_ns(), ls.vclock);
            const bool after = sid > ls.rr_after;
            if (key < best_key || (key == best_key && after && !best_after)) {
                best = sid;
                best_key = key;
                best_after = after;
            }
        }
        if (best_key == UINT64_MAX) return;
        SessionRef& ref = session_owner_.at(best);
        Client& c = *clients_.at(ref.client);
        ServiceSession& s = *c.sessions.at(best);
        // Catch an idle session up: its virtual start moves so that its key is the clock.
        if (ref.vstart + s.engine_ns() < ls.vclock) ref.vstart = ls.vclock - s.engine_ns();
        ls.vclock = best_key;
        ls.rr_after = best;
        auto begun = s.begin();
        if (begun.violation) {
            violation(c, 0, "session " + std::to_string(best) + ": " + *begun.violation);
            continue;
        }
        if (!signal(c, s)) continue; // drops and rejections published by begin()
        if (!begun.job) continue;    // nothing for the engine: pick again
        ls.frame_in_flight = true;
        auto job = begun.job;
        ServiceSession* target = &s; // outlives the job: its destruction is posted after it
        const uint32_t sid = best;
        ls.lane->post([this, lane_index, sid, job, target](fgsr::Engine*) {
            auto spent = std::make_shared<ServiceSession::Spent>();
            target->execute(*job, *spent);
            const size_t bytes = spent->bytes();
            reaper_.dispose(std::move(spent), bytes); // freed off the critical path (reaper.hpp)
            return Lane::Continuation([this, lane_index, sid, job] { frame_done(lane_index, sid, job); });
        });
    }
}

void Server::frame_done(int lane_index, uint32_t session_id,
                        const std::shared_ptr<ServiceSession::FrameJob>& job) {
    lanes_[size_t(lane_index)].frame_in_flight = false;
    auto ref = session_owner_.find(session_id);
    if (ref != session_owner_.end()) { // else destroyed while the frame ran: nothing to publish
        Client& c = *clients_.at(ref->second.client);
        ServiceSession& s = *c.sessions.at(session_id);
        if (auto why = s.finish(*job))
            violation(c, 0, "session " + std::to_string(session_id) + ": " + *why);
        else
            signal(c, s);
    }
    start_frame(lane_index);
}

} // namespace fgsrd::detail
