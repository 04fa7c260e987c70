/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Transfers between the client and the SafeLine server: every protocol and size class. */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static uint8_t out[DOM_SIZE + 16];
static uint8_t in[DOM_SIZE + 16];

static void before(void *f)
{
	h_setup();
	zassert_ok(co_sdo_cli_set_server(h_cli(0), SRV_ID));
	zassert_ok(co_sdo_cli_set_server(h_cli(1), SRV2_ID));
	zassert_ok(co_sdo_cli_set_server(h_cli(2), FAKE_ID));
}

/* Download and wait; returns the abort code. */
static uint32_t dl(uint8_t num, uint16_t idx, uint8_t sub, const void *data, size_t len,
		   enum co_sdo_cli_mode mode)
{
	struct con_rec *rec = &h.con[num];

	memset(rec, 0, sizeof(*rec));
	zassert_ok(co_sdo_cli_download_req(h_cli(num), idx, sub, data, len, mode, 0, h_con, rec));
	h_run_for_con(rec, 10 * TIMEOUT_US);
	zassert_equal(rec->calls, 1U, "confirmed %u times", rec->calls);
	zassert_equal(rec->cli, h_cli(num));
	zassert_false(co_sdo_cli_busy(h_cli(num)));
	if (rec->code == 0U) {
		zassert_equal(rec->size, len);
	}
	return rec->code;
}

static uint32_t ul(uint8_t num, uint16_t idx, uint8_t sub, void *buf, size_t cap, size_t *len,
		   enum co_sdo_cli_mode mode)
{
	struct con_rec *rec = &h.con[num];

	memset(rec, 0, sizeof(*rec));
	zassert_ok(co_sdo_cli_upload_req(h_cli(num), idx, sub, buf, cap, mode, 0, h_con, rec));
	h_run_for_con(rec, 10 * TIMEOUT_US);
	zassert_equal(rec->calls, 1U, "confirmed %u times", rec->calls);
	*len = rec->size;
	return rec->code;
}

/* Value of the server's dictionary. */
static void srv_read(uint16_t idx, void *buf, size_t cap, size_t *len)
{
	zassert_equal(h_od_read(&h.snode, idx, 0, 0, buf, cap, len, CO_OD_WRITER_APP), 0U);
}

/* Count the frames on 600h + SRV_ID / 580h + SRV_ID since the last call. */
static void count_frames(uint32_t *c2s, uint32_t *s2c, uint8_t *first_b0, uint8_t *first_rsp)
{
	bool first = true, first_r = true;

	*c2s = 0;
	*s2c = 0;
	for (; h.rd != h.wr; h.rd++) {
		const struct can_frame *f = &h.ring[h.rd % RING];

		if (f->id == 0x600U + SRV_ID) {
			(*c2s)++;
			if (first && first_b0 != NULL) {
				*first_b0 = f->data[0];
			}
			first = false;
		} else if (f->id == 0x580U + SRV_ID) {
			(*s2c)++;
			if (first_r && first_rsp != NULL) {
				*first_rsp = f->data[0];
			}
			first_r = false;
		}
	}
}

ZTEST(sdo_cli_transfers, test_expedited_download_and_upload_1_to_4_bytes)
{
	static const struct {
		uint16_t idx;
		uint8_t len;
		uint8_t b0;
	} objs[] = {{0x2002, 1, 0x2F}, {0x2001, 2, 0x2B}, {0x2003, 3, 0x27}, {0x2000, 4, 0x23}};

	for (size_t i = 0; i < ARRAY_SIZE(objs); i++) {
		uint8_t v[4] = {0x11 + i, 0x22, 0x33, 0x44};
		uint8_t r[8] = {0};
		size_t len = 0;
		uint32_t c2s, s2c;
		uint8_t b0 = 0, rsp = 0;

		h_skip_all();
		zassert_equal(dl(0, objs[i].idx, 0, v, objs[i].len, CO_SDO_CLI_AUTO), 0U);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(c2s, 1U);
		zassert_equal(s2c, 1U);
		zassert_equal(b0, objs[i].b0, "byte 0 %02x", b0);
		srv_read(objs[i].idx, r, sizeof(r), &len);
		zassert_equal(len, objs[i].len);
		zassert_mem_equal(r, v, len);

		memset(r, 0, sizeof(r));
		zassert_equal(ul(0, objs[i].idx, 0, r, sizeof(r), &len, CO_SDO_CLI_AUTO), 0U);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(c2s, 1U);
		zassert_equal(s2c, 1U);
		zassert_equal(b0, 0x40);
		zassert_equal(rsp, 0x43 | ((4 - objs[i].len) << 2));
		zassert_equal(len, objs[i].len);
		zassert_mem_equal(r, v, len);
	}
}

