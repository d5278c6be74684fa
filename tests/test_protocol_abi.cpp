// Pins the ABI of fgsr/protocol.h: struct sizes and alignments, the offset and size of every field,
// every enum and #define value, and fgsr_status_string for every status. A failure here means the
// wire or shared-memory layout changed: bump FGSR_PROTOCOL_MAJOR (incompatible) or add fields only at
// the end (minor), then update these numbers on purpose.
#include <fgsr/protocol.h>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <string>

namespace {

#define FGSR_FIELD(T, f, off, size)                                                                          \
    EXPECT_EQ(offsetof(T, f), size_t(off)) << #T "." #f;                                                     \
    EXPECT_EQ(sizeof(T::f), size_t(size)) << #T "." #f

TEST(ProtocolAbi, Layout_fgsr_msg_header) {
    EXPECT_EQ(sizeof(fgsr_msg_header), size_t(16));
    EXPECT_EQ(alignof(fgsr_msg_header), size_t(4));
    FGSR_FIELD(fgsr_msg_header, magic, 0, 4);
    FGSR_FIELD(fgsr_msg_header, type, 4, 2);
    FGSR_FIELD(fgsr_msg_header, reserved, 6, 2);
    FGSR_FIELD(fgsr_msg_header, size, 8, 4);
    FGSR_FIELD(fgsr_msg_header, sequence, 12, 4);
}

TEST(ProtocolAbi, Layout_fgsr_hello) {
    EXPECT_EQ(sizeof(fgsr_hello), size_t(64));
    EXPECT_EQ(alignof(fgsr_hello), size_t(4));
    FGSR_FIELD(fgsr_hello, header, 0, 16);
    FGSR_FIELD(fgsr_hello, major, 16, 2);
    FGSR_FIELD(fgsr_hello, minor, 18, 2);
    FGSR_FIELD(fgsr_hello, capabilities, 20, 4);
    FGSR_FIELD(fgsr_hello, pid, 24, 4);
    FGSR_FIELD(fgsr_hello, reserved, 28, 4);
    FGSR_FIELD(fgsr_hello, name, 32, 32);
}

TEST(ProtocolAbi, Layout_fgsr_hello_reply) {
    EXPECT_EQ(sizeof(fgsr_hello_reply), size_t(104));
    EXPECT_EQ(alignof(fgsr_hello_reply), size_t(8));
    FGSR_FIELD(fgsr_hello_reply, header, 0, 16);
    FGSR_FIELD(fgsr_hello_reply, status, 16, 4);
    FGSR_FIELD(fgsr_hello_reply, major, 20, 2);
    FGSR_FIELD(fgsr_hello_reply, minor, 22, 2);
    FGSR_FIELD(fgsr_hello_reply, capabilities, 24, 4);
    FGSR_FIELD(fgsr_hello_reply, reserved, 28, 4);
    FGSR_FIELD(fgsr_hello_reply, epoch, 32, 8);
    FGSR_FIELD(fgsr_hello_reply, device, 40, 64);
}

TEST(ProtocolAbi, Layout_fgsr_session_desc) {
    EXPECT_EQ(sizeof(fgsr_session_desc), size_t(128));
    EXPECT_EQ(alignof(fgsr_session_desc), size_t(4));
    FGSR_FIELD(fgsr_session_desc, struct_size, 0, 4);
    FGSR_FIELD(fgsr_session_desc, width, 4, 4);
    FGSR_FIELD(fgsr_session_desc, height, 8, 4);
    FGSR_FIELD(fgsr_session_desc, color_format, 12, 4);
    FGSR_FIELD(fgsr_session_desc, mv_format, 16, 4);
    FGSR_FIELD(fgsr_session_desc, depth_kind, 20, 4);
    FGSR_FIELD(fgsr_session_desc, mv_units, 24, 4);
    FGSR_FIELD(fgsr_session_desc, mv_direction, 28, 4);
    FGSR_FIELD(fgsr_session_desc, near_plane, 32, 4);
    FGSR_FIELD(fgsr_session_desc, far_plane, 36, 4);
    FGSR_FIELD(fgsr_session_desc, scale, 40, 4);
    FGSR_FIELD(fgsr_session_desc, modes, 44, 4);
    FGSR_FIELD(fgsr_session_desc, flags, 48, 4);
    FGSR_FIELD(fgsr_session_desc, queue_policy, 52, 4);
    FGSR_FIELD(fgsr_session_desc, input_slots, 56, 4);
    FGSR_FIELD(fgsr_session_desc, output_slots, 60, 4);
    FGSR_FIELD(fgsr_session_desc, output_format, 64, 4);
    FGSR_FIELD(fgsr_session_desc, ring_capacity, 68, 4);
    FGSR_FIELD(fgsr_session_desc, t_depth, 72, 4);
    FGSR_FIELD(fgsr_session_desc, t_bright, 76, 4);
    FGSR_FIELD(fgsr_session_desc, sr_a, 80, 4);
    FGSR_FIELD(fgsr_session_desc, sr_b, 84, 4);
    FGSR_FIELD(fgsr_session_desc, reserved, 88, 40);
}

TEST(ProtocolAbi, Layout_fgsr_create_session) {
    EXPECT_EQ(sizeof(fgsr_create_session), size_t(144));
    EXPECT_EQ(alignof(fgsr_create_session), size_t(4));
    FGSR_FIELD(fgsr_create_session, header, 0, 16);
    FGSR_FIELD(fgsr_create_session, desc, 16, 128);
}

TEST(ProtocolAbi, Layout_fgsr_plane) {
    EXPECT_EQ(sizeof(fgsr_plane), size_t(24));
    EXPECT_EQ(alignof(fgsr_plane), size_t(8));
    FGSR_FIELD(fgsr_plane, offset, 0, 8);
    FGSR_FIELD(fgsr_plane, size, 8, 8);
    FGSR_FIELD(fgsr_plane, row_pitch, 16, 4);
    FGSR_FIELD(fgsr_plane, format, 20, 4);
}

TEST(ProtocolAbi, Layout_fgsr_pool_layout) {
    EXPECT_EQ(sizeof(fgsr_pool_layout), size_t(160));
    EXPECT_EQ(alignof(fgsr_pool_layout), size_t(8));
    FGSR_FIELD(fgsr_pool_layout, input_slot_stride, 0, 8);
    FGSR_FIELD(fgsr_pool_layout, input_pool_size, 8, 8);
    FGSR_FIELD(fgsr_pool_layout, input_slot_count, 16, 4);
    FGSR_FIELD(fgsr_pool_layout, output_slot_count, 20, 4);
    FGSR_FIELD(fgsr_pool_layout, output_slot_stride, 24, 8);
    FGSR_FIELD(fgsr_pool_layout, output_pool_size, 32, 8);
    FGSR_FIELD(fgsr_pool_layout, output_width, 40, 4);
    FGSR_FIELD(fgsr_pool_layout, output_height, 44, 4);
    FGSR_FIELD(fgsr_pool_layout, color, 48, 24);
    FGSR_FIELD(fgsr_pool_layout, depth, 72, 24);
    FGSR_FIELD(fgsr_pool_layout, mv, 96, 24);
    FGSR_FIELD(fgsr_pool_layout, output, 120, 24);
    FGSR_FIELD(fgsr_pool_layout, rings_size, 144, 8);
    FGSR_FIELD(fgsr_pool_layout, ring_capacity, 152, 4);
    FGSR_FIELD(fgsr_pool_layout, reserved, 156, 4);
}

TEST(ProtocolAbi, Layout_fgsr_create_session_reply) {
    EXPECT_EQ(sizeof(fgsr_create_session_reply), size_t(256));
    EXPECT_EQ(alignof(fgsr_create_session_reply), size_t(8));
    FGSR_FIELD(fgsr_create_session_reply, header, 0, 16);
    FGSR_FIELD(fgsr_create_session_reply, status, 16, 4);
    FGSR_FIELD(fgsr_create_session_reply, session_id, 20, 4);
    FGSR_FIELD(fgsr_create_session_reply, epoch, 24, 8);
    FGSR_FIELD(fgsr_create_session_reply, layout, 32, 160);
    FGSR_FIELD(fgsr_create_session_reply, reason, 192, 64);
}

TEST(ProtocolAbi, Layout_fgsr_session_ref) {
    EXPECT_EQ(sizeof(fgsr_session_ref), size_t(24));
    EXPECT_EQ(alignof(fgsr_session_ref), size_t(4));
    FGSR_FIELD(fgsr_session_ref, header, 0, 16);
    FGSR_FIELD(fgsr_session_ref, session_id, 16, 4);
    FGSR_FIELD(fgsr_session_ref, reserved, 20, 4);
}

TEST(ProtocolAbi, Layout_fgsr_reply) {
    EXPECT_EQ(sizeof(fgsr_reply), size_t(152));
    EXPECT_EQ(alignof(fgsr_reply), size_t(4));
    FGSR_FIELD(fgsr_reply, header, 0, 16);
    FGSR_FIELD(fgsr_reply, status, 16, 4);
    FGSR_FIELD(fgsr_reply, session_id, 20, 4);
    FGSR_FIELD(fgsr_reply, reason, 24, 128);
}

TEST(ProtocolAbi, Layout_fgsr_session_stats) {
    EXPECT_EQ(sizeof(fgsr_session_stats), size_t(128));
    EXPECT_EQ(alignof(fgsr_session_stats), size_t(8));
    FGSR_FIELD(fgsr_session_stats, frames_submitted, 0, 8);
    FGSR_FIELD(fgsr_session_stats, frames_rejected, 8, 8);
    FGSR_FIELD(fgsr_session_stats, frames_dropped, 16, 8);
    FGSR_FIELD(fgsr_session_stats, outputs_written, 24, 8);
    FGSR_FIELD(fgsr_session_stats, latency_p50_ns, 32, 8);
    FGSR_FIELD(fgsr_session_stats, latency_p99_ns, 40, 8);
    FGSR_FIELD(fgsr_session_stats, gpu_p50_ns, 48, 8);
    FGSR_FIELD(fgsr_session_stats, gpu_p99_ns, 56, 8);
    FGSR_FIELD(fgsr_session_stats, queue_wait_p50_ns, 64, 8);
    FGSR_FIELD(fgsr_session_stats, queue_wait_p99_ns, 72, 8);
    FGSR_FIELD(fgsr_session_stats, bytes_copied, 80, 8);
    FGSR_FIELD(fgsr_session_stats, reserved, 88, 40);
}

TEST(ProtocolAbi, Layout_fgsr_stats_reply) {
    EXPECT_EQ(sizeof(fgsr_stats_reply), size_t(152));
    EXPECT_EQ(alignof(fgsr_stats_reply), size_t(8));
    FGSR_FIELD(fgsr_stats_reply, header, 0, 16);
    FGSR_FIELD(fgsr_stats_reply, status, 16, 4);
    FGSR_FIELD(fgsr_stats_reply, session_id, 20, 4);
    FGSR_FIELD(fgsr_stats_reply, stats, 24, 128);
}

TEST(ProtocolAbi, Layout_fgsr_ring_header) {
    EXPECT_EQ(sizeof(fgsr_ring_header), size_t(128));
    EXPECT_EQ(alignof(fgsr_ring_header), size_t(8));
    FGSR_FIELD(fgsr_ring_header, head, 0, 8);
    FGSR_FIELD(fgsr_ring_header, pad0, 8, 56);
    FGSR_FIELD(fgsr_ring_header, tail, 64, 8);
    FGSR_FIELD(fgsr_ring_header, pad1, 72, 56);
}

TEST(ProtocolAbi, Layout_fgsr_submit_entry) {
    EXPECT_EQ(sizeof(fgsr_submit_entry), size_t(128));
    EXPECT_EQ(alignof(fgsr_submit_entry), size_t(8));
    FGSR_FIELD(fgsr_submit_entry, sequence, 0, 8);
    FGSR_FIELD(fgsr_submit_entry, input_slot, 8, 4);
    FGSR_FIELD(fgsr_submit_entry, flags, 12, 4);
    FGSR_FIELD(fgsr_submit_entry, jitter_x, 16, 4);
    FGSR_FIELD(fgsr_submit_entry, jitter_y, 20, 4);
    FGSR_FIELD(fgsr_submit_entry, interp_count, 24, 4);
    FGSR_FIELD(fgsr_submit_entry, extrap_count, 28, 4);
    FGSR_FIELD(fgsr_submit_entry, interp_alphas, 32, 32);
    FGSR_FIELD(fgsr_submit_entry, extrap_alphas, 64, 32);
    FGSR_FIELD(fgsr_submit_entry, submit_time_ns, 96, 8);
    FGSR_FIELD(fgsr_submit_entry, present_time_ns, 104, 8);
    FGSR_FIELD(fgsr_submit_entry, user_data, 112, 8);
    FGSR_FIELD(fgsr_submit_entry, reserved, 120, 8);
}

TEST(ProtocolAbi, Layout_fgsr_pass_record) {
    EXPECT_EQ(sizeof(fgsr_pass_record), size_t(32));
    EXPECT_EQ(alignof(fgsr_pass_record), size_t(8));
    FGSR_FIELD(fgsr_pass_record, pass, 0, 4);
    FGSR_FIELD(fgsr_pass_record, tiles_total, 4, 4);
    FGSR_FIELD(fgsr_pass_record, tiles_skipped, 8, 4);
    FGSR_FIELD(fgsr_pass_record, runs, 12, 4);
    FGSR_FIELD(fgsr_pass_record, gpu_begin_ns, 16, 8);
    FGSR_FIELD(fgsr_pass_record, gpu_end_ns, 24, 8);
}

TEST(ProtocolAbi, Layout_fgsr_telemetry) {
    EXPECT_EQ(sizeof(fgsr_telemetry), size_t(464));
    EXPECT_EQ(alignof(fgsr_telemetry), size_t(8));
    FGSR_FIELD(fgsr_telemetry, frame_type, 0, 4);
    FGSR_FIELD(fgsr_telemetry, pass_count, 4, 4);
    FGSR_FIELD(fgsr_telemetry, target_time, 8, 4);
    FGSR_FIELD(fgsr_telemetry, skipped_passes, 12, 4);
    FGSR_FIELD(fgsr_telemetry, target_present_ns, 16, 8);
    FGSR_FIELD(fgsr_telemetry, submit_ns, 24, 8);
    FGSR_FIELD(fgsr_telemetry, dequeue_ns, 32, 8);
    FGSR_FIELD(fgsr_telemetry, start_ns, 40, 8);
    FGSR_FIELD(fgsr_telemetry, complete_ns, 48, 8);
    FGSR_FIELD(fgsr_telemetry, queue_wait_ns, 56, 8);
    FGSR_FIELD(fgsr_telemetry, gpu_ns, 64, 8);
    FGSR_FIELD(fgsr_telemetry, daemon_cpu_ns, 72, 8);
    FGSR_FIELD(fgsr_telemetry, passes, 80, 384);
}

TEST(ProtocolAbi, Layout_fgsr_completion_entry) {
    EXPECT_EQ(sizeof(fgsr_completion_entry), size_t(528));
    EXPECT_EQ(alignof(fgsr_completion_entry), size_t(8));
    FGSR_FIELD(fgsr_completion_entry, sequence, 0, 8);
    FGSR_FIELD(fgsr_completion_entry, status, 8, 4);
    FGSR_FIELD(fgsr_completion_entry, flags, 12, 4);
    FGSR_FIELD(fgsr_completion_entry, input_slot, 16, 4);
    FGSR_FIELD(fgsr_completion_entry, output_slot, 20, 4);
    FGSR_FIELD(fgsr_completion_entry, output_index, 24, 4);
    FGSR_FIELD(fgsr_completion_entry, reserved0, 28, 4);
    FGSR_FIELD(fgsr_completion_entry, user_data, 32, 8);
    FGSR_FIELD(fgsr_completion_entry, telemetry, 40, 464);
    FGSR_FIELD(fgsr_completion_entry, reserved1, 504, 24);
}

TEST(ProtocolAbi, Layout_fgsr_release_entry) {
    EXPECT_EQ(sizeof(fgsr_release_entry), size_t(8));
    EXPECT_EQ(alignof(fgsr_release_entry), size_t(4));
    FGSR_FIELD(fgsr_release_entry, output_slot, 0, 4);
    FGSR_FIELD(fgsr_release_entry, reserved, 4, 4);
}

TEST(ProtocolAbi, Layout_fgsr_present_report) {
    EXPECT_EQ(sizeof(fgsr_present_report), size_t(56));
    EXPECT_EQ(alignof(fgsr_present_report), size_t(8));
    FGSR_FIELD(fgsr_present_report, sequence, 0, 8);
    FGSR_FIELD(fgsr_present_report, output_index, 8, 4);
    FGSR_FIELD(fgsr_present_report, frame_type, 12, 4);
    FGSR_FIELD(fgsr_present_report, flags, 16, 4);
    FGSR_FIELD(fgsr_present_report, reserved, 20, 4);
    FGSR_FIELD(fgsr_present_report, submit_ns, 24, 8);
    FGSR_FIELD(fgsr_present_report, received_ns, 32, 8);
    FGSR_FIELD(fgsr_present_report, intended_ns, 40, 8);
    FGSR_FIELD(fgsr_present_report, presented_ns, 48, 8);
}

TEST(ProtocolAbi, Layout_fgsr_report) {
    EXPECT_EQ(sizeof(fgsr_report), size_t(920));
    EXPECT_EQ(alignof(fgsr_report), size_t(8));
    FGSR_FIELD(fgsr_report, header, 0, 16);
    FGSR_FIELD(fgsr_report, session_id, 16, 4);
    FGSR_FIELD(fgsr_report, count, 20, 4);
    FGSR_FIELD(fgsr_report, reports, 24, 16 * 56);
}

TEST(ProtocolAbi, Layout_fgsr_probe_sample) {
    EXPECT_EQ(sizeof(fgsr_probe_sample), size_t(24));
    EXPECT_EQ(alignof(fgsr_probe_sample), size_t(8));
    FGSR_FIELD(fgsr_probe_sample, click_ns, 0, 8);
    FGSR_FIELD(fgsr_probe_sample, photon_ns, 8, 8);
    FGSR_FIELD(fgsr_probe_sample, mode, 16, 4);
    FGSR_FIELD(fgsr_probe_sample, pid, 20, 4);
}

TEST(ProtocolAbi, Layout_fgsr_probe) {
    EXPECT_EQ(sizeof(fgsr_probe), size_t(792));
    FGSR_FIELD(fgsr_probe, header, 0, 16);
    FGSR_FIELD(fgsr_probe, count, 16, 4);
    FGSR_FIELD(fgsr_probe, reserved, 20, 4);
    FGSR_FIELD(fgsr_probe, samples, 24, 32 * 24);
}

TEST(ProtocolAbi, Layout_fgsr_rings_layout) {
    EXPECT_EQ(sizeof(fgsr_rings_layout), size_t(56));
    EXPECT_EQ(alignof(fgsr_rings_layout), size_t(8));
    FGSR_FIELD(fgsr_rings_layout, submit_header, 0, 8);
    FGSR_FIELD(fgsr_rings_layout, submit_entries, 8, 8);
    FGSR_FIELD(fgsr_rings_layout, completion_header, 16, 8);
    FGSR_FIELD(fgsr_rings_layout, completion_entries, 24, 8);
    FGSR_FIELD(fgsr_rings_layout, release_header, 32, 8);
    FGSR_FIELD(fgsr_rings_layout, release_entries, 40, 8);
    FGSR_FIELD(fgsr_rings_layout, total_size, 48, 8);
}

TEST(ProtocolAbi, EnumValues) {
    EXPECT_EQ(int64_t(FGSR_STATUS_OK), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_STATUS_INVALID_ARGUMENT), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_STATUS_DAEMON_UNAVAILABLE), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_STATUS_DISCONNECTED), int64_t(3));
    EXPECT_EQ(int64_t(FGSR_STATUS_VERSION_MISMATCH), int64_t(4));
    EXPECT_EQ(int64_t(FGSR_STATUS_PROTOCOL_ERROR), int64_t(5));
    EXPECT_EQ(int64_t(FGSR_STATUS_PERMISSION_DENIED), int64_t(6));
    EXPECT_EQ(int64_t(FGSR_STATUS_OUT_OF_MEMORY), int64_t(7));
    EXPECT_EQ(int64_t(FGSR_STATUS_UNSUPPORTED), int64_t(8));
    EXPECT_EQ(int64_t(FGSR_STATUS_BAD_FRAME), int64_t(9));
    EXPECT_EQ(int64_t(FGSR_STATUS_NO_SLOT), int64_t(10));
    EXPECT_EQ(int64_t(FGSR_STATUS_TIMEOUT), int64_t(11));
    EXPECT_EQ(int64_t(FGSR_STATUS_DROPPED), int64_t(12));
    EXPECT_EQ(int64_t(FGSR_STATUS_NOT_READY), int64_t(13));
    EXPECT_EQ(int64_t(FGSR_STATUS_DEVICE_ERROR), int64_t(14));
    EXPECT_EQ(int64_t(FGSR_STATUS_BUSY), int64_t(15));
    EXPECT_EQ(int64_t(FGSR_STATUS_INTERNAL), int64_t(16));
    EXPECT_EQ(int64_t(FGSR_STATUS_COUNT_), int64_t(17));
    EXPECT_EQ(int64_t(FGSR_COLOR_RGBA8_SRGB), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_COLOR_RGBA16F_LINEAR), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_COLOR_RGBA32F_LINEAR), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_DEPTH_LINEAR), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_DEPTH_DEVICE), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_DEPTH_DEVICE_REVERSED), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_MV_RG16F), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_MV_RG32F), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_MV_PIXELS), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_MV_UV), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_MV_TO_PREVIOUS), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_MV_FROM_PREVIOUS), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_QUEUE_FIFO), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_QUEUE_MAILBOX), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_MSG_HELLO), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_MSG_HELLO_REPLY), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_MSG_CREATE_SESSION), int64_t(3));
    EXPECT_EQ(int64_t(FGSR_MSG_CREATE_SESSION_REPLY), int64_t(4));
    EXPECT_EQ(int64_t(FGSR_MSG_DESTROY_SESSION), int64_t(5));
    EXPECT_EQ(int64_t(FGSR_MSG_DESTROY_SESSION_REPLY), int64_t(6));
    EXPECT_EQ(int64_t(FGSR_MSG_STATS), int64_t(7));
    EXPECT_EQ(int64_t(FGSR_MSG_STATS_REPLY), int64_t(8));
    EXPECT_EQ(int64_t(FGSR_MSG_ERROR), int64_t(9));
    EXPECT_EQ(int64_t(FGSR_MSG_REPORT), int64_t(10));
    EXPECT_EQ(int64_t(FGSR_MSG_PROBE), int64_t(11));
    EXPECT_EQ(int64_t(FGSR_FD_INPUT_POOL), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_FD_OUTPUT_POOL), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_FD_RINGS), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_FD_SUBMIT_EVENT), int64_t(3));
    EXPECT_EQ(int64_t(FGSR_FD_COMPLETE_EVENT), int64_t(4));
    EXPECT_EQ(int64_t(FGSR_FD_COUNT), int64_t(5));
    EXPECT_EQ(int64_t(FGSR_FRAME_NONE), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_FRAME_UPSCALED), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_FRAME_INTERPOLATED), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_FRAME_EXTRAPOLATED), int64_t(3));
    EXPECT_EQ(int64_t(FGSR_PASS_INGEST), int64_t(0));
    EXPECT_EQ(int64_t(FGSR_PASS_SPLAT), int64_t(1));
    EXPECT_EQ(int64_t(FGSR_PASS_REFINE), int64_t(2));
    EXPECT_EQ(int64_t(FGSR_PASS_DISOCC), int64_t(3));
    EXPECT_EQ(int64_t(FGSR_PASS_WARP), int64_t(4));
    EXPECT_EQ(int64_t(FGSR_PASS_BLEND), int64_t(5));
    EXPECT_EQ(int64_t(FGSR_PASS_GENERATE), int64_t(6));
    EXPECT_EQ(int64_t(FGSR_PASS_SR), int64_t(7));
    EXPECT_EQ(int64_t(FGSR_PASS_GENERATE_SR), int64_t(8));
    EXPECT_EQ(int64_t(FGSR_PASS_CLASSIFY), int64_t(9));
    EXPECT_EQ(int64_t(FGSR_PASS_DENOISE), int64_t(10));
    EXPECT_EQ(int64_t(FGSR_PASS_LUMA), int64_t(11));
    EXPECT_EQ(int64_t(FGSR_PASS_MATCH), int64_t(12));
    EXPECT_EQ(int64_t(FGSR_PASS_FLOW), int64_t(13));
    EXPECT_EQ(int64_t(FGSR_PASS_POLISH), int64_t(14));
    EXPECT_EQ(int64_t(FGSR_PASS_AGREE), int64_t(15));
    EXPECT_EQ(int64_t(FGSR_PASS_COUNT_), int64_t(16));
}

