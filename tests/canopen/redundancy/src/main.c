/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Redundant lines (CiA 302-6) on simulated time: node 1 on two simulation lines, D (default)
 * and R (redundant). It supervises nodes 2 and 3 (heartbeat 100 ms), sends its heartbeat every
 * 50 ms, consumes RPDO 1 on 182h and SYNC, sends TPDO 1 on 181h, serves SDO on 601h/581h and
 * has 1F60h sub 5 = 12. The tests feed frames into either line and read what the node sent on
 * each.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/redundancy.h>
#include <canopen/sync.h>
#include <zephyr/drivers/can.h>

#include "line_internal.h"
#include "rdn_test_od.h"

#define NODE_ID 1
#define MS      1000ULL
#define MAX_TX  256
#define MAX_EV  64
#define D       CO_LINE_DEFAULT
#define R       CO_LINE_REDUNDANT

struct sent {
	struct can_frame f;
	uint64_t at;
};

static struct {
	struct co_line line[2];
	struct co_node node;
	struct rdn_test_od_ram ram;
	struct co_listener listener;
	uint64_t now;
	struct sent tx[2][MAX_TX];
	int n_tx[2];
	bool busy;
	/* The line's interface is down: the driver refuses every frame with -ENETDOWN. */
	bool down[2];
	uint32_t refused[2][MAX_TX];
	int n_refused[2];
	struct co_event ev[MAX_EV];
	int n_ev;
	int n_sync;
	bool veto_refuses;
	int veto_asked;
	int n_emcy;
	uint16_t emcy_code[8];
	struct co_rx ext_rx;
	int n_ext;
	uint8_t ext_line[8];
} t;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	int l = (int)(intptr_t)user_data;

	if (t.busy) {
		return -EAGAIN;
	}
	if (t.down[l]) {
		zassert_true(t.n_refused[l] < MAX_TX);
		t.refused[l][t.n_refused[l]++] = frame->id;
		return -ENETDOWN;
	}
	zassert_true(t.n_tx[l] < MAX_TX, "too many frames on line %d", l);
	t.tx[l][t.n_tx[l]++] = (struct sent){*frame, t.now};
	return 0;
}

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	zassert_true(t.n_ev < MAX_EV);
	t.ev[t.n_ev++] = *ev;
	return 0;
}

static bool veto(struct co_node *node, enum co_rdn_event why, uint8_t to, void *user_data)
{
	t.veto_asked++;
	return !t.veto_refuses;
}

static void on_emcy(struct co_node *node, uint16_t cob_id, uint8_t remote_id, uint16_t code,
		    uint8_t reg, const uint8_t msef[5], void *user_data)
{
	zassert_true(t.n_emcy < (int)ARRAY_SIZE(t.emcy_code));
	t.emcy_code[t.n_emcy++] = code;
}

static void on_ext(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	zassert_true(t.n_ext < (int)ARRAY_SIZE(t.ext_line));
	t.ext_line[t.n_ext++] = co_node_rx_line(&t.node);
}

static void on_sync(struct co_node *node, uint8_t counter, void *user_data)
{
	t.n_sync++;
}

/* Advance both lines to @p at, running the node's deadlines (all on line D) on the way. */
static void run_until(uint64_t at)
{
	while (true) {
		uint64_t next = co_line_next_deadline(&t.line[D]);

		if (next == UINT64_MAX || next > at) {
			break;
		}
		t.now = next;
		co_line_process(&t.line[D], t.now);
		co_line_process(&t.line[R], t.now);
	}
	t.now = at;
	co_line_process(&t.line[D], t.now);
	co_line_process(&t.line[R], t.now);
}

static void rx(int l, uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}
	co_line_rx(&t.line[l], &f, t.now);
}

static void heartbeat(int l, uint8_t id)
{
	const uint8_t st = 0x05;

	rx(l, 0x700 + id, 1, &st);
}

/* Heartbeats of nodes 2 and 3 every 50 ms on the lines of @p mask, until @p until. */
static __unused void heartbeats_until(uint8_t mask2, uint8_t mask3, uint64_t until)
{
	while (t.now + 50 * MS <= until) {
		run_until(t.now + 50 * MS);
		for (int l = 0; l < 2; l++) {
			if (mask2 & BIT(l)) {
				heartbeat(l, 2);
			}
			if (mask3 & BIT(l)) {
				heartbeat(l, 3);
			}
		}
	}
	run_until(until);
}