ZTEST(sdo_cli_transfers, test_segmented_download_and_upload_sizes)
{
	static const size_t sizes[] = {0, 1, 4, 5, 6, 7, 8, 13, 14, 15, 100, 888, 889, 890, 4000};

	for (size_t i = 0; i < ARRAY_SIZE(sizes); i++) {
		size_t n = sizes[i];
		size_t len = 0;
		uint32_t c2s, s2c;
		uint8_t b0 = 0, rsp = 0;
		size_t segs = n == 0 ? 1 : DIV_ROUND_UP(n, 7);

		h_fill(out, n, (uint32_t)i);
		h_skip_all();
		/* AUTO goes segmented above 4 bytes (and for 0); SEGMENTED always. */
		zassert_equal(
			dl(0, 0x2005, 0, out, n, n > 4 ? CO_SDO_CLI_AUTO : CO_SDO_CLI_SEGMENTED),
			0U, "size %zu", n);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(b0, 0x21, "size %zu", n);
		zassert_equal(c2s, 1 + segs);
		zassert_equal(s2c, 1 + segs);
		srv_read(0x2005, in, sizeof(in), &len);
		zassert_equal(len, n);
		zassert_mem_equal(in, out, n);

		memset(in, 0xEE, sizeof(in));
		zassert_equal(ul(0, 0x2005, 0, in, DOM_SIZE, &len, CO_SDO_CLI_AUTO), 0U, "size %zu",
			      n);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(len, n);
		zassert_mem_equal(in, out, n);
		/* Nothing written past the value. */
		zassert_equal(in[n], 0xEE);
		if (n > 4 || n == 0) {
			zassert_equal(rsp, 0x41);
			zassert_equal(c2s, 1 + segs);
		}
	}
}

ZTEST(sdo_cli_transfers, test_block_download_sizes)
{
	static const size_t sizes[] = {1, 6, 7, 8, 14, 15, 100, 888, 889, 890, 1000, 4000};

	for (size_t i = 0; i < ARRAY_SIZE(sizes); i++) {
		size_t n = sizes[i];
		size_t len = 0;
		uint32_t c2s, s2c;
		uint8_t b0 = 0, rsp = 0;

		h_fill(out, n, 100 + (uint32_t)i);
		h_skip_all();
		zassert_equal(dl(0, 0x2005, 0, out, n, CO_SDO_CLI_BLOCK), 0U, "size %zu", n);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(b0, CLI_CRC ? 0xC6 : 0xC2);
		zassert_equal(rsp, CLI_CRC ? 0xA4 : 0xA0);
		/* initiate + segments + end; the server answers each sub-block. */
		zassert_equal(c2s, 2 + DIV_ROUND_UP(n, 7), "size %zu: %u", n, c2s);
		srv_read(0x2005, in, sizeof(in), &len);
		zassert_equal(len, n);
		zassert_mem_equal(in, out, n);
	}
	/* A U32 by block transfer. */
	sys_put_le32(0xCAFEF00D, out);
	zassert_equal(dl(0, 0x2000, 0, out, 4, CO_SDO_CLI_BLOCK), 0U);
	{
		size_t len;

		srv_read(0x2000, in, 4, &len);
	}
	zassert_equal(sys_get_le32(in), 0xCAFEF00D);
}

