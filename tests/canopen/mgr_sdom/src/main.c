/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SDO manager (CiA 302 §7) on simulated time: a manager (node 01h), an SDO requesting
 * device (SRD, node 7Eh), a slave with one free server SDO 1201h (0Ah) and a slave with only
 * its default SDO (0Bh). Every node sits on its own simulation line; the test is the bus and
 * hands each frame to every other live node. The SRD talks to the manager and to the slaves
 * with its own SDO clients over the COB-IDs the manager handed out.
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/mgr.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>
#include <canopen/sdo_cli.h>
#include <canopen/sdom.h>

#include "line_internal.h"

#include "co_bus.h"

#include "sdom_mgr_od.h"
#include "sdom_plain_od.h"
#include "sdom_slave_od.h"
#include "sdom_srd_od.h"

#define MS       1000ULL
#define MAX_NODE 5
#define MAX_CFG  16
#define INJECTED CO_BUS_INJECTED

#define MGR   0
#define SRD   1
#define SLV   2
#define PLAIN 3

#define ID_MGR   0x01U
#define ID_SRD   0x7EU
#define ID_SLV   0x0AU
#define ID_PLAIN 0x0BU
#define POOL0    0x6C0U

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
		struct sdom_mgr_od_ram m;
		struct sdom_srd_od_ram r;
		struct sdom_slave_od_ram s;
		struct sdom_plain_od_ram p;
	} ram;
	struct cfg_entry cfg[MAX_CFG];
	int n_cfg;
	char name[8];
};

static struct {
	struct nd n[MAX_NODE];
	uint32_t su;      /* the manager's 1F80h, 01h when 0 */
	uint32_t boot_ms; /* what network() lets run after the start, 2000 ms when 0 */
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

static void node_add(int i, uint8_t id, const struct co_od_def *def)
{
	struct nd *d = &t.n[i];

	snprintf(d->name, sizeof(d->name), "n%02x", id);
	co_bus_attach(i, &d->line, d->name);
	zassert_ok(co_node_init(&d->node, d->name, &d->line, def, &d->ram, id));
	co_od_set_restore_cb(co_node_od(&d->node), restore, d);
}

static uint32_t od_u(int i, uint16_t index, uint8_t sub)
{
	uint32_t v;

	co_node_lock(&t.n[i].node);
	v = co_od_uint(co_node_od(&t.n[i].node), index, sub, 0);
	co_node_unlock(&t.n[i].node);
	return v;
}

static uint32_t od_w(int i, uint16_t index, uint8_t sub, uint32_t v, enum co_od_writer who)
{
	uint8_t b[4];
	uint32_t ab;

	sys_put_le32(v, b);
	co_node_lock(&t.n[i].node);
	ab = co_od_write(co_node_od(&t.n[i].node), index, sub, b, 4, who);
	co_node_unlock(&t.n[i].node);
	co_bus_settle();
	return ab;
}

static void od_w16(int i, uint16_t index, uint8_t sub, uint16_t v)
{
	uint8_t b[2];

	sys_put_le16(v, b);
	co_node_lock(&t.n[i].node);
	zassert_equal(co_od_write(co_node_od(&t.n[i].node), index, sub, b, 2, CO_OD_WRITER_APP),
		      0U);
	co_node_unlock(&t.n[i].node);
	co_bus_settle();
}

/* Manager with a pool of @p pool COB-IDs from 6C0h; all four nodes started and settled. */
static void network(int pool)
{
	node_add(MGR, ID_MGR, &sdom_mgr_od_def);
	node_add(SRD, ID_SRD, &sdom_srd_od_def);
	node_add(SLV, ID_SLV, &sdom_slave_od_def);
	node_add(PLAIN, ID_PLAIN, &sdom_plain_od_def);
	cfg(MGR, 0x1F80, 0, t.su != 0U ? t.su : 0x01U, 4);
	for (int k = 0; k < pool; k++) {
		cfg(MGR, 0x1F02, (uint8_t)(k + 1), POOL0 + (uint32_t)k, 4);
	}
	for (int i = 0; i < MAX_NODE; i++) {
		if (bus.port[i].used) {
			zassert_ok(co_node_start(&t.n[i].node));
		}
	}
	/* The manager's startup resets the others (Reset Communication); let it end. */
	co_bus_run_ms(t.boot_ms != 0U ? t.boot_ms : 2000U);
}

/* --- The SRD's SDO client ------------------------------------------------------------------- */

static struct {
	bool done;
	uint32_t ab;
	size_t size;
	uint8_t buf[8];
} sdo;

static void sdo_con(struct co_sdo_cli *cli, uint32_t ab, size_t size, void *user_data)
{
	ARG_UNUSED(cli);
	ARG_UNUSED(user_data);
	sdo.done = true;
	sdo.ab = ab;
	sdo.size = size;
}

/* Download @p v to @p index:@p sub over the SRD's client @p num; the abort code. */
static uint32_t srd_download(uint8_t num, uint16_t index, uint8_t sub, uint32_t v)
{
	struct co_node *n = &t.n[SRD].node;
	int err;

	memset(&sdo, 0, sizeof(sdo));
	sys_put_le32(v, sdo.buf);
	co_node_lock(n);
	err = co_sdo_cli_download_req(co_sdo_cli_get(n, num), index, sub, sdo.buf, 4,
				      CO_SDO_CLI_AUTO, 100, sdo_con, NULL);
	co_node_unlock(n);
	zassert_ok(err);
	co_bus_run_ms(300);
	zassert_true(sdo.done);
	return sdo.ab;
}

static uint32_t upload_on(int i, uint8_t num, uint16_t index, uint8_t sub, uint32_t *v)
{
	struct co_node *n = &t.n[i].node;
	int err;

	memset(&sdo, 0, sizeof(sdo));
	co_node_lock(n);
	err = co_sdo_cli_upload_req(co_sdo_cli_get(n, num), index, sub, sdo.buf, sizeof(sdo.buf),
				    CO_SDO_CLI_AUTO, 100, sdo_con, NULL);
	co_node_unlock(n);
	zassert_ok(err);
	co_bus_run_ms(300);
	zassert_true(sdo.done);
	*v = sys_get_le32(sdo.buf);
	return sdo.ab;
}

static uint32_t srd_upload(uint8_t num, uint16_t index, uint8_t sub, uint32_t *v)
{
	return upload_on(SRD, num, index, sub, v);
}

/* Whether a frame with CAN-ID @p id was on the bus since @p since. */
static bool seen(uint32_t id, uint64_t since)
{
	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == id) {
			return true;
		}
	}
	return false;
}

