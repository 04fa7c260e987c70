/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SDO manager (CiA 302 §7, doc/sdo-manager.md): registration of SDO requesting devices
 * (SRDs) on 6E0h, connections to slaves on request (1F00h), releases (1F01h), the COB-ID
 * pool 1F02h and the connection table 1F03h.
 *
 * One operation runs at a time over one SDO client (the node's last one) bound to the
 * default SDO of the node it talks to; 1F00h/1F01h writes that arrive meanwhile wait in a
 * small queue. An operation is a list of writes (SDO downloads, or local writes for our own
 * server entries) run in order, preceded for a registration by the scan of 1F10h and for a
 * dynamic connection by the search of a free server entry on the slave.
 */

#include <string.h>

#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/sdo_abort.h>

#include "mgr_internal.h"

LOG_MODULE_REGISTER(co_mgr_sdom, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_REQ_SDO  0x1F00U
#define IDX_REL_SDO  0x1F01U
#define IDX_POOL     0x1F02U
#define IDX_CONN     0x1F03U
#define IDX_SRD_STAT 0x1F10U
#define IDX_SRV_PAR  0x1200U
#define IDX_CLI_PAR  0x1280U
#define TRIGGER_ID   0x6E0U

#define COB_INVALID BIT(31)
#define COB_USED    BIT(30)
#define COB_EXT     BIT(29)

/* 1F10h: Rq indication, connection state (bits 2..1), Req EC, error code, index. */
#define ST_RQ           BIT(0)
#define ST_STATE(s)     ((uint32_t)(s) << 1)
#define ST_REQ_EC       BIT(3)
#define ST_ALL_DEFAULTS 0x00000003U

enum {
	OP_NONE,
	OP_SCAN,
	OP_PROBE,
	OP_SEARCH,
	OP_WRITE
};

/* What the writes of an operation end in. */
enum {
	END_REG,
	END_CONN,
	END_REL,
	END_STATUS
};

static struct co_sdo_cli *cli(struct co_mgr *m)
{
	return co_sdo_cli_get(m->node, CONFIG_CANOPEN_SDO_CLIENTS - 1);
}

static uint8_t own_id(struct co_mgr *m)
{
	return co_node_id(m->node);
}

/* --- 1F02h pool and 1F03h table -------------------------------------------------------- */

static uint8_t subs(struct co_mgr *m, uint16_t index)
{
	return (uint8_t)co_mgr_od(m, index, 0);
}

static void od_put32(struct co_mgr *m, uint16_t index, uint8_t sub, uint32_t v)
{
	uint8_t b[4];

	sys_put_le32(v, b);
	m->sdom.own_write = true;
	(void)co_od_write(&m->node->od, index, sub, b, 4, CO_OD_WRITER_APP);
	m->sdom.own_write = false;
}

/* Two free valid entries of 1F02h, or false. */
static bool pool_find(struct co_mgr *m, uint8_t pair[2])
{
	uint8_t n = 0U;

	for (uint8_t i = 1U; i <= subs(m, IDX_POOL) && n < 2U; i++) {
		if ((co_mgr_od(m, IDX_POOL, i) & (COB_INVALID | COB_USED)) == 0U) {
			pair[n++] = i;
		}
	}
	return n == 2U;
}

static void pool_mark(struct co_mgr *m, uint8_t sub, bool used)
{
	uint32_t v = co_mgr_od(m, IDX_POOL, sub);

	od_put32(m, IDX_POOL, sub, used ? (v | COB_USED) : (v & ~COB_USED));
}

/* A pool entry as a COB-ID of an SDO parameter (bit 29 is the frame type there too). */
static uint32_t pool_cobid(struct co_mgr *m, uint8_t sub)
{
	return co_mgr_od(m, IDX_POOL, sub) & ~(COB_INVALID | COB_USED);
}

static uint8_t conn_free(struct co_mgr *m)
{
	uint8_t n = MIN(subs(m, IDX_CONN), CONFIG_CANOPEN_MGR_SDOM_CONNS);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = co_mgr_od(m, IDX_CONN, i);

		if ((uint8_t)c == 0U || (uint8_t)(c >> 16) == 0U) {
			return i;
		}
	}
	return 0U;
}

static bool default_taken(struct co_mgr *m, uint8_t slave)
{
	uint8_t n = MIN(subs(m, IDX_CONN), CONFIG_CANOPEN_MGR_SDOM_CONNS);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = co_mgr_od(m, IDX_CONN, i);

		if ((uint8_t)c == slave && (uint8_t)(c >> 8) == 0U && (uint8_t)(c >> 16) != 0U) {
			return true;
		}
	}
	return false;
}

