// libfgsr_client, sessions: fgsr_session_create (the description checked and normalised by the
// protocol's one rule set, CREATE_SESSION, then the reply checked: its layout must equal the one
// computed here with fgsr_pool_layout_for, its fds must be the memfds and eventfds the wire
// promises), mapping the pools and rings; destroy, layout, stats, and the recording switch.
#include "client_internal.hpp"

#include <fgsr/core/clock.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef F_SEAL_FUTURE_WRITE
#define F_SEAL_FUTURE_WRITE 0x0010
#endif

using namespace fgsr::client;

namespace {

bool is_eventfd(int fd) {
    char path[64], target[64];
    std::snprintf(path, sizeof(path), "/proc/self/fd/%d", fd);
    const ssize_t n = ::readlink(path, target, sizeof(target) - 1);
    if (n <= 0) return false;
    target[n] = '\0';
    return std::strcmp(target, "anon_inode:[eventfd]") == 0;
}

// fstat and seals of a pool memfd: a regular file of at least `size` bytes with `seals`.
bool memfd_ok(int fd, uint64_t size, int seals_required, int seals_any_of) {
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) < size) return false;
    if (seals_required == 0 && seals_any_of == 0) return true;
    const int seals = ::fcntl(fd, F_GET_SEALS);
    if (seals < 0 || (seals & seals_required) != seals_required) return false;
    return seals_any_of == 0 || (seals & seals_any_of) != 0;
}

// The daemon's layout equals the one the client computes for its own normalised description.
// `reserved` is not compared (a later minor version may use it).
bool same_layout(fgsr_pool_layout a, fgsr_pool_layout b) {
    a.reserved = b.reserved = 0;
    return std::memcmp(&a, &b, sizeof(a)) == 0;
}

} // namespace

void fgsr_session::stop_recording() {
    if (!recorder) return;
    if (recorder->finish() != FGSR_STATUS_OK) log_line("recording: %s", recorder->error().c_str());
    recorder.reset();
}

