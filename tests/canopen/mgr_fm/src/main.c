/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Flying master and NMT master detection (CiA 302 §5.5, CiA 302-2 §3.7, §5) on simulated
 * time. Every node sits on its own simulation line; the test is the bus: it logs each frame
 * with its sender and time and hands it to every other node that is alive and on the same
 * side of a split. Killing a node drops its frames and freezes it; frames the test injects
 * play the part of other devices. Tests named test_s9_NN check row NN of the CiA 302
 * bus-observable behaviours (doc/flying-master.md lists them).
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>

#include "line_internal.h"

#include "co_bus.h"

#include "fm_master_od.h"
#include "fm_slave_od.h"

#define MS       1000ULL
#define MAX_NODE 6
#define MAX_CFG  24
#define MAX_EV   32
#define INJECTED CO_BUS_INJECTED

struct cfg_entry {
	uint16_t index;
	uint8_t sub;
	uint8_t len;
	uint32_t value;
};

struct nd {
	struct co_line line;
	struct co_node node;
	union {
		struct fm_master_od_ram m;
		struct fm_slave_od_ram s;
	} ram;
	struct cfg_entry cfg[MAX_CFG];
	int n_cfg;
	struct co_listener listener;
	struct co_event ev[MAX_EV];
	int n_ev;
	bool master;
	char name[8];
};

static struct {
	struct nd n[MAX_NODE];
} t;

/* --- The bus -------------------------------------------------------------------------------- */

static void inject(uint16_t id, uint8_t dlc, uint8_t b0, uint8_t b1)
{
	const struct can_frame f = {.id = id, .dlc = dlc, .data = {b0, b1}};

	co_bus_inject(&f);
}

/* --- Nodes ----------------------------------------------------------------------------------- */

static void restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	struct nd *d = user_data;

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (int i = 0; i < d->n_cfg; i++) {
		uint8_t buf[4];

		sys_put_le32(d->cfg[i].value, buf);
		zassert_equal(co_od_write(od, d->cfg[i].index, d->cfg[i].sub, buf, d->cfg[i].len,
					  CO_OD_WRITER_STORAGE),
			      0U, "config %04x:%02x", d->cfg[i].index, d->cfg[i].sub);
	}
}

static void cfg(int i, uint16_t index, uint8_t sub, uint32_t value, uint8_t len)
{
	struct nd *d = &t.n[i];

	zassert_true(d->n_cfg < MAX_CFG);
	d->cfg[d->n_cfg++] = (struct cfg_entry){index, sub, len, value};
}

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct nd *d = user_data;

	ARG_UNUSED(node);
	if (d->n_ev < MAX_EV) {
		d->ev[d->n_ev++] = *ev;
	}
	return 0;
}

static void node_add(int i, uint8_t id, bool master)
{
	struct nd *d = &t.n[i];

	d->master = master;
	snprintf(d->name, sizeof(d->name), "n%02x", id);
	co_bus_attach(i, &d->line, d->name);
	zassert_ok(co_node_init(&d->node, d->name, &d->line,
				master ? &fm_master_od_def : &fm_slave_od_def, &d->ram, id));
	co_od_set_restore_cb(co_node_od(&d->node), restore, d);
	co_listener_init(&d->listener, "test", CO_EV_BIT(CO_EV_FM), on_event, d);
	zassert_ok(co_node_listener_add(&d->node, &d->listener));
}

/*
 * A flying-master candidate: 1F80h = 21h, priority @p prio, heartbeat 100 ms, the slaves
 * 0Ah..0Ch and the other candidates assigned (05h: slave, boot), 1029h:01 = 1 (the 302-2
 * error handler decides, not the CiA 301 consumer).
 */
static void candidate(int i, uint8_t id, uint8_t prio)
{
	node_add(i, id, true);
	cfg(i, 0x1F80, 0, 0x21, 4);
	cfg(i, 0x1F90, 3, prio, 2);
	cfg(i, 0x1017, 0, 100, 2);
	cfg(i, 0x1029, 1, 1, 1);
	for (uint8_t s = 0x0A; s <= 0x0C; s++) {
		cfg(i, 0x1F81, s, 0x05, 4);
	}
}

/* Each candidate assigns and watches the others (heartbeat consumer 300 ms). */
static void peers(int a, int b)
{
	uint8_t ida = co_node_id(&t.n[a].node);
	uint8_t idb = co_node_id(&t.n[b].node);

	cfg(a, 0x1F81, idb, 0x05, 4);
	cfg(b, 0x1F81, ida, 0x05, 4);
	cfg(a, 0x1016, 1, ((uint32_t)idb << 16) | 300U, 4);
	cfg(b, 0x1016, 1, ((uint32_t)ida << 16) | 300U, 4);
}

static void slaves(int first)
{
	for (int k = 0; k < 3; k++) {
		node_add(first + k, (uint8_t)(0x0A + k), false);
	}
}

