/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The client against a scripted server (client 2, bound to FAKE_ID): every frame of the
 * client is checked byte by byte, the server's answers are injected. Error paths, aborts both
 * ways, timeouts, block-transfer details, NMT.
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

#define C 2U

static uint8_t buf[512];
static uint8_t data[512];

static void before(void *f)
{
	h_setup();
	zassert_ok(co_sdo_cli_set_server(h_cli(C), FAKE_ID));
	memset(buf, 0xEE, sizeof(buf));
	h_fill(data, sizeof(data), 9);
}

static struct con_rec *rec(void)
{
	return &h.con[C];
}

static void start_ul(uint16_t idx, uint8_t sub, size_t cap, enum co_sdo_cli_mode mode,
		     uint32_t timeout_ms)
{
	zassert_ok(co_sdo_cli_upload_req(h_cli(C), idx, sub, buf, cap, mode, timeout_ms, h_con,
					 CON(C)));
	h_pump();
}

static void start_dl(uint16_t idx, uint8_t sub, size_t len, enum co_sdo_cli_mode mode)
{
	zassert_ok(co_sdo_cli_download_req(h_cli(C), idx, sub, data, len, mode, 0, h_con, CON(C)));
	h_pump();
}

/* Exactly one confirmation with @p code; nothing more from the client after it. */
static void expect_con(uint32_t code)
{
	h_pump();
	zassert_equal(rec()->calls, 1U, "confirmed %u times", rec()->calls);
	zassert_equal(rec()->code, code, "code %08x, expected %08x", rec()->code, code);
	zassert_false(co_sdo_cli_busy(h_cli(C)));
	h_advance(3 * TIMEOUT_US);
	zassert_equal(rec()->calls, 1U);
	h_expect_none();
}

static void seg(uint8_t b0, const uint8_t *p)
{
	uint8_t d[8] = {b0};

	memcpy(&d[1], p, 7);
	h_fake_raw(d);
}

/* --- Timeouts ---------------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_timeout_05040000_after_the_configured_time)
{
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_advance(TIMEOUT_US - 1);
	zassert_equal(rec()->calls, 0U);
	h_expect_none();
	h_advance(1);
	h_expect_abort(0x2000, 0, CO_SDO_AB_TIMEOUT);
	expect_con(CO_SDO_AB_TIMEOUT);
}

ZTEST(sdo_cli_errors, test_timeout_of_the_request_and_restart_per_answer)
{
	/* 50 ms given by the request; each answer of the server restarts it. */
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 50);
	h_expect(0x40, 0x2005, 0, 0);
	h_advance(40 * MS);
	h_fake(0x41, 0x2005, 0, 14);
	h_expect(0x60, 0, 0, 0);
	h_advance(40 * MS);
	zassert_equal(rec()->calls, 0U);
	seg(0x00, data);
	h_expect(0x70, 0, 0, 0);
	h_advance(50 * MS);
	h_expect_abort(0x2005, 0, CO_SDO_AB_TIMEOUT);
	expect_con(CO_SDO_AB_TIMEOUT);
	zassert_equal(rec()->size, 7U);
}

ZTEST(sdo_cli_errors, test_timeout_in_block_upload_sub_block)
{
	start_ul(0x2005, 0, 500, CO_SDO_CLI_BLOCK, 0);
	h_skip_all();
	h_fake(0xC6, 0x2005, 0, 100);
	h_skip_all();
	/* One segment, then silence: the end of the sub-block never comes. */
	seg(0x01, data);
	h_advance(TIMEOUT_US);
	h_expect_abort(0x2005, 0, CO_SDO_AB_TIMEOUT);
	expect_con(CO_SDO_AB_TIMEOUT);
}

/* --- Aborts ------------------------------------------------------------------------------ */

