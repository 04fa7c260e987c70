/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Emergency object (CiA 301 §7.2.7, objects §7.5.2): producer with its active-error table,
 * error register 1001h, pre-defined error field 1003h, COB-ID 1014h and inhibit time 1015h;
 * consumer 1028h; error behaviour 1029h for the stack's own communication errors.
 *
 * Decisions (doc/emcy.md):
 * - Frames go out only in Pre-operational and Operational (CiA 301 Table 82). Errors raised in
 *   Stopped are recorded (1001h, 1003h) but their frames are not sent, then or later; entering
 *   Stopped drops frames still waiting for the inhibit time.
 * - Every clear sends an error reset (0000h) with the remaining 1001h (CiA 301 §7.2.7.2,
 *   transitions 3 and 5); after the last clear 1001h is 0.
 * - 1003h manufacturer info (bits 31..16) is msef[0..1], little endian.
 * - Reset Communication reloads 1001h and 1003h from the dictionary; errors raised by the
 *   application stay active (their bits are put back into 1001h), the stack's own
 *   communication errors are dropped (monitoring starts afresh), except 8120h while the
 *   controller is still error passive.
 * - Line events (a listener on the node's line): 8110h on an RX queue overrun or a TX queue
 *   overflow (msef[0] 01h / 02h), 8120h while error passive, 8140h on each return from
 *   bus-off; 8110h and 8140h end after CONFIG_CANOPEN_EMCY_COMM_HOLD_MS without a new
 *   occurrence. Entering bus-off applies 1029h sub1.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/cob_id.h>
#include <canopen/emcy.h>
#include <canopen/node.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_ERR_REG   0x1001U
#define IDX_ERR_FIELD 0x1003U
#define IDX_COB_ID    0x1014U
#define IDX_INHIBIT   0x1015U
#define IDX_CONSUMER  0x1028U
#define IDX_BEHAVIOUR 0x1029U

#define COB_INVALID BIT(31)
#define COB_EXT     BIT(29)

/* 1029h values (CiA 301 §7.5.2.33). */
#define BEH_PRE_OPERATIONAL 0U
#define BEH_NO_CHANGE       1U
#define BEH_STOPPED         2U

static void od_put(struct co_node *node, uint16_t index, uint8_t sub, uint64_t v, size_t len)
{
	uint8_t buf[8];

	co_od_le_put(buf, len, v);
	node->emcy.self_write = true;
	(void)co_od_write(&node->od, index, sub, buf, len, CO_OD_WRITER_APP);
	node->emcy.self_write = false;
}

/* 1001h from the active errors, plus the bits of errors that did not fit the table. */
static void update_reg(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;
	uint8_t reg = em->lost_reg;

	for (int i = 0; i < em->n_active; i++) {
		reg |= em->active[i].reg;
	}
	/* Bit 0 (generic) is set whenever any error is present. */
	if (reg != 0U || em->n_active != 0U) {
		reg |= CO_EMCY_REG_GENERIC;
	}
	em->reg = reg;
	od_put(node, IDX_ERR_REG, 0, reg, 1U);
}

/* --- Frames and the inhibit time ---------------------------------------------------------- */

/* How long an EMCY that found a TX queue of its lines full waits before it tries again. */
#define EMCY_RETRY_US 10000U

static uint64_t inhibit_us(const struct co_emcy *em)
{
	return (uint64_t)em->inhibit_100us * 100U;
}

/* An EMCY frame sent or received, for the node's listeners (CO_EV_EMCY). */
static void publish(struct co_node *node, const struct can_frame *f, bool own)
{
	struct co_event ev = {
		.type = CO_EV_EMCY,
		.emcy = {.cob_id = (uint16_t)f->id,
			 .own = own,
			 .code = (uint16_t)(f->data[0] | (f->data[1] << 8)),
			 .reg = f->data[2]},
	};

	if (own) {
		ev.emcy.node_id = co_node_id(node);
	} else if (f->id > CO_EMCY_COB_ID && f->id <= CO_EMCY_COB_ID + 127U) {
		ev.emcy.node_id = (uint8_t)(f->id - CO_EMCY_COB_ID);
	}
	memcpy(ev.emcy.msef, &f->data[3], sizeof(ev.emcy.msef));
	(void)co_node_publish(node, &ev, NULL);
}

/*
 * Send one EMCY frame, or return false when the TX queue of a line it goes on is full: the
 * frame would be dropped there (and sent on the other line only), and an 8110h raised because
 * that queue overflowed would be lost with the frames it reports. The caller keeps it in the
 * inhibit queue and tries again EMCY_RETRY_US later. The check looks at the route the frame
 * takes, so on two lines it waits until both have room.
 */
static bool transmit(struct co_node *node, const uint8_t data[8], uint64_t now_us)
{
	struct can_frame f = {
		.id = node->emcy.cob_id & 0x7ffU,
		.dlc = 8U,
	};

	if (co_node_tx_space(node, CO_ROUTE_PROCESS) <= 0) {
		node->emcy.retry_us = now_us + EMCY_RETRY_US;
		return false;
	}
	memcpy(f.data, data, 8);
	(void)co_node_send(node, CO_ROUTE_PROCESS, &f);
	node->emcy.last_tx_us = now_us;
	node->emcy.sent_any = true;
	publish(node, &f, true);
	return true;
}

static bool producer_on(const struct co_emcy *em)
{
	return em->enabled && (em->cob_id & COB_INVALID) == 0U;
}

static void arm_inhibit(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;

	if (em->q_count != 0U) {
		co_node_timer_start(node, &em->inhibit_timer,
				    MAX(em->last_tx_us + inhibit_us(em), em->retry_us));
	} else {
		co_timer_stop(&em->inhibit_timer);
	}
}

static void inhibit_expired(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	struct co_emcy *em = &node->emcy;

	if (em->q_count == 0U || !producer_on(em)) {
		return;
	}
	if (transmit(node, em->queue[em->q_head], now_us)) {
		em->q_head = (uint8_t)((em->q_head + 1U) % CONFIG_CANOPEN_EMCY_QUEUE);
		em->q_count--;
	}
	arm_inhibit(node);
}

static void flush_queue(struct co_emcy *em)
{
	co_timer_stop(&em->inhibit_timer);
	em->q_head = 0U;
	em->q_count = 0U;
}

static void emit(struct co_node *node, uint16_t code, uint8_t reg, const uint8_t msef[5])
{
	struct co_emcy *em = &node->emcy;
	uint64_t now = co_node_time(node);
	uint8_t data[8] = {(uint8_t)code, (uint8_t)(code >> 8), reg};

	if (!producer_on(em)) {
		return;
	}
	if (msef != NULL) {
		memcpy(&data[3], msef, 5);
	}
	if (em->q_count == 0U &&
	    (!em->sent_any || em->inhibit_100us == 0U ||
	     co_time_before_eq(em->last_tx_us + inhibit_us(em), now)) &&
	    transmit(node, data, now)) {
		return;
	}
	if (em->q_count == CONFIG_CANOPEN_EMCY_QUEUE) {
		em->overflows++;
		LOG_WRN("%s: EMCY %04x lost, inhibit queue full", node->name, code);
		return;
	}
	memcpy(em->queue[(em->q_head + em->q_count) % CONFIG_CANOPEN_EMCY_QUEUE], data, 8);
	em->q_count++;
	arm_inhibit(node);
}

/* --- Pre-defined error field 1003h -------------------------------------------------------- */

static void history_push(struct co_node *node, uint32_t entry)
{
	uint8_t max = node->emcy.hist_max;
	uint8_t count;

	if (max == 0U) {
		return;
	}
	count = (uint8_t)co_od_uint(&node->od, IDX_ERR_FIELD, 0, 0U);
	if (count > max) {
		count = max;
	}
	/* Newest at sub1; the oldest drops off when full. */
	for (uint8_t s = (count < max) ? count + 1U : max; s > 1U; s--) {
		od_put(node, IDX_ERR_FIELD, s, co_od_uint(&node->od, IDX_ERR_FIELD, s - 1U, 0U),
		       4U);
	}
	od_put(node, IDX_ERR_FIELD, 1, entry, 4U);
	od_put(node, IDX_ERR_FIELD, 0, count < max ? count + 1U : max, 1U);
}

static uint32_t history_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	if (node->emcy.self_write || req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	/* CiA 301 §7.5.2.3: only 0 may be written to sub0, and it clears the list. */
	if (req->info->sub != 0U || co_od_req_uint(req) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static void history_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	if (node->emcy.self_write || req->info->sub != 0U) {
		return;
	}
	for (uint8_t s = 1U; s <= node->emcy.hist_max; s++) {
		od_put(node, IDX_ERR_FIELD, s, 0U, 4U);
	}
}

#if defined(CO_OD_HOOK_READ_CHECK)
/* CiA 301 §7.5.2.3 / `[CON]`: an entry beyond the number of errors holds no data. */
static uint32_t history_read_check(const struct co_od *od, const struct co_od_info *info,
				   enum co_od_writer reader, void *user_data)
{
	struct co_node *node = user_data;

	if (info->sub == 0U || info->sub <= co_od_uint(&node->od, IDX_ERR_FIELD, 0, 0U)) {
		return 0U;
	}
	return CO_SDO_AB_NO_DATA;
}
#endif

static uint32_t reg_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	/* 1001h follows the active errors; only this module writes it. */
	return node->emcy.self_write ? 0U : CO_SDO_AB_READONLY;
}

/* --- 1014h, 1015h ------------------------------------------------------------------------- */

static uint32_t cob_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t old = node->emcy.cob_id;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	/* 29-bit identifiers are not supported: only 11-bit COB-IDs are served. */
	if ((v & COB_EXT) != 0U || (v & 0x1ffff800U) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if ((v & COB_INVALID) != 0U) {
		return 0U;
	}
	/* The CAN-ID may only change while the object is invalid (CiA 301 §7.5.2.15). */
	if ((old & COB_INVALID) == 0U && (old & 0x7ffU) != (v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (co_cob_id_restricted(v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static void cob_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->emcy.cob_id = (uint32_t)co_od_req_uint(req);
	if ((node->emcy.cob_id & COB_INVALID) != 0U) {
		flush_queue(&node->emcy);
	}
}

static void inhibit_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->emcy.inhibit_100us = (uint16_t)co_od_req_uint(req);
	/* Frames already waiting are due at the new inhibit time after the last one. */
	arm_inhibit(node);
}

/* --- Consumer 1028h ----------------------------------------------------------------------- */

/* Without consumer entries (CONFIG_CANOPEN_EMCY_CONSUMERS=0) nothing below is built. */
#if CONFIG_CANOPEN_EMCY_CONSUMERS > 0
static void cons_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_emcy *em = &node->emcy;
	uint16_t id = (uint16_t)frame->id;
	uint8_t remote = 0U;

	/* An EMCY is always 8 bytes (CiA 301 §7.2.7.3.1). */
	if (frame->dlc != 8U || (frame->flags & CAN_FRAME_RTR) != 0U || !em->enabled) {
		return;
	}
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/*
	 * A node on two lines hears an EMCY on both (the producer sends it on both): the same
	 * frame from the other line within the window is the copy of one taken there, and a copy
	 * ends the wait for the copies of that producer's (CAN-ID's) older frames, as for RPDOs.
	 * A repeat on the same line is a new emergency.
	 */
	if (co_rdn_is_copy(em->taken, (uint8_t)ARRAY_SIZE(em->taken), &em->taken_next,
			   co_node_rx_line(node), frame, now_us)) {
		return;
	}
#endif
	if (id > CO_EMCY_COB_ID && id <= CO_EMCY_COB_ID + 127U) {
		remote = (uint8_t)(id - CO_EMCY_COB_ID);
	}
	if (em->ind != NULL) {
		em->ind(node, id, remote, (uint16_t)(frame->data[0] | (frame->data[1] << 8)),
			frame->data[2], &frame->data[3], em->ind_user_data);
	}
	publish(node, frame, false);
}

static void cons_configure(struct co_node *node, int i, uint32_t v)
{
	struct co_rx *rx = &node->emcy.cons_rx[i];

	co_rx_unregister(rx);
	if ((v & (COB_INVALID | COB_EXT)) != 0U || (v & 0x7ffU) == 0U) {
		return;
	}
	rx->id = v & 0x7ffU;
	if (co_node_rx_register(node, CO_LINE_DEFAULT, rx) != 0) {
		LOG_ERR("%s: no receive slot for EMCY consumer %03x", node->name, rx->id);
	}
}

static void cons_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint8_t sub = req->info->sub;

	if (sub >= 1U && sub <= CONFIG_CANOPEN_EMCY_CONSUMERS) {
		cons_configure(node, sub - 1, (uint32_t)co_od_req_uint(req));
	}
}
#endif /* CONFIG_CANOPEN_EMCY_CONSUMERS > 0 */

/* --- Active errors ------------------------------------------------------------------------ */

static int find_active(const struct co_emcy *em, uint16_t code)
{
	for (int i = 0; i < em->n_active; i++) {
		if (em->active[i].code == code) {
			return i;
		}
	}
	return -1;
}

static int raise_locked(struct co_node *node, uint16_t code, uint8_t reg_bits,
			const uint8_t msef[5], bool internal)
{
	struct co_emcy *em = &node->emcy;
	int i = find_active(em, code);
	uint32_t info = (msef != NULL) ? (uint32_t)(msef[0] | (msef[1] << 8)) : 0U;
	int err = 0;

	reg_bits |= CO_EMCY_REG_GENERIC;
	if (i >= 0) {
		em->active[i].reg |= reg_bits;
	} else if (em->n_active < CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS) {
		em->active[em->n_active++] = (struct co_emcy_active){
			.code = code, .reg = reg_bits, .internal = internal};
	} else {
		/* No slot: its bits stay until the last clear. */
		em->lost_reg |= reg_bits;
		err = -ENOSPC;
	}
	update_reg(node);
	history_push(node, code | (info << 16));
	emit(node, code, em->reg, msef);
	return err;
}

static int clear_locked(struct co_node *node, uint16_t code)
{
	struct co_emcy *em = &node->emcy;
	int i = find_active(em, code);

	if (i < 0) {
		return -ENOENT;
	}
	em->active[i] = em->active[--em->n_active];
	if (em->n_active == 0U) {
		em->lost_reg = 0U;
	}
	update_reg(node);
	emit(node, CO_EMCY_NO_ERROR, em->reg, NULL);
	return 0;
}

/* --- 1029h and the stack's communication errors ------------------------------------------- */

static void error_behaviour(struct co_node *node, uint8_t sub)
{
	/* An absent 1029h behaves as its default, 0 (Pre-operational). */
	uint8_t beh = (uint8_t)co_od_uint(&node->od, IDX_BEHAVIOUR, sub, BEH_PRE_OPERATIONAL);

	switch (beh) {
	case BEH_PRE_OPERATIONAL:
		if (co_node_nmt_state(node) == CO_NMT_OPERATIONAL) {
			(void)co_nmt_req(node, CO_NMT_CS_ENTER_PRE_OPERATIONAL);
		}
		break;
	case BEH_STOPPED:
		(void)co_nmt_req(node, CO_NMT_CS_STOP);
		break;
	default:
		/* 1 = no change; reserved and manufacturer values change nothing either. */
		break;
	}
}

/* Another service's error (CO_EV_ERROR): raised once while present, cleared by its end. */
static void service_error(struct co_node *node, uint16_t code, uint8_t reg_bits, uint8_t info,
			  uint32_t detail, uint8_t flags)
{
	uint8_t msef[5] = {info};

	co_od_le_put(&msef[1], 4, detail);

	if ((flags & CO_ERROR_F_ACTIVE) == 0U) {
		(void)clear_locked(node, code);
		return;
	}
	if (find_active(&node->emcy, code) < 0) {
		(void)raise_locked(node, code, reg_bits, msef, true);
	}
	if ((flags & CO_ERROR_F_BEHAVIOUR) != 0U) {
		error_behaviour(node, 1U);
	}
}

/* --- Line events: 8110h, 8120h, 8140h ------------------------------------------------------ */

#if defined(CONFIG_CANOPEN_EMCY_LINE_EVENTS)

static void hold(struct co_node *node, struct co_timer *timer)
{
	if (CONFIG_CANOPEN_EMCY_COMM_HOLD_MS > 0) {
		co_node_timer_start(node, timer,
				    co_node_time(node) +
					    (uint64_t)CONFIG_CANOPEN_EMCY_COMM_HOLD_MS * 1000U);
	}
}

static void overrun_expired(struct co_timer *timer, uint64_t now_us)
{
	(void)clear_locked(timer->user_data, CO_EMCY_CAN_OVERRUN);
}

static void recovered_expired(struct co_timer *timer, uint64_t now_us)
{
	(void)clear_locked(timer->user_data, CO_EMCY_BUS_OFF_RECOV);
}

/* Frames were lost: one 8110h while it lasts, so a flood cannot become an EMCY flood. */
static void line_overrun(struct co_node *node, uint8_t which)
{
	const uint8_t msef[5] = {which};

	if (find_active(&node->emcy, CO_EMCY_CAN_OVERRUN) < 0) {
		(void)raise_locked(node, CO_EMCY_CAN_OVERRUN, CO_EMCY_REG_COMMUNICATION, msef,
				   true);
	}
	hold(node, &node->emcy.overrun_timer);
}

static void line_state(struct co_node *node, enum can_state to)
{
	struct co_emcy *em = &node->emcy;
	enum can_state from = (enum can_state)em->can_state;

	if (to == CAN_STATE_STOPPED || to == from) {
		/* A stopped controller says nothing about the bus. */
		return;
	}
	em->can_state = (uint8_t)to;
	if (to == CAN_STATE_BUS_OFF) {
		/* Nothing can be sent now; 8140h follows the recovery. CiA 301 §7.5.2.33:
		 * bus-off is a communication error for 1029h sub1.
		 */
		LOG_WRN("%s: bus-off", node->name);
		error_behaviour(node, 1U);
		return;
	}
	if (from == CAN_STATE_BUS_OFF) {
		/* Every recovery is reported, even while an earlier one is still held. */
		(void)raise_locked(node, CO_EMCY_BUS_OFF_RECOV, CO_EMCY_REG_COMMUNICATION, NULL,
				   true);
		hold(node, &em->recovered_timer);
	}
	if (to == CAN_STATE_ERROR_PASSIVE) {
		if (find_active(em, CO_EMCY_CAN_PASSIVE) < 0) {
			(void)raise_locked(node, CO_EMCY_CAN_PASSIVE, CO_EMCY_REG_COMMUNICATION,
					   NULL, true);
		}
	} else {
		/* Error-active or warning: both are "error active" in ISO 11898-1. */
		(void)clear_locked(node, CO_EMCY_CAN_PASSIVE);
	}
}

static void line_event(struct co_node *node, enum co_line_event event, int arg)
{
	switch (event) {
	case CO_LINE_EV_RX_OVERRUN:
		line_overrun(node, CO_EMCY_OVERRUN_RX);
		break;
	case CO_LINE_EV_TX_OVERFLOW:
		line_overrun(node, CO_EMCY_OVERRUN_TX);
		break;
	case CO_LINE_EV_CAN_STATE:
		line_state(node, (enum can_state)arg);
		break;
	default:
		/* A failed send is logged and counted by the line; CiA 301 has no code for it. */
		break;
	}
}

static void line_events_init(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;

	co_timer_init(&em->overrun_timer, overrun_expired, &node->lock, node);
	co_timer_init(&em->recovered_timer, recovered_expired, &node->lock, node);
	em->can_state = (uint8_t)CAN_STATE_ERROR_ACTIVE;
}

static void line_events_reset_comm(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;

	co_timer_stop(&em->overrun_timer);
	co_timer_stop(&em->recovered_timer);
	/* Still error passive: the condition has not gone away (already recorded in 1003h). */
	if (em->can_state == (uint8_t)CAN_STATE_ERROR_PASSIVE &&
	    find_active(em, CO_EMCY_CAN_PASSIVE) < 0 &&
	    em->n_active < CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS) {
		em->active[em->n_active++] = (struct co_emcy_active){
			.code = CO_EMCY_CAN_PASSIVE,
			.reg = CO_EMCY_REG_GENERIC | CO_EMCY_REG_COMMUNICATION,
			.internal = true};
	}
}

#endif /* CONFIG_CANOPEN_EMCY_LINE_EVENTS */

/* --- Events: other services' errors and the lines' events --------------------------------- */

static int node_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	ARG_UNUSED(user_data);
	if (ev->type == CO_EV_ERROR) {
		service_error(node, ev->error.code, ev->error.reg_bits, ev->error.info,
			      ev->error.detail, ev->error.flags);
	}
#if defined(CONFIG_CANOPEN_EMCY_LINE_EVENTS)
	/* The controller state of the default line; a redundant line's state is the
	 * redundancy service's to judge.
	 */
	if (ev->type == CO_EV_LINE && ev->line.idx == CO_LINE_DEFAULT) {
		line_event(node, ev->line.event, ev->line.arg);
	}
#endif
	return 0;
}

/* --- Node interface ----------------------------------------------------------------------- */

static int emcy_init(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_ERR_REG,
			.index_last = IDX_ERR_REG,
			.validate = reg_validate,
			.user_data = node,
		},
		{
			.index_first = IDX_ERR_FIELD,
			.index_last = IDX_ERR_FIELD,
			.sub_first = 0,
			.sub_last = 254,
			.validate = history_validate,
			.notify = history_notify,
			.user_data = node,
#if defined(CO_OD_HOOK_READ_CHECK)
			.read_check = history_read_check,
#endif
		},
		{
			.index_first = IDX_COB_ID,
			.index_last = IDX_COB_ID,
			.validate = cob_validate,
			.notify = cob_notify,
			.user_data = node,
		},
		{
			.index_first = IDX_INHIBIT,
			.index_last = IDX_INHIBIT,
			.notify = inhibit_notify,
			.user_data = node,
		},
#if CONFIG_CANOPEN_EMCY_CONSUMERS > 0
		{
			.index_first = IDX_CONSUMER,
			.index_last = IDX_CONSUMER,
			.sub_first = 1,
			.sub_last = 127,
			.notify = cons_notify,
			.user_data = node,
		},
#endif
	};
	int err;

	co_timer_init(&em->inhibit_timer, inhibit_expired, &node->lock, node);