/* Whether an SDO download was started on CAN-ID @p id since @p since (CiA 301 ccs 1). */
static bool seen_download(uint32_t id, uint64_t since)
{
	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == id &&
		    (bus.log[i].f.data[0] & 0xE0U) == 0x20U) {
			return true;
		}
	}
	return false;
}

/* The SRD registers with client entry 1280h (1F10h = 12800001h, then 6E0#). */
static void srd_register(uint32_t req)
{
	zassert_equal(od_w(SRD, 0x1F10, 0, req, CO_OD_WRITER_APP), 0U);
	inject(0x6E0, 0, 0, 0);
	/* Node-ID 7Fh is absent (scan timeout), 7Eh answers. */
	co_bus_run_ms(1000);
}

/* Connection @p k: 1F03h:01..03, then 1F04h:01..03 (the manager dictionary's sizes). */
static uint32_t conn(uint8_t k)
{
	return k <= 3U ? od_u(MGR, 0x1F03, k) : od_u(MGR, 0x1F04, (uint8_t)(k - 3U));
}

/* Let node @p i reset its communication (it sends its boot-up). */
static void node_reset(int i)
{
	co_node_lock(&t.n[i].node);
	zassert_ok(co_nmt_req(&t.n[i].node, CO_NMT_CS_RESET_COMMUNICATION));
	co_node_unlock(&t.n[i].node);
	co_bus_settle();
}

/* Frames with CAN-ID @p id since @p since. */
static int count(uint32_t id, uint64_t since)
{
	int n = 0;

	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == id) {
			n++;
		}
	}
	return n;
}

#define REQ(idx, srd, s) (((uint32_t)(idx) << 16) | ((uint32_t)(srd) << 8) | (s))

static void before(void *unused)
{
	ARG_UNUSED(unused);
	memset(&t, 0, sizeof(t));
	co_bus_init();
}

/* SAFELINE_SDOM_TRACE=1 prints every frame of each test (reading a failure). */
static void after(void *unused)
{
	const char *e = getenv("SAFELINE_SDOM_TRACE");

	ARG_UNUSED(unused);
	if (e != NULL && e[0] == '1') {
		for (int i = 0; i < bus.n_log; i++) {
			const struct can_frame *f = &bus.log[i].f;

			printf("%10llu %3x [%u] %02x %02x %02x %02x %02x %02x %02x %02x\n",
			       (unsigned long long)bus.log[i].at, f->id, f->dlc, f->data[0],
			       f->data[1], f->data[2], f->data[3], f->data[4], f->data[5],
			       f->data[6], f->data[7]);
		}
	}
}

/* --- Tests ------------------------------------------------------------------------------------ */

/* 302 §7.2.1: scan from 7Fh down, pair from 1F02h, SRD's 1280h, our 1201h, 1F03h, 1F10h. */
ZTEST(co_mgr_sdom, test_registration)
{
	uint32_t v;
	uint64_t t0;

	network(6);
	t0 = bus.now;
	srd_register(0x12800001U);
	zassert_true(seen(0x600U + 0x7FU, t0), "7Fh scanned first");
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U, "Rq 0, state 1, index 1280h");
	zassert_equal(od_u(SRD, 0x1280, 1), POOL0);
	zassert_equal(od_u(SRD, 0x1280, 2), POOL0 + 1U);
	zassert_equal(od_u(SRD, 0x1280, 3), ID_MGR);
	zassert_equal(od_u(MGR, 0x1201, 1), POOL0);
	zassert_equal(od_u(MGR, 0x1201, 2), POOL0 + 1U);
	zassert_equal(od_u(MGR, 0x1201, 3), ID_SRD);
	zassert_equal(od_u(MGR, 0x1F02, 1), POOL0 | BIT(30));
	zassert_equal(od_u(MGR, 0x1F02, 2), (POOL0 + 1U) | BIT(30));
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U);
	zassert_equal(conn(1), ((uint32_t)ID_SRD << 16) | (1U << 8) | ID_MGR, "offsets 0 and 1");
	/* The channel works: the SRD reads the manager's pool through 6C0h/6C1h. */
	t0 = bus.now;
	zassert_equal(srd_upload(0, 0x1F02, 3, &v), 0U);
	zassert_equal(v, POOL0 + 2U);
	zassert_true(seen(POOL0, t0) && seen(POOL0 + 1U, t0));
}

