/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A whole network booted by the CiA 302 manager with real threads on the virtual bus.
 *
 * The manager (node 1) is alone on line 0; the 126 slaves (node-IDs 2..127: every ID the
 * manager does not have) are spread over lines 1..7, 18 per line. Each line has its own
 * thread and controller on one virtual bus; slaves of one line reach each other through the
 * line's local delivery, the manager through the bus. The manager checks every identity
 * object (1F84h-1F88h all set), downloads a 20-entry concise DCF to each slave (1017h and
 * 2200h:01..13h), starts error control on the heartbeat that DCF turns on and starts each
 * slave individually (1F80h = 01h), all slaves at once. Built with MGR_NET_START_ALL (scenario
 * canopen.mgr_net.start_all) the manager starts them with one broadcast instead (1F80h = 03h,
 * CiA 302-2 §3.1 h).
 *
 * Asserted: startup DONE; every slave OK at the first attempt with the identity the slave
 * really has; every slave's dictionary holds every value of the concise DCF; every slave
 * OPERATIONAL, and the manager sees it so from its heartbeat. Times are printed, not judged.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/cfg.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>

#include "net_master_od.h"
#include "net_slave_cdcf.h"
#include "net_slave_od.h"

#define N_LINES        8
#define MANAGER_ID     1U
#define FIRST_SLAVE    2U
#define N_SLAVES       126U
#define STARTUP_WAIT_S 60
#define STATE_WAIT_MS  10000

BUILD_ASSERT(CONFIG_CAN_VIRTUAL_NUM_CONTROLLERS >= N_LINES, "one controller per line");
BUILD_ASSERT(CONFIG_CANOPEN_MGR_SLAVES >= N_SLAVES, "one manager slot per slave");

struct slave {
	struct co_node node;
	struct net_slave_od_ram ram;
};

static struct co_line lines[N_LINES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static struct slave slaves[N_SLAVES];
static struct co_node mgr;
static struct net_master_od_ram mram;
static struct co_cfg cfg;

/* Written by the indications (manager line thread, manager lock held); read under that lock. */
static struct {
	uint16_t boot_calls[128];
	uint8_t boot_status[128];
	uint16_t boot_errors;
	int startup_calls;
	enum co_mgr_startup startup;
	struct co_mgr_boot_error halt_err;
} seen;
static K_SEM_DEFINE(startup_sem, 0, 1);

static uint64_t start_us;
static typeof(seen) snap;

static void on_boot(struct co_node *node, uint8_t id, uint8_t status,
		    const struct co_mgr_boot_error *err, void *user_data)
{
	seen.boot_calls[id & 0x7f]++;
	seen.boot_status[id & 0x7f] = status;
	if (err != NULL) {
		seen.boot_errors++;
		printk("mgr_net: node %u boot error %c in %s, %04X:%02X expected %08X actual %08X "
		       "abort %08X\n",
		       id, status, co_mgr_step_str(err->step), err->index, err->sub, err->expected,
		       err->actual, err->abort_code);
	}
}

static void on_startup(struct co_node *node, enum co_mgr_startup result,
		       const struct co_mgr_boot_error *err, void *user_data)
{
	seen.startup_calls++;
	seen.startup = result;
	if (err != NULL) {
		seen.halt_err = *err;
	}
	k_sem_give(&startup_sem);
}

#if defined(MGR_NET_START_ALL)
/* Reset Communication reloads 1F80h from the dictionary (01h): make it "start all". */
static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		(void)co_od_set_u32(od, 0x1F80, 0, 0x03, CO_OD_WRITER_APP);
	}
}
#endif

static struct slave *slave_of(uint8_t id)
{
	return &slaves[id - FIRST_SLAVE];
}

