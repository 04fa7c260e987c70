/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT error control (CiA 301 §7.2.8.3.2): heartbeat producer 1017h, heartbeat consumer 1016h,
 * node guarding answers and life guarding 100Ch/100Dh. Writes to these objects take effect at
 * once through OD hooks.
 *
 * Decisions (doc/nmt.md):
 * - A node with a heartbeat period (1017h != 0) does not answer guarding requests: a node is
 *   heartbeat-monitored or guarded, not both (CiA 301 §7.2.8.3.2.1).
 * - The producer sends one heartbeat at once on every change among Pre-operational,
 *   Operational and Stopped, so masters see the new state without waiting a period; the first
 *   heartbeat after the boot-up message is due one period later.
 * - A consumer starts monitoring with the first heartbeat, not the boot-up message (a boot-up
 *   is reported, and monitoring waits for the node's first heartbeat again).
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/emcy.h>
#include <canopen/errctl.h>
#include <canopen/node.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_GUARD_TIME  0x100CU
#define IDX_LIFE_FACTOR 0x100DU
#define IDX_HB_CONSUMER 0x1016U
#define IDX_HB_PRODUCER 0x1017U

enum hb_mon {
	HB_IDLE,
	HB_ACTIVE,
	HB_LOST,
};

static uint64_t now_of(struct co_node *node)
{
	return co_node_time(node);
}

/* The node's state on @p route: heartbeats on every line it has, guarding answers where asked. */
static void send_state(struct co_node *node, uint8_t toggle, co_route_t route)
{
	struct can_frame f = {
		.id = CO_NMT_EC_COB_ID + node->node_id,
		.dlc = 1U,
		.data = {(uint8_t)(toggle | (uint8_t)co_node_nmt_state(node))},
	};

	(void)co_node_send(node, route, &f);
}

/*
 * A heartbeat or life guarding event (@p event true) or its end, as a node error: 8130h with
 * the error behaviour 1029h sub1 (the EMCY service acts on it). The error stays while any
 * monitor is lost, so an end is reported only when the last one ends.
 */
static void comm_error(struct co_node *node, uint8_t remote_id, bool event)
{
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	bool active = node->ec.life_lost;
#else
	bool active = false;
#endif

	for (int i = 0; i < CONFIG_CANOPEN_HB_CONSUMERS; i++) {
		active = active || node->ec.hbc[i].mon == HB_LOST;
	}
	if (event) {
		co_node_error(node, CO_EMCY_HEARTBEAT, CO_EMCY_REG_COMMUNICATION, remote_id,
			      CO_ERROR_F_ACTIVE | CO_ERROR_F_BEHAVIOUR);
	} else if (!active) {
		co_node_error(node, CO_EMCY_HEARTBEAT, CO_EMCY_REG_COMMUNICATION, remote_id, 0U);
	} else {
		/* A heartbeat or the life guard is still lost: the error stays active. */
	}
}

/* --- Heartbeat producer ------------------------------------------------------------------- */

/* Everything but the node's own heartbeats; a boot-up (state 00h) is kept, it tells of a reset. */
static bool not_a_heartbeat(const struct can_frame *f, void *arg)
{
	const struct co_node *node = arg;

	return f->id != CO_NMT_EC_COB_ID + node->node_id || f->data[0] == 0U;
}

static void hb_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	uint64_t period = (uint64_t)node->ec.hb_period_ms * 1000U;
	uint64_t next = timer->deadline + period;

	/* Held (redundancy: TPDO supervision) the heartbeat stays silent, its cadence runs on. */
	if (!node->ec.hb_held) {
		/*
		 * A heartbeat still waiting behind back-pressure carries an old state: the new
		 * one replaces it, so a line that was blocked gets one, not every one it missed.
		 */
		(void)co_node_tx_withdraw(node, CO_ROUTE_EC, not_a_heartbeat, node);
		send_state(node, 0U, CO_ROUTE_EC);
	}
	/* Keep the cadence; after a long stall start afresh rather than burst. */
	if (co_time_before_eq(next, now_us)) {
		next = now_us + period;
	}
	co_node_timer_start(node, timer, next);
}

