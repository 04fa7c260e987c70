/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Two lines, each on its own virtual bus, with two nodes each; every line has its own thread.
 * Nodes on one line reach each other (local delivery) and never the other bus. Application
 * threads write the nodes' dictionaries while the lines run.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>
#include <canopen/node.h>

#include "nmt_test_od.h"

#define N_LINES        2
#define NODES_PER_LINE 2
#define HB_MS          20U
#define WAIT_MS        5000

struct test_node {
	struct co_node node;
	struct nmt_test_od_ram ram;
	/* Heartbeat events seen by this node, per remote node-ID. */
	uint8_t started[128];
	uint8_t last_state[128];
};

static struct co_line lines[N_LINES];
static struct test_node nodes[N_LINES][NODES_PER_LINE];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(events, 0, K_SEM_MAX_LIMIT);

static uint8_t id_of(int l, int n)
{
	return (uint8_t)(1 + l * NODES_PER_LINE + n);
}

static void hb_ind(struct co_node *node, uint8_t remote, enum co_hb_event ev,
		   enum co_nmt_state state, void *user_data)
{
	struct test_node *tn = user_data;

	if (ev == CO_HB_EV_STARTED) {
		tn->started[remote]++;
	}
	if (ev != CO_HB_EV_BOOTUP) {
		tn->last_state[remote] = (uint8_t)state;
	}
	k_sem_give(&events);
}

/*
 * Wakes the waiting test thread. Runs before the change, with the node's lock held; the
 * waiter checks the state under that lock, so it sees the change once it gets the lock.
 */
static int state_ind(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
		     void *user_data)
{
	k_sem_give(&events);
	return 0;
}

static uint32_t hb_entry(uint8_t id, uint16_t ms)
{
	return ((uint32_t)id << 16) | ms;
}

/*
 * A node sends a heartbeat every 20 ms and monitors every other node of both lines; only the
 * nodes of its own line can ever be heard. (Reset Communication undoes this.)
 */
static void configure(int l, int n)
{
	struct co_node *node = &nodes[l][n].node;
	uint8_t sub = 1;

	co_node_lock(node);
	zassert_ok(co_od_set_u16(co_node_od(node), 0x1017, 0, HB_MS, CO_OD_WRITER_APP));
	for (int ol = 0; ol < N_LINES; ol++) {
		for (int on = 0; on < NODES_PER_LINE; on++) {
			if (ol == l && on == n) {
				continue;
			}
			zassert_ok(co_od_set_u32(co_node_od(node), 0x1016, sub++,
						 hb_entry(id_of(ol, on), 1000), CO_OD_WRITER_APP));
		}
	}
	co_node_unlock(node);
}