extern "C" {

fgsr_status fgsr_session_create(fgsr_connection* connection, const fgsr_session_desc* desc,
                                fgsr_session** out) {
    if (!out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = nullptr;
    if (!connection || !desc) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        auto s = std::make_unique<fgsr_session>();
        s->conn = connection;
        char refused[128];
        fgsr_status st = fgsr_session_desc_normalize(desc, &s->desc, refused, sizeof(refused));
        if (st != FGSR_STATUS_OK) {
            log_line("session description refused: %s", refused);
            return st;
        }
        fgsr_create_session msg{};
        msg.desc = s->desc;
        fgsr_create_session_reply reply{};
        std::vector<Fd> fds;
        {
            std::lock_guard<std::mutex> lock(connection->mutex);
            st = connection->request(&msg, sizeof(msg), FGSR_MSG_CREATE_SESSION, &reply, sizeof(reply),
                                     FGSR_MSG_CREATE_SESSION_REPLY, &fds, kDefaultTimeoutMs);
        }
        if (st != FGSR_STATUS_OK) return st;
        reply.reason[sizeof(reply.reason) - 1] = '\0';
        if (reply.status != FGSR_STATUS_OK) {
            if (reply.reason[0]) log_line("fgsrd refused the session: %s", reply.reason);
            const fgsr_status r = peer_status(reply.status);
            return r == FGSR_STATUS_INVALID_ARGUMENT || r == FGSR_STATUS_UNSUPPORTED ||
                           r == FGSR_STATUS_OUT_OF_MEMORY || r == FGSR_STATUS_BUSY
                       ? r
                       : FGSR_STATUS_PROTOCOL_ERROR;
        }
        // From here on any mismatch is the daemon's fault: every received fd is closed (fds owns
        // them) and the session is destroyed on the daemon's side when we tell it.
        auto refuse = [&](const char* why) {
            log_line("session reply rejected: %s", why);
            (void)connection->destroy_session(reply.session_id);
            return FGSR_STATUS_PROTOCOL_ERROR;
        };
        if (fds.size() != FGSR_FD_COUNT) return refuse("wrong number of fds");
        if (reply.session_id == 0) return refuse("session id 0");
        const fgsr_pool_layout& l = reply.layout;
        if (!same_layout(l, fgsr_pool_layout_for(&s->desc)))
            return refuse("layout does not match the request");
        if (!memfd_ok(fds[FGSR_FD_INPUT_POOL].get(), l.input_pool_size, F_SEAL_SHRINK | F_SEAL_GROW, 0) ||
            !memfd_ok(fds[FGSR_FD_OUTPUT_POOL].get(), l.output_pool_size, F_SEAL_SHRINK | F_SEAL_GROW,
                      F_SEAL_WRITE | F_SEAL_FUTURE_WRITE) ||
            !memfd_ok(fds[FGSR_FD_RINGS].get(), l.rings_size, 0, 0))
            return refuse("pool fds do not match the layout (size, type or seals)");
        if (!is_eventfd(fds[FGSR_FD_SUBMIT_EVENT].get()) || !is_eventfd(fds[FGSR_FD_COMPLETE_EVENT].get()))
            return refuse("event fds are not eventfds");
        s->input = Mapping::map(fds[FGSR_FD_INPUT_POOL].get(), l.input_pool_size, PROT_READ | PROT_WRITE);
        s->output = Mapping::map(fds[FGSR_FD_OUTPUT_POOL].get(), l.output_pool_size, PROT_READ);
        s->rings_map = Mapping::map(fds[FGSR_FD_RINGS].get(), l.rings_size, PROT_READ | PROT_WRITE);
        if (!s->input.valid() || !s->output.valid() || !s->rings_map.valid()) return refuse("mmap failed");
        s->id = reply.session_id;
        s->layout = l;
        for (int i = 0; i < FGSR_FD_COUNT; ++i) s->fds[i] = std::move(fds[size_t(i)]);
        s->rings = fgsr::ipc::Rings::at(s->rings_map.data(), l.ring_capacity);
        // Positions start where the daemon left them (0 for a new session).
        s->submit_head = fgsr_ring_load_head(s->rings.submit.header);
        s->completion_tail = fgsr_ring_load_tail(s->rings.completion.header);
        s->release_head = fgsr_ring_load_head(s->rings.release.header);
        if (s->submit_head != 0 || s->completion_tail != 0 || s->release_head != 0)
            return refuse("rings are not empty");
        s->wait_spin_ns = wait_spin_ns_from_env();
        if (const char* dir = std::getenv("FGSR_CAPTURE"); dir && *dir) {
            std::string reason;
            s->recorder = make_recorder(dir, connection->name, s->desc, reason);
            if (!s->recorder)
                log_line("FGSR_CAPTURE: %s", reason.c_str());
            else
                s->record_dir = dir;
        }
        *out = s.release();
        return FGSR_STATUS_OK;
    });
}

void fgsr_session_destroy(fgsr_session* session) {
    if (!session) return;
    (void)guarded([&]() -> fgsr_status {
        session->stop_recording();
        (void)session->flush_reports();
        return session->conn->destroy_session(session->id);
    });
    delete session;
}

fgsr_status fgsr_session_layout(const fgsr_session* session, fgsr_pool_layout* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = session->layout;
    return FGSR_STATUS_OK;
}

int fgsr_session_event_fd(const fgsr_session* session) {
    return session ? session->fds[FGSR_FD_COMPLETE_EVENT].get() : -1;
}

fgsr_status fgsr_session_stats_get(fgsr_session* session, fgsr_session_stats* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        fgsr_session_ref ref{};
        ref.session_id = session->id;
        fgsr_stats_reply r{};
        fgsr_status st;
        {
            std::lock_guard<std::mutex> lock(session->conn->mutex);
            st = session->conn->request(&ref, sizeof(ref), FGSR_MSG_STATS, &r, sizeof(r),
                                        FGSR_MSG_STATS_REPLY, nullptr, kDefaultTimeoutMs);
        }
        if (st != FGSR_STATUS_OK) return st;
        if (r.status != FGSR_STATUS_OK) return peer_status(r.status);
        if (r.session_id != session->id) return FGSR_STATUS_PROTOCOL_ERROR;
        *out = r.stats;
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_session_record(fgsr_session* session, const char* dir) {
    if (!session) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        session->stop_recording();
        if (!dir) return FGSR_STATUS_OK;
        if (!*dir) return FGSR_STATUS_INVALID_ARGUMENT;
        std::string reason;
        session->recorder = make_recorder(dir, session->conn->name, session->desc, reason);
        if (!session->recorder) {
            log_line("recording: %s", reason.c_str());
            return FGSR_STATUS_UNSUPPORTED;
        }
        session->record_dir = dir;
        return FGSR_STATUS_OK;
    });
}

} // extern "C"

