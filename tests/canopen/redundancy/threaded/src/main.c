/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Redundant lines (CiA 302-6) with real line threads on two virtual buses (bit timing on,
 * 500 kbit/s): a master (node 1) and two slaves (nodes 2, 3), each with one controller on bus 0
 * (its default line) and one on bus 1 (its redundant line). Every node sends its heartbeat
 * every 50 ms; the master supervises the slaves, the slaves the master, with 125 ms. The slaves
 * send a counter in TPDO 1 every 10 ms (a new value in each frame); the master's application
 * counts how often each value reaches it. Controller 6 (bus 0) is a raw flooder, controller 7
 * (bus 1) a raw observer that records the values seen on the redundant line.
 *
 * What is asserted is behaviour, with a scheduling allowance, not timing precision:
 * - a cut of the default line (every controller of bus 0) makes every node switch to the
 *   redundant line within the consumer time + one heartbeat period + the allowance, and not
 *   before a heartbeat could have been missed; no value that reached the redundant line is lost
 *   or reaches the application twice;
 * - restoring the default line brings every node back, after three heartbeat cycles there;
 * - a bus-off of one node's default controller moves that node and the master, not the other
 *   slave; a bus-off that recovers at once, error passive, change nothing;
 * - a flood of high-priority frames on the default line acts like a cut.
 *
 * Tests marked KNOWN BUG (ZTEST_EXPECT_FAIL; none at the moment) assert what doc/redundancy.md
 * promises and the service does not do yet; each says why. Remove the mark when the service is
 * fixed (the test then fails as "passed unexpectedly" until the mark goes). Their preconditions are
 * assumptions: one that no longer holds skips the test, which also fails it (a skip is not the
 * failure expected), rather than passing it for the wrong reason.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/random/random.h>
#include <zephyr/sys/atomic.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>
#include <canopen/errctl.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/redundancy.h>

#include "thr_master_od.h"
#include "thr_slave_od.h"

#define N_UNITS     3
#define N_SLAVES    2
#define D           CO_LINE_DEFAULT
#define R           CO_LINE_REDUNDANT
#define HB_MS       50U
#define CONSUMER_MS 125U
#define PDO_MS      10U
/*
 * What the threads may be late by on a loaded machine, and much more under TSan (seen: a
 * switch 600 ms after the start of a flood under TSan and 427 ms without, with load average
 * 4.5 on two cores shared with other builds; 100 ms when the machine is quiet).
 */
#define ALLOW_MS    (IS_ENABLED(CONFIG_TSAN) ? 1000U : 400U)
/* The earliest a cut can be noticed: the last heartbeat came at most a period before it. */
#define EARLIEST_MS (CONSUMER_MS - HB_MS)
#define BOUND_MS    (CONSUMER_MS + HB_MS)
#define MAX_VALUES  4096U
#define MAX_EVENTS  256
#define IDX_COUNTER 0x2000U
#define IDX_COUNTS  0x2100U
#define IDX_RDN     0x1F60U
#define FLOOD_ID    0x001U

struct rec {
	struct co_event ev;
	uint64_t seen_us; /* when the listener ran */
};

struct unit {
	const char *name;
	uint8_t id;
	struct co_line line[CO_NODE_LINES];
	struct co_node node;
	struct co_listener listener;
	const struct device *can[CO_NODE_LINES];
	/* Under the node's mutex. */
	uint32_t produced; /* slave: the last value sampled into TPDO 1 */
	struct rec ev[MAX_EVENTS];
	int n_ev;
};

static struct unit units[N_UNITS] = {
	{.name = "master", .id = 1},
	{.name = "node2", .id = 2},
	{.name = "node3", .id = 3},
};
#define MASTER (&units[0])
#define NODE2  (&units[1])
#define NODE3  (&units[2])

static struct thr_master_od_ram master_ram;
static struct thr_slave_od_ram slave_ram[N_SLAVES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_UNITS *CO_NODE_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* Master: how often each value of each slave reached the application (under its mutex). */
static uint8_t delivered[N_SLAVES][MAX_VALUES];
/* ... the line and time of the first delivery, and the first few second ones, to show. */
static uint8_t first_line[N_SLAVES][MAX_VALUES];
static uint64_t first_at[N_SLAVES][MAX_VALUES];
#define SHOW_TWICE 4
static struct {
	uint32_t value;
	uint8_t line;
	uint64_t at;
} again[N_SLAVES][SHOW_TWICE];
static int n_again[N_SLAVES];
/* Values seen on the redundant line by the observer (its callback runs in the bus thread). */
static ATOMIC_DEFINE(on_redundant[N_SLAVES], MAX_VALUES);

static const struct device *flooder;
static const struct device *observer;

/* --- Network -------------------------------------------------------------------------------- */

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct unit *u = user_data;

	if (u->n_ev < MAX_EVENTS) {
		u->ev[u->n_ev++] = (struct rec){.ev = *ev, .seen_us = co_line_now()};
	}
	return 0;
}