static int count_id(int l, uint32_t id)
{
	int n = 0;

	for (int i = 0; i < t.n_tx[l]; i++) {
		n += t.tx[l][i].f.id == id;
	}
	return n;
}

static const struct co_event *last_rdn(enum co_rdn_event what)
{
	for (int i = t.n_ev - 1; i >= 0; i--) {
		if (t.ev[i].type == CO_EV_REDUNDANCY && t.ev[i].redundancy.what == what) {
			return &t.ev[i];
		}
	}
	return NULL;
}

static uint8_t active(enum co_rdn_state *st)
{
	return co_redundancy_get(&t.node, st, NULL);
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_line_init_sim(&t.line[D], "D", sink, (void *)(intptr_t)D);
	co_line_init_sim(&t.line[R], "R", sink, (void *)(intptr_t)R);
	zassert_ok(co_node_init(&t.node, "dut", &t.line[D], &rdn_test_od_def, &t.ram, NODE_ID));
	zassert_ok(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line[R]));
	co_listener_init(&t.listener, "test", CO_EV_BIT(CO_EV_REDUNDANCY), on_event, NULL);
	zassert_ok(co_node_listener_add(&t.node, &t.listener));
	co_redundancy_set_veto(&t.node, veto, NULL);
	co_sync_set_ind(&t.node, on_sync, NULL);
	co_emcy_set_ind(&t.node, on_emcy, NULL);
	zassert_ok(co_node_start(&t.node));
}

ZTEST_SUITE(co_redundancy, NULL, NULL, before, NULL, NULL);

#if !defined(CONFIG_CANOPEN_REDUNDANCY_ECSS)

/* --- 48: boot ------------------------------------------------------------------------------- */

ZTEST(co_redundancy, test_48_three_heartbeats_on_the_default_line_make_it_active)
{
	enum co_rdn_state st;

	zassert_equal(active(&st), D);
	zassert_equal(st, CO_RDN_NEGOTIATING);
	heartbeats_until(BIT(D), BIT(D), 100 * MS); /* two each */
	zassert_equal(active(&st), D);
	zassert_equal(st, CO_RDN_NEGOTIATING);
	heartbeats_until(BIT(D), BIT(D), 150 * MS); /* the third */
	active(&st);
	zassert_equal(st, CO_RDN_DEFAULT_ACTIVE);
	zassert_not_null(last_rdn(CO_RDN_EV_DEFAULT_LINE_OK));
	zassert_is_null(last_rdn(CO_RDN_EV_SWITCH), "the default line was active all along");
	zassert_equal(t.veto_asked, 0, "the evaluation asks no veto");
}

ZTEST(co_redundancy, test_48_no_heartbeats_on_the_default_line_redundant_at_evaluation_end)
{
	enum co_rdn_state st;
	const struct co_event *sw;

	heartbeats_until(BIT(R), BIT(R), 2990 * MS);
	zassert_equal(active(&st), D);
	zassert_equal(st, CO_RDN_NEGOTIATING);
	heartbeats_until(BIT(R), BIT(R), 3010 * MS);
	zassert_equal(active(&st), R);
	zassert_equal(st, CO_RDN_REDUNDANT_ACTIVE);
	zassert_not_null(last_rdn(CO_RDN_EV_EVAL_TIMEOUT));
	sw = last_rdn(CO_RDN_EV_SWITCH);
	zassert_not_null(sw);
	zassert_equal(sw->redundancy.line, R);
	zassert_equal(sw->redundancy.time_us, 3000 * MS, "CONFIG_CANOPEN_REDUNDANCY_EVAL_MS");
}

/* --- 49: failover and failback -------------------------------------------------------------- */

static void boot_default_active(void)
{
	enum co_rdn_state st;

	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), 200 * MS);
	zassert_equal(active(&st), D);
	zassert_equal(st, CO_RDN_DEFAULT_ACTIVE);
}