static int srd_find(struct co_mgr *m, uint8_t id)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SDOM_SRDS; i++) {
		if (m->sdom.srds[i] == id && id != 0U) {
			return i;
		}
	}
	return -1;
}

/* --- Running an operation --------------------------------------------------------------- */

/*
 * What follows the end of a step runs from this timer, never from the step itself: the
 * chain request -> write -> next request stays free of recursion (MISRA C:2012 rule 17.2).
 */
static void kick(struct co_mgr *m)
{
	co_node_timer_start(m->node, &m->sdom.work, co_mgr_now(m));
}

static void add_wr(struct co_mgr *m, uint8_t node, uint16_t index, uint8_t sub, uint32_t v,
		   uint8_t len)
{
	struct co_mgr_sdom *d = &m->sdom;

	__ASSERT_NO_MSG(d->n_wr < ARRAY_SIZE(d->wr));
	d->wr[d->n_wr++] = (struct co_mgr_sdom_wr){
		.node = node, .index = index, .sub = sub, .len = len, .val = v};
}

/* The SRD's 1F10h: a failure (state 0) with @p code, or a confirmation. */
static void add_status(struct co_mgr *m, uint8_t srd, uint32_t v)
{
	add_wr(m, srd, IDX_SRD_STAT, 0U, v, 4U);
}

static void con(struct co_sdo_cli *c, uint32_t ab, size_t size, void *user_data);

static uint8_t n_conns_of(struct co_mgr *m, uint8_t srd)
{
	uint8_t n = MIN(subs(m, IDX_CONN), CONFIG_CANOPEN_MGR_SDOM_CONNS);
	uint8_t k = 0U;

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = co_mgr_od(m, IDX_CONN, i);

		if ((uint8_t)(c >> 16) == srd && (uint8_t)c != 0U) {
			k++;
		}
	}
	return k;
}

static void start_upload(struct co_mgr *m, uint8_t node, uint16_t index, uint8_t sub)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint32_t timeout = d->op == OP_SCAN ? CONFIG_CANOPEN_MGR_SDOM_SCAN_TIMEOUT
					    : CONFIG_CANOPEN_MGR_SDO_TIMEOUT;

	if (co_sdo_cli_set_server(cli(m), node) != 0 ||
	    co_sdo_cli_upload_req(cli(m), index, sub, d->buf, sizeof(d->buf), CO_SDO_CLI_AUTO,
				  timeout, con, m) != 0) {
		/* Answered from the timer as a failed upload: no call back into con() here. */
		d->fake_ab = CO_SDO_AB_GENERAL;
		kick(m);
	}
}

static void step_write(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	while (d->i_wr < d->n_wr) {
		struct co_mgr_sdom_wr *w = &d->wr[d->i_wr];

		sys_put_le32(w->val, d->buf);
		if (w->node == own_id(m)) {
			/* Our own server entry of the SRD's channel: no SDO. */
			(void)co_od_write(&m->node->od, w->index, w->sub, d->buf, w->len,
					  CO_OD_WRITER_APP);
			d->i_wr++;
			continue;
		}
		if (co_sdo_cli_set_server(cli(m), w->node) != 0 ||
		    co_sdo_cli_download_req(cli(m), w->index, w->sub, d->buf, w->len,
					    CO_SDO_CLI_AUTO, CONFIG_CANOPEN_MGR_SDO_TIMEOUT, con,
					    m) != 0) {
			LOG_WRN("SDO manager: cannot write %u %04x:%02x", w->node, w->index,
				w->sub);
			d->i_wr++;
			continue;
		}
		return;
	}
	/* The table follows the writes: a failed write of a release still frees the entry. */
	if (d->end == END_REL) {
		od_put32(m, IDX_CONN, d->conn, 0U);
		for (int k = 0; k < 2; k++) {
			if (d->cpool[d->conn - 1U][k] != 0U) {
				pool_mark(m, d->cpool[d->conn - 1U][k], false);
				d->cpool[d->conn - 1U][k] = 0U;
			}
		}
	}
	d->op = OP_NONE;
	kick(m);
}

/* The pair d->pool is in use by table entry d->conn. */
static void use_pair(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	for (int k = 0; k < 2; k++) {
		pool_mark(m, d->pool[k], true);
		d->cpool[d->conn - 1U][k] = d->pool[k];
	}
}

