/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The master's own objects (doc/mgr.md "Request NMT 1F82h and request guarding 1F83h"):
 * 1F80h and 1F81h refuse the bits we do not support, a 1F81h write assigns or releases a
 * slave slot, 1F82h and 1F83h writes are commands carried out by their hooks, and 1F82h
 * reads return the master's view of each slave's state, which the manager keeps written.
 */

#include <zephyr/kernel.h>

#include <canopen/sdo_abort.h>

#include "mgr_internal.h"

void co_mgr_set_nmt_view(struct co_mgr_slave *s, uint8_t v)
{
	struct co_mgr *m = s->mgr;

	s->nmt_state = v;
	/* Our own write of the read value is not a request: the hook lets it through. */
	m->od_update = true;
	(void)co_od_write(&m->node->od, IDX_REQ_NMT, s->id, &v, 1, CO_OD_WRITER_APP);
	m->od_update = false;
}

static uint8_t req_cs(uint8_t v)
{
	switch (v & 0x7fU) {
	case 0x04:
		return CO_NMT_CS_STOP;
	case 0x05:
		return CO_NMT_CS_START;
	case 0x06:
		return CO_NMT_CS_RESET_NODE;
	case 0x07:
		return CO_NMT_CS_RESET_COMMUNICATION;
	case 0x7f:
		return CO_NMT_CS_ENTER_PRE_OPERATIONAL;
	default:
		return 0U;
	}
}

static bool is_master(struct co_mgr *m)
{
	return (co_mgr_startup_obj(m) & SU_MASTER) != 0U && m->startup != CO_MGR_STARTUP_IDLE;
}