ZTEST(co_redundancy, test_49_heartbeat_lost_on_default_switches_and_three_cycles_switch_back)
{
	enum co_rdn_state st;
	const struct co_event *e;

	boot_default_active();
	/* Node 2 goes silent on the default line only. */
	heartbeats_until(BIT(R), BIT(D) | BIT(R), 400 * MS);
	e = last_rdn(CO_RDN_EV_HB_ERROR);
	zassert_not_null(e);
	zassert_equal(e->redundancy.line, D);
	zassert_equal(e->redundancy.node_id, 2);
	zassert_equal(active(&st), R, "switched on the heartbeat error");
	zassert_equal(st, CO_RDN_REDUNDANT_ACTIVE);
	zassert_equal(t.veto_asked, 1);
	/* Node 2 back on the default line: the third heartbeat switches back. */
	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), 500 * MS);
	zassert_equal(active(&st), R, "two heartbeats are not enough");
	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), 560 * MS);
	zassert_equal(active(&st), D);
	zassert_equal(st, CO_RDN_DEFAULT_ACTIVE);
	zassert_not_null(last_rdn(CO_RDN_EV_HB_OK));
	zassert_equal(t.veto_asked, 2);
}

ZTEST(co_redundancy, test_49_the_application_vetoes_the_switch)
{
	enum co_rdn_state st;

	boot_default_active();
	t.veto_refuses = true;
	heartbeats_until(BIT(R), BIT(D) | BIT(R), 400 * MS);
	zassert_equal(active(&st), D, "vetoed");
	zassert_equal(st, CO_RDN_DEFAULT_ACTIVE);
	zassert_not_null(last_rdn(CO_RDN_EV_VETOED));
	/* A command switches without asking. */
	zassert_ok(co_redundancy_switch_req(&t.node, CO_LINE_REDUNDANT));
	zassert_equal(active(&st), R);
	zassert_equal(t.veto_asked, 1);
}

ZTEST(co_redundancy, test_49_a_burst_of_held_back_heartbeats_is_not_three_cycles)
{
	enum co_rdn_state st;

	boot_default_active();
	heartbeats_until(BIT(R), BIT(D) | BIT(R), 400 * MS);
	zassert_equal(active(&st), R);
	/* A restored line delivers what it held back at once: three heartbeats of node 2. */
	heartbeat(D, 2);
	heartbeat(D, 2);
	heartbeat(D, 2);
	run_until(t.now + 1 * MS);
	zassert_equal(active(&st), R, "one cycle, not three");
	/* Then real cycles: 50 ms apart (at least half the consumer time). */
	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), t.now + 110 * MS);
	zassert_equal(active(&st), D, "the burst counted once, two real cycles after it");
}

/* --- Routing -------------------------------------------------------------------------------- */

ZTEST(co_redundancy, test_heartbeat_and_tpdo_go_on_both_lines)
{
	const uint8_t start[2] = {0x01, NODE_ID};

	run_until(200 * MS);
	zassert_true(count_id(D, 0x701) >= 4);
	zassert_equal(count_id(D, 0x701), count_id(R, 0x701), "heartbeat on both lines");
	rx(D, 0x000, 2, start);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(count_id(D, 0x181), 1);
	zassert_equal(count_id(R, 0x181), 1);
}

ZTEST(co_redundancy, test_nmt_from_either_line_and_pdo_copies_delivered_once)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	uint8_t v;

	rx(R, 0x000, 2, start);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL, "NMT from the redundant line");
	v = 0x11;
	rx(D, 0x182, 1, &v);
	run_until(t.now + 1 * MS);
	rx(R, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1, "the copy is dropped");
	/* A new value on the redundant line alone (the default line lost it) is taken. */
	v = 0x22;
	run_until(t.now + 1 * MS);
	rx(R, 0x182, 1, &v);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), 0x6200, 1, &v));
	co_node_unlock(&t.node);
	zassert_equal(v, 0x22);
	/* The same value again on the same line is a new frame, not a copy. */
	rx(R, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1);
	/* Its copy on the other line after the window is taken too. */
	run_until(t.now + CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US + 1000U);
	rx(D, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1);
}

static uint8_t rpdo_value(void)
{
	uint8_t v = 0;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), 0x6200, 1, &v));
	co_node_unlock(&t.node);
	return v;
}

/*
 * Each line carries the producer's frames in the order sent. The redundant line lost the copy
 * of 11h and brought 22h's: 11h can have no copy any more, so the 11h the producer sends next
 * (first on the redundant line, the default line about to fail) is a new value, not 11h's
 * late copy (it was dropped as one before, and lost with the default line).
 */
