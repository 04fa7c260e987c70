/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Flying master (CiA 302 §5.5, CiA 302-2 §3.7 and §5.2-§5.5) and NMT master detection of a
 * self-starting device (CiA 302-2 §5.1), doc/flying-master.md.
 *
 * One const table of states x events gives each transition's action and next state. The
 * manager's NMT startup (mgr_startup.c) asks us first: a candidate (1F80h bits 0 and 5) only
 * runs the startup once it won the negotiation; while another node is the active master it
 * stays a slave with the manager's functions off (startup IDLE: no boot-ups handled, 1F82h
 * and 1F83h refused, no NMT commands). 1F80h itself is never changed (302-2 Table 15).
 *
 * Every master change comes with a network-wide Reset Communication, so no state is handed
 * over: the winner simply runs the NMT startup from its beginning (302 §5.5).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/sdo_abort.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_FM_TIMING 0x1F90U
#define IDX_SS_TIMING 0x1F91U

#define COB_MASTER_ID  0x071U /* active master / negotiation result: prio, node-ID */
#define COB_TRIGGER    0x072U /* start negotiation (time-slot trigger) */
#define COB_ASK_ACTIVE 0x073U /* who is the active master? */
#define COB_CAPABLE    0x074U /* I am master-capable */
#define COB_ASK_CAPAB  0x075U /* is any master-capable device present? */
#define COB_FORCE      0x076U /* force negotiation */

/* 1F90h sub-indexes and their defaults (302 §5.5.6; sized for 125 kbit/s). */
enum {
	FT_DETECT = 1,    /* timeout for the detection of an active master: 100 ms */
	FT_DELAY = 2,     /* negotiation time delay: 500 ms */
	FT_PRIO = 3,      /* priority 0 high, 1 medium, 2 low */
	FT_PRIO_SLOT = 4, /* priority time slot: 1500 ms */
	FT_NODE_SLOT = 5, /* node time slot: 10 ms */
	FT_CYCLE = 6,     /* multiple master detect cycle: 4000 + 10 x node-ID ms */
};

#define PRIO_LOWEST 2U

/* Events of the state table. */
enum fm_ev {
	E_START, /* the NMT startup began (after our boot-up) */
	E_TIMER, /* the state's wait ended */
	E_071,   /* an active master / a negotiation result: ev->prio, ev->id */
	E_072,
	E_073,
	E_074,
	E_076,
	E_HB_LOST,   /* the active master's heartbeat was lost */
	E_OPER,      /* we entered Operational (a self-starter's start came from elsewhere) */
	E_RECOVERED, /* our controller came back from bus-off */
	E_COUNT,
};

struct fm_ev_data {
	enum fm_ev type;
	uint8_t prio;
	uint8_t id;
};

#define KEEP 0xffU /* an action's result: take the table's next state */

typedef uint8_t (*fm_action_t)(struct co_mgr *m, const struct fm_ev_data *ev);

/* --- Objects ---------------------------------------------------------------------------------- */

static uint16_t fm_obj(struct co_mgr *m, uint8_t sub)
{
	static const uint16_t dflt[] = {0, 100, 500, 1, 1500, 10, 0};
	uint32_t v = co_od_uint(&m->node->od, IDX_FM_TIMING, sub, dflt[sub]);

	if (sub == FT_CYCLE && v == 0U) {
		/* 302 §5.5.6: 4000 + 10 x node-ID, so every master's cycle differs (§5.4). */
		v = 4000U + 10U * m->node->node_id;
	}
	return (uint16_t)v;
}

static uint16_t ss_obj(struct co_mgr *m, uint8_t sub)
{
	static const uint16_t dflt[] = {0, 100, 500, 15};

	return (uint16_t)co_od_uint(&m->node->od, IDX_SS_TIMING, sub, dflt[sub]);
}

static uint8_t own_prio(struct co_mgr *m)
{
	uint16_t p = fm_obj(m, FT_PRIO);

	return p > PRIO_LOWEST ? (uint8_t)PRIO_LOWEST : (uint8_t)p;
}

/* The negotiation's waiting time W = priority x 1F90h:04 + node-ID x 1F90h:05 [ms]. */
static uint32_t wait_ms(struct co_mgr *m)
{
	return (uint32_t)own_prio(m) * fm_obj(m, FT_PRIO_SLOT) +
	       (uint32_t)m->node->node_id * fm_obj(m, FT_NODE_SLOT);
}

