/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SYNC object (CiA 301 §7.2.5): producer (1005h bit 30, period 1006h, counter 1019h),
 * consumer (the 1005h COB-ID) and the synchronous window 1007h handed to the PDOs. Writes
 * take effect at once through OD hooks.
 *
 * Decisions (doc/sync.md):
 * - SYNC runs in Pre-operational and Operational; the counter restarts at 1 whenever the
 *   producer (re)starts: enable, new period, new overflow value, leaving Stopped.
 * - A SYNC whose length does not match 1019h (0 without counter, 1 with) is ignored and
 *   raises EMCY 8240h; the next good SYNC clears it.
 * - The producer's own SYNC is indicated to the application like a received one.
 * - Each SYNC runs: the application's indication, the synchronous PDOs (with the 1007h
 *   window, which applies from the next SYNC after a write), the post-PDO indication.
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/cob_id.h>
#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/sync.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_COB_ID   0x1005U
#define IDX_PERIOD   0x1006U
#define IDX_WINDOW   0x1007U
#define IDX_OVERFLOW 0x1019U

#define COB_GEN BIT(30)
#define COB_EXT BIT(29)

/*
 * One SYNC: the application, then the SYNC event (the synchronous PDOs and every other
 * listener), then the application again.
 */
static void indicate(struct co_node *node, uint8_t counter, uint64_t now_us)
{
	struct co_sync *s = &node->sync;
	struct co_event ev = {
		.type = CO_EV_SYNC,
		.sync = {.counter = counter, .window_us = s->window_us, .time_us = now_us},
	};

	if (s->ind != NULL) {
		s->ind(node, counter, s->ind_user_data);
	}
	(void)co_node_publish(node, &ev, NULL);
	if (s->post_ind != NULL) {
		s->post_ind(node, counter, s->post_ind_user_data);
	}
}

/* --- Producer ----------------------------------------------------------------------------- */

static bool producing(const struct co_sync *s)
{
	return s->enabled && (s->cob_id & COB_GEN) != 0U && s->period_us != 0U;
}

static void send_sync(struct co_node *node, uint64_t now_us)
{
	struct co_sync *s = &node->sync;
	struct can_frame f = {.id = s->cob_id & 0x7ffU};
	uint8_t counter = 0U;

	if (s->overflow != 0U) {
		counter = s->counter;
		f.dlc = 1U;
		f.data[0] = counter;
		s->counter = counter >= s->overflow ? 1U : (uint8_t)(counter + 1U);
	}
	(void)co_node_send(node, CO_ROUTE_PROCESS, &f);
	indicate(node, counter, now_us);
}

static void timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	struct co_sync *s = &node->sync;
	uint64_t next = timer->deadline + s->period_us;

	if (!producing(s)) {
		return;
	}
	send_sync(node, now_us);
	/* Keep the cadence; after a long stall start afresh rather than burst. */
	if (co_time_before_eq(next, now_us)) {
		next = now_us + s->period_us;
	}
	co_node_timer_start(node, timer, next);
}

static void producer_restart(struct co_node *node)
{
	struct co_sync *s = &node->sync;

	co_timer_stop(&s->timer);
	s->counter = 1U;
	if (producing(s)) {
		co_node_timer_start(node, &s->timer, co_node_time(node) + s->period_us);
	}
}

/* --- Consumer ----------------------------------------------------------------------------- */

static void sync_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_sync *s = &node->sync;
	uint8_t want = s->overflow != 0U ? 1U : 0U;

	/* A node on two lines hears SYNC/TIME on both and acts on the active line's. */
	if (co_node_rx_line(node) != co_node_active_line(node)) {
		return;
	}
	if (!s->enabled || (frame->flags & CAN_FRAME_RTR) != 0U) {
		return;
	}
	/* 8240h is reported when it appears and when it goes, not per frame: a valid SYNC costs
	 * no error event.
	 */
	if (frame->dlc != want) {
		if (!s->length_error) {
			s->length_error = true;
			co_node_error(node, CO_EMCY_SYNC_LENGTH, CO_EMCY_REG_COMMUNICATION, 0U,
				      CO_ERROR_F_ACTIVE);
		}
		return;
	}
	if (s->length_error) {
		s->length_error = false;
		co_node_error(node, CO_EMCY_SYNC_LENGTH, CO_EMCY_REG_COMMUNICATION, 0U, 0U);
	}
	indicate(node, want != 0U ? frame->data[0] : 0U, now_us);
}

