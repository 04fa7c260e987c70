/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT master and the CiA 302-2 boot-up (doc/mgr.md): life cycle, slave slots and public
 * API. The rest lives beside it, one concern per file (mgr_internal.h lists them).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/sdo_abort.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

/* --- Slave slots ------------------------------------------------------------------------------ */

struct co_mgr_slave *co_mgr_slot_find(struct co_mgr *m, uint8_t id)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		if (m->slaves[i].id == id && id != 0U) {
			return &m->slaves[i];
		}
	}
	return NULL;
}

struct co_mgr_slave *co_mgr_slot_get(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_slave *s = co_mgr_slot_find(m, id);

	if (s != NULL) {
		return s;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		s = &m->slaves[i];
		if (s->id == 0U) {
			s->id = id;
			s->status = CO_MGR_ST_NONE;
			s->last_status = CO_MGR_ST_NONE;
			s->last_read_mask = 0U;
			(void)memset(s->last_ident, 0, sizeof(s->last_ident));
			(void)memset(&s->last_err, 0, sizeof(s->last_err));
			s->nmt_state = 0U;
			s->rep_state = 0U;
			return s;
		}
	}
	LOG_ERR("%s: no slave slot for node %u (CONFIG_CANOPEN_MGR_SLAVES)", m->node->name, id);
	return NULL;
}

/* --- Node interface ------------------------------------------------------------------------ */

static void slaves_reset(struct co_mgr *m)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		co_timer_stop(&s->timer);
		co_timer_stop(&s->ec_timer);
		s->id = 0U;
		s->booting = false;
		s->sdo_pending = false;
		s->hb_on = false;
		s->guarding = false;
		s->ec_lost = false;
		s->parked = false;
		s->wait_reboot = false;
		s->start_deferred = false;
		s->tried = false;
		s->cfg_wait = false;
		s->await_bootup = false;
		s->held = false;
		s->status = CO_MGR_ST_NONE;
		s->last_status = CO_MGR_ST_NONE;
		s->rep_state = 0U;
		s->step = CO_MGR_STEP_IDLE;
		s->attempts = 0U;
	}
}

static bool sdo_runs_in(enum co_nmt_state st)
{
	return st == CO_NMT_PRE_OPERATIONAL || st == CO_NMT_OPERATIONAL;
}

/*
 * The master is about to leave the states in which SDO runs (a Stop, or a reset, of its own
 * or from another device): abort the boot transfers on the bus while it may still send them
 * (CiA 301: no SDO in Stopped), so the slaves' servers do not wait for a timeout.
 */
static int mgr_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct co_mgr *m = user_data;

	ARG_UNUSED(node);
	if (!sdo_runs_in(ev->nmt.from) || sdo_runs_in(ev->nmt.to)) {
		return 0;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		co_mgr_boot_abort_sdo(&m->slaves[i], CO_SDO_AB_DATA_DEV_STATE);
	}
	return 0;
}

static int mgr_init(struct co_node *node)
{
	struct co_mgr *m = &node->mgr;

	(void)memset(m, 0, sizeof(*m));
	m->node = node;
	co_timer_init(&m->nmt_timer, co_mgr_nmt_timer_handler, &node->lock, m);
	co_timer_init(&m->start_timer, co_mgr_start_timer_handler, &node->lock, m);
	co_timer_init(&m->boot_timer, co_mgr_boot_timer_handler, &node->lock, m);
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		s->mgr = m;
		s->slot = (uint8_t)i;
		s->status = CO_MGR_ST_NONE;
		s->last_status = CO_MGR_ST_NONE;
		co_timer_init(&s->timer, co_mgr_slave_timer_handler, &node->lock, s);
		co_timer_init(&s->ec_timer, co_mgr_ec_timer_handler, &node->lock, s);
	}
	/* Every error-control frame 700h..77Fh; ours never comes back to us. */
	co_rx_init(&m->ec_rx, CO_NMT_EC_COB_ID, co_mgr_ec_rx, &node->lock, m);
	m->ec_rx.mask = 0x780U;
	if (co_node_rx_register(m->node, CO_LINE_DEFAULT, &m->ec_rx) != 0) {
		return -ENOSPC;
	}
	co_listener_init(&m->listener, "mgr", CO_EV_BIT(CO_EV_NMT_LEAVE), mgr_event, m);
	if (co_node_listener_add(node, &m->listener) != 0) {
		return -ENOSPC;
	}
#if defined(CONFIG_CANOPEN_MGR_FLYING)
	if (co_mgr_fm_init(m) != 0) {
		return -ENOSPC;
	}
#endif
#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
	if (co_mgr_lss_init(m) != 0) {
		return -ENOSPC;
	}
#endif
#if defined(CONFIG_CANOPEN_MGR_SDOM)
	if (co_mgr_sdom_init(m) != 0) {
		return -ENOSPC;
	}
#endif
	return co_mgr_od_hooks_register(m);
}

static void mgr_reset_comm(struct co_node *node)
{
	struct co_mgr *m = &node->mgr;

	co_timer_stop(&m->nmt_timer);
	co_timer_stop(&m->start_timer);
	co_timer_stop(&m->boot_timer);
	m->nmt_head = 0U;
	m->nmt_count = 0U;
	m->nmt_next_us = 0U;
	m->startup = CO_MGR_STARTUP_IDLE;
	m->phase = PH_NONE;
	slaves_reset(m);
	for (uint8_t id = 1; id <= 127U; id++) {
		if (id != node->node_id && (co_mgr_assign(m, id) & AS_SLAVE) != 0U) {
			(void)co_mgr_slot_get(m, id);
		}
	}
	m->boot_pending = true;
}

