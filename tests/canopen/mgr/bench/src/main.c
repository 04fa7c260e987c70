/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Manager boot-up benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * The CiA 302 manager (node 1) brings 1, 16 and 126 slaves (the whole network) to
 * OPERATIONAL: identity checks 1F84h-1F88h (all five objects read), a 20-entry concise DCF
 * each (1017h = 100 ms and 2200h:01..13h), start error control on the first heartbeat and an
 * individual NMT start. Real line threads (the manager alone on line 0, the slaves spread over
 * lines 1..7) on the virtual bus with bit timing at 1 Mbit/s, so every frame holds the bus
 * for its real length.
 *
 * Each run starts with the manager's Reset Communication (its restore callback assigns only
 * the slaves of the run in 1F81h); the NMT startup then resets the slaves and boots them. The
 * time is from that reset to the last slave entering OPERATIONAL (its own state change).
 *
 * The bus-limited lower bound is the frames the boot needs at the least (the reset, per slave
 * its boot-up, 5 uploads, 20 downloads, the first heartbeat and the start), each with its
 * real length in bits (can_virtual_frame_bits(), stuff bits included) at 1 µs per bit. The
 * boot also waits for the slave's first heartbeat, one 1017h period after the concise DCF set
 * it, which no bus speed shortens: "floor_ms" is the larger of the bus bound and one slave's
 * own chain (its frames, with that period in the middle), "ratio_to_floor" the time over it.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <can_virtual.h>
#include <canopen/cfg.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>

#include "net_master_od.h"
#include "net_slave_cdcf.h"
#include "net_slave_od.h"

#define N_LINES     8
#define MANAGER_ID  1U
#define FIRST_SLAVE 2U
#define MAX_SLAVES  126U
#define BITRATE     1000000U
#define RUN_WAIT_MS 30000
#define IDENT_READS 5U /* 1000h, 1018h:01..04 */

BUILD_ASSERT(CONFIG_CAN_VIRTUAL_NUM_CONTROLLERS >= N_LINES, "one controller per line");
BUILD_ASSERT(CONFIG_CANOPEN_MGR_SLAVES >= MAX_SLAVES, "one manager slot per slave");

static const unsigned int runs[] = {1, 16, MAX_SLAVES};

struct slave {
	struct co_node node;
	struct net_slave_od_ram ram;
	bool started;
};

static struct co_line lines[N_LINES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static struct slave slaves[MAX_SLAVES];
static struct co_node mgr;
static struct net_master_od_ram mram;
static struct co_cfg cfg;

/* Slaves assigned in this run; read by the manager's restore callback under its lock. */
static unsigned int n_active;
static K_SEM_DEFINE(startup_sem, 0, 1);
static K_SEM_DEFINE(all_op_sem, 0, 1);
static atomic_t op_count;
static atomic_t op_target;
static uint64_t last_op_us; /* written by the slave that completes the count */
static enum co_mgr_startup startup_result;

/*
 * What happened during a run besides the boots, printed when a run fails so that a failure
 * says why: heartbeat losses the manager saw, boot attempts that ended with an error (the
 * first one kept), line queue overruns and overflows.
 */
static atomic_t hb_lost;
static atomic_t boot_errors;
static atomic_t line_events;
static struct co_mgr_boot_error first_err; /* under the manager's lock */

/*
 * How far each line thread runs behind: a timer on every line asks to run every 10 ms and
 * notes how late it ran, the longest of the run over all lines. Slaves, bus and manager
 * share one host process; when the host gives them less CPU than the boot needs (a loaded
 * machine), the line threads fall behind real time, and a lag near a protocol timeout of the
 * boot (SDO, heartbeat consumer) fails a boot that a real network would not fail.
 */
#define LAG_TICK_US 10000U
static atomic_t lag_max_us;
static struct co_timer lag_timers[N_LINES];
static uint64_t lag_due[N_LINES]; /* written by each line's own thread */

static void lag_tick(struct co_timer *timer, uint64_t now_us)
{
	struct co_line *line = timer->user_data;
	int l = (int)(line - lines);
	int64_t late = (int64_t)(co_line_now() - lag_due[l]);

	/* Eight line threads update the maximum. */
	for (atomic_val_t m = atomic_get(&lag_max_us); late > m; m = atomic_get(&lag_max_us)) {
		if (atomic_cas(&lag_max_us, m, (atomic_val_t)late)) {
			break;
		}
	}
	lag_due[l] = co_line_now() + LAG_TICK_US;
	co_timer_start(line, timer, lag_due[l]);
}

static void fail(const char *what)
{
	printf("mgr_bench: %s\n", what);
	exit(1);
}

/* Reset Communication reloads 1F81h from the dictionary: keep only this run's slaves. */
static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (unsigned int id = FIRST_SLAVE + n_active; id <= 127U; id++) {
		(void)co_od_set_u32(od, 0x1F81, (uint8_t)id, 0U, CO_OD_WRITER_APP);
	}
}

