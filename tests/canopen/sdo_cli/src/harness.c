/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

struct harness h;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (h.sink_result != 0) {
		return h.sink_result;
	}
	if (h.bus_paced) {
		if (h.bus_credit == 0) {
			return -EAGAIN;
		}
		h.bus_credit--;
	}
	zassert_true(h.wr - h.rd < RING, "frame ring overflow");
	h.ring_at[h.wr % RING] = h.now;
	h.ring[h.wr++ % RING] = *frame;
	return 0;
}

void h_setup(void)
{
	memset(&h, 0, sizeof(h));
	h.now = 1000 * MS;
	co_line_init_sim(&h.line, "sim", sink, NULL);
	co_line_process(&h.line, h.now);
	zassert_ok(co_node_init(&h.cnode, "cli", &h.line, &sdo_cli_test_od_def, &h.cram, CLI_ID));
	zassert_ok(co_node_init(&h.snode, "srv", &h.line, &sdo_cli_test_od_def, &h.sram, SRV_ID));
	zassert_ok(
		co_node_init(&h.snode2, "srv2", &h.line, &sdo_cli_test_od_def, &h.sram2, SRV2_ID));
	zassert_ok(
		co_node_init(&h.snode3, "srv3", &h.line, &sdo_cli_test_od_def, &h.sram3, SRV3_ID));
	zassert_ok(co_node_start(&h.cnode));
	zassert_ok(co_node_start(&h.snode));
	zassert_ok(co_node_start(&h.snode2));
	zassert_ok(co_node_start(&h.snode3));
	h_pump();
	/* Four boot-ups. */
	zassert_equal(h.wr, 4U);
	h.rd = h.wr;
}

struct co_sdo_cli *h_cli(uint8_t num)
{
	return co_sdo_cli_get(&h.cnode, num);
}

void h_pump(void)
{
	for (int i = 0; i < 100000; i++) {
		co_line_process(&h.line, h.now);
		uint64_t next = co_line_next_deadline(&h.line);

		if (k_msgq_num_used_get(&h.line.rxq) == 0U &&
		    (next == UINT64_MAX || next > h.now)) {
			return;
		}
	}
	zassert_unreachable(
		"line does not settle: rxq %u next %llu now %llu", k_msgq_num_used_get(&h.line.rxq),
		(unsigned long long)co_line_next_deadline(&h.line), (unsigned long long)h.now);
}

void h_run_until(uint64_t at)
{
	h_pump();
	while (true) {
		uint64_t next = co_line_next_deadline(&h.line);

		if (next == UINT64_MAX || next > at) {
			break;
		}
		h.now = MAX(h.now, next);
		h_pump();
	}
	h.now = at;
	h_pump();
}

void h_advance(uint64_t us)
{
	h_run_until(h.now + us);
}

void h_run_for_con(struct con_rec *rec, uint64_t max_us)
{
	uint64_t end = h.now + max_us;

	h_pump();
	while (rec->calls == 0U && h.now < end) {
		uint64_t next = co_line_next_deadline(&h.line);

		if (next == UINT64_MAX || next > end) {
			h.now = end;
		} else {
			h.now = MAX(h.now, next);
		}
		h_pump();
	}
}

void h_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data)
{
	struct con_rec *rec = user_data;

	/* The confirmation runs with the client node's mutex held. */
	zassert_true(h.cnode.lock.lock_count >= 1U);
	rec->calls++;
	rec->code = code;
	rec->size = size;
	rec->user_data = user_data;
	rec->cli = cli;
}

/* --- Scripted server --------------------------------------------------------------------- */

const struct can_frame *h_next_from(uint32_t id)
{
	while (h.rd != h.wr) {
		const struct can_frame *f = &h.ring[h.rd++ % RING];

		if (f->id == id) {
			return f;
		}
	}
	return NULL;
}

void h_skip_all(void)
{
	h.rd = h.wr;
}

uint32_t h_count_from(uint32_t id)
{
	uint32_t n = 0;

	for (uint32_t i = h.rd; i != h.wr; i++) {
		n += h.ring[i % RING].id == id ? 1U : 0U;
	}
	return n;
}

void h_fake_dlc(const uint8_t *d, uint8_t dlc)
{
	struct can_frame f = {.id = 0x580U + FAKE_ID, .dlc = dlc};

	memcpy(f.data, d, dlc);
	co_line_rx(&h.line, &f, h.now);
	h_pump();
}

void h_fake_raw(const uint8_t d[8])
{
	h_fake_dlc(d, 8);
}

void h_fake(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v)
{
	uint8_t d[8] = {b0};

	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	sys_put_le32(v, &d[4]);
	h_fake_raw(d);
}

void h_expect_raw(const uint8_t d[8])
{
	const struct can_frame *f = h_next_from(0x600U + FAKE_ID);

	zassert_not_null(f, "no frame from the client");
	zassert_equal(f->dlc, 8U);
	zassert_mem_equal(f->data, d, 8, "frame %02x %02x %02x %02x %02x %02x %02x %02x",
			  f->data[0], f->data[1], f->data[2], f->data[3], f->data[4], f->data[5],
			  f->data[6], f->data[7]);
}

void h_expect(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v)
{
	uint8_t d[8] = {b0};

	sys_put_le16(idx, &d[1]);
	d[3] = sub;
	sys_put_le32(v, &d[4]);
	h_expect_raw(d);
}

void h_expect_abort(uint16_t idx, uint8_t sub, uint32_t code)
{
	h_expect(0x80, idx, sub, code);
}

void h_expect_none(void)
{
	zassert_equal(h_count_from(0x600U + FAKE_ID), 0U, "unexpected frame from the client");
}

void h_fill(uint8_t *p, size_t len, uint32_t seed)
{
	uint32_t x = seed * 2654435761U + 1U;

	for (size_t i = 0; i < len; i++) {
		x = x * 1103515245U + 12345U;
		p[i] = (uint8_t)(x >> 16);
	}
}

uint16_t ref_crc16(const uint8_t *p, size_t len)
{
	uint16_t crc = 0;

	for (size_t i = 0; i < len; i++) {
		crc ^= (uint16_t)p[i] << 8;
		for (int b = 0; b < 8; b++) {
			crc = (crc & 0x8000U) ? (uint16_t)((crc << 1) ^ 0x1021U)
					      : (uint16_t)(crc << 1);
		}
	}
	return crc;
}

void h_nmt(uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = 0, .dlc = 2, .data = {cs, id}};

	co_line_rx(&h.line, &f, h.now);
	h_pump();
}

uint32_t h_od_write(struct co_node *n, uint16_t idx, uint8_t sub, const void *data, size_t len,
		    enum co_od_writer w)
{
	uint32_t ab;

	co_node_lock(n);
	ab = co_od_write(co_node_od(n), idx, sub, data, len, w);
	co_node_unlock(n);
	return ab;
}

uint32_t h_od_read(struct co_node *n, uint16_t idx, uint8_t sub, uint32_t off, void *buf,
		   size_t cap, size_t *len, enum co_od_writer r)
{
	uint32_t ab;

	co_node_lock(n);
	ab = co_od_read(co_node_od(n), idx, sub, off, buf, cap, len, r);
	co_node_unlock(n);
	return ab;
}

uint32_t h_od_set_u32(struct co_node *n, uint16_t idx, uint8_t sub, uint32_t v, enum co_od_writer w)
{
	uint32_t ab;

	co_node_lock(n);
	ab = co_od_set_u32(co_node_od(n), idx, sub, v, w);
	co_node_unlock(n);
	return ab;
}
