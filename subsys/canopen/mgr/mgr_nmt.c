/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT command queue of the master (doc/mgr.md "NMT master"). Every command (API, 1F82h,
 * boot-up, error handler) goes through one FIFO so that commands are sent in request order
 * and at least 102Ah apart; none is dropped. Broadcasts "including self" are applied to our
 * own NMT state once sent, because the controller never receives its own frames.
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

bool co_mgr_cs_valid(uint8_t cs)
{
	return cs == CO_NMT_CS_START || cs == CO_NMT_CS_STOP ||
	       cs == CO_NMT_CS_ENTER_PRE_OPERATIONAL || cs == CO_NMT_CS_RESET_NODE ||
	       cs == CO_NMT_CS_RESET_COMMUNICATION;
}

/* The state a command leaves its targets in, until their heartbeat says otherwise. */
static void nmt_expect(struct co_mgr *m, uint8_t cs, uint8_t id)
{
	uint8_t v;

	switch (cs) {
	case CO_NMT_CS_START:
		v = CO_NMT_OPERATIONAL;
		break;
	case CO_NMT_CS_STOP:
		v = CO_NMT_STOPPED;
		break;
	case CO_NMT_CS_ENTER_PRE_OPERATIONAL:
		v = CO_NMT_PRE_OPERATIONAL;
		break;
	default:
		v = 0U; /* reset: unknown until the boot-up */
		break;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (id == 0U || id == s->id) && !s->ec_lost) {
			co_mgr_set_nmt_view(s, v);
		}
	}
}

/* A reset went out: the slave's SDO server is back with its boot-up (the boot waits for it). */
static void nmt_reset_sent(struct co_mgr *m, uint8_t cs, uint8_t id, uint64_t now)
{
	if (cs != CO_NMT_CS_RESET_NODE && cs != CO_NMT_CS_RESET_COMMUNICATION) {
		return;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (id == 0U || id == s->id)) {
			s->await_bootup = true;
			s->reset_us = now;
		}
	}
}

static void nmt_kick(struct co_mgr *m)
{
	struct co_node *node = m->node;
	uint64_t now = co_mgr_now(m);
	uint64_t inhibit_us = (uint64_t)(uint16_t)co_mgr_od(m, IDX_INHIBIT, 0) * 100U;

	while (m->nmt_count > 0U) {
		struct co_mgr_nmt_cmd cmd = m->nmtq[m->nmt_head];
		struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2U};

		if (inhibit_us != 0U && !co_time_before_eq(m->nmt_next_us, now)) {
			co_node_timer_start(m->node, &m->nmt_timer, m->nmt_next_us);
			return;
		}
		if (co_node_tx_space(m->node, CO_ROUTE_ACTIVE) <= 0) {
			/* Never drop a command: wait for the queue to drain. */
			co_node_timer_start(m->node, &m->nmt_timer, now + MS_US(1));
			return;
		}
		m->nmt_head = (uint16_t)((m->nmt_head + 1U) % CONFIG_CANOPEN_MGR_NMT_QUEUE);
		m->nmt_count--;
		f.data[0] = cmd.cs;
		f.data[1] = cmd.id;
		(void)co_node_send(node, CO_ROUTE_ACTIVE, &f);
		m->nmt_next_us = now + inhibit_us;
		nmt_expect(m, cmd.cs, cmd.id);
		nmt_reset_sent(m, cmd.cs, cmd.id, now);
		if (cmd.self) {
			/* May reset us (the queue with it): nothing of ours is valid afterwards. */
			(void)co_nmt_req(node, (enum co_nmt_cs)cmd.cs);
			if (cmd.cs == CO_NMT_CS_RESET_NODE ||
			    cmd.cs == CO_NMT_CS_RESET_COMMUNICATION) {
				return;
			}
		}
	}
	if (m->phase == PH_RESETTING) {
		co_mgr_startup_resets_sent(m);
	}
}

int co_mgr_nmt_queue(struct co_mgr *m, uint8_t cs, uint8_t id, bool self)
{
	uint16_t tail;

	if (m->nmt_count >= CONFIG_CANOPEN_MGR_NMT_QUEUE) {
		LOG_ERR("%s: NMT queue full", m->node->name);
		return -ENOSPC;
	}
	tail = (uint16_t)((m->nmt_head + m->nmt_count) % CONFIG_CANOPEN_MGR_NMT_QUEUE);
	m->nmtq[tail] = (struct co_mgr_nmt_cmd){.cs = cs, .id = id, .self = self};
	m->nmt_count++;
	if (!co_timer_is_armed(&m->nmt_timer)) {
		nmt_kick(m);
	}
	return 0;
}

void co_mgr_nmt_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	nmt_kick(timer->user_data);
}