static void hb_restart(struct co_node *node, bool send_now)
{
	co_timer_stop(&node->ec.hb_timer);
	if (node->ec.hb_period_ms == 0U || co_node_nmt_state(node) == CO_NMT_INITIALISING) {
		return;
	}
	if (send_now && !node->ec.hb_held) {
		send_state(node, 0U, CO_ROUTE_EC);
	}
	co_node_timer_start(node, &node->ec.hb_timer,
			    now_of(node) + (uint64_t)node->ec.hb_period_ms * 1000U);
}

static void hb_producer_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->ec.hb_period_ms = (uint16_t)co_od_req_uint(req);
	/* A new period takes effect at once: the next heartbeat is one new period away. */
	hb_restart(node, false);
}

/* --- Heartbeat consumer ------------------------------------------------------------------- */

/* The producer's node-ID (0: the entry is unused). */
static uint8_t hbc_remote(const struct co_hb_entry *e)
{
	return (uint8_t)(e->rx.id - CO_NMT_EC_COB_ID);
}

static void hbc_report(struct co_hb_entry *e, enum co_hb_event ev)
{
	struct co_node *node = e->node;
	struct co_event event = {
		.type = CO_EV_HB,
		.hb = {.node_id = hbc_remote(e), .event = ev, .state = (enum co_nmt_state)e->state},
	};

	if (node->ec.hb_ind != NULL) {
		node->ec.hb_ind(node, hbc_remote(e), ev, (enum co_nmt_state)e->state,
				node->ec.hb_user_data);
	}
	(void)co_node_publish(node, &event, NULL);
}

static void hbc_timeout(struct co_timer *timer, uint64_t now_us)
{
	struct co_hb_entry *e = timer->user_data;

	if (e->mon == HB_ACTIVE) {
		e->mon = HB_LOST;
		LOG_WRN("%s: heartbeat of node %u lost", e->node->name, hbc_remote(e));
		hbc_report(e, CO_HB_EV_LOST);
		comm_error(e->node, hbc_remote(e), true);
	}
}

static void hbc_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_hb_entry *e = rx->user_data;
	uint8_t state;
	uint8_t prev = e->state;

	/* Guarding requests (RTR) and answers (toggle bit set) are not heartbeats. */
	if ((frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc != 1U ||
	    (frame->data[0] & 0x80U) != 0U) {
		return;
	}
	state = frame->data[0];
	e->state = state;
	if (state == (uint8_t)CO_NMT_INITIALISING) {
		bool was_lost = e->mon == HB_LOST;

		co_timer_stop(&e->timer);
		e->mon = HB_IDLE;
		hbc_report(e, CO_HB_EV_BOOTUP);
		if (was_lost) {
			comm_error(e->node, hbc_remote(e), false);
		}
		return;
	}
	co_node_timer_start(e->node, &e->timer, now_us + (uint64_t)e->time_ms * 1000U);
	if (e->mon == HB_IDLE) {
		e->mon = HB_ACTIVE;
		hbc_report(e, CO_HB_EV_STARTED);
	} else if (e->mon == HB_LOST) {
		e->mon = HB_ACTIVE;
		hbc_report(e, CO_HB_EV_RECOVERED);
		comm_error(e->node, hbc_remote(e), false);
	} else if (prev != state) {
		hbc_report(e, CO_HB_EV_STATE);
	} else {
		/* The same state again: no event. */
	}
}

static bool hbc_value_active(uint32_t v)
{
	uint8_t id = (uint8_t)(v >> 16);

	return id >= 1U && id <= 127U && (v & 0xffffU) != 0U;
}

/* Apply 1016h sub (i + 1) to entry i. */
static void hbc_configure(struct co_node *node, int i, uint32_t value)
{
	struct co_hb_entry *e = &node->ec.hbc[i];
	bool was_lost = e->mon == HB_LOST;

	co_rx_unregister(&e->rx);
	co_timer_stop(&e->timer);
	e->mon = HB_IDLE;
	if (was_lost) {
		comm_error(node, hbc_remote(e), false);
	}
	e->state = (uint8_t)CO_NMT_INITIALISING;
	e->rx.id = CO_NMT_EC_COB_ID;
	e->time_ms = 0U;
	if (!hbc_value_active(value)) {
		return;
	}
	e->time_ms = (uint16_t)value;
	e->rx.id = CO_NMT_EC_COB_ID + ((value >> 16) & 0x7fU);
	if (co_node_rx_register(node, CO_LINE_DEFAULT, &e->rx) != 0) {
		LOG_ERR("%s: no receive slot to monitor node %u", node->name, hbc_remote(e));
	}
}