ZTEST(sdo_cli_errors, test_server_abort_is_confirmed_with_its_code_unanswered)
{
	start_dl(0x2005, 0, 20, CO_SDO_CLI_AUTO);
	h_expect(0x21, 0x2005, 0, 20);
	h_fake(0x60, 0x2005, 0, 0);
	h_skip_all();
	h_fake(0x80, 0x2005, 0, CO_SDO_AB_DATA_DEV_STATE);
	expect_con(CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(rec()->size, 0U);
}

ZTEST(sdo_cli_errors, test_server_abort_with_code_zero_is_a_general_error)
{
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x80, 0x2000, 0, 0);
	expect_con(CO_SDO_AB_GENERAL);
}

ZTEST(sdo_cli_errors, test_application_abort_sends_frame_and_confirms_later)
{
	struct co_sdo_cli_stats st;

	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	zassert_ok(co_sdo_cli_abort_req(h_cli(C), CO_SDO_AB_DATA_LOC_CTRL));
	/* The frame at once; the confirmation from the line (next processing). */
	h_expect_abort(0x2005, 0, CO_SDO_AB_DATA_LOC_CTRL);
	zassert_equal(rec()->calls, 0U);
	zassert_true(co_sdo_cli_busy(h_cli(C)));
	zassert_equal(co_sdo_cli_abort_req(h_cli(C), CO_SDO_AB_GENERAL), -EALREADY);
	zassert_equal(co_sdo_cli_upload_req(h_cli(C), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(C)),
		      -EBUSY);
	/* A late answer of the server is ignored. */
	h_fake(0x41, 0x2005, 0, 14);
	expect_con(CO_SDO_AB_DATA_LOC_CTRL);
	zassert_equal(co_sdo_cli_abort_req(h_cli(C), CO_SDO_AB_GENERAL), -EALREADY);
	co_sdo_cli_get_stats(h_cli(C), &st);
	zassert_equal(st.aborts_sent, 1U);
	zassert_equal(st.rx_stray, 1U);
}

/* --- Protocol errors --------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_abort_05030000_toggle_upload)
{
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2005, 0, 0);
	h_fake(0x41, 0x2005, 0, 14);
	h_expect(0x60, 0, 0, 0);
	seg(0x10, data);
	h_expect_abort(0x2005, 0, CO_SDO_AB_TOGGLE);
	expect_con(CO_SDO_AB_TOGGLE);
}

ZTEST(sdo_cli_errors, test_abort_05030000_toggle_download)
{
	uint8_t d[8] = {0x00};

	start_dl(0x2005, 0, 10, CO_SDO_CLI_AUTO);
	h_expect(0x21, 0x2005, 0, 10);
	h_fake(0x60, 0x2005, 0, 0);
	memcpy(&d[1], data, 7);
	h_expect_raw(d);
	h_fake(0x20, 0, 0, 0);
	d[0] = 0x10 | (4 << 1) | 1;
	memset(&d[1], 0, 7);
	memcpy(&d[1], &data[7], 3);
	h_expect_raw(d);
	/* The server echoes the wrong toggle. */
	h_fake(0x20, 0, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_TOGGLE);
	expect_con(CO_SDO_AB_TOGGLE);
	zassert_equal(rec()->size, 7U);
}

ZTEST(sdo_cli_errors, test_abort_05040001_wrong_command_specifier)
{
	/* A download response to an upload. */
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x60, 0x2000, 0, 0);
	h_expect_abort(0x2000, 0, CO_SDO_AB_CMD);
	expect_con(CO_SDO_AB_CMD);

	/* A download response to a download of the same object, when an upload is awaited. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x60, 0x2005, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_CMD);
	expect_con(CO_SDO_AB_CMD);

	/* An upload segment in a segmented download. */
	memset(rec(), 0, sizeof(*rec()));
	start_dl(0x2005, 0, 10, CO_SDO_CLI_AUTO);
	h_fake(0x60, 0x2005, 0, 0);
	h_skip_all();
	h_fake(0x00, 0, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_CMD);
	expect_con(CO_SDO_AB_CMD);

	/* A block download frame answering a block upload. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_skip_all();
	h_fake(0xA4, 0x2005, 0, 127);
	h_expect_abort(0x2005, 0, CO_SDO_AB_CMD);
	expect_con(CO_SDO_AB_CMD);
}

/*
 * The answer to a transfer that timed out comes after the next request: it names another
 * object and is ignored; the next transfer gets its own answer (it used to abort with
 * 05040001h, and each later transfer then got the answer of the one before).
 */