ZTEST(sdo_cli_transfers, test_block_upload_sizes_and_protocol_switch)
{
	static const size_t sizes[] = {0, 1, 4, 5, 27, 28, 29, 100, 888, 889, 890, 1000, 4000};

	for (size_t i = 0; i < ARRAY_SIZE(sizes); i++) {
		size_t n = sizes[i];
		size_t len = 0;
		uint32_t c2s, s2c;
		uint8_t b0 = 0, rsp = 0;
		bool sw = CONFIG_CANOPEN_SDO_CLIENT_PST != 0 && n <= CONFIG_CANOPEN_SDO_CLIENT_PST;

		h_fill(out, n, 200 + (uint32_t)i);
		zassert_equal(h_od_write(&h.snode, 0x2005, 0, out, n, CO_OD_WRITER_APP), 0U);
		h_skip_all();
		memset(in, 0xEE, sizeof(in));
		zassert_equal(ul(0, 0x2005, 0, in, DOM_SIZE, &len, CO_SDO_CLI_BLOCK), 0U,
			      "size %zu", n);
		count_frames(&c2s, &s2c, &b0, &rsp);
		zassert_equal(b0, CLI_CRC ? 0xA4 : 0xA0);
		zassert_equal(len, n);
		zassert_mem_equal(in, out, n);
		zassert_equal(in[n], 0xEE);
		if (sw) {
			/* Protocol switch: a normal upload response. */
			zassert_equal(rsp >> 5, 2, "size %zu: %02x", n, rsp);
		} else {
			zassert_equal(rsp, CLI_CRC ? 0xC6 : 0xC2, "size %zu: %02x", n, rsp);
		}
	}
}

ZTEST(sdo_cli_transfers, test_segmented_small_download_to_u8)
{
	uint8_t v = 0x5A, r = 0;
	size_t len;

	zassert_equal(dl(0, 0x2002, 0, &v, 1, CO_SDO_CLI_SEGMENTED), 0U);
	srv_read(0x2002, &r, 1, &len);
	zassert_equal(r, 0x5A);
}

ZTEST(sdo_cli_transfers, test_server_abort_codes_are_confirmed)
{
	uint8_t v[8] = {1, 2, 3, 4, 5};
	size_t len;

	/* Size mismatch: 5 bytes into a U32 (the server says so). */
	zassert_equal(dl(0, 0x2000, 0, v, 5, CO_SDO_CLI_AUTO), CO_SDO_AB_DATA_LONG);
	zassert_equal(dl(0, 0x2000, 0, v, 2, CO_SDO_CLI_AUTO), CO_SDO_AB_DATA_SHORT);
	zassert_equal(dl(0, 0x2000, 0, v, 5, CO_SDO_CLI_BLOCK), CO_SDO_AB_DATA_LONG);
	zassert_equal(dl(0, 0x2004, 0, v, 4, CO_SDO_CLI_AUTO), CO_SDO_AB_READONLY);
	zassert_equal(dl(0, 0x2FFF, 0, v, 4, CO_SDO_CLI_AUTO), CO_SDO_AB_NO_OBJECT);
	zassert_equal(ul(0, 0x2FFF, 0, v, 8, &len, CO_SDO_CLI_AUTO), CO_SDO_AB_NO_OBJECT);
	zassert_equal(ul(0, 0x2FFF, 0, v, 8, &len, CO_SDO_CLI_BLOCK), CO_SDO_AB_NO_OBJECT);
	zassert_equal(ul(0, 0x2000, 7, v, 8, &len, CO_SDO_CLI_AUTO), CO_SDO_AB_NO_SUB);
}