/* S's default SDO: the table and the SRD's client entry; nothing is written to S. */
static void conn_default(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	od_put32(m, IDX_CONN, d->conn,
		 ((uint32_t)(d->idx - IDX_CLI_PAR) << 24) | ((uint32_t)d->srd << 16) | d->slave);
	d->srv_num = 0U;
	d->n_wr = 0U;
	d->i_wr = 0U;
	d->end = END_CONN;
	add_wr(m, d->srd, d->idx, 3U, d->slave, 1U);
	add_wr(m, d->srd, d->idx, 1U, 0x600U + d->slave, 4U);
	add_wr(m, d->srd, d->idx, 2U, 0x580U + d->slave, 4U);
	add_status(m, d->srd, ((uint32_t)d->idx << 16) | ST_STATE(3));
	d->op = OP_WRITE;
	step_write(m);
}

/*
 * A write of a set-up was refused (e.g. the SRD has no such client entry): the table entry
 * and its pool pair are freed, what S or we got is invalidated, a registration is forgotten,
 * and the SRD's 1F10h says state 0, error 00h (unspecified).
 */
static void undo(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint8_t end = d->end;

	od_put32(m, IDX_CONN, d->conn, 0U);
	for (int k = 0; k < 2; k++) {
		if (d->cpool[d->conn - 1U][k] != 0U) {
			pool_mark(m, d->cpool[d->conn - 1U][k], false);
			d->cpool[d->conn - 1U][k] = 0U;
		}
	}
	d->n_wr = 0U;
	d->i_wr = 0U;
	d->end = END_STATUS;
	if (end == END_REG) {
		int i = srd_find(m, d->srd);

		if (i >= 0) {
			d->srds[i] = 0U;
		}
		add_wr(m, own_id(m), IDX_SRV_PAR + d->srv_num, 1U, COB_INVALID, 4U);
		add_wr(m, own_id(m), IDX_SRV_PAR + d->srv_num, 2U, COB_INVALID, 4U);
	} else if (d->srv_num != 0U) {
		add_wr(m, d->slave, IDX_SRV_PAR + d->srv_num, 1U, COB_INVALID, 4U);
		add_wr(m, d->slave, IDX_SRV_PAR + d->srv_num, 2U, COB_INVALID, 4U);
	}
	add_status(m, d->srd, 0U);
	d->op = OP_WRITE;
	step_write(m);
}

/* A dynamic connection: server entry on S, client entry on the SRD, table, confirmation. */
static void conn_dynamic(struct co_mgr *m, uint8_t num)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint32_t c2s = pool_cobid(m, d->pool[0]);
	uint32_t s2c = pool_cobid(m, d->pool[1]);
	uint16_t srv = IDX_SRV_PAR + num;

	use_pair(m);
	od_put32(m, IDX_CONN, d->conn,
		 ((uint32_t)(d->idx - IDX_CLI_PAR) << 24) | ((uint32_t)d->srd << 16) |
			 ((uint32_t)num << 8) | d->slave);
	d->n_wr = 0U;
	d->i_wr = 0U;
	d->end = END_CONN;
	add_wr(m, d->slave, srv, 3U, d->srd, 1U);
	add_wr(m, d->slave, srv, 1U, c2s, 4U);
	add_wr(m, d->slave, srv, 2U, s2c, 4U);
	add_wr(m, d->srd, d->idx, 3U, d->slave, 1U);
	add_wr(m, d->srd, d->idx, 1U, c2s, 4U);
	add_wr(m, d->srd, d->idx, 2U, s2c, 4U);
	add_status(m, d->srd, ((uint32_t)d->idx << 16) | ST_STATE(3));
	d->op = OP_WRITE;
	step_write(m);
}

/* Only the SRD's 1F10h: a failure (state 0, error @p code) or "all default SDOs". */
static void status_only(struct co_mgr *m, uint8_t srd, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;

	d->n_wr = 0U;
	d->i_wr = 0U;
	d->end = END_STATUS;
	add_status(m, srd, v);
	d->op = OP_WRITE;
	step_write(m);
}

static void fail(struct co_mgr *m, uint8_t srd, uint8_t code)
{
	status_only(m, srd, (uint32_t)code << 8);
}