/* Whether (p1, id1) beats (p2, id2): higher priority (lower value), then lower node-ID. */
static bool beats(uint8_t p1, uint8_t id1, uint8_t p2, uint8_t id2)
{
	return p1 < p2 || (p1 == p2 && id1 < id2);
}

/* --- Helpers ---------------------------------------------------------------------------------- */

static void send(struct co_mgr *m, uint16_t cob, uint8_t dlc, uint8_t b0, uint8_t b1)
{
	struct can_frame f = {.id = cob, .dlc = dlc, .data = {b0, b1}};

	(void)co_node_send(m->node, CO_ROUTE_DEFAULT, &f);
}

static void arm(struct co_mgr *m, uint32_t ms)
{
	co_node_timer_start(m->node, &m->fm.timer, co_mgr_now(m) + MS_US(ms));
}

static void publish(struct co_mgr *m, enum co_mgr_fm_event what)
{
	struct co_event ev = {
		.type = CO_EV_FM,
		.fm = {.what = (uint8_t)what,
		       .master_id = m->fm.master_id,
		       .priority = m->fm.master_prio,
		       .time_us = co_mgr_now(m)},
	};

	m->fm.changed_us = ev.fm.time_us;
	(void)co_node_publish(m->node, &ev, NULL);
}

/* Reset Communication of every node, ourselves included (302 §5.5.2/§5.5.4): the network
 * restarts from a clean warm state and everyone negotiates again.
 */
static void reset_all(struct co_mgr *m)
{
	/*
	 * Our controller does not receive its own frame, so we reset ourselves; first, since a
	 * reset withdraws what the node still has queued (the frame could be held by a busy bus).
	 */
	(void)co_nmt_req(m->node, CO_NMT_CS_RESET_COMMUNICATION);
	send(m, 0x000, 2, CO_NMT_CS_RESET_COMMUNICATION, 0x00);
}

static void hb_watch(struct co_mgr *m, uint8_t id)
{
	uint16_t t = co_mgr_hb_time(m, id);

	/* 302 §5.5.4: 1016h when the tool configured it, else our own supervision time. */
	m->fm.hb_ms = t != 0U ? t : (uint16_t)CONFIG_CANOPEN_MGR_FLYING_HB_TIME;
	if (co_node_rx_set_id(m->node, CO_LINE_DEFAULT, &m->fm.hb_rx, 0x700U + id) != 0) {
		LOG_ERR("%s: no receiver for the master's heartbeat", m->node->name);
	}
	/* The timeout runs at once: a master that never sends a heartbeat is lost too. */
	co_node_timer_start(m->node, &m->fm.hb_timer, co_mgr_now(m) + MS_US(m->fm.hb_ms));
}

static void hb_unwatch(struct co_mgr *m)
{
	co_timer_stop(&m->fm.hb_timer);
	co_rx_unregister(&m->fm.hb_rx);
}

/* --- Actions ---------------------------------------------------------------------------------- */

static uint8_t a_start(struct co_mgr *m, const struct fm_ev_data *ev)
{
	uint32_t su = co_mgr_startup_obj(m);

	ARG_UNUSED(ev);
	m->fm.seen_072 = false;
	m->fm.master_id = 0U;
	if ((su & (SU_MASTER | SU_FLYING)) == (SU_MASTER | SU_FLYING)) {
		/* F1: even out different initialisation times. */
		arm(m, fm_obj(m, FT_DELAY));
		return CO_MGR_FM_DELAY;
	}
	/* 1F80h = 02h: a startup-capable device asks first (302-2 §5.1). */
	arm(m, ss_obj(m, 2));
	return CO_MGR_FM_SS_DELAY;
}

/* F2: who is the active master? */
static uint8_t a_ask(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	send(m, COB_ASK_ACTIVE, 0, 0, 0);
	arm(m, fm_obj(m, FT_DETECT));
	return KEEP;
}

static uint8_t negotiate(struct co_mgr *m)
{
	if (!m->fm.seen_072) {
		/* A device that saw 072h already does not send it again. */
		send(m, COB_TRIGGER, 0, 0, 0);
	}
	arm(m, wait_ms(m));
	return CO_MGR_FM_NEGOTIATE;
}

