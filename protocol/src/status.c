/* fgsr_status_string and fgsr_pass_name: the one table of status descriptions; the pass
 * names come from the pass table (fgsr/passes.h). */
#include <fgsr/protocol.h>

const char* fgsr_status_string(int32_t status) {
    switch ((fgsr_status)status) {
    case FGSR_STATUS_OK: return "ok";
    case FGSR_STATUS_INVALID_ARGUMENT: return "invalid argument";
    case FGSR_STATUS_DAEMON_UNAVAILABLE: return "fgsrd is not running (no daemon on the socket)";
    case FGSR_STATUS_DISCONNECTED: return "disconnected from fgsrd";
    case FGSR_STATUS_VERSION_MISMATCH: return "fgsrd speaks another major protocol version";
    case FGSR_STATUS_PROTOCOL_ERROR: return "protocol error (malformed message or ring entry)";
    case FGSR_STATUS_PERMISSION_DENIED: return "permission denied";
    case FGSR_STATUS_OUT_OF_MEMORY: return "out of memory";
    case FGSR_STATUS_UNSUPPORTED: return "unsupported format, mode or scale";
    case FGSR_STATUS_BAD_FRAME: return "frame rejected";
    case FGSR_STATUS_NO_SLOT: return "no free slot";
    case FGSR_STATUS_TIMEOUT: return "timed out";
    case FGSR_STATUS_DROPPED: return "dropped (superseded by a newer frame)";
    case FGSR_STATUS_NOT_READY: return "not ready (needs an earlier frame)";
    case FGSR_STATUS_DEVICE_ERROR: return "device error";
    case FGSR_STATUS_BUSY: return "busy (too many sessions or clients)";
    case FGSR_STATUS_INTERNAL: return "internal error";
    case FGSR_STATUS_COUNT_: break;
    }
    return "unknown status";
}

const char* fgsr_pass_name(uint32_t pass) {
    switch ((fgsr_pass_id)pass) {
#define FGSR_PASS_NAME_(ID, name, value) case FGSR_PASS_##ID: return #name;
    FGSR_PASSES(FGSR_PASS_NAME_)
#undef FGSR_PASS_NAME_
    case FGSR_PASS_COUNT_: break;
    }
    return "unknown";
}