static void registered(struct co_mgr *m, uint8_t id, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;
	int slot = srd_find(m, 0U);
	uint16_t idx = (uint16_t)(v >> 16);
	uint8_t srv = 0U;

	for (int i = 0; i < CONFIG_CANOPEN_MGR_SDOM_SRDS && slot < 0; i++) {
		if (d->srds[i] == 0U) {
			slot = i;
		}
	}
	if (slot < 0) {
		fail(m, id, 0x01U);
		return;
	}
	if (v == ST_ALL_DEFAULTS) {
		d->srds[slot] = id;
		d->all[slot] = true;
		/* Nothing to set up: the SRD uses the default SDOs (state 2). */
		status_only(m, id, ST_STATE(2));
		return;
	}
	for (uint8_t n = 1U; n < 128U && srv == 0U; n++) {
		uint32_t c;

		if (co_od_get_u32(&m->node->od, IDX_SRV_PAR + n, 1U, &c) != CO_SDO_AB_NONE) {
			break;
		}
		if ((c & COB_INVALID) != 0U) {
			srv = n;
		}
	}
	d->conn = conn_free(m);
	if (idx < IDX_CLI_PAR || idx > 0x12FFU || srv == 0U || d->conn == 0U ||
	    !pool_find(m, d->pool)) {
		fail(m, id, 0x01U);
		return;
	}
	d->srds[slot] = id;
	d->all[slot] = false;
	d->srd = id;
	d->srv_num = srv;
	use_pair(m);
	od_put32(m, IDX_CONN, d->conn,
		 ((uint32_t)(idx - IDX_CLI_PAR) << 24) | ((uint32_t)id << 16) |
			 ((uint32_t)srv << 8) | own_id(m));
	d->n_wr = 0U;
	d->i_wr = 0U;
	d->end = END_REG;
	add_wr(m, own_id(m), IDX_SRV_PAR + srv, 3U, id, 1U);
	add_wr(m, own_id(m), IDX_SRV_PAR + srv, 1U, pool_cobid(m, d->pool[0]), 4U);
	add_wr(m, own_id(m), IDX_SRV_PAR + srv, 2U, pool_cobid(m, d->pool[1]), 4U);
	add_wr(m, id, idx, 3U, own_id(m), 1U);
	add_wr(m, id, idx, 1U, pool_cobid(m, d->pool[0]), 4U);
	add_wr(m, id, idx, 2U, pool_cobid(m, d->pool[1]), 4U);
	/* Req EC cleared: this manager does not start error control for the SRD's slaves. */
	add_status(m, id, ((uint32_t)idx << 16) | ST_STATE(1));
	d->op = OP_WRITE;
	step_write(m);
}

/* Scan from node-ID @p id downwards for the next node that is not registered. */
static void scan_from(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_sdom *d = &m->sdom;

	while (id > 0U && (id == own_id(m) || srd_find(m, id) >= 0)) {
		id--;
	}
	if (id == 0U) {
		d->op = OP_NONE;
		kick(m);
		return;
	}
	d->op = OP_SCAN;
	d->scan_id = id;
	start_upload(m, id, IDX_SRD_STAT, 0U);
}

static void con(struct co_sdo_cli *c, uint32_t ab, size_t size, void *user_data)
{
	struct co_mgr *m = user_data;
	struct co_mgr_sdom *d = &m->sdom;
	uint32_t v = sys_get_le32(d->buf);

	ARG_UNUSED(c);
	switch (d->op) {
	case OP_SCAN:
		/* 302 §7.2.1: the first SRD with Rq indication set ends the scan. */
		if (ab == 0U && size == 4U &&
		    (v == ST_ALL_DEFAULTS || (v & (ST_RQ | ST_STATE(3))) == ST_RQ)) {
			registered(m, d->scan_id, v);
			return;
		}
		scan_from(m, (uint8_t)(d->scan_id - 1U));
		return;
	case OP_PROBE:
		if (ab == 0U) {
			conn_default(m);
		} else {
			fail(m, d->srd, 0x04U);
		}
		return;
	case OP_SEARCH:
		if (ab == 0U && (v & COB_INVALID) != 0U) {
			conn_dynamic(m, d->srv_num);
			return;
		}
		if (ab == 0U && d->srv_num < 127U) {
			d->srv_num++;
			start_upload(m, d->slave, IDX_SRV_PAR + d->srv_num, 1U);
			return;
		}
		/* No entry left (the object is missing), or S does not answer. */
		fail(m, d->srd,
		     (ab == 0U || (ab >> 16) == 0x0602U || (ab >> 16) == 0x0609U) ? 0x03U : 0x04U);
		return;
	case OP_WRITE:
		if (ab != 0U) {
			struct co_mgr_sdom_wr *w = &d->wr[d->i_wr];

			LOG_WRN("SDO manager: %u %04x:%02x refused (%08x)", w->node, w->index,
				w->sub, ab);
			if ((d->end == END_CONN || d->end == END_REG) && w->index != IDX_SRD_STAT) {
				undo(m);
				return;
			}
		}
		d->i_wr++;
		step_write(m);
		return;
	default:
		return;
	}
}