static void start(int i)
{
	zassert_ok(co_node_start(&t.n[i].node));
	co_bus_settle();
}

static void start_all(void)
{
	for (int i = 0; i < MAX_NODE; i++) {
		if (bus.port[i].used) {
			zassert_ok(co_node_start(&t.n[i].node));
		}
	}
	co_bus_settle();
}

static uint32_t od_u(int i, uint16_t index, uint8_t sub)
{
	uint32_t v;

	co_node_lock(&t.n[i].node);
	v = co_od_uint(co_node_od(&t.n[i].node), index, sub, 0);
	co_node_unlock(&t.n[i].node);
	return v;
}

static struct co_mgr_fm_info fm(int i)
{
	struct co_mgr_fm_info info;

	zassert_ok(co_mgr_fm_get(&t.n[i].node, &info));
	return info;
}

static void before(void *unused)
{
	ARG_UNUSED(unused);
	memset(&t, 0, sizeof(t));
	co_bus_init();
}

/* SAFELINE_FM_TRACE=1 prints every frame of each test (reading a failure). */
static void after(void *unused)
{
	const char *e = getenv("SAFELINE_FM_TRACE");

	ARG_UNUSED(unused);
	if (e == NULL || e[0] != '1') {
		return;
	}
	for (int k = 0; k < bus.n_log; k++) {
		const struct co_bus_frame *l = &bus.log[k];

		printk("%8llu.%03llu %2d %03x#", l->at / MS, l->at % MS, l->from, l->f.id);
		for (int b = 0; b < l->f.dlc; b++) {
			printk("%02x", l->f.data[b]);
		}
		printk("\n");
	}
}

ZTEST_SUITE(co_mgr_fm, NULL, NULL, before, after, NULL);

/* --- Log queries ---------------------------------------------------------------------------- */

static bool is(const struct co_bus_frame *l, uint16_t id, int from)
{
	return l->f.id == id && (from == -2 || l->from == from);
}

/* First frame @p id (from node @p from, -2: anyone) at or after @p since [µs]; -1 if none. */
static int find(uint16_t id, int from, uint64_t since)
{
	for (int k = 0; k < bus.n_log; k++) {
		if (bus.log[k].at >= since && is(&bus.log[k], id, from)) {
			return k;
		}
	}
	return -1;
}

static int count(uint16_t id, int from, uint64_t since)
{
	int n = 0;

	for (int k = 0; k < bus.n_log; k++) {
		n += bus.log[k].at >= since && is(&bus.log[k], id, from) ? 1 : 0;
	}
	return n;
}

static int find_nmt(uint8_t cs, uint8_t id, int from, uint64_t since)
{
	for (int k = 0; k < bus.n_log; k++) {
		const struct co_bus_frame *l = &bus.log[k];

		if (l->at >= since && l->f.id == 0 && l->f.dlc == 2 && l->f.data[0] == cs &&
		    l->f.data[1] == id && (from == -2 || l->from == from)) {
			return k;
		}
	}
	return -1;
}

static uint64_t at_ms(int k)
{
	zassert_true(k >= 0, "frame not found");
	return bus.log[k].at / MS;
}

static int n_ev(int i, enum co_mgr_fm_event what)
{
	int n = 0;

	for (int k = 0; k < t.n[i].n_ev; k++) {
		n += t.n[i].ev[k].fm.what == what ? 1 : 0;
	}
	return n;
}

static int active_count(void)
{
	int n = 0;

	for (int i = 0; i < MAX_NODE; i++) {
		if (bus.port[i].used && t.n[i].master && bus.port[i].alive &&
		    fm(i).state == CO_MGR_FM_ACTIVE) {
			n++;
		}
	}
	return n;
}

/* --- §9 rows, one candidate and injected frames ----------------------------------------- */

ZTEST(co_mgr_fm, test_s9_53_alone_cold_boot_timeline)
{
	int k;

	candidate(0, 5, 1);
	slaves(1);
	start_all();
	co_bus_run_ms(12000);

	/* 705#00 -> +500 073 -> +100 000#8200 -> (warm) +500 073 -> +100 072 -> +1550 071. */
	zassert_equal(at_ms(find(0x705, 0, 0)), 0);
	k = find(0x073, 0, 0);
	zassert_equal(at_ms(k), 500);
	zassert_equal(bus.log[k].f.dlc, 0);
	k = find_nmt(0x82, 0, 0, 0);
	zassert_equal(at_ms(k), 600);
	zassert_equal(bus.log[k].from, 0);
	zassert_equal(at_ms(find(0x705, 0, 600 * MS)), 600, "warm boot-up");
	zassert_equal(at_ms(find(0x073, 0, 601 * MS)), 1100);
	k = find(0x072, 0, 0);
	zassert_equal(at_ms(k), 1200);
	zassert_equal(bus.log[k].f.dlc, 0);
	k = find(0x071, 0, 0);
	zassert_equal(at_ms(k), 2750);
	zassert_equal(bus.log[k].f.dlc, 2);
	zassert_equal(bus.log[k].f.data[0], 1);
	zassert_equal(bus.log[k].f.data[1], 5);
	/* Then the NMT startup (Reset Communication of all), then 076h every 4050 ms. */
	zassert_equal(at_ms(find_nmt(0x82, 0, 0, 2750 * MS)), 2750);
	zassert_equal(at_ms(find(0x076, 0, 0)), 2750 + 4050);
	zassert_equal(at_ms(find(0x076, 0, 6801 * MS)), 2750 + 2 * 4050);
	zassert_equal(count(0x071, 0, 0), 1, "one announcement, no answer asked for");
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
	zassert_equal(fm(0).master_id, 5);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_ACTIVE), 1);
	/* The winner's startup booted and started the slaves. */
	zassert_true(find_nmt(0x01, 0x0A, 0, 2750 * MS) >= 0);
	zassert_equal(co_nmt_get_state(&t.n[1].node), CO_NMT_OPERATIONAL);
	zassert_equal(co_mgr_get_startup(&t.n[0].node), CO_MGR_STARTUP_DONE);
}