static void tpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	struct unit *u = user_data;

	if (num == 0U && u->produced + 1U < MAX_VALUES) {
		u->produced++;
		(void)co_od_set_u32(co_node_od(node), IDX_COUNTER, 0, u->produced,
				    CO_OD_WRITER_APP);
	}
}

static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	uint32_t v = 0U;

	if (num >= N_SLAVES ||
	    co_od_get_u32(co_node_od(node), IDX_COUNTS, (uint8_t)(num + 1U), &v) != 0U ||
	    v >= MAX_VALUES || delivered[num][v] == UINT8_MAX) {
		return;
	}
	if (delivered[num][v]++ == 0U) {
		first_line[num][v] = co_node_rx_line(node);
		first_at[num][v] = co_line_now();
	} else if (n_again[num] < SHOW_TWICE) {
		again[num][n_again[num]++] =
			(typeof(again[0][0])){v, co_node_rx_line(node), co_line_now()};
	}
}

static void observe(const struct device *dev, struct can_frame *frame, void *user_data)
{
	uint32_t slave = (frame->id & 0x7FU) - 2U;
	uint32_t v = sys_get_le32(frame->data);

	if (slave < N_SLAVES && frame->dlc >= 4U && v < MAX_VALUES) {
		atomic_set_bit(on_redundant[slave], v);
	}
}

/* Heartbeats that got through the flood on bus 0 (seen by the flooder's own controller) after
 * this time [µs, low 32 bits; 0: not counting].
 */
static atomic_t leak_after;
static atomic_t leaked;

static void heartbeat_on_bus0(const struct device *dev, struct can_frame *frame, void *user_data)
{
	uint32_t after = (uint32_t)atomic_get(&leak_after);

	if (after != 0U && (int32_t)((uint32_t)co_line_now() - after) > 0) {
		atomic_inc(&leaked);
	}
}

static void unit_start(struct unit *u, int index)
{
	const struct co_od_def *def = u == MASTER ? &thr_master_od_def : &thr_slave_od_def;
	void *ram = u == MASTER ? (void *)&master_ram : (void *)&slave_ram[index - 1];
	static const char *const names[N_UNITS][CO_NODE_LINES] = {
		{"m-D", "m-R"}, {"n2-D", "n2-R"}, {"n3-D", "n3-R"}};
	char dev_name[16];

	for (int l = 0; l < (int)CO_NODE_LINES; l++) {
		snprintk(dev_name, sizeof(dev_name), "can_virtual%d", 2 * index + l);
		u->can[l] = device_get_binding(dev_name);
		zassert_not_null(u->can[l]);
		zassert_equal(can_virtual_get_bus(u->can[l]), l, "controller 2i + l on bus l");
		zassert_ok(co_line_init(&u->line[l], names[index][l], u->can[l]));
	}
	/* Node 2's default controller recovers from bus-off only when told (the bus-off tests). */
	if (u == NODE2) {
		zassert_ok(can_set_mode(u->can[D], CAN_MODE_MANUAL_RECOVERY));
	}
	zassert_ok(co_node_init(&u->node, u->name, &u->line[D], def, ram, u->id));
	zassert_ok(co_node_attach_line(&u->node, CO_LINE_REDUNDANT, &u->line[R]));
	co_listener_init(&u->listener, u->name,
			 CO_EV_BIT(CO_EV_REDUNDANCY) | CO_EV_BIT(CO_EV_HB) | CO_EV_BIT(CO_EV_LINE),
			 on_event, u);
	zassert_ok(co_node_listener_add(&u->node, &u->listener));
	if (u == MASTER) {
		co_rpdo_set_ind(&u->node, rpdo_ind, NULL);
	} else {
		co_tpdo_set_ind(&u->node, tpdo_ind, u);
	}
	for (int l = 0; l < (int)CO_NODE_LINES; l++) {
		zassert_ok(co_line_start(&u->line[l], stacks[index * CO_NODE_LINES + l],
					 K_THREAD_STACK_SIZEOF(stacks[0]),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	}
	zassert_ok(co_node_start(&u->node));
}

static void *setup(void)
{
	const struct can_filter tpdo1 = {.id = 0x180, .mask = 0x7F0};
	const struct can_filter heartbeats = {.id = 0x700, .mask = 0x780};

	for (int bus = 0; bus < 2; bus++) {
		zassert_ok(can_virtual_bus_set_bit_timing(bus, true));
	}
	flooder = device_get_binding("can_virtual6");
	observer = device_get_binding("can_virtual7");
	zassert_equal(can_virtual_get_bus(flooder), 0);
	zassert_equal(can_virtual_get_bus(observer), 1);
	zassert_ok(can_start(flooder));
	zassert_ok(can_start(observer));
	zassert_true(can_add_rx_filter(observer, observe, NULL, &tpdo1) >= 0);
	zassert_true(can_add_rx_filter(flooder, heartbeat_on_bus0, NULL, &heartbeats) >= 0);
	for (int i = 0; i < N_UNITS; i++) {
		unit_start(&units[i], i);
	}
	return NULL;
}

/* --- Helpers -------------------------------------------------------------------------------- */

static uint64_t now_us(void)
{
	return co_line_now();
}

static unsigned int ms_of(uint64_t us)
{
	return (unsigned int)(us / 1000U);
}

/* "%u.%u" ms of a span in µs. */
#define MS_ARGS(us) ms_of(us), (unsigned int)((us) % 1000U / 100U)

static void nmt_send(uint8_t cs)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, 0}};

	co_node_lock(&MASTER->node);
	zassert_ok(co_node_send(&MASTER->node, CO_ROUTE_ACTIVE, &f));
	co_node_unlock(&MASTER->node);
}

