#include "messages.hpp"

#include <cstring>
#include <optional>

namespace fgsrd {

Request parse_request(const std::byte* data, size_t size, bool hello_done) {
    fgsr_msg_header h{};
    if (size < sizeof(h))
        return Violation{0, "message of " + std::to_string(size) + " bytes is shorter than a header"};
    std::memcpy(&h, data, sizeof(h));
    if (h.magic != FGSR_PROTOCOL_MAGIC) return Violation{h.sequence, "bad magic"};
    if (h.size != size)
        return Violation{h.sequence, "header size " + std::to_string(h.size) + " but the packet has " +
                                         std::to_string(size) + " bytes"};
    auto truncated = [&](size_t need) {
        return Violation{h.sequence, "message type " + std::to_string(h.type) + " truncated to " +
                                         std::to_string(size) + " bytes (needs " + std::to_string(need) +
                                         ")"};
    };
    // Messages of a head (`head` bytes, the entry count at `count_at`) and 1..max entries of
    // `entry` bytes: the count is checked against the packet, the entries copied to dst.
    auto counted = [&](size_t head, size_t count_at, uint32_t max, size_t entry, const char* what,
                       uint32_t& count, void* dst) -> std::optional<Violation> {
        if (size < head + entry) return truncated(head + entry);
        std::memcpy(&count, data + count_at, sizeof(count));
        if (count == 0 || count > max)
            return Violation{h.sequence, std::string(what) + " " + std::to_string(count) + " is not 1.." +
                                             std::to_string(max)};
        if (size < head + entry * count) return truncated(head + entry * count);
        std::memcpy(dst, data + head, entry * count);
        return std::nullopt;
    };
    if (!hello_done && h.type != FGSR_MSG_HELLO)
        return Violation{h.sequence, "the first message must be HELLO"};
    switch (h.type) {
    case FGSR_MSG_HELLO: {
        if (hello_done) return Violation{h.sequence, "second HELLO"};
        if (size < sizeof(fgsr_hello)) return truncated(sizeof(fgsr_hello));
        HelloRequest r;
        std::memcpy(&r.hello, data, sizeof(r.hello));
        r.hello.name[sizeof(r.hello.name) - 1] = 0;
        return r;
    }
    case FGSR_MSG_CREATE_SESSION: {
        if (size < sizeof(fgsr_create_session)) return truncated(sizeof(fgsr_create_session));
        CreateRequest r;
        r.sequence = h.sequence;
        std::memcpy(&r.desc, data + sizeof(fgsr_msg_header), sizeof(r.desc));
        if (r.desc.struct_size < sizeof(fgsr_session_desc) ||
            r.desc.struct_size > size - sizeof(fgsr_msg_header))
            return Violation{h.sequence, "session description struct_size " +
                                             std::to_string(r.desc.struct_size) +
                                             " does not match the message"};
        return r;
    }
    case FGSR_MSG_DESTROY_SESSION:
    case FGSR_MSG_STATS: {
        if (size < sizeof(fgsr_session_ref)) return truncated(sizeof(fgsr_session_ref));
        SessionRequest r;
        r.type = h.type;
        std::memcpy(&r.ref, data, sizeof(r.ref));
        return r;
    }
    case FGSR_MSG_REPORT: {
        ReportRequest r;
        if (auto v = counted(FGSR_REPORT_MESSAGE_SIZE(0), sizeof(fgsr_msg_header) + 4, FGSR_MAX_REPORTS_PER_MESSAGE,
                             sizeof(fgsr_present_report), "report count", r.count, r.reports))
            return *v;
        std::memcpy(&r.session_id, data + sizeof(fgsr_msg_header), sizeof(r.session_id));
        return r;
    }
    case FGSR_MSG_PROBE: {
        ProbeRequest r;
        if (auto v = counted(FGSR_PROBE_MESSAGE_SIZE(0), sizeof(fgsr_msg_header), FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE,
                             sizeof(fgsr_probe_sample), "probe sample count", r.count, r.samples))
            return *v;
        return r;
    }
    default:
        return Violation{h.sequence, "unknown message type " + std::to_string(h.type)};
    }
}

} // namespace fgsrd