static void rx_configure(struct co_node *node)
{
	struct co_sync *s = &node->sync;

	/* Receivers never see the node's own frames; a producer consumes nothing else. */
	if ((s->cob_id & (COB_GEN | COB_EXT)) != 0U) {
		co_rx_unregister(&s->rx);
		return;
	}
	if (co_node_rx_set_id(node, CO_LINE_DEFAULT, &s->rx, s->cob_id & 0x7ffU) != 0) {
		LOG_ERR("%s: no receive slot for SYNC", node->name);
	}
}

/* --- Hooks -------------------------------------------------------------------------------- */

static uint32_t cob_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t old = node->sync.cob_id;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	/* Only 11-bit SYNC is served; bit 31 is "don't care" for SYNC. */
	if ((v & COB_EXT) != 0U || (v & 0x1ffff800U) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* CiA 301 §7.3.5: not on another service's identifier (000h would be NMT). */
	if (co_cob_id_restricted(v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* A producer keeps its CAN-ID (CiA 301 §7.5.2.5). */
	if ((old & COB_GEN) != 0U && (v & COB_GEN) != 0U && (old & 0x7ffU) != (v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static void cob_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->sync.cob_id = (uint32_t)co_od_req_uint(req);
	rx_configure(node);
	producer_restart(node);
}

static void period_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->sync.period_us = (uint32_t)co_od_req_uint(req);
	producer_restart(node);
}

static void window_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	/* Applies from the next SYNC on. */
	node->sync.window_us = (uint32_t)co_od_req_uint(req);
}

static uint32_t overflow_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint64_t v = co_od_req_uint(req);

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	/* CiA 301 §7.5.2.20: only while no SYNC is produced; 0 or 2..240. */
	if (co_od_uint(&node->od, IDX_PERIOD, 0, 0U) != 0U) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (v == 1U || v > 240U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static void overflow_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->sync.overflow = (uint8_t)co_od_req_uint(req);
	producer_restart(node);
}

/* --- Node interface ----------------------------------------------------------------------- */

static int sync_init(struct co_node *node)
{
	struct co_sync *s = &node->sync;
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_COB_ID,
			.index_last = IDX_COB_ID,
			.validate = cob_validate,
			.notify = cob_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_PERIOD,
			.index_last = IDX_PERIOD,
			.notify = period_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_WINDOW,
			.index_last = IDX_WINDOW,
			.notify = window_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_OVERFLOW,
			.index_last = IDX_OVERFLOW,
			.validate = overflow_validate,
			.notify = overflow_notify,
			.user_data = node,
		},
	};

	co_timer_init(&s->timer, timer_handler, &node->lock, node);
	co_rx_init(&s->rx, 0U, sync_rx, &node->lock, node);
	return co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));
}

static void sync_reset_comm(struct co_node *node)
{
	struct co_sync *s = &node->sync;
	struct co_od_info info;

	/* Without 1005h the node neither produces nor consumes SYNC. */
	if (co_od_find(&node->od, IDX_COB_ID, 0, &info) != 0U) {
		s->cob_id = COB_EXT;
	} else {
		s->cob_id = (uint32_t)co_od_uint(&node->od, IDX_COB_ID, 0, CO_SYNC_COB_ID);
	}
	s->period_us = (uint32_t)co_od_uint(&node->od, IDX_PERIOD, 0, 0U);
	/* Reset Communication drops the stack's own errors (EMCY does the same). */
	s->length_error = false;
	s->window_us = (uint32_t)co_od_uint(&node->od, IDX_WINDOW, 0, 0U);
	s->overflow = (uint8_t)co_od_uint(&node->od, IDX_OVERFLOW, 0, 0U);
	if (s->overflow == 1U || s->overflow > 240U) {
		s->overflow = 0U;
	}
	rx_configure(node);
	producer_restart(node);
}

static void sync_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	struct co_sync *s = &node->sync;
	bool on = to == CO_NMT_PRE_OPERATIONAL || to == CO_NMT_OPERATIONAL;

	ARG_UNUSED(from);

	if (on == s->enabled) {
		return;
	}
	s->enabled = on;
	producer_restart(node);
}

const struct co_service co_service_sync = {
	.name = "sync",
	.init = sync_init,
	.reset_comm = sync_reset_comm,
	.set_state = sync_set_state,
};

void co_sync_set_ind(struct co_node *node, co_sync_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->sync.ind = cb;
	node->sync.ind_user_data = user_data;
	co_node_unlock(node);
}

void co_sync_set_post_ind(struct co_node *node, co_sync_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->sync.post_ind = cb;
	node->sync.post_ind_user_data = user_data;
	co_node_unlock(node);
}
