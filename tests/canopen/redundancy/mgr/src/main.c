/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The manager on two lines, on simulated time: node 1 (NMT master, 1F80h = 01h) on simulation
 * lines D (default) and R (redundant), with the redundancy service. Slaves 2 and 3 are
 * assigned in 1F81h for error control only (01h) and supervised with 100 ms in 1016h; the
 * test plays them, sending their boot-up after the master's reset and a heartbeat every
 * 50 ms on the lines it chooses. The manager follows each slave on each line and reports a
 * slave lost or found on one line while the other still brings it (CO_EV_HB with
 * CO_HB_EV_LINE_LOST/CO_HB_EV_LINE_FOUND and the line).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/mgr.h>
#include <canopen/node.h>
#include <zephyr/drivers/can.h>

#include "rdn_mgr_od.h"

#define MASTER  1
#define MS      1000ULL
#define MAX_EV  128
#define D       CO_LINE_DEFAULT
#define R       CO_LINE_REDUNDANT
#define HB_MS   50U
#define CONS_MS 100U

struct rec {
	struct co_event ev;
	uint64_t at;
};

static struct {
	struct co_line line[2];
	struct co_node node;
	struct rdn_mgr_od_ram ram;
	struct co_listener listener;
	uint64_t now;
	uint64_t next_hb;
	bool reset_seen;
	/* BIT(line) each slave's heartbeat goes on (index: node-ID). */
	uint8_t lines_of[4];
	uint64_t last_hb[4][2];
	struct rec ev[MAX_EV];
	int n_ev;
	int n_mgr_lost[4];
} t;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	/* NMT Reset Communication or Reset Node, to all or to one slave: it boots up again. */
	if (frame->id == 0 && frame->dlc == 2 &&
	    (frame->data[0] == 0x81 || frame->data[0] == 0x82)) {
		t.reset_seen = true;
	}
	return 0;
}

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	zassert_true(t.n_ev < MAX_EV);
	t.ev[t.n_ev++] = (struct rec){*ev, t.now};
	return 0;
}

static void ec_ind(struct co_node *node, uint8_t id, enum co_mgr_ec_event ev,
		   enum co_nmt_state state, void *user_data)
{
	if (ev == CO_MGR_EC_HB_LOST && id < ARRAY_SIZE(t.n_mgr_lost)) {
		t.n_mgr_lost[id]++;
	}
}

static void master_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	uint8_t buf[4];

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	sys_put_le32(0x01, buf);
	zassert_equal(co_od_write(od, 0x1F81, 2, buf, 4, CO_OD_WRITER_STORAGE), 0U);
	zassert_equal(co_od_write(od, 0x1F81, 3, buf, 4, CO_OD_WRITER_STORAGE), 0U);
}

static void rx(int l, uint32_t id, uint8_t byte)
{
	struct can_frame f = {.id = id, .dlc = 1, .data = {byte}};

	co_line_rx(&t.line[l], &f, t.now);
}

static void process(void)
{
	co_line_process(&t.line[D], t.now);
	co_line_process(&t.line[R], t.now);
}

/* What the slaves send at t.now: boot-ups after a reset, heartbeats every 50 ms. */
static void slaves(void)
{
	if (t.reset_seen) {
		t.reset_seen = false;
		for (uint8_t id = 2; id <= 3; id++) {
			for (int l = 0; l < 2; l++) {
				if (t.lines_of[id] & BIT(l)) {
					rx(l, 0x700 + id, 0x00);
				}
			}
		}
	}
	if (t.now < t.next_hb) {
		return;
	}
	t.next_hb = t.now + HB_MS * MS;
	for (uint8_t id = 2; id <= 3; id++) {
		for (int l = 0; l < 2; l++) {
			if (t.lines_of[id] & BIT(l)) {
				rx(l, 0x700 + id, 0x7f);
				t.last_hb[id][l] = t.now;
			}
		}
	}
}

/* Run to @p at in steps of 1 ms (the node's deadlines and the slaves' frames on the way). */
static void run_until(uint64_t at)
{
	while (t.now < at) {
		uint64_t next = co_line_next_deadline(&t.line[D]);
		uint64_t step = MIN(t.now + MS, at);

		if (next != UINT64_MAX && next > t.now && next < step) {
			step = next;
		}
		t.now = step;
		process();
		slaves();
		process();
	}
}

/* The manager's per-line events @p what for @p id (any line: @p line < 0). */
static const struct rec *line_ev(enum co_hb_event what, uint8_t id, int line, int *count)
{
	const struct rec *first = NULL;
	int n = 0;

	for (int i = 0; i < t.n_ev; i++) {
		const struct co_event *e = &t.ev[i].ev;

		if (e->type == CO_EV_HB && e->hb.event == what && e->hb.node_id == id &&
		    (line < 0 || e->hb.line == line)) {
			first = first == NULL ? &t.ev[i] : first;
			n++;
		}
	}
	if (count != NULL) {
		*count = n;
	}
	return first;
}

static int count_hb(enum co_hb_event what, uint8_t id)
{
	int n = 0;

	for (int i = 0; i < t.n_ev; i++) {
		n += t.ev[i].ev.type == CO_EV_HB && t.ev[i].ev.hb.event == what &&
		     t.ev[i].ev.hb.node_id == id;
	}
	return n;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	t.lines_of[2] = BIT(D) | BIT(R);
	t.lines_of[3] = BIT(D) | BIT(R);
	co_line_init_sim(&t.line[D], "D", sink, NULL);
	co_line_init_sim(&t.line[R], "R", sink, NULL);
	zassert_ok(co_node_init(&t.node, "mgr", &t.line[D], &rdn_mgr_od_def, &t.ram, MASTER));
	zassert_ok(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line[R]));
	co_od_set_restore_cb(co_node_od(&t.node), master_restore, NULL);
	co_listener_init(&t.listener, "test", CO_EV_BIT(CO_EV_HB), on_event, NULL);
	zassert_ok(co_node_listener_add(&t.node, &t.listener));
	co_mgr_set_ec_ind(&t.node, ec_ind, NULL);
	zassert_ok(co_node_start(&t.node));
}