ZTEST(co_redundancy, test_a_copy_in_order_ends_the_wait_for_older_copies)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	uint8_t v;

	rx(D, 0x000, 2, start);
	v = 0x11;
	rx(D, 0x182, 1, &v);
	run_until(t.now + 1 * MS);
	v = 0x22;
	rx(D, 0x182, 1, &v);
	run_until(t.now + 1 * MS);
	rx(R, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1, "22h's copy is dropped");
	run_until(t.now + 1 * MS);
	v = 0x11;
	rx(R, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1, "the new 11h is no copy");
	zassert_equal(rpdo_value(), 0x11);
	/* Its copy on the default line, if it still comes, is one. */
	rx(D, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 2);
}

/* A loaded host holds one line's frames back for tens of milliseconds: still a copy. */
ZTEST(co_redundancy, test_a_copy_150_ms_late_is_dropped)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	uint8_t v = 0x5A;

	rx(D, 0x000, 2, start);
	rx(D, 0x182, 1, &v);
	run_until(t.now + 150 * MS);
	rx(R, 0x182, 1, &v);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1);
}

/*
 * A classic CAN frame may carry a DLC of 9 to 15, meaning 8 bytes: its copy is found by those
 * 8 bytes (nothing past the frame's data is read), and a frame that differs in them is none.
 */
ZTEST(co_redundancy, test_a_pdo_copy_with_a_dlc_over_8_is_compared_by_its_8_bytes)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	struct can_frame f = {.id = 0x182, .dlc = 12, .data = {0x33, 1, 2, 3, 4, 5, 6, 7}};

	rx(D, 0x000, 2, start);
	co_line_rx(&t.line[D], &f, t.now);
	run_until(t.now + 1 * MS);
	co_line_rx(&t.line[R], &f, t.now);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1, "its copy is dropped");
	zassert_equal(rpdo_value(), 0x33);

	f.data[0] = 0x44;
	co_line_rx(&t.line[D], &f, t.now);
	run_until(t.now + 1 * MS);
	f.data[7] = 0x70;
	co_line_rx(&t.line[R], &f, t.now);
	zassert_equal(co_pdo_rx_duplicates(&t.node), 1, "a frame that differs in byte 7 is new");
}

/* A cut controller's held frame, or frames a flood held up, come late on a failing line. */
ZTEST(co_redundancy, test_pdo_frames_of_a_line_that_lost_a_heartbeat_are_not_taken)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	uint8_t v;

	rx(D, 0x000, 2, start);
	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), 200 * MS);
	/* Node 2's heartbeat stops on the default line only: lost there after 100 ms. */
	heartbeats_until(BIT(R), BIT(D) | BIT(R), 400 * MS);
	zassert_not_null(last_rdn(CO_RDN_EV_HB_ERROR));
	v = 0x33;
	rx(D, 0x182, 1, &v);
	zassert_not_equal(rpdo_value(), 0x33, "a late frame of the failing line is not taken");
	v = 0x44;
	rx(R, 0x182, 1, &v);
	zassert_equal(rpdo_value(), 0x44, "the other line's frames are");
	/* Node 2 is back on the default line: its frames are taken again. */
	heartbeats_until(BIT(D) | BIT(R), BIT(D) | BIT(R), 500 * MS);
	zassert_not_null(last_rdn(CO_RDN_EV_HB_OK));
	v = 0x55;
	rx(D, 0x182, 1, &v);
	zassert_equal(rpdo_value(), 0x55);
	/* Heartbeats lost on both lines (node 2 on one, node 3 on the other): both are taken. */
	heartbeats_until(BIT(R), BIT(D), 800 * MS);
	v = 0x66;
	rx(D, 0x182, 1, &v);
	zassert_equal(rpdo_value(), 0x66, "no line is better than the other");
	v = 0x77;
	rx(R, 0x182, 1, &v);
	zassert_equal(rpdo_value(), 0x77);
}

ZTEST(co_redundancy, test_sync_counts_from_the_active_line_only)
{
	rx(R, 0x080, 0, NULL);
	zassert_equal(t.n_sync, 0, "the redundant line is not active");
	rx(D, 0x080, 0, NULL);
	zassert_equal(t.n_sync, 1);
	zassert_ok(co_redundancy_switch_req(&t.node, CO_LINE_REDUNDANT));
	rx(D, 0x080, 0, NULL);
	rx(R, 0x080, 0, NULL);
	zassert_equal(t.n_sync, 2);
}