static void on_startup(struct co_node *node, enum co_mgr_startup result,
		       const struct co_mgr_boot_error *err, void *user_data)
{
	startup_result = result;
	k_sem_give(&startup_sem);
}

static void on_boot(struct co_node *node, uint8_t id, uint8_t status,
		    const struct co_mgr_boot_error *err, void *user_data)
{
	if (status != CO_MGR_ST_OK && atomic_inc(&boot_errors) == 0 && err != NULL) {
		first_err = *err;
	}
}

static void on_ec(struct co_node *node, uint8_t id, enum co_mgr_ec_event event,
		  enum co_nmt_state state, void *user_data)
{
	if (event == CO_MGR_EC_HB_LOST) {
		atomic_inc(&hb_lost);
	}
}

static void on_line_event(struct co_line *line, enum co_line_event event, int arg, void *user_data)
{
	if (event == CO_LINE_EV_RX_OVERRUN || event == CO_LINE_EV_TX_OVERFLOW) {
		atomic_inc(&line_events);
	}
}

/* Why a run failed: the counters, then each slave that did not end a full boot. */
static void explain(unsigned int n)
{
	printf("mgr_bench: %ld heartbeat losses, %ld failed boot attempts, %ld line overruns, "
	       "longest line lag %.1f ms\n",
	       (long)atomic_get(&hb_lost), (long)atomic_get(&boot_errors),
	       (long)atomic_get(&line_events), (double)atomic_get(&lag_max_us) / 1e3);
	static enum co_nmt_state own[MAX_SLAVES];

	/* Each slave's state under its own lock, before the manager's (no nested locks). */
	for (unsigned int i = 0; i < n; i++) {
		co_node_lock(&slaves[i].node);
		own[i] = co_node_nmt_state(&slaves[i].node);
		co_node_unlock(&slaves[i].node);
	}
	co_node_lock(&mgr);
	if (atomic_get(&boot_errors) != 0) {
		printf("mgr_bench: first failed attempt: node %u status %c in %s, %04Xh:%02Xh "
		       "abort %08X\n",
		       first_err.node_id, first_err.status, co_mgr_step_str(first_err.step),
		       first_err.index, first_err.sub, first_err.abort_code);
	}
	for (unsigned int i = 0; i < n; i++) {
		struct co_mgr_boot_info b;
		uint8_t id = (uint8_t)(FIRST_SLAVE + i);

		if (co_mgr_get_boot(&mgr, id, &b) != 0) {
			continue;
		}
		if (b.status != CO_MGR_ST_OK || b.attempts != 1U || b.read_mask != 0x1FU ||
		    b.booting || own[i] != CO_NMT_OPERATIONAL) {
			printf("mgr_bench: node %u: status %02X (%s) attempts %u read %02X "
			       "booting %d own state %02X, in the manager's view %02X\n",
			       id, b.status,
			       b.status == CO_MGR_ST_OK ? "ok" : co_mgr_step_str(b.error.step),
			       b.attempts, b.read_mask, b.booting, own[i], b.nmt_state);
		}
	}
	co_node_unlock(&mgr);
}