ZTEST(co_mgr_sdom, test_registration_all_default_sdos)
{
	network(6);
	srd_register(0x00000003U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000004U, "state 2");
	zassert_equal(od_u(MGR, 0x1F02, 1), POOL0, "nothing allocated");
	zassert_equal(conn(1), 0U);
}

ZTEST(co_mgr_sdom, test_registration_pool_empty)
{
	network(1);
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000100U, "state 0, error 01h");
	zassert_equal(conn(1), 0U);
}

/* The slave's default SDO is free: only the table and the SRD's client entry change. */
ZTEST(co_mgr_sdom, test_connection_default_sdo)
{
	uint32_t v;
	uint64_t t0;

	network(6);
	srd_register(0x12800001U);
	t0 = bus.now;
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12810006U, "state 3, index 1281h");
	zassert_equal(od_u(SRD, 0x1281, 1), 0x600U + ID_SLV);
	zassert_equal(od_u(SRD, 0x1281, 2), 0x580U + ID_SLV);
	zassert_equal(od_u(SRD, 0x1281, 3), ID_SLV);
	zassert_equal(conn(2), ((uint32_t)1 << 24) | ((uint32_t)ID_SRD << 16) | ID_SLV);
	zassert_equal(od_u(SLV, 0x1201, 1), 0x80000000U, "nothing written to S");
	zassert_true(seen(0x600U + ID_SLV, t0), "the manager checks that S answers");
	zassert_false(seen_download(0x600U + ID_SLV, t0), "but writes nothing to S");
	zassert_equal(srd_upload(1, 0x2000, 0, &v), 0U);
	zassert_equal(v, 0x12345678U);
}

/* The default SDO is taken: a free server entry on S, COB-IDs from the pool. */
ZTEST(co_mgr_sdom, test_connection_dynamic)
{
	uint32_t v;
	uint64_t t0;

	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12820006U);
	zassert_equal(od_u(SLV, 0x1201, 1), POOL0 + 2U);
	zassert_equal(od_u(SLV, 0x1201, 2), POOL0 + 3U);
	zassert_equal(od_u(SLV, 0x1201, 3), ID_SRD);
	zassert_equal(od_u(SRD, 0x1282, 1), POOL0 + 2U);
	zassert_equal(od_u(SRD, 0x1282, 2), POOL0 + 3U);
	zassert_equal(od_u(SRD, 0x1282, 3), ID_SLV);
	zassert_equal(od_u(MGR, 0x1F02, 3), (POOL0 + 2U) | BIT(30));
	zassert_equal(conn(3), ((uint32_t)2 << 24) | ((uint32_t)ID_SRD << 16) | (1U << 8) | ID_SLV);
	/* The SRD really talks to S through 6C2h/6C3h. */
	t0 = bus.now;
	zassert_equal(srd_download(2, 0x2000, 0, 0xCAFEF00DU), 0U);
	zassert_equal(od_u(SLV, 0x2000, 0), 0xCAFEF00DU);
	zassert_true(seen(POOL0 + 2U, t0) && seen(POOL0 + 3U, t0));
	zassert_false(seen(0x600U + ID_SLV, t0));
	zassert_equal(srd_upload(2, 0x2000, 0, &v), 0U);
	zassert_equal(v, 0xCAFEF00DU);
}

ZTEST(co_mgr_sdom, test_pool_exhausted)
{
	network(4);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1283, ID_SRD, ID_SLV)),
		      CO_SDO_AB_NO_RESOURCE);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000200U, "state 0, error 02h");
}

ZTEST(co_mgr_sdom, test_no_free_server_entry)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_PLAIN)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_PLAIN)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000300U, "state 0, error 03h");
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U, "pair not taken");
	zassert_equal(conn(3), 0U);
}

/* S must answer on its default SDO before the SRD gets it (error 04h otherwise). */
ZTEST(co_mgr_sdom, test_slave_absent)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, 0x20)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000400U, "state 0, error 04h");
	zassert_equal(conn(2), 0U);
	zassert_equal(od_u(SRD, 0x1281, 1), 0x80000000U, "the SRD's entry untouched");
}

/* A refused write while setting up (the SRD has no 1283h) undoes what was done. */
ZTEST(co_mgr_sdom, test_refused_write_undone)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1283, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000000U, "state 0, error 00h");
	zassert_equal(conn(2), 0U);
	/* The same over a dynamic entry: S's entry and the pool pair are given back. */
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12810006U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1283, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000000U);
	zassert_equal(conn(3), 0U);
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U);
	zassert_equal(od_u(MGR, 0x1F02, 4), POOL0 + 3U);
	/* Still registered, and the pair serves the next request. */
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12820006U);
	zassert_equal(od_u(SLV, 0x1201, 1), POOL0 + 2U);
}

