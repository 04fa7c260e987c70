/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Redundant CAN lines (CiA 302-6, with the ECSS-E-ST-50-15C toggle profile as an option).
 *
 * Decisions (doc/redundancy.md):
 * - The node hears both lines: catch-all receivers on the redundant line (11- and 29-bit)
 *   hand its frames to the node's receivers of the default line (co_node_dispatch_from()), so
 *   no service needs a second set of receivers; services that care ask co_node_rx_line().
 * - Heartbeats of the nodes in 1016h are supervised per line with 1016h's consumer times, by
 *   one masked receiver for 701h-77Fh; the heartbeat consumer service keeps judging the node
 *   as a whole (heard on any line).
 * - The line choice is a const table of (state, input) -> (next state, may the application
 *   veto); commands switch without asking.
 * - 1F60h's layout is ours (CiA 302-6's is not public): sub 1 Bdefault, 2 Ttoggle, 3 Ntoggle,
 *   4 Ctoggle (the ECSS names), 5 the TPDO 1 error-counter limit. CONFIG_CANOPEN_REDUNDANCY_ECSS
 *   uses subs 1-4, the CiA 302-6 profile sub 5.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/errctl.h>
#include <canopen/node.h>
#include <canopen/redundancy.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_HB_CONSUMER 0x1016U
#define HB_COB_BASE     0x700U
#define GOOD_HEARTBEATS 3U
#define TPDO_FAIL_STEP  4U
#define ECSS            IS_ENABLED(CONFIG_CANOPEN_REDUNDANCY_ECSS)

/* Inputs of the line choice. */
enum rdn_input {
	IN_DEFAULT_OK,
	IN_EVAL_TIMEOUT,
	IN_HB_ERROR_DEFAULT,
};

struct rdn_step {
	uint8_t state;
	uint8_t input;
	uint8_t next;
	uint8_t why; /* enum co_rdn_event, for the veto and the events */
	bool vetoable;
};

/* CiA 302-6 as far as it is public; everything else leaves the state alone. */
static const struct rdn_step steps[] = {
	{CO_RDN_NEGOTIATING, IN_DEFAULT_OK, CO_RDN_DEFAULT_ACTIVE, CO_RDN_EV_DEFAULT_LINE_OK,
	 false},
	{CO_RDN_NEGOTIATING, IN_EVAL_TIMEOUT, CO_RDN_REDUNDANT_ACTIVE, CO_RDN_EV_EVAL_TIMEOUT,
	 false},
	{CO_RDN_DEFAULT_ACTIVE, IN_HB_ERROR_DEFAULT, CO_RDN_REDUNDANT_ACTIVE, CO_RDN_EV_HB_ERROR,
	 true},
	{CO_RDN_REDUNDANT_ACTIVE, IN_DEFAULT_OK, CO_RDN_DEFAULT_ACTIVE, CO_RDN_EV_DEFAULT_LINE_OK,
	 true},
};

static bool two_lines(const struct co_node *node)
{
	return node->lines[CO_LINE_REDUNDANT].line != NULL;
}

static void publish(struct co_node *node, enum co_rdn_event what, uint8_t line, uint8_t id,
		    uint64_t now)
{
	struct co_event ev = {
		.type = CO_EV_REDUNDANCY,
		.redundancy = {.what = what, .line = line, .node_id = id, .time_us = now},
	};

	(void)co_node_publish(node, &ev, NULL);
}

static uint8_t line_of_state(uint8_t state, uint8_t current)
{
	switch (state) {
	case CO_RDN_DEFAULT_ACTIVE:
		return CO_LINE_DEFAULT;
	case CO_RDN_REDUNDANT_ACTIVE:
		return CO_LINE_REDUNDANT;
	default:
		return current;
	}
}

static void enter(struct co_node *node, uint8_t state, uint64_t now)
{
	struct co_redundancy *r = &node->rdn;
	uint8_t from = co_node_active_line(node);
	uint8_t to = line_of_state(state, from);

	r->state = state;
	if (to != from) {
		(void)co_node_set_active_line(node, (enum co_node_line_id)to);
		r->switches++;
		LOG_INF("%s: line %u active", node->name, to);
		publish(node, CO_RDN_EV_SWITCH, to, 0U, now);
	}
}