TEST(ProtocolAbi, DefineValues) {
    EXPECT_EQ(uint64_t(FGSR_PROTOCOL_MAGIC), uint64_t(0x52534746u));
    EXPECT_EQ(uint64_t(FGSR_PROTOCOL_MAJOR), uint64_t(1u));
    EXPECT_EQ(uint64_t(FGSR_PROTOCOL_MINOR), uint64_t(8u));
    EXPECT_EQ(uint64_t(FGSR_REPORT_APPLICATION), uint64_t(0xffffffffu));
    EXPECT_EQ(uint64_t(FGSR_REPORT_DROPPED), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_MAX_REPORTS_PER_MESSAGE), uint64_t(16u));
    EXPECT_EQ(uint64_t(FGSR_REPORT_MESSAGE_SIZE(3)), uint64_t(24u + 3u * 56u));
    EXPECT_EQ(uint64_t(FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE), uint64_t(32u));
    EXPECT_EQ(uint64_t(FGSR_PROBE_MESSAGE_SIZE(2)), uint64_t(24u + 2u * 24u));
    EXPECT_EQ(uint64_t(FGSR_PROBE_MODE_UNKNOWN), uint64_t(0u));
    EXPECT_EQ(uint64_t(FGSR_PROBE_MODE_OFF), uint64_t(1u));
    EXPECT_EQ(uint64_t(FGSR_PROBE_MODE_INTERPOLATE), uint64_t(2u));
    EXPECT_EQ(uint64_t(FGSR_PROBE_MODE_EXTRAPOLATE), uint64_t(3u));
    EXPECT_EQ(uint64_t(FGSR_CACHE_LINE), uint64_t(64u));
    EXPECT_EQ(uint64_t(FGSR_PLANE_ALIGNMENT), uint64_t(4096u));
    EXPECT_EQ(uint64_t(FGSR_MAX_ALPHAS), uint64_t(8u));
    EXPECT_EQ(uint64_t(FGSR_MAX_PASSES), uint64_t(12u));
    EXPECT_EQ(uint64_t(FGSR_MAX_SLOTS), uint64_t(64u));
    EXPECT_EQ(uint64_t(FGSR_MAX_MESSAGE_SIZE), uint64_t(1024u));
    EXPECT_EQ(uint64_t(FGSR_NO_SLOT), uint64_t(0xffffffffu));
    EXPECT_EQ(uint64_t(FGSR_MODE_SR), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_MODE_INTERPOLATE), uint64_t(0x2u));
    EXPECT_EQ(uint64_t(FGSR_MODE_EXTRAPOLATE), uint64_t(0x4u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_MVS_CONTAIN_JITTER), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_DILATE_MVS), uint64_t(0x2u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_MV_Y_UP), uint64_t(0x4u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_LINEAR_MOTION), uint64_t(0x8u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_NO_DENOISE), uint64_t(0x10u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_NO_MVS), uint64_t(0x20u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_NO_DEPTH), uint64_t(0x40u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_CORRECT_MVS), uint64_t(0x80u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_FAST_MOTION), uint64_t(0x100u));
    EXPECT_EQ(uint64_t(FGSR_SESSION_COLOUR_AGREE), uint64_t(0x200u));
    EXPECT_EQ(uint64_t(FGSR_CAP_ZERO_COPY_INPUT), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_CAP_SR), uint64_t(0x2u));
    EXPECT_EQ(uint64_t(FGSR_CAP_INTERPOLATE), uint64_t(0x4u));
    EXPECT_EQ(uint64_t(FGSR_CAP_EXTRAPOLATE), uint64_t(0x8u));
    EXPECT_EQ(uint64_t(FGSR_CAP_CALIBRATED_TIME), uint64_t(0x10u));
    EXPECT_EQ(uint64_t(FGSR_SUBMIT_RESET), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_SUBMIT_HAS_MV), uint64_t(0x2u));
    EXPECT_EQ(uint64_t(FGSR_SUBMIT_WANT_SR), uint64_t(0x4u));
    EXPECT_EQ(uint64_t(FGSR_COMPLETION_INPUT_RELEASED), uint64_t(0x1u));
    EXPECT_EQ(uint64_t(FGSR_COMPLETION_LAST), uint64_t(0x2u));
}

