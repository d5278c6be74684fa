// Control messages from a client, parsed and checked before the server acts on them: a pure
// function of the packet's bytes and whether HELLO was said, so that it can be fuzzed
// (tests/fuzz) and tested without a socket.
#pragma once

#include <fgsr/wire.h>

#include <cstddef>
#include <string>
#include <variant>

namespace fgsrd {

struct Violation {
    uint32_t sequence = 0;
    std::string reason;
};
struct HelloRequest {
    fgsr_hello hello; // name NUL-terminated
};
struct CreateRequest {
    uint32_t sequence = 0;
    fgsr_session_desc desc; // struct_size checked against the packet; not yet normalised
};
struct SessionRequest {
    uint16_t type = 0; // FGSR_MSG_DESTROY_SESSION or FGSR_MSG_STATS
    fgsr_session_ref ref;
};
struct ReportRequest {
    uint32_t session_id = 0;
    uint32_t count = 0;              // 1..FGSR_MAX_REPORTS_PER_MESSAGE, checked against the packet
    fgsr_present_report reports[FGSR_MAX_REPORTS_PER_MESSAGE]; // values unchecked (the hub checks)
};
struct ProbeRequest {
    uint32_t count = 0; // 1..FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE, checked against the packet
    fgsr_probe_sample samples[FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE]; // values unchecked (the hub checks)
};
using Request = std::variant<Violation, HelloRequest, CreateRequest, SessionRequest, ReportRequest, ProbeRequest>;

// Every check of the wire format (daemon/fgsrd/README.md, "Protocol violations"): header size,
// magic, header.size against the packet, truncation per type, HELLO first and once, known types,
// desc.struct_size within the packet. Longer packets of a known type are accepted.
Request parse_request(const std::byte* data, size_t size, bool hello_done);

} // namespace fgsrd