/* Run a lone candidate until it is the active master. */
static void lone_active(uint8_t id, uint8_t prio)
{
	candidate(0, id, prio);
	start_all();
	co_bus_run_ms(500 + 100 + 500 + 100 + prio * 1500 + id * 10 + 50);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
}

ZTEST(co_mgr_fm, test_reset_all_survives_a_busy_controller)
{
	candidate(0, 5, 1);
	start_all();
	co_bus_run_ms(599);
	/* The cold boot's 000#8200 is due at 600 ms while the controller cannot take it. */
	bus.port[0].busy = true;
	co_bus_run_ms(50);
	bus.port[0].busy = false;
	co_bus_run_ms(100);
	/* Sent at the line's next round (the heartbeat at 700 ms), not dropped by our reset. */
	zassert_equal(at_ms(find_nmt(0x82, 0, 0, 0)), 700);
}

ZTEST(co_mgr_fm, test_s9_54_active_master_answers_073)
{
	uint64_t since;
	int k;

	lone_active(10, 0);
	co_bus_run_ms(100);
	since = bus.now;
	inject(0x073, 0, 0, 0);
	co_bus_run_ms(100);
	k = find(0x071, 0, since);
	zassert_true(k >= 0);
	zassert_true(bus.log[k].at - since <= 100 * MS, "within 1F90h:01");
	zassert_equal(bus.log[k].f.dlc, 2);
	zassert_equal(bus.log[k].f.data[0], 0x00);
	zassert_equal(bus.log[k].f.data[1], 0x0A);
}

ZTEST(co_mgr_fm, test_s9_55_lower_priority_candidate_becomes_slave)
{
	uint64_t since;

	candidate(0, 5, 2);
	start_all();
	co_bus_run_ms(500);
	zassert_equal(count(0x073, 0, 0), 1);
	since = bus.now + 1; /* after its 073h */
	inject(0x071, 2, 0x00, 0x0A);
	/* Keep the master's heartbeat coming. */
	for (int i = 0; i < 50; i++) {
		inject(0x70A, 1, 0x05, 0);
		co_bus_run_ms(100);
	}
	zassert_equal(count(0x072, 0, since) + count(0x071, 0, since) + count(0x076, 0, since) +
			      count(0x073, 0, since) + count(0x000, 0, since),
		      0, "sends nothing more");
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
	zassert_equal(fm(0).master_id, 0x0A);
	zassert_equal(fm(0).master_prio, 0);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_MASTER), 1);
	zassert_equal(t.n[0].ev[0].fm.master_id, 0x0A);
	/* Its manager functions are off. */
	zassert_equal(co_mgr_nmt_req(&t.n[0].node, 0x0B, CO_NMT_CS_START), -EPERM);
	zassert_equal(co_mgr_get_startup(&t.n[0].node), CO_MGR_STARTUP_IDLE);
	{
		uint8_t v = 0x05;
		uint32_t ab;

		co_node_lock(&t.n[0].node);
		ab = co_od_write(co_node_od(&t.n[0].node), 0x1F82, 0x0B, &v, 1, CO_OD_WRITER_SDO);
		co_node_unlock(&t.n[0].node);
		zassert_equal(ab, CO_SDO_AB_DATA_DEV_STATE);
	}
	/* 1F80h is configuration: losing does not change it. */
	zassert_equal(od_u(0, 0x1F80, 0), 0x21);
}

ZTEST(co_mgr_fm, test_s9_56_higher_priority_candidate_forces)
{
	int k;

	candidate(0, 5, 0);
	start_all();
	co_bus_run_ms(500);
	inject(0x071, 2, 0x02, 0x0A);
	k = find(0x076, 0, 0);
	zassert_true(k >= 0);
	zassert_equal(bus.log[k].f.dlc, 0);
	zassert_equal(at_ms(k), 500);
	zassert_equal(fm(0).state, CO_MGR_FM_FORCED);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_FORCE), 1);
	/* The master resets the network: we negotiate from a warm boot. */
	inject(0x000, 2, 0x82, 0x00);
	co_bus_run_ms(500 + 100 + 5 * 10 + 10);
	zassert_equal(at_ms(find(0x072, 0, 0)), 500 + 500 + 100);
	zassert_equal(at_ms(find(0x071, 0, 0)), 500 + 500 + 100 + 50);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
}

