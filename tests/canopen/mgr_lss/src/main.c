/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The manager assigns node-IDs by LSS (doc/mgr.md, "Node-IDs by LSS"), on a simulation
 * line: the manager (node 1) and three SafeLine slaves without node-ID (serial numbers
 * 1001h, 1002h, 1003h), each with an LSS storage medium. 1F81h assigns nodes 2..5:
 *
 *   node 2: serial 1003h                          -> found, node-ID 2, stored, booted
 *   node 3: serial 1001h                          -> found, node-ID 3, stored, booted
 *   node 4: serial 9999h (no such device)         -> not found (-ENODEV)
 *   node 5: serial 1002h, revision 2.0 expected   -> the device has 1.5: -EILSEQ, no node-ID
 *
 * With CONFIG_CANOPEN_MGR_LSS_ASSIGN=n the same network stays as it is: no LSS frame.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/lss.h>
#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "co_bus.h"

#include "mgr_master_od.h"
#include "mgr_slave_od.h"

#define MASTER   1U
#define N_SLAVES 3
#define MS       1000ULL
#define VENDOR   0x00000539U
#define PRODUCT  0x00000042U
#define REVISION 0x00010005U

static const uint32_t serials[N_SLAVES] = {0x1001, 0x1002, 0x1003};

static struct {
	struct co_line line;
	uint32_t n_lss_req;
	struct co_node master;
	struct mgr_master_od_ram mram;
	struct co_node slave[N_SLAVES];
	struct mgr_slave_od_ram sram[N_SLAVES];
	struct co_storage_ram medium[N_SLAVES];
	uint8_t mem[N_SLAVES][64];
	/* LSS results per node-ID: err + 1 (0: none), serial found. */
	int lss_err[8];
	uint32_t lss_serial[8];
	int n_lss_ind;
} t;

/* Counts the LSS requests the line sends. */
static void tap(const struct can_frame *f, int from)
{
	ARG_UNUSED(from);
	if (f->id == CO_LSS_MASTER_COB_ID) {
		t.n_lss_req++;
	}
}

static void put(struct co_od *od, uint16_t index, uint8_t sub, uint32_t value)
{
	uint8_t buf[4];

	sys_put_le32(value, buf);
	zassert_equal(co_od_write(od, index, sub, buf, 4, CO_OD_WRITER_APP), 0U, "%04x:%02x", index,
		      sub);
}

/* The configuration survives every reset, as a stored one would. */
static void master_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	put(od, 0x1F80, 0, 0x01);
	for (uint8_t id = 2; id <= 5; id++) {
		put(od, 0x1F81, id, 0x05); /* slave, may boot; optional */
		put(od, 0x1F85, id, VENDOR);
		put(od, 0x1F86, id, PRODUCT);
		put(od, 0x1F87, id, REVISION);
	}
	put(od, 0x1F88, 2, 0x1003);
	put(od, 0x1F88, 3, 0x1001);
	put(od, 0x1F88, 4, 0x9999);
	put(od, 0x1F88, 5, 0x1002);
	put(od, 0x1F87, 5, 0x00020000);
}

static void slave_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	put(od, 0x1018, 4, serials[(int)(intptr_t)user_data]);
}

#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
static void lss_ind(struct co_node *node, uint8_t id, int err, const struct co_lss_address *addr,
		    void *user_data)
{
	zassert_true(id >= 2 && id <= 5);
	zassert_equal(t.lss_err[id], 0, "node %u searched once", id);
	t.lss_err[id] = err + 1;
	t.lss_serial[id] = addr != NULL ? addr->part[3] : 0U;
	t.n_lss_ind++;
}
#endif

static void before(void *unused)
{
	memset(&t, 0, sizeof(t));
	co_bus_init();
	co_bus_attach(0, &t.line, "sim");
	bus.tap = tap;
	bus.no_log = true;
	zassert_ok(co_node_init(&t.master, "master", &t.line, &mgr_master_od_def, &t.mram, MASTER));
	co_od_set_restore_cb(co_node_od(&t.master), master_restore, NULL);
#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
	co_mgr_set_lss_ind(&t.master, lss_ind, NULL);
#endif
	for (int i = 0; i < N_SLAVES; i++) {
		zassert_ok(co_node_init(&t.slave[i], "slave", &t.line, &mgr_slave_od_def,
					&t.sram[i], CO_NODE_ID_UNCONFIGURED));
		co_od_set_restore_cb(co_node_od(&t.slave[i]), slave_restore, (void *)(intptr_t)i);
		zassert_ok(co_storage_ram_init(&t.medium[i], t.mem[i], sizeof(t.mem[i])));
		zassert_equal(co_lss_store_attach(&t.slave[i], &t.medium[i].be, NULL), -ENOENT);
		zassert_ok(co_node_start(&t.slave[i]));
	}
	zassert_ok(co_node_start(&t.master));
}