ZTEST(sdo_cli_errors, test_late_answer_of_an_ended_transfer_is_ignored)
{
	struct co_sdo_cli_stats st;

	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_advance(TIMEOUT_US);
	h_expect_abort(0x2000, 0, CO_SDO_AB_TIMEOUT);
	expect_con(CO_SDO_AB_TIMEOUT);

	/* A download: the upload's answer, then the server's abort of it, come first. */
	memset(rec(), 0, sizeof(*rec()));
	start_dl(0x2001, 0, 4, CO_SDO_CLI_AUTO);
	h_skip_all();
	h_fake(0x43, 0x2000, 0, 0x11223344);
	h_fake(0x80, 0x2000, 0, CO_SDO_AB_TIMEOUT);
	h_expect_none();
	zassert_equal(rec()->calls, 0U);
	h_fake(0x60, 0x2001, 0, 0);
	expect_con(0);

	/* An upload: a late download response of another object is ignored too. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_fake(0x60, 0x2001, 0, 0);
	h_expect_none();
	h_fake(0x43, 0x2000, 0, 0x04030201);
	expect_con(0);
	zassert_equal(sys_get_le32(buf), 0x04030201);

	/* An abort naming no object still ends the transfer. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x80, 0x0000, 0, CO_SDO_AB_NO_OBJECT);
	expect_con(CO_SDO_AB_NO_OBJECT);

	co_sdo_cli_get_stats(h_cli(C), &st);
	zassert_equal(st.rx_stray, 3U);
}

ZTEST(sdo_cli_errors, test_malformed_and_stray_frames_are_ignored)
{
	uint8_t d[8] = {0x43, 0x00, 0x20, 0x00, 1, 2, 3, 4};
	struct co_sdo_cli_stats st;

	/* In idle: nothing happens. */
	h_fake_raw(d);
	h_expect_none();
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	/* DLC 7: not an SDO frame; the transfer goes on. */
	h_fake_dlc(d, 7);
	zassert_equal(rec()->calls, 0U);
	h_fake_raw(d);
	expect_con(0);
	zassert_equal(sys_get_le32(buf), 0x04030201);
	co_sdo_cli_get_stats(h_cli(C), &st);
	zassert_equal(st.rx_malformed, 1U);
	zassert_equal(st.rx_stray, 1U);
}

/* --- Buffer and sizes -------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_abort_05040005_buffer_too_small)
{
	/* Size indicated above the capacity: aborted at the initiate. */
	start_ul(0x2005, 0, 20, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x41, 0x2005, 0, 21);
	h_expect_abort(0x2005, 0, CO_SDO_AB_OUT_OF_MEM);
	expect_con(CO_SDO_AB_OUT_OF_MEM);

	/* Size not indicated: aborted at the segment that does not fit. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2005, 0, 10, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x40, 0x2005, 0, 0);
	h_expect(0x60, 0, 0, 0);
	seg(0x00, data);
	h_expect(0x70, 0, 0, 0);
	seg(0x10, &data[7]);
	h_expect_abort(0x2005, 0, CO_SDO_AB_OUT_OF_MEM);
	expect_con(CO_SDO_AB_OUT_OF_MEM);
	zassert_equal(rec()->size, 7U);
	zassert_equal(buf[10], 0xEE, "written past the capacity");

	/* Expedited without size (4 bytes) into 3. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 3, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_fake(0x42, 0x2000, 0, 0x11223344);
	h_expect_abort(0x2000, 0, CO_SDO_AB_OUT_OF_MEM);
	expect_con(CO_SDO_AB_OUT_OF_MEM);

	/* Block upload without size: the last segment's data exceeds the buffer. */
	memset(rec(), 0, sizeof(*rec()));
	memset(buf, 0xEE, sizeof(buf));
	start_ul(0x2005, 0, 10, CO_SDO_CLI_BLOCK, 0);
	h_skip_all();
	h_fake(0xC0, 0x2005, 0, 0);
	h_skip_all();
	seg(0x01, data);
	seg(0x82, &data[7]);
	h_skip_all();
	h_fake(0xC1 | (2 << 2), 0, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_OUT_OF_MEM);
	expect_con(CO_SDO_AB_OUT_OF_MEM);
	zassert_equal(buf[10], 0xEE, "written past the capacity");
}