static void *setup(void)
{
	for (int l = 0; l < N_LINES; l++) {
		char name[16];

		snprintk(name, sizeof(name), "can_virtual%d", l);
		zassert_ok(co_line_init(&lines[l], l == 0 ? "lineA" : "lineB",
					device_get_binding(name)));
		zassert_ok(co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
		for (int n = 0; n < NODES_PER_LINE; n++) {
			struct test_node *tn = &nodes[l][n];

			zassert_ok(co_node_init(&tn->node, "node", &lines[l], &nmt_test_od_def,
						&tn->ram, id_of(l, n)));
			co_hb_set_ind(&tn->node, hb_ind, tn);
			co_nmt_set_state_ind(&tn->node, state_ind, NULL);
			zassert_ok(co_node_start(&tn->node));
		}
	}
	for (int l = 0; l < N_LINES; l++) {
		for (int n = 0; n < NODES_PER_LINE; n++) {
			configure(l, n);
		}
	}
	return NULL;
}

/* Wait until @p cond is true, checked under every node's lock in turn. */
static bool wait_until(bool (*cond)(void))
{
	int64_t end = k_uptime_get() + WAIT_MS;

	while (!cond()) {
		if (k_sem_take(&events, K_TIMEOUT_ABS_MS(end)) != 0) {
			return cond();
		}
	}
	return true;
}

static bool locked_started(struct test_node *tn, uint8_t remote)
{
	bool started;

	co_node_lock(&tn->node);
	started = tn->started[remote] > 0U;
	co_node_unlock(&tn->node);
	return started;
}

static bool both_lines_see_their_partner(void)
{
	return locked_started(&nodes[0][0], id_of(0, 1)) &&
	       locked_started(&nodes[0][1], id_of(0, 0)) &&
	       locked_started(&nodes[1][0], id_of(1, 1)) &&
	       locked_started(&nodes[1][1], id_of(1, 0));
}

ZTEST_SUITE(co_threaded, NULL, setup, NULL, NULL, NULL);

ZTEST(co_threaded, test_nodes_of_a_line_hear_each_other_and_not_the_other_bus)
{
	struct co_line_stats a, b;

	zassert_true(wait_until(both_lines_see_their_partner),
		     "each node hears the other node of its line");
	k_msleep(200); /* ten more heartbeat periods */
	zassert_false(locked_started(&nodes[0][0], id_of(1, 0)), "line B is another bus");
	zassert_false(locked_started(&nodes[1][1], id_of(0, 1)), "line A is another bus");

	co_line_get_stats(&lines[0], &a);
	co_line_get_stats(&lines[1], &b);
	zassert_true(a.tx_frames >= 10U && b.tx_frames >= 10U, "traffic on both lines (%u, %u)",
		     a.tx_frames, b.tx_frames);
	zassert_equal(a.tx_dropped + b.tx_dropped, 0U);
}

static bool node2_operational(void)
{
	enum co_nmt_state st = co_nmt_get_state(&nodes[0][1].node);

	return st == CO_NMT_OPERATIONAL;
}

ZTEST(co_threaded, test_nmt_command_from_a_node_reaches_its_neighbour)
{
	struct can_frame f = {.id = 0x000, .dlc = 2, .data = {CO_NMT_CS_START, id_of(0, 1)}};

	co_node_lock(&nodes[0][0].node);
	zassert_ok(co_node_send(&nodes[0][0].node, CO_ROUTE_DEFAULT, &f));
	co_node_unlock(&nodes[0][0].node);
	zassert_true(wait_until(node2_operational));
	zassert_equal(co_nmt_get_state(&nodes[0][0].node), CO_NMT_PRE_OPERATIONAL,
		      "the sender is not addressed");
}

/* Application threads writing the dictionaries while the line threads read them. */
static void writer(void *p1, void *p2, void *p3)
{
	struct co_node *node = p1;

	for (uint32_t i = 0; i < 2000; i++) {
		co_node_lock(node);
		(void)co_od_set_u32(co_node_od(node), 0x2000, 0, i, CO_OD_WRITER_APP);
		if ((i % 100U) == 0U) {
			/* Reconfigures the producer through its OD hook, from this thread. */
			(void)co_od_set_u16(co_node_od(node), 0x1017, 0, HB_MS + (i % 3U),
					    CO_OD_WRITER_APP);
		}
		co_node_unlock(node);
		if ((i % 50U) == 0U) {
			k_yield();
		}
	}
}

static K_THREAD_STACK_ARRAY_DEFINE(writer_stacks, N_LINES, 4096);
static struct k_thread writer_threads[N_LINES];

static bool neighbour_heard_again(void)
{
	return locked_started(&nodes[0][1], id_of(0, 0));
}

ZTEST(co_threaded, test_application_threads_and_line_threads_share_nodes)
{
	uint32_t v;

	for (int l = 0; l < N_LINES; l++) {
		k_thread_create(&writer_threads[l], writer_stacks[l],
				K_THREAD_STACK_SIZEOF(writer_stacks[l]), writer, &nodes[l][0].node,
				NULL, NULL, 5, 0, K_NO_WAIT);
	}
	for (int l = 0; l < N_LINES; l++) {
		zassert_ok(k_thread_join(&writer_threads[l], K_MSEC(30000)));
	}
	for (int l = 0; l < N_LINES; l++) {
		co_node_lock(&nodes[l][0].node);
		zassert_ok(co_od_get_u32(co_node_od(&nodes[l][0].node), 0x2000, 0, &v));
		co_node_unlock(&nodes[l][0].node);
		zassert_equal(v, 1999U);
	}
	/* After all that reconfiguration a reset node is heard again by its neighbour. */
	co_node_lock(&nodes[0][1].node);
	nodes[0][1].started[id_of(0, 0)] = 0;
	co_node_unlock(&nodes[0][1].node);
	zassert_ok(co_nmt_req(&nodes[0][0].node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_true(wait_until(neighbour_heard_again), "heartbeat after the reset (1017h 1 s)");
	configure(0, 0);
}

static bool queue_empty(void)
{
	return co_line_tx_space(&lines[1]) == CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE;
}

ZTEST(co_threaded, test_frames_sent_while_the_line_is_stopped_go_out_at_start)
{
	struct can_frame f = {.id = 0x555, .dlc = 1, .data = {0x42}};
	struct co_line_stats before, after;

	zassert_ok(co_line_stop(&lines[1]));
	co_line_get_stats(&lines[1], &before);
	zassert_ok(co_line_send(&lines[1], &f), "queued, not an error");
	zassert_true(co_line_tx_space(&lines[1]) < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	zassert_ok(co_line_start(&lines[1], stacks[1], K_THREAD_STACK_SIZEOF(stacks[1]),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	for (int i = 0; i < 100 && !queue_empty(); i++) {
		k_msleep(10);
	}
	zassert_true(queue_empty(), "the queue drains once the line runs");
	co_line_get_stats(&lines[1], &after);
	zassert_equal(after.tx_errors, before.tx_errors, "nothing refused with -ENETDOWN");
	zassert_equal(after.tx_dropped, before.tx_dropped);
	zassert_true(after.tx_frames > before.tx_frames);
}

/* --- A node on both lines ------------------------------------------------------------------ */

static struct test_node dual;
static atomic_t seen_on[N_LINES];

static void count_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	atomic_inc(rx->user_data);
	k_sem_give(&events);
}

static bool seen(int a, int b)
{
	return atomic_get(&seen_on[0]) == a && atomic_get(&seen_on[1]) == b;
}

static bool seen_1_0(void)
{
	return seen(1, 0);
}

static bool seen_1_1(void)
{
	return seen(1, 1);
}

static bool seen_2_2(void)
{
	return seen(2, 2);
}

ZTEST(co_threaded, test_node_on_two_virtual_lines_sends_on_each_route)
{
	struct can_frame f = {.id = 0x555, .dlc = 1, .data = {0x5A}};
	struct co_rx rx[N_LINES];

	/* Observers: a receiver of a node of each line (frames reach them by local delivery). */
	for (int l = 0; l < N_LINES; l++) {
		co_rx_init(&rx[l], 0x555, count_rx, &nodes[l][0].node.lock, &seen_on[l]);
		zassert_ok(co_rx_register(&lines[l], &rx[l]));
	}
	zassert_ok(co_node_init(&dual.node, "dual", &lines[0], &nmt_test_od_def, &dual.ram, 10));
	zassert_ok(co_node_attach_line(&dual.node, CO_LINE_REDUNDANT, &lines[1]));
	zassert_ok(co_node_start(&dual.node));

	co_node_lock(&dual.node);
	zassert_ok(co_node_send(&dual.node, CO_ROUTE_DEFAULT, &f));
	co_node_unlock(&dual.node);
	zassert_true(wait_until(seen_1_0), "default route: line A only");

	co_node_lock(&dual.node);
	zassert_ok(co_node_send(&dual.node, CO_ROUTE_REDUNDANT, &f));
	co_node_unlock(&dual.node);
	zassert_true(wait_until(seen_1_1), "redundant route: line B");

	co_node_lock(&dual.node);
	zassert_ok(co_node_send(&dual.node, CO_ROUTE_BOTH, &f));
	co_node_unlock(&dual.node);
	zassert_true(wait_until(seen_2_2), "both routes: one more on each line");

	k_msleep(50);
	zassert_true(seen(2, 2), "nothing more");
	for (int l = 0; l < N_LINES; l++) {
		co_rx_unregister(&rx[l]);
	}
}