/* 302 §5.3 / 302-2 §3.7 i: a lower-priority 071h during our own negotiation is forced too. */
ZTEST(co_mgr_fm, test_lower_priority_071_during_negotiation_forces)
{
	int k;

	candidate(0, 5, 0);
	start_all();
	/* Cold: 073h at 500, 000#8200 at 600; warm: 073h at 1100, 072h at 1200, W = 50 ms. */
	co_bus_run_ms(1220);
	zassert_equal(fm(0).state, CO_MGR_FM_NEGOTIATE);
	inject(0x071, 2, 0x02, 0x0A);
	k = find(0x076, 0, 1200 * MS);
	zassert_true(k >= 0, "076h to the lower-priority node");
	zassert_equal(bus.log[k].f.dlc, 0);
	zassert_equal(at_ms(k), 1220);
	zassert_equal(fm(0).state, CO_MGR_FM_FORCED);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_FORCE), 1);
	/* No announcement of our own while the other resets the network. */
	co_bus_run_ms(100);
	zassert_equal(count(0x071, 0, 0), 0);
}

/*
 * CiA 302 §5.5.2: a lower-priority node that wins the negotiation we forced (its timing
 * parameters beat our priority) stays the master: one 076h, not a loop of them.
 */
ZTEST(co_mgr_fm, test_lower_priority_winner_is_forced_once)
{
	int first;

	candidate(0, 5, 0);
	start_all();
	co_bus_run_ms(1220);
	inject(0x071, 2, 0x02, 0x0A);
	first = find(0x076, 0, 1200 * MS);
	zassert_true(first >= 0, "the first 076h");
	zassert_equal(fm(0).state, CO_MGR_FM_FORCED);
	/*
	 * Node 0Ah resets the network and wins the new round before our slot again (warm: our
	 * 073h 500 ms after the reset, a 072h would come at 600 and our W is 50 ms).
	 */
	inject(0x000, 2, 0x82, 0x00);
	co_bus_run_ms(560);
	zassert_equal(fm(0).state, CO_MGR_FM_DETECT);
	inject(0x072, 0, 0, 0);
	co_bus_run_ms(10);
	inject(0x071, 2, 0x02, 0x0A);
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
	zassert_equal(fm(0).master_id, 0x0A);
	for (int i = 0; i < 5; i++) {
		inject(0x70A, 1, 0x05, 0);
		co_bus_run_ms(100);
	}
	zassert_equal(count(0x076, first + 1, 0), 0, "no second 076h");
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_FORCE), 1);
}

/* 302 §5.3: 076h is for the active master only; every other state ignores it. */
ZTEST(co_mgr_fm, test_076_ignored_unless_active_master)
{
	uint64_t since;

	candidate(0, 5, 2);
	start_all();
	/* In the negotiation time delay: the timeline goes on unchanged (073h at 500). */
	co_bus_run_ms(200);
	inject(0x076, 0, 0, 0);
	co_bus_run_ms(300);
	zassert_equal(at_ms(find(0x073, 0, 0)), 500);
	zassert_equal(find_nmt(0x82, 0, 0, 0), -1, "no reset for a 076h before the detection");
	/* As a slave of node 0Ah (priority 0): no reset, no state change. */
	inject(0x071, 2, 0x00, 0x0A);
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
	since = bus.now + 1; /* after its 073h */
	for (int i = 0; i < 10; i++) {
		inject(0x70A, 1, 0x05, 0);
		if (i == 3) {
			inject(0x076, 0, 0, 0);
		}
		co_bus_run_ms(100);
	}
	zassert_equal(count(0x000, 0, since), 0, "a slave does not reset the network on 076h");
	zassert_equal(count(0x071, 0, since) + count(0x072, 0, since) + count(0x073, 0, since), 0);
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_RESIGN), 0);
}

ZTEST(co_mgr_fm, test_s9_57_second_072_restarts_the_slot_timer)
{
	candidate(0, 5, 1);
	start_all();
	/* Cold: 073 at 500, 8200 at 600; warm: 073 at 1100, detection ends at 1200. */
	co_bus_run_ms(1150);
	inject(0x072, 0, 0, 0);
	co_bus_run_ms(150); /* 1300 */
	zassert_equal(count(0x072, 0, 0), 0, "saw one: does not send its own");
	inject(0x072, 0, 0, 0);
	co_bus_run_ms(1600);
	/* W = 1 x 1500 + 5 x 10 after the last 072h. */
	zassert_equal(at_ms(find(0x071, 0, 0)), 1300 + 1550);
	zassert_equal(count(0x072, 0, 0), 0);
}