ZTEST(co_mgr_sdom, test_release_one_and_all_to_slave)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(conn(3), 0U);
	zassert_not_equal(conn(2), 0U, "the other connection stays");
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SRD, 0x1282, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U, "bit 30 cleared");
	zassert_equal(od_u(MGR, 0x1F02, 4), POOL0 + 3U);
	/* Index 0: every connection to S. */
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0, ID_SRD, ID_SLV)), 0U);
	zassert_equal(conn(2), 0U);
	zassert_equal(conn(3), 0U);
	zassert_equal(od_u(SRD, 0x1281, 1) & BIT(31), BIT(31));
	zassert_not_equal(conn(1), 0U, "still registered");
}

ZTEST(co_mgr_sdom, test_deregistration)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	/* Slave 0: all released, the SRD's own channel last (the write is confirmed first). */
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0, ID_SRD, 0)), 0U);
	for (uint8_t i = 1; i <= 6; i++) {
		zassert_equal(conn(i), 0U, "1F03h:%u", i);
		zassert_equal(od_u(MGR, 0x1F02, i), POOL0 + i - 1U, "1F02h:%u", i);
	}
	zassert_equal(od_u(MGR, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SRD, 0x1280, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31));
	/* No longer registered: a request is refused. */
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE);
	/* It may register again. */
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U);
}

ZTEST(co_mgr_sdom, test_wrong_values_refused)
{
	network(6);
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE, "SRD not registered");
	zassert_equal(od_w(MGR, 0x1F01, 0, REQ(0, ID_SRD, 0), CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "release by an unknown SRD");
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, 0)), CO_SDO_AB_NO_RESOURCE,
		      "slave 0");
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000400U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1000, ID_SRD, ID_SLV)),
		      CO_SDO_AB_NO_RESOURCE, "not a client entry");
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000100U);
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1000, ID_SRD, ID_SLV)),
		      CO_SDO_AB_INVALID_VALUE);
	zassert_equal(srd_download(0, 0x1F03, 1, 0), CO_SDO_AB_READONLY);
	zassert_equal(srd_download(0, 0x1F02, 5, 0x6D0), CO_SDO_AB_DATA_DEV_STATE,
		      "pool rewritten while connections are open");
	/* Not the manager (1F80h bit 0 clear): no connections handed out. */
	zassert_equal(od_w(MGR, 0x1F80, 0, 0, CO_OD_WRITER_APP), 0U);
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(od_w(MGR, 0x1F01, 0, REQ(0, ID_SRD, 0), CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
}

/* While a request runs, four more wait; the next one is refused. */
ZTEST(co_mgr_sdom, test_queue_full)
{
	network(6);
	srd_register(0x12800001U);
	/* The first one waits for the absent node 20h to answer (SDO timeout). */
	for (int k = 0; k < 5; k++) {
		zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, 0x20), CO_OD_WRITER_SDO), 0U,
			      "request %d", k);
	}
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, 0x20), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE);
	zassert_equal(od_w(MGR, 0x1F01, 0, REQ(0, ID_SRD, 0x20), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE);
	/* All five end (error 04h each); the queue takes requests again. */
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000400U);
	zassert_equal(od_w(MGR, 0x1F01, 0, REQ(0, ID_SRD, 0x20), CO_OD_WRITER_SDO), 0U);
}

/* The SRD's helpers (include/canopen/sdom.h): register, status, request, release. */
ZTEST(co_mgr_sdom, test_srd_helpers)
{
	struct co_sdom_srd srd;
	struct co_sdom_status st;
	struct co_node *n;
	uint32_t v;
	uint64_t t0;

	network(6);
	n = &t.n[SRD].node;
	co_node_lock(n);
	zassert_equal(co_sdom_srd_register(&srd, n, 0x1000), -EINVAL);
	zassert_ok(co_sdom_srd_register(&srd, n, 0x1280));
	zassert_ok(co_sdom_srd_status(&srd, &st));
	co_node_unlock(n);
	zassert_true(st.pending);
	t0 = bus.now;
	co_bus_settle();
	zassert_true(seen(0x6E0U, t0), "the SRD sent 6E0h");
	co_bus_run_ms(1000);
	co_node_lock(n);
	zassert_ok(co_sdom_srd_status(&srd, &st));
	zassert_false(st.pending);
	zassert_equal(st.state, CO_SDOM_REGISTERED);
	zassert_equal(st.index, 0x1280);
	zassert_equal(co_sdom_srd_request(&srd, 0x1281, 0, sdo_con, NULL), -EINVAL);
	memset(&sdo, 0, sizeof(sdo));
	zassert_ok(co_sdom_srd_request(&srd, 0x1281, ID_SLV, sdo_con, NULL));
	co_node_unlock(n);
	co_bus_run_ms(300);
	zassert_true(sdo.done);
	zassert_equal(sdo.ab, 0U);
	co_node_lock(n);
	zassert_ok(co_sdom_srd_status(&srd, &st));
	co_node_unlock(n);
	zassert_equal(st.state, CO_SDOM_CONNECTED);
	zassert_equal(st.index, 0x1281);
	zassert_equal(srd_upload(1, 0x2000, 0, &v), 0U);
	zassert_equal(v, 0x12345678U);
	co_node_lock(n);
	memset(&sdo, 0, sizeof(sdo));
	zassert_ok(co_sdom_srd_release(&srd, 0, 0, sdo_con, NULL));
	co_node_unlock(n);
	co_bus_run_ms(300);
	zassert_equal(sdo.ab, 0U);
	zassert_equal(conn(1), 0U);
	zassert_equal(conn(2), 0U);
	zassert_equal(od_u(SRD, 0x1281, 1) & BIT(31), BIT(31));
}