static void step(struct co_node *node, enum rdn_input input, uint64_t now)
{
	struct co_redundancy *r = &node->rdn;

	for (size_t i = 0; i < ARRAY_SIZE(steps); i++) {
		const struct rdn_step *s = &steps[i];
		uint8_t to = line_of_state(s->next, co_node_active_line(node));

		if (s->state != r->state || s->input != input) {
			continue;
		}
		if (s->vetoable && r->veto != NULL &&
		    !r->veto(node, (enum co_rdn_event)s->why, to, r->veto_user_data)) {
			publish(node, CO_RDN_EV_VETOED, to, 0U, now);
			return;
		}
		enter(node, s->next, now);
		return;
	}
}

/* --- Heartbeats per line -------------------------------------------------------------------- */

static void link_state(struct co_node *node, uint8_t idx, bool down);

static bool default_line_ok(const struct co_redundancy *r)
{
	for (uint8_t i = 0; i < r->n_hb; i++) {
		if (r->hb[CO_LINE_DEFAULT][i].count < GOOD_HEARTBEATS) {
			return false;
		}
	}
	return true;
}

static void arm(struct co_node *node)
{
	struct co_redundancy *r = &node->rdn;
	uint64_t next = UINT64_MAX;

	for (uint8_t l = 0; l < CO_NODE_LINES; l++) {
		for (uint8_t i = 0; i < r->n_hb; i++) {
			const struct co_rdn_hb *h = &r->hb[l][i];

			if (h->seen && !h->lost && h->deadline < next) {
				next = h->deadline;
			}
		}
	}
	if (!ECSS && r->state == CO_RDN_NEGOTIATING && r->eval_end < next) {
		next = r->eval_end;
	}
	if (ECSS && r->state != CO_RDN_NO_MASTER && r->toggle_at < next) {
		next = r->toggle_at;
	}
	if (next == UINT64_MAX) {
		co_timer_stop(&r->timer);
	} else {
		co_node_timer_start(node, &r->timer, next);
	}
}

/* ECSS: the master's heartbeat period times Ttoggle, from @p from. */
static uint64_t toggle_deadline(struct co_node *node, uint64_t from)
{
	uint32_t t = co_od_uint(&node->od, CO_RDN_IDX, CO_RDN_SUB_TTOGGLE, 0U);

	if (node->rdn.n_hb == 0U || t == 0U) {
		return UINT64_MAX;
	}
	return from + (uint64_t)node->rdn.hb_us[0] * t;
}

static void ecss_toggle(struct co_node *node, uint64_t now)
{
	struct co_redundancy *r = &node->rdn;
	struct co_od *od = &node->od;
	uint8_t to =
		co_node_active_line(node) == CO_LINE_DEFAULT ? CO_LINE_REDUNDANT : CO_LINE_DEFAULT;
	uint8_t count = (uint8_t)(co_od_uint(od, CO_RDN_IDX, CO_RDN_SUB_CTOGGLE, 0U) + 1U);

	enter(node, to == CO_LINE_DEFAULT ? CO_RDN_DEFAULT_ACTIVE : CO_RDN_REDUNDANT_ACTIVE, now);
	(void)co_od_set_u8(od, CO_RDN_IDX, CO_RDN_SUB_CTOGGLE, count, CO_OD_WRITER_APP);
	if (count < co_od_uint(od, CO_RDN_IDX, CO_RDN_SUB_NTOGGLE, 0U)) {
		r->toggle_at = toggle_deadline(node, now);
		return;
	}
	/* No master on either bus: stay here and make it the default. */
	(void)co_od_set_u8(od, CO_RDN_IDX, CO_RDN_SUB_BDEFAULT, to, CO_OD_WRITER_APP);
	r->state = CO_RDN_NO_MASTER;
	r->toggle_at = UINT64_MAX;
	publish(node, CO_RDN_EV_NO_MASTER, to, 0U, now);
}