ZTEST(co_mgr_fm, test_s9_57_shortest_wait_answers)
{
	/* Two candidates negotiating from the same 072h: only the shorter wait sends 071h. */
	candidate(0, 5, 1);
	candidate(1, 3, 1);
	start_all();
	co_bus_run_ms(4000);
	zassert_equal(at_ms(find(0x071, 1, 0)), 1200 + 1530);
	/* Node 5 heard it before its own slot and never announced itself. */
	zassert_equal(count(0x071, 0, 0), 0);
	zassert_equal(fm(0).state, CO_MGR_FM_SLAVE);
}

ZTEST(co_mgr_fm, test_s9_58_master_heartbeat_lost)
{
	uint64_t last;
	int k;

	candidate(0, 5, 2);
	cfg(0, 0x1016, 1, (0x0AU << 16) | 300U, 4);
	start_all();
	co_bus_run_ms(500);
	inject(0x071, 2, 0x00, 0x0A);
	for (int i = 0; i < 10; i++) {
		inject(0x70A, 1, 0x05, 0);
		co_bus_run_ms(100);
	}
	last = bus.now - 100 * MS;
	co_bus_run_ms(1000);
	k = find_nmt(0x82, 0, 0, last);
	zassert_true(k >= 0, "000#8200 after the loss");
	zassert_equal(bus.log[k].at - last, 300 * MS, "within the consumer time 1016h");
	zassert_equal(n_ev(0, CO_MGR_FM_EV_LOST), 1);
	/* It negotiates again and takes over: W = 2 x 1500 + 5 x 10. */
	co_bus_run_ms(4000);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
	zassert_equal(at_ms(find(0x071, 0, 0)), bus.log[k].at / MS + 500 + 100 + 3050);
}

ZTEST(co_mgr_fm, test_hb_supervision_default_without_1016)
{
	int k;

	candidate(0, 5, 2);
	start_all();
	co_bus_run_ms(500);
	inject(0x071, 2, 0x00, 0x0A);
	/* No heartbeat at all: the timeout runs from the announcement. */
	co_bus_run_ms(CONFIG_CANOPEN_MGR_FLYING_HB_TIME + 10);
	k = find_nmt(0x82, 0, 0, 501 * MS);
	zassert_equal(at_ms(k), 500 + CONFIG_CANOPEN_MGR_FLYING_HB_TIME);
}

ZTEST(co_mgr_fm, test_s9_59_self_starter_starts_the_network)
{
	int k;

	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x02, 4);
	start_all();
	co_bus_run_ms(1000);
	k = find(0x075, 0, 0);
	zassert_equal(at_ms(k), 500);
	zassert_equal(bus.log[k].f.dlc, 0);
	/* No 074h within 100 ms, then 7 x 15 ms. */
	zassert_equal(at_ms(find_nmt(0x01, 0x00, 0, 0)), 500 + 100 + 105);
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_OPERATIONAL);
	zassert_equal(fm(0).state, CO_MGR_FM_SS_DONE);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_SELF_START), 1);
}

ZTEST(co_mgr_fm, test_s9_59_self_starter_defers_to_a_master_capable_device)
{
	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x02, 4);
	start_all();
	co_bus_run_ms(550);
	inject(0x074, 0, 0, 0);
	co_bus_run_ms(2000);
	zassert_equal(find_nmt(0x01, 0x00, 0, 0), -1, "no start");
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(n_ev(0, CO_MGR_FM_EV_CAPABLE), 1);
}

ZTEST(co_mgr_fm, test_s9_59_self_starter_sends_no_second_start)
{
	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x02, 4);
	start_all();
	co_bus_run_ms(650); /* in its node-ID slot */
	inject(0x000, 2, 0x01, 0x00);
	co_bus_run_ms(1000);
	zassert_equal(find_nmt(0x01, 0x00, 0, 0), -1, "another's start came first");
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_OPERATIONAL);
}

ZTEST(co_mgr_fm, test_s9_60_master_capable_answers_075)
{
	int k;

	/* A plain NMT master (no flying master) and a candidate that is a slave. */
	node_add(0, 1, true);
	cfg(0, 0x1F80, 0, 0x01, 4);
	candidate(1, 5, 2);
	start_all();
	co_bus_run_ms(510);
	inject(0x071, 2, 0x00, 0x0A);
	inject(0x075, 0, 0, 0);
	zassert_equal(count(0x074, 0, bus.now), 1);
	zassert_equal(count(0x074, 1, bus.now), 1, "a candidate that is a slave answers too");
	k = find(0x074, 0, bus.now);
	zassert_equal(bus.log[k].f.dlc, 0);
}

ZTEST(co_mgr_fm, test_s9_61_self_starting_slave_sends_nothing)
{
	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x08, 4);
	start_all();
	co_bus_run_ms(2000);
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_OPERATIONAL);
	zassert_equal(count(0x000, 0, 0) + count(0x075, 0, 0), 0);
}