/* SDO download requests (ccs 1) on CAN-ID @p id since @p since. */
static int count_downloads(uint32_t id, uint64_t since)
{
	int n = 0;

	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == id &&
		    (bus.log[i].f.data[0] & 0xE0U) == 0x20U) {
			n++;
		}
	}
	return n;
}

/* --- Error control (302 §7.2.1 step 5, §7.2.2) ------------------------------------------------ */

#define SRD2       4
#define ID_SRD2    0x7DU
#define HB(id, ms) (((uint32_t)(id) << 16) | (ms))

/* The manager consumes the SRD's heartbeat (250 ms); the SRD produces it every 100 ms. */
static void srd_heartbeat(void)
{
	cfg(MGR, 0x1016, 1, HB(ID_SRD, 250U), 4);
	cfg(SRD, 0x1017, 0, 100U, 2);
}

/* The SRD's heartbeat stops (it still answers SDO): all it held is released, de-registered. */
ZTEST(co_mgr_sdom, test_srd_heartbeat_lost_releases)
{
	srd_heartbeat();
	network(6);
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U, "Req EC not asked, not set");
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	co_bus_run_ms(1000);
	zassert_not_equal(conn(3), 0U, "kept while the heartbeat runs");
	od_w16(SRD, 0x1017, 0, 0U);
	co_bus_run_ms(1000);
	for (uint8_t k = 1U; k <= 6U; k++) {
		zassert_equal(conn(k), 0U, "connection %u", k);
		zassert_equal(od_u(MGR, 0x1F02, k), POOL0 + k - 1U, "1F02h:%u", k);
	}
	zassert_equal(od_u(SRD, 0x1280, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SRD, 0x1281, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SRD, 0x1282, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(MGR, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE, "de-registered");
	/* Not registered any more: the scan finds it again. */
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U);
}

/* "All default SDOs" is given back by stopping the error control, which de-registers. */
ZTEST(co_mgr_sdom, test_all_default_sdos_given_back_by_heartbeat)
{
	srd_heartbeat();
	network(6);
	srd_register(0x00000003U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000004U);
	co_bus_run_ms(1000);
	/* Still registered: a new 6E0h scan skips it, 1F10h keeps the request. */
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800001U, "still holds the default SDOs");
	od_w16(SRD, 0x1017, 0, 0U);
	co_bus_run_ms(1000);
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U, "de-registered, registers anew");
}

/* No 1016h entry for the SRD: node guarding with 1F81h's guard time and retry factor. */
ZTEST(co_mgr_sdom, test_srd_guarded_without_heartbeat)
{
	uint64_t t0;
	int rtr = 0;

	/* Guard time 100 ms, retry factor 3; bit 0 clear: no NMT slave of ours. */
	cfg(MGR, 0x1F81, ID_SRD, (100U << 16) | (3U << 8), 4);
	network(6);
	t0 = bus.now;
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U);
	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= t0 && bus.log[i].f.id == 0x700U + ID_SRD &&
		    (bus.log[i].f.flags & CAN_FRAME_RTR) != 0U) {
			rtr++;
		}
	}
	zassert_true(rtr >= 8, "RTRs every 100 ms (%d)", rtr);
	zassert_not_equal(conn(1), 0U, "its answers keep it");
	bus.port[SRD].alive = false;
	co_bus_run_ms(1000);
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE, "de-registered");
	zassert_equal(od_u(MGR, 0x1201, 1) & BIT(31), BIT(31), "our entry released");
}

/*
 * The SRD dies: its client entries cannot be written (one try, then no more within the
 * release), the slaves' entries are; the table entries and pool pairs stay as stale until the
 * SRD's boot-up shows its entries are back to their defaults.
 */
