/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Flying-master benchmark (doc/flying-master.md, doc/bench.md): how long a network runs
 * without an NMT master when the active one dies, on the virtual bus in real time (bit timing
 * on). Figures only, nothing is judged.
 *
 * Node 3 (priority 0) and node 2 (priority 1) are candidates (1F80h = 21h), node 10 a slave;
 * each candidate watches the other's heartbeat (1016h) and assigns the other and the slave in
 * 1F81h. A raw controller (can_virtual3) stamps every frame on the bus. Each run:
 *
 *   1. node 3 is the active master and its NMT startup is done;
 *   2. at a random point of the heartbeat cycle node 3's controller is cut (it dies);
 *   3. node 2 loses node 3's heartbeat, resets the network (000#8200), waits 1F90h:02, asks
 *      073h, waits 1F90h:01, sends 072h, waits its slot and announces 071#01 02, then starts
 *      the NMT startup with 000#8200;
 *   4. node 3 is restored and reset (Reset Node): it asks 073h, hears node 2's 071h, forces a
 *      negotiation (076h) and wins again, ready for the next run.
 *
 * Per run, from node 3's last heartbeat on the bus:
 *
 *   loss      -> node 2's 000#8200 (the heartbeat consumer time, 1016h)
 *   announce  -> node 2's 071#01 02
 *   takeover  -> node 2's first NMT command as master (its startup's 000#8200)
 *
 * against the bound 1016h + 1F90h:02 + 1F90h:01 + priority x 1F90h:04 + node-ID x 1F90h:05.
 * Two sets of timings: "fast" (heartbeat 50 ms, consumer 150 ms, 1F90h 50/100/300/2 ms) over
 * --runs runs, and the CiA 302 defaults of 1F90h with the sample's heartbeat (100/300 ms) over
 * --default-runs runs.
 */

#include <stdio.h>
#include <stdlib.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/random/random.h>
#include <zephyr/sys/byteorder.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/nmt.h>
#include <canopen/node.h>

#include "cmdline.h"
#include "fm_master_od.h"
#include "fm_slave_od.h"
#include "posix_native_task.h"

#define N_MGR    2
#define SLAVE_ID 10U
#define MAX_RUNS 100U

static uint32_t runs_arg = 20U;
static uint32_t default_runs_arg = 3U;

static void runs_found(char *argv, int offset)
{
	runs_arg = (uint32_t)cmd_read_uint_option("runs", &argv[offset], 1U, MAX_RUNS);
}