static void mgr_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	struct co_mgr *m = &node->mgr;

	ARG_UNUSED(from);
	switch (to) {
	case CO_NMT_INITIALISING:
		co_timer_stop(&m->nmt_timer);
		co_timer_stop(&m->start_timer);
		co_timer_stop(&m->boot_timer);
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			co_timer_stop(&m->slaves[i].timer);
			co_timer_stop(&m->slaves[i].ec_timer);
			m->slaves[i].booting = false;
			m->slaves[i].sdo_pending = false;
			m->slaves[i].held = false;
		}
		break;
	case CO_NMT_PRE_OPERATIONAL:
	case CO_NMT_OPERATIONAL:
		if (to == CO_NMT_PRE_OPERATIONAL && m->boot_pending) {
			/* Run the startup after the boot-up message, from the line thread. */
			m->boot_pending = false;
			m->phase = PH_BEGIN;
			co_node_timer_start(m->node, &m->start_timer, co_mgr_now(m));
		}
		/* Back from Stopped: the attempts cut or held there start now. */
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			co_mgr_boot_resume(&m->slaves[i]);
		}
		break;
	case CO_NMT_STOPPED:
		/*
		 * Boots stop with the SDO clients; supervision goes on. Each running attempt ends
		 * (B, indicated) and starts again when the master runs again, so the startup
		 * always ends (doc/mgr.md, "Decisions").
		 */
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			co_mgr_boot_stopped(&m->slaves[i]);
		}
		break;
	default:
		break;
	}
}

const struct co_service co_service_mgr = {
	.name = "mgr",
	.init = mgr_init,
	.reset_comm = mgr_reset_comm,
	.set_state = mgr_set_state,
};

/* --- API --------------------------------------------------------------------------------- */

int co_mgr_nmt_req(struct co_node *node, uint8_t id, enum co_nmt_cs cs)
{
	struct co_mgr *m = &node->mgr;
	int err;

	if (id > 127U || !co_mgr_cs_valid((uint8_t)cs)) {
		return -EINVAL;
	}
	co_node_lock(node);
	if ((co_mgr_startup_obj(m) & SU_MASTER) == 0U) {
		err = -EPERM;
#if defined(CONFIG_CANOPEN_MGR_FLYING)
	} else if ((co_mgr_startup_obj(m) & SU_FLYING) != 0U && !co_mgr_fm_active(m)) {
		/* A flying-master candidate that is not the active master is a slave. */
		err = -EPERM;
#endif
	} else if (id == node->node_id) {
		err = co_nmt_req(node, cs);
	} else {
		err = co_mgr_nmt_queue(m, (uint8_t)cs, id, id == 0U);
		if (err == 0 && id != 0U) {
			struct co_mgr_slave *s = co_mgr_slot_find(m, id);

			if (s != NULL) {
				s->parked = true;
			}
		}
	}
	co_node_unlock(node);
	return err;
}

int co_mgr_boot_req(struct co_node *node, uint8_t id)
{
	struct co_mgr *m = &node->mgr;
	struct co_mgr_slave *s;
	int err = 0;

	if (id == 0U || id > 127U || id == node->node_id) {
		return -EINVAL;
	}
	co_node_lock(node);
	s = co_mgr_slot_get(m, id);
	if (s == NULL) {
		err = -ENOSPC;
	} else if (s->booting) {
		err = -EALREADY;
	} else {
		s->parked = false;
		co_mgr_boot_process_start(s);
	}
	co_node_unlock(node);
	return err;
}

int co_mgr_get_boot(struct co_node *node, uint8_t id, struct co_mgr_boot_info *info)
{
	struct co_mgr *m = &node->mgr;
	struct co_mgr_slave *s;
	uint32_t as;
	int err = 0;

	co_node_lock(node);
	s = co_mgr_slot_find(m, id);
	as = id != 0U && id <= 127U ? co_mgr_assign(m, id) : 0U;
	if (s == NULL) {
		err = -ENOENT;
	} else {
		*info = (struct co_mgr_boot_info){
			.node_id = id,
			.assigned = (as & AS_SLAVE) != 0U,
			.mandatory = (as & AS_MANDATORY) != 0U,
			.booting = s->booting,
			.status = s->last_status,
			.device_type = s->last_ident[0],
			.identity = {s->last_ident[1], s->last_ident[2], s->last_ident[3],
				     s->last_ident[4]},
			.read_mask = s->last_read_mask,
			.attempts = s->attempts,
			.started_us = s->started_us,
			.finished_us = s->finished_us,
			.nmt_state = s->nmt_state,
			.error = s->last_err,
		};
	}
	co_node_unlock(node);
	return err;
}

enum co_mgr_startup co_mgr_get_startup(struct co_node *node)
{
	enum co_mgr_startup st;

	co_node_lock(node);
	st = (enum co_mgr_startup)node->mgr.startup;
	co_node_unlock(node);
	return st;
}

void co_mgr_release(struct co_node *node, uint8_t id)
{
	struct co_mgr_slave *s;

	co_node_lock(node);
	s = co_mgr_slot_find(&node->mgr, id);
	if (s != NULL) {
		s->parked = false;
	}
	co_node_unlock(node);
}

void co_mgr_set_boot_ind(struct co_node *node, co_mgr_boot_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.boot_ind = cb;
	node->mgr.boot_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_startup_ind(struct co_node *node, co_mgr_startup_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.startup_ind = cb;
	node->mgr.startup_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_ec_ind(struct co_node *node, co_mgr_ec_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.ec_ind = cb;
	node->mgr.ec_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_sw_ind(struct co_node *node, co_mgr_sw_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.sw_ind = cb;
	node->mgr.sw_user_data = user_data;
	co_node_unlock(node);
}
