/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Reactions to malformed and unexpected frames, client aborts, NMT states and timeouts
 * (cia301.md §3.6, §10 items 21-25; doc/sdo.md "Unexpected frames").
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_protocol, NULL, NULL, before, NULL, NULL);

/* Start a segmented download of 2003h announcing @p size bytes. */
static void start_seg_download(uint32_t size)
{
	h_req(0x21, 0x2003, 0, size);
	h_expect(0x60, 0x2003, 0, 0);
}

ZTEST(sdo_protocol, test_abort_05040001_reserved_command_specifier)
{
	/* §10 item 21: E0h. No transfer, so the abort names no object. */
	h_req(0xE0, 0x1000, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	h_req(0xFF, 0x1000, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	h_expect_none();
}

ZTEST(sdo_protocol, test_abort_05040001_segment_without_transfer)
{
	/* §10 item 22: download segment 00h, upload segment 60h with nothing open. */
	h_req(0x00, 0x1000, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	h_req(0x60, 0, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	h_req(0x70, 0, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
}

ZTEST(sdo_protocol, test_abort_05040001_stray_block_frames)
{
	/* Block acknowledge, start, end frames of either direction with nothing open. */
	static const uint8_t stray[] = {0xA1, 0xA2, 0xA3, 0xC1, 0xC5};

	for (size_t i = 0; i < ARRAY_SIZE(stray); i++) {
		h_req(stray[i], 0x1000, 0, 0);
		h_expect_abort(0, 0, CO_SDO_AB_CMD);
	}
}

ZTEST(sdo_protocol, test_abort_05040001_new_initiate_during_transfer)
{
	/* The running transfer is aborted (with its multiplexer) and the new request is not
	 * started; the old value stays.
	 */
	start_seg_download(10);
	h_req(0x40, 0x1000, 0, 0);
	h_expect_abort(0x2003, 0, CO_SDO_AB_CMD);
	h_expect_none();
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
	/* The server is idle again: the request now works. */
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_protocol, test_abort_05040001_wrong_segment_type)
{
	/* An upload segment request during a download. */
	start_seg_download(10);
	h_req(0x60, 0, 0, 0);
	h_expect_abort(0x2003, 0, CO_SDO_AB_CMD);
	/* A download segment during an upload. */
	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	h_req(0x00, 0, 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_CMD);
}

ZTEST(sdo_protocol, test_client_abort_in_idle_is_ignored)
{
	h_req(0x80, 0x1000, 0, CO_SDO_AB_TIMEOUT);
	h_expect_none();
	zassert_equal(h_stats(0).aborts_received, 0);
}

ZTEST(sdo_protocol, test_abort_05040001_abort_with_reserved_bits)
{
	/* Only 80h is an abort; 81h-9Fh are unknown commands (outside a block download). */
	h_req(0x81, 0x1000, 0, CO_SDO_AB_TIMEOUT);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	start_seg_download(10);
	h_req(0x9F, 0x2003, 0, CO_SDO_AB_TIMEOUT);
	h_expect_abort(0x2003, 0, CO_SDO_AB_CMD);
	zassert_equal(h_stats(0).aborts_received, 0);
}

ZTEST(sdo_protocol, test_client_abort_ends_transfer_silently)
{
	/* §10 item 24: no frame; the value stays; the next transfer works. */
	uint8_t seg[8] = {0x00, 'n', 'e', 'w', 'v', 'a', 'l', 'u'};

	start_seg_download(10);
	h_send(seg);
	h_expect(0x20, 0, 0, 0);
	h_req(0x80, 0x2003, 0, CO_SDO_AB_GENERAL);
	h_expect_none();
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
	zassert_equal(h_stats(0).aborts_received, 1);
	zassert_equal(h_stats(0).last_abort, CO_SDO_AB_GENERAL);
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
	/* No timeout follows. */
	h_advance(2 * TIMEOUT_US);
	h_expect_none();
	zassert_ok(cli_dl_seg(0x2003, 0, "fresh value", 11, true));
	zassert_str_equal(h.ram.manuf.x2003_string, "fresh value");
}

ZTEST(sdo_protocol, test_short_frames_are_ignored)
{
	uint8_t d[8] = {0x40, 0x00, 0x10, 0x00};

	/* DLC 4 carries every field an upload request needs; it is still not an SDO frame. */
	for (uint8_t dlc = 0; dlc < 8; dlc++) {
		h_send_dlc(d, dlc);
	}
	h_expect_none();
	zassert_equal(h_stats(0).rx_malformed, 8);
	/* During a transfer they change nothing either: the transfer goes on. */
	start_seg_download(7 + 4);
	memcpy(d, "\x00segment", 8);
	h_send_dlc(d, 7);
	h_expect_none();
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	memcpy(d, "\x17 two\0\0\0", 8);
	h_send(d);
	h_expect(0x30, 0, 0, 0);
	zassert_str_equal(h.ram.manuf.x2003_string, "segment two");
	zassert_equal(h_stats(0).rx_malformed, 9);
}

ZTEST(sdo_protocol, test_remote_frames_are_ignored)
{
	struct can_frame f = {.id = 0x600 + NODE_ID, .dlc = 8, .flags = CAN_FRAME_RTR};

	f.data[0] = 0x40;
	co_line_rx(&h.line, &f, h.now);
	h_expect_none();
	zassert_equal(h_stats(0).rx_malformed, 1);
}

ZTEST(sdo_protocol, test_stopped_node_does_not_answer)
{
	/* §10 item 4. */
	h_nmt(CO_NMT_CS_STOP);
	h.rd = h.wr;
	h_req(0x40, 0x1000, 0, 0);
	h_req(0xE0, 0, 0, 0);
	h_expect_none();
	zassert_equal(h_stats(0).rx_inactive, 2);
	/* Operational and Pre-operational answer. */
	h_nmt(CO_NMT_CS_START);
	h.rd = h.wr;
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
	h_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL);
	h.rd = h.wr;
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_protocol, test_stop_drops_running_transfer)
{
	uint8_t seg[8] = {0x00, 'a', 'b', 'c', 'd', 'e', 'f', 'g'};

	start_seg_download(14);
	h_nmt(CO_NMT_CS_STOP);
	h.rd = h.wr;
	h_advance(2 * TIMEOUT_US);
	/* Dropped without a frame, also no timeout abort later. */
	h_expect_none();
	zassert_equal(h_stats(0).dropped, 1);
	h_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL);
	h.rd = h.wr;
	/* The transfer is gone: its next segment is unexpected. */
	h_send(seg);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_protocol, test_reset_communication_drops_transfer)
{
	start_seg_download(14);
	h_nmt(CO_NMT_CS_RESET_COMMUNICATION);
	/* Only the boot-up frame. */
	zassert_equal(h_pending(), 1);
	zassert_equal(h.ring[h.rd % RING].id, 0x700 + NODE_ID);
	h.rd = h.wr;
	h_advance(2 * TIMEOUT_US);
	h_expect_none();
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_protocol, test_abort_05040000_timeout_segmented_download)
{
	/* §10 item 25: silence after the initiate. Nothing before the timeout, the abort at it. */
	uint64_t t0 = h.now;

	start_seg_download(14);
	h_run_until(t0 + TIMEOUT_US - 1);
	h_expect_none();
	h_run_until(t0 + TIMEOUT_US);
	h_expect_abort(0x2003, 0, CO_SDO_AB_TIMEOUT);
	h_advance(10 * TIMEOUT_US);
	h_expect_none();
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_protocol, test_abort_05040000_timeout_restarts_with_each_frame)
{
	uint8_t seg[8] = {0x00, 'a', 'b', 'c', 'd', 'e', 'f', 'g'};
	uint64_t t1;

	start_seg_download(14);
	h_advance(TIMEOUT_US - 10);
	h_send(seg);
	h_expect(0x20, 0, 0, 0);
	t1 = h.now;
	h_run_until(t1 + TIMEOUT_US - 1);
	h_expect_none();
	h_run_until(t1 + TIMEOUT_US);
	h_expect_abort(0x2003, 0, CO_SDO_AB_TIMEOUT);
}

ZTEST(sdo_protocol, test_abort_05040000_timeout_segmented_upload)
{
	uint64_t t0 = h.now;

	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	h_run_until(t0 + TIMEOUT_US);
	h_expect_abort(0x1008, 0, CO_SDO_AB_TIMEOUT);
	zassert_equal(h_stats(0).last_abort, CO_SDO_AB_TIMEOUT);
}

ZTEST(sdo_protocol, test_no_timer_when_idle)
{
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
	h_advance(5 * TIMEOUT_US);
	h_expect_none();
}