ZTEST(sdo_cli_transfers, test_upload_longer_than_buffer_is_aborted_05040005)
{
	size_t len;
	struct co_sdo_srv_stats st;

	h_fill(out, 100, 7);
	zassert_equal(h_od_write(&h.snode, 0x2005, 0, out, 100, CO_OD_WRITER_APP), 0U);
	zassert_equal(ul(0, 0x2005, 0, in, 99, &len, CO_SDO_CLI_AUTO), CO_SDO_AB_OUT_OF_MEM);
	zassert_equal(ul(0, 0x2005, 0, in, 99, &len, CO_SDO_CLI_BLOCK), CO_SDO_AB_OUT_OF_MEM);
	/* Expedited value into a buffer of 2. */
	zassert_equal(ul(0, 0x2000, 0, in, 2, &len, CO_SDO_CLI_AUTO), CO_SDO_AB_OUT_OF_MEM);
	/* The server heard the aborts (the expedited one after it had finished). */
	co_sdo_srv_get_stats(&h.snode.sdo_srv[0], &st);
	zassert_equal(st.aborts_received, 2U);
	zassert_equal(st.last_abort, CO_SDO_AB_OUT_OF_MEM);
	zassert_false(co_sdo_srv_busy(&h.snode.sdo_srv[0]));
}

/* Block download while the controller pushes back: the TX queue fills, nothing is lost. */
ZTEST(sdo_cli_transfers, test_block_download_paced_by_tx_space)
{
	struct co_line_stats ls;
	struct con_rec *rec = &h.con[0];
	size_t len;

	h_fill(out, DOM_SIZE, 77);
	h.sink_result = -EAGAIN;
	zassert_ok(co_sdo_cli_download_req(h_cli(0), 0x2005, 0, out, DOM_SIZE, CO_SDO_CLI_BLOCK, 0,
					   h_con, rec));
	/* Let the initiate and its answer through while the controller accepts. */
	h.sink_result = 0;
	h_pump();
	h.sink_result = -EAGAIN;
	h_advance(3 * MS);
	co_line_get_stats(&h.line, &ls);
	zassert_true(ls.tx_queued > 0U);
	zassert_equal(ls.tx_dropped, 0U);
	/* The client stops with a quarter of the queue free for the line's other traffic. */
	zassert_equal(co_line_tx_space(&h.line), MAX(2, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE / 4));
	h.sink_result = 0;
	h_run_for_con(rec, 10 * TIMEOUT_US);
	zassert_equal(rec->calls, 1U);
	zassert_equal(rec->code, 0U);
	co_line_get_stats(&h.line, &ls);
	zassert_equal(ls.tx_dropped, 0U);
	srv_read(0x2005, in, sizeof(in), &len);
	zassert_equal(len, DOM_SIZE);
	zassert_mem_equal(in, out, DOM_SIZE);
	{
		struct co_sdo_cli_stats cs;

		co_sdo_cli_get_stats(h_cli(0), &cs);
		zassert_true(cs.tx_retries > 0U);
	}
}

/*
 * A block download on a line of limited rate (one frame per 250 us, about 500 kbit/s) with a
 * short TX queue (16) that it shares with the client node's heartbeat (20 ms): the client
 * sends its sub-blocks of 127 segments as the queue has room, so the download completes,
 * nothing is dropped, and every heartbeat goes out on time, late at most by the segments
 * queued before it.
 */