static void timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	struct co_redundancy *r = &node->rdn;

	for (uint8_t l = 0; l < CO_NODE_LINES; l++) {
		for (uint8_t i = 0; i < r->n_hb; i++) {
			struct co_rdn_hb *h = &r->hb[l][i];

			if (!h->seen || h->lost || !co_time_before_eq(h->deadline, now_us)) {
				continue;
			}
			h->lost = true;
			h->count = 0U;
			publish(node, CO_RDN_EV_HB_ERROR, l, r->hb_id[i], now_us);
			if (!ECSS && l == CO_LINE_DEFAULT) {
				step(node, IN_HB_ERROR_DEFAULT, now_us);
			}
		}
	}
	if (!ECSS && r->state == CO_RDN_NEGOTIATING && co_time_before_eq(r->eval_end, now_us)) {
		publish(node, CO_RDN_EV_EVAL_TIMEOUT, CO_LINE_DEFAULT, 0U, now_us);
		step(node, IN_EVAL_TIMEOUT, now_us);
	}
	if (ECSS && r->state != CO_RDN_NO_MASTER && co_time_before_eq(r->toggle_at, now_us)) {
		ecss_toggle(node, now_us);
	}
	arm(node);
}

static void hb_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_redundancy *r = &node->rdn;
	uint8_t id = (uint8_t)(frame->id - HB_COB_BASE);
	uint8_t line = co_node_rx_line(node);
	bool was_ok = default_line_ok(r);
	uint8_t i;

	if ((r->link_down & BIT(line)) != 0U) {
		/* Frames come in there again: the interface is back up. */
		link_state(node, line, false);
	}
	if ((frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc < 1U) {
		return;
	}
	for (i = 0; i < r->n_hb && r->hb_id[i] != id; i++) {
	}
	if (i == r->n_hb) {
		return;
	}
	struct co_rdn_hb *h = &r->hb[line][i];

	h->seen = true;
	h->deadline = now_us + r->hb_us[i];
	/*
	 * A good cycle is a heartbeat at least half a consumer time after the last one counted:
	 * heartbeats a cut line held back arrive in a burst when it comes back and are no proof
	 * of three cycles.
	 */
	if (h->count < GOOD_HEARTBEATS &&
	    (h->count == 0U || co_time_before_eq(h->counted_at + r->hb_us[i] / 2U, now_us))) {
		h->count++;
		h->counted_at = now_us;
	}
	if (h->lost) {
		h->lost = false;
		publish(node, CO_RDN_EV_HB_OK, line, id, now_us);
	}
	if (ECSS) {
		/* The master's heartbeat on the active bus holds the toggling off. */
		if (i == 0U && line == co_node_active_line(node)) {
			r->toggle_at = toggle_deadline(node, now_us);
			if (r->state == CO_RDN_NO_MASTER) {
				r->state = line == CO_LINE_DEFAULT ? CO_RDN_DEFAULT_ACTIVE
								   : CO_RDN_REDUNDANT_ACTIVE;
			}
		}
	} else if (line == CO_LINE_DEFAULT && !was_ok && default_line_ok(r)) {
		publish(node, CO_RDN_EV_DEFAULT_LINE_OK, CO_LINE_DEFAULT, 0U, now_us);
		step(node, IN_DEFAULT_OK, now_us);
	} else {
		/* Without ECSS, the default line did not just become good: nothing to report. */
	}
	arm(node);
}

/* Every frame of the redundant line reaches the node's services. */
static void fwd_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	(void)co_node_dispatch_from(rx->user_data, CO_LINE_REDUNDANT, frame, now_us);
}

/* --- Lines that cannot send ----------------------------------------------------------------- */

/* What a line that cannot send keeps queued: NMT and error control (its recovery shows). */
static bool keep_ec(const struct can_frame *frame, void *arg)
{
	ARG_UNUSED(arg);
	return frame->id == CO_NMT_COB_ID || (frame->id & ~0x7fU) == CO_NMT_EC_COB_ID;
}

/*
 * A controller in error passive (a cut line: no acknowledgement) or bus-off cannot send:
 * process data queued behind it would go out stale when it recovers, as copies the other
 * line delivered long before. Such a line gets no process data until its controller is back
 * below error passive, and what the node queued there is withdrawn.
 */
