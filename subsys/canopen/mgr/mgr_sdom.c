/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SDO manager (CiA 302 §7, doc/sdo-manager.md): registration of SDO requesting devices
 * (SRDs) on 6E0h, connections to slaves on request (1F00h), releases (1F01h), the COB-ID
 * pool 1F02h, the connection table 1F03h-1F06h, and the error control of SRDs (their loss
 * releases their connections) and, on request (1F10h Req EC), of their slaves (1F11h).
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
#define IDX_CONN_END 0x1F06U
#define IDX_SRD_STAT 0x1F10U
#define IDX_SRD_FAIL 0x1F11U
#define IDX_SRV_PAR  0x1200U
#define IDX_CLI_PAR  0x1280U
#define TRIGGER_ID   0x6E0U

#define COB_INVALID BIT(31)
#define COB_USED    BIT(30)
#define COB_EXT     BIT(29)

/* Sides of a connection whose release writes failed (stale[]). */
#define SIDE_CLIENT BIT(0)
#define SIDE_SERVER BIT(1)

/* A step that would use a booting slave's default SDO looks again after this [ms]. */
#define BOOT_WAIT_MS 10U

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
	END_STATUS,
	END_ALL
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

/*
 * Connection k (1..) is the k-th entry of 1F03h, then of 1F04h-1F06h (302 §7.2.3: parts 2-4
 * take up where the one before ends), each with as many entries as its sub 0 says.
 */
static uint8_t conn_count(struct co_mgr *m)
{
	uint32_t n = 0U;

	for (uint16_t idx = IDX_CONN; idx <= IDX_CONN_END; idx++) {
		n += subs(m, idx);
	}
	return (uint8_t)MIN(n, (uint32_t)CONFIG_CANOPEN_MGR_SDOM_CONNS);
}

static uint16_t conn_loc(struct co_mgr *m, uint8_t k, uint8_t *sub)
{
	uint8_t left = k;
	uint16_t idx = IDX_CONN;

	while (idx < IDX_CONN_END && left > subs(m, idx)) {
		left -= subs(m, idx);
		idx++;
	}
	*sub = left;
	return idx;
}

static uint32_t conn_get(struct co_mgr *m, uint8_t k)
{
	uint8_t sub;
	uint16_t idx = conn_loc(m, k, &sub);

	return co_mgr_od(m, idx, sub);
}

static void conn_put(struct co_mgr *m, uint8_t k, uint32_t v)
{
	uint8_t sub;
	uint16_t idx = conn_loc(m, k, &sub);

	od_put32(m, idx, sub, v);
}

static uint8_t conn_free(struct co_mgr *m)
{
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);

		if ((uint8_t)c == 0U || (uint8_t)(c >> 16) == 0U) {
			return i;
		}
	}
	return 0U;
}

static bool default_taken(struct co_mgr *m, uint8_t slave)
{
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);

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

/* Connections of @p srd the running release has not taken yet. */
static uint8_t n_conns_of(struct co_mgr *m, uint8_t srd)
{
	uint8_t n = conn_count(m);
	uint8_t k = 0U;

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);

		if ((uint8_t)(c >> 16) == srd && (uint8_t)c != 0U && !m->sdom.tried[i - 1U]) {
			k++;
		}
	}
	return k;
}

static bool bit_get(const uint32_t *map, uint8_t id)
{
	return (map[id / 32U] & BIT(id % 32U)) != 0U;
}

static void bit_set(uint32_t *map, uint8_t id, bool on)
{
	if (on) {
		map[id / 32U] |= BIT(id % 32U);
	} else {
		map[id / 32U] &= ~BIT(id % 32U);
	}
}

/*
 * Whether the boot process of @p id uses its default SDO (302 §7.1: it belongs to the boot
 * then). A boot that waits for an SRD to give the default SDO back does not use it.
 */
static bool booting(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_slave *s = co_mgr_slot_find(m, id);

	return s != NULL && s->booting && !s->sdo_wait;
}