ZTEST(co_redundancy, test_a_line_that_cannot_send_gets_no_process_data_and_drops_its_backlog)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	struct co_line_stats stats;

	rx(D, 0x000, 2, start);
	/* The default line's controller goes error passive (a cut): frames pile up there. */
	t.busy = true;
	co_line_inject_event(&t.line[D], CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	co_line_get_stats(&t.line[D], &stats);
	t.busy = false;
	run_until(t.now + 1 * MS);
	t.n_tx[D] = t.n_tx[R] = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(count_id(D, 0x181), 0, "no process data on a line that cannot send");
	zassert_equal(count_id(R, 0x181), 1);
	run_until(t.now + 120 * MS);
	zassert_true(count_id(D, 0x701) >= 2, "the heartbeat still goes there");
	co_line_inject_event(&t.line[D], CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_ACTIVE);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(count_id(D, 0x181), 1, "back on both lines");
	zassert_equal(count_id(R, 0x181), 2);
}

static int count_refused(int l, uint32_t id)
{
	int n = 0;

	for (int i = 0; i < t.n_refused[l]; i++) {
		n += t.refused[l][i] == id;
	}
	return n;
}

/* SocketCAN after ip link set ... down: no controller state, every send refused. */
ZTEST(co_redundancy, test_a_line_whose_sends_fail_with_enetdown_gets_no_process_data)
{
	const uint8_t start[2] = {0x01, NODE_ID};

	rx(D, 0x000, 2, start);
	run_until(t.now + 1 * MS);
	t.down[D] = true;
	/* Three refused before the line thread hears of it: no TPDO 1 failure for a link. */
	for (int i = 0; i < 3; i++) {
		(void)co_tpdo_send_req(&t.node, 0);
	}
	zassert_equal(count_refused(D, 0x181), 3);
	run_until(t.now + 1 * MS);
	t.n_refused[D] = 0;
	t.n_tx[R] = 0;
	for (int i = 0; i < 20; i++) {
		zassert_ok(co_tpdo_send_req(&t.node, 0));
	}
	zassert_equal(count_refused(D, 0x181), 0, "no process data tried on the down line");
	zassert_equal(count_id(R, 0x181), 20);
	run_until(t.now + 120 * MS);
	zassert_true(count_refused(D, 0x701) >= 2, "the heartbeat is still tried there");
	zassert_true(count_id(R, 0x701) >= 2, "and still goes out on the other line");
	zassert_is_null(last_rdn(CO_RDN_EV_TPDO_FAILED), "a link down is no TPDO 1 failure");

	/* The link is back, but nothing says so until a frame comes in there. */
	t.down[D] = false;
	t.n_tx[D] = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(count_id(D, 0x181), 0);
	heartbeat(D, 2);
	run_until(t.now + 1 * MS);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(count_id(D, 0x181), 1, "back on both lines");
}

ZTEST(co_redundancy, test_queued_process_data_withdrawn_when_the_line_goes_error_passive)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	struct co_line_stats before_stats, after_stats;

	rx(D, 0x000, 2, start);
	t.busy = true;
	for (int i = 0; i < 3; i++) {
		(void)co_tpdo_send_req(&t.node, 0);
	}
	co_line_get_stats(&t.line[D], &before_stats);
	co_line_inject_event(&t.line[D], CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	co_line_get_stats(&t.line[D], &after_stats);
	zassert_equal(after_stats.tx_purged - before_stats.tx_purged, 3, "three TPDOs withdrawn");
	t.busy = false;
	run_until(t.now + 1 * MS);
	zassert_equal(count_id(D, 0x181), 0, "none goes out stale");
	zassert_equal(count_id(R, 0x181), 3);
}

/* --- What else each line brings ---------------------------------------------------------- */

ZTEST(co_redundancy, test_emcy_copies_from_the_other_line_reach_the_consumer_once)
{
	const uint8_t e1[8] = {0x00, 0x50, 0x01, 1, 2, 3, 4, 5};
	const uint8_t e2[8] = {0x00, 0x42, 0x09};

	run_until(10 * MS);
	rx(D, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	rx(R, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 1, "node 2's EMCY on both lines is one emergency");
	/* The redundant line first works the same way. */
	rx(R, 0x082, 8, e2);
	rx(D, 0x082, 8, e2);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 2);
	zassert_equal(t.emcy_code[1], 0x4200);
	/* The same EMCY again on one line is a new emergency, and so is its copy's copy. */
	rx(D, 0x082, 8, e1);
	rx(D, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 4);
	rx(R, 0x082, 8, e1);
	rx(R, 0x082, 8, e1);
	rx(R, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 5, "two copies, one new");
	/* A copy later than the window is a new emergency (the PDO copies' limit too). */
	rx(D, 0x082, 8, e2);
	run_until(t.now + CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US + 10 * MS);
	rx(R, 0x082, 8, e2);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 7);
}