static void exclusion_update(struct co_node *node, uint8_t idx)
{
	struct co_redundancy *r = &node->rdn;
	uint8_t excluded = (uint8_t)(r->tx_excluded | r->link_down);
	uint8_t bit = (uint8_t)BIT(idx);
	bool was = (r->excluded_now & bit) != 0U;

	r->excluded_now = excluded;
	co_node_set_tx_excluded(node, excluded);
	if (!was && (excluded & bit) != 0U) {
		(void)co_line_tx_purge(node->lines[idx].line, &node->lock, keep_ec, NULL);
	}
}

static void line_state(struct co_node *node, uint8_t idx, int state)
{
	struct co_redundancy *r = &node->rdn;
	uint8_t bit = (uint8_t)BIT(idx);
	bool down = state == CAN_STATE_ERROR_PASSIVE || state == CAN_STATE_BUS_OFF;

	if (down == ((r->tx_excluded & bit) != 0U) || state == CAN_STATE_STOPPED) {
		return;
	}
	r->tx_excluded = down ? (uint8_t)(r->tx_excluded | bit) : (uint8_t)(r->tx_excluded & ~bit);
	exclusion_update(node, idx);
}

/*
 * A send refused with -ENETDOWN or -ENETUNREACH: the interface is down (SocketCAN after
 * ip link set ... down; its driver reports no controller state) or the controller stopped.
 * The line gets no process data until a frame is received on it again.
 */
static bool link_error(int err)
{
	return err == -ENETDOWN || err == -ENETUNREACH;
}

static void link_state(struct co_node *node, uint8_t idx, bool down)
{
	struct co_redundancy *r = &node->rdn;
	uint8_t bit = (uint8_t)BIT(idx);

	if (down == ((r->link_down & bit) != 0U)) {
		return;
	}
	r->link_down = down ? (uint8_t)(r->link_down | bit) : (uint8_t)(r->link_down & ~bit);
	LOG_INF("%s: line %u %s", node->name, idx,
		down ? "cannot send: no process data there"
		     : "receives again: process data resume");
	exclusion_update(node, idx);
}

/* --- TPDO 1 supervision --------------------------------------------------------------------- */

static int node_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct co_redundancy *r = &node->rdn;
	uint64_t now = co_node_time(node);

	ARG_UNUSED(user_data);
	if (ev->type == CO_EV_LINE) {
		if (two_lines(node) && ev->line.event == CO_LINE_EV_CAN_STATE) {
			line_state(node, ev->line.idx, ev->line.arg);
		} else if (two_lines(node) && ev->line.event == CO_LINE_EV_TX_ERROR &&
			   link_error(ev->line.arg)) {
			link_state(node, ev->line.idx, true);
		} else {
			/* Other line events do not change a line's state. */
		}
		return 0;
	}
	if (ev->type != CO_EV_TPDO || ev->tpdo.num != 0U || r->tpdo_max == 0U) {
		return 0;
	}
	/* A line that cannot send is left out of the route (above), not a TPDO 1 failure. */
	if (two_lines(node) && link_error(ev->tpdo.err)) {
		return 0;
	}
	/* Capped at the limit: twelve good sends resume after any number of failures. */
	if (ev->tpdo.err != 0) {
		r->tpdo_errors = (uint16_t)MIN(r->tpdo_errors + TPDO_FAIL_STEP, r->tpdo_max);
	} else if (r->tpdo_errors > 0U) {
		r->tpdo_errors--;
	} else {
		/* No error counted and none to take back. */
	}
	if (!r->tpdo_failed && r->tpdo_errors >= r->tpdo_max) {
		r->tpdo_failed = true;
		co_hb_hold(node, true);
		LOG_WRN("%s: TPDO 1 fails: heartbeat stopped", node->name);
		publish(node, CO_RDN_EV_TPDO_FAILED, co_node_active_line(node), 0U, now);
	} else if (r->tpdo_failed && r->tpdo_errors == 0U) {
		r->tpdo_failed = false;
		co_hb_hold(node, false);
		publish(node, CO_RDN_EV_TPDO_OK, co_node_active_line(node), 0U, now);
	} else {
		/* TPDO 1 state unchanged. */
	}
	return 0;
}

/* --- Node interface ------------------------------------------------------------------------- */

static void config_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	if (req->info->sub == CO_RDN_SUB_TPDO_MAX) {
		node->rdn.tpdo_max = (uint8_t)co_od_req_uint(req);
	}
}

