/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

struct harness h;

/* --- Node and line ----------------------------------------------------------------------- */

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (h.sink_result != 0) {
		return h.sink_result;
	}
	zassert_true(h.wr - h.rd < RING, "frame ring overflow");
	h.ring[h.wr++ % RING] = *frame;
	return 0;
}

static uint32_t hook_2007(struct co_od *od, struct co_od_req *req, void *user_data)
{
	return h.hook_code;
}

/* --- Provider for 3000h-30FFh ------------------------------------------------------------ */

static uint32_t prov_info(const struct co_od_provider *p, struct co_od_info *info)
{
	if (info->index > IDX_SHRINKS) {
		return CO_SDO_AB_NO_OBJECT;
	}
	if (info->sub != 0U) {
		return CO_SDO_AB_NO_SUB;
	}
	info->dtype = CO_DTYPE_DOMAIN;
	info->limit = NULL;
	switch (info->index) {
	case IDX_DOM:
		info->access = CO_OD_ACCESS_RW;
		info->flags = CO_OD_F_STREAM;
		info->size = DOM_CAP;
		break;
	case IDX_BROKEN:
		info->access = CO_OD_ACCESS_RO;
		info->flags = 0;
		info->size = BROKEN_LEN;
		break;
	default:
		info->access = CO_OD_ACCESS_RO;
		info->flags = 0;
		info->size = 100;
		break;
	}
	return 0;
}

static uint32_t prov_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	return info->index == IDX_DOM ? h.dom_len : info->size;
}

static uint32_t prov_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	uint32_t end;

	*len = 0;
	switch (info->index) {
	case IDX_DOM:
		end = h.dom_len;
		break;
	case IDX_BROKEN:
		if (offset >= BROKEN_AT) {
			return CO_SDO_AB_HW;
		}
		end = BROKEN_AT;
		break;
	default:
		end = 10;
		break;
	}
	if (offset >= end) {
		return 0;
	}
	*len = MIN(cap, end - offset);
	if (info->index == IDX_DOM) {
		memcpy(buf, &h.dom[offset], *len);
	} else {
		for (size_t i = 0; i < *len; i++) {
			((uint8_t *)buf)[i] = (uint8_t)(offset + i);
		}
	}
	return 0;
}

/* Streamed writes: stage the chunks, commit with the last one, drop on an abort. */
static uint32_t prov_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	zassert_equal(info->index, IDX_DOM);
	if (data == NULL && len == 0U) {
		h.stream_aborts++;
		return 0;
	}
	if ((uint64_t)offset + len > DOM_CAP) {
		return CO_SDO_AB_DATA_LONG;
	}
	memcpy(&h.stage[offset], data, len);
	h.chunks++;
	h.chunk_max = MAX(h.chunk_max, (uint32_t)len);
	if (last) {
		memcpy(h.dom, h.stage, offset + len);
		h.dom_len = offset + (uint32_t)len;
		h.commits++;
	}
	return 0;
}

static const struct co_od_provider_api prov_api = {
	.info = prov_info,
	.length = prov_length,
	.read = prov_read,
	.write = prov_write,
};

void h_setup(void)
{
	const struct co_od_hook hook = {
		.index_first = 0x2007,
		.index_last = 0x2007,
		.sub_first = 0,
		.sub_last = 0,
		.validate = hook_2007,
		.user_data = &h,
	};

	memset(&h, 0, sizeof(h));
	h.now = 1000 * MS;
	h.cli_tx = 0x600U + NODE_ID;
	h.cli_rx = 0x580U + NODE_ID;
	h.prov.api = &prov_api;
	h.prov.index_first = IDX_DOM;
	h.prov.index_last = 0x30ff;
	co_line_init_sim(&h.line, "sim", sink, NULL);
	zassert_ok(co_node_init(&h.node, "dut", &h.line, &sdo_test_od_def, &h.ram, NODE_ID));
	co_node_lock(&h.node);
	zassert_ok(co_od_provider_register(co_node_od(&h.node), &h.prov));
	zassert_ok(co_od_hook_register(co_node_od(&h.node), &hook));
	co_node_unlock(&h.node);
	zassert_ok(co_node_start(&h.node));
	/* Boot-up. */
	zassert_true(h_pending() >= 1U);
	zassert_equal(h.ring[0].id, 0x700U + NODE_ID);
	h.rd = h.wr;
}

void h_run_until(uint64_t at)
{
	while (true) {
		uint64_t next = co_line_next_deadline(&h.line);

		if (next == UINT64_MAX || next > at) {
			break;
		}
		h.now = MAX(h.now, next);
		co_line_process(&h.line, h.now);
	}
	h.now = at;
	co_line_process(&h.line, h.now);
}

void h_advance(uint64_t us)
{
	h_run_until(h.now + us);
}