#if CONFIG_CANOPEN_EMCY_CONSUMERS > 0
	for (int i = 0; i < CONFIG_CANOPEN_EMCY_CONSUMERS; i++) {
		co_rx_init(&em->cons_rx[i], 0U, cons_rx, &node->lock, node);
	}
#endif
	em->cob_id = COB_INVALID;
#if defined(CONFIG_CANOPEN_EMCY_LINE_EVENTS)
	line_events_init(node);
#endif
	co_listener_init(&em->listener, "emcy", CO_EV_BIT(CO_EV_ERROR) | CO_EV_BIT(CO_EV_LINE),
			 node_event, NULL);
	err = co_node_listener_add(node, &em->listener);
	if (err != 0) {
		return err;
	}
	return co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));
}

static void emcy_reset_comm(struct co_node *node)
{
	struct co_emcy *em = &node->emcy;
	struct co_od_info info;
	uint8_t n = 0U;

	flush_queue(em);
	em->overflows = 0U;
	em->sent_any = false;
	/* Without 1014h there is no EMCY producer. */
	em->cob_id = (uint32_t)co_od_uint(&node->od, IDX_COB_ID, 0, COB_INVALID);
	em->inhibit_100us = (uint16_t)co_od_uint(&node->od, IDX_INHIBIT, 0, 0U);

	/* 1003h entries served: the dictionary's array, at most CONFIG_CANOPEN_EMCY_HISTORY. */
	while (n < CONFIG_CANOPEN_EMCY_HISTORY &&
	       co_od_find(&node->od, IDX_ERR_FIELD, (uint8_t)(n + 1U), &info) == 0U) {
		n++;
	}
	em->hist_max = n;

	/* The stack's own errors restart with monitoring; the application's stay. */
	for (int i = 0; i < em->n_active;) {
		if (em->active[i].internal) {
			em->active[i] = em->active[--em->n_active];
		} else {
			i++;
		}
	}
#if defined(CONFIG_CANOPEN_EMCY_LINE_EVENTS)
	line_events_reset_comm(node);
#endif
	update_reg(node);

#if CONFIG_CANOPEN_EMCY_CONSUMERS > 0
	uint8_t count = (uint8_t)co_od_uint(&node->od, IDX_CONSUMER, 0, 0U);
	if (count > CONFIG_CANOPEN_EMCY_CONSUMERS) {
		LOG_WRN("%s: 1028h has %u entries, CONFIG_CANOPEN_EMCY_CONSUMERS=%d are served",
			node->name, count, CONFIG_CANOPEN_EMCY_CONSUMERS);
	}
	for (int i = 0; i < CONFIG_CANOPEN_EMCY_CONSUMERS; i++) {
		uint32_t v = i < count ? (uint32_t)co_od_uint(&node->od, IDX_CONSUMER,
							      (uint8_t)(i + 1), COB_INVALID)
				       : COB_INVALID;

		cons_configure(node, i, v);
	}
#endif
}