ZTEST(sdo_cli_errors, test_upload_more_or_less_than_indicated)
{
	/* 10 announced, 14 sent. */
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_fake(0x41, 0x2005, 0, 10);
	seg(0x00, data);
	h_skip_all();
	seg(0x11, &data[7]);
	h_expect_abort(0x2005, 0, CO_SDO_AB_DATA_LONG);
	expect_con(CO_SDO_AB_DATA_LONG);

	/* 20 announced, 14 sent. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_fake(0x41, 0x2005, 0, 20);
	seg(0x00, data);
	h_skip_all();
	seg(0x11, &data[7]);
	h_expect_abort(0x2005, 0, CO_SDO_AB_DATA_SHORT);
	expect_con(CO_SDO_AB_DATA_SHORT);

	/* Block upload: 10 announced, the end says 14. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_fake(0xC2, 0x2005, 0, 10);
	seg(0x01, data);
	seg(0x82, &data[7]);
	h_skip_all();
	h_fake(0xC1, 0, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_DATA_LONG);
	expect_con(CO_SDO_AB_DATA_LONG);
}

ZTEST(sdo_cli_errors, test_expedited_upload_without_size_takes_4_bytes)
{
	start_ul(0x2000, 0, 8, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_fake(0x42, 0x2000, 0, 0xA1B2C3D4);
	expect_con(0);
	zassert_equal(rec()->size, 4U);
	zassert_equal(sys_get_le32(buf), 0xA1B2C3D4);
}

/* --- Block upload ------------------------------------------------------------------------ */

/* Block upload of 10 bytes with the CRC field @p crc; returns after the end request. */
static void blk_up_10(uint8_t sc, uint16_t crc)
{
	uint8_t d[8] = {0xC1 | (4 << 2)};

	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_expect_raw((uint8_t[8]){CLI_CRC ? 0xA4 : 0xA0, 0x05, 0x20, 0,
				  CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE, CONFIG_CANOPEN_SDO_CLIENT_PST,
				  0, 0});
	h_fake(0xC2 | sc, 0x2005, 0, 10);
	h_expect(0xA3, 0, 0, 0);
	seg(0x01, data);
	h_expect_none();
	seg(0x82, &data[7]);
	h_expect_raw((uint8_t[8]){0xA2, 2, CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE, 0, 0, 0, 0, 0});
	sys_put_le16(crc, &d[1]);
	h_fake_raw(d);
}

ZTEST(sdo_cli_errors, test_block_upload_crc_checked)
{
	uint16_t good = ref_crc16(data, 10);

	if (!CLI_CRC) {
		ztest_test_skip();
	}
	blk_up_10(0x04, good ^ 0x0100);
	h_expect_abort(0x2005, 0, CO_SDO_AB_CRC);
	expect_con(CO_SDO_AB_CRC);

	memset(rec(), 0, sizeof(*rec()));
	blk_up_10(0x04, good);
	h_expect(0xA1, 0, 0, 0);
	expect_con(0);
	zassert_equal(rec()->size, 10U);
	zassert_mem_equal(buf, data, 10);
	zassert_equal(buf[10], 0xEE);
}

ZTEST(sdo_cli_errors, test_block_upload_without_server_crc_ignores_the_field)
{
	blk_up_10(0x00, 0xDEAD);
	h_expect(0xA1, 0, 0, 0);
	expect_con(0);
	zassert_mem_equal(buf, data, 10);
}

ZTEST(sdo_cli_errors, test_abort_05040003_block_upload_sequence_number)
{
	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_fake(0xC6, 0x2005, 0, 10);
	h_skip_all();
	seg(0x00, data);
	h_expect_abort(0x2005, 0, CO_SDO_AB_SEQ_NUM);
	expect_con(CO_SDO_AB_SEQ_NUM);

	if (CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE < 127) {
		memset(rec(), 0, sizeof(*rec()));
		start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
		h_fake(0xC6, 0x2005, 0, 10);
		h_skip_all();
		seg(CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE + 1, data);
		h_expect_abort(0x2005, 0, CO_SDO_AB_SEQ_NUM);
		expect_con(CO_SDO_AB_SEQ_NUM);
	}
}

/* A segment lost: the client acknowledges the last one in order; the server resends. */
ZTEST(sdo_cli_errors, test_block_upload_gap_acknowledges_last_in_order)
{
	uint8_t d[8] = {0xC1 | (0 << 2)};
	struct co_sdo_cli_stats st;

	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_fake(0xC6, 0x2005, 0, 35);
	h_skip_all();
	seg(0x01, data);
	seg(0x02, &data[7]);
	/* 3 lost. */
	seg(0x04, &data[21]);
	seg(0x85, &data[28]);
	h_expect_raw((uint8_t[8]){0xA2, 2, CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE, 0, 0, 0, 0, 0});
	/* Resent from 3, numbered from 1; a duplicate of the old 2 in between is ignored. */
	seg(0x01, &data[14]);
	seg(0x01, &data[14]);
	seg(0x02, &data[21]);
	seg(0x83, &data[28]);
	h_expect_raw((uint8_t[8]){0xA2, 3, CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE, 0, 0, 0, 0, 0});
	sys_put_le16(CLI_CRC ? ref_crc16(data, 35) : 0, &d[1]);
	h_fake_raw(d);
	h_expect(0xA1, 0, 0, 0);
	expect_con(0);
	zassert_equal(rec()->size, 35U);
	zassert_mem_equal(buf, data, 35);
	co_sdo_cli_get_stats(h_cli(C), &st);
	zassert_equal(st.blk_seg_ignored, 3U);
}

ZTEST(sdo_cli_errors, test_block_upload_protocol_switch_to_segmented)
{
	if (CONFIG_CANOPEN_SDO_CLIENT_PST == 0) {
		/* No switch asked for: a normal response is a wrong command. */
		start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
		h_skip_all();
		h_fake(0x41, 0x2005, 0, 10);
		h_expect_abort(0x2005, 0, CO_SDO_AB_CMD);
		expect_con(CO_SDO_AB_CMD);
		return;
	}
	start_ul(0x2005, 0, 100, CO_SDO_CLI_BLOCK, 0);
	h_skip_all();
	h_fake(0x41, 0x2005, 0, 10);
	h_expect(0x60, 0, 0, 0);
	seg(0x00, data);
	h_expect(0x70, 0, 0, 0);
	seg(0x11 | (4 << 1), &data[7]);
	expect_con(0);
	zassert_equal(rec()->size, 10U);
	zassert_mem_equal(buf, data, 10);
}

/* --- Block download ---------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_block_download_partial_ack_resends_and_crc)
{
	uint8_t d[8];
	uint8_t end[8] = {0xC1 | (5 << 2)};

	/* 30 bytes: 5 segments, the last with 2 bytes. */
	start_dl(0x2005, 0, 30, CO_SDO_CLI_BLOCK);
	h_expect(CLI_CRC ? 0xC6 : 0xC2, 0x2005, 0, 30);
	h_fake(0xA4, 0x2005, 0, 3);
	for (int i = 0; i < 3; i++) {
		d[0] = i + 1;
		memcpy(&d[1], &data[7 * i], 7);
		h_expect_raw(d);
	}
	h_expect_none();
	/* Only the first arrived: resend from segment 2 (data 7..), renumbered. */
	h_fake_raw((uint8_t[8]){0xA2, 1, 3});
	for (int i = 0; i < 3; i++) {
		d[0] = i + 1;
		memcpy(&d[1], &data[7 * (i + 1)], 7);
		h_expect_raw(d);
	}
	/* All three arrived; the next sub-block has 2 bytes of data in its only segment. */
	h_fake_raw((uint8_t[8]){0xA2, 3, 3});
	memset(d, 0, sizeof(d));
	d[0] = 0x81;
	memcpy(&d[1], &data[28], 2);
	h_expect_raw(d);
	h_fake_raw((uint8_t[8]){0xA2, 1, 3});
	if (CLI_CRC) {
		sys_put_le16(ref_crc16(data, 30), &end[1]);
	}
	h_expect_raw(end);
	h_fake(0xA1, 0, 0, 0);
	expect_con(0);
	zassert_equal(rec()->size, 30U);
}