void h_nmt(uint8_t cs)
{
	struct can_frame f = {.id = 0, .dlc = 2, .data = {cs, NODE_ID}};

	co_line_rx(&h.line, &f, h.now);
}

/* --- Frames ------------------------------------------------------------------------------ */

void h_send_dlc(const uint8_t *d, uint8_t dlc)
{
	struct can_frame f = {.id = h.cli_tx, .dlc = dlc, .flags = h.cli_ext ? CAN_FRAME_IDE : 0};

	memcpy(f.data, d, dlc);
	co_line_rx(&h.line, &f, h.now);
}

void h_send(const uint8_t d[8])
{
	h_send_dlc(d, 8);
}

void h_req(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v)
{
	uint8_t d[8] = {b0};

	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	sys_put_le32(v, &d[4]);
	h_send(d);
}

uint32_t h_pending(void)
{
	return h.wr - h.rd;
}

const struct can_frame *h_next(void)
{
	const struct can_frame *f;

	zassert_true(h.rd < h.wr, "no frame from the server");
	f = &h.ring[h.rd++ % RING];
	zassert_equal(f->id, h.cli_rx, "frame on %x, expected %x", f->id, h.cli_rx);
	zassert_equal(f->dlc, 8, "SDO frame with DLC %u", f->dlc);
	zassert_equal((f->flags & CAN_FRAME_IDE) != 0, h.cli_ext, "wrong frame format");
	return f;
}

void h_expect(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v)
{
	const struct can_frame *f = h_next();
	uint8_t d[8] = {b0};

	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	sys_put_le32(v, &d[4]);
	zassert_mem_equal(f->data, d, 8,
			  "got %02x %02x %02x %02x %02x %02x %02x %02x, expected %02x %02x %02x "
			  "%02x %02x %02x %02x %02x",
			  f->data[0], f->data[1], f->data[2], f->data[3], f->data[4], f->data[5],
			  f->data[6], f->data[7], d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7]);
}

void h_expect_abort(uint16_t idx, uint8_t sub, uint32_t code)
{
	h_expect(0x80, idx, sub, code);
}

void h_expect_none(void)
{
	zassert_equal(h.rd, h.wr, "unexpected frame %02x...", h.ring[h.rd % RING].data[0]);
}

struct co_sdo_srv_stats h_stats(uint8_t num)
{
	struct co_sdo_srv_stats s;

	co_sdo_srv_get_stats(co_sdo_srv_get(&h.node, num), &s);
	return s;
}

uint32_t h_get_u32(uint16_t idx, uint8_t sub)
{
	uint32_t v = 0;

	co_node_lock(&h.node);
	zassert_ok(co_od_get_u32(co_node_od(&h.node), idx, sub, &v));
	co_node_unlock(&h.node);
	return v;
}

uint32_t h_set(uint16_t idx, uint8_t sub, const void *data, size_t len, enum co_od_writer w)
{
	uint32_t ab;

	co_node_lock(&h.node);
	ab = co_od_write(co_node_od(&h.node), idx, sub, data, len, w);
	co_node_unlock(&h.node);
	return ab;
}

void h_fill(uint8_t *p, uint32_t len, uint32_t seed)
{
	uint32_t x = seed * 2654435761U + 1U;

	for (uint32_t i = 0; i < len; i++) {
		x = x * 1103515245U + 12345U;
		p[i] = (uint8_t)(x >> 16);
	}
}

uint16_t ref_crc16(const uint8_t *p, uint32_t len)
{
	uint16_t crc = 0;

	for (uint32_t i = 0; i < len; i++) {
		crc ^= (uint16_t)(p[i] << 8);
		for (int b = 0; b < 8; b++) {
			crc = (crc & 0x8000U) ? (uint16_t)((crc << 1) ^ 0x1021U)
					      : (uint16_t)(crc << 1);
		}
	}
	return crc;
}

/* --- Client ------------------------------------------------------------------------------ */

/* If @p f is an abort, check its multiplexer and return the code; else 0. */
static uint32_t abort_of(const struct can_frame *f, uint16_t idx, uint8_t sub)
{
	if (f->data[0] != 0x80) {
		return 0;
	}
	zassert_equal(sys_get_le16(&f->data[1]), idx, "abort names %04x",
		      sys_get_le16(&f->data[1]));
	zassert_equal(f->data[3], sub, "abort names sub %u", f->data[3]);
	zassert_not_equal(sys_get_le32(&f->data[4]), 0U, "abort code 0");
	return sys_get_le32(&f->data[4]);
}

static void check_mux(const struct can_frame *f, uint16_t idx, uint8_t sub)
{
	zassert_equal(sys_get_le16(&f->data[1]), idx);
	zassert_equal(f->data[3], sub);
}