static void emcy_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	ARG_UNUSED(from);
	struct co_emcy *em = &node->emcy;

	/* CiA 301 Table 82: EMCY in Pre-operational and Operational only. */
	em->enabled = to == CO_NMT_PRE_OPERATIONAL || to == CO_NMT_OPERATIONAL;
	if (!em->enabled) {
		flush_queue(em);
	}
}

const struct co_service co_service_emcy = {
	.name = "emcy",
	.init = emcy_init,
	.reset_comm = emcy_reset_comm,
	.set_state = emcy_set_state,
};

/* --- API ---------------------------------------------------------------------------------- */

int co_emcy_raise(struct co_node *node, uint16_t code, uint8_t reg_bits, const uint8_t msef[5])
{
	int err;

	if (node == NULL || code == CO_EMCY_NO_ERROR) {
		return -EINVAL;
	}
	co_node_lock(node);
	err = raise_locked(node, code, reg_bits, msef, false);
	co_node_unlock(node);
	return err;
}

int co_emcy_clear(struct co_node *node, uint16_t code)
{
	int err;

	if (node == NULL) {
		return -EINVAL;
	}
	co_node_lock(node);
	err = clear_locked(node, code);
	co_node_unlock(node);
	return err;
}

bool co_emcy_is_active(struct co_node *node, uint16_t code)
{
	bool active;

	co_node_lock(node);
	active = find_active(&node->emcy, code) >= 0;
	co_node_unlock(node);
	return active;
}

uint8_t co_emcy_get_reg(struct co_node *node)
{
	uint8_t reg;

	co_node_lock(node);
	reg = node->emcy.reg;
	co_node_unlock(node);
	return reg;
}

void co_emcy_get_status(struct co_node *node, struct co_emcy_status *status)
{
	co_node_lock(node);
	status->active = node->emcy.n_active;
	status->queued = node->emcy.q_count;
	status->overflows = node->emcy.overflows;
	co_node_unlock(node);
}

void co_emcy_set_ind(struct co_node *node, co_emcy_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->emcy.ind = cb;
	node->emcy.ind_user_data = user_data;
	co_node_unlock(node);
}