/* Whether a boot of a node other than @p srd uses its default SDO now. */
static bool any_booting(struct co_mgr *m, uint8_t srd)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		const struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && s->id != srd && booting(m, s->id)) {
			return true;
		}
	}
	return false;
}

/* Look again once the boot had time to go on; the step is taken up by work_handler(). */
static void wait_boot(struct co_mgr *m)
{
	m->sdom.wait = true;
	co_node_timer_start(m->node, &m->sdom.work, co_mgr_now(m) + MS_US(BOOT_WAIT_MS));
}

/* Connection k is gone: table entry and pool pair free. */
static void conn_drop(struct co_mgr *m, uint8_t k)
{
	struct co_mgr_sdom *d = &m->sdom;

	conn_put(m, k, 0U);
	for (int j = 0; j < 2; j++) {
		if (d->cpool[k - 1U][j] != 0U) {
			pool_mark(m, d->cpool[k - 1U][j], false);
			d->cpool[k - 1U][j] = 0U;
		}
	}
	d->stale[k - 1U] = 0U;
}

/*
 * Error control of node @p id by the NMT master's means (302 §7.2.1 step 5): heartbeat when
 * our 1016h has a consumer time for it, else node guarding with 1F81h's guard time and retry
 * factor. Nothing configured: not supervised (logged).
 */
static void supervise(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_slave *s = co_mgr_slot_get(m, id);
	uint32_t as = co_mgr_assign(m, id);
	uint16_t hb = co_mgr_hb_time(m, id);

	if (s == NULL || s->hb_on || s->guarding || s->booting) {
		/* No slot (logged), already supervised, or the boot starts it. */
		return;
	}
	if (hb != 0U) {
		s->hb_ms = hb;
		co_mgr_hb_start(s, co_mgr_now(m));
	} else if ((uint16_t)(as >> 16) != 0U && (uint8_t)(as >> 8) != 0U) {
		co_mgr_guard_start(s, (uint16_t)(as >> 16), (uint8_t)(as >> 8));
	} else {
		LOG_WRN("SDO manager: no heartbeat or guarding configured for node %u", id);
	}
}

/* Whether an SRD with Req EC still has a connection to @p id (one that was not released). */
static bool reqec_conn_to(struct co_mgr *m, uint8_t id)
{
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);
		int k = srd_find(m, (uint8_t)(c >> 16));

		if ((uint8_t)c == id && k >= 0 && m->sdom.reqec[k] && m->sdom.stale[i - 1U] == 0U) {
			return true;
		}
	}
	return false;
}

/*
 * Node @p id lost a reason to be supervised by us (de-registered as an SRD, or the last
 * connection of an SRD with Req EC to it ended): its supervision stops and it leaves its
 * slot, unless another reason remains: an NMT slave of ours (its boot owns its error
 * control), a registered SRD, or a slave of a Req EC connection.
 */
static void unsupervise(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_slave *s = co_mgr_slot_find(m, id);

	if (s != NULL && (co_mgr_assign(m, id) & AS_SLAVE) == 0U && !s->booting &&
	    srd_find(m, id) < 0 && !reqec_conn_to(m, id)) {
		co_mgr_ec_stop(s);
		s->id = 0U;
	}
}

/* Slaves supervised for Req EC whose last such connection ended (302 §7.2.2). */
static void ec_review(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	for (uint8_t id = 1U; id <= 127U; id++) {
		if (bit_get(d->ecmap, id) && !reqec_conn_to(m, id)) {
			bit_set(d->ecmap, id, false);
			unsupervise(m, id);
		}
	}
}