/* Nobody answered 073h: at a cold boot reset everyone first, at a warm boot negotiate. */
static uint8_t a_no_master(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	if (!m->fm.warm) {
		/* Clean warm state everywhere: no PDO traffic skews the time slots. */
		reset_all(m);
		return KEEP; /* the reset started us again */
	}
	return negotiate(m);
}

/* Someone's 072h: the round starts (or starts again, timers re-synchronise). */
static uint8_t a_072(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	m->fm.seen_072 = true;
	arm(m, wait_ms(m));
	return CO_MGR_FM_NEGOTIATE;
}

static uint8_t become_slave(struct co_mgr *m, uint8_t prio, uint8_t id)
{
	co_timer_stop(&m->fm.timer);
	m->fm.master_id = id;
	m->fm.master_prio = prio;
	hb_watch(m, id);
	/* Found again after each network reset: listeners hear of a change only. */
	if (m->fm.ev_master != id) {
		m->fm.ev_master = id;
		LOG_INF("%s: node %u (priority %u) is the active master", m->node->name, id, prio);
		publish(m, CO_MGR_FM_EV_MASTER);
	}
	return CO_MGR_FM_SLAVE;
}

/* An active master or a negotiation winner announced itself (071h). */
static uint8_t a_071(struct co_mgr *m, const struct fm_ev_data *ev)
{
	if (beats(ev->prio, ev->id, own_prio(m), m->node->node_id)) {
		return become_slave(m, ev->prio, ev->id);
	}
	if (ev->prio == own_prio(m)) {
		/*
		 * Equal priority, higher node-ID: it is the master all the same (302-2 covers only
		 * higher and lower; forcing here would loop, the slot timing ranks by node-ID).
		 */
		return become_slave(m, ev->prio, ev->id);
	}
	if (ev->id == m->fm.forced_id) {
		/*
		 * It won the negotiation our 076h forced: its timing parameters beat our priority.
		 * Forcing again would only loop (CiA 302 §5.5.2): it stays the master.
		 */
		LOG_WRN("%s: lower-priority node %u won again: not forcing (check 1F90h timings)",
			m->node->name, ev->id);
		return become_slave(m, ev->prio, ev->id);
	}
	/* A lower-priority master: make it renegotiate (302-2 §3.7 g). */
	m->fm.forced_id = ev->id;
	co_timer_stop(&m->fm.timer);
	m->fm.master_id = ev->id;
	m->fm.master_prio = ev->prio;
	hb_unwatch(m);
	send(m, COB_FORCE, 0, 0, 0);
	publish(m, CO_MGR_FM_EV_FORCE);
	/* Its Reset Communication restarts us; if it never comes, ask again. */
	arm(m, fm_obj(m, FT_DELAY));
	return CO_MGR_FM_FORCED;
}

/* W expired: we won. */
static uint8_t a_win(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	m->fm.master_id = m->node->node_id;
	m->fm.master_prio = own_prio(m);
	m->fm.forced_id = 0U;
	m->fm.wins++;
	send(m, COB_MASTER_ID, 2, m->fm.master_prio, m->fm.master_id);
	co_node_timer_start(m->node, &m->fm.cycle, co_mgr_now(m) + MS_US(fm_obj(m, FT_CYCLE)));
	LOG_INF("%s: active master (priority %u)", m->node->name, m->fm.master_prio);
	m->fm.ev_master = m->fm.master_id;
	publish(m, CO_MGR_FM_EV_ACTIVE);
	/* F4: the NMT startup from its beginning (its Reset Communication brings everyone). */
	m->phase = PH_BEGIN;
	co_node_timer_start(m->node, &m->start_timer, co_mgr_now(m));
	return CO_MGR_FM_ACTIVE;
}

/* Active master: answer 073h (and a 072h of a node that missed us). */
static uint8_t a_identify(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	send(m, COB_MASTER_ID, 2, own_prio(m), m->node->node_id);
	return KEEP;
}

/* Active master: another one announced itself (two masters after a split). */
static uint8_t a_other_master(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	/* Whoever receives a 076h first resets the whole network; both then negotiate. */
	send(m, COB_FORCE, 0, 0, 0);
	return KEEP;
}

/* Active master: 076h from someone else. */
static uint8_t a_resign(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	LOG_INF("%s: forced negotiation: resetting the network", m->node->name);
	publish(m, CO_MGR_FM_EV_RESIGN);
	reset_all(m);
	return KEEP;
}