/* CiA 301: two active entries for one node-ID are a parameter incompatibility. */
static uint32_t hbc_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint8_t sub = req->info->sub;
	uint8_t count;

	if (sub == 0U || !hbc_value_active(v)) {
		return 0U;
	}
	count = (uint8_t)co_od_uint(&node->od, IDX_HB_CONSUMER, 0, 0U);
	for (uint8_t s = 1; s <= count; s++) {
		uint32_t other = (uint32_t)co_od_uint(&node->od, IDX_HB_CONSUMER, s, 0U);

		if (s != sub && hbc_value_active(other) &&
		    (uint8_t)(other >> 16) == (uint8_t)(v >> 16)) {
			return CO_SDO_AB_PARAM_INCOMPAT;
		}
	}
	return 0U;
}

static void hbc_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint8_t sub = req->info->sub;

	if (sub >= 1U && sub <= CONFIG_CANOPEN_HB_CONSUMERS) {
		hbc_configure(node, sub - 1, (uint32_t)co_od_req_uint(req));
	}
}

/* --- Node guarding and life guarding ------------------------------------------------------ */

#if defined(CONFIG_CANOPEN_NODE_GUARDING)

static void life_report(struct co_node *node, bool lost)
{
	struct co_event ev = {.type = CO_EV_LIFE, .life = {.lost = lost}};

	if (node->ec.life_ind != NULL) {
		node->ec.life_ind(node, lost, node->ec.life_user_data);
	}
	(void)co_node_publish(node, &ev, NULL);
}

static void life_timeout(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;

	node->ec.life_lost = true;
	LOG_WRN("%s: life guarding event (no guarding request within %u ms)", node->name,
		node->ec.guard_time_ms * node->ec.life_factor);
	life_report(node, true);
	comm_error(node, 0U, true);
}

static void life_restart(struct co_node *node, uint64_t now_us)
{
	uint32_t life_ms = (uint32_t)node->ec.guard_time_ms * node->ec.life_factor;

	if (!node->ec.guarded || life_ms == 0U) {
		co_timer_stop(&node->ec.life_timer);
		return;
	}
	co_node_timer_start(node, &node->ec.life_timer, now_us + (uint64_t)life_ms * 1000U);
}

static void guard_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;

	if ((frame->flags & CAN_FRAME_RTR) == 0U || node->ec.hb_period_ms != 0U ||
	    co_node_nmt_state(node) == CO_NMT_INITIALISING) {
		return;
	}
	send_state(node, node->ec.toggle, co_node_route_of(node, rx));
	node->ec.toggle ^= 0x80U;
	/* Life guarding starts with the first request. */
	node->ec.guarded = true;
	life_restart(node, now_us);
	if (node->ec.life_lost) {
		node->ec.life_lost = false;
		life_report(node, false);
		comm_error(node, 0U, false);
	}
}

static void guard_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	if (req->info->index == IDX_GUARD_TIME) {
		node->ec.guard_time_ms = (uint16_t)co_od_req_uint(req);
	} else {
		node->ec.life_factor = (uint8_t)co_od_req_uint(req);
	}
	life_restart(node, now_of(node));
}
#endif /* CONFIG_CANOPEN_NODE_GUARDING */

/* --- Node interface ----------------------------------------------------------------------- */

static int errctl_init(struct co_node *node)
{
	struct co_errctl *ec = &node->ec;
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_HB_PRODUCER,
			.index_last = IDX_HB_PRODUCER,
			.notify = hb_producer_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_HB_CONSUMER,
			.index_last = IDX_HB_CONSUMER,
			.sub_first = 1,
			.sub_last = 255,
			.validate = hbc_validate,
			.notify = hbc_notify,
			.user_data = node,
		},
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
		{
			.index_first = IDX_GUARD_TIME,
			.index_last = IDX_LIFE_FACTOR,
			.notify = guard_notify,
			.user_data = node,
		},