ZTEST(co_mgr_sdom, test_srd_dead_entries_stale_until_bootup)
{
	uint64_t t0;

	srd_heartbeat();
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	bus.port[SRD].alive = false;
	t0 = bus.now;
	co_bus_run_ms(2000);
	zassert_equal(count_downloads(0x600U + ID_SRD, t0), 1, "the dead SRD is asked once");
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31), "the slave's entry released");
	zassert_equal(od_u(MGR, 0x1201, 1) & BIT(31), BIT(31), "our own entry released");
	for (uint8_t k = 1U; k <= 3U; k++) {
		zassert_not_equal(conn(k), 0U, "connection %u kept as stale", k);
	}
	for (uint8_t k = 1U; k <= 4U; k++) {
		zassert_equal(od_u(MGR, 0x1F02, k) & BIT(30), BIT(30), "1F02h:%u still in use", k);
	}
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_RESOURCE, "de-registered");
	/* It comes back with a reset: its entries are the defaults again, the stale ones go. */
	bus.port[SRD].alive = true;
	node_reset(SRD);
	co_bus_run_ms(10);
	for (uint8_t k = 1U; k <= 6U; k++) {
		zassert_equal(conn(k), 0U, "connection %u", k);
		zassert_equal(od_u(MGR, 0x1F02, k), POOL0 + k - 1U, "1F02h:%u", k);
	}
}

/* Req EC (1F10h = iiii0009h): a failed slave is reported in 1F11h, its client entries cleared. */
ZTEST(co_mgr_sdom, test_req_ec_slave_failed)
{
	srd_heartbeat();
	cfg(MGR, 0x1016, 2, HB(ID_SLV, 250U), 4);
	cfg(SLV, 0x1017, 0, 100U, 2);
	network(6);
	srd_register(0x12800009U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x1280000AU, "Req EC kept: supported");
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD, 0x1F11, 0), 0U, "alive");
	bus.port[SLV].alive = false;
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD, 0x1F11, 0), ID_SLV, "reason 00h, slave 0Ah");
	zassert_equal(od_u(SRD, 0x1281, 1) & BIT(31), BIT(31));
	zassert_equal(od_u(SRD, 0x1282, 1) & BIT(31), BIT(31));
	zassert_equal(conn(2), 0U, "the default SDO connection is gone");
	zassert_not_equal(conn(3), 0U, "the slave may still hold 6C2h/6C3h: stale");
	zassert_equal(od_u(MGR, 0x1F02, 3) & BIT(30), BIT(30));
	zassert_not_equal(conn(1), 0U, "the SRD stays registered");
	/* The slave boots again: its server entry is invalid, the pair is free. */
	bus.port[SLV].alive = true;
	node_reset(SLV);
	co_bus_run_ms(10);
	zassert_equal(conn(3), 0U);
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U);
	zassert_equal(od_u(MGR, 0x1F02, 4), POOL0 + 3U);
}

/* A release the slave does not answer keeps the entry; a later 1F01h gets it through. */
ZTEST(co_mgr_sdom, test_release_unanswered_kept_then_retried)
{
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	bus.port[SLV].alive = false;
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	co_bus_run_ms(500);
	zassert_equal(od_u(SRD, 0x1282, 1) & BIT(31), BIT(31), "the SRD's side released");
	zassert_not_equal(conn(3), 0U, "kept: the slave may still use the COB-IDs");
	zassert_equal(od_u(MGR, 0x1F02, 3) & BIT(30), BIT(30));
	/* The slave is back without a reset (it still holds the entry): the release again. */
	bus.port[SLV].alive = true;
	zassert_equal(od_u(SLV, 0x1201, 1), POOL0 + 2U);
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SLV, 0x1201, 1) & BIT(31), BIT(31));
	zassert_equal(conn(3), 0U);
	zassert_equal(od_u(MGR, 0x1F02, 3), POOL0 + 2U);
	zassert_not_equal(conn(2), 0U, "the other connection untouched");
}

/* 1F03h full (3 entries here): the next connection is 1F04h:01. */
ZTEST(co_mgr_sdom, test_connections_part_2)
{
	uint32_t v;

	node_add(SRD2, ID_SRD2, &sdom_srd_od_def);
	network(6);
	srd_register(0x12800001U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_PLAIN)), 0U);
	zassert_not_equal(od_u(MGR, 0x1F03, 3), 0U);
	zassert_equal(od_w(SRD2, 0x1F10, 0, 0x12800001U, CO_OD_WRITER_APP), 0U);
	inject(0x6E0, 0, 0, 0);
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD2, 0x1F10, 0), 0x12800002U);
	zassert_equal(od_u(MGR, 0x1F04, 1), ((uint32_t)ID_SRD2 << 16) | (2U << 8) | ID_MGR,
		      "1F04h:01, our 1202h");
	zassert_equal(upload_on(SRD2, 0, 0x1F04, 1, &v), 0U, "the channel works");
	zassert_equal(v, ((uint32_t)ID_SRD2 << 16) | (2U << 8) | ID_MGR);
	zassert_equal(srd_download(0, 0x1F04, 1, 0), CO_SDO_AB_READONLY);
	/* Released like the others. */
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0, ID_SRD, 0)), 0U);
	zassert_not_equal(od_u(MGR, 0x1F04, 1), 0U, "another SRD's");
	zassert_equal(od_u(MGR, 0x1F03, 1), 0U);
}

