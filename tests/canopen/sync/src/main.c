/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SYNC producer and consumer, driven frame by frame on a simulation line (no thread,
 * simulated time). Frames the node sends land in `sent`.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/sdo_abort.h>
#include <canopen/sync.h>

#include "sync_test_od.h"

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define MS      1000ULL
#define MAX_TX  64

static struct {
	struct co_line line;
	struct co_node node;
	struct sync_test_od_ram ram;
	struct can_frame sent[MAX_TX];
	uint64_t sent_at[MAX_TX];
	int n_sent;
	uint64_t now;
	int n_ind;
	uint8_t ind_counter[MAX_TX];
	char order[MAX_TX + 1];
	int n_order;
} t;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	zassert_true(t.n_sent < MAX_TX, "too many frames");
	t.sent_at[t.n_sent] = t.now;
	t.sent[t.n_sent++] = *frame;
	return 0;
}

static void sync_ind(struct co_node *node, uint8_t counter, void *user_data)
{
	zassert_true(t.n_ind < MAX_TX);
	t.order[t.n_order++] = 'a';
	t.ind_counter[t.n_ind++] = counter;
}

static void sync_post_ind(struct co_node *node, uint8_t counter, void *user_data)
{
	zassert_true(t.n_order < MAX_TX);
	zassert_equal(counter, t.ind_counter[t.n_ind - 1], "same SYNC");
	t.order[t.n_order++] = 'b';
}

static void run_until(uint64_t at)
{
	while (true) {
		uint64_t next = co_line_next_deadline(&t.line);

		if (next == UINT64_MAX || next > at) {
			break;
		}
		t.now = next;
		co_line_process(&t.line, t.now);
	}
	t.now = at;
	co_line_process(&t.line, t.now);
}

static void rx(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}
	co_line_rx(&t.line, &f, t.now);
}

static void nmt(uint8_t cs)
{
	uint8_t d[2] = {cs, NODE_ID};

	rx(0x000, 2, d);
}

static uint32_t od_write_u(uint16_t index, uint8_t sub, uint32_t value, size_t len)
{
	uint8_t buf[4];
	uint32_t ab;

	for (size_t i = 0; i < len; i++) {
		buf[i] = (uint8_t)(value >> (8 * i));
	}
	co_node_lock(&t.node);
	ab = co_od_write(co_node_od(&t.node), index, sub, buf, len, CO_OD_WRITER_SDO);
	co_node_unlock(&t.node);
	return ab;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_line_init_sim(&t.line, "sim", sink, NULL);
	zassert_ok(co_node_init(&t.node, "dut", &t.line, &sync_test_od_def, &t.ram, NODE_ID));
	co_sync_set_ind(&t.node, sync_ind, NULL);
	zassert_ok(co_node_start(&t.node));
	t.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_sync, NULL, NULL, before, NULL, NULL);

ZTEST(co_sync, test_producer_sends_dlc0_sync_every_1006h_period)
{
	zassert_equal(od_write_u(0x1005, 0, 0x40000080U, 4), 0U);
	run_until(100 * MS);
	zassert_equal(t.n_sent, 0, "no SYNC while 1006h = 0");
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U, "10 ms");
	run_until(155 * MS);
	zassert_equal(t.n_sent, 5);
	for (int i = 0; i < t.n_sent; i++) {
		zassert_equal(t.sent[i].id, 0x080);
		zassert_equal(t.sent[i].dlc, 0, "no counter while 1019h = 0");
		zassert_equal(t.sent_at[i], (110 + 10 * i) * MS, "frame %d at the period", i);
	}
	zassert_equal(t.n_ind, 5, "the producer's own SYNC is indicated");
	zassert_equal(od_write_u(0x1006, 0, 0, 4), 0U);
	run_until(300 * MS);
	zassert_equal(t.n_sent, 5, "1006h = 0 stops production");
}