static void set_u8(struct unit *u, uint16_t index, uint8_t sub, uint8_t v)
{
	co_node_lock(&u->node);
	zassert_ok(co_od_set_u8(co_node_od(&u->node), index, sub, v, CO_OD_WRITER_APP));
	co_node_unlock(&u->node);
}

/* Line @p l of every node: every controller of bus @p l. */
static uint64_t line_cut(int l)
{
	uint64_t at = now_us();

	for (int i = 0; i < N_UNITS; i++) {
		zassert_ok(can_virtual_cut(units[i].can[l]));
	}
	return at;
}

static uint64_t line_restore(int l)
{
	uint64_t at = now_us();

	for (int i = 0; i < N_UNITS; i++) {
		zassert_ok(can_virtual_restore(units[i].can[l]));
	}
	return at;
}

static bool all_on(int l, uint32_t timeout_ms)
{
	int64_t end = k_uptime_get() + timeout_ms;

	do {
		bool all = true;

		for (int i = 0; i < N_UNITS; i++) {
			all = all && co_redundancy_get(&units[i].node, NULL, NULL) == l;
		}
		if (all) {
			return true;
		}
		k_msleep(2);
	} while (k_uptime_get() < end);
	return false;
}

/* When @p u heard its switch to line @p l after @p after_us (0: none). */
static uint64_t switched_at(struct unit *u, int l, uint64_t after_us)
{
	uint64_t at = 0U;

	co_node_lock(&u->node);
	for (int i = 0; i < u->n_ev && at == 0U; i++) {
		const struct rec *r = &u->ev[i];

		if (r->ev.type == CO_EV_REDUNDANCY && r->ev.redundancy.what == CO_RDN_EV_SWITCH &&
		    r->ev.redundancy.line == l && r->seen_us >= after_us) {
			at = r->seen_us;
		}
	}
	co_node_unlock(&u->node);
	return at;
}

/* Redundancy events @p what on line @p l (any line: 0xFF) after @p after_us. */
static int count_rdn(struct unit *u, uint8_t what, uint8_t l, uint64_t after_us)
{
	int n = 0;

	co_node_lock(&u->node);
	for (int i = 0; i < u->n_ev; i++) {
		const struct rec *r = &u->ev[i];

		n += r->ev.type == CO_EV_REDUNDANCY && r->ev.redundancy.what == what &&
		     (l == 0xFFU || r->ev.redundancy.line == l) && r->seen_us >= after_us;
	}
	co_node_unlock(&u->node);
	return n;
}

/* Heartbeat consumer (1016h) events @p what after @p after_us: the node lost on every line. */
static int count_hb(struct unit *u, enum co_hb_event what, uint64_t after_us)
{
	int n = 0;

	co_node_lock(&u->node);
	for (int i = 0; i < u->n_ev; i++) {
		const struct rec *r = &u->ev[i];

		n += r->ev.type == CO_EV_HB && r->ev.hb.event == what && r->seen_us >= after_us;
	}
	co_node_unlock(&u->node);
	return n;
}

/* Every node switched to @p l within [EARLIEST_MS, BOUND_MS + ALLOW_MS] of @p fault_us. */
static void assert_switch_within_bound(struct unit *u, int l, uint64_t fault_us)
{
	uint64_t at = switched_at(u, l, fault_us);
	uint64_t d = at - fault_us;

	zassert_true(at != 0U, "%s did not switch to line %d", u->name, l);
	TC_PRINT("%s: on line %d %u.%u ms after the fault (bound %u ms + %u ms)\n", u->name, l,
		 MS_ARGS(d), BOUND_MS, ALLOW_MS);
	zassert_true(d >= EARLIEST_MS * 1000U,
		     "%s switched %u ms after the fault, before any "
		     "heartbeat could be missed (%u ms)",
		     u->name, ms_of(d), EARLIEST_MS);
	zassert_true(d <= (BOUND_MS + ALLOW_MS) * 1000U, "%s switched %u ms after the fault",
		     u->name, ms_of(d));
}

/* Stop the slaves' PDOs (NMT pre-operational on the master's active line) and let the last
 * frames arrive.
 */
static void stop_slaves(void)
{
	nmt_send(CO_NMT_CS_ENTER_PRE_OPERATIONAL);
	k_msleep(100);
}