/* As for RPDOs: a copy in order ends the wait for the copies of the producer's older EMCYs. */
ZTEST(co_redundancy, test_emcy_copy_in_order_ends_the_wait_for_older_copies)
{
	const uint8_t e1[8] = {0x00, 0x50, 0x01, 1, 2, 3, 4, 5};
	const uint8_t e2[8] = {0x00, 0x42, 0x09};

	run_until(10 * MS);
	rx(D, 0x082, 8, e1);
	rx(D, 0x082, 8, e2);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 2);
	/* The redundant line lost e1's copy and brings e2's. */
	rx(R, 0x082, 8, e2);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 2, "e2's copy");
	/* The same emergency as e1 again, first on the redundant line: a new one. */
	rx(R, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 3, "not e1's late copy");
	rx(D, 0x082, 8, e1);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_emcy, 3, "its copy");
}

ZTEST(co_redundancy, test_extended_frames_of_the_redundant_line_reach_the_node)
{
	struct can_frame f = {.id = 0x1234567, .dlc = 1, .flags = CAN_FRAME_IDE};

	co_rx_init(&t.ext_rx, 0x1234567, on_ext, &t.node.lock, NULL);
	t.ext_rx.ext = true;
	zassert_ok(co_node_rx_register(&t.node, CO_LINE_DEFAULT, &t.ext_rx));
	co_line_rx(&t.line[D], &f, t.now);
	co_line_rx(&t.line[R], &f, t.now);
	run_until(t.now + 1 * MS);
	zassert_equal(t.n_ext, 2);
	zassert_equal(t.ext_line[0], D);
	zassert_equal(t.ext_line[1], R, "a 29-bit frame of the redundant line, handed over");
	co_rx_unregister(&t.ext_rx);
}

/* --- 50: SDO server ------------------------------------------------------------------------- */

ZTEST(co_redundancy, test_50_sdo_request_on_the_redundant_line_answered_there_only)
{
	const uint8_t upload[8] = {0x40, 0x17, 0x10, 0x00};

	run_until(10 * MS);
	t.n_tx[D] = t.n_tx[R] = 0;
	rx(R, 0x601, 8, upload);
	run_until(t.now + 1 * MS);
	zassert_equal(count_id(R, 0x581), 1);
	zassert_equal(count_id(D, 0x581), 0);
	rx(D, 0x601, 8, upload);
	run_until(t.now + 1 * MS);
	zassert_equal(count_id(D, 0x581), 1);
	zassert_equal(count_id(R, 0x581), 1);
}

/* --- 51: TPDO 1 supervision ----------------------------------------------------------------- */

ZTEST(co_redundancy, test_51_tpdo1_failures_stop_the_heartbeat_good_sends_resume_it)
{
	const uint8_t start[2] = {0x01, NODE_ID};
	int hb;

	rx(D, 0x000, 2, start);
	/* CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE=8: with the line busy the queue fills, then sends fail.
	 */
	t.busy = true;
	for (int i = 0; i < 8; i++) {
		(void)co_tpdo_send_req(&t.node, 0);
	}
	zassert_is_null(last_rdn(CO_RDN_EV_TPDO_FAILED), "queued sends do not count");
	for (int i = 0; i < 3; i++) {
		(void)co_tpdo_send_req(&t.node, 0);
	}
	zassert_not_null(last_rdn(CO_RDN_EV_TPDO_FAILED), "three failures: 12");
	t.busy = false;
	run_until(t.now + 1 * MS);
	t.n_tx[D] = t.n_tx[R] = 0;
	run_until(t.now + 300 * MS);
	zassert_equal(count_id(D, 0x701) + count_id(R, 0x701), 0, "heartbeat stopped");
	for (int i = 0; i < 11; i++) {
		zassert_ok(co_tpdo_send_req(&t.node, 0));
	}
	zassert_is_null(last_rdn(CO_RDN_EV_TPDO_OK), "11 good sends: 1 left");
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_not_null(last_rdn(CO_RDN_EV_TPDO_OK));
	hb = count_id(D, 0x701);
	run_until(t.now + 200 * MS);
	zassert_true(count_id(D, 0x701) > hb, "heartbeat resumed");
}

