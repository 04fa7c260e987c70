/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Error control of the slaves (doc/mgr.md "NMT master", "Error handler and boot-up
 * handler"). One masked receiver on 700h..77Fh sees boot-ups, heartbeats and guarding
 * replies of every slave. The manager times heartbeats itself (from 1016h) because CiA 302-2
 * §4.1 starts the timeout at once, not at the first heartbeat as the CiA 301 consumer does.
 * Node guarding runs from 1F81h's guard time and retry factor (or a 1F83h request).
 *
 * On two lines (the redundancy service hands the redundant line's frames over) each slave's
 * heartbeat is also followed per line: a line where it stayed away for its consumer time is
 * reported (CO_HB_EV_LINE_LOST, naming the line) when the other line's next heartbeat shows
 * the slave alive, so a slave that died on both lines gives only the usual loss.
 */

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

uint16_t co_mgr_hb_time(struct co_mgr *m, uint8_t id)
{
	uint8_t n = (uint8_t)co_mgr_od(m, IDX_HB_CONSUMER, 0);

	for (uint8_t s = 1; s <= n && s != 0U; s++) {
		uint32_t v = co_mgr_od(m, IDX_HB_CONSUMER, s);

		if ((uint8_t)(v >> 16) == id && (v & 0xffffU) != 0U) {
			return (uint16_t)v;
		}
	}
	return 0U;
}

static void ec_indicate(struct co_mgr *m, uint8_t id, enum co_mgr_ec_event ev, uint8_t state)
{
	if (m->ec_ind != NULL) {
		m->ec_ind(m->node, id, ev, (enum co_nmt_state)state, m->ec_user_data);
	}
}

void co_mgr_send_rtr(struct co_mgr_slave *s)
{
	struct can_frame f = {
		.id = CO_NMT_EC_COB_ID + s->id,
		.dlc = 1U,
		.flags = CAN_FRAME_RTR,
	};

	(void)co_node_send(s->mgr->node, CO_ROUTE_ACTIVE, &f);
}

void co_mgr_ec_stop(struct co_mgr_slave *s)
{
	co_timer_stop(&s->ec_timer);
	s->hb_on = false;
	s->guarding = false;
	s->ec_lost = false;
}

void co_mgr_guard_start(struct co_mgr_slave *s, uint16_t gt_ms, uint8_t rf)
{
	s->guard_ms = gt_ms;
	s->guard_rf = rf;
	s->guard_missed = 0U;
	s->guard_ans = false;
	s->guard_toggle = 0xffU;
	s->guarding = true;
	s->ec_lost = false;
	co_mgr_send_rtr(s);
	co_node_timer_start(s->mgr->node, &s->ec_timer, co_mgr_now(s->mgr) + MS_US(gt_ms));
}

void co_mgr_hb_start(struct co_mgr_slave *s, uint64_t now)
{
	/* Both lines supervised from now on (302-2 §4.1); a reported loss stays reported. */
	s->line_hb_us[CO_LINE_DEFAULT] = now;
	s->line_hb_us[CO_LINE_REDUNDANT] = now;
	s->hb_on = true;
	s->ec_lost = false;
	co_node_timer_start(s->mgr->node, &s->ec_timer, now + MS_US(s->hb_ms));
}

/* CiA 302-2 §4.2 error handler. */
static void error_handler(struct co_mgr_slave *s, enum co_mgr_ec_event ev)
{
	struct co_mgr *m = s->mgr;
	uint32_t as = co_mgr_assign(m, s->id);
	uint32_t su = co_mgr_startup_obj(m);

	if ((as & AS_SLAVE) == 0U || m->startup == CO_MGR_STARTUP_IDLE) {
		return;
	}
	if ((as & AS_MANDATORY) != 0U) {
		if ((su & SU_STOP_ALL) != 0U) {
			/*
			 * Without this a startup waiting for another mandatory slave (no 1F89h)
			 * would wait forever for a boot the Stopped master cannot run (fuzzing).
			 */
			co_mgr_startup_halt_ec(s, ev == CO_MGR_EC_GUARD_LOST);
			(void)co_mgr_nmt_queue(m, CO_NMT_CS_STOP, 0U, true);
			return;
		}
		if ((su & SU_RESET_ALL) != 0U) {
			(void)co_mgr_nmt_queue(m, CO_NMT_CS_RESET_NODE, 0U, true);
			return;
		}
	}
	if (s->parked) {
		return;
	}
	if ((as & (AS_MANDATORY | AS_BOOT)) != 0U) {
		(void)co_mgr_nmt_queue(m, CO_NMT_CS_RESET_NODE, s->id, false);
		/* The boot-up handler re-boots it; without a boot-up, boot anyway (polls: B). */
		s->wait_reboot = (as & AS_BOOT) != 0U;
		if (s->wait_reboot && !s->booting) {
			co_node_timer_start(m->node, &s->timer,
					    co_mgr_now(m) + MS_US(CONFIG_CANOPEN_MGR_BOOTUP_WAIT));
		}
	}
}

static void ec_event(struct co_mgr_slave *s, enum co_mgr_ec_event ev)
{
	struct co_mgr *m = s->mgr;

	if (s->ec_lost) {
		return;
	}
	s->ec_lost = true;
	/* The next report after the loss is a change, whatever it says. */
	s->rep_state = 0U;
	LOG_WRN("%s: node %u %s", m->node->name, s->id,
		ev == CO_MGR_EC_HB_LOST ? "heartbeat lost" : "node guarding lost");
	co_mgr_set_nmt_view(s, 0x01U);
	ec_indicate(m, s->id, ev, 0x01U);
#if defined(CONFIG_CANOPEN_MGR_SDOM)
	co_mgr_sdom_lost(m, s->id);
#endif
	error_handler(s, ev);
}

void co_mgr_ec_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr_slave *s = timer->user_data;

	if (s->hb_on) {
		s->hb_on = false;
		ec_event(s, CO_MGR_EC_HB_LOST);
		return;
	}
	if (!s->guarding) {
		return;
	}
	if (s->guard_ans) {
		s->guard_missed = 0U;
		s->ec_lost = false;
	} else if (s->guard_missed < 0xffU) {
		s->guard_missed++;
	} else {
		/* Saturated: already far past the life time factor. */
	}
	if (s->guard_missed >= s->guard_rf) {
		ec_event(s, CO_MGR_EC_GUARD_LOST);
		if (!s->guarding) {
			return;
		}
	}
	s->guard_ans = false;
	co_mgr_send_rtr(s);
	co_node_timer_start(s->mgr->node, &s->ec_timer, now_us + MS_US(s->guard_ms));
}

static void line_event(struct co_mgr_slave *s, uint8_t line, enum co_hb_event what)
{
	struct co_event ev = {
		.type = CO_EV_HB,
		.hb = {.node_id = s->id,
		       .event = what,
		       .state = (enum co_nmt_state)s->rep_state,
		       .line = line},
	};

	LOG_WRN("%s: node %u heartbeat %s on line %u", s->mgr->node->name, s->id,
		what == CO_HB_EV_LINE_LOST ? "lost" : "back", line);
	(void)co_node_publish(s->mgr->node, &ev, NULL);
}

/* A heartbeat of a monitored slave on line co_node_rx_line(): follow both lines. */
static void line_hb(struct co_mgr_slave *s, uint64_t now_us)
{
	struct co_node *node = s->mgr->node;
	uint8_t l = co_node_rx_line(node);
	uint8_t o = l == CO_LINE_DEFAULT ? CO_LINE_REDUNDANT : CO_LINE_DEFAULT;

	if (!IS_ENABLED(CONFIG_CANOPEN_REDUNDANCY) ||
	    co_node_get_line(node, CO_LINE_REDUNDANT) == NULL || l >= CO_NODE_LINES) {
		return;
	}
	s->line_hb_us[l] = now_us;
	if ((s->line_lost & BIT(l)) != 0U) {
		s->line_lost &= (uint8_t)~BIT(l);
		line_event(s, l, CO_HB_EV_LINE_FOUND);
	}
	/* Silent there for longer than the consumer time, alive here: lost on that line. */
	if ((s->line_lost & BIT(o)) == 0U &&
	    !co_time_before_eq(now_us, s->line_hb_us[o] + MS_US(s->hb_ms))) {
		s->line_lost |= (uint8_t)BIT(o);
		line_event(s, o, CO_HB_EV_LINE_LOST);
	}
}

/* 302-2 §4 boot-up handler. */
static void bootup_handler(struct co_mgr *m, uint8_t id, struct co_mgr_slave *s)
{
	if (m->startup == CO_MGR_STARTUP_IDLE) {
		return;
	}
	ec_indicate(m, id, CO_MGR_EC_BOOTUP, 0U);
	if (s != NULL) {
		/* The boot-up reports Pre-operational (its own event, not a state change). */
		s->rep_state = CO_NMT_PRE_OPERATIONAL;
	}
	if (s == NULL || (co_mgr_assign(m, id) & AS_SLAVE) == 0U) {
		/* Not in 1F81h: the application's business (302-2 §3.1). */
		return;
	}
	if (s->booting) {
		/* Our own reset inside the boot: that process waits for it. */
		co_mgr_boot_ec(s, 0U);
		return;
	}
	co_mgr_ec_stop(s);
	co_mgr_set_nmt_view(s, CO_NMT_PRE_OPERATIONAL);
	if (m->startup == CO_MGR_STARTUP_RUNNING && m->phase != PH_BOOTING) {
		/* The startup is about to boot it. */
		return;
	}
	if (s->parked) {
		return;
	}
	s->wait_reboot = false;
	if ((co_mgr_assign(m, id) & AS_BOOT) != 0U) {
		co_mgr_boot_process_start(s);
	} else {
		co_timer_stop(&s->timer);
	}
}

void co_mgr_ec_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;
	uint8_t id = (uint8_t)(frame->id - CO_NMT_EC_COB_ID);
	struct co_mgr_slave *s;
	uint8_t byte;
	uint8_t state;

	if (id == 0U || id > 127U || id == m->node->node_id ||
	    (frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc < 1U) {
		return;
	}
	byte = frame->data[0];
	s = co_mgr_slot_find(m, id);
	if (byte == 0U) {
#if defined(CONFIG_CANOPEN_MGR_SDOM)
		co_mgr_sdom_bootup(m, id);
#endif
		if (s != NULL) {
			s->await_bootup = false;
		}
		bootup_handler(m, id, s);
		return;
	}
	if (s == NULL) {
		return;
	}
	state = byte & 0x7fU;
	if (s->guarding && !s->hb_on) {
		/*
		 * CiA 301 §7.2.8.3.2.1: the toggle bit alternates; a reply that repeats the
		 * last one is not an answer. The first reply sets the phase (the slave's toggle
		 * runs on from any earlier guarding, e.g. the keep-alive check).
		 */
		uint8_t tg = byte & 0x80U;

		if (s->guard_toggle == 0xffU || tg == s->guard_toggle) {
			s->guard_ans = true;
		}
		s->guard_toggle = tg ^ 0x80U;
	}
	if (s->hb_on) {
		co_node_timer_start(m->node, &s->ec_timer, now_us + MS_US(s->hb_ms));
	} else if (s->ec_lost && s->hb_ms != 0U && !s->booting) {
		/* Heartbeat back after a loss: monitor again. */
		co_mgr_hb_start(s, now_us);
	} else {
		/* A guarding reply, or a heartbeat not monitored (none configured, or its
		 * boot watches it).
		 */
	}
	if (s->hb_on) {
		line_hb(s, now_us);
	}
	if (state != s->nmt_state) {
		co_mgr_set_nmt_view(s, state);
	}
	/*
	 * The event follows what the slave reports, not the master's view: a start the master
	 * sent set the view already, its confirmation by the heartbeat is still a change.
	 */
	if (state != s->rep_state) {
		s->rep_state = state;
		ec_indicate(m, id, CO_MGR_EC_STATE, state);
	}
	if (s->booting) {
		co_mgr_boot_ec(s, byte);
	}
}