static int on_slave_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
			  void *user_data)
{
	if (to == CO_NMT_OPERATIONAL && atomic_inc(&op_count) + 1 == atomic_get(&op_target)) {
		last_op_us = co_line_time(co_node_line(node));
		k_sem_give(&all_op_sem);
	}
	return 0;
}

static void setup(void)
{
	char name[16];

	for (int l = 0; l < N_LINES; l++) {
		snprintf(name, sizeof(name), "can_virtual%d", l);
		if (co_line_init(&lines[l], l == 0 ? "mgr" : "slaves", device_get_binding(name)) !=
		    0) {
			fail("line init failed");
		}
	}
	for (unsigned int i = 0; i < MAX_SLAVES; i++) {
		if (co_node_init(&slaves[i].node, "slave", &lines[1 + i % (N_LINES - 1)],
				 &net_slave_od_def, &slaves[i].ram,
				 (uint8_t)(FIRST_SLAVE + i)) != 0) {
			fail("slave init failed");
		}
		co_nmt_set_state_ind(&slaves[i].node, on_slave_state, NULL);
	}
	if (co_node_init(&mgr, "manager", &lines[0], &net_master_od_def, &mram, MANAGER_ID) != 0 ||
	    co_cfg_init(&cfg, &mgr) != 0) {
		fail("manager init failed");
	}
	co_od_set_restore_cb(co_node_od(&mgr), mgr_restore, NULL);
	for (unsigned int i = 0; i < MAX_SLAVES; i++) {
		if (co_cfg_set_concise_dcf(&cfg, (uint8_t)(FIRST_SLAVE + i), net_slave_cdcf,
					   sizeof(net_slave_cdcf)) != 0) {
			fail("concise DCF refused");
		}
	}
	co_mgr_set_startup_ind(&mgr, on_startup, NULL);
	co_mgr_set_boot_ind(&mgr, on_boot, NULL);
	co_mgr_set_ec_ind(&mgr, on_ec, NULL);
	for (int l = 0; l < N_LINES; l++) {
		co_line_set_event_cb(&lines[l], on_line_event, NULL);
	}
	for (int l = 0; l < N_LINES; l++) {
		if (co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
				  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0) {
			fail("line start failed");
		}
	}
}

/* --- Bus-limited lower bound ---------------------------------------------------------------- */

static uint32_t bits_of(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	memcpy(f.data, data, dlc);
	return can_virtual_frame_bits(&f);
}

static uint32_t sdo_pair_bits(uint8_t id, uint8_t req_cs, uint8_t resp_cs, uint16_t index,
			      uint8_t sub, const uint8_t *val, uint8_t len, bool upload)
{
	uint8_t req[8] = {req_cs, (uint8_t)index, (uint8_t)(index >> 8), sub};
	uint8_t resp[8] = {resp_cs, (uint8_t)index, (uint8_t)(index >> 8), sub};

	memcpy(upload ? &resp[4] : &req[4], val, len);
	return bits_of(0x600U + id, 8, req) + bits_of(0x580U + id, 8, resp);
}

/*
 * Bits the boot of slave @p id needs at the least, with the values it really carries: boot-up,
 * uploads of 1000h and 1018h:01..04 (expedited, 4 bytes), the concise DCF downloads
 * (expedited), the first heartbeat (Pre-operational) and the NMT start. @p before_hb: the bits
 * up to the download of 1017h, after which the slave's first heartbeat is one period away;
 * @p tail: that heartbeat and the start.
 */
