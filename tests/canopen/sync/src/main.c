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

#include "co_sim.h"
#include "sync_test_od.h"

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define MS      1000ULL
#define MAX_TX  64

static struct {
	struct co_node node;
	struct sync_test_od_ram ram;
	int n_ind;
	uint8_t ind_counter[MAX_TX];
	char order[MAX_TX + 1];
	int n_order;
} t;

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

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &sync_test_od_def, &t.ram, NODE_ID));
	co_sync_set_ind(&t.node, sync_ind, NULL);
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_sync, NULL, NULL, before, NULL, NULL);

ZTEST(co_sync, test_producer_sends_dlc0_sync_every_1006h_period)
{
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000080U, 4), 0U);
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 0, "no SYNC while 1006h = 0");
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U, "10 ms");
	co_sim_run_until(155 * MS);
	zassert_equal(sim.n_sent, 5);
	for (int i = 0; i < sim.n_sent; i++) {
		zassert_equal(sim.sent[i].id, 0x080);
		zassert_equal(sim.sent[i].dlc, 0, "no counter while 1019h = 0");
		zassert_equal(sim.sent_at[i], (110 + 10 * i) * MS, "frame %d at the period", i);
	}
	zassert_equal(t.n_ind, 5, "the producer's own SYNC is indicated");
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 0, 4), 0U);
	co_sim_run_until(300 * MS);
	zassert_equal(sim.n_sent, 5, "1006h = 0 stops production");
}

ZTEST(co_sync, test_counter_runs_1_to_1019h_then_wraps)
{
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 3, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U);
	co_sim_run_until(50 * MS);
	zassert_equal(sim.n_sent, 5);
	const uint8_t want[5] = {1, 2, 3, 1, 2};

	for (int i = 0; i < 5; i++) {
		zassert_equal(sim.sent[i].dlc, 1);
		zassert_equal(sim.sent[i].data[0], want[i], "frame %d counter %u", i,
			      sim.sent[i].data[0]);
		zassert_equal(t.ind_counter[i], want[i]);
	}
}

ZTEST(co_sync, test_1005h_refuses_restricted_can_ids_06090030h)
{
	static const uint32_t restricted[] = {0x000, 0x001, 0x07F, 0x101, 0x180, 0x581, 0x5FF,
					      0x601, 0x67F, 0x6E0, 0x6FF, 0x701, 0x77F, 0x7FF};

	for (size_t i = 0; i < ARRAY_SIZE(restricted); i++) {
		zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000000U | restricted[i], 4),
			      CO_SDO_AB_INVALID_VALUE, "producer on %03x", restricted[i]);
		zassert_equal(co_sim_write(&t.node, 0x1005, 0, restricted[i], 4),
			      CO_SDO_AB_INVALID_VALUE, "consumer on %03x", restricted[i]);
	}
	/* The attack of the fuzzing campaign: SYNC on the NMT identifier every millisecond. */
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000000U, 4), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 1000, 4), 0U);
	sim.n_sent = 0;
	co_sim_run_until(sim.now + 10 * MS);
	for (int i = 0; i < sim.n_sent; i++) {
		zassert_not_equal(sim.sent[i].id, 0x000, "nothing on the NMT identifier");
	}
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x00000081U, 4), 0U, "081h is free");
}

ZTEST(co_sync, test_1019h_write_rules_08000022h_and_06090030h)
{
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 1, 1), CO_SDO_AB_INVALID_VALUE,
		      "1 reserved");
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 241, 1), CO_SDO_AB_INVALID_VALUE,
		      "241 reserved");
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 255, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 2, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 240, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 5, 1), CO_SDO_AB_DATA_DEV_STATE,
		      "not while 1006h != 0");
}

ZTEST(co_sync, test_1005h_producer_cannot_change_can_id)
{
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000081U, 4), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x00000080U, 4), 0U, "producer off");
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x00000081U, 4), 0U,
		      "then the id may change");
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000081U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x20000081U, 4), CO_SDO_AB_INVALID_VALUE,
		      "29-bit not supported");
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U);
	co_sim_run_until(10 * MS);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x081);
}

ZTEST(co_sync, test_consumer_indicates_sync_and_counter)
{
	uint8_t c = 7;

	co_sim_rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.ind_counter[0], 0);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 10, 1), 0U);
	co_sim_rx(0x080, 1, &c);
	zassert_equal(t.n_ind, 2);
	zassert_equal(t.ind_counter[1], 7);
	zassert_equal(sim.n_sent, 0, "no EMCY for good SYNCs");
}

ZTEST(co_sync, test_sync_with_wrong_length_raises_emcy_8240h)
{
	uint8_t c = 1;

	co_sim_rx(0x080, 1, &c);
	zassert_equal(t.n_ind, 0, "a SYNC with DLC 1 while 1019h = 0 is not indicated");
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, EMCY_ID);
	zassert_equal(sim.sent[0].dlc, 8);
	zassert_equal(sim.sent[0].data[0], 0x40);
	zassert_equal(sim.sent[0].data[1], 0x82);
	zassert_equal(sim.sent[0].data[2], 0x11, "generic + communication");
	co_sim_rx(0x080, 1, &c);
	zassert_equal(sim.n_sent, 1, "raised once while it lasts");

	co_sim_rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1);
	zassert_equal(sim.n_sent, 2, "a good SYNC clears it");
	zassert_equal(sim.sent[1].data[0], 0x00);
	zassert_equal(sim.sent[1].data[1], 0x00);

	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 2, 1), 0U);
	co_sim_rx(0x080, 0, NULL);
	zassert_equal(t.n_ind, 1, "DLC 0 while 1019h > 0 is wrong too");
	zassert_equal(sim.n_sent, 3);
	zassert_equal(sim.sent[2].data[1], 0x82);
}

ZTEST(co_sync, test_no_sync_in_stopped_counter_restarts_after)
{
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 5, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U);
	co_sim_run_until(20 * MS);
	zassert_equal(sim.n_sent, 2);
	co_sim_nmt(0x02, NODE_ID);
	sim.n_sent = 0;
	t.n_ind = 0;
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 0, "no SYNC produced in Stopped");
	co_sim_rx(0x080, 1, (const uint8_t[]){1});
	zassert_equal(t.n_ind, 0, "no SYNC consumed in Stopped");

	co_sim_nmt(0x80, NODE_ID);
	co_sim_run_until(110 * MS);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].data[0], 1, "counter restarts at 1 after Stopped");
}

ZTEST(co_sync, test_post_indication_follows_each_sync)
{
	co_sync_set_post_ind(&t.node, sync_post_ind, NULL);
	zassert_equal(co_sim_write(&t.node, 0x1007, 0, 1000, 4), 0U, "1007h window accepted");
	co_sim_rx(0x080, 0, NULL);
	zassert_equal(co_sim_write(&t.node, 0x1005, 0, 0x40000080U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1006, 0, 10000, 4), 0U);
	co_sim_run_until(20 * MS);
	zassert_equal(t.n_ind, 3, "one received, two produced");
	zassert_str_equal(t.order, "ababab", "pre, then post, for every SYNC");
	co_sync_set_post_ind(&t.node, NULL, NULL);
	co_sim_run_until(30 * MS);
	zassert_equal(t.n_order, 7, "removed");
}