static uint32_t req_nmt_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t sub = req->info->sub;
	uint8_t v = (uint8_t)co_od_req_uint(req);
	bool excl = v == 0x84U || v == 0x85U || v == 0x86U || v == 0x87U || v == 0x8fU;
	uint8_t cs = req_cs(v);

	if (m->od_update) {
		return 0U;
	}
	if (sub == 0U) {
		return CO_SDO_AB_READONLY;
	}
	if (cs == 0U || (v >= 0x80U && !excl) || (excl && sub != ALL_NODES)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (excl && req->writer != CO_OD_WRITER_APP) {
		/* 302-2 §6.4: the requester must be known; over SDO it is not. */
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (!is_master(m)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (sub == ALL_NODES) {
		if (excl) {
			/* Individual frames: a broadcast plus "undo" cannot undo a reset. */
			for (uint8_t id = 1; id <= 127U; id++) {
				if (id != m->node->node_id &&
				    co_mgr_nmt_queue(m, cs, id, false) != 0) {
					return CO_SDO_AB_DATA_DEV_STATE;
				}
			}
		} else if (co_mgr_nmt_queue(m, cs, 0U, true) != 0) {
			return CO_SDO_AB_DATA_DEV_STATE;
		} else {
			/* The broadcast is queued. */
		}
		return CO_OD_HANDLED;
	}
	if (sub == m->node->node_id) {
		(void)co_nmt_req(m->node, (enum co_nmt_cs)cs);
		return CO_OD_HANDLED;
	}
	{
		struct co_mgr_slave *s = co_mgr_slot_get(m, sub);

		if (s != NULL) {
			/* No automatic re-boot of a slave an operator parked (302 §5.4). */
			s->parked = true;
		}
	}
	if (co_mgr_nmt_queue(m, cs, sub, false) != 0) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	return CO_OD_HANDLED;
}

static uint32_t guard_one(struct co_mgr *m, uint8_t id, uint8_t v)
{
	struct co_mgr_slave *s;
	uint32_t as = co_mgr_assign(m, id);

	if (id == m->node->node_id) {
		return 0U;
	}
	if (v == 0U) {
		s = co_mgr_slot_find(m, id);
		if (s != NULL && s->guarding) {
			co_mgr_ec_stop(s);
		}
		return 0U;
	}
	if ((uint16_t)(as >> 16) == 0U || (uint8_t)(as >> 8) == 0U) {
		/* Guard time and retry factor come from 1F81h. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	s = co_mgr_slot_get(m, id);
	if (s == NULL) {
		return CO_SDO_AB_NO_RESOURCE;
	}
	co_timer_stop(&s->ec_timer);
	s->hb_on = false;
	co_mgr_guard_start(s, (uint16_t)(as >> 16), (uint8_t)(as >> 8));
	return 0U;
}

static uint32_t req_guard_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t sub = req->info->sub;
	uint8_t v = (uint8_t)co_od_req_uint(req);
	uint32_t ab = 0U;

	if (m->od_update) {
		return 0U;
	}
	if (sub == 0U) {
		return CO_SDO_AB_READONLY;
	}
	if (v > 1U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (!is_master(m)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (sub != ALL_NODES) {
		return guard_one(m, sub, v);
	}
	/* All or nothing: every assigned slave needs its guard time and retry factor. */
	for (uint8_t id = 1; id <= 127U && v == 1U; id++) {
		uint32_t as = co_mgr_assign(m, id);

		if (id != m->node->node_id && (as & AS_SLAVE) != 0U &&
		    ((uint16_t)(as >> 16) == 0U || (uint8_t)(as >> 8) == 0U)) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
	}
	for (uint8_t id = 1; id <= 127U && ab == 0U; id++) {
		if ((co_mgr_assign(m, id) & AS_SLAVE) != 0U) {
			ab = guard_one(m, id, v);
		}
	}
	if (ab == 0U) {
		/* Reads of the per-node entries follow. */
		m->od_update = true;
		for (uint8_t id = 1; id <= 127U; id++) {
			if ((co_mgr_assign(m, id) & AS_SLAVE) != 0U) {
				(void)co_od_write(od, IDX_REQ_GUARD, id, &v, 1, CO_OD_WRITER_APP);
			}
		}
		m->od_update = false;
	}
	return ab;
}

/* 302-2 §6.2/§6.3: unsupported bits are refused. */
static uint32_t startup_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t ok =
		SU_MASTER | SU_START_ALL | SU_NO_SELF_OP | SU_NO_START | SU_RESET_ALL | SU_STOP_ALL;

	if (IS_ENABLED(CONFIG_CANOPEN_MGR_FLYING)) {
		ok |= SU_FLYING;
	}
	if ((v & ~ok) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static uint32_t assign_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint32_t v = (uint32_t)co_od_req_uint(req);

	if (req->info->sub != 0U && (v & BIT(1)) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

/* A slave assigned at run time gets a slot; one removed loses its supervision. */
static void assign_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t id = req->info->sub;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	struct co_mgr_slave *s;

	if (id == 0U || id > 127U || id == m->node->node_id) {
		return;
	}
	if ((v & AS_SLAVE) != 0U) {
		(void)co_mgr_slot_get(m, id);
		return;
	}
	s = co_mgr_slot_find(m, id);
	if (s != NULL && !s->booting && !s->sdo_pending) {
		co_mgr_ec_stop(s);
		co_timer_stop(&s->timer);
		s->id = 0U;
	}
}

int co_mgr_od_hooks_register(struct co_mgr *m)
{
	/* On the stack: user_data is this node's manager (no file-scope state). */
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_STARTUP,
			.index_last = IDX_STARTUP,
			.sub_first = 0,
			.sub_last = 0,
			.validate = startup_validate,
			.user_data = m,
		},
		{
			.index_first = IDX_ASSIGN,
			.index_last = IDX_ASSIGN,
			.sub_first = 0,
			.sub_last = 127,
			.validate = assign_validate,
			.notify = assign_notify,
			.user_data = m,
		},
		{
			.index_first = IDX_REQ_NMT,
			.index_last = IDX_REQ_NMT,
			.sub_first = 0,
			.sub_last = ALL_NODES,
			.validate = req_nmt_validate,
			.user_data = m,
		},
		{
			.index_first = IDX_REQ_GUARD,
			.index_last = IDX_REQ_GUARD,
			.sub_first = 0,
			.sub_last = ALL_NODES,
			.validate = req_guard_validate,
			.user_data = m,
		},
	};

	return co_od_hooks_register(&m->node->od, hooks, ARRAY_SIZE(hooks));
}