/* --- Requests -------------------------------------------------------------------------------- */

/* Start the release of the next connection of 1F01h value @p v; false when none is left. */
static bool release_next(struct co_mgr *m, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint16_t idx = (uint16_t)(v >> 16);
	uint8_t srd = (uint8_t)(v >> 8);
	uint8_t slave = (uint8_t)v;
	uint8_t n = MIN(subs(m, IDX_CONN), CONFIG_CANOPEN_MGR_SDOM_CONNS);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = co_mgr_od(m, IDX_CONN, i);
		uint16_t ci = (uint16_t)(IDX_CLI_PAR + (c >> 24));
		uint8_t srv = (uint8_t)(c >> 8);
		uint8_t s = (uint8_t)c;
		bool reg = s == own_id(m);

		/* Slave 0: everything of the SRD, its own channel to us last. */
		if ((uint8_t)(c >> 16) != srd || s == 0U || (slave != 0U && s != slave) ||
		    (slave == 0U && reg && n_conns_of(m, srd) > 1U) || (idx != 0U && ci != idx)) {
			continue;
		}
		d->n_wr = 0U;
		d->i_wr = 0U;
		d->end = END_REL;
		d->conn = i;
		/* The client entry on the SRD first: it stops using the channel. */
		add_wr(m, srd, ci, 1U, COB_INVALID, 4U);
		add_wr(m, srd, ci, 2U, COB_INVALID, 4U);
		if (srv != 0U) {
			add_wr(m, s, IDX_SRV_PAR + srv, 1U, COB_INVALID, 4U);
			add_wr(m, s, IDX_SRV_PAR + srv, 2U, COB_INVALID, 4U);
		}
		d->op = OP_WRITE;
		step_write(m);
		return true;
	}
	return false;
}

static void request(struct co_mgr *m, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;

	d->idx = (uint16_t)(v >> 16);
	d->srd = (uint8_t)(v >> 8);
	d->slave = (uint8_t)v;
	d->conn = conn_free(m);
	if (d->conn == 0U) {
		fail(m, d->srd, 0x02U);
		return;
	}
	if (!default_taken(m, d->slave)) {
		/* S must answer on its default SDO (1000h) before the SRD gets it. */
		d->op = OP_PROBE;
		start_upload(m, d->slave, IDX_DEVTYPE, 0U);
		return;
	}
	if (!pool_find(m, d->pool)) {
		fail(m, d->srd, 0x02U);
		return;
	}
	d->op = OP_SEARCH;
	d->srv_num = 1U;
	start_upload(m, d->slave, IDX_SRV_PAR + 1U, 1U);
}

/* Start what waits: a release in progress, a queued request, a registration scan. */
static void next(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	while (d->op == OP_NONE) {
		if (d->rel_active) {
			if (release_next(m, d->rel_val)) {
				return;
			}
			d->rel_active = false;
			if ((uint8_t)d->rel_val == 0U) {
				int i = srd_find(m, (uint8_t)(d->rel_val >> 8));

				if (i >= 0) {
					d->srds[i] = 0U;
					d->all[i] = false;
				}
			}
			continue;
		}
		if (d->n_q > 0U) {
			struct co_mgr_sdom_req q = d->q[0];

			memmove(&d->q[0], &d->q[1], (d->n_q - 1U) * sizeof(d->q[0]));
			d->n_q--;
			if (q.kind == IDX_REL_SDO) {
				d->rel_active = true;
				d->rel_val = q.val;
			} else if (q.kind == IDX_REQ_SDO) {
				request(m, q.val);
			} else {
				fail(m, (uint8_t)(q.val >> 8), (uint8_t)q.kind);
			}
			continue;
		}
		if (d->trig) {
			d->trig = false;
			scan_from(m, 127U);
			continue;
		}
		return;
	}
}

static uint32_t enqueue(struct co_mgr *m, uint16_t kind, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;

	if (d->n_q >= ARRAY_SIZE(d->q)) {
		return CO_SDO_AB_NO_RESOURCE;
	}
	d->q[d->n_q++] = (struct co_mgr_sdom_req){.kind = kind, .val = v};
	next(m);
	return CO_OD_HANDLED;
}