static uint32_t slave_boot_bits(uint8_t id, uint32_t *frames, uint32_t *before_hb, uint32_t *tail)
{
	struct co_node *n = &slaves[id - FIRST_SLAVE].node;
	const uint8_t *p = net_slave_cdcf + CO_CFG_CDCF_HDR_SIZE;
	uint32_t entries = (uint32_t)co_od_le_get(net_slave_cdcf, 4);
	const uint8_t bootup = 0x00, preop = 0x7F, start[2] = {0x01, id};
	uint32_t bits = bits_of(0x700U + id, 1, &bootup);
	uint8_t v[4];

	for (uint8_t k = 0; k < IDENT_READS; k++) {
		uint16_t index = k == 0 ? 0x1000 : 0x1018;
		uint8_t sub = k == 0 ? 0 : k;
		uint32_t val = 0;

		co_node_lock(n);
		(void)co_od_get_u32(co_node_od(n), index, sub, &val);
		co_node_unlock(n);
		co_od_le_put(v, 4, val);
		bits += sdo_pair_bits(id, 0x40, 0x43, index, sub, v, 4, true);
	}
	for (uint32_t e = 0; e < entries; e++) {
		uint16_t index = (uint16_t)co_od_le_get(p, 2);
		uint8_t sub = p[2];
		uint32_t size = (uint32_t)co_od_le_get(p + 3, 4);

		if (size > 4U) {
			fail("the bound assumes expedited downloads");
		}
		/* 2Fh/2Bh/27h/23h: expedited, size indicated */
		bits += sdo_pair_bits(id, (uint8_t)(0x23U | ((4U - size) << 2)), 0x60, index, sub,
				      p + CO_CFG_CDCF_ENTRY_HDR, (uint8_t)size, false);
		p += CO_CFG_CDCF_ENTRY_HDR + size;
		if (index == 0x1017 && sub == 0U) {
			*before_hb = bits;
		}
	}
	*tail = bits_of(0x700U + id, 1, &preop) + bits_of(0x000, 2, start);
	bits += *tail;
	*frames += 1U + 2U * IDENT_READS + 2U * entries + 2U;
	return bits;
}

/* Value of @p index:sub in the concise DCF (0 if absent): the heartbeat period it sets. */
static uint32_t cdcf_value(uint16_t index, uint8_t sub)
{
	const uint8_t *p = net_slave_cdcf + CO_CFG_CDCF_HDR_SIZE;
	uint32_t entries = (uint32_t)co_od_le_get(net_slave_cdcf, 4);

	for (uint32_t e = 0; e < entries; e++) {
		uint32_t size = (uint32_t)co_od_le_get(p + 3, 4);

		if (co_od_le_get(p, 2) == index && p[2] == sub && size <= 4U) {
			return (uint32_t)co_od_le_get(p + CO_CFG_CDCF_ENTRY_HDR, size);
		}
		p += CO_CFG_CDCF_ENTRY_HDR + size;
	}
	return 0;
}

/* --- One run --------------------------------------------------------------------------------- */

