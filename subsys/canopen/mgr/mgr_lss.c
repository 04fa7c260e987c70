/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Node-IDs for missing slaves by LSS (CONFIG_CANOPEN_MGR_LSS_ASSIGN, doc/mgr.md).
 *
 * It follows the manager's own boot results (CO_EV_BOOT): a slave whose boot ended with B
 * is queued once per reset of the master. One search at a time: fastscan with the known
 * parts of 1F85h/1F86h/1F88h, the revision checked as the boot checks 1F87h, then configure
 * node-ID, store, switch global to waiting. The device boots by itself (CiA 305: a device
 * without node-ID that got one resets its communication on the switch to waiting); the
 * manager's retry of B then boots it as any slave. Only the parts with known values are
 * fixed, so a device of another kind is never given the node-ID.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/logging/log.h>

#include <canopen/lss_master.h>
#include <canopen/mgr_lss.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_EXP_PRODUCT  0x1F86U
#define IDX_EXP_REVISION 0x1F87U
#define IDX_EXP_SERIAL   0x1F88U

enum {
	STEP_IDLE,
	STEP_SCAN,
	STEP_NODE_ID,
	STEP_STORE,
};

static struct co_mgr_lss *ml(struct co_mgr *m)
{
	return &m->lss;
}

static bool bit_get(const uint32_t *set, uint8_t id)
{
	return (set[id / 32U] & BIT(id % 32U)) != 0U;
}

static void bit_put(uint32_t *set, uint8_t id, bool on)
{
	if (on) {
		set[id / 32U] |= BIT(id % 32U);
	} else {
		set[id / 32U] &= ~BIT(id % 32U);
	}
}

static bool searchable(struct co_mgr *m, uint8_t id)
{
	return id >= 1U && id <= 127U && id != co_node_id(m->node) &&
	       (co_mgr_assign(m, id) & AS_SLAVE) != 0U && co_mgr_od(m, IDX_EXP_VENDOR, id) != 0U;
}

/* CiA 302-2: same major revision (high 16 bits), minor at least the expected one. */
static bool revision_ok(uint32_t expected, uint32_t actual)
{
	return expected == 0U ||
	       ((actual >> 16) == (expected >> 16) && (actual & 0xFFFFU) >= (expected & 0xFFFFU));
}

static void next_search(struct co_mgr *m);

static void report(struct co_mgr *m, int err, const struct co_lss_address *addr)
{
	struct co_mgr_lss *l = ml(m);
	uint8_t id = l->id;

	if (err == 0) {
		LOG_INF("%s: LSS: node %u found (serial %08Xh), node-ID given", m->node->name, id,
			addr->part[3]);
	} else {
		LOG_WRN("%s: LSS: node %u not assigned (%d)", m->node->name, id, err);
	}
	l->id = 0U;
	l->step = STEP_IDLE;
	if (l->ind != NULL) {
		l->ind(m->node, id, err, addr, l->ind_user_data);
	}
	next_search(m);
}

static void lss_con(struct co_node *node, int err, const struct co_lss_master_result *res,
		    void *user_data)
{
	struct co_mgr *m = user_data;
	struct co_mgr_lss *l = ml(m);
	int e;

	switch (l->step) {
	case STEP_SCAN:
		if (err != 0) {
			report(m, err == -EIO ? -ENODEV : err, NULL);
			return;
		}
		l->found = res->address;
		if (!revision_ok(co_mgr_od(m, IDX_EXP_REVISION, l->id), l->found.part[2])) {
			/* In configuration now: back to waiting, still without node-ID. */
			(void)co_lss_master_switch_global(node, CO_LSS_MODE_WAITING);
			report(m, -EILSEQ, &l->found);
			return;
		}
		l->step = STEP_NODE_ID;
		e = co_lss_master_config_node_id_req(node, l->id, 0U, lss_con, m);
		break;
	case STEP_NODE_ID:
		if (err != 0) {
			(void)co_lss_master_switch_global(node, CO_LSS_MODE_WAITING);
			report(m, err, &l->found);
			return;
		}
		l->step = STEP_STORE;
		e = co_lss_master_store_req(node, 0U, lss_con, m);
		break;
	case STEP_STORE:
		if (err != 0) {
			LOG_WRN("%s: LSS: node %u could not store its node-ID (%d, error %u)",
				node->name, l->id, err, res->lss_err);
		}
		/* The device resets its communication and sends its boot-up. */
		e = co_lss_master_switch_global(node, CO_LSS_MODE_WAITING);
		report(m, e, &l->found);
		return;
	default:
		return;
	}
	if (e != 0) {
		(void)co_lss_master_switch_global(node, CO_LSS_MODE_WAITING);
		report(m, e, &l->found);
	}
}