ZTEST(co_mgr_fm, test_s9_61_self_starting_28h_as_08h)
{
	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x28, 4);
	start_all();
	co_bus_run_ms(2000);
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_OPERATIONAL);
	zassert_equal(count(0x000, 0, 0) + count(0x075, 0, 0) + count(0x073, 0, 0), 0);
}

ZTEST(co_mgr_fm, test_s9_59_self_starter_22h_as_02h)
{
	node_add(0, 7, true);
	cfg(0, 0x1F80, 0, 0x22, 4);
	start_all();
	co_bus_run_ms(1000);
	zassert_equal(at_ms(find(0x075, 0, 0)), 500);
	zassert_equal(at_ms(find_nmt(0x01, 0x00, 0, 0)), 500 + 100 + 105);
}

ZTEST(co_mgr_fm, test_wrong_dlc_ignored)
{
	uint64_t since;

	lone_active(10, 0);
	since = bus.now;
	/* 073h, 076h, 072h, 075h with data, 071h with 1 or 3 bytes: none of them counts. */
	inject(0x073, 1, 0, 0);
	inject(0x076, 2, 0, 0);
	inject(0x072, 1, 0, 0);
	inject(0x075, 1, 0, 0);
	inject(0x071, 1, 0x00, 0);
	inject(0x071, 3, 0x00, 0x01);
	co_bus_run_ms(200);
	zassert_equal(count(0x071, 0, since) + count(0x074, 0, since) + count(0x000, 0, since), 0);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
	/* The same frames with the right DLC are answered. */
	inject(0x073, 0, 0, 0);
	zassert_equal(count(0x071, 0, since), 1);
	inject(0x075, 0, 0, 0);
	zassert_equal(count(0x074, 0, since), 1);
}

ZTEST(co_mgr_fm, test_wrong_dlc_071_does_not_stop_negotiation)
{
	candidate(0, 5, 2);
	start_all();
	co_bus_run_ms(500);
	inject(0x071, 1, 0x00, 0x0A);
	inject(0x071, 8, 0x00, 0x0A);
	zassert_equal(fm(0).state, CO_MGR_FM_DETECT);
	co_bus_run_ms(100);
	zassert_equal(count(0x000, 0, 0), 1, "cold boot, nobody answered: 000#8200");
}

