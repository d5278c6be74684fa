// Fuzz target: fgsrd's control-message handler front end (daemon/fgsrd/messages.cpp), the code
// that reads every packet a client sends, before and after HELLO. Checks what the parser promises:
// an accepted request came from a packet at least as long as its struct whose header agrees with
// the packet; a HELLO name is NUL-terminated; a session description's struct_size lies within the
// packet; a report or probe message holds 1..max entries, all within the packet; every violation
// names a reason.
#include "fuzz_support.hpp"

#include "messages.hpp"

#include <cstring>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // A heap copy of exactly `size` bytes: ASan sees any read past the packet.
    std::vector<std::byte> packet(size);
    if (size) std::memcpy(packet.data(), data, size);
    for (const bool hello_done : {false, true}) {
        const fgsrd::Request r = fgsrd::parse_request(packet.data(), size, hello_done);
        if (const auto* v = std::get_if<fgsrd::Violation>(&r)) {
            FGSR_FUZZ_CHECK(!v->reason.empty());
            continue;
        }
        FGSR_FUZZ_CHECK(size >= sizeof(fgsr_msg_header));
        fgsr_msg_header h;
        std::memcpy(&h, packet.data(), sizeof(h));
        FGSR_FUZZ_CHECK(h.magic == FGSR_PROTOCOL_MAGIC && h.size == size);
        if (const auto* hello = std::get_if<fgsrd::HelloRequest>(&r)) {
            FGSR_FUZZ_CHECK(!hello_done && size >= sizeof(fgsr_hello));
            FGSR_FUZZ_CHECK(std::memchr(hello->hello.name, 0, sizeof(hello->hello.name)) != nullptr);
        } else if (const auto* create = std::get_if<fgsrd::CreateRequest>(&r)) {
            FGSR_FUZZ_CHECK(hello_done && size >= sizeof(fgsr_create_session));
            FGSR_FUZZ_CHECK(create->desc.struct_size >= sizeof(fgsr_session_desc));
            FGSR_FUZZ_CHECK(create->desc.struct_size <= size - sizeof(fgsr_msg_header));
        } else if (const auto* report = std::get_if<fgsrd::ReportRequest>(&r)) {
            FGSR_FUZZ_CHECK(hello_done && report->count >= 1 && report->count <= FGSR_MAX_REPORTS_PER_MESSAGE);
            FGSR_FUZZ_CHECK(size >= FGSR_REPORT_MESSAGE_SIZE(report->count));
        } else if (const auto* probe = std::get_if<fgsrd::ProbeRequest>(&r)) {
            FGSR_FUZZ_CHECK(hello_done && probe->count >= 1 && probe->count <= FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE);
            FGSR_FUZZ_CHECK(size >= FGSR_PROBE_MESSAGE_SIZE(probe->count));
        } else {
            const auto& ref = std::get<fgsrd::SessionRequest>(r);
            FGSR_FUZZ_CHECK(hello_done && size >= sizeof(fgsr_session_ref));
            FGSR_FUZZ_CHECK(ref.type == FGSR_MSG_STATS || ref.type == FGSR_MSG_DESTROY_SESSION);
        }
    }
    return 0;
}