ZTEST(co_sync, test_counter_runs_1_to_1019h_then_wraps)
{
	zassert_equal(od_write_u(0x1019, 0, 3, 1), 0U);
	zassert_equal(od_write_u(0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U);
	run_until(50 * MS);
	zassert_equal(t.n_sent, 5);
	const uint8_t want[5] = {1, 2, 3, 1, 2};

	for (int i = 0; i < 5; i++) {
		zassert_equal(t.sent[i].dlc, 1);
		zassert_equal(t.sent[i].data[0], want[i], "frame %d counter %u", i,
			      t.sent[i].data[0]);
		zassert_equal(t.ind_counter[i], want[i]);
	}
}

ZTEST(co_sync, test_1019h_write_rules_08000022h_and_06090030h)
{
	zassert_equal(od_write_u(0x1019, 0, 1, 1), CO_SDO_AB_INVALID_VALUE, "1 reserved");
	zassert_equal(od_write_u(0x1019, 0, 241, 1), CO_SDO_AB_INVALID_VALUE, "241 reserved");
	zassert_equal(od_write_u(0x1019, 0, 255, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(od_write_u(0x1019, 0, 2, 1), 0U);
	zassert_equal(od_write_u(0x1019, 0, 240, 1), 0U);
	zassert_equal(od_write_u(0x1019, 0, 0, 1), 0U);
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U);
	zassert_equal(od_write_u(0x1019, 0, 5, 1), CO_SDO_AB_DATA_DEV_STATE,
		      "not while 1006h != 0");
}

ZTEST(co_sync, test_1005h_producer_cannot_change_can_id)
{
	zassert_equal(od_write_u(0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(od_write_u(0x1005, 0, 0x40000081U, 4), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(od_write_u(0x1005, 0, 0x00000080U, 4), 0U, "producer off");
	zassert_equal(od_write_u(0x1005, 0, 0x00000081U, 4), 0U, "then the id may change");
	zassert_equal(od_write_u(0x1005, 0, 0x40000081U, 4), 0U);
	zassert_equal(od_write_u(0x1005, 0, 0x20000081U, 4), CO_SDO_AB_INVALID_VALUE,
		      "29-bit not supported");
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U);
	run_until(10 * MS);
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.sent[0].id, 0x081);
}

ZTEST(co_sync, test_consumer_indicates_sync_and_counter)
{
	uint8_t c = 7;

	rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.ind_counter[0], 0);
	zassert_equal(od_write_u(0x1019, 0, 10, 1), 0U);
	rx(0x080, 1, &c);
	zassert_equal(t.n_ind, 2);
	zassert_equal(t.ind_counter[1], 7);
	zassert_equal(t.n_sent, 0, "no EMCY for good SYNCs");
}

ZTEST(co_sync, test_sync_with_wrong_length_raises_emcy_8240h)
{
	uint8_t c = 1;

	rx(0x080, 1, &c);
	zassert_equal(t.n_ind, 0, "a SYNC with DLC 1 while 1019h = 0 is not indicated");
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.sent[0].id, EMCY_ID);
	zassert_equal(t.sent[0].dlc, 8);
	zassert_equal(t.sent[0].data[0], 0x40);
	zassert_equal(t.sent[0].data[1], 0x82);
	zassert_equal(t.sent[0].data[2], 0x11, "generic + communication");
	rx(0x080, 1, &c);
	zassert_equal(t.n_sent, 1, "raised once while it lasts");

	rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.n_sent, 2, "a good SYNC clears it");
	zassert_equal(t.sent[1].data[0], 0x00);
	zassert_equal(t.sent[1].data[1], 0x00);

	zassert_equal(od_write_u(0x1019, 0, 2, 1), 0U);
	rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1, "DLC 0 while 1019h > 0 is wrong too");
	zassert_equal(t.n_sent, 3);
	zassert_equal(t.sent[2].data[1], 0x82);
}

ZTEST(co_sync, test_no_sync_in_stopped_counter_restarts_after)
{
	zassert_equal(od_write_u(0x1019, 0, 5, 1), 0U);
	zassert_equal(od_write_u(0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U);
	run_until(20 * MS);
	zassert_equal(t.n_sent, 2);
	nmt(0x02);
	t.n_sent = 0;
	t.n_ind = 0;
	run_until(100 * MS);
	zassert_equal(t.n_sent, 0, "no SYNC produced in Stopped");
	rx(0x080, 1, (const uint8_t[]){1});
	zassert_equal(t.n_ind, 0, "no SYNC consumed in Stopped");

	nmt(0x80);
	run_until(110 * MS);
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.sent[0].data[0], 1, "counter restarts at 1 after Stopped");
}

ZTEST(co_sync, test_post_indication_follows_each_sync)
{
	co_sync_set_post_ind(&t.node, sync_post_ind, NULL);
	zassert_equal(od_write_u(0x1007, 0, 1000, 4), 0U, "1007h window accepted");
	rx(0x080, 0, NULL);
	zassert_equal(od_write_u(0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(od_write_u(0x1006, 0, 10000, 4), 0U);
	run_until(20 * MS);
	zassert_equal(t.n_ind, 3, "one received, two produced");
	zassert_str_equal(t.order, "ababab", "pre, then post, for every SYNC");
	co_sync_set_post_ind(&t.node, NULL, NULL);
	run_until(30 * MS);
	zassert_equal(t.n_order, 7, "removed");
}