static void start_upload(struct co_mgr *m, uint8_t node, uint16_t index, uint8_t sub)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint32_t timeout = d->op == OP_SCAN ? CONFIG_CANOPEN_MGR_SDOM_SCAN_TIMEOUT
					    : CONFIG_CANOPEN_MGR_SDO_TIMEOUT;

	d->up_node = node;
	d->up_index = index;
	d->up_sub = sub;
	if (booting(m, node)) {
		wait_boot(m);
		return;
	}
	if (co_sdo_cli_set_server(cli(m), node) != 0 ||
	    co_sdo_cli_upload_req(cli(m), index, sub, d->buf, sizeof(d->buf), CO_SDO_CLI_AUTO,
				  timeout, con, m) != 0) {
		/* Answered from the timer as a failed upload: no call back into con() here. */
		d->fake_ab = CO_SDO_AB_GENERAL;
		kick(m);
		return;
	}
	d->busy_node = node;
}

static void step_write(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	while (d->i_wr < d->n_wr) {
		struct co_mgr_sdom_wr *w = &d->wr[d->i_wr];

		sys_put_le32(w->val, d->buf);
		if (d->end == END_REL && bit_get(d->dead, w->node)) {
			/* It did not answer within this release: not asked again, left stale. */
			d->fail_side |= w->node == d->srd ? SIDE_CLIENT : SIDE_SERVER;
			d->i_wr++;
			continue;
		}
		/*
		 * "All default SDOs" is confirmed once no running boot uses one: a boot's
		 * transfer is not overlapped by the SRD's (boots that wait for it do not count).
		 */
		if ((w->node != own_id(m) && booting(m, w->node)) ||
		    (d->end == END_ALL && any_booting(m, d->srd))) {
			wait_boot(m);
			return;
		}
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
		d->busy_node = w->node;
		return;
	}
	if (d->end == END_REL && d->fail_side == 0U) {
		conn_drop(m, d->conn);
	} else if (d->end == END_REL) {
		/*
		 * A device that refused or did not answer may still use the COB-IDs: the
		 * entry and its pool pair stay until that device boots (its entries are back
		 * to their defaults) or a later 1F01h gets the writes through.
		 */
		d->stale[d->conn - 1U] = d->fail_side;
		LOG_WRN("SDO manager: connection %u kept as stale (%s side)", d->conn,
			d->fail_side == SIDE_SERVER ? "server" : "client");
	} else if (d->end == END_REG || d->end == END_ALL) {
		supervise(m, d->srd);
	} else if (d->end == END_CONN && srd_find(m, d->srd) >= 0 &&
		   d->reqec[srd_find(m, d->srd)]) {
		/* 302 §7.2.2: the SRD asked for error control of its slaves. */
		bit_set(d->ecmap, d->slave, true);
		supervise(m, d->slave);
	} else {
		/* A failure status written: nothing follows. */
	}
	ec_review(m);
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

	conn_put(m, d->conn,
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

	conn_drop(m, d->conn);
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
	} else {
		/* No server of the slave was configured for it: nothing to undo there. */
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
	conn_put(m, d->conn,
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
		d->reqec[slot] = false;
		d->srd = id;
		/* Nothing to set up: the SRD uses the default SDOs (state 2). */
		d->n_wr = 0U;
		d->i_wr = 0U;
		d->end = END_ALL;
		add_status(m, id, ST_STATE(2));
		d->op = OP_WRITE;
		step_write(m);
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
	d->reqec[slot] = (v & ST_REQ_EC) != 0U;
	d->srd = id;
	d->srv_num = srv;
	use_pair(m);
	conn_put(m, d->conn,
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
	/* Req EC echoed: the slaves of its connections will be supervised (1F11h). */
	add_status(m, id, ((uint32_t)idx << 16) | ST_STATE(1) | (v & ST_REQ_EC));
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
	d->busy_node = 0U;
	/* This transfer, and what it ends (a release, a de-registration), may free a default
	 * SDO: a waiting boot looks once this call has returned, not at its next poll.
	 */
	co_mgr_boot_sdo_recheck(m);
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
			if (d->end == END_REL && w->index != IDX_SRD_FAIL) {
				d->fail_side |= w->node == d->srd ? SIDE_CLIENT : SIDE_SERVER;
				if (ab == CO_SDO_AB_TIMEOUT) {
					bit_set(d->dead, w->node, true);
				}
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
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);
		uint16_t ci = (uint16_t)(IDX_CLI_PAR + (c >> 24));
		uint8_t srv = (uint8_t)(c >> 8);
		uint8_t s = (uint8_t)c;
		bool reg = s == own_id(m);

		/* Slave 0: everything of the SRD, its own channel to us last. */
		if ((uint8_t)(c >> 16) != srd || s == 0U || d->tried[i - 1U] ||
		    (slave != 0U && s != slave) ||
		    (slave == 0U && reg && n_conns_of(m, srd) > 1U) || (idx != 0U && ci != idx)) {
			continue;
		}
		d->tried[i - 1U] = true;
		d->n_wr = 0U;
		d->i_wr = 0U;
		d->end = END_REL;
		d->conn = i;
		d->srd = srd;
		d->fail_side = 0U;
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

/* A release starts: every entry may be taken once, every device is asked again. */
static void release_begin(struct co_mgr *m, uint32_t v)
{
	struct co_mgr_sdom *d = &m->sdom;

	(void)memset(d->tried, 0, sizeof(d->tried));
	(void)memset(d->dead, 0, sizeof(d->dead));
	d->rel_active = true;
	d->rel_val = v;
}

/*
 * Slave @p id failed (302 §7.2.2): each SRD that asked for error control learns it through
 * its 1F11h (reason 00h), then its client entry for the slave is cleared. The slave is not
 * written: a dynamic entry it still holds keeps its pool pair until it boots. False when no
 * such connection is left.
 */
static bool slave_failed_next(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);
		uint8_t srd = (uint8_t)(c >> 16);
		uint16_t ci = (uint16_t)(IDX_CLI_PAR + (c >> 24));
		int k = srd_find(m, srd);

		if ((uint8_t)c != id || srd == 0U || k < 0 || !d->reqec[k] ||
		    d->stale[i - 1U] != 0U) {
			continue;
		}
		(void)memset(d->dead, 0, sizeof(d->dead));
		d->n_wr = 0U;
		d->i_wr = 0U;
		d->end = END_REL;
		d->conn = i;
		d->srd = srd;
		d->fail_side = (uint8_t)(c >> 8) != 0U ? SIDE_SERVER : 0U;
		add_wr(m, srd, IDX_SRD_FAIL, 0U, id, 2U);
		add_wr(m, srd, ci, 1U, COB_INVALID, 4U);
		add_wr(m, srd, ci, 2U, COB_INVALID, 4U);
		d->op = OP_WRITE;
		step_write(m);
		return true;
	}
	return false;
}

/* Handle the next lost node; false when none is left. */
static bool lost_next(struct co_mgr *m)
{
	struct co_mgr_sdom *d = &m->sdom;

	for (uint8_t id = 1U; id <= 127U; id++) {
		if (!bit_get(d->lost, id)) {
			continue;
		}
		if (srd_find(m, id) >= 0) {
			/* The SRD failed: everything it held is released, it is de-registered. */
			bit_set(d->lost, id, false);
			release_begin(m, (uint32_t)id << 8);
			return true;
		}
		if (slave_failed_next(m, id)) {
			return true;
		}
		bit_set(d->lost, id, false);
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
					d->reqec[i] = false;
					unsupervise(m, (uint8_t)(d->rel_val >> 8));
					ec_review(m);
				}
			}
			continue;
		}
		if (lost_next(m)) {
			continue;
		}
		if (d->n_q > 0U) {
			struct co_mgr_sdom_req q = d->q[0];

			(void)memmove(&d->q[0], &d->q[1], (d->n_q - 1U) * sizeof(d->q[0]));
			d->n_q--;
			if (q.kind == IDX_REL_SDO) {
				release_begin(m, q.val);
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

/*
 * The SDO manager works while its NMT master is the active one (302 §4: manager functions
 * run only on the active master): 1F80h bit 0, and with the flying master the won
 * negotiation.
 */
static bool sdom_active(struct co_mgr *m)
{
	if ((co_mgr_startup_obj(m) & SU_MASTER) == 0U) {
		return false;
	}
#if defined(CONFIG_CANOPEN_MGR_FLYING)
	if ((co_mgr_startup_obj(m) & SU_FLYING) != 0U && !co_mgr_fm_active(m)) {
		return false;
	}
#endif
	return true;
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
	if (!sdom_active(m)) {
		/* Only the active manager (1F80h bit 0) hands out connections. */
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
	} else {
		/* A connection can be made: code stays 0. */
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
	if (!sdom_active(m)) {
		/* Only the active manager (1F80h bit 0) hands out connections. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (srd_find(m, (uint8_t)(v >> 8)) < 0 || (uint8_t)v > 127U ||
	    (idx != 0U && (idx < IDX_CLI_PAR || idx > 0x12FFU))) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return enqueue(m, IDX_REL_SDO, v);
}

/* 1F02h is changed by tools only while no connection uses it; 1F03h-1F06h are ours. */
static uint32_t table_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t n = conn_count(m);

	ARG_UNUSED(od);
	if (m->sdom.own_write || req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (req->info->index >= IDX_CONN) {
		return CO_SDO_AB_READONLY;
	}
	for (uint8_t i = 1U; i <= n; i++) {
		if ((uint8_t)(conn_get(m, i) >> 16) != 0U) {
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
	/* A loss handled here (next()) may free a default SDO too. */
	co_mgr_boot_sdo_recheck(m);
	if (ab != 0U) {
		m->sdom.fake_ab = 0U;
		con(cli(m), ab, 0U, m);
		return;
	}
	if (m->sdom.wait) {
		/* The step that waited for a slave's boot: try it again. */
		m->sdom.wait = false;
		if (m->sdom.op == OP_WRITE) {
			step_write(m);
		} else {
			start_upload(m, m->sdom.up_node, m->sdom.up_index, m->sdom.up_sub);
		}
		return;
	}
	next(m);
}

bool co_mgr_sdom_default_held(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_sdom *d = &m->sdom;

	if (d->busy_node == id || default_taken(m, id)) {
		return true;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SDOM_SRDS; i++) {
		/* An SRD with all default SDOs: every one but its own. */
		if (d->srds[i] != 0U && d->srds[i] != id && d->all[i]) {
			return true;
		}
	}
	return false;
}

void co_mgr_sdom_lost(struct co_mgr *m, uint8_t id)
{
	if (id == 0U || id > 127U) {
		return;
	}
	bit_set(m->sdom.lost, id, true);
	/* Handled from the timer, when the running operation has ended. */
	if (m->sdom.op == OP_NONE) {
		kick(m);
	}
}

void co_mgr_sdom_bootup(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_sdom *d = &m->sdom;
	uint8_t n = conn_count(m);

	for (uint8_t i = 1U; i <= n; i++) {
		uint32_t c = conn_get(m, i);

		if (d->stale[i - 1U] == 0U || (d->op != OP_NONE && d->conn == i)) {
			continue;
		}
		/* Its reset brought its SDO entries back to their defaults. */
		if ((uint8_t)(c >> 16) == id) {
			d->stale[i - 1U] &= (uint8_t)~SIDE_CLIENT;
		}
		if ((uint8_t)c == id) {
			d->stale[i - 1U] &= (uint8_t)~SIDE_SERVER;
		}
		if (d->stale[i - 1U] == 0U) {
			LOG_INF("SDO manager: stale connection %u freed (node %u booted)", i, id);
			conn_drop(m, i);
		}
	}
}

static void trigger_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;

	ARG_UNUSED(now_us);
	/* Only the manager (1F80h bit 0) answers; every other node ignores 6E0h. */
	if (frame->dlc != 0U || !sdom_active(m)) {
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
			.index_last = IDX_CONN_END,
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