ZTEST(co_mgr_fm, test_bus_off_during_negotiation_restarts_it)
{
	candidate(0, 5, 1);
	start_all();
	/* Negotiating from 1200 ms (072h), own slot at 2750 ms. */
	co_bus_run_ms(1300);
	co_line_inject_event(&t.n[0].line, CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
	co_bus_run_ms(100);
	co_line_inject_event(&t.n[0].line, CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_ACTIVE);
	co_bus_settle();
	zassert_equal(fm(0).state, CO_MGR_FM_DELAY);
	co_bus_run_ms(3000);
	/* Again from F1: 073h +500, (warm) 072h +100, 071h +1550. */
	zassert_equal(at_ms(find(0x073, 0, 1401 * MS)), 1900);
	zassert_equal(at_ms(find(0x072, 0, 1401 * MS)), 2000);
	zassert_equal(count(0x071, 0, 0), 1);
	zassert_equal(at_ms(find(0x071, 0, 0)), 3550);
}

ZTEST(co_mgr_fm, test_bus_off_of_the_active_master_keeps_it)
{
	lone_active(10, 0);
	co_line_inject_event(&t.n[0].line, CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
	co_line_inject_event(&t.n[0].line, CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_ACTIVE);
	co_bus_settle();
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE, "its 076h cycle finds a second master");
}

ZTEST(co_mgr_fm, test_1f90_timing_rule_checked_on_write)
{
	struct co_od *od;

	candidate(0, 5, 1);
	od = co_node_od(&t.n[0].node);
	co_node_lock(&t.n[0].node);
	/* Priority time slot must exceed 127 x node time slot. */
	zassert_equal(co_od_write(od, 0x1F90, 5, (uint8_t[]){12, 0}, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "1500 <= 127 x 12");
	zassert_equal(co_od_write(od, 0x1F90, 4, (uint8_t[]){0xF6, 0x04}, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "1270 = 127 x 10");
	zassert_equal(co_od_write(od, 0x1F90, 4, (uint8_t[]){0xF7, 0x04}, 2, CO_OD_WRITER_SDO), 0U,
		      "1271 > 1270");
	zassert_equal(co_od_write(od, 0x1F90, 5, (uint8_t[]){0, 0}, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_od_write(od, 0x1F90, 3, (uint8_t[]){3, 0}, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "priorities 0..2");
	zassert_equal(co_od_write(od, 0x1F90, 3, (uint8_t[]){2, 0}, 2, CO_OD_WRITER_SDO), 0U);
	zassert_equal(co_od_write(od, 0x1F90, 1, (uint8_t[]){0, 0}, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE);
	/* 1F80h bit 5 is accepted with the flying master built in. */
	zassert_equal(co_od_write(od, 0x1F80, 0, (uint8_t[]){0x21, 0, 0, 0}, 4, CO_OD_WRITER_SDO),
		      0U);
	co_node_unlock(&t.n[0].node);
	zassert_equal(od_u(0, 0x1F90, 4), 1271);
}

/* --- Two candidates and three slaves ------------------------------------------------------ */

/* Candidates in slots 0 and 1, slaves in 2..4. */
static void network(uint8_t id0, uint8_t prio0, uint8_t id1, uint8_t prio1)
{
	candidate(0, id0, prio0);
	candidate(1, id1, prio1);
	peers(0, 1);
	slaves(2);
}

static void check_stable(int winner, int loser)
{
	zassert_equal(fm(winner).state, CO_MGR_FM_ACTIVE);
	zassert_equal(fm(loser).state, CO_MGR_FM_SLAVE);
	zassert_equal(fm(loser).master_id, co_node_id(&t.n[winner].node));
	zassert_equal(active_count(), 1);
	zassert_equal(co_mgr_get_startup(&t.n[winner].node), CO_MGR_STARTUP_DONE);
	zassert_equal(co_mgr_get_startup(&t.n[loser].node), CO_MGR_STARTUP_IDLE);
	for (int s = 2; s <= 4; s++) {
		zassert_equal(co_nmt_get_state(&t.n[s].node), CO_NMT_OPERATIONAL, "slave %d", s);
	}
	zassert_equal(co_nmt_get_state(&t.n[loser].node), CO_NMT_OPERATIONAL,
		      "the loser is started as a slave");
}

ZTEST(co_mgr_fm, test_two_candidates_higher_priority_wins)
{
	/* Node 3 has priority 0, node 2 priority 1: the priority decides, not the node-ID. */
	network(3, 0, 2, 1);
	start_all();
	co_bus_run_ms(6000);
	check_stable(0, 1);
	zassert_equal(count(0x071, 1, 0), 0, "the loser never announced itself");
	zassert_equal(n_ev(1, CO_MGR_FM_EV_MASTER), 1);
	zassert_equal(t.n[1].ev[0].fm.priority, 0);
	/* The loser's manager sent no NMT command after the winner's announcement. */
	zassert_equal(count(0x000, 1, at_ms(find(0x071, 0, 0)) * MS), 0);
}

ZTEST(co_mgr_fm, test_two_candidates_equal_priority_lower_id_wins)
{
	network(3, 1, 2, 1);
	start_all();
	co_bus_run_ms(6000);
	check_stable(1, 0);
	zassert_equal(at_ms(find(0x071, 1, 0)), 1200 + 1500 + 20);
}

ZTEST(co_mgr_fm, test_active_master_killed_other_takes_over)
{
	uint64_t killed, detect, announce, first_nmt;
	uint64_t bound;
	int k;

	network(3, 0, 2, 1);
	start_all();
	co_bus_run_ms(6000);
	check_stable(0, 1);
	killed = bus.now;
	bus.port[0].alive = false;
	co_bus_run_ms(5000);
	zassert_equal(fm(1).state, CO_MGR_FM_ACTIVE);
	zassert_equal(n_ev(1, CO_MGR_FM_EV_LOST), 1);
	k = find_nmt(0x82, 0, 1, killed);
	zassert_true(k >= 0);
	detect = bus.log[k].at;
	k = find(0x071, 1, killed);
	announce = bus.log[k].at;
	zassert_equal(bus.log[k].f.data[0], 1);
	zassert_equal(bus.log[k].f.data[1], 2);
	k = find_nmt(0x82, 0, 1, announce);
	first_nmt = bus.log[k].at;
	/* Bound from 1F90h: heartbeat time + 1F90:02 + 1F90:01 + W (1 x 1500 + 2 x 10). */
	bound = (300 + 500 + 100 + 1520) * MS;
	printk("flying master take-over: killed at %llu ms; loss detected +%llu ms; "
	       "new master 071h +%llu ms; its first NMT command +%llu ms; bound %llu ms "
	       "(after the last heartbeat)\n",
	       killed / MS, (detect - killed) / MS, (announce - killed) / MS,
	       (first_nmt - killed) / MS, bound / MS);
	zassert_true(first_nmt - killed <= bound, "within the 1F90h bound");
	/* The slaves run again under the new master. */
	co_bus_run_ms(2000);
	for (int s = 2; s <= 4; s++) {
		zassert_equal(co_nmt_get_state(&t.n[s].node), CO_NMT_OPERATIONAL);
	}
	zassert_equal(co_mgr_get_startup(&t.n[1].node), CO_MGR_STARTUP_DONE);
}

ZTEST(co_mgr_fm, test_force_negotiation_by_higher_priority)
{
	uint64_t joined;
	int k;

	network(3, 1, 2, 0);
	/* Node 3 (priority 1) runs alone first. */
	bus.port[1].alive = false;
	for (int i = 0; i < MAX_NODE; i++) {
		if (bus.port[i].used && i != 1) {
			zassert_ok(co_node_start(&t.n[i].node));
		}
	}
	co_bus_run_ms(5000);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
	/* Node 2 (priority 0) powers on. */
	joined = bus.now;
	bus.port[1].alive = true;
	start(1);
	co_bus_run_ms(600);
	k = find(0x076, 1, joined);
	zassert_true(k >= 0, "the higher-priority candidate forces");
	zassert_equal(at_ms(k) * MS - joined, 500 * MS);
	zassert_true(find_nmt(0x82, 0, 0, bus.log[k].at) >= 0, "the active master resets all");
	zassert_equal(n_ev(0, CO_MGR_FM_EV_RESIGN), 1);
	co_bus_run_ms(5000);
	check_stable(1, 0);
}

static int n_con;
static uint32_t con_abort;

static void req_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	ARG_UNUSED(cli);
	ARG_UNUSED(size);
	ARG_UNUSED(user_data);
	n_con++;
	con_abort = abort_code;
}

ZTEST(co_mgr_fm, test_request_nmt_through_the_active_master)
{
	uint64_t since;

	n_con = 0;
	network(3, 0, 2, 1);
	start_all();
	co_bus_run_ms(6000);
	check_stable(0, 1);
	/* Node 2 (a slave now) asks the active master to stop node 0Ah: 1F82h:0A = 04h. */
	since = bus.now;
	zassert_ok(co_mgr_request_nmt(&t.n[1].node, 0, 0x0A, 0x04, req_con, NULL));
	co_bus_run_ms(50);
	zassert_equal(n_con, 1);
	zassert_equal(con_abort, 0U);
	zassert_true(find(0x603, 1, since) >= 0, "an SDO request to node 3");
	zassert_true(find_nmt(0x02, 0x0A, 0, since) >= 0, "node 3 sends the stop");
	zassert_equal(count(0x000, 1, since), 0, "node 2 sends no NMT frame itself");
	zassert_equal(co_nmt_get_state(&t.n[2].node), CO_NMT_STOPPED);
	/* Pre-operational for all nodes (80h): the master applies it to itself too. */
	zassert_ok(co_mgr_request_nmt(&t.n[1].node, 0, 0x80, 0x7F, req_con, NULL));
	co_bus_run_ms(50);
	zassert_equal(con_abort, 0U);
	zassert_true(find_nmt(0x80, 0x00, 0, since) >= 0);
	zassert_equal(co_nmt_get_state(&t.n[0].node), CO_NMT_PRE_OPERATIONAL);
	/* Guarding of 0Ah needs a guard time in the master's 1F81h: the master refuses. */
	zassert_ok(co_mgr_request_guarding(&t.n[1].node, 0, 0x0A, true, req_con, NULL));
	co_bus_run_ms(50);
	zassert_equal(n_con, 3);
	zassert_equal(con_abort, CO_SDO_AB_DATA_DEV_STATE);
	/* Refused locally. */
	zassert_equal(co_mgr_request_nmt(&t.n[1].node, 0, 0x0A, 0x08, req_con, NULL), -EINVAL);
	zassert_equal(co_mgr_request_nmt(&t.n[1].node, 0, 0, 0x05, req_con, NULL), -EINVAL);
	zassert_equal(co_mgr_request_nmt(&t.n[0].node, 0, 0x0A, 0x05, req_con, NULL), -EPERM,
		      "the active master writes its own 1F82h");
}

ZTEST(co_mgr_fm, test_request_nmt_without_a_known_master)
{
	candidate(0, 5, 1);
	start_all();
	co_bus_run_ms(100);
	zassert_equal(co_mgr_request_nmt(&t.n[0].node, 0, 0x0A, 0x05, req_con, NULL), -ENOENT);
}

ZTEST(co_mgr_fm, test_split_two_active_masters_resolve)
{
	uint64_t joined;

	network(3, 0, 2, 1);
	start_all();
	co_bus_run_ms(6000);
	check_stable(0, 1);
	/* Split: node 3 with slave 0Ah, node 2 with 0Bh and 0Ch. */
	bus.port[1].side = 1;
	bus.port[3].side = 1;
	bus.port[4].side = 1;
	co_bus_run_ms(5000);
	zassert_equal(fm(0).state, CO_MGR_FM_ACTIVE);
	zassert_equal(fm(1).state, CO_MGR_FM_ACTIVE, "each side has its master");
	/* Joined again: the 076h cycles make one reset the network and all negotiate. */
	joined = bus.now;
	for (int i = 0; i < MAX_NODE; i++) {
		bus.port[i].side = 0;
	}
	co_bus_run_ms(15000);
	zassert_true(count(0x076, -2, joined) >= 1);
	check_stable(0, 1);
	printk("split resolved: 076h after %llu ms of the join\n",
	       at_ms(find(0x076, -2, joined)) - joined / MS);
}