ZTEST(sdo_cli_errors, test_block_download_server_without_crc)
{
	uint8_t d[8] = {0x81};

	start_dl(0x2005, 0, 3, CO_SDO_CLI_BLOCK);
	h_skip_all();
	h_fake(0xA0, 0x2005, 0, 127);
	memcpy(&d[1], data, 3);
	h_expect_raw(d);
	h_fake_raw((uint8_t[8]){0xA2, 1, 127});
	/* n = 4, CRC field 0. */
	h_expect(0xC1 | (4 << 2), 0, 0, 0);
	h_fake(0xA1, 0, 0, 0);
	expect_con(0);
}

ZTEST(sdo_cli_errors, test_abort_05040002_and_05040003_block_download)
{
	/* blksize 0 in the initiate response. */
	start_dl(0x2005, 0, 30, CO_SDO_CLI_BLOCK);
	h_skip_all();
	h_fake(0xA4, 0x2005, 0, 0);
	h_expect_abort(0x2005, 0, CO_SDO_AB_BLK_SIZE);
	expect_con(CO_SDO_AB_BLK_SIZE);

	/* blksize 128 in an acknowledgement. */
	memset(rec(), 0, sizeof(*rec()));
	start_dl(0x2005, 0, 30, CO_SDO_CLI_BLOCK);
	h_fake(0xA4, 0x2005, 0, 2);
	h_skip_all();
	h_fake_raw((uint8_t[8]){0xA2, 2, 128});
	h_expect_abort(0x2005, 0, CO_SDO_AB_BLK_SIZE);
	expect_con(CO_SDO_AB_BLK_SIZE);

	/* ackseq beyond the segments sent. */
	memset(rec(), 0, sizeof(*rec()));
	start_dl(0x2005, 0, 30, CO_SDO_CLI_BLOCK);
	h_fake(0xA4, 0x2005, 0, 2);
	h_skip_all();
	h_fake_raw((uint8_t[8]){0xA2, 3, 2});
	h_expect_abort(0x2005, 0, CO_SDO_AB_SEQ_NUM);
	expect_con(CO_SDO_AB_SEQ_NUM);
}