static void supervised_read(struct co_node *node);

/* A new 1016h: supervise its nodes from now on (heartbeats counted afresh). */
static void consumer_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	struct co_redundancy *r = &node->rdn;

	if (!two_lines(node)) {
		return;
	}
	supervised_read(node);
	(void)memset(r->hb, 0, sizeof(r->hb));
	if (ECSS && r->state != CO_RDN_NO_MASTER) {
		r->toggle_at = toggle_deadline(node, co_node_time(node));
	}
	arm(node);
}

static int rdn_init(struct co_node *node)
{
	struct co_redundancy *r = &node->rdn;
	const struct co_od_hook hooks[] = {
		{
			.index_first = CO_RDN_IDX,
			.index_last = CO_RDN_IDX,
			.sub_last = 255,
			.notify = config_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_HB_CONSUMER,
			.index_last = IDX_HB_CONSUMER,
			.sub_last = 255,
			.notify = consumer_notify,
			.user_data = node,
		},
	};

	(void)memset(r, 0, sizeof(*r));
	co_rx_init(&r->fwd, 0U, fwd_rx, &node->lock, node);
	r->fwd.mask = 0U;
	co_rx_init(&r->fwd_ext, 0U, fwd_rx, &node->lock, node);
	r->fwd_ext.mask = 0U;
	r->fwd_ext.ext = true;
	co_rx_init(&r->hb_rx, HB_COB_BASE, hb_rx, &node->lock, node);
	r->hb_rx.mask = 0x780U;
	co_timer_init(&r->timer, timer_handler, &node->lock, node);
	co_listener_init(&r->listener, "redundancy", CO_EV_BIT(CO_EV_TPDO) | CO_EV_BIT(CO_EV_LINE),
			 node_event, NULL);

	int err = co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));

	return err != 0 ? err : co_node_listener_add(node, &r->listener);
}

/* The supervised nodes: 1016h's entries with a consumer time. */
static void supervised_read(struct co_node *node)
{
	struct co_redundancy *r = &node->rdn;
	uint32_t n = co_od_uint(&node->od, IDX_HB_CONSUMER, 0, 0U);

	r->n_hb = 0U;
	for (uint32_t sub = 1; sub <= n && r->n_hb < CONFIG_CANOPEN_REDUNDANCY_NODES; sub++) {
		uint32_t e = co_od_uint(&node->od, IDX_HB_CONSUMER, (uint8_t)sub, 0U);
		uint8_t id = (uint8_t)(e >> 16);

		if (id >= 1U && id <= 127U && (e & 0xffffU) != 0U) {
			r->hb_id[r->n_hb] = id;
			r->hb_us[r->n_hb] = (e & 0xffffU) * 1000U;
			r->n_hb++;
		}
	}
}

static void rdn_reset_comm(struct co_node *node)
{
	struct co_redundancy *r = &node->rdn;
	uint64_t now = co_node_time(node);

	co_timer_stop(&r->timer);
	co_rx_unregister(&r->fwd);
	co_rx_unregister(&r->fwd_ext);
	co_rx_unregister(&r->hb_rx);
	(void)memset(r->hb, 0, sizeof(r->hb));
	r->tpdo_max = (uint8_t)co_od_uint(&node->od, CO_RDN_IDX, CO_RDN_SUB_TPDO_MAX, 0U);
	r->tpdo_errors = 0U;
	if (r->tpdo_failed) {
		r->tpdo_failed = false;
		co_hb_hold(node, false);
	}
	if (!two_lines(node)) {
		r->state = CO_RDN_DEFAULT_ACTIVE;
		return;
	}
	supervised_read(node);
	(void)co_node_set_process_route(node, ECSS ? CO_ROUTE_ACTIVE : CO_ROUTE_BOTH);
	if (co_node_rx_register(node, CO_LINE_REDUNDANT, &r->fwd) != 0 ||
	    co_node_rx_register(node, CO_LINE_REDUNDANT, &r->fwd_ext) != 0 ||
	    co_node_rx_register(node, CO_LINE_DEFAULT, &r->hb_rx) != 0) {
		LOG_ERR("%s: no receive slot for redundancy", node->name);
	}
	if (ECSS) {
		uint8_t b = (uint8_t)co_od_uint(&node->od, CO_RDN_IDX, CO_RDN_SUB_BDEFAULT, 0U);

		(void)co_node_set_active_line(node, b == CO_LINE_REDUNDANT ? CO_LINE_REDUNDANT
									   : CO_LINE_DEFAULT);
		r->state = b == CO_LINE_REDUNDANT ? CO_RDN_REDUNDANT_ACTIVE : CO_RDN_DEFAULT_ACTIVE;
		r->toggle_at = toggle_deadline(node, now);
	} else {
		/* Communication starts on the default line while the lines are evaluated. */
		(void)co_node_set_active_line(node, CO_LINE_DEFAULT);
		r->state = CO_RDN_NEGOTIATING;
		r->eval_end = now + (uint64_t)CONFIG_CANOPEN_REDUNDANCY_EVAL_MS * 1000U;
		if (default_line_ok(r)) {
			step(node, IN_DEFAULT_OK, now);
		}
	}
	arm(node);
}