/* A flying master candidate is the SDO manager only once it won the negotiation. */
ZTEST(co_mgr_sdom, test_flying_master_manager_once_active)
{
#if !defined(CONFIG_CANOPEN_MGR_FLYING)
	ztest_test_skip();
#else
	uint64_t t0;

	t.su = 0x21U;
	t.boot_ms = 10U;
	network(6);
	t0 = bus.now;
	zassert_equal(od_w(SRD, 0x1F10, 0, 0x12800001U, CO_OD_WRITER_APP), 0U);
	inject(0x6E0, 0, 0, 0);
	co_bus_run_ms(500);
	zassert_false(seen(0x600U + 0x7FU, t0) || seen(0x600U + ID_SRD, t0),
		      "6E0h ignored while negotiating");
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
	/* Alone, it wins within about 3 s (1F90h defaults) and serves the SRD. */
	co_bus_run_ms(5000);
	srd_register(0x12800001U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U);
#endif
}

/* A slave's default SDO is the boot's while its boot runs: the connection waits for its end. */
ZTEST(co_mgr_sdom, test_connection_waits_for_boot)
{
	uint64_t t0;

	cfg(MGR, 0x1F81, ID_SLV, 0x05U, 4);
	/* The boot's "start error control" waits 500 ms for a heartbeat that never comes. */
	cfg(MGR, 0x1016, 1, HB(ID_SLV, 500U), 4);
	network(6);
	srd_register(0x12800001U);
	node_reset(SLV);
	co_bus_run_ms(50);
	t0 = bus.now;
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO), 0U);
	co_bus_run_ms(200);
	zassert_equal(count(0x600U + ID_SLV, t0), 0, "no SDO manager transfer during the boot");
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12800002U, "not yet");
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x12810006U, "set up once the boot ended");
	zassert_true(seen(0x600U + ID_SLV, t0));
}

/* Node guarding RTRs on 700h + @p id since @p since. */
static int count_rtr(uint8_t id, uint64_t since)
{
	int n = 0;

	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == 0x700U + id &&
		    (bus.log[i].f.flags & CAN_FRAME_RTR) != 0U) {
			n++;
		}
	}
	return n;
}

/*
 * Time from the frame before the first SDO upload of @p index on CAN-ID @p id since @p since
 * to that upload (the wake-up of a step that waited), or -1 without such an upload.
 */
static int64_t gap_before_upload(uint32_t id, uint16_t index, uint64_t since)
{
	for (int i = 1; i < bus.n_log; i++) {
		const struct can_frame *f = &bus.log[i].f;

		if (bus.log[i].at >= since && f->id == id && (f->data[0] & 0xE0U) == 0x40U &&
		    sys_get_le16(&f->data[1]) == index) {
			return (int64_t)(bus.log[i].at - bus.log[i - 1].at);
		}
	}
	return -1;
}

/* Whether the NMT master sent "start" (000#01nn) to @p id since @p since. */
static bool seen_start(uint8_t id, uint64_t since)
{
	for (int i = 0; i < bus.n_log; i++) {
		if (bus.log[i].at >= since && bus.log[i].f.id == 0U &&
		    bus.log[i].f.data[0] == 0x01U && bus.log[i].f.data[1] == id) {
			return true;
		}
	}
	return false;
}

/* SDO uploads of @p index started on CAN-ID @p id since @p since (ccs 2). */
static int count_uploads(uint32_t id, uint16_t index, uint64_t since)
{
	int n = 0;

	for (int i = 0; i < bus.n_log; i++) {
		const struct can_frame *f = &bus.log[i].f;

		if (bus.log[i].at >= since && f->id == id && (f->data[0] & 0xE0U) == 0x40U &&
		    sys_get_le16(&f->data[1]) == index) {
			n++;
		}
	}
	return n;
}

/*
 * The boot of a slave whose default SDO an SRD holds (a connection over it) waits: none of
 * its transfers goes out on 600h + S until the connection is released, then it runs to the
 * end (NMT start). The release writes the slave's dynamic entry first, over its default SDO:
 * a boot that waits does not hold that write up.
 */
ZTEST(co_mgr_sdom, test_boot_waits_for_srd_default_connection)
{
	int64_t gap;
	uint64_t t0;

	cfg(MGR, 0x1F81, ID_SLV, 0x05U, 4);
	network(6);
	srd_register(0x12800001U);
	/* Connection 3 over S's default SDO, then connection 2 dynamic to S (its 1201h). */
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_PLAIN)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1281, ID_SRD, ID_PLAIN)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(od_u(SRD, 0x1282, 1), 0x600U + ID_SLV, "over the default SDO");
	zassert_equal(conn(2) & 0xFF00U, 1U << 8, "dynamic: S's 1201h");
	t0 = bus.now;
	/* Its boot-up starts the boot process (1F81h bit 2). */
	node_reset(SLV);
	co_bus_run_ms(1000);
	zassert_equal(count(0x600U + ID_SLV, t0), 0, "the boot left 60Ah to the SRD");
	zassert_false(seen_start(ID_SLV, t0), "boot not ended");
	t0 = bus.now;
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0, ID_SRD, ID_SLV)), 0U);
	co_bus_run_ms(500);
	zassert_equal(conn(2), 0U, "released");
	zassert_equal(conn(3), 0U, "released");
	zassert_true(count_uploads(0x600U + ID_SLV, 0x1000, t0) > 0, "the boot goes on");
	/* Woken by the release's end, not by its 100 ms poll. */
	gap = gap_before_upload(0x600U + ID_SLV, 0x1000, t0);
	zassert_true(gap >= 0 && gap < 1000, "the boot's first request %lld us after the release",
		     (long long)gap);
	zassert_true(seen_start(ID_SLV, t0), "and ends: NMT start");
}