static void run(unsigned int n)
{
	struct can_virtual_bus_stats s0, s1;
	const uint8_t reset_all[2] = {0x82, 0x00};
	uint32_t bound_bits = bits_of(0x000, 2, reset_all);
	uint32_t bound_frames = 1U;
	uint32_t hb_ms = cdcf_value(0x1017, 0);
	uint64_t t0;
	bool first = n == runs[0];
	double ms, bound_ms, chain_ms = 0, floor_ms;

	/* Slaves of this run that are not running yet join now, before the manager resets. */
	for (unsigned int i = 0; i < n; i++) {
		if (!slaves[i].started) {
			if (co_node_start(&slaves[i].node) != 0) {
				fail("slave start failed");
			}
			slaves[i].started = true;
		}
	}
	k_sleep(K_MSEC(300));

	co_node_lock(&mgr);
	n_active = n;
	co_node_unlock(&mgr);
	atomic_set(&op_count, 0);
	atomic_set(&op_target, (atomic_val_t)n);
	atomic_set(&hb_lost, 0);
	atomic_set(&boot_errors, 0);
	atomic_set(&line_events, 0);
	atomic_set(&lag_max_us, 0);
	k_sem_reset(&startup_sem);
	k_sem_reset(&all_op_sem);
	(void)can_virtual_bus_get_stats(0, &s0);
	t0 = co_line_time(&lines[0]);
	/* Initialising -> Pre-operational runs the NMT startup (CiA 302-2 §3.1). */
	if ((first ? co_node_start(&mgr) : co_nmt_req(&mgr, CO_NMT_CS_RESET_COMMUNICATION)) != 0) {
		fail("manager start failed");
	}
	if (k_sem_take(&startup_sem, K_MSEC(RUN_WAIT_MS)) != 0 ||
	    startup_result != CO_MGR_STARTUP_DONE) {
		explain(n);
		fail("the startup did not complete");
	}
	if (k_sem_take(&all_op_sem, K_MSEC(RUN_WAIT_MS)) != 0) {
		printf("mgr_bench: %ld of %u slaves OPERATIONAL\n", (long)atomic_get(&op_count), n);
		explain(n);
		fail("not every slave became OPERATIONAL");
	}
	(void)can_virtual_bus_get_stats(0, &s1);

	/* Every boot was a full one: OK at the first attempt, every identity object read. */
	for (unsigned int i = 0; i < n; i++) {
		struct co_mgr_boot_info b;
		uint8_t id = (uint8_t)(FIRST_SLAVE + i);

		co_node_lock(&mgr);
		if (co_mgr_get_boot(&mgr, id, &b) != 0 || b.status != CO_MGR_ST_OK ||
		    b.attempts != 1U || b.read_mask != 0x1FU) {
			co_node_unlock(&mgr);
			printf("mgr_bench: node %u status %02X attempts %u read %02X\n", id,
			       b.status, b.attempts, b.read_mask);
			explain(n);
			fail("a boot was not a full one");
		}
		co_node_unlock(&mgr);
		uint32_t frames = 0, before_hb = 0, tail = 0;
		uint32_t bits = slave_boot_bits(id, &frames, &before_hb, &tail);
		double rest_ms = (double)(bits - before_hb - tail) * (1e3 / BITRATE);

		/*
		 * One slave's own chain, which no parallelism shortens: its frames up to 1017h,
		 * then the heartbeat period (the other downloads fit in it), the heartbeat, the
		 * start.
		 */
		chain_ms = MAX(chain_ms, (double)(before_hb + tail) * (1e3 / BITRATE) +
						 MAX((double)hb_ms, rest_ms));
		bound_bits += bits;
		bound_frames += frames;
	}

	ms = (double)(last_op_us - t0) / 1e3;
	bound_ms = (double)bound_bits * (1e3 / BITRATE);
	floor_ms = MAX(bound_ms, chain_ms);
	printf("BENCH {\"name\": \"mgr.boot_%u\", \"slaves\": %u, \"ms\": %.1f, "
	       "\"bus_bound_ms\": %.2f, \"floor_ms\": %.2f, \"ratio_to_floor\": %.2f, "
	       "\"frames_needed\": %u, "
	       "\"bits_needed\": %u, \"bus_frames\": %u, \"bus_busy_ms\": %.2f, "
	       "\"cdcf_entries\": %u, \"hb_ms\": %u, \"bitrate\": %u, "
	       "\"line_lag_ms\": %.1f}\n",
	       n, n, ms, bound_ms, floor_ms, ms / floor_ms, bound_frames, bound_bits,
	       s1.frames - s0.frames, (double)(s1.busy_ns - s0.busy_ns) / 1e6,
	       (unsigned int)co_od_le_get(net_slave_cdcf, 4), hb_ms, BITRATE,
	       (double)atomic_get(&lag_max_us) / 1e3);
}

int main(void)
{
	printf("mgr_bench: manager boots 1, 16 and %u slaves at %u bit/s (bit timing on)\n",
	       MAX_SLAVES, BITRATE);
	setup();
	for (int l = 0; l < N_LINES; l++) {
		co_timer_init(&lag_timers[l], lag_tick, NULL, &lines[l]);
		lag_due[l] = co_line_now() + LAG_TICK_US;
		co_timer_start(&lines[l], &lag_timers[l], lag_due[l]);
	}
	for (size_t r = 0; r < ARRAY_SIZE(runs); r++) {
		run(runs[r]);
	}
	printf("mgr_bench: done\n");
	return 0;
}