struct tally {
	uint32_t sent;
	uint32_t delivered;   /* distinct values */
	uint32_t twice;       /* deliveries beyond the first */
	uint32_t on_r;        /* values seen on the redundant line */
	uint32_t on_r_missed; /* of those, never delivered */
	uint32_t first_missed;
};

static void tally(int slave, struct tally *t)
{
	struct unit *u = &units[slave + 1];

	memset(t, 0, sizeof(*t));
	co_node_lock(&u->node);
	t->sent = u->produced;
	co_node_unlock(&u->node);
	co_node_lock(&MASTER->node);
	for (uint32_t v = 1; v < MAX_VALUES; v++) {
		bool r = atomic_test_bit(on_redundant[slave], v);

		t->delivered += delivered[slave][v] > 0U;
		t->twice += delivered[slave][v] > 1U ? delivered[slave][v] - 1U : 0U;
		t->on_r += r;
		if (r && delivered[slave][v] == 0U && t->on_r_missed++ == 0U) {
			t->first_missed = v;
		}
	}
	co_node_unlock(&MASTER->node);
	TC_PRINT("node %u: sent %u, delivered %u, twice %u, on the redundant line %u\n", u->id,
		 t->sent, t->delivered, t->twice, t->on_r);
	co_node_lock(&MASTER->node);
	for (int i = 0; i < n_again[slave]; i++) {
		uint32_t v = again[slave][i].value;
		uint64_t d = again[slave][i].at - first_at[slave][v];

		TC_PRINT("  value %u again on line %u, %u.%u ms after it came on line %u\n", v,
			 again[slave][i].line, MS_ARGS(d), first_line[slave][v]);
	}
	co_node_unlock(&MASTER->node);
}

/*
 * 1: report, not fail on, values delivered twice by chance. The duplicate filter matches a
 * copy within CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US (250 ms) of the frame it took, by receive
 * stamps, and the last CONFIG_CANOPEN_REDUNDANCY_DUP_DEPTH frames; on a loaded host a bus or
 * line thread late by more than that lets copies through (with a 50 ms window: seen with
 * load average 4.5 on two cores, 11 values of node 2 again on the redundant line 80-110 ms
 * after the default line's, in the error-passive test).
 * The deterministic cases are strict: test_a_late_line_thread_delivers_no_value_twice (35 ms)
 * and test_copies_held_back_on_a_failed_line_are_not_delivered_again.
 */
#define TOLERATE_CHANCE_DUPLICATES 1

/*
 * Every value sent reached the application (@p lost), none of them twice (@p twice: strictly
 * when @p strict, else within TOLERATE_CHANCE_DUPLICATES).
 */
static void assert_values_ex(bool lost, bool twice, bool strict)
{
	for (int s = 0; s < N_SLAVES; s++) {
		struct tally t;

		tally(s, &t);
		zassert_true(t.sent > 0U, "node %u sent nothing", s + 2);
		if (lost) {
			zassert_equal(t.on_r_missed, 0U,
				      "node %u: %u values reached the redundant line and never the "
				      "application (the first: %u)",
				      s + 2, t.on_r_missed, t.first_missed);
			zassert_equal(t.delivered, t.sent, "node %u: %u of %u values lost", s + 2,
				      t.sent - t.delivered, t.sent);
		}
		if (twice && t.twice != 0U && !strict && TOLERATE_CHANCE_DUPLICATES) {
			TC_PRINT("KNOWN BUG: node %u: %u values reached the application twice "
				 "(tolerated here, see "
				 "test_a_late_line_thread_delivers_no_value_twice)\n",
				 s + 2, t.twice);
		} else if (twice) {
			zassert_equal(t.twice, 0U,
				      "node %u: %u values reached the application twice", s + 2,
				      t.twice);
		}
	}
}

static void assert_values(bool lost, bool twice)
{
	assert_values_ex(lost, twice, false);
}

/* Nothing moves for @p ms after @p since_us. */
static void assert_no_switch(uint32_t ms, uint64_t since_us)
{
	k_msleep(ms);
	for (int i = 0; i < N_UNITS; i++) {
		zassert_equal(count_rdn(&units[i], CO_RDN_EV_SWITCH, 0xFFU, since_us), 0,
			      "%s switched", units[i].name);
		zassert_equal(co_redundancy_get(&units[i].node, NULL, NULL), D);
	}
}

/* --- Flood ---------------------------------------------------------------------------------- */

static atomic_t flooding;
static K_THREAD_STACK_DEFINE(flood_stack, 2048);
static struct k_thread flood_thread;

static void flood_sent(const struct device *dev, int error, void *user_data)
{
}

/*
 * A babbling controller: the lowest identifier, back to back, wins every arbitration. With a
 * completion callback can_send() only waits for a free transmit slot, so the controller always
 * has frames pending when the bus turns idle (without one it would wait for each frame).
 */
