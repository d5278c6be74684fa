// fgsrd --http ADDR:PORT: the telemetry dashboard and its feeds, read-only (docs/TELEMETRY.md).
//   /             the live page (daemon/fgsrd/http/dashboard.html), /chart.min.js (Debian's Chart.js)
//   /events       server-sent events: "state" (the page's State object; the first one carries the
//                 window's frames), then "frames" (new records, every 250 ms) and "state" each second
//   /api/state    the State object with the window's frames (JSON)
//   /metrics      Prometheus text format
//   /trace.json   Chrome trace of the last --http-trace-seconds (?seconds=N to choose)
// Only GET and HEAD are served (anything else: 405), so nothing served can change the daemon.
// Loopback addresses only, unless allow_remote. The server's threads run at a lower CPU priority
// than the daemon's, and event streams are limited in number; a client that stops reading its
// stream is dropped after the write timeout, so neither page loads nor stalled readers hold up
// frames.
#pragma once

#include "telemetry_hub.hpp"

#include <fgsr/core/result.hpp>

#include <memory>
#include <string>

namespace fgsrd {

struct HttpOptions {
    std::string address; // "HOST:PORT" ([v6]:PORT); port 0 picks a free one
    bool allow_remote = false;
    double trace_seconds = 10;
    size_t max_streams = 100; // concurrent /events streams (more: 503)
    int nice = 5;             // added to the HTTP threads' nice value
};

// Splits "HOST:PORT" and checks that HOST is a loopback address unless allow_remote; errors say
// what to change.
struct HttpEndpoint {
    std::string host;
    int port = 0;
};
fgsr::Result<HttpEndpoint> parse_http_address(const std::string& address, bool allow_remote);

class HttpServer {
  public:
    // Binds and starts serving on its own threads; the hub must outlive the server.
    static fgsr::Result<std::unique_ptr<HttpServer>> start(const HttpOptions& options, TelemetryHub& hub);
    ~HttpServer(); // stops and joins
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;
    int port() const;
    std::string url() const;

  private:
    HttpServer() = default;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fgsrd