static void check_zero(const uint8_t *p, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		zassert_equal(p[i], 0, "byte %u not 0", (unsigned int)i);
	}
}

uint32_t cli_dl_exp(uint16_t idx, uint8_t sub, const void *data, uint8_t len)
{
	uint8_t d[8] = {(uint8_t)(0x23 | ((4U - len) << 2))};
	const struct can_frame *f;
	uint32_t ab;

	zassert_true(len >= 1 && len <= 4);
	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	memcpy(&d[4], data, len);
	h_send(d);
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab == 0U) {
		zassert_equal(f->data[0], 0x60);
		check_mux(f, idx, sub);
		check_zero(&f->data[4], 4);
	}
	h_expect_none();
	return ab;
}

uint32_t cli_dl_seg(uint16_t idx, uint8_t sub, const void *data, uint32_t len, bool size_ind)
{
	const uint8_t *p = data;
	const struct can_frame *f;
	uint32_t off = 0;
	uint8_t toggle = 0;
	bool last;
	uint32_t ab;

	h_req(size_ind ? 0x21 : 0x20, idx, sub, size_ind ? len : 0);
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab != 0U) {
		return ab;
	}
	zassert_equal(f->data[0], 0x60);
	check_mux(f, idx, sub);
	check_zero(&f->data[4], 4);
	do {
		uint8_t d[8] = {0};
		uint32_t n = MIN(7U, len - off);

		last = off + n == len;
		d[0] = (uint8_t)((toggle << 4) | ((7U - n) << 1) | (last ? 1U : 0U));
		memcpy(&d[1], &p[off], n);
		h_send(d);
		f = h_next();
		ab = abort_of(f, idx, sub);
		if (ab != 0U) {
			return ab;
		}
		zassert_equal(f->data[0], 0x20 | (toggle << 4), "segment response %02x",
			      f->data[0]);
		check_zero(&f->data[1], 7);
		toggle ^= 1U;
		off += n;
	} while (!last);
	h_expect_none();
	return 0;
}

uint32_t cli_ul_cont(uint16_t idx, uint8_t sub, const struct can_frame *f, void *buf, uint32_t cap,
		     uint32_t *len)
{
	uint8_t *p = buf;
	uint32_t size;
	uint32_t off = 0;
	uint8_t toggle = 0;
	uint32_t ab = abort_of(f, idx, sub);

	if (ab != 0U) {
		return ab;
	}
	zassert_equal(f->data[0] >> 5, 2, "not an initiate upload response: %02x", f->data[0]);
	check_mux(f, idx, sub);
	if (f->data[0] & 0x02) {
		/* Expedited: the server always indicates the size. */
		zassert_true(f->data[0] & 0x01, "expedited upload without size");
		size = 4U - ((f->data[0] >> 2) & 3U);
		zassert_true(size <= cap);
		memcpy(p, &f->data[4], size);
		check_zero(&f->data[4 + size], 4 - size);
		*len = size;
		h_expect_none();
		return 0;
	}
	zassert_equal(f->data[0], 0x41, "segmented upload response %02x", f->data[0]);
	size = sys_get_le32(&f->data[4]);
	zassert_true(size == 0U || size > 4U, "segmented upload of %u bytes", size);
	while (true) {
		uint8_t d[8] = {(uint8_t)(0x60 | (toggle << 4))};
		uint32_t n;

		h_send(d);
		f = h_next();
		ab = abort_of(f, idx, sub);
		if (ab != 0U) {
			return ab;
		}
		zassert_equal(f->data[0] & 0xf0, toggle << 4, "upload segment %02x", f->data[0]);
		n = 7U - ((f->data[0] >> 1) & 7U);
		zassert_true(off + n <= cap);
		memcpy(&p[off], &f->data[1], n);
		check_zero(&f->data[1 + n], 7 - n);
		off += n;
		toggle ^= 1U;
		if (f->data[0] & 0x01) {
			break;
		}
		zassert_equal(n, 7, "short segment before the last");
	}
	zassert_equal(off, size, "uploaded %u of %u announced bytes", off, size);
	*len = off;
	h_expect_none();
	return 0;
}

uint32_t cli_ul(uint16_t idx, uint8_t sub, void *buf, uint32_t cap, uint32_t *len)
{
	h_req(0x40, idx, sub, 0);
	return cli_ul_cont(idx, sub, h_next(), buf, cap, len);
}