static void flood(void *p1, void *p2, void *p3)
{
	const struct can_frame f = {.id = FLOOD_ID, .dlc = 8};

	while (atomic_get(&flooding) != 0) {
		(void)can_send(flooder, &f, K_MSEC(50), flood_sent, NULL);
	}
}

static void flood_start(void)
{
	atomic_set(&flooding, 1);
	k_thread_create(&flood_thread, flood_stack, K_THREAD_STACK_SIZEOF(flood_stack), flood, NULL,
			NULL, NULL, 1, 0, K_NO_WAIT);
}

static void flood_stop(void)
{
	if (atomic_set(&flooding, 0) != 0) {
		zassert_ok(k_thread_join(&flood_thread, K_SECONDS(5)));
	}
}

/* --- Each test starts from a network on its default line, the slaves sending ---------------- */

static bool slaves_operational(void)
{
	for (uint8_t id = 2; id < 2 + N_SLAVES; id++) {
		enum co_nmt_state st = CO_NMT_INITIALISING;

		if (co_hb_get_remote_state(&MASTER->node, id, &st) != 0 ||
		    st != CO_NMT_OPERATIONAL) {
			return false;
		}
	}
	return true;
}

static void before(void *f)
{
	int64_t end;

	flood_stop();
	for (int i = 0; i < N_UNITS; i++) {
		for (int l = 0; l < (int)CO_NODE_LINES; l++) {
			(void)can_virtual_restore(units[i].can[l]);
			(void)can_virtual_set_state(units[i].can[l], CAN_STATE_ERROR_ACTIVE);
		}
	}
	for (int bus = 0; bus < 2; bus++) {
		(void)can_virtual_clear_faults(bus);
	}
	/* What the last test left queued goes out, then every node starts afresh. */
	k_msleep(300);
	for (int i = 0; i < N_UNITS; i++) {
		zassert_ok(co_nmt_req(&units[i].node, CO_NMT_CS_RESET_COMMUNICATION));
	}
	/* The last frames the slaves sent before arrive before the counts start. */
	k_msleep(50);
	for (int i = 0; i < N_UNITS; i++) {
		co_node_lock(&units[i].node);
		units[i].n_ev = 0;
		units[i].produced = 0U;
		co_node_unlock(&units[i].node);
	}
	co_node_lock(&MASTER->node);
	memset(delivered, 0, sizeof(delivered));
	memset(n_again, 0, sizeof(n_again));
	co_node_unlock(&MASTER->node);
	for (int s = 0; s < N_SLAVES; s++) {
		for (uint32_t v = 0; v < MAX_VALUES; v++) {
			atomic_clear_bit(on_redundant[s], v);
		}
	}
	for (int i = 0; i < N_UNITS; i++) {
		enum co_rdn_state st;

		for (end = k_uptime_get() + 2000; k_uptime_get() < end;) {
			(void)co_redundancy_get(&units[i].node, &st, NULL);
			if (st == CO_RDN_DEFAULT_ACTIVE) {
				break;
			}
			k_msleep(5);
		}
		zassert_equal(st, CO_RDN_DEFAULT_ACTIVE, "%s: the default line is not active",
			      units[i].name);
	}
	zassert_ok(co_nmt_req(&MASTER->node, CO_NMT_CS_START));
	nmt_send(CO_NMT_CS_START);
	for (end = k_uptime_get() + 2000; !slaves_operational() && k_uptime_get() < end;) {
		k_msleep(5);
	}
	zassert_true(slaves_operational());
	/* The fault falls anywhere in the heartbeat cycle (repeatable with --seed). */
	k_msleep(200 + sys_rand32_get() % HB_MS);
}

static void after(void *f)
{
	atomic_set(&leak_after, 0);
	flood_stop();
}

ZTEST_SUITE(co_redundancy_threaded, NULL, setup, before, after, NULL);

/* --- Cut and restore of the default line ---------------------------------------------------- */

ZTEST(co_redundancy_threaded, test_cut_default_line_every_node_switches_within_the_bound)
{
	uint64_t cut = line_cut(D);

	zassert_true(all_on(R, BOUND_MS + ALLOW_MS + 500U), "every node on the redundant line");
	for (int i = 0; i < N_UNITS; i++) {
		assert_switch_within_bound(&units[i], R, cut);
	}
	/* Each lost every heartbeat of the default line (the last one a period after the first
	 * switch at most), and none of the redundant line.
	 */
	k_msleep(HB_MS + ALLOW_MS);
	zassert_equal(count_rdn(MASTER, CO_RDN_EV_HB_ERROR, D, cut), N_SLAVES);
	zassert_equal(count_rdn(NODE2, CO_RDN_EV_HB_ERROR, D, cut), 1);
	for (int i = 0; i < N_UNITS; i++) {
		zassert_equal(count_rdn(&units[i], CO_RDN_EV_HB_ERROR, R, cut), 0);
		zassert_equal(count_hb(&units[i], CO_HB_EV_LOST, cut), 0,
			      "%s: 1016h saw a node lost on both lines", units[i].name);
	}
}