/* Slave: the active master's heartbeat was lost (302 §5.5.4). */
static uint8_t a_lost(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	LOG_WRN("%s: active master %u lost: taking over", m->node->name, m->fm.master_id);
	m->fm.ev_master = 0U;
	m->fm.forced_id = 0U;
	publish(m, CO_MGR_FM_EV_LOST);
	/* 076h cannot help: no master is left to act on it. */
	reset_all(m);
	return KEEP;
}

/*
 * Back from bus-off while detecting or negotiating: frames of this round were missed and the
 * error frames shifted the time slots (302 §5.5.4), so the round starts again from F1.
 */
static uint8_t a_restart(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	LOG_WRN("%s: bus-off during the negotiation: detecting again", m->node->name);
	m->fm.seen_072 = false;
	m->fm.warm = true;
	arm(m, fm_obj(m, FT_DELAY));
	return CO_MGR_FM_DELAY;
}

/* Self-starting device: is a master-capable device there? */
static uint8_t a_ss_ask(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	send(m, COB_ASK_CAPAB, 0, 0, 0);
	arm(m, ss_obj(m, 1));
	return CO_MGR_FM_SS_ASK;
}

static uint8_t a_ss_capable(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	co_timer_stop(&m->fm.timer);
	LOG_INF("%s: a master-capable device is present: not starting", m->node->name);
	publish(m, CO_MGR_FM_EV_CAPABLE);
	return CO_MGR_FM_SS_DONE;
}

static uint8_t a_ss_slot(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	arm(m, (uint32_t)m->node->node_id * ss_obj(m, 3));
	return CO_MGR_FM_SS_SLOT;
}

static uint8_t a_ss_start(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	send(m, 0x000, 2, CO_NMT_CS_START, 0x00);
	/* Before our own start: its Operational event must not count as another's start. */
	m->fm.state = CO_MGR_FM_SS_DONE;
	publish(m, CO_MGR_FM_EV_SELF_START);
	/* 1F80h bit 2 = 0: we enter Operational ourselves (02h). */
	if ((co_mgr_startup_obj(m) & SU_NO_SELF_OP) == 0U) {
		(void)co_nmt_req(m->node, CO_NMT_CS_START);
	}
	return CO_MGR_FM_SS_DONE;
}

/* Another self-starter's start came first: do not send another one. */
static uint8_t a_ss_started(struct co_mgr *m, const struct fm_ev_data *ev)
{
	ARG_UNUSED(ev);
	co_timer_stop(&m->fm.timer);
	publish(m, CO_MGR_FM_EV_SELF_START);
	return CO_MGR_FM_SS_DONE;
}

/* --- The state table ------------------------------------------------------------------------ */

#define ANY 0xffU /* a row for every state */

/*
 * The transitions, one row each: in @p state, on @p ev, run @p act; it returns the next state
 * (KEEP: the row's @p next). An event without a row is ignored in that state (e.g. 076h at a
 * node that is not the active master, 302 §5.5.2).
 */
