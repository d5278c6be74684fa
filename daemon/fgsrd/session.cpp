#include "session.hpp"

#include "log.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/engine/color.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <mutex>
#include <pthread.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <unistd.h>

namespace fgsrd {

uint64_t thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

namespace {

// The signal that interrupts a blocked eventfd write (see signal_eventfd).
int interrupt_signal() {
    return SIGRTMIN + 2;
}

} // namespace

bool signal_eventfd(int fd) {
    struct ThreadTimer {
        timer_t id{};
        bool ok = false;
        sigset_t set{};
        ThreadTimer() {
            static std::once_flag installed;
            std::call_once(installed, [] {
                struct sigaction sa {};
                sa.sa_handler = [](int) {}; // no SA_RESTART: the write returns EINTR
                sigemptyset(&sa.sa_mask);
                sigaction(interrupt_signal(), &sa, nullptr);
            });
            sigemptyset(&set);
            sigaddset(&set, interrupt_signal());
            pthread_sigmask(SIG_BLOCK, &set, nullptr); // unblocked only around the write
            sigevent ev{};
            ev.sigev_notify = SIGEV_THREAD_ID;
            ev.sigev_signo = interrupt_signal();
            ev._sigev_un._tid = gettid(); // sigev_notify_thread_id in glibc >= 2.37
            ok = timer_create(CLOCK_MONOTONIC, &ev, &id) == 0;
            if (!ok) log::error("timer_create: {}; eventfd writes are not protected", std::strerror(errno));
        }
        ~ThreadTimer() {
            if (ok) timer_delete(id);
        }
    };
    thread_local ThreadTimer timer;
    const uint64_t one = 1;
    if (!timer.ok) return write(fd, &one, sizeof(one)) == sizeof(one) || errno == EAGAIN;
    // 10 ms: far longer than a write that does not block takes, short enough that one hostile
    // client costs the others one hiccup before it is dropped.
    itimerspec arm{};
    arm.it_value.tv_nsec = 10'000'000;
    timer_settime(timer.id, 0, &arm, nullptr);
    pthread_sigmask(SIG_UNBLOCK, &timer.set, nullptr);
    const ssize_t n = write(fd, &one, sizeof(one));
    const int err = errno;
    pthread_sigmask(SIG_BLOCK, &timer.set, nullptr);
    const itimerspec disarm{};
    timer_settime(timer.id, 0, &disarm, nullptr);
    // A signal that fired after the write returned stays pending while blocked: take it now.
    const timespec zero{};
    while (sigtimedwait(&timer.set, nullptr, &zero) > 0) {
    }
    if (n == sizeof(one)) return true;
    if (err == EAGAIN) return true; // counter full and non-blocking: the client has a wake-up pending
    if (err != EINTR) log::warn("eventfd write: {}", std::strerror(err));
    return false;
}

namespace {

constexpr size_t kLatencySamples = 4096;
constexpr uint32_t kKnownSubmitFlags = FGSR_SUBMIT_RESET | FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR;

uint64_t percentile(std::vector<uint64_t> v, double q) {
    if (v.empty()) return 0;
    const size_t k = std::min(v.size() - 1, size_t(std::floor(q * double(v.size() - 1) + 0.5)));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

UniqueFd make_memfd(const char* name, uint64_t size) {
    UniqueFd fd(memfd_create(name, MFD_CLOEXEC | MFD_ALLOW_SEALING));
    if (!fd) return fd;
    if (ftruncate(fd.get(), off_t(size)) != 0) fd.reset();
    return fd;
}

} // namespace

std::unique_ptr<ServiceSession> ServiceSession::create(fgsr::Engine* engine, uint32_t id,
                                                       const fgsr_session_desc& in, bool zero_copy,
                                                       int32_t& status, std::string& reason) {
    status = FGSR_STATUS_INVALID_ARGUMENT;
    auto bad = [&](std::string why) -> std::unique_ptr<ServiceSession> {
        reason = std::move(why);
        return nullptr;
    };
    fgsr_session_desc d;
    char why[128];
    if (fgsr_session_desc_normalize(&in, &d, why, sizeof(why)) != FGSR_STATUS_OK) return bad(why);

    fgsr::FrameFormat format;
    format.width = d.width;
    format.height = d.height;
    format.color_format = fgsr::ColorFormat(d.color_format);
    format.mv_format = fgsr::MvFormat(d.mv_format);
    format.conventions.depth_kind = fgsr::DepthKind(d.depth_kind);
    format.conventions.near_plane = d.near_plane;
    format.conventions.far_plane = d.far_plane;
    format.conventions.mv_units = fgsr::MvUnits(d.mv_units);
    format.conventions.mv_direction = fgsr::MvDirection(d.mv_direction);
    format.conventions.mv_y_up = (d.flags & FGSR_SESSION_MV_Y_UP) != 0;
    format.has_vectors = (d.flags & FGSR_SESSION_NO_MVS) == 0;
    format.has_depth = (d.flags & FGSR_SESSION_NO_DEPTH) == 0;
    fgsr::Params params;
    params.scale = d.scale;
    if (d.t_depth > 0) params.t_depth = d.t_depth;
    if (d.t_bright > 0) params.t_bright = d.t_bright;
    if (d.sr_a > 0) params.sr_a = d.sr_a;
    if (d.sr_b > 0) params.sr_b = d.sr_b;
    params.motion =
        (d.flags & FGSR_SESSION_LINEAR_MOTION) ? fgsr::MotionModel::linear : fgsr::MotionModel::quadratic;
    params.dilate_mvs = (d.flags & FGSR_SESSION_DILATE_MVS) != 0;
    params.mvs_contain_jitter = (d.flags & FGSR_SESSION_MVS_CONTAIN_JITTER) != 0;
    params.denoise = (d.flags & FGSR_SESSION_NO_DENOISE) == 0;
    params.correct_vectors = (d.flags & FGSR_SESSION_CORRECT_MVS) != 0;
    params.fast_motion = (d.flags & FGSR_SESSION_FAST_MOTION) != 0;
    params.colour_agree = (d.flags & FGSR_SESSION_COLOUR_AGREE) != 0;

    std::unique_ptr<ServiceSession> s(new ServiceSession());
    s->id_ = id;
    s->desc_ = d;

    // Layout: planes and slots on FGSR_PLANE_ALIGNMENT (host-pointer import and page mapping); the
    // client computes the same and compares.
    s->layout_ = fgsr_pool_layout_for(&d);
    const fgsr_pool_layout& l = s->layout_;

    if (engine) {
        auto engine_session = engine->create_session(format, params);
        if (!engine_session) {
            status = engine_session.error().code == fgsr::Errc::unsupported ? FGSR_STATUS_UNSUPPORTED
                     : engine_session.error().code == fgsr::Errc::vulkan    ? FGSR_STATUS_OUT_OF_MEMORY
                                                                            : FGSR_STATUS_INVALID_ARGUMENT;
            return bad(engine_session.error().message);
        }
        s->engine_session_ = std::move(*engine_session);
    }

    status = FGSR_STATUS_OUT_OF_MEMORY;
    s->input_fd_ = make_memfd("fgsr-input", l.input_pool_size);
    s->output_fd_ = make_memfd("fgsr-output", l.output_pool_size);
    s->rings_fd_ = make_memfd("fgsr-rings", l.rings_size);
    if (!s->input_fd_ || !s->output_fd_ || !s->rings_fd_)
        return bad(std::string("memfd: ") + std::strerror(errno));
    // The daemon maps the input pool read-write only so that drivers which pin imported pages for
    // writing can import it; it never writes there.
    s->input_map_ = Mapping::map(s->input_fd_.get(), l.input_pool_size, PROT_READ | PROT_WRITE);
    s->output_map_ = Mapping::map(s->output_fd_.get(), l.output_pool_size, PROT_READ | PROT_WRITE);
    s->rings_map_ = Mapping::map(s->rings_fd_.get(), l.rings_size, PROT_READ | PROT_WRITE);
    if (!s->input_map_.valid() || !s->output_map_.valid() || !s->rings_map_.valid())
        return bad(std::string("mmap: ") + std::strerror(errno));
    s->rings_ = fgsr::ipc::Rings::at(s->rings_map_.data(), l.ring_capacity);
    // Seals: no side can change the sizes (no SIGBUS from a truncation); the output pool gets
    // FUTURE_WRITE after the daemon's writable mapping exists, so clients can map it read-only only.
    if (fcntl(s->input_fd_.get(), F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0 ||
        fcntl(s->rings_fd_.get(), F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0 ||
        fcntl(s->output_fd_.get(), F_ADD_SEALS,
              F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_FUTURE_WRITE | F_SEAL_SEAL) != 0) {
        status = FGSR_STATUS_INTERNAL;
        return bad(std::string("F_ADD_SEALS: ") + std::strerror(errno));
    }
    s->submit_event_.reset(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
    s->complete_event_.reset(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
    if (!s->submit_event_ || !s->complete_event_) return bad(std::string("eventfd: ") + std::strerror(errno));

    if (zero_copy && engine) {
        const size_t align = engine->host_import_alignment();
        if (align > 0 && FGSR_PLANE_ALIGNMENT % align == 0) {
            auto imp = engine->import_host_memory(s->input_map_.data(), l.input_pool_size);
            if (imp)
                s->import_ = std::move(*imp);
            else
                log::warn("session {}: host import failed, staging copies instead: {}", id,
                          imp.error().message);
        }
    }
    s->free_outputs_ = d.output_slots;
    status = FGSR_STATUS_OK;
    return s;
}

ServiceSession::~ServiceSession() = default;

std::array<int, FGSR_FD_COUNT> ServiceSession::fds() const {
    return {input_fd_.get(), output_fd_.get(), rings_fd_.get(), submit_event_.get(), complete_event_.get()};
}

void ServiceSession::close_shared_fds() {
    input_fd_.reset();
    output_fd_.reset();
    rings_fd_.reset();
}

uint32_t ServiceSession::requested_outputs(const fgsr_submit_entry& e) const {
    return ((e.flags & FGSR_SUBMIT_WANT_SR) ? 1u : 0u) + e.interp_count + e.extrap_count;
}

std::optional<std::string> ServiceSession::validate(const fgsr_submit_entry& e) const {
    if (e.sequence <= last_sequence_)
        return "submit sequence " + std::to_string(e.sequence) + " does not increase (last " +
               std::to_string(last_sequence_) + ")";
    if (e.input_slot >= layout_.input_slot_count)
        return "submit names input slot " + std::to_string(e.input_slot) + " of " +
               std::to_string(layout_.input_slot_count);
    if (input_with_daemon_[e.input_slot])
        return "submit names input slot " + std::to_string(e.input_slot) + " the daemon still holds";
    if (e.flags & ~kKnownSubmitFlags) return "unknown submit flags " + std::to_string(e.flags);
    if ((e.flags & FGSR_SUBMIT_HAS_MV) && (desc_.flags & FGSR_SESSION_NO_MVS))
        return "submit says it has vectors in a session without vectors";
    if ((e.flags & FGSR_SUBMIT_WANT_SR) && !(desc_.modes & FGSR_MODE_SR))
        return "submit wants super resolution the session did not declare";
    if (e.interp_count > FGSR_MAX_ALPHAS || e.extrap_count > FGSR_MAX_ALPHAS)
        return "more than " + std::to_string(FGSR_MAX_ALPHAS) + " alphas";
    if (e.interp_count && !(desc_.modes & FGSR_MODE_INTERPOLATE))
        return "submit wants interpolation the session did not declare";
    if (e.extrap_count && !(desc_.modes & FGSR_MODE_EXTRAPOLATE))
        return "submit wants extrapolation the session did not declare";
    for (uint32_t i = 0; i < e.interp_count; ++i)
        if (!(std::isfinite(e.interp_alphas[i]) && e.interp_alphas[i] > 0.f && e.interp_alphas[i] < 1.f))
            return "interpolation alpha " + std::to_string(e.interp_alphas[i]) + " outside (0, 1)";
    for (uint32_t i = 0; i < e.extrap_count; ++i)
        if (!(std::isfinite(e.extrap_alphas[i]) && e.extrap_alphas[i] > 0.f && e.extrap_alphas[i] <= 1.f))
            return "extrapolation alpha " + std::to_string(e.extrap_alphas[i]) + " outside (0, 1]";
    return std::nullopt;
}

std::optional<std::string> ServiceSession::poll() {
    const uint32_t cap = layout_.ring_capacity;
    // Submits: each entry is copied out of the ring, then the copy is validated.
    std::optional<std::string> why;
    uint64_t head = 0;
    auto drained = fgsr::ipc::drain(rings_.submit, submit_tail_, head, [&](const fgsr_submit_entry& e) {
        if ((why = validate(e))) return false;
        last_sequence_ = e.sequence;
        input_with_daemon_[e.input_slot] = true;
        ++stats_.frames_submitted;
        pending_.push_back(Pending{e, monotonic_ns()});
        return true;
    });
    if (drained == fgsr::ipc::Drain::overrun)
        return "submit ring head " + std::to_string(head) + " is beyond tail " +
               std::to_string(submit_tail_) + " + capacity " + std::to_string(cap);
    if (why) return why;
    // Releases.
    drained = fgsr::ipc::drain(rings_.release, release_tail_, head, [&](const fgsr_release_entry& r) {
        if (r.output_slot >= layout_.output_slot_count || !output_taken_[r.output_slot] ||
            reserved(r.output_slot)) {
            why = "release of output slot " + std::to_string(r.output_slot) + " the client does not hold";
            return false;
        }
        output_taken_[r.output_slot] = false;
        ++free_outputs_;
        return true;
    });
    if (drained == fgsr::ipc::Drain::overrun)
        return "release ring head " + std::to_string(head) + " is beyond tail " +
               std::to_string(release_tail_) + " + capacity " + std::to_string(cap);
    if (why) return why;
    if (!completion_free()) return std::string("completion ring tail corrupted by the client");
    return std::nullopt;
}

std::optional<uint64_t> ServiceSession::completion_free() const {
    const int64_t room = rings_.completion.free_space(completion_head_);
    if (room < 0) return std::nullopt; // tail beyond head, or too far behind
    return uint64_t(room);
}

bool ServiceSession::ready() const {
    if (pending_.empty() || in_flight_) return false;
    const auto room = completion_free();
    if (!room) return true; // process_one reports the violation
    if (desc_.queue_policy == FGSR_QUEUE_MAILBOX && pending_.size() > 1) return *room >= 1;
    const uint32_t n = requested_outputs(pending_.front().entry);
    if (n > layout_.output_slot_count) return *room >= 1; // rejected with INVALID_ARGUMENT
    return free_outputs_ >= n && *room >= std::max(n, 1u);
}

bool ServiceSession::waiting_on_completion_ring() const {
    if (pending_.empty() || in_flight_) return false;
    const auto room = completion_free();
    return room && *room < std::max(requested_outputs(pending_.front().entry), 1u);
}

void ServiceSession::push_completion(const fgsr_completion_entry& c) {
    rings_.completion.push(completion_head_, c);
    if (observer_) observer_(c);
}

bool ServiceSession::signal_complete() {
    signal_pending_ = false;
    return signal_eventfd(complete_event_.get());
}

void ServiceSession::record_latency(std::vector<uint64_t>& v, uint64_t ns) {
    if (v.size() >= kLatencySamples) v.erase(v.begin(), v.begin() + kLatencySamples / 2);
    v.push_back(ns);
}

void ServiceSession::complete_without_output(const Pending& p, int32_t status) {
    fgsr_completion_entry c{};
    c.sequence = p.entry.sequence;
    c.status = status;
    c.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
    c.input_slot = p.entry.input_slot;
    c.output_slot = FGSR_NO_SLOT;
    c.user_data = p.entry.user_data;
    c.telemetry.submit_ns = p.entry.submit_time_ns;
    c.telemetry.dequeue_ns = p.dequeue_ns;
    c.telemetry.start_ns = c.telemetry.complete_ns = monotonic_ns();
    c.telemetry.queue_wait_ns = c.telemetry.start_ns - p.dequeue_ns;
    input_with_daemon_[p.entry.input_slot] = false;
    if (status == FGSR_STATUS_DROPPED)
        ++stats_.frames_dropped;
    else
        ++stats_.frames_rejected;
    push_completion(c);
    signal_pending_ = true;
}

ServiceSession::Begun ServiceSession::begin() {
    if (!completion_free()) return {std::string("completion ring tail corrupted by the client"), nullptr};
    if (!ready()) return {};
    if (desc_.queue_policy == FGSR_QUEUE_MAILBOX && pending_.size() > 1) {
        // Latest wins: everything but the newest pending submit is dropped, as ring room allows.
        while (pending_.size() > 1 && completion_free().value_or(0) >= 1) {
            const Pending p = pending_.front();
            pending_.pop_front();
            complete_without_output(p, FGSR_STATUS_DROPPED);
        }
        if (!ready()) return {};
    }
    const Pending p = pending_.front();
    pending_.pop_front();
    const uint32_t n = requested_outputs(p.entry);
    if (n > layout_.output_slot_count) {
        log::warn("session {}: submit {} wants {} outputs, the session has {} output slots", id_,
                  p.entry.sequence, n, layout_.output_slot_count);
        complete_without_output(p, FGSR_STATUS_INVALID_ARGUMENT);
        return {};
    }
    auto job = std::make_shared<FrameJob>();
    job->pending = p;
    for (uint32_t slot = 0; slot < layout_.output_slot_count && job->slots.size() < n; ++slot)
        if (!output_taken_[slot]) {
            output_taken_[slot] = true; // ready() guaranteed n free slots
            job->slots.push_back(slot);
        }
    free_outputs_ -= uint32_t(job->slots.size());
    reserved_ = job->slots;
    in_flight_ = true;
    return {std::nullopt, std::move(job)};
}

bool ServiceSession::reserved(uint32_t slot) const {
    return std::find(reserved_.begin(), reserved_.end(), slot) != reserved_.end();
}

void ServiceSession::write_output(uint32_t slot, const fgsr::ImageRGBA& image) {
    std::byte* dst = output_map_.data() + uint64_t(slot) * layout_.output_slot_stride + layout_.output.offset;
    // The session's output_format was checked at creation (a fgsr_color_format, same values).
    fgsr::encode_output(image, fgsr::ColorFormat(desc_.output_format), dst);
}

size_t ServiceSession::Spent::bytes() const {
    size_t n = sr ? sr->color.rgba.size() * sizeof(float) : 0;
    for (const auto* v : {&interp, &extrap})
        for (const fgsr::GeneratedFrame& f : *v) n += f.color.rgba.size() * sizeof(float);
    return n;
}

void ServiceSession::execute(FrameJob& job, Spent& spent) {
    const uint64_t job_start = monotonic_ns();
    struct Timed {
        FrameJob& job;
        uint64_t start;
        ~Timed() { job.engine_ns = monotonic_ns() - start; }
    } timed{job, job_start};
    const Pending& p = job.pending;
    const fgsr_submit_entry& e = p.entry;
    auto complete_without_output = [&](int32_t status) {
        fgsr_completion_entry c{};
        c.sequence = e.sequence;
        c.status = status;
        c.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
        c.input_slot = e.input_slot;
        c.output_slot = FGSR_NO_SLOT;
        c.user_data = e.user_data;
        c.telemetry.submit_ns = e.submit_time_ns;
        c.telemetry.dequeue_ns = p.dequeue_ns;
        c.telemetry.start_ns = c.telemetry.complete_ns = monotonic_ns();
        c.telemetry.queue_wait_ns = c.telemetry.start_ns - p.dequeue_ns;
        job.completions.push_back(c);
    };
    const uint64_t start_ns = monotonic_ns();
    uint64_t cpu_mark = thread_cpu_ns();

    if (!engine_session_) return complete_without_output(FGSR_STATUS_DEVICE_ERROR); // made without an engine
    const std::byte* slot = input_map_.data() + uint64_t(e.input_slot) * layout_.input_slot_stride;
    fgsr::FrameView view;
    view.color = {slot + layout_.color.offset, size_t(layout_.color.size)};
    if (layout_.depth.size) view.depth = {slot + layout_.depth.offset, size_t(layout_.depth.size)};
    if (e.flags & FGSR_SUBMIT_HAS_MV) view.mv = {slot + layout_.mv.offset, size_t(layout_.mv.size)};
    view.jitter_x = e.jitter_x;
    view.jitter_y = e.jitter_y;
    view.reset = (e.flags & FGSR_SUBMIT_RESET) != 0;
    auto submitted = import_ ? engine_session_->submit(view, *import_) : engine_session_->submit(view);
    if (!submitted) {
        log::info("session {}: frame {} rejected: {}", id_, e.sequence, submitted.error().message);
        return complete_without_output(submitted.error().code == fgsr::Errc::vulkan ? FGSR_STATUS_DEVICE_ERROR
                                                                                    : FGSR_STATUS_BAD_FRAME);
    }
    if (!import_) job.bytes_copied = view.color.size() + view.depth.size() + view.mv.size();
    const fgsr::PassTiming ingest = engine_session_->last_ingest_timing();
    // Colour-only sessions: the motion passes of this submit (luma, match, flow) belong to every
    // output made from it, as ingest does.
    const std::vector<fgsr::PassTiming> motion = engine_session_->last_motion_timings();
    if (view.reset) previous_present_ns_ = 0;

    // Every requested output in presentation order: interpolated, upscaled, extrapolated.
    std::vector<Output> outputs;
    std::optional<fgsr::GeneratedFrame>& sr = spent.sr;
    std::vector<fgsr::GeneratedFrame>&interp = spent.interp, &extrap = spent.extrap;
    int32_t interp_status = FGSR_STATUS_OK, extrap_status = FGSR_STATUS_OK, sr_status = FGSR_STATUS_OK;
    if (e.flags & FGSR_SUBMIT_WANT_SR) {
        auto r = engine_session_->super_resolved();
        if (r)
            sr = std::move(*r);
        else {
            sr_status = FGSR_STATUS_DEVICE_ERROR;
            log::error("session {}: frame {}: {}", id_, e.sequence, r.error().message);
        }
    }
    const bool two_frames = engine_session_->frames_submitted() >= 2;
    auto generate = [&](bool extrapolate, uint32_t count, const float* alphas,
                        std::vector<fgsr::GeneratedFrame>& out, int32_t& st) {
        if (count == 0) return;
        if (!two_frames) {
            st = FGSR_STATUS_NOT_READY;
            log::info("session {}: frame {}: {} not ready: needs two submitted frames since the start or the "
                      "last reset",
                      id_, e.sequence, extrapolate ? "extrapolation" : "interpolation");
        } else {
            auto r = extrapolate ? engine_session_->extrapolate({alphas, count})
                                 : engine_session_->interpolate({alphas, count});
            if (r)
                out = std::move(*r);
            else {
                st = FGSR_STATUS_DEVICE_ERROR;
                log::error("session {}: frame {}: {}", id_, e.sequence, r.error().message);
            }
        }
    };
    generate(false, e.interp_count, e.interp_alphas, interp, interp_status);
    generate(true, e.extrap_count, e.extrap_alphas, extrap, extrap_status);
    for (uint32_t i = 0; i < e.interp_count; ++i)
        outputs.push_back({interp_status, FGSR_FRAME_INTERPOLATED, e.interp_alphas[i],
                           interp_status == FGSR_STATUS_OK ? &interp[i] : nullptr});
    if (e.flags & FGSR_SUBMIT_WANT_SR)
        outputs.push_back({sr_status, FGSR_FRAME_UPSCALED, 1.f, sr ? &*sr : nullptr});
    for (uint32_t i = 0; i < e.extrap_count; ++i)
        outputs.push_back({extrap_status, FGSR_FRAME_EXTRAPOLATED, 1.f + e.extrap_alphas[i],
                           extrap_status == FGSR_STATUS_OK ? &extrap[i] : nullptr});

    // A submit without requested outputs still gets one completion (its input slot back).
    if (outputs.empty()) outputs.push_back({FGSR_STATUS_OK, FGSR_FRAME_NONE, 1.f, nullptr});

    const uint64_t cur_present = e.present_time_ns;
    const uint64_t prev_present = previous_present_ns_;
    size_t written = 0;
    for (size_t k = 0; k < outputs.size(); ++k) {
        const Output& o = outputs[k];
        fgsr_completion_entry c{};
        c.sequence = e.sequence;
        c.status = o.status;
        c.input_slot = e.input_slot;
        c.output_slot = FGSR_NO_SLOT;
        c.output_index = uint32_t(k);
        c.user_data = e.user_data;
        fgsr_telemetry& t = c.telemetry;
        t.frame_type = o.frame_type;
        t.target_time = o.target_time;
        if (cur_present && o.frame_type == FGSR_FRAME_UPSCALED) t.target_present_ns = cur_present;
        if (cur_present && prev_present && cur_present > prev_present &&
            o.frame_type != FGSR_FRAME_UPSCALED && o.frame_type != FGSR_FRAME_NONE)
            t.target_present_ns =
                prev_present + uint64_t(double(cur_present - prev_present) * double(o.target_time));
        t.submit_ns = e.submit_time_ns;
        t.dequeue_ns = p.dequeue_ns;
        t.start_ns = start_ns;
        t.queue_wait_ns = start_ns - p.dequeue_ns;
        // Passes: this frame's ingest and motion estimation, then the output's own passes. A pass
        // that runs more than once for the output (colour_agree generates from two fields) gets one
        // record summing its runs (fgsr_pass_record.runs), so that every pass fits.
        auto add_pass = [&](const fgsr::PassTiming& pt) {
            t.gpu_ns += uint64_t(std::llround(pt.ms * 1e6));
            const uint32_t id = uint32_t(pt.pass);
            for (uint32_t i = 0; i < t.pass_count; ++i) {
                fgsr_pass_record& r = t.passes[i];
                if (r.pass != id) continue;
                r.gpu_end_ns += pt.end_ns > pt.begin_ns ? pt.end_ns - pt.begin_ns : 0;
                r.tiles_total += pt.tiles_total;
                r.tiles_skipped += pt.tiles_skipped;
                ++r.runs;
                return;
            }
            if (t.pass_count >= FGSR_MAX_PASSES) return;
            fgsr_pass_record& r = t.passes[t.pass_count++];
            r.pass = id;
            r.runs = 1;
            r.gpu_begin_ns = pt.begin_ns;
            r.gpu_end_ns = pt.end_ns > pt.begin_ns ? pt.end_ns : pt.begin_ns;
            r.tiles_total = pt.tiles_total;
            r.tiles_skipped = pt.tiles_skipped;
        };
        add_pass(ingest);
        for (const fgsr::PassTiming& pt : motion) add_pass(pt);
        if (o.status == FGSR_STATUS_OK && o.frame) {
            for (const fgsr::PassTiming& pt : o.frame->passes) add_pass(pt);
            const uint32_t out_slot = job.slots[written++]; // begin() reserved one per output
            write_output(out_slot, o.frame->color);
            c.output_slot = out_slot;
        }
        if (o.status != FGSR_STATUS_OK) {
            t.skipped_passes = o.frame_type == FGSR_FRAME_UPSCALED
                                   ? (1u << FGSR_PASS_SR)
                                   : (1u << FGSR_PASS_SPLAT) | (1u << FGSR_PASS_GENERATE);
        } else {
            // A pass that skipped every tile (e.g. splat of a frame without motion) did no work.
            for (uint32_t i = 0; i < t.pass_count; ++i) {
                const fgsr_pass_record& r = t.passes[i];
                if (r.tiles_total > 0 && r.tiles_skipped >= r.tiles_total && r.pass < 32)
                    t.skipped_passes |= 1u << r.pass;
            }
        }
        if (k + 1 == outputs.size()) c.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
        const uint64_t cpu_now = thread_cpu_ns();
        t.daemon_cpu_ns = cpu_now - cpu_mark;
        cpu_mark = cpu_now;
        t.complete_ns = monotonic_ns();
        job.completions.push_back(c);
    }
    previous_present_ns_ = cur_present;
}

std::optional<std::string> ServiceSession::finish(FrameJob& job) {
    in_flight_ = false;
    reserved_.clear();
    engine_ns_ += job.engine_ns;
    stats_.bytes_copied += job.bytes_copied;
    const Pending& p = job.pending;
    // Slots reserved for outputs that were not written (an error, or NOT_READY) go back.
    std::array<bool, FGSR_MAX_SLOTS> used{};
    for (const fgsr_completion_entry& c : job.completions)
        if (c.output_slot != FGSR_NO_SLOT) used[c.output_slot] = true;
    for (uint32_t slot : job.slots)
        if (!used[slot]) {
            output_taken_[slot] = false;
            ++free_outputs_;
        }
    input_with_daemon_[p.entry.input_slot] = false;
    // The client may only have made room in the ring since begin() checked it, or corrupted it.
    const auto room = completion_free();
    if (!room) return std::string("completion ring tail corrupted by the client");
    if (*room < job.completions.size()) return std::string("completion ring shrank while a frame ran");
    for (fgsr_completion_entry& c : job.completions) {
        fgsr_telemetry& t = c.telemetry;
        if (c.output_slot != FGSR_NO_SLOT) {
            ++stats_.outputs_written;
            record_latency(gpu_, t.gpu_ns);
        }
        if (c.status != FGSR_STATUS_OK && t.frame_type == FGSR_FRAME_NONE) {
            if (c.status == FGSR_STATUS_DROPPED)
                ++stats_.frames_dropped;
            else
                ++stats_.frames_rejected;
        }
        t.complete_ns = monotonic_ns();
        const uint64_t from = (p.entry.submit_time_ns && p.entry.submit_time_ns <= t.complete_ns)
                                  ? p.entry.submit_time_ns
                                  : p.dequeue_ns;
        record_latency(latency_, t.complete_ns - from);
        record_latency(queue_wait_, t.queue_wait_ns);
        push_completion(c);
    }
    signal_pending_ = true;
    return std::nullopt;
}

fgsr_session_stats ServiceSession::stats() const {
    fgsr_session_stats s = stats_;
    s.latency_p50_ns = percentile(latency_, 0.50);
    s.latency_p99_ns = percentile(latency_, 0.99);
    s.gpu_p50_ns = percentile(gpu_, 0.50);
    s.gpu_p99_ns = percentile(gpu_, 0.99);
    s.queue_wait_p50_ns = percentile(queue_wait_, 0.50);
    s.queue_wait_p99_ns = percentile(queue_wait_, 0.99);
    return s;
}

} // namespace fgsrd