ZTEST(co_redundancy_threaded, test_cut_default_line_no_value_lost_or_delivered_twice)
{
	(void)line_cut(D);
	zassert_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(300);
	stop_slaves();
	assert_values(true, true);
}

ZTEST(co_redundancy_threaded, test_restore_default_line_every_node_switches_back)
{
	uint64_t back;

	(void)line_cut(D);
	zassert_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(300);
	back = line_restore(D);
	zassert_true(all_on(D, 3U * HB_MS + ALLOW_MS + 500U), "every node back on the default");
	for (int i = 0; i < N_UNITS; i++) {
		uint64_t d = switched_at(&units[i], D, back) - back;

		TC_PRINT("%s: back on the default line %u.%u ms after the restore\n", units[i].name,
			 MS_ARGS(d));
		zassert_true(d <= (3U * HB_MS + ALLOW_MS) * 1000U, "%s: %u ms", units[i].name,
			     ms_of(d));
	}
	k_msleep(300);
	stop_slaves();
	assert_values(true, false);
}

/*
 * Heartbeats a cut controller held back go out back to back when it comes back; they are no
 * proof of three heartbeat cycles (the service counts a heartbeat as a cycle only half a
 * consumer time after the last one it counted).
 */
ZTEST(co_redundancy_threaded, test_restore_default_line_switches_back_after_three_heartbeat_cycles)
{
	uint64_t back;

	(void)line_cut(D);
	zassume_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(300);
	back = line_restore(D);
	zassume_true(all_on(D, 3U * HB_MS + ALLOW_MS + 500U));
	for (int i = 0; i < N_UNITS; i++) {
		uint64_t d = switched_at(&units[i], D, back) - back;

		/* Three heartbeats one period apart: the third at least two periods after. */
		zassert_true(d >= (2U * HB_MS - 10U) * 1000U,
			     "%s back on the default line %u.%u ms after the restore, before "
			     "three heartbeat cycles (%u ms)",
			     units[i].name, MS_ARGS(d), 2U * HB_MS);
	}
}

/*
 * No value twice after a restore. The process data the node queued on the cut line are
 * withdrawn when its controller goes error passive, but the frame the controller itself holds
 * (handed to the driver before the cut, retransmitted without acknowledgement; Zephyr's CAN
 * API cannot abort it) goes out when the line comes back, long after its copy on the
 * redundant line. It comes before any heartbeat there, while the master still has its
 * supervised heartbeats lost on that line and none on the other: RPDOs of such a line are
 * not taken (it delivered one value per slave and restore twice before).
 */
ZTEST(co_redundancy_threaded, test_restore_default_line_delivers_no_value_twice)
{
	(void)line_cut(D);
	zassume_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(300);
	(void)line_restore(D);
	zassume_true(all_on(D, 3U * HB_MS + ALLOW_MS + 500U));
	k_msleep(300);
	stop_slaves();
	assert_values_ex(false, true, true);
}

/* The master's default line thread stops for a while (a long handler, a burst to dispatch). */
#define STALL_MS (3U * PDO_MS + 5U)

static void stall(struct co_timer *timer, uint64_t now_us)
{
	k_msleep(STALL_MS);
}

/*
 * A line thread of the master late by more than a PDO period: while the default line's thread
 * is held up, the redundant line's thread takes values N, N+1, N+2, ...; the default line's
 * copies that follow must all be recognised (each RPDO remembers its last
 * CONFIG_CANOPEN_REDUNDANCY_DUP_DEPTH frames, not just the last).
 */
ZTEST(co_redundancy_threaded, test_a_late_line_thread_delivers_no_value_twice)
{
	static struct co_timer stall_timer;

	co_timer_init(&stall_timer, stall, NULL, NULL);
	co_timer_start(&MASTER->line[D], &stall_timer, now_us());
	k_msleep(200);
	stop_slaves();
	/* Nothing is lost, whatever the order. */
	assert_values(true, false);
	assert_values_ex(false, true, true);
}

/* --- A cut longer than the TX queue holds --------------------------------------------------- */

/* 160 frames of TX queue and 8 in the controller, at about 120 frames per second. */
#define LONG_CUT_MS 2500

ZTEST(co_redundancy_threaded, test_long_cut_without_tpdo1_supervision_loses_nothing)
{
	uint64_t cut = line_cut(D);

	zassert_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(LONG_CUT_MS);
	for (int i = 0; i < N_UNITS; i++) {
		zassert_equal(count_rdn(&units[i], CO_RDN_EV_HB_ERROR, R, cut), 0,
			      "%s lost a heartbeat on the redundant line", units[i].name);
		zassert_equal(count_hb(&units[i], CO_HB_EV_LOST, cut), 0);
	}
	stop_slaves();
	assert_values(true, true);
}

/*
 * With TPDO 1 supervision (1F60h:05 = 12) a long cut of the default line leaves the
 * heartbeat on the redundant line alone: a controller in error passive gets no process data
 * (CO_ROUTE_PROCESS leaves its line out), so TPDO 1 does not fail on it.
 */