/* --- NMT --------------------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_nmt_reset_during_transfer_confirms_general_error)
{
	start_ul(0x2005, 0, 100, CO_SDO_CLI_AUTO, 0);
	h_fake(0x41, 0x2005, 0, 20);
	h_skip_all();
	/* Reset Communication of the client's node. */
	h_nmt(0x82, CLI_ID);
	zassert_equal(rec()->calls, 1U);
	zassert_equal(rec()->code, CO_SDO_AB_GENERAL);
	/* No abort frame: the node was Initialising. */
	h_expect_none();
	/* The transfer is gone: a late segment is ignored. */
	seg(0x00, data);
	expect_con(CO_SDO_AB_GENERAL);
	/* Client 2 has no 1280h: its binding survived. Client 0's 1280h is back to invalid. */
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_fake(0x43, 0x2000, 0, 7);
	expect_con(0);
	zassert_equal(co_sdo_cli_upload_req(h_cli(0), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(0)),
		      -ENOTCONN);
}

ZTEST(sdo_cli_errors, test_nmt_reset_node_and_stop)
{
	start_dl(0x2005, 0, 100, CO_SDO_CLI_BLOCK);
	h_skip_all();
	h_nmt(0x81, CLI_ID);
	zassert_equal(rec()->calls, 1U);
	zassert_equal(rec()->code, CO_SDO_AB_GENERAL);
	h_expect_none();
	/* Reset Node restored 1280h (client 0 unbound); client 2 keeps its binding. */
	zassert_ok(co_sdo_cli_set_server(h_cli(0), SRV_ID));

	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_skip_all();
	h_nmt(0x02, CLI_ID);
	zassert_equal(rec()->calls, 1U);
	zassert_equal(rec()->code, CO_SDO_AB_GENERAL);
	h_expect_none();
	zassert_equal(co_sdo_cli_upload_req(h_cli(C), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(C)),
		      -ENETDOWN);
	h_nmt(0x01, CLI_ID);
	memset(rec(), 0, sizeof(*rec()));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	h_expect(0x40, 0x2000, 0, 0);
	h_fake(0x4F, 0x2000, 0, 9);
	expect_con(0);
	zassert_equal(rec()->size, 1U);
}