#endif
	};

	co_timer_init(&ec->hb_timer, hb_timer_handler, &node->lock, node);
	for (int i = 0; i < CONFIG_CANOPEN_HB_CONSUMERS; i++) {
		struct co_hb_entry *e = &ec->hbc[i];

		e->node = node;
		co_rx_init(&e->rx, CO_NMT_EC_COB_ID, hbc_rx, &node->lock, e);
		co_timer_init(&e->timer, hbc_timeout, &node->lock, e);
	}
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	co_timer_init(&ec->life_timer, life_timeout, &node->lock, node);
	co_rx_init(&ec->guard_rx, 0U, guard_rx, &node->lock, node);
#endif

	return co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));
}

static void errctl_reset_comm(struct co_node *node)
{
	struct co_errctl *ec = &node->ec;
	uint8_t count = (uint8_t)co_od_uint(&node->od, IDX_HB_CONSUMER, 0, 0U);

	co_timer_stop(&ec->hb_timer);
	ec->hb_period_ms = (uint16_t)co_od_uint(&node->od, IDX_HB_PRODUCER, 0, 0U);
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	co_timer_stop(&ec->life_timer);
	ec->guard_time_ms = (uint16_t)co_od_uint(&node->od, IDX_GUARD_TIME, 0, 0U);
	ec->life_factor = (uint8_t)co_od_uint(&node->od, IDX_LIFE_FACTOR, 0, 0U);
	/* The first guarding answer after a reset has the toggle bit 0. */
	ec->toggle = 0U;
	ec->guarded = false;
	ec->life_lost = false;
#endif

	if (count > CONFIG_CANOPEN_HB_CONSUMERS) {
		LOG_WRN("%s: 1016h has %u entries, CONFIG_CANOPEN_HB_CONSUMERS=%d are served",
			node->name, count, CONFIG_CANOPEN_HB_CONSUMERS);
	}
	for (int i = 0; i < CONFIG_CANOPEN_HB_CONSUMERS; i++) {
		uint32_t v = i < count ? (uint32_t)co_od_uint(&node->od, IDX_HB_CONSUMER,
							      (uint8_t)(i + 1), 0U)
				       : 0U;

		hbc_configure(node, i, v);
	}
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	if (co_node_rx_set_id(node, CO_LINE_DEFAULT, &ec->guard_rx,
			      CO_NMT_EC_COB_ID + node->node_id) != 0) {
		LOG_ERR("%s: no receive slot for node guarding", node->name);
	}
#endif
}

static void errctl_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	struct co_errctl *ec = &node->ec;

	if (to == CO_NMT_INITIALISING) {
		co_timer_stop(&ec->hb_timer);
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
		co_timer_stop(&ec->life_timer);
#endif
		for (int i = 0; i < CONFIG_CANOPEN_HB_CONSUMERS; i++) {
			co_timer_stop(&ec->hbc[i].timer);
		}
		return;
	}
	/* From Initialising the boot-up message was just sent. */
	hb_restart(node, from != CO_NMT_INITIALISING);
}

const struct co_service co_service_errctl = {
	.name = "errctl",
	.init = errctl_init,
	.reset_comm = errctl_reset_comm,
	.set_state = errctl_set_state,
};

void co_hb_set_ind(struct co_node *node, co_hb_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->ec.hb_ind = cb;
	node->ec.hb_user_data = user_data;
	co_node_unlock(node);
}

void co_life_set_ind(struct co_node *node, co_life_ind_t cb, void *user_data)
{
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	co_node_lock(node);
	node->ec.life_ind = cb;
	node->ec.life_user_data = user_data;
	co_node_unlock(node);
#else
	/* Without guarding there is no life guarding event to indicate. */
	ARG_UNUSED(node);
	ARG_UNUSED(cb);
	ARG_UNUSED(user_data);
#endif
}

int co_hb_get_remote_state(struct co_node *node, uint8_t remote_id, enum co_nmt_state *state)
{
	int err = -ENOENT;

	co_node_lock(node);
	for (int i = 0; i < CONFIG_CANOPEN_HB_CONSUMERS; i++) {
		struct co_hb_entry *e = &node->ec.hbc[i];

		if (hbc_remote(e) == remote_id && e->time_ms != 0U) {
			if (e->mon == HB_IDLE) {
				err = -EAGAIN;
			} else {
				*state = (enum co_nmt_state)e->state;
				err = 0;
			}
			break;
		}
	}
	co_node_unlock(node);
	return err;
}

void co_hb_hold(struct co_node *node, bool hold)
{
	co_node_lock(node);
	node->ec.hb_held = hold;
	co_node_unlock(node);
}