TEST(ProtocolAbi, PassNames) {
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_INGEST)), "ingest");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_GENERATE_SR)), "generate_sr");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_CLASSIFY)), "classify");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_DENOISE)), "denoise");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_LUMA)), "luma");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_MATCH)), "match");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_FLOW)), "flow");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_POLISH)), "polish");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_AGREE)), "agree");
    EXPECT_EQ(std::string(fgsr_pass_name(FGSR_PASS_COUNT_)), "unknown");
}

TEST(ProtocolAbi, StatusStrings) {
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_OK)), "ok");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_INVALID_ARGUMENT)), "invalid argument");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_DAEMON_UNAVAILABLE)),
              "fgsrd is not running (no daemon on the socket)");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_DISCONNECTED)), "disconnected from fgsrd");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_VERSION_MISMATCH)),
              "fgsrd speaks another major protocol version");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_PROTOCOL_ERROR)),
              "protocol error (malformed message or ring entry)");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_PERMISSION_DENIED)), "permission denied");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_OUT_OF_MEMORY)), "out of memory");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_UNSUPPORTED)), "unsupported format, mode or scale");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_BAD_FRAME)), "frame rejected");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_NO_SLOT)), "no free slot");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_TIMEOUT)), "timed out");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_DROPPED)), "dropped (superseded by a newer frame)");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_NOT_READY)), "not ready (needs an earlier frame)");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_DEVICE_ERROR)), "device error");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_BUSY)), "busy (too many sessions or clients)");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_INTERNAL)), "internal error");
    EXPECT_EQ(std::string(fgsr_status_string(FGSR_STATUS_COUNT_)), "unknown status");
    EXPECT_EQ(std::string(fgsr_status_string(-1)), "unknown status");
    EXPECT_EQ(std::string(fgsr_status_string(1000)), "unknown status");
}