ZTEST_SUITE(co_mgr_lss, NULL, NULL, before, NULL, NULL);

static uint8_t stored_node_id(int i)
{
	struct co_lss_config cfg;

	zassert_ok(co_lss_store_attach(&t.slave[i], &t.medium[i].be, &cfg));
	return cfg.node_id;
}

ZTEST(co_mgr_lss, test_missing_slaves_are_found_given_their_id_and_booted)
{
	struct co_mgr_boot_info info;

	if (!IS_ENABLED(CONFIG_CANOPEN_MGR_LSS_ASSIGN)) {
		ztest_test_skip();
	}
	co_bus_run_until(15000 * MS);
	zassert_equal(t.n_lss_ind, 4, "every missing slave searched, once");
	zassert_equal(t.lss_err[2], 0 + 1);
	zassert_equal(t.lss_serial[2], 0x1003);
	zassert_equal(t.lss_err[3], 0 + 1);
	zassert_equal(t.lss_serial[3], 0x1001);
	zassert_equal(t.lss_err[4], -ENODEV + 1, "no device with serial 9999h");
	zassert_equal(t.lss_err[5], -EILSEQ + 1, "revision 1.5 where 2.0 is expected");
	zassert_equal(t.lss_serial[5], 0x1002);

	zassert_equal(co_node_id(&t.slave[2]), 2, "serial 1003h is node 2");
	zassert_equal(co_node_id(&t.slave[0]), 3, "serial 1001h is node 3");
	zassert_equal(co_node_id(&t.slave[1]), CO_NODE_ID_UNCONFIGURED, "the wrong revision");
	zassert_equal(stored_node_id(2), 2, "stored");
	zassert_equal(stored_node_id(0), 3, "stored");

	zassert_ok(co_mgr_get_boot(&t.master, 2, &info));
	zassert_equal(info.status, CO_MGR_ST_OK, "node 2 booted by the manager");
	zassert_ok(co_mgr_get_boot(&t.master, 3, &info));
	zassert_equal(info.status, CO_MGR_ST_OK, "node 3 booted by the manager");
	zassert_ok(co_mgr_get_boot(&t.master, 4, &info));
	zassert_equal(info.status, CO_MGR_ST_B, "never found: still missing");
	zassert_equal(co_node_nmt_state(&t.slave[2]), CO_NMT_OPERATIONAL);
	zassert_equal(co_node_nmt_state(&t.slave[0]), CO_NMT_OPERATIONAL);

#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
	/* Searched once per reset: later B results send nothing. */
	uint32_t n = t.n_lss_req;

	co_bus_run_until(bus.now + 5000 * MS);
	zassert_equal(t.n_lss_req, n);
	zassert_equal(co_mgr_lss_search(&t.master, 6), -EINVAL, "not assigned");
	zassert_equal(co_mgr_lss_search(&t.master, 0), -EINVAL);
	t.lss_err[4] = 0;
	zassert_ok(co_mgr_lss_search(&t.master, 4), "asked again by the application");
	co_bus_run_until(bus.now + 5000 * MS);
	zassert_true(t.n_lss_req > n);
	zassert_equal(t.n_lss_ind, 5);
#endif
}

ZTEST(co_mgr_lss, test_turned_off_sends_no_lss)
{
	if (IS_ENABLED(CONFIG_CANOPEN_MGR_LSS_ASSIGN)) {
		ztest_test_skip();
	}
	co_bus_run_until(15000 * MS);
	zassert_equal(t.n_lss_req, 0);
	for (int i = 0; i < N_SLAVES; i++) {
		zassert_equal(co_node_id(&t.slave[i]), CO_NODE_ID_UNCONFIGURED);
	}
}