const struct co_service co_service_redundancy = {
	.name = "redundancy",
	.init = rdn_init,
	.reset_comm = rdn_reset_comm,
};

/* --- API ------------------------------------------------------------------------------------ */

void co_redundancy_set_veto(struct co_node *node, co_rdn_veto_t cb, void *user_data)
{
	co_node_lock(node);
	node->rdn.veto = cb;
	node->rdn.veto_user_data = user_data;
	co_node_unlock(node);
}

int co_redundancy_switch_req(struct co_node *node, uint8_t idx)
{
	int ret = 0;

	co_node_lock(node);
	if (!two_lines(node)) {
		ret = -ENODEV;
	} else if ((unsigned int)idx >= CO_NODE_LINES) {
		ret = -EINVAL;
	} else {
		enter(node,
		      idx == CO_LINE_DEFAULT ? CO_RDN_DEFAULT_ACTIVE : CO_RDN_REDUNDANT_ACTIVE,
		      co_node_time(node));
		arm(node);
	}
	co_node_unlock(node);
	return ret;
}

uint8_t co_redundancy_get(struct co_node *node, enum co_rdn_state *state, uint32_t *switches)
{
	uint8_t line;

	co_node_lock(node);
	line = co_node_active_line(node);
	if (state != NULL) {
		*state = (enum co_rdn_state)node->rdn.state;
	}
	if (switches != NULL) {
		*switches = node->rdn.switches;
	}
	co_node_unlock(node);
	return line;
}

/* --- Duplicate filter: the copies of frames taken from the other line -------------------- */

bool co_rdn_is_copy(struct co_rdn_taken *ring, uint8_t n, uint8_t *next, uint8_t line,
		    const struct can_frame *frame, uint64_t now_us)
{
	/* Classic CAN: a DLC of 9 to 15 carries 8 bytes, all the frame's data holds. */
	size_t len = MIN(frame->dlc, sizeof(ring->data));

	for (uint8_t k = 0U; k < n; k++) {
		/* Oldest first: equal values pair with their copies in the order sent. */
		struct co_rdn_taken *e = &ring[(*next + k) % n];
		uint64_t age = now_us >= e->at ? now_us - e->at : e->at - now_us;

		if (e->used && !e->copied && e->line != line && e->id == (uint16_t)frame->id &&
		    e->len == frame->dlc && age <= CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US &&
		    memcmp(frame->data, e->data, len) == 0) {
			/*
			 * A line delivers one producer's frames in the order sent: the older
			 * frames of this producer taken from the other line that this line has
			 * not copied yet, it lost. They can have no copy any more, so a later
			 * value equal to one of them is not mistaken for it.
			 */
			for (uint8_t j = 0U; j <= k; j++) {
				struct co_rdn_taken *o = &ring[(*next + j) % n];

				if (o->line != line && o->id == e->id) {
					o->copied = true;
				}
			}
			return true;
		}
	}

	struct co_rdn_taken *e = &ring[*next];

	*next = (uint8_t)((*next + 1U) % n);
	*e = (struct co_rdn_taken){.at = now_us,
				   .id = (uint16_t)frame->id,
				   .len = frame->dlc,
				   .line = line,
				   .used = true};
	(void)memcpy(e->data, frame->data, len);
	return false;
}
