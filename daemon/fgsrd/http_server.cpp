#include "http_server.hpp"

#include "http/assets.hpp"
#include "log.hpp"

#include <httplib.h>

#include <arpa/inet.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace fgsrd {

using fgsr::Errc;
using fgsr::make_error;

namespace {

// JSON as text; invalid UTF-8 (an executable's name can hold anything) is replaced, never thrown.
std::string dump(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// httplib's worker threads, each at a lower CPU priority than the daemon's: the dashboard gets
// what the frames leave.
class NicePool : public httplib::TaskQueue {
  public:
    NicePool(size_t n, int nice) {
        for (size_t i = 0; i < n; ++i)
            threads_.emplace_back([this, nice] {
                const id_t tid = id_t(gettid());
                errno = 0;
                const int now = getpriority(PRIO_PROCESS, tid);
                if (errno == 0) (void)setpriority(PRIO_PROCESS, tid, std::min(19, now + nice));
                work();
            });
    }
    ~NicePool() override { shutdown(); }
    void enqueue(std::function<void()> fn) override {
        {
            std::lock_guard lock(mutex_);
            jobs_.push_back(std::move(fn));
        }
        cv_.notify_one();
    }
    void shutdown() override {
        {
            std::lock_guard lock(mutex_);
            if (stop_) return;
            stop_ = true;
        }
        cv_.notify_all();
        for (std::thread& t : threads_) t.join();
    }

  private:
    void work() {
        for (;;) {
            std::function<void()> fn;
            {
                std::unique_lock lock(mutex_);
                cv_.wait(lock, [&] { return stop_ || !jobs_.empty(); });
                if (jobs_.empty()) return; // stopping and nothing left
                fn = std::move(jobs_.front());
                jobs_.pop_front();
            }
            fn();
        }
    }
    std::vector<std::thread> threads_;
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<std::function<void()>> jobs_;
    bool stop_ = false;
};

bool is_loopback(const std::string& host) {
    if (host == "localhost") return true;
    in_addr a4{};
    if (inet_pton(AF_INET, host.c_str(), &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
    in6_addr a6{};
    if (inet_pton(AF_INET6, host.c_str(), &a6) == 1) return IN6_IS_ADDR_LOOPBACK(&a6);
    return false;
}

} // namespace

fgsr::Result<HttpEndpoint> parse_http_address(const std::string& address, bool allow_remote) {
    HttpEndpoint ep;
    std::string port;
    if (!address.empty() && address.front() == '[') { // [v6]:port
        const size_t close = address.find(']');
        if (close == std::string::npos || close + 1 >= address.size() || address[close + 1] != ':')
            return make_error(Errc::invalid_argument, "--http " + address + ": expected [ADDRESS]:PORT");
        ep.host = address.substr(1, close - 1);
        port = address.substr(close + 2);
    } else {
        const size_t colon = address.rfind(':');
        if (colon == std::string::npos || colon == 0 || address.find(':') != colon)
            return make_error(Errc::invalid_argument,
                              "--http " + address + ": expected ADDRESS:PORT (e.g. 127.0.0.1:8080; [::1]:8080)");
        ep.host = address.substr(0, colon);
        port = address.substr(colon + 1);
    }
    char* end = nullptr;
    const long p = std::strtol(port.c_str(), &end, 10);
    if (port.empty() || !end || *end != '\0' || p < 0 || p > 65535)
        return make_error(Errc::invalid_argument, "--http " + address + ": port '" + port + "' is not 0-65535");
    ep.port = int(p);
    if (!allow_remote && !is_loopback(ep.host))
        return make_error(Errc::invalid_argument,
                          "--http " + address + ": " + ep.host +
                              " is not a loopback address; the dashboard serves this machine only unless "
                              "--http-allow-remote is given");
    return ep;
}

struct HttpServer::Impl {
    HttpOptions opt;
    TelemetryHub* hub = nullptr;
    httplib::Server svr;
    std::thread thread;
    int port = 0;
    std::string host;
    std::atomic<bool> stopping{false};
    std::atomic<size_t> streams{0};

    void routes();
    // One server-sent event stream (the page's live feed).
    void events(httplib::Response& res);
};

void HttpServer::Impl::routes() {
    // Read-only: GET and HEAD, nothing else.
    svr.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
        if (req.method == "GET" || req.method == "HEAD") return httplib::Server::HandlerResponse::Unhandled;
        res.status = 405;
        res.set_header("Allow", "GET, HEAD");
        res.set_content("fgsrd's dashboard is read-only\n", "text/plain");
        return httplib::Server::HandlerResponse::Handled;
    });
    svr.Get("/", [](const httplib::Request&, httplib::Response& res) {
        const std::string_view page = fgsr::dashboard::page();
        res.set_content(page.data(), page.size(), "text/html; charset=utf-8");
    });
    svr.Get("/chart.min.js", [](const httplib::Request&, httplib::Response& res) {
        const std::string_view js = fgsr::dashboard::chart_js();
        res.set_header("Cache-Control", "max-age=3600");
        res.set_content(js.data(), js.size(), "text/javascript; charset=utf-8");
    });
    svr.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
        res.set_content(dump(hub->state(true)), "application/json");
    });
    svr.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
        res.set_content(hub->metrics_text(), "text/plain; version=0.0.4; charset=utf-8");
    });
    svr.Get("/trace.json", [this](const httplib::Request& req, httplib::Response& res) {
        double seconds = opt.trace_seconds;
        if (req.has_param("seconds")) {
            const std::string v = req.get_param_value("seconds");
            char* end = nullptr;
            seconds = std::strtod(v.c_str(), &end);
            if (v.empty() || !end || *end != '\0' || !(seconds > 0) || seconds > 3600) {
                res.status = 400;
                res.set_content("seconds: a number in (0, 3600]\n", "text/plain");
                return;
            }
        }
        res.set_content(dump(hub->trace(seconds)), "application/json");
    });
    svr.Get("/events", [this](const httplib::Request&, httplib::Response& res) { events(res); });
}