fgsr_status fgsr_session::flush_reports() {
    std::lock_guard<std::mutex> lock(conn->mutex);
    if (conn->dead) {
        reports.clear();
        return FGSR_STATUS_DISCONNECTED;
    }
    size_t sent = 0;
    while (sent < reports.size()) {
        fgsr_report m{};
        const uint32_t n = uint32_t(std::min<size_t>(FGSR_MAX_REPORTS_PER_MESSAGE, reports.size() - sent));
        const uint32_t size = FGSR_REPORT_MESSAGE_SIZE(n);
        m.header = fgsr_msg_header_for(FGSR_MSG_REPORT, size, 0);
        m.session_id = id;
        m.count = n;
        std::memcpy(m.reports, reports.data() + sent, sizeof(fgsr_present_report) * n);
        // No reply comes; a full socket drops the reports rather than block the caller's present.
        const ssize_t w = ::send(conn->sock.get(), &m, size, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (w != ssize_t(size)) {
            if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
                reports.clear();
                return FGSR_STATUS_DISCONNECTED;
            }
            reports_lost += reports.size() - sent;
            break;
        }
        sent += n;
    }
    reports.clear();
    return FGSR_STATUS_OK;
}

fgsr_status fgsr_report_presents(fgsr_session* session, const fgsr_present_report* reports, uint32_t count) {
    if (!session || (count > 0 && !reports)) return FGSR_STATUS_INVALID_ARGUMENT;
    for (uint32_t i = 0; i < count; ++i)
        if (reports[i].frame_type > FGSR_FRAME_EXTRAPOLATED) return FGSR_STATUS_INVALID_ARGUMENT;
    if (session->conn->info.minor < 3) return FGSR_STATUS_UNSUPPORTED;
    return guarded([&]() -> fgsr_status {
        const uint64_t now = fgsr::monotonic_ns();
        if (session->reports.empty()) session->reports_since_ns = now;
        session->reports.insert(session->reports.end(), reports, reports + count);
        // Batched: a message per 16 reports, or when the oldest has waited 50 ms.
        constexpr uint64_t kMaxDelayNs = 50'000'000;
        if (session->reports.size() >= FGSR_MAX_REPORTS_PER_MESSAGE ||
            now - session->reports_since_ns >= kMaxDelayNs)
            return session->flush_reports();
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_report_probe_samples(fgsr_connection* connection, const fgsr_probe_sample* samples,
                                      uint32_t count) {
    if (!connection || (count > 0 && !samples)) return FGSR_STATUS_INVALID_ARGUMENT;
    for (uint32_t i = 0; i < count; ++i)
        if (samples[i].photon_ns < samples[i].click_ns || samples[i].mode > FGSR_PROBE_MODE_EXTRAPOLATE)
            return FGSR_STATUS_INVALID_ARGUMENT;
    if (connection->info.minor < 3) return FGSR_STATUS_UNSUPPORTED;
    return guarded([&]() -> fgsr_status {
        std::lock_guard<std::mutex> lock(connection->mutex);
        if (connection->dead) return FGSR_STATUS_DISCONNECTED;
        for (uint32_t sent = 0; sent < count;) {
            fgsr_probe m{};
            const uint32_t n = std::min(FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE, count - sent);
            const uint32_t size = FGSR_PROBE_MESSAGE_SIZE(n);
            m.header = fgsr_msg_header_for(FGSR_MSG_PROBE, size, 0);
            m.count = n;
            std::memcpy(m.samples, samples + sent, sizeof(fgsr_probe_sample) * n);
            // No reply comes; a full socket drops the samples rather than block.
            const ssize_t w = ::send(connection->sock.get(), &m, size, MSG_DONTWAIT | MSG_NOSIGNAL);
            if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return FGSR_STATUS_DISCONNECTED;
            if (w != ssize_t(size)) return FGSR_STATUS_OK; // dropped
            sent += n;
        }
        return FGSR_STATUS_OK;
    });
}