ZTEST(co_redundancy_threaded, test_long_cut_keeps_the_heartbeat_on_the_redundant_line)
{
	uint64_t cut;

	set_u8(NODE2, IDX_RDN, 5, 12);
	set_u8(NODE3, IDX_RDN, 5, 12);
	cut = line_cut(D);
	zassume_true(all_on(R, BOUND_MS + ALLOW_MS + 500U));
	k_msleep(LONG_CUT_MS);
	zassert_equal(count_rdn(MASTER, CO_RDN_EV_HB_ERROR, R, cut), 0,
		      "the master lost %d slave heartbeats on the redundant line",
		      count_rdn(MASTER, CO_RDN_EV_HB_ERROR, R, cut));
	zassert_equal(count_hb(MASTER, CO_HB_EV_LOST, cut), 0,
		      "the master's 1016h lost the slaves on both lines");
}

/*
 * A long cut does not count as TPDO 1 failures: the cut line's controller goes error passive
 * and gets no process data, so every TPDO 1 reaches the redundant line. (The counter's cap,
 * twelve good sends after any number of failures, is tested on simulated time in
 * tests/canopen/redundancy.)
 */
ZTEST(co_redundancy_threaded, test_long_cut_is_no_tpdo1_failure)
{
	set_u8(NODE2, IDX_RDN, 5, 12);
	set_u8(NODE3, IDX_RDN, 5, 12);
	(void)line_cut(D);
	k_msleep(LONG_CUT_MS);
	zassert_equal(count_rdn(NODE2, CO_RDN_EV_TPDO_FAILED, 0xFFU, 0U), 0);
	zassert_equal(count_rdn(NODE3, CO_RDN_EV_TPDO_FAILED, 0xFFU, 0U), 0);
	(void)line_restore(D);
}

/* --- One controller in trouble -------------------------------------------------------------- */

ZTEST(co_redundancy_threaded, test_bus_off_of_a_default_controller_moves_its_node_and_the_master)
{
	uint64_t off = now_us();
	uint64_t on;

	/* Node 2's default controller is in manual recovery: bus-off until the test ends it. */
	zassert_ok(can_virtual_set_state(NODE2->can[D], CAN_STATE_BUS_OFF));
	k_msleep(BOUND_MS + ALLOW_MS + 200U);
	/* The master misses node 2 on the default line, node 2 hears nothing there. */
	assert_switch_within_bound(MASTER, R, off);
	assert_switch_within_bound(NODE2, R, off);
	zassert_equal(co_redundancy_get(&NODE3->node, NULL, NULL), D, "node 3 hears the master");
	zassert_equal(count_rdn(NODE3, CO_RDN_EV_SWITCH, 0xFFU, off), 0);
	zassert_equal(count_hb(MASTER, CO_HB_EV_LOST, off), 0);

	on = now_us();
	zassert_ok(can_virtual_set_state(NODE2->can[D], CAN_STATE_ERROR_ACTIVE));
	zassert_true(all_on(D, 3U * HB_MS + ALLOW_MS + 500U), "back after the recovery");
	for (int i = 0; i < 2; i++) {
		uint64_t d = switched_at(&units[i], D, on) - on;

		TC_PRINT("%s: back on the default line %u.%u ms after the recovery\n",
			 units[i].name, MS_ARGS(d));
		zassert_true(d <= (3U * HB_MS + ALLOW_MS) * 1000U);
	}
	k_msleep(200);
	stop_slaves();
	assert_values(true, true);
}

/*
 * The bus-off form of test_long_cut_keeps_the_heartbeat_on_the_redundant_line: node 2's
 * bus-off default controller gets no process data, TPDO 1 keeps reaching the redundant line.
 */
ZTEST(co_redundancy_threaded,
      test_bus_off_with_tpdo1_supervision_keeps_the_heartbeat_on_the_redundant_line)
{
	uint64_t off;

	set_u8(NODE2, IDX_RDN, 5, 12);
	off = now_us();
	zassert_ok(can_virtual_set_state(NODE2->can[D], CAN_STATE_BUS_OFF));
	k_msleep(BOUND_MS + ALLOW_MS + 500U);
	zassert_equal(count_rdn(MASTER, CO_RDN_EV_HB_ERROR, R, off), 0,
		      "the master lost node 2's heartbeat on the redundant line");
	zassert_equal(count_hb(MASTER, CO_HB_EV_LOST, off), 0,
		      "the master's 1016h lost node 2 on both lines");
}

ZTEST(co_redundancy_threaded, test_bus_off_that_recovers_at_once_changes_nothing)
{
	uint64_t off = now_us();

	/* Node 3's default controller recovers by itself after 128 x 11 bits (2.8 ms). */
	zassert_ok(can_virtual_set_state(NODE3->can[D], CAN_STATE_BUS_OFF));
	assert_no_switch(BOUND_MS + ALLOW_MS + 200U, off);
	zassert_equal(count_rdn(MASTER, CO_RDN_EV_HB_ERROR, 0xFFU, off), 0);
	stop_slaves();
	assert_values(true, true);
}