static const struct fm_tr {
	uint8_t state;
	uint8_t ev;
	fm_action_t act;
	uint8_t next;
} fm_table[] = {
	/* Our boot-up, cold or warm (F0): candidate or self-starter. */
	{ANY, E_START, a_start, KEEP},
	/* F1: 1F90h:02 passed, ask who the active master is. */
	{CO_MGR_FM_DELAY, E_TIMER, a_ask, CO_MGR_FM_DETECT},
	{CO_MGR_FM_DELAY, E_071, a_071, KEEP},
	{CO_MGR_FM_DELAY, E_072, a_072, KEEP},
	{CO_MGR_FM_DELAY, E_RECOVERED, a_restart, KEEP},
	/* F2: nobody answered within 1F90h:01 (cold: reset all; warm: negotiate). */
	{CO_MGR_FM_DETECT, E_TIMER, a_no_master, KEEP},
	{CO_MGR_FM_DETECT, E_071, a_071, KEEP},
	{CO_MGR_FM_DETECT, E_072, a_072, KEEP},
	{CO_MGR_FM_DETECT, E_RECOVERED, a_restart, KEEP},
	/* Forced a lower-priority master; no reset came: ask again. */
	{CO_MGR_FM_FORCED, E_TIMER, a_ask, CO_MGR_FM_DETECT},
	{CO_MGR_FM_FORCED, E_072, a_072, KEEP},
	{CO_MGR_FM_FORCED, E_RECOVERED, a_restart, KEEP},
	/* F3: our slot came first, or someone else's 071h did. */
	{CO_MGR_FM_NEGOTIATE, E_TIMER, a_win, KEEP},
	{CO_MGR_FM_NEGOTIATE, E_071, a_071, KEEP},
	{CO_MGR_FM_NEGOTIATE, E_072, a_072, KEEP},
	{CO_MGR_FM_NEGOTIATE, E_RECOVERED, a_restart, KEEP},
	/* F4: the active master. */
	{CO_MGR_FM_ACTIVE, E_073, a_identify, KEEP},
	{CO_MGR_FM_ACTIVE, E_072, a_identify, KEEP},
	{CO_MGR_FM_ACTIVE, E_071, a_other_master, KEEP},
	{CO_MGR_FM_ACTIVE, E_076, a_resign, KEEP},
	/* A slave of another master. */
	{CO_MGR_FM_SLAVE, E_HB_LOST, a_lost, KEEP},
	{CO_MGR_FM_SLAVE, E_071, a_071, KEEP},
	{CO_MGR_FM_SLAVE, E_072, a_072, KEEP},
	/* NMT master detection of a self-starting device (302-2 §5.1). */
	{CO_MGR_FM_SS_DELAY, E_TIMER, a_ss_ask, KEEP},
	{CO_MGR_FM_SS_DELAY, E_OPER, a_ss_started, KEEP},
	{CO_MGR_FM_SS_ASK, E_TIMER, a_ss_slot, KEEP},
	{CO_MGR_FM_SS_ASK, E_074, a_ss_capable, KEEP},
	{CO_MGR_FM_SS_ASK, E_OPER, a_ss_started, KEEP},
	{CO_MGR_FM_SS_SLOT, E_TIMER, a_ss_start, KEEP},
	{CO_MGR_FM_SS_SLOT, E_074, a_ss_capable, KEEP},
	{CO_MGR_FM_SS_SLOT, E_OPER, a_ss_started, KEEP},
};

static const char *const state_names[CO_MGR_FM_STATE_COUNT] = {
	"OFF",   "DELAY",    "DETECT", "FORCED",  "NEGOTIATE", "ACTIVE",
	"SLAVE", "SS_DELAY", "SS_ASK", "SS_SLOT", "SS_DONE",
};

const char *co_mgr_fm_state_str(enum co_mgr_fm_state state)
{
	return (unsigned int)state < CO_MGR_FM_STATE_COUNT ? state_names[state] : "?";
}

static void fm_run(struct co_mgr *m, const struct fm_ev_data *ev)
{
	uint8_t from = m->fm.state;
	const struct fm_tr *tr = NULL;
	uint8_t next;

	for (size_t i = 0; i < ARRAY_SIZE(fm_table); i++) {
		if ((fm_table[i].state == from || fm_table[i].state == ANY) &&
		    fm_table[i].ev == (uint8_t)ev->type) {
			tr = &fm_table[i];
			break;
		}
	}
	if (tr == NULL) {
		return;
	}
	next = tr->act(m, ev);
	if (m->fm.state != from) {
		/* The action reset the node: the restart already set the state. */
		return;
	}
	if (next == KEEP) {
		next = tr->next;
	}
	if (next != KEEP && next != from) {
		LOG_DBG("%s: flying master %s -> %s", m->node->name, state_names[from],
			state_names[next]);
		m->fm.state = next;
	}
}

static void fm_post(struct co_mgr *m, enum fm_ev type, uint8_t prio, uint8_t id)
{
	struct fm_ev_data ev = {.type = type, .prio = prio, .id = id};

	fm_run(m, &ev);
}

/* --- Receivers, timers, listener ----------------------------------------------------------- */