/*
 * The SDO manager's own transfer to a slave (the 1000h check of a 1F00h) is not overlapped by
 * the slave's boot: the boot's first upload goes out once the check ended.
 */
ZTEST(co_mgr_sdom, test_boot_waits_for_manager_transfer)
{
	uint64_t t0;

	cfg(MGR, 0x1F81, ID_SLV, 0x05U, 4);
	network(6);
	srd_register(0x12800001U);
	bus.port[SLV].alive = false;
	t0 = bus.now;
	zassert_equal(od_w(MGR, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV), CO_OD_WRITER_SDO), 0U);
	co_bus_run_ms(10);
	/* A boot-up of S while the manager's 1000h upload waits for its 100 ms timeout. */
	inject(0x700U + ID_SLV, 1, 0, 0);
	co_bus_run_ms(50);
	zassert_equal(count(0x600U + ID_SLV, t0), 1, "only the SDO manager's request");
	co_bus_run_ms(200);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000400U, "S did not answer: error 04h");
	zassert_equal(count_uploads(0x600U + ID_SLV, 0x1000, t0), 2, "then the boot's upload");
}

/* An SRD with all default SDOs holds the slave's too: the boot waits until it gives them back. */
ZTEST(co_mgr_sdom, test_boot_waits_for_all_default_sdos)
{
	uint64_t t0;

	cfg(MGR, 0x1F81, ID_SLV, 0x05U, 4);
	cfg(MGR, 0x1016, 1, HB(ID_SRD, 250U), 4);
	cfg(SRD, 0x1017, 0, 100U, 2);
	network(6);
	srd_register(0x00000003U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000004U);
	t0 = bus.now;
	node_reset(SLV);
	co_bus_run_ms(1000);
	zassert_equal(count(0x600U + ID_SLV, t0), 0, "the boot left 60Ah to the SRD");
	zassert_false(seen_start(ID_SLV, t0));
	/* The SRD gives the default SDOs back by stopping its heartbeat. */
	t0 = bus.now;
	od_w16(SRD, 0x1017, 0, 0U);
	co_bus_run_ms(1000);
	zassert_true(seen(0x600U + ID_SLV, t0), "the boot goes on");
	zassert_true(seen_start(ID_SLV, t0), "and ends: NMT start");
}

/* "All default SDOs" is granted once the running boot of a slave no longer uses its SDO. */
ZTEST(co_mgr_sdom, test_all_default_sdos_wait_for_running_boot)
{
	cfg(MGR, 0x1F81, ID_SLV, 0x05U, 4);
	/* The boot's "start error control" waits 500 ms for a heartbeat that never comes. */
	cfg(MGR, 0x1016, 1, HB(ID_SLV, 500U), 4);
	network(6);
	node_reset(SLV);
	co_bus_run_ms(50);
	zassert_equal(od_w(SRD, 0x1F10, 0, 0x00000003U, CO_OD_WRITER_APP), 0U);
	inject(0x6E0, 0, 0, 0);
	co_bus_run_ms(200);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000003U, "not while the boot runs");
	co_bus_run_ms(1000);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x00000004U, "granted after its end");
}

/*
 * Req EC: the slave is guarded from its first connection (1F81h guard time, bit 0 clear: no
 * NMT slave of ours) until its last one ends, by a release or by the de-registration.
 */
ZTEST(co_mgr_sdom, test_req_ec_supervision_ends_with_last_connection)
{
	uint64_t t0;

	cfg(MGR, 0x1F81, ID_SLV, (100U << 16) | (3U << 8), 4);
	network(6);
	srd_register(0x12800009U);
	zassert_equal(od_u(SRD, 0x1F10, 0), 0x1280000AU);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_equal(count_rtr(ID_SLV, t0), 0, "not supervised before a connection");
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_true(count_rtr(ID_SLV, t0) >= 4, "guarded (%d)", count_rtr(ID_SLV, t0));
	/* One of two connections ends: still guarded. */
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_true(count_rtr(ID_SLV, t0) >= 4, "the other connection keeps it");
	/* The last one: guarding stops. */
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0x1282, ID_SRD, ID_SLV)), 0U);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_equal(count_rtr(ID_SLV, t0), 0, "no connection left");
	/* Again, ended by the de-registration (slave 0). */
	zassert_equal(srd_download(0, 0x1F00, 0, REQ(0x1281, ID_SRD, ID_SLV)), 0U);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_true(count_rtr(ID_SLV, t0) >= 4, "guarded again");
	zassert_equal(srd_download(0, 0x1F01, 0, REQ(0, ID_SRD, 0)), 0U);
	co_bus_run_ms(100);
	t0 = bus.now;
	co_bus_run_ms(500);
	zassert_equal(count_rtr(ID_SLV, t0), 0, "de-registered");
}

ZTEST_SUITE(co_mgr_sdom, NULL, NULL, before, after, NULL);