ZTEST(co_redundancy_threaded, test_error_passive_changes_nothing)
{
	uint64_t at = now_us();
	bool seen = false;

	zassert_ok(can_virtual_set_state(NODE3->can[D], CAN_STATE_ERROR_PASSIVE));
	assert_no_switch(BOUND_MS + ALLOW_MS + 200U, at);
	co_node_lock(&NODE3->node);
	for (int i = 0; i < NODE3->n_ev; i++) {
		const struct co_event *ev = &NODE3->ev[i].ev;

		seen = seen || (ev->type == CO_EV_LINE && ev->line.idx == D &&
				ev->line.event == CO_LINE_EV_CAN_STATE &&
				ev->line.arg == CAN_STATE_ERROR_PASSIVE);
	}
	co_node_unlock(&NODE3->node);
	zassert_true(seen, "node 3 heard of its error-passive default controller");
	zassert_ok(can_virtual_set_state(NODE3->can[D], CAN_STATE_ERROR_ACTIVE));
	stop_slaves();
	assert_values(true, true);
}

/* --- Copies held back on a line that failed ------------------------------------------------ */

/*
 * A copy that a failed line delivers later than CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US is not
 * taken again. Here, as in a flood that lets a frame through now and then
 * (test_flood_on_the_default_line_acts_like_a_cut, seen 75-270 ms late), the default line
 * carries no heartbeat (every node switches away from it) and its TPDOs arrive 150 ms late.
 * The filter matches a copy only within the window after the frame it took; what closes it
 * is that RPDOs are not taken from a line on which a supervised heartbeat is lost while the
 * other line has them all (40 values per slave were delivered twice before).
 */
#define HELD_BACK_MS 150U

ZTEST(co_redundancy_threaded, test_copies_held_back_on_a_failed_line_are_not_delivered_again)
{
	const struct can_filter heartbeats = {.id = 0x700, .mask = 0x780};
	const struct can_filter tpdo1 = {.id = 0x180, .mask = 0x7F0};

	zassert_ok(can_virtual_drop_frames(0, &heartbeats, UINT32_MAX));
	zassert_ok(can_virtual_delay_frames(0, &tpdo1, UINT32_MAX, HELD_BACK_MS * 1000U));
	zassume_true(all_on(R, BOUND_MS + ALLOW_MS + 500U), "every node left the default line");
	k_msleep(300);
	stop_slaves();
	k_msleep(HELD_BACK_MS);
	assert_values(true, false);
	assert_values_ex(false, true, true);
}

/* --- A flood on the default line ------------------------------------------------------------ */

ZTEST(co_redundancy_threaded, test_flood_on_the_default_line_acts_like_a_cut)
{
	uint64_t at = now_us();
	struct can_virtual_bus_stats st0, st;
	bool all;
	int through;

	zassert_ok(can_virtual_bus_get_stats(0, &st0));
	atomic_set(&leaked, 0);
	/* Heartbeats already on their way when the flood starts may still pass. */
	atomic_set(&leak_after, (atomic_val_t)(uint32_t)(at + 5000U) | 1);
	flood_start();
	all = all_on(R, BOUND_MS + ALLOW_MS + 500U);
	through = (int)atomic_get(&leaked);
	/*
	 * The flooder is a thread keeping its controller's 8 transmit slots full (2 ms of frames);
	 * on a loaded host it falls behind and heartbeats slip through, and then nothing needs to
	 * switch. That says nothing about the service: the test is skipped.
	 */
	zassume_true(all || through == 0,
		     "%d heartbeats got through the flood: the host is too loaded to keep it up",
		     through);
	zassert_true(all, "every node on the redundant line");
	for (int i = 0; i < N_UNITS && through == 0; i++) {
		assert_switch_within_bound(&units[i], R, at);
	}
	k_msleep(200);
	stop_slaves();
	atomic_set(&leak_after, 0);
	zassert_ok(can_virtual_bus_get_stats(0, &st));
	TC_PRINT("bus 0: %u frames, busy %u ms of %u, %d heartbeats through the flood\n",
		 st.frames - st0.frames, (unsigned int)((st.busy_ns - st0.busy_ns) / 1000000U),
		 ms_of(now_us() - at), through);
	/*
	 * Frames queued behind the flood slip through whenever the flooder's thread is late to
	 * refill its controller, tens to hundreds of ms late: copies older than the window. Once
	 * the heartbeats there are lost they are not taken
	 * (test_copies_held_back_on_a_failed_line_are_not_delivered_again); before that they
	 * may be, depending on the host's load, so they are printed here, not judged.
	 */
	assert_values(true, false);
	flood_stop();
	zassert_true(all_on(D, 3U * HB_MS + ALLOW_MS + 1000U), "back when the flood ends");
}