static void *setup(void)
{
	char name[16];

	for (int l = 0; l < N_LINES; l++) {
		snprintk(name, sizeof(name), "can_virtual%d", l);
		zassert_ok(co_line_init(&lines[l], l == 0 ? "mgr" : "slaves",
					device_get_binding(name)));
	}
	/* Slave i on line 1 + i % 7. */
	for (unsigned int i = 0; i < N_SLAVES; i++) {
		zassert_ok(co_node_init(&slaves[i].node, "slave", &lines[1 + i % (N_LINES - 1)],
					&net_slave_od_def, &slaves[i].ram,
					(uint8_t)(FIRST_SLAVE + i)));
	}
	zassert_ok(co_node_init(&mgr, "manager", &lines[0], &net_master_od_def, &mram, MANAGER_ID));
	zassert_ok(co_cfg_init(&cfg, &mgr));
#if defined(MGR_NET_START_ALL)
	co_od_set_restore_cb(co_node_od(&mgr), mgr_restore, NULL);
#endif
	for (unsigned int i = 0; i < N_SLAVES; i++) {
		zassert_ok(co_cfg_set_concise_dcf(&cfg, (uint8_t)(FIRST_SLAVE + i), net_slave_cdcf,
						  sizeof(net_slave_cdcf)));
	}
	co_mgr_set_boot_ind(&mgr, on_boot, NULL);
	co_mgr_set_startup_ind(&mgr, on_startup, NULL);
	for (int l = 0; l < N_LINES; l++) {
		zassert_ok(co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	}
	for (unsigned int i = 0; i < N_SLAVES; i++) {
		zassert_ok(co_node_start(&slaves[i].node));
	}
	return NULL;
}

/* Line counters: tell a slow machine (timeouts) from lost frames (overruns, drops). */
static void after(void *unused)
{
	for (int l = 0; l < N_LINES; l++) {
		struct co_line_stats st;

		co_line_get_stats(&lines[l], &st);
		printk("mgr_net: line %d rx %u tx %u queue_max %u dropped %u errors %u overruns "
		       "%u\n",
		       l, st.rx_frames, st.tx_frames, st.tx_queue_max, st.tx_dropped, st.tx_errors,
		       st.rx_overruns);
	}
}

ZTEST_SUITE(mgr_net, NULL, setup, NULL, after, NULL);

static uint32_t od_u32(struct co_node *n, uint16_t index, uint8_t sub)
{
	uint32_t v = 0;
	uint32_t ab;

	co_node_lock(n);
	ab = co_od_get_u32(co_node_od(n), index, sub, &v);
	co_node_unlock(n);
	zassert_equal(ab, 0U, "%04X:%02X abort %08X", index, sub, ab);
	return v;
}

static unsigned int count_operational(void)
{
	unsigned int n = 0;

	for (unsigned int i = 0; i < N_SLAVES; i++) {
		n += co_nmt_get_state(&slaves[i].node) == CO_NMT_OPERATIONAL ? 1U : 0U;
	}
	return n;
}

/* Every entry of the concise DCF is in the slave's dictionary, byte for byte. */
static void check_configured(uint8_t id)
{
	struct co_node *n = &slave_of(id)->node;
	const uint8_t *p = net_slave_cdcf;
	uint32_t entries = (uint32_t)co_od_le_get(p, 4);

	zassert_equal(entries, 20U, "the concise DCF has %u entries", entries);
	p += CO_CFG_CDCF_HDR_SIZE;
	for (uint32_t e = 0; e < entries; e++) {
		uint16_t index = (uint16_t)co_od_le_get(p, 2);
		uint8_t sub = p[2];
		uint32_t size = (uint32_t)co_od_le_get(p + 3, 4);
		uint8_t buf[8];
		size_t len = 0;
		uint32_t ab;

		zassert_true(size <= sizeof(buf));
		co_node_lock(n);
		ab = co_od_read(co_node_od(n), index, sub, 0, buf, sizeof(buf), &len,
				CO_OD_WRITER_APP);
		co_node_unlock(n);
		zassert_equal(ab, 0U, "node %u %04X:%02X abort %08X", id, index, sub, ab);
		zassert_equal(len, size, "node %u %04X:%02X", id, index, sub);
		zassert_mem_equal(buf, p + CO_CFG_CDCF_ENTRY_HDR, size, "node %u %04X:%02X", id,
				  index, sub);
		p += CO_CFG_CDCF_ENTRY_HDR + size;
	}
}

ZTEST(mgr_net, test_boot_126_slaves)
{
	uint64_t done_us, op_us = 0, last_boot_us = 0;
	unsigned int op = 0;
	int64_t end;

	/* The manager's start runs the NMT startup (1F80h = 01h) by itself. */
	start_us = co_line_time(&lines[0]);
	zassert_ok(co_node_start(&mgr));
	zassert_ok(k_sem_take(&startup_sem, K_SECONDS(STARTUP_WAIT_S)), "no end of the startup");
	done_us = co_line_time(&lines[0]);

	/* Copies under the manager's lock; a failing assertion must not leave it locked. */
	co_node_lock(&mgr);
	snap = seen;
	co_node_unlock(&mgr);
	zassert_equal(snap.startup_calls, 1);
	zassert_equal(snap.startup, CO_MGR_STARTUP_DONE, "startup %d, node %u status %c",
		      snap.startup, snap.halt_err.node_id, snap.halt_err.status);
	zassert_equal(co_mgr_get_startup(&mgr), CO_MGR_STARTUP_DONE);
	zassert_equal(snap.boot_errors, 0U);
	zassert_equal(od_u32(&mgr, 0x1F80, 0), IS_ENABLED(MGR_NET_START_ALL) ? 0x03U : 0x01U);

	/* The individual starts leave the NMT queue after the startup indication. */
	end = k_uptime_get() + STATE_WAIT_MS;
	while ((op = count_operational()) < N_SLAVES && k_uptime_get() < end) {
		k_sleep(K_MSEC(5));
	}
	op_us = co_line_time(&lines[0]);
	zassert_equal(op, N_SLAVES, "%u of %u slaves OPERATIONAL", op, N_SLAVES);
	co_node_lock(&mgr);
	snap = seen;
	co_node_unlock(&mgr);

	for (uint8_t id = FIRST_SLAVE; id < FIRST_SLAVE + N_SLAVES; id++) {
		struct co_node *n = &slave_of(id)->node;
		struct co_mgr_boot_info b;

		zassert_ok(co_mgr_get_boot(&mgr, id, &b));
		zassert_equal(snap.boot_calls[id], 1U, "node %u: %u boot indications", id,
			      snap.boot_calls[id]);
		zassert_equal(snap.boot_status[id], CO_MGR_ST_OK);
		zassert_true(b.assigned);
		zassert_equal(b.status, CO_MGR_ST_OK, "node %u: %c", id, b.status);
		zassert_equal(b.attempts, 1U, "node %u: %u attempts", id, b.attempts);

		/* Full identity check: every expectation set, every object read, as the slave has
		 * it. */
		zassert_equal(b.read_mask, 0x1FU, "node %u read %02X", id, b.read_mask);
		zassert_equal(b.device_type, od_u32(n, 0x1000, 0));
		zassert_equal(od_u32(&mgr, 0x1F84, id), b.device_type);
		for (uint8_t k = 0; k < 4; k++) {
			uint32_t expect = od_u32(&mgr, 0x1F85 + k, id);

			zassert_equal(b.identity[k], od_u32(n, 0x1018, k + 1), "node %u 1018:%u",
				      id, k + 1);
			zassert_not_equal(expect, 0U, "1F%02Xh:%u checks nothing", 0x85 + k, id);
		}
		/* 1F87h: same major, minor at least the expected one (CiA 302-2 §6.9). */
		zassert_equal(b.identity[2] >> 16, od_u32(&mgr, 0x1F87, id) >> 16);
		zassert_true((b.identity[2] & 0xffffU) >= (od_u32(&mgr, 0x1F87, id) & 0xffffU));

		check_configured(id);
		last_boot_us = MAX(last_boot_us, b.finished_us);
	}

	/* The manager's view, from the heartbeats the concise DCF turned on. */
	end = k_uptime_get() + STATE_WAIT_MS;
	for (uint8_t id = FIRST_SLAVE; id < FIRST_SLAVE + N_SLAVES; id++) {
		struct co_mgr_boot_info b;

		do {
			zassert_ok(co_mgr_get_boot(&mgr, id, &b));
			if (b.nmt_state != CO_NMT_OPERATIONAL) {
				k_sleep(K_MSEC(5));
			}
		} while (b.nmt_state != CO_NMT_OPERATIONAL && k_uptime_get() < end);
		zassert_equal(b.nmt_state, CO_NMT_OPERATIONAL, "manager sees node %u in %02X", id,
			      b.nmt_state);
	}
	zassert_equal(co_nmt_get_state(&mgr), CO_NMT_OPERATIONAL);

	printk("mgr_net: %u slaves on %d lines: last boot %llu ms, startup DONE %llu ms, all "
	       "OPERATIONAL by %llu ms\n",
	       N_SLAVES, N_LINES - 1, (unsigned long long)(last_boot_us - start_us) / 1000U,
	       (unsigned long long)(done_us - start_us) / 1000U,
	       (unsigned long long)(op_us - start_us) / 1000U);
}