static void default_runs_found(char *argv, int offset)
{
	default_runs_arg =
		(uint32_t)cmd_read_uint_option("default-runs", &argv[offset], 0U, MAX_RUNS);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "runs",
			.name = "n",
			.type = 'u',
			.call_when_found = runs_found,
			.descript = "take-overs with the fast timings (1..100, default 20)",
		},
		{
			.option = "default-runs",
			.name = "n",
			.type = 'u',
			.call_when_found = default_runs_found,
			.descript =
				"take-overs with the CiA 302 defaults of 1F90h (0..100, default 3)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 20);

/* One set of timings [ms]: heartbeat, consumer time, 1F90h:01, :02, :04, :05. */
struct timing {
	const char *name;
	uint16_t hb, consumer, detect, delay, prio_slot, node_slot;
};

static const struct timing timings[] = {
	{"fast", 50U, 150U, 50U, 100U, 300U, 2U},
	{"default", 100U, 300U, 100U, 500U, 1500U, 10U},
};

static const uint8_t mgr_id[N_MGR] = {3, 2};
static const uint8_t mgr_prio[N_MGR] = {0, 1};

static const struct timing *tm = &timings[0];
static struct co_line lines[3];
static struct co_node mgr[N_MGR];
static struct fm_master_od_ram mgr_ram[N_MGR];
static struct co_node slave;
static struct fm_slave_od_ram slave_ram;
static K_THREAD_STACK_ARRAY_DEFINE(stacks, 3, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(startup_done, 0, 8);
static atomic_t startup_of = ATOMIC_INIT(-1);

static uint32_t bound_ms(void)
{
	return tm->consumer + tm->delay + tm->detect + mgr_prio[1] * tm->prio_slot +
	       mgr_id[1] * tm->node_slot;
}

/* --- The observer: the times of the frames a run is about [µs, can_virtual_time_us()] ----- */

/* The observer runs in the virtual bus's thread; held only for a few stores. */
static K_MUTEX_DEFINE(obs_lock);
static struct {
	uint64_t last_hb3;  /* node 3's last heartbeat */
	uint64_t cut;       /* 0 until node 3 is cut: then the frames below are taken */
	uint64_t reset;     /* the first 000#8200 after the cut (node 2's loss) */
	uint64_t announce;  /* 071#01 02 */
	uint64_t first_nmt; /* the first NMT frame after it */
} obs;

static void observe(const struct device *dev, struct can_frame *f, void *user_data)
{
	uint64_t now = can_virtual_time_us();

	ARG_UNUSED(dev);
	ARG_UNUSED(user_data);
	(void)k_mutex_lock(&obs_lock, K_FOREVER);
	if (obs.cut == 0U) {
		if (f->id == 0x703U) {
			obs.last_hb3 = now;
		}
	} else if (f->id == 0x000U && f->dlc == 2U) {
		if (obs.reset == 0U && f->data[0] == 0x82U && f->data[1] == 0U) {
			obs.reset = now;
		} else if (obs.announce != 0U && obs.first_nmt == 0U) {
			obs.first_nmt = now;
		}
	} else if (f->id == 0x071U && f->dlc == 2U && f->data[0] == mgr_prio[1] &&
		   f->data[1] == mgr_id[1] && obs.announce == 0U) {
		obs.announce = now;
	}
	(void)k_mutex_unlock(&obs_lock);
}

/* --- The network -------------------------------------------------------------------------- */

static void put(struct co_od *od, uint16_t index, uint8_t sub, uint32_t v, size_t len)
{
	uint8_t buf[4];

	sys_put_le32(v, buf);
	(void)co_od_write(od, index, sub, buf, len, CO_OD_WRITER_STORAGE);
}

/* The candidates' configuration, applied at every reset as a storage module would. */
static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	int i = (int)(intptr_t)user_data;
	uint8_t other = mgr_id[1 - i];

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	put(od, 0x1F80, 0, 0x21, 4); /* NMT master, flying master */
	/* :04 before :05 would break :04 > 127 x :05 with the old :04 on the way down. */
	put(od, 0x1F90, 5, tm->node_slot, 2);
	put(od, 0x1F90, 4, tm->prio_slot, 2);
	put(od, 0x1F90, 5, tm->node_slot, 2);
	put(od, 0x1F90, 1, tm->detect, 2);
	put(od, 0x1F90, 2, tm->delay, 2);
	put(od, 0x1F90, 3, mgr_prio[i], 2);
	put(od, 0x1017, 0, tm->hb, 2);
	put(od, 0x1029, 1, 1, 1); /* the manager handles lost heartbeats, not 1029h */
	put(od, 0x1016, 1, ((uint32_t)other << 16) | tm->consumer, 4);
	put(od, 0x1F81, other, 0x05, 4); /* slave, boot */
	put(od, 0x1F81, SLAVE_ID, 0x05, 4);
}

static void startup_ind(struct co_node *node, enum co_mgr_startup result,
			const struct co_mgr_boot_error *err, void *user_data)
{
	ARG_UNUSED(node);
	ARG_UNUSED(err);
	if (result == CO_MGR_STARTUP_DONE) {
		(void)atomic_set(&startup_of, (atomic_val_t)(intptr_t)user_data);
		k_sem_give(&startup_done);
	}
}

static void fail(const char *what)
{
	printf("mgr_fm_bench: FAILED: %s\n", what);
	exit(1);
}

static int setup(void)
{
	static const char *const names[] = {"mgr3", "mgr2"};
	int err = 0;

	for (int l = 0; l < 3 && err == 0; l++) {
		char dev[16];
		char name[8];

		(void)snprintf(dev, sizeof(dev), "can_virtual%d", l);
		(void)snprintf(name, sizeof(name), "line%d", l);
		err = co_line_init(&lines[l], name, device_get_binding(dev));
	}
	for (int i = 0; i < N_MGR && err == 0; i++) {
		err = co_node_init(&mgr[i], names[i], &lines[i], &fm_master_od_def, &mgr_ram[i],
				   mgr_id[i]);
		if (err == 0) {
			co_od_set_restore_cb(co_node_od(&mgr[i]), mgr_restore, (void *)(intptr_t)i);
			co_mgr_set_startup_ind(&mgr[i], startup_ind, (void *)(intptr_t)i);
		}
	}
	if (err == 0) {
		err = co_node_init(&slave, "s10", &lines[2], &fm_slave_od_def, &slave_ram,
				   SLAVE_ID);
	}
	for (int l = 0; l < 3 && err == 0; l++) {
		err = co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	return err;
}

/* Wait until node @p i ran its NMT startup to the end; false after @p s seconds. */
static bool wait_startup(int i, int s)
{
	int64_t end = k_uptime_get() + s * 1000;

	while (k_uptime_get() < end) {
		if (k_sem_take(&startup_done, K_MSEC(100)) == 0 && atomic_get(&startup_of) == i) {
			return true;
		}
	}
	return false;
}

/*
 * Wait until node 2 is node 3's slave: the startup of node 3 may end before node 2, reset by
 * it, has asked 073h again and heard the answer (then a cut would find node 2 negotiating,
 * not supervising a master).
 */
static bool wait_settled(int s)
{
	int64_t end = k_uptime_get() + s * 1000;
	struct co_mgr_fm_info info = {0};

	while (k_uptime_get() < end) {
		co_node_lock(&mgr[1]);
		(void)co_mgr_fm_get(&mgr[1], &info);
		co_node_unlock(&mgr[1]);
		if (info.state == CO_MGR_FM_SLAVE && info.master_id == mgr_id[0]) {
			return true;
		}
		k_sleep(K_MSEC(10));
	}
	return false;
}

static void reset_node(struct co_node *node)
{
	co_node_lock(node);
	(void)co_nmt_req(node, CO_NMT_CS_RESET_NODE);
	co_node_unlock(node);
}

static int cmp_u32(const void *a, const void *b)
{
	uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;

	return x < y ? -1 : (x > y ? 1 : 0);
}

/* One BENCH line: min/median/max of @p n samples [µs], against @p bound (0: none) [ms]. */
static void figure(const char *name, uint32_t *us, uint32_t n, uint32_t bound)
{
	uint32_t within = 0U;

	qsort(us, n, sizeof(us[0]), cmp_u32);
	for (uint32_t i = 0; i < n; i++) {
		within += (bound != 0U && us[i] <= bound * 1000U) ? 1U : 0U;
	}
	printf("BENCH {\"name\": \"%s\", \"ops\": %u, \"ns_per_op\": %.1f, \"ms\": %.1f, "
	       "\"min_ms\": %.1f, \"median_ms\": %.1f, \"max_ms\": %.1f",
	       name, n, us[n / 2U] * 1e3, us[n / 2U] / 1e3, us[0] / 1e3, us[n / 2U] / 1e3,
	       us[n - 1U] / 1e3);
	if (bound != 0U) {
		printf(", \"bound_ms\": %u, \"within_bound\": %u", bound, within);
	}
	printf("}\n");
}

static uint32_t s_loss[MAX_RUNS], s_announce[MAX_RUNS], s_takeover[MAX_RUNS];

/* One series of @p n take-overs with the timings @p set. */
static void series(const struct timing *set, uint32_t n)
{
	const struct device *dev3 = device_get_binding("can_virtual0");
	char name[48];

	if (n == 0U) {
		return;
	}
	tm = set;
	/* New timings: both candidates and the slave start from a Reset Node. */
	k_sem_reset(&startup_done);
	reset_node(&slave);
	reset_node(&mgr[1]);
	reset_node(&mgr[0]);
	if (!wait_startup(0, 30)) {
		fail("node 3 did not become the master");
	}
	printf("mgr_fm_bench: %s timings: heartbeat %u ms, consumer %u ms, 1F90h:01 %u, :02 %u, "
	       ":04 %u, :05 %u ms; bound %u ms\n",
	       tm->name, tm->hb, tm->consumer, tm->detect, tm->delay, tm->prio_slot, tm->node_slot,
	       bound_ms());
	for (uint32_t r = 0; r < n; r++) {
		if (!wait_settled(30)) {
			fail("node 2 did not become node 3's slave");
		}
		/* Two consumer times of supervision, then a random point of the heartbeat cycle. */
		k_sleep(K_MSEC(2U * tm->consumer));
		k_sleep(K_MSEC(200U + sys_rand32_get() % tm->hb));
		(void)k_mutex_lock(&obs_lock, K_FOREVER);
		obs.cut = can_virtual_time_us();
		obs.reset = obs.announce = obs.first_nmt = 0U;
		(void)k_mutex_unlock(&obs_lock);
		k_sem_reset(&startup_done);
		if (can_virtual_cut(dev3) != 0) {
			fail("cut");
		}
		if (!wait_startup(1, 30)) {
			fail("node 2 did not take over");
		}
		(void)k_mutex_lock(&obs_lock, K_FOREVER);
		if (obs.reset == 0U || obs.announce == 0U || obs.first_nmt == 0U) {
			(void)k_mutex_unlock(&obs_lock);
			fail("a frame of the take-over was not seen");
		}
		s_loss[r] = (uint32_t)(obs.reset - obs.last_hb3);
		s_announce[r] = (uint32_t)(obs.announce - obs.last_hb3);
		s_takeover[r] = (uint32_t)(obs.first_nmt - obs.last_hb3);
		obs.cut = 0U;
		(void)k_mutex_unlock(&obs_lock);
		printf("mgr_fm_bench: %s run %u: loss %.1f ms, 071h %.1f ms, first NMT command "
		       "%.1f ms after node 3's last heartbeat (bound %u ms)\n",
		       tm->name, r + 1U, s_loss[r] / 1e3, s_announce[r] / 1e3, s_takeover[r] / 1e3,
		       bound_ms());
		/* Node 3 back: it forces a negotiation and wins again. */
		k_sem_reset(&startup_done);
		(void)can_virtual_restore(dev3);
		reset_node(&mgr[0]);
		if (!wait_startup(0, 30)) {
			fail("node 3 did not win back");
		}
	}
	(void)snprintf(name, sizeof(name), "mgr_fm.loss_%s", tm->name);
	figure(name, s_loss, n, tm->consumer);
	(void)snprintf(name, sizeof(name), "mgr_fm.announce_%s", tm->name);
	figure(name, s_announce, n, bound_ms());
	(void)snprintf(name, sizeof(name), "mgr_fm.takeover_%s", tm->name);
	figure(name, s_takeover, n, bound_ms());
}

int main(void)
{
	const struct device *observer = device_get_binding("can_virtual3");
	struct can_filter all = {.id = 0, .mask = 0, .flags = 0};

	if (observer == NULL || can_start(observer) != 0 ||
	    can_add_rx_filter(observer, observe, NULL, &all) < 0) {
		fail("observer set-up failed");
	}
	(void)can_virtual_bus_set_bit_timing(0, true);
	if (setup() != 0) {
		fail("set-up");
	}
	co_node_lock(&slave);
	(void)co_node_start(&slave);
	co_node_unlock(&slave);
	for (int i = 0; i < N_MGR; i++) {
		(void)co_node_start(&mgr[i]);
	}
	series(&timings[0], runs_arg);
	series(&timings[1], default_runs_arg);
	printf("mgr_fm_bench: done\n");
	return 0;
}
