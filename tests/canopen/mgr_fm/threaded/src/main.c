/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Flying master with real line threads (doc/flying-master.md): node 3 (priority 0) and node 2
 * (priority 1) are candidates, nodes 10-14 mandatory slaves, each node on its own controller of
 * one virtual bus in real time. Every slave's controller gets its frames late (150, 300, ... 750
 * ms), so node 3's startup boots them one after the other. When the first slave is booted,
 * node 3 is cut off the bus: the boot is cut in the middle. Node 2 loses node 3's heartbeat,
 * resets the network, wins the negotiation alone and must boot every slave to Operational.
 */

#include <stdio.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/nmt.h>
#include <canopen/node.h>

#include "fm_master_od.h"
#include "fm_slave_od.h"

#define N_MGR   2
#define N_SLAVE 5
#define N_NODES (N_MGR + N_SLAVE)
#define MAX_EV  64

/* Heartbeat 50 ms, consumer 150 ms; 1F90h:01 50, :02 100, :04 300, :05 2 ms. */
#define HB_MS       50U
#define CONSUMER_MS 150U
#define BOUND_MS    (CONSUMER_MS + 100U + 50U + 1U * 300U + 2U * 2U)

static const uint8_t node_id[N_NODES] = {3, 2, 10, 11, 12, 13, 14};
static const uint8_t mgr_prio[N_MGR] = {0, 1};

static struct co_line lines[N_NODES];
static struct co_node nodes[N_NODES];
static struct fm_master_od_ram mgr_ram[N_MGR];
static struct fm_slave_od_ram slave_ram[N_SLAVE];
static struct co_listener listener[N_MGR];
static const struct device *can[N_NODES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_NODES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(first_boot, 0, 1);

#define MGR3 (&nodes[0])
#define MGR2 (&nodes[1])

/* What each candidate's listener heard, under the candidate's mutex. */
struct rec {
	struct co_event ev;
	int64_t at_ms;
};

static struct {
	struct rec ev[MAX_EV];
	int n;
	bool done; /* the NMT startup ended DONE */
	int64_t done_ms;
} heard[N_MGR];

static void put(struct co_od *od, uint16_t index, uint8_t sub, uint32_t v, size_t len)
{
	uint8_t buf[4];

	sys_put_le32(v, buf);
	(void)co_od_write(od, index, sub, buf, len, CO_OD_WRITER_STORAGE);
}

static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	int i = (int)(intptr_t)user_data;

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	put(od, 0x1F80, 0, 0x21, 4); /* NMT master, flying master */
	put(od, 0x1F90, 5, 2, 2);
	put(od, 0x1F90, 4, 300, 2);
	put(od, 0x1F90, 1, 50, 2);
	put(od, 0x1F90, 2, 100, 2);
	put(od, 0x1F90, 3, mgr_prio[i], 2);
	put(od, 0x1017, 0, HB_MS, 2);
	put(od, 0x1029, 1, 1, 1); /* the manager handles lost heartbeats, not 1029h */
	put(od, 0x1016, 1, ((uint32_t)node_id[1 - i] << 16) | CONSUMER_MS, 4);
	put(od, 0x1F81, node_id[1 - i], 0x05, 4); /* the other candidate: optional slave */
	for (int s = N_MGR; s < N_NODES; s++) {
		put(od, 0x1F81, node_id[s], 0x0D, 4); /* slave, boot, mandatory */
	}
}

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	int i = (int)(intptr_t)user_data;

	if (heard[i].n < MAX_EV) {
		heard[i].ev[heard[i].n].ev = *ev;
		heard[i].ev[heard[i].n].at_ms = k_uptime_get();
		heard[i].n++;
	}
	if (i == 0 && ev->type == CO_EV_BOOT && ev->boot.status == 0 &&
	    ev->boot.node_id >= node_id[N_MGR]) {
		k_sem_give(&first_boot);
	}
	return 0;
}