TEST(ProtocolAbi, RingsLayout) {
    // Capacity 64: 128 + 64 * 128 = 8320; 8320 + 128 + 64 * 528 = 42240; + 128 + 64 * 8 = 42880,
    // rounded up to a page: 45056.
    const fgsr_rings_layout l = fgsr_rings_layout_for(64);
    EXPECT_EQ(l.submit_header, 0u);
    EXPECT_EQ(l.submit_entries, 128u);
    EXPECT_EQ(l.completion_header, 8320u);
    EXPECT_EQ(l.completion_entries, 8448u);
    EXPECT_EQ(l.release_header, 42240u);
    EXPECT_EQ(l.release_entries, 42368u);
    EXPECT_EQ(l.total_size, 45056u);
    for (uint32_t cap : {1u, 4u, 64u, 4096u}) {
        const fgsr_rings_layout r = fgsr_rings_layout_for(cap);
        EXPECT_EQ(r.completion_header % FGSR_CACHE_LINE, 0u);
        EXPECT_EQ(r.release_header % FGSR_CACHE_LINE, 0u);
        EXPECT_GE(r.completion_header, r.submit_entries + cap * sizeof(fgsr_submit_entry));
        EXPECT_GE(r.total_size, r.release_entries + cap * sizeof(fgsr_release_entry));
        EXPECT_EQ(r.total_size % 4096u, 0u);
    }
    EXPECT_EQ(fgsr_ring_index(64, 64), 0u);
    EXPECT_EQ(fgsr_ring_index(67, 64), 3u);
    EXPECT_EQ(fgsr_align_up(1, 4096), 4096u);
    EXPECT_EQ(fgsr_align_up(4096, 4096), 4096u);
}

} // namespace