static void fm_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;
	uint32_t su = co_mgr_startup_obj(m);

	ARG_UNUSED(now_us);
	if ((frame->flags & CAN_FRAME_RTR) != 0U) {
		return;
	}
	/* 302 §5.1 frame layouts: a frame with another DLC is not ours and is ignored. */
	switch (frame->id) {
	case COB_MASTER_ID:
		if (frame->dlc == 2U && frame->data[1] != 0U && frame->data[1] <= 127U &&
		    frame->data[1] != m->node->node_id) {
			fm_post(m, E_071, frame->data[0], frame->data[1]);
		}
		break;
	case COB_TRIGGER:
	case COB_ASK_ACTIVE:
	case COB_CAPABLE:
	case COB_FORCE:
		if (frame->dlc == 0U) {
			fm_post(m,
				frame->id == COB_TRIGGER      ? E_072
				: frame->id == COB_ASK_ACTIVE ? E_073
				: frame->id == COB_CAPABLE    ? E_074
							      : E_076,
				0U, 0U);
		}
		break;
	case COB_ASK_CAPAB:
		/* 302 §5.5.3.1: every master-capable device answers, active or not. */
		if (frame->dlc == 0U && (su & SU_MASTER) != 0U) {
			send(m, COB_CAPABLE, 0, 0, 0);
		}
		break;
	default:
		break;
	}
}

static void fm_hb_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;

	if ((frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc < 1U ||
	    m->fm.state != CO_MGR_FM_SLAVE) {
		return;
	}
	co_node_timer_start(m->node, &m->fm.hb_timer, now_us + MS_US(m->fm.hb_ms));
}

static void fm_timer(struct co_timer *timer, uint64_t now_us)
{
	ARG_UNUSED(now_us);
	fm_post(timer->user_data, E_TIMER, 0U, 0U);
}

static void fm_hb_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;

	ARG_UNUSED(now_us);
	if (m->fm.state == CO_MGR_FM_SLAVE) {
		fm_post(m, E_HB_LOST, 0U, 0U);
	}
}

/* Multiple-master detection (302 §5.5.4): another active master resets on our 076h. */
static void fm_cycle(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;

	if (m->fm.state != CO_MGR_FM_ACTIVE) {
		return;
	}
	send(m, COB_FORCE, 0, 0, 0);
	co_node_timer_start(m->node, &m->fm.cycle, now_us + MS_US(fm_obj(m, FT_CYCLE)));
}

static int fm_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct co_mgr *m = user_data;

	ARG_UNUSED(node);
	if (ev->type == CO_EV_NMT_RESET) {
		/* A Reset Communication restarts warm; power-on and Reset Node are cold. */
		m->fm.warm = ev->reset.cs == CO_NMT_CS_RESET_COMMUNICATION;
		co_timer_stop(&m->fm.timer);
		co_timer_stop(&m->fm.cycle);
		hb_unwatch(m);
		m->fm.state = CO_MGR_FM_OFF;
	} else if (ev->type == CO_EV_NMT_STATE && ev->nmt.to == CO_NMT_OPERATIONAL) {
		fm_post(m, E_OPER, 0U, 0U);
	} else if (ev->type == CO_EV_LINE && ev->line.idx == (uint8_t)CO_LINE_DEFAULT &&
		   ev->line.event == CO_LINE_EV_CAN_STATE) {
		if (ev->line.arg == (int)CAN_STATE_BUS_OFF) {
			m->fm.bus_off = true;
		} else if (ev->line.arg == (int)CAN_STATE_ERROR_ACTIVE && m->fm.bus_off) {
			m->fm.bus_off = false;
			fm_post(m, E_RECOVERED, 0U, 0U);
		} else {
			/* Warning or passive: still on the bus. */
		}
	} else {
		/* Other NMT states, other lines, other line events: nothing to do. */
	}
	return 0;
}

/* --- Interface to the manager ---------------------------------------------------------------- */

bool co_mgr_fm_active(struct co_mgr *m)
{
	return m->fm.state == CO_MGR_FM_ACTIVE;
}

void co_mgr_fm_begin(struct co_mgr *m)
{
	fm_post(m, E_START, 0U, 0U);
}

static uint32_t timing_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t sub = req->info->sub;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t prio_slot = fm_obj(m, FT_PRIO_SLOT);
	uint32_t node_slot = fm_obj(m, FT_NODE_SLOT);

	ARG_UNUSED(od);
	switch (sub) {
	case FT_PRIO:
		return v > PRIO_LOWEST ? CO_SDO_AB_INVALID_VALUE : 0U;
	case FT_PRIO_SLOT:
		prio_slot = v;
		break;
	case FT_NODE_SLOT:
		node_slot = v;
		break;
	case FT_DETECT:
	case FT_DELAY:
		return v == 0U ? CO_SDO_AB_INVALID_VALUE : 0U;
	default:
		return 0U;
	}
	/* 302 §5.5.6: a priority-0 node 127 must still beat every priority-1 node. */
	if (node_slot == 0U || prio_slot <= 127U * node_slot) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