static void startup_ind(struct co_node *node, enum co_mgr_startup result,
			const struct co_mgr_boot_error *err, void *user_data)
{
	int i = (int)(intptr_t)user_data;

	ARG_UNUSED(node);
	ARG_UNUSED(err);
	if (result == CO_MGR_STARTUP_DONE) {
		heard[i].done = true;
		heard[i].done_ms = k_uptime_get();
	}
}

static void *setup(void)
{
	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	for (int k = 0; k < N_NODES; k++) {
		char dev[16];
		char name[8];

		(void)snprintf(dev, sizeof(dev), "can_virtual%d", k);
		(void)snprintf(name, sizeof(name), "n%u", node_id[k]);
		can[k] = device_get_binding(dev);
		zassert_not_null(can[k]);
		if (k >= N_MGR) {
			/*
			 * 150, 300, ... 750 ms (below the manager's 1 s SDO timeout): the slaves'
			 * boots end one after the other.
			 */
			zassert_ok(can_virtual_set_latency(can[k], 150000U * (uint32_t)(k - 1)));
		}
		zassert_ok(co_line_init(&lines[k], name, can[k]));
		if (k < N_MGR) {
			zassert_ok(co_node_init(&nodes[k], name, &lines[k], &fm_master_od_def,
						&mgr_ram[k], node_id[k]));
			co_od_set_restore_cb(co_node_od(&nodes[k]), mgr_restore,
					     (void *)(intptr_t)k);
			co_mgr_set_startup_ind(&nodes[k], startup_ind, (void *)(intptr_t)k);
			co_listener_init(&listener[k], "test",
					 CO_EV_BIT(CO_EV_FM) | CO_EV_BIT(CO_EV_BOOT), on_event,
					 (void *)(intptr_t)k);
			zassert_ok(co_node_listener_add(&nodes[k], &listener[k]));
		} else {
			zassert_ok(co_node_init(&nodes[k], name, &lines[k], &fm_slave_od_def,
						&slave_ram[k - N_MGR], node_id[k]));
		}
	}
	for (int k = 0; k < N_NODES; k++) {
		zassert_ok(co_line_start(&lines[k], stacks[k], K_THREAD_STACK_SIZEOF(stacks[k]),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	}
	return NULL;
}

ZTEST_SUITE(co_mgr_fm_threaded, NULL, setup, NULL, NULL, NULL);

/* Boot results of candidate @p i for the slaves, heard after @p since_ms: status per slave
 * (-1: none heard), the last one counting.
 */
static void boots_of(int i, int64_t since_ms, int *status)
{
	for (int s = 0; s < N_SLAVE; s++) {
		status[s] = -1;
	}
	co_node_lock(&nodes[i]);
	for (int k = 0; k < heard[i].n; k++) {
		const struct rec *r = &heard[i].ev[k];

		for (int s = 0; s < N_SLAVE && r->ev.type == CO_EV_BOOT && r->at_ms >= since_ms;
		     s++) {
			if (r->ev.boot.node_id == node_id[N_MGR + s]) {
				status[s] = r->ev.boot.status;
			}
		}
	}
	co_node_unlock(&nodes[i]);
}

static int64_t heard_fm(int i, enum co_mgr_fm_event what, int64_t since_ms)
{
	int64_t at = 0;

	co_node_lock(&nodes[i]);
	for (int k = 0; k < heard[i].n && at == 0; k++) {
		const struct rec *r = &heard[i].ev[k];

		if (r->ev.type == CO_EV_FM && r->ev.fm.what == what && r->at_ms >= since_ms) {
			at = r->at_ms;
		}
	}
	co_node_unlock(&nodes[i]);
	return at;
}

static bool settled(int timeout_ms)
{
	int64_t end = k_uptime_get() + timeout_ms;
	struct co_mgr_fm_info info = {0};

	do {
		co_node_lock(MGR2);
		(void)co_mgr_fm_get(MGR2, &info);
		co_node_unlock(MGR2);
		if (info.state == CO_MGR_FM_SLAVE && info.master_id == node_id[0]) {
			return true;
		}
		k_msleep(5);
	} while (k_uptime_get() < end);
	return false;
}

static bool wait_done(int i, int timeout_ms)
{
	int64_t end = k_uptime_get() + timeout_ms;
	bool done = false;

	while (!done && k_uptime_get() < end) {
		k_msleep(10);
		co_node_lock(&nodes[i]);
		done = heard[i].done;
		co_node_unlock(&nodes[i]);
	}
	return done;
}

ZTEST(co_mgr_fm_threaded, test_master_cut_mid_boot_other_completes_it)
{
	int before[N_SLAVE], after[N_SLAVE];
	int booted = 0;
	int64_t cut_ms, active_ms;

	for (int k = N_NODES - 1; k >= 0; k--) {
		zassert_ok(co_node_start(&nodes[k]));
	}
	/*
	 * Node 3 wins and starts booting the slaves; cut it when the first one is booted and node
	 * 2, reset by node 3's startup, has found node 3 again (073h, 071h) and watches its
	 * heartbeat.
	 */
	zassert_ok(k_sem_take(&first_boot, K_SECONDS(20)), "node 3 booted no slave");
	zassert_true(settled(2000), "node 2 is node 3's slave");
	zassert_ok(can_virtual_cut(can[0]));
	cut_ms = k_uptime_get();
	zassert_true(heard_fm(0, CO_MGR_FM_EV_ACTIVE, 0) != 0, "node 3 was the master");
	boots_of(0, 0, before);
	for (int s = 0; s < N_SLAVE; s++) {
		booted += before[s] == 0 ? 1 : 0;
	}
	TC_PRINT("node 3 cut at %lld ms with %d of %d slaves booted\n", (long long)cut_ms, booted,
		 N_SLAVE);
	zassert_true(booted >= 1 && booted < N_SLAVE, "cut in the middle of the boot (%d)", booted);
	co_node_lock(MGR3);
	zassert_false(heard[0].done, "node 3's startup had not ended");
	co_node_unlock(MGR3);

	/* Node 2 takes over within the bound of 1016h and 1F90h (and the line threads' lag). */
	zassert_true(wait_done(1, 15000), "node 2's startup did not end");
	zassert_true(heard_fm(1, CO_MGR_FM_EV_LOST, cut_ms) != 0, "node 2 lost node 3");
	active_ms = heard_fm(1, CO_MGR_FM_EV_ACTIVE, cut_ms);
	zassert_true(active_ms != 0, "node 2 became the master");
	TC_PRINT("node 2 active %lld ms after the cut (bound %u ms from node 3's last heartbeat), "
		 "startup done after %lld ms\n",
		 (long long)(active_ms - cut_ms), BOUND_MS, (long long)(heard[1].done_ms - cut_ms));
	zassert_true(active_ms - cut_ms <= BOUND_MS + 500U, "take-over late");

	/* Every slave booted by node 2 (mandatory: DONE means every one), all Operational. */
	boots_of(1, cut_ms, after);
	for (int s = 0; s < N_SLAVE; s++) {
		zassert_equal(after[s], 0, "node %u booted by node 2 (status %d)",
			      node_id[N_MGR + s], after[s]);
	}
	/* The individual starts reach the last slaves late (their latency, up to 750 ms). */
	for (int s = 0; s < N_SLAVE; s++) {
		struct co_node *n = &nodes[N_MGR + s];
		enum co_nmt_state st = CO_NMT_INITIALISING;
		int64_t end = k_uptime_get() + 2000;

		while (st != CO_NMT_OPERATIONAL && k_uptime_get() < end) {
			co_node_lock(n);
			st = co_nmt_get_state(n);
			co_node_unlock(n);
			k_msleep(10);
		}
		zassert_equal(st, CO_NMT_OPERATIONAL, "node %u Operational", node_id[N_MGR + s]);
	}
	/* Node 2 is the master, node 3 (cut) has no say. */
	{
		struct co_mgr_fm_info info;

		co_node_lock(MGR2);
		zassert_ok(co_mgr_fm_get(MGR2, &info));
		co_node_unlock(MGR2);
		zassert_equal(info.state, CO_MGR_FM_ACTIVE);
		zassert_equal(info.master_id, 2);
	}
}