static void next_search(struct co_mgr *m)
{
	struct co_mgr_lss *l = ml(m);
	struct co_lss_address known = {0};
	uint8_t mask = BIT(CO_LSS_FASTSCAN_VENDOR);
	int err;

	if (l->step != STEP_IDLE) {
		return;
	}
	for (uint8_t id = 1U; id <= 127U; id++) {
		if (!bit_get(l->pending, id)) {
			continue;
		}
		bit_put(l->pending, id, false);
		if (!searchable(m, id)) {
			continue;
		}
		known.part[0] = co_mgr_od(m, IDX_EXP_VENDOR, id);
		known.part[1] = co_mgr_od(m, IDX_EXP_PRODUCT, id);
		known.part[3] = co_mgr_od(m, IDX_EXP_SERIAL, id);
		mask |= known.part[1] != 0U ? BIT(CO_LSS_FASTSCAN_PRODUCT) : 0U;
		mask |= known.part[3] != 0U ? BIT(CO_LSS_FASTSCAN_SERIAL) : 0U;
		l->id = id;
		l->step = STEP_SCAN;
		LOG_INF("%s: LSS: searching node %u (vendor %08Xh product %08Xh serial %08Xh)",
			m->node->name, id, known.part[0], known.part[1], known.part[3]);
		err = co_lss_master_fastscan_req(m->node, &known, mask, 0U, lss_con, m);
		if (err != 0) {
			/* The application's own LSS request runs: try at the next B. */
			bit_put(l->searched, id, false);
			l->id = 0U;
			l->step = STEP_IDLE;
			LOG_WRN("%s: LSS: cannot search node %u now (%d)", m->node->name, id, err);
		}
		return;
	}
}

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct co_mgr *m = user_data;
	struct co_mgr_lss *l = ml(m);
	uint8_t id;

	if (ev->type == CO_EV_NMT_RESET) {
		/* A new startup: every slave may be searched again. */
		(void)memset(l->searched, 0, sizeof(l->searched));
		(void)memset(l->pending, 0, sizeof(l->pending));
		return 0;
	}
	id = ev->boot.node_id;
	if (ev->boot.status != CO_MGR_ST_B || id > 127U || bit_get(l->searched, id) ||
	    !searchable(m, id)) {
		return 0;
	}
	bit_put(l->searched, id, true);
	bit_put(l->pending, id, true);
	next_search(m);
	return 0;
}

int co_mgr_lss_init(struct co_mgr *m)
{
	struct co_mgr_lss *l = ml(m);

	co_listener_init(&l->listener, "mgr_lss",
			 CO_EV_BIT(CO_EV_BOOT) | CO_EV_BIT(CO_EV_NMT_RESET), on_event, m);
	return co_node_listener_add(m->node, &l->listener);
}

void co_mgr_set_lss_ind(struct co_node *node, co_mgr_lss_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.lss.ind = cb;
	node->mgr.lss.ind_user_data = user_data;
	co_node_unlock(node);
}

int co_mgr_lss_search(struct co_node *node, uint8_t id)
{
	struct co_mgr *m = &node->mgr;
	int err = 0;

	co_node_lock(node);
	if (!searchable(m, id)) {
		err = -EINVAL;
	} else {
		bit_put(ml(m)->searched, id, true);
		bit_put(ml(m)->pending, id, true);
		next_search(m);
	}
	co_node_unlock(node);
	return err;
}