void HttpServer::Impl::events(httplib::Response& res) {
    if (streams.fetch_add(1) >= opt.max_streams) {
        streams.fetch_sub(1);
        res.status = 503;
        res.set_header("Retry-After", "5");
        res.set_content("too many event streams\n", "text/plain");
        return;
    }
    struct Stream {
        bool first = true;
        uint64_t cursor = 0;
        std::chrono::steady_clock::time_point last_state{};
    };
    auto st = std::make_shared<Stream>();
    res.set_header("Cache-Control", "no-cache");
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, st](size_t, httplib::DataSink& sink) {
            auto send = [&](const char* event, const nlohmann::json& data) {
                const std::string msg = std::string("event: ") + event + "\ndata: " + dump(data) + "\n\n";
                return sink.write(msg.data(), msg.size());
            };
            if (stopping.load()) {
                sink.done();
                return true;
            }
            const auto now = std::chrono::steady_clock::now();
            if (st->first) {
                st->first = false;
                st->last_state = now;
                static const char kRetry[] = "retry: 1000\n\n"; // reconnect after 1 s (browsers wait 3 s)
                if (!sink.write(kRetry, sizeof(kRetry) - 1)) return false;
                return send("state", hub->state(true, &st->cursor));
            }
            // A batch every 250 ms: few events per second whatever the frame rate.
            std::this_thread::sleep_for(std::chrono::milliseconds(250));
            if (stopping.load()) {
                sink.done();
                return true;
            }
            if (hub->cursor() > st->cursor && !send("frames", hub->frames_since(st->cursor))) return false;
            if (std::chrono::steady_clock::now() - st->last_state >= std::chrono::seconds(1)) {
                st->last_state = std::chrono::steady_clock::now();
                if (!send("state", hub->state(false))) return false;
            }
            return true;
        },
        [this](bool) { streams.fetch_sub(1); });
}

fgsr::Result<std::unique_ptr<HttpServer>> HttpServer::start(const HttpOptions& options, TelemetryHub& hub) {
    auto ep = parse_http_address(options.address, options.allow_remote);
    if (!ep) return ep.error();
    std::unique_ptr<HttpServer> s(new HttpServer());
    s->impl_ = std::make_unique<Impl>();
    Impl& m = *s->impl_;
    m.opt = options;
    m.hub = &hub;
    m.host = ep->host;
    const size_t threads = options.max_streams + 32; // streams hold a thread each; page loads need the rest
    const int nice = options.nice;
    m.svr.new_task_queue = [threads, nice] { return new NicePool(threads, nice); };
    m.svr.set_write_timeout(2, 0); // a reader that stops reading is dropped after this
    m.svr.set_read_timeout(5, 0);
    m.svr.set_keep_alive_timeout(2);
    m.routes();
    errno = 0;
    m.port = ep->port == 0 ? m.svr.bind_to_any_port(ep->host) : (m.svr.bind_to_port(ep->host, ep->port) ? ep->port : -1);
    if (m.port <= 0)
        return make_error(Errc::io, "--http " + options.address + ": cannot listen there" +
                                        (errno ? std::string(" (") + std::strerror(errno) + ")" : std::string()));
    m.thread = std::thread([&m] { m.svr.listen_after_bind(); });
    return s;
}

HttpServer::~HttpServer() {
    if (!impl_) return;
    impl_->stopping = true;
    impl_->svr.stop();
    if (impl_->thread.joinable()) impl_->thread.join();
}

int HttpServer::port() const {
    return impl_->port;
}

std::string HttpServer::url() const {
    const bool v6 = impl_->host.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + impl_->host + "]" : impl_->host) + ":" + std::to_string(impl_->port) + "/";
}

} // namespace fgsrd