ZTEST(sdo_cli_transfers, test_block_download_leaves_room_for_the_heartbeat)
{
	const uint16_t hb_ms = 20;
	const uint64_t frame_us = 250;
	/* What the client may have queued ahead of a heartbeat, sent at one frame per slot. */
	const uint64_t late_us = (CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE -
				  MAX(2, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE / 4) + 1) *
				 frame_us;
	struct con_rec *rec = &h.con[0];
	struct co_line_stats ls;
	uint64_t start, end, prev = 0, hb_at[64];
	uint32_t n_hb = 0, n_seg = 0, max_seq = 0, last_seq = 0;
	size_t len;
	uint8_t hb_le[2];

	BUILD_ASSERT(CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE < 128, "a sub-block must not fit the queue");
	/* The dictionary takes wire bytes: little-endian on any host. */
	sys_put_le16(hb_ms, hb_le);
	zassert_equal(h_od_write(&h.cnode, 0x1017, 0, hb_le, 2, CO_OD_WRITER_APP), 0U);
	h_advance(1 * MS);
	h_fill(out, DOM_SIZE, 91);
	h.bus_paced = true;
	h.rd = h.wr;
	start = h.now;
	zassert_ok(co_sdo_cli_download_req(h_cli(0), 0x2005, 0, out, DOM_SIZE, CO_SDO_CLI_BLOCK, 0,
					   h_con, rec));
	while (rec->calls == 0U && h.now < start + 5000 * MS) {
		/* The bus takes one frame per slot. */
		h.bus_credit = 1;
		co_line_process(&h.line, h.now);
		h_advance(frame_us);
	}
	/* Two heartbeat periods more, to see the one after the download too. */
	end = h.now + 2U * hb_ms * MS;
	while (h.now < end) {
		h.bus_credit = 1;
		co_line_process(&h.line, h.now);
		h_advance(frame_us);
	}
	zassert_equal(rec->calls, 1U);
	zassert_equal(rec->code, 0U, "download %08x", rec->code);
	srv_read(0x2005, in, sizeof(in), &len);
	zassert_equal(len, DOM_SIZE);
	zassert_mem_equal(in, out, DOM_SIZE);
	co_line_get_stats(&h.line, &ls);
	zassert_equal(ls.tx_dropped, 0U, "no frame of the line dropped");

	for (uint32_t i = h.rd; i != h.wr; i++) {
		const struct can_frame *f = &h.ring[i % RING];

		if (f->id == 0x700U + CLI_ID) {
			zassert_true(n_hb < ARRAY_SIZE(hb_at));
			hb_at[n_hb++] = h.ring_at[i % RING];
		} else if (f->id == 0x600U + SRV_ID) {
			/* Between the initiate and the end request: the segments. */
			if (n_seg > 1U) {
				max_seq = MAX(max_seq, last_seq);
			}
			last_seq = f->data[0] & 0x7FU;
			n_seg++;
		}
	}
	n_seg -= 2U;
	zassert_equal(n_seg, DIV_ROUND_UP(DOM_SIZE, 7U), "every segment once (%u)", n_seg);
	zassert_equal(max_seq, CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE,
		      "sub-blocks of the server's size");
	zassert_true(n_hb >= (h.now - start) / (hb_ms * MS) - 1U, "%u heartbeats in %llu us", n_hb,
		     (unsigned long long)(h.now - start));
	for (uint32_t i = 0; i < n_hb; i++) {
		if (i > 0U) {
			uint64_t gap = hb_at[i] - prev;

			zassert_true(gap + late_us >= hb_ms * MS && gap <= hb_ms * MS + late_us,
				     "heartbeat %u after %llu us", i, (unsigned long long)gap);
		}
		prev = hb_at[i];
	}
}

/*
 * Three clients to three servers at once: 0 and 1 (with 1280h/1281h) download, 3 (bound by
 * co_sdo_cli_set_server() only) uploads by block; 2 talks to the scripted server meanwhile.
 */