int co_mgr_fm_init(struct co_mgr *m)
{
	struct co_node *node = m->node;
	const struct co_od_hook hook = {
		.index_first = IDX_FM_TIMING,
		.index_last = IDX_FM_TIMING,
		.sub_first = 1,
		.sub_last = 6,
		.validate = timing_validate,
		.user_data = m,
	};

	co_timer_init(&m->fm.timer, fm_timer, &node->lock, m);
	co_timer_init(&m->fm.cycle, fm_cycle, &node->lock, m);
	co_timer_init(&m->fm.hb_timer, fm_hb_timer, &node->lock, m);
	/* 070h..077h: the flying-master frames (071h..076h). */
	co_rx_init(&m->fm.rx, 0x070U, fm_rx, &node->lock, m);
	m->fm.rx.mask = 0x7f8U;
	if (co_node_rx_register(node, CO_LINE_DEFAULT, &m->fm.rx) != 0) {
		return -ENOSPC;
	}
	co_rx_init(&m->fm.hb_rx, 0x700U, fm_hb_rx, &node->lock, m);
	co_listener_init(&m->fm.listener, "mgr_fm",
			 CO_EV_BIT(CO_EV_NMT_RESET) | CO_EV_BIT(CO_EV_NMT_STATE) |
				 CO_EV_BIT(CO_EV_LINE),
			 fm_event, m);
	if (co_node_listener_add(node, &m->fm.listener) != 0) {
		return -ENOSPC;
	}
	return co_od_hook_register(&node->od, &hook);
}

int co_mgr_fm_get(struct co_node *node, struct co_mgr_fm_info *info)
{
	struct co_mgr *m = &node->mgr;

	co_node_lock(node);
	*info = (struct co_mgr_fm_info){
		.state = (enum co_mgr_fm_state)m->fm.state,
		.master_id = m->fm.master_id,
		.master_prio = m->fm.master_prio,
		.own_prio = own_prio(m),
		.wins = m->fm.wins,
		.changed_us = m->fm.changed_us,
	};
	co_node_unlock(node);
	return 0;
}

/* A write to the active master's request object (1F82h/1F83h) over our SDO client. */
static int request(struct co_node *node, uint8_t cli_num, uint16_t index, uint8_t id, uint8_t value,
		   co_sdo_cli_con_t con, void *user_data)
{
	struct co_mgr *m = &node->mgr;
	struct co_sdo_cli *cli = co_sdo_cli_get(node, cli_num);
	int err;

	if (cli == NULL || con == NULL || id == 0U || id > ALL_NODES) {
		return -EINVAL;
	}
	co_node_lock(node);
	if (m->fm.state == CO_MGR_FM_ACTIVE) {
		err = -EPERM;
	} else if (m->fm.state != CO_MGR_FM_SLAVE || m->fm.master_id == 0U) {
		err = -ENOENT;
	} else {
		err = co_sdo_cli_set_server(cli, m->fm.master_id);
		if (err == 0) {
			/* Kept here: the client reads the data while it sends. */
			m->fm.req_val = value;
			err = co_sdo_cli_download_req(cli, index, id, &m->fm.req_val, 1U,
						      CO_SDO_CLI_AUTO, 0U, con, user_data);
		}
	}
	co_node_unlock(node);
	return err;
}

int co_mgr_request_nmt(struct co_node *node, uint8_t cli_num, uint8_t id, uint8_t value,
		       co_sdo_cli_con_t con, void *user_data)
{
	if (value != 0x04U && value != 0x05U && value != 0x06U && value != 0x07U &&
	    value != 0x7fU) {
		return -EINVAL;
	}
	return request(node, cli_num, IDX_REQ_NMT, id, value, con, user_data);
}

int co_mgr_request_guarding(struct co_node *node, uint8_t cli_num, uint8_t id, bool on,
			    co_sdo_cli_con_t con, void *user_data)
{
	return request(node, cli_num, IDX_REQ_GUARD, id, on ? 1U : 0U, con, user_data);
}