uint32_t cli_blk_dl(uint16_t idx, uint8_t sub, const void *data, uint32_t len, bool crc)
{
	const uint8_t *p = data;
	const struct can_frame *f;
	uint32_t off = 0;
	uint32_t last_len = 0;
	uint8_t blksize;
	bool last = false;
	uint32_t ab;
	uint8_t d[8] = {0};

	h_req(0xC2 | (crc ? 0x04 : 0), idx, sub, len);
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab != 0U) {
		return ab;
	}
	/* The server's CRC bit answers the client's (doc/sdo.md). */
	zassert_equal(f->data[0], crc ? 0xA4 : 0xA0, "block download initiate response %02x",
		      f->data[0]);
	check_mux(f, idx, sub);
	blksize = f->data[4];
	zassert_equal(blksize, SRV_BLKSIZE);
	check_zero(&f->data[5], 3);
	while (!last) {
		uint8_t seq;

		for (seq = 1; seq <= blksize; seq++) {
			uint32_t n = MIN(7U, len - off);

			last = off + n >= len;
			memset(d, 0, sizeof(d));
			d[0] = (uint8_t)(seq | (last ? 0x80 : 0));
			memcpy(&d[1], &p[off], n);
			h_send(d);
			off += n;
			last_len = n;
			if (last) {
				break;
			}
			/* No answer inside a sub-block. */
			if (seq < blksize) {
				h_expect_none();
			}
		}
		f = h_next();
		ab = abort_of(f, idx, sub);
		if (ab != 0U) {
			return ab;
		}
		zassert_equal(f->data[0], 0xA2, "block ack %02x", f->data[0]);
		zassert_equal(f->data[1], last ? seq : blksize, "ackseq %u", f->data[1]);
		blksize = f->data[2];
		zassert_equal(blksize, SRV_BLKSIZE);
		check_zero(&f->data[3], 5);
	}
	memset(d, 0, sizeof(d));
	d[0] = (uint8_t)(0xC1 | ((7U - last_len) << 2));
	if (crc) {
		sys_put_le16(ref_crc16(p, len), &d[1]);
	}
	h_send(d);
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab != 0U) {
		return ab;
	}
	zassert_equal(f->data[0], 0xA1, "block download end response %02x", f->data[0]);
	check_mux(f, idx, sub);
	check_zero(&f->data[4], 4);
	h_expect_none();
	return 0;
}

uint32_t cli_blk_ul(uint16_t idx, uint8_t sub, void *buf, uint32_t cap, uint32_t *len,
		    uint8_t blksize, bool crc, uint8_t pst, bool *switched)
{
	uint8_t *p = buf;
	const struct can_frame *f;
	uint8_t d[8] = {(uint8_t)(0xA0 | (crc ? 0x04 : 0))};
	uint32_t size;
	uint32_t off = 0;
	bool last = false;
	uint32_t ab;
	uint8_t n;

	*switched = false;
	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	d[4] = blksize;
	d[5] = pst;
	h_send(d);
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab != 0U) {
		return ab;
	}
	if ((f->data[0] >> 5) == 2) {
		*switched = true;
		return cli_ul_cont(idx, sub, f, buf, cap, len);
	}
	zassert_equal(f->data[0], crc ? 0xC6 : 0xC2, "block upload initiate response %02x",
		      f->data[0]);
	check_mux(f, idx, sub);
	size = sys_get_le32(&f->data[4]);
	zassert_true(size + 7U <= cap, "buffer too small for %u bytes", size);
	h_req(0xA3, 0, 0, 0);
	while (!last) {
		uint8_t seq;

		for (seq = 1; seq <= blksize; seq++) {
			f = h_next();
			ab = abort_of(f, idx, sub);
			if (ab != 0U) {
				return ab;
			}
			zassert_equal(f->data[0] & 0x7f, seq, "segment %02x, expected seqno %u",
				      f->data[0], seq);
			last = (f->data[0] & 0x80) != 0;
			/* @p buf holds the size rounded up to whole segments. */
			zassert_true(off + 7U <= cap, "upload longer than the buffer");
			memcpy(&p[off], &f->data[1], 7U);
			off += 7U;
			if (last) {
				break;
			}
		}
		/* The server waits for the acknowledgement. */
		h_expect_none();
		memset(d, 0, sizeof(d));
		d[0] = 0xA2;
		d[1] = last ? seq : blksize;
		d[2] = blksize;
		h_send(d);
	}
	f = h_next();
	ab = abort_of(f, idx, sub);
	if (ab != 0U) {
		return ab;
	}
	zassert_equal(f->data[0] & 0xE3, 0xC1, "block upload end request %02x", f->data[0]);
	n = (f->data[0] >> 2) & 7U;
	zassert_equal(off - n, size, "%u bytes received, %u announced", off - n, size);
	if (crc) {
		zassert_equal(sys_get_le16(&f->data[1]), ref_crc16(p, size), "CRC %04x",
			      sys_get_le16(&f->data[1]));
	} else {
		check_zero(&f->data[1], 2);
	}
	check_zero(&f->data[3], 5);
	h_req(0xA1, 0, 0, 0);
	h_expect_none();
	*len = size;
	return 0;
}