/* 1F00h: refusals that are known now abort the write (060A0023h) and still tell the SRD. */
static uint32_t req_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint16_t idx = (uint16_t)(v >> 16);
	uint8_t srd = (uint8_t)(v >> 8);
	uint8_t slave = (uint8_t)v;
	int i = srd_find(m, srd);
	uint8_t code = 0U;
	uint8_t pair[2];

	ARG_UNUSED(od);
	if (req->len != 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	if ((co_mgr_startup_obj(m) & SU_MASTER) == 0U) {
		/* Only the manager (1F80h bit 0) hands out connections. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (i < 0 || m->sdom.all[i]) {
		/* Not registered (or it owns every default SDO already): nobody to tell. */
		return CO_SDO_AB_NO_RESOURCE;
	}
	if (idx < IDX_CLI_PAR || idx > 0x12FFU) {
		code = 0x01U;
	} else if (slave == 0U || slave > 127U || slave == srd || slave == own_id(m)) {
		code = 0x04U;
	} else if (conn_free(m) == 0U || (default_taken(m, slave) && !pool_find(m, pair))) {
		code = 0x02U;
	}
	if (code != 0U) {
		/* The failure status is written later by the queue: kind = the error code. */
		(void)enqueue(m, code, v);
		return CO_SDO_AB_NO_RESOURCE;
	}
	return enqueue(m, IDX_REQ_SDO, v);
}

static uint32_t rel_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint16_t idx = (uint16_t)(v >> 16);

	ARG_UNUSED(od);
	if (req->len != 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	if ((co_mgr_startup_obj(m) & SU_MASTER) == 0U) {
		/* Only the manager (1F80h bit 0) hands out connections. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (srd_find(m, (uint8_t)(v >> 8)) < 0 || (uint8_t)v > 127U ||
	    (idx != 0U && (idx < IDX_CLI_PAR || idx > 0x12FFU))) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return enqueue(m, IDX_REL_SDO, v);
}

/* 1F02h is changed by tools only while no connection uses it; 1F03h is ours. */
static uint32_t table_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t n = MIN(subs(m, IDX_CONN), CONFIG_CANOPEN_MGR_SDOM_CONNS);

	ARG_UNUSED(od);
	if (m->sdom.own_write || req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (req->info->index == IDX_CONN) {
		return CO_SDO_AB_READONLY;
	}
	for (uint8_t i = 1U; i <= n; i++) {
		if ((uint8_t)(co_mgr_od(m, IDX_CONN, i) >> 16) != 0U) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
	}
	return 0U;
}

static void work_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;
	uint32_t ab = m->sdom.fake_ab;

	ARG_UNUSED(now_us);
	if (ab != 0U) {
		m->sdom.fake_ab = 0U;
		con(cli(m), ab, 0U, m);
		return;
	}
	next(m);
}

static void trigger_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;

	ARG_UNUSED(now_us);
	/* Only the manager (1F80h bit 0) answers; every other node ignores 6E0h. */
	if (frame->dlc != 0U || (co_mgr_startup_obj(m) & SU_MASTER) == 0U) {
		return;
	}
	m->sdom.trig = true;
	next(m);
}

int co_mgr_sdom_init(struct co_mgr *m)
{
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_REQ_SDO,
			.index_last = IDX_REQ_SDO,
			.sub_first = 0,
			.sub_last = 0,
			.validate = req_validate,
			.user_data = m,
		},
		{
			.index_first = IDX_REL_SDO,
			.index_last = IDX_REL_SDO,
			.sub_first = 0,
			.sub_last = 0,
			.validate = rel_validate,
			.user_data = m,
		},
		{
			.index_first = IDX_POOL,
			.index_last = IDX_CONN,
			.sub_first = 1,
			.sub_last = 255,
			.validate = table_validate,
			.user_data = m,
		},
	};

	co_timer_init(&m->sdom.work, work_handler, &m->node->lock, m);
	co_rx_init(&m->sdom.trig_rx, TRIGGER_ID, trigger_rx, &m->node->lock, m);
	if (co_node_rx_register(m->node, CO_LINE_DEFAULT, &m->sdom.trig_rx) != 0) {
		return -ENOSPC;
	}
	return co_od_hooks_register(&m->node->od, hooks, ARRAY_SIZE(hooks));
}