ZTEST_SUITE(co_rdn_mgr, NULL, NULL, before, NULL, NULL);

/* Both slaves on both lines, monitored: nothing per line to report. */
static void boot_both_lines(void)
{
	run_until(1000 * MS);
	zassert_equal(co_mgr_get_startup(&t.node), CO_MGR_STARTUP_DONE);
	for (uint8_t id = 2; id <= 3; id++) {
		zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, id, -1, NULL));
		zassert_equal(t.n_mgr_lost[id], 0);
	}
}

ZTEST(co_rdn_mgr, test_slave_silent_on_the_default_line_is_lost_there_only)
{
	int n;

	boot_both_lines();
	t.lines_of[2] = BIT(R);
	uint64_t cut = t.now;
	uint64_t last = t.last_hb[2][D];

	run_until(cut + 1000 * MS);
	const struct rec *lost = line_ev(CO_HB_EV_LINE_LOST, 2, D, &n);

	zassert_not_null(lost, "node 2 lost on the default line");
	zassert_equal(n, 1, "reported once");
	/* After the consumer time, at the redundant line's next heartbeat: within one period. */
	zassert_true(lost->at > last + CONS_MS * MS, "lost %llu ms after its last heartbeat",
		     (lost->at - last) / MS);
	zassert_true(lost->at <= last + (CONS_MS + HB_MS) * MS, "lost %llu ms after it",
		     (lost->at - last) / MS);
	zassert_equal(lost->ev.hb.state, CO_NMT_PRE_OPERATIONAL);
	/* The slave as a whole is alive: no heartbeat loss, no error handler. */
	zassert_equal(t.n_mgr_lost[2], 0);
	zassert_equal(count_hb(CO_HB_EV_LOST, 2), 0);
	/* Node 3 was not touched. */
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 3, -1, NULL));
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 2, R, NULL));

	/* Back on the default line: found at its first heartbeat there, once. */
	t.lines_of[2] = BIT(D) | BIT(R);
	uint64_t restore = t.now;

	run_until(restore + 500 * MS);
	const struct rec *found = line_ev(CO_HB_EV_LINE_FOUND, 2, D, &n);

	zassert_not_null(found);
	zassert_equal(n, 1);
	zassert_true(found->at - restore <= HB_MS * MS, "found %llu ms after the restore",
		     (found->at - restore) / MS);
	line_ev(CO_HB_EV_LINE_LOST, 2, D, &n);
	zassert_equal(n, 1, "no new loss");
}

ZTEST(co_rdn_mgr, test_slave_silent_on_the_redundant_line_is_lost_there)
{
	boot_both_lines();
	t.lines_of[3] = BIT(D);
	run_until(t.now + 1000 * MS);
	const struct rec *lost = line_ev(CO_HB_EV_LINE_LOST, 3, R, NULL);

	zassert_not_null(lost);
	zassert_equal(lost->ev.hb.line, R);
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 3, D, NULL));
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 2, -1, NULL));
	zassert_equal(t.n_mgr_lost[3], 0);
}

ZTEST(co_rdn_mgr, test_slave_silent_on_both_lines_is_lost_not_lost_per_line)
{
	boot_both_lines();
	t.lines_of[2] = 0;
	run_until(t.now + 1000 * MS);
	zassert_equal(t.n_mgr_lost[2], 1, "the manager's heartbeat loss");
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 2, -1, NULL), "no line of its own to blame");

	/* It comes back on both lines: monitored again, nothing per line. */
	t.lines_of[2] = BIT(D) | BIT(R);
	run_until(t.now + 1000 * MS);
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 2, -1, NULL));
	zassert_is_null(line_ev(CO_HB_EV_LINE_FOUND, 2, -1, NULL));
}

ZTEST(co_rdn_mgr, test_slave_back_on_one_line_after_a_full_loss_is_lost_on_the_other)
{
	boot_both_lines();
	t.lines_of[2] = 0;
	run_until(t.now + 1000 * MS);
	zassert_equal(t.n_mgr_lost[2], 1);
	t.lines_of[2] = BIT(D);
	uint64_t back = t.now;

	run_until(back + 1000 * MS);
	const struct rec *lost = line_ev(CO_HB_EV_LINE_LOST, 2, R, NULL);

	zassert_not_null(lost, "the redundant line never brought it back");
	zassert_true(lost->at - back > CONS_MS * MS, "supervised from its return on");
}

ZTEST(co_rdn_mgr, test_slave_heard_on_one_line_from_the_start)
{
	int n;

	t.lines_of[3] = BIT(R);
	run_until(2000 * MS);
	zassert_equal(co_mgr_get_startup(&t.node), CO_MGR_STARTUP_DONE);
	zassert_not_null(line_ev(CO_HB_EV_LINE_LOST, 3, D, &n));
	zassert_equal(n, 1);
	zassert_equal(t.n_mgr_lost[3], 0);
	zassert_is_null(line_ev(CO_HB_EV_LINE_LOST, 2, -1, NULL));
}