/* An NMT change made by the application confirms from the line, not inside the call. */
ZTEST(sdo_cli_errors, test_nmt_stop_by_application_confirms_from_the_line)
{
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	zassert_ok(co_nmt_req(&h.cnode, CO_NMT_CS_STOP));
	zassert_equal(rec()->calls, 0U);
	zassert_true(co_sdo_cli_busy(h_cli(C)));
	h_pump();
	zassert_equal(rec()->calls, 1U);
	zassert_equal(rec()->code, CO_SDO_AB_GENERAL);
}

/* --- Arguments --------------------------------------------------------------------------- */

ZTEST(sdo_cli_errors, test_request_argument_errors)
{
	zassert_equal(
		co_sdo_cli_upload_req(h_cli(C), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, NULL, NULL),
		-EINVAL);
	zassert_equal(co_sdo_cli_upload_req(h_cli(C), 0x2000, 0, NULL, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    NULL),
		      -EINVAL);
	zassert_equal(co_sdo_cli_download_req(h_cli(C), 0x2000, 0, NULL, 4, CO_SDO_CLI_AUTO, 0,
					      h_con, NULL),
		      -EINVAL);
	/* Client 3 is bound to nothing. */
	zassert_equal(
		co_sdo_cli_upload_req(h_cli(3), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con, NULL),
		-ENOTCONN);
	zassert_equal(co_sdo_cli_set_server(h_cli(3), 0), -EINVAL);
	zassert_equal(co_sdo_cli_set_server(h_cli(3), 128), -EINVAL);
	zassert_is_null(co_sdo_cli_get(&h.cnode, CONFIG_CANOPEN_SDO_CLIENTS));
	start_ul(0x2000, 0, 4, CO_SDO_CLI_AUTO, 0);
	zassert_equal(co_sdo_cli_set_server(h_cli(C), SRV_ID), -EBUSY);
	zassert_equal(co_sdo_cli_download_req(h_cli(C), 0x2000, 0, data, 4, CO_SDO_CLI_AUTO, 0,
					      h_con, NULL),
		      -EBUSY);
	/* A send error of the first frame: nothing starts. */
	zassert_equal(co_sdo_cli_abort_req(h_cli(C), CO_SDO_AB_GENERAL), 0);
	h_pump();
	memset(rec(), 0, sizeof(*rec()));
	h_skip_all();
	zassert_equal(co_sdo_cli_abort_req(h_cli(C), CO_SDO_AB_GENERAL), -EALREADY);
}

ZTEST_SUITE(sdo_cli_errors, NULL, NULL, before, NULL, NULL);