ZTEST(sdo_cli_transfers, test_several_clients_to_several_servers_concurrently)
{
	static uint8_t o[4][2000], r[4][2000];
	size_t len;

	zassert_ok(co_sdo_cli_set_server(h_cli(3), SRV3_ID));
	for (int i = 0; i < 4; i++) {
		h_fill(o[i], sizeof(o[i]), 300 + i);
		memset(&h.con[i], 0, sizeof(h.con[i]));
	}
	zassert_equal(h_od_write(&h.snode3, 0x2005, 0, o[3], 1999, CO_OD_WRITER_APP), 0U);
	zassert_ok(co_sdo_cli_download_req(h_cli(0), 0x2005, 0, o[0], 2000, CO_SDO_CLI_BLOCK, 0,
					   h_con, CON(0)));
	zassert_ok(co_sdo_cli_download_req(h_cli(1), 0x2005, 0, o[1], 1500, CO_SDO_CLI_AUTO, 0,
					   h_con, CON(1)));
	zassert_ok(co_sdo_cli_upload_req(h_cli(2), 0x2004, 0, r[2], 4, CO_SDO_CLI_AUTO, 0, h_con,
					 CON(2)));
	zassert_ok(co_sdo_cli_upload_req(h_cli(3), 0x2005, 0, r[3], 2000, CO_SDO_CLI_BLOCK, 0,
					 h_con, CON(3)));
	zassert_equal(co_sdo_cli_upload_req(h_cli(0), 0x2004, 0, r[0], 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(0)),
		      -EBUSY);
	h_pump();
	/* The scripted server answers client 2 in the middle of it. */
	h_expect(0x40, 0x2004, 0, 0);
	h_fake(0x43, 0x2004, 0, 0xA5A5A5A5);
	for (int i = 0; i < 4; i++) {
		h_run_for_con(&h.con[i], 10 * TIMEOUT_US);
	}
	for (int i = 0; i < 4; i++) {
		zassert_equal(h.con[i].calls, 1U, "client %d", i);
		zassert_equal(h.con[i].code, 0U, "client %d: %08x", i, h.con[i].code);
	}
	zassert_equal(h.con[0].size, 2000U);
	zassert_equal(h.con[1].size, 1500U);
	zassert_equal(h.con[2].size, 4U);
	zassert_equal(h.con[3].size, 1999U);
	zassert_equal(sys_get_le32(r[2]), 0xA5A5A5A5);
	zassert_mem_equal(r[3], o[3], 1999);
	zassert_equal(h_od_read(&h.snode, 0x2005, 0, 0, r[0], 2000, &len, CO_OD_WRITER_APP), 0U);
	zassert_equal(len, 2000U);
	zassert_mem_equal(r[0], o[0], 2000);
	zassert_equal(h_od_read(&h.snode2, 0x2005, 0, 0, r[1], 2000, &len, CO_OD_WRITER_APP), 0U);
	zassert_equal(len, 1500U);
	zassert_mem_equal(r[1], o[1], 1500);
}

/* A confirmation starts the next transfer on the same client. */
static void chain_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data)
{
	h_con(cli, code, size, user_data);
	if (h.con[0].calls == 1U) {
		zassert_false(co_sdo_cli_busy(cli));
		zassert_ok(co_sdo_cli_upload_req(cli, 0x2000, 0, in, 4, CO_SDO_CLI_AUTO, 0,
						 chain_con, user_data));
	}
}

ZTEST(sdo_cli_transfers, test_confirmation_may_start_the_next_transfer)
{
	uint32_t v = 0x01020304;

	sys_put_le32(v, out);
	zassert_ok(co_sdo_cli_download_req(h_cli(0), 0x2000, 0, out, 4, CO_SDO_CLI_AUTO, 0,
					   chain_con, CON(0)));
	h_run_for_con(&h.con[0], 10 * TIMEOUT_US);
	h_advance(10 * MS);
	zassert_equal(h.con[0].calls, 2U);
	zassert_equal(h.con[0].code, 0U);
	zassert_equal(sys_get_le32(in), v);
}

/* An empty value in every protocol, into a NULL buffer of capacity 0. */
ZTEST(sdo_cli_transfers, test_empty_values_every_protocol)
{
	static const enum co_sdo_cli_mode modes[] = {CO_SDO_CLI_AUTO, CO_SDO_CLI_SEGMENTED,
						     CO_SDO_CLI_BLOCK};

	for (size_t m = 0; m < ARRAY_SIZE(modes); m++) {
		size_t len = 99;

		zassert_equal(h_od_write(&h.snode, 0x2005, 0, out, 10, CO_OD_WRITER_APP), 0U);
		zassert_equal(dl(0, 0x2005, 0, NULL, 0, modes[m]), 0U, "mode %zu", m);
		srv_read(0x2005, in, sizeof(in), &len);
		zassert_equal(len, 0U, "mode %zu", m);
		len = 99;
		zassert_equal(ul(0, 0x2005, 0, NULL, 0, &len, modes[m]), 0U, "mode %zu", m);
		zassert_equal(len, 0U);
	}
	zassert_equal(co_sdo_cli_abort_req(h_cli(0), 0), -EINVAL);
}

ZTEST_SUITE(sdo_cli_transfers, NULL, NULL, before, NULL, NULL);