ZTEST(co_redundancy, test_51_twelve_good_sends_resume_after_any_number_of_failures)
{
	const uint8_t start[2] = {0x01, NODE_ID};

	rx(D, 0x000, 2, start);
	t.busy = true;
	for (int i = 0; i < 8 + 40; i++) {
		(void)co_tpdo_send_req(&t.node, 0);
	}
	zassert_not_null(last_rdn(CO_RDN_EV_TPDO_FAILED));
	t.busy = false;
	run_until(t.now + 1 * MS);
	for (int i = 0; i < 12; i++) {
		zassert_ok(co_tpdo_send_req(&t.node, 0));
	}
	zassert_not_null(last_rdn(CO_RDN_EV_TPDO_OK), "the counter stops at the limit");
}

#else /* CONFIG_CANOPEN_REDUNDANCY_ECSS */

/* --- 52: the ECSS-E-ST-50-15C toggle profile ------------------------------------------------ */

static uint8_t od_u8(uint16_t index, uint8_t sub)
{
	uint8_t v = 0xAA;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), index, sub, &v));
	co_node_unlock(&t.node);
	return v;
}

/* Master (node 2) heartbeat time 550 ms, Ttoggle 3, Ntoggle 5 (the published test numbers). */
static void ecss_setup(void)
{
	co_node_lock(&t.node);
	zassert_ok(co_od_set_u32(co_node_od(&t.node), 0x1016, 1, 0x00020226, CO_OD_WRITER_APP));
	co_node_unlock(&t.node);
	t.n_ev = 0;
}

static int switches_at(uint64_t *at, int max)
{
	int n = 0;

	for (int i = 0; i < t.n_ev && n < max; i++) {
		if (t.ev[i].type == CO_EV_REDUNDANCY &&
		    t.ev[i].redundancy.what == CO_RDN_EV_SWITCH) {
			at[n++] = t.ev[i].redundancy.time_us;
		}
	}
	return n;
}

ZTEST(co_redundancy, test_52_ecss_toggles_every_ttoggle_periods_then_no_master)
{
	enum co_rdn_state st;
	uint64_t at[8];

	ecss_setup();
	run_until(100 * MS);
	heartbeat(D, 2); /* the master's last heartbeat */
	run_until(1749 * MS);
	zassert_equal(switches_at(at, 8), 0);
	run_until(10000 * MS);
	zassert_equal(switches_at(at, 8), 5, "Ntoggle switches");
	for (int k = 0; k < 5; k++) {
		zassert_equal(at[k], (100 + 1650 * (k + 1)) * MS, "switch %d", k);
	}
	zassert_equal(od_u8(0x1F60, 4), 5, "Ctoggle");
	zassert_equal(active(&st), R, "D -> R -> D -> R -> D -> R");
	zassert_equal(st, CO_RDN_NO_MASTER);
	zassert_equal(od_u8(0x1F60, 1), R, "Bdefault := the current bus");
	zassert_not_null(last_rdn(CO_RDN_EV_NO_MASTER));
}

ZTEST(co_redundancy, test_52_master_heartbeat_on_the_new_bus_stops_toggling)
{
	enum co_rdn_state st;
	uint64_t at[8];

	ecss_setup();
	run_until(100 * MS);
	heartbeat(D, 2);
	run_until(1800 * MS);
	zassert_equal(switches_at(at, 8), 1);
	zassert_equal(active(&st), R);
	heartbeat(D, 2); /* on the old bus: not the active one, ignored */
	heartbeat(R, 2);
	for (uint64_t ms = 2300; ms <= 9000; ms += 500) {
		run_until(ms * MS);
		heartbeat(R, 2);
	}
	zassert_equal(switches_at(at, 8), 1, "the master is on the active bus");
	zassert_equal(od_u8(0x1F60, 4), 1);
}

ZTEST(co_redundancy, test_52_ecss_talks_on_the_active_bus_only)
{
	run_until(200 * MS);
	zassert_true(count_id(D, 0x701) >= 3);
	zassert_equal(count_id(R, 0x701), 0);
}

#endif /* CONFIG_CANOPEN_REDUNDANCY_ECSS */

/* --- Errors --------------------------------------------------------------------------------- */

ZTEST(co_redundancy, test_switch_request_errors)
{
	zassert_equal(co_redundancy_switch_req(&t.node, 5), -EINVAL);
}
