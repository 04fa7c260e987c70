/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Safety-relevant data objects (CiA 304 / EN 50325-5): producer, consumer with every check
 * inside the stack, the configuration rules of 1300h-13FFh and the global fail-safe command.
 *
 * Decisions (doc/srdo.md):
 * - The configuration is compiled once per entry into Operational, where it cannot change
 *   (writes are refused there with 08000022h). Timing checks use the frames' receive
 *   timestamps (the now_us the line hands to a receiver).
 * - The consumer keeps one timer at the earlier of its two deadlines: SRVT of the pending pair
 *   and SCT since the last valid pair. A frame is checked against both on its own timestamp
 *   too, so a frame the line thread reaches late is judged by when it arrived.
 * - Faults latch until the node leaves Operational; leaving it puts every SRDO in the safe
 *   state (reason "not operational") and withdraws the EMCYs of SRDO faults.
 * - 13FEh = A5h is checked when written and again before Operational: a failure there refuses
 *   Operational through the node's veto (CONFIG_CANOPEN_SRDO_PERMISSIVE_START: it is entered
 *   with the SRDOs held safe, as CANopenNode does), raises EMCY 6300h and clears 13FEh.
 * - SRDO 1's COB-IDs stored as the bare defaults FFh/100h are replaced by FFh/100h + 2 x
 *   node-ID at every Reset Communication (nodes 1..64), so they follow the node-ID and SDO
 *   reads see the real identifiers.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/crc.h>

#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/srdo.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define SUB_DIR   1U
#define SUB_CYCLE 2U
#define SUB_SRVT  3U
#define SUB_TT    4U
#define SUB_COB1  5U
#define SUB_COB2  6U

#define COB1_MIN 0x101U
#define COB1_MAX 0x17FU
#define COB2_MIN 0x102U
#define COB2_MAX 0x180U

#define MAP_MAX 16U

/* Emergencies raised, in the order report_clear() withdraws them. */
#define RAISED_PROTOCOL BIT(0)
#define RAISED_LENGTH   BIT(1)
#define RAISED_CONFIG   BIT(2)

/* Read back as "absent" by co_od_uint(): no SRDO parameter can hold it. */
#define ABSENT UINT32_MAX

/* The parameters of one SRDO as the dictionary holds them. */
struct srdo_params {
	uint32_t dir;
	uint32_t cycle;
	uint32_t srvt;
	uint32_t tt;
	uint32_t cob1;
	uint32_t cob2;
	uint32_t n_map;
	uint32_t map[MAP_MAX];
};

static inline uint16_t comm_idx(uint8_t n)
{
	return (uint16_t)(CO_SRDO_IDX_COMM + n);
}

static inline uint16_t map_idx(uint8_t n)
{
	return (uint16_t)(CO_SRDO_IDX_MAP + n);
}

static inline uint32_t cfg_err(uint16_t index, uint8_t sub, uint8_t cause)
{
	return ((uint32_t)index << 16) | ((uint32_t)sub << 8) | cause;
}

static struct co_srdo_inst *inst_of(struct co_node *node, uint8_t n)
{
	if (n == 0U || n > node->srdo.n_srdo) {
		return NULL;
	}
	return &node->srdo.inst[n - 1U];
}

static bool is_safe(uint8_t reason)
{
	return reason != CO_SRDO_R_NONE;
}

/* --- Events --------------------------------------------------------------------------------- */

static void announce(struct co_node *node, uint8_t n, uint8_t reason, uint64_t time_us)
{
	struct co_srdo *s = &node->srdo;
	struct co_event ev = {
		.type = CO_EV_SRDO,
		.srdo = {.srdo = n, .safe = is_safe(reason), .reason = reason, .time_us = time_us},
	};

	if (s->ind != NULL) {
		s->ind(node, n, is_safe(reason), (enum co_srdo_reason)reason, time_us,
		       s->ind_user_data);
	}
	(void)co_node_publish(node, &ev, NULL);
}

static void set_reason(struct co_srdo_inst *in, uint8_t reason, uint64_t time_us)
{
	if (in->reason == reason) {
		return;
	}
	in->reason = reason;
	announce(in->node, in->number, reason, time_us);
}

/* An emergency with a 32-bit detail in manufacturer bytes 1..4 (EMCY turns CO_EV_ERROR into it). */
static void report(struct co_node *node, uint16_t code, uint8_t srdo, uint32_t detail)
{
	struct co_event ev = {
		.type = CO_EV_ERROR,
		.error = {.code = code,
			  .reg_bits = CO_EMCY_REG_COMMUNICATION,
			  .info = srdo,
			  .detail = detail,
			  .flags = CO_ERROR_F_ACTIVE},
	};

	node->srdo.raised |= code == CO_EMCY_SRDO_PROTOCOL ? RAISED_PROTOCOL
			     : code == CO_EMCY_PDO_LENGTH  ? RAISED_LENGTH
							   : RAISED_CONFIG;
	(void)co_node_publish(node, &ev, NULL);
}

/* Withdraw the emergencies this service raised (the node left Operational). */
static void report_clear(struct co_node *node)
{
	static const uint16_t codes[] = {CO_EMCY_SRDO_PROTOCOL, CO_EMCY_PDO_LENGTH,
					 CO_EMCY_SRDO_CONFIG};

	for (uint8_t i = 0; i < ARRAY_SIZE(codes); i++) {
		if ((node->srdo.raised & BIT(i)) != 0U) {
			co_node_error(node, codes[i], CO_EMCY_REG_COMMUNICATION, 0U, 0U);
		}
	}
	node->srdo.raised = 0U;
}

/* Stop processing: the SRDO holds its user in the safe state until Operational is re-entered. */
static void fail(struct co_srdo_inst *in, uint8_t reason, uint64_t time_us)
{
	co_timer_stop(&in->timer);
	in->expect_inverted = false;
	if (reason == CO_SRDO_R_SHORT) {
		report(in->node, CO_EMCY_PDO_LENGTH, in->number, 0U);
	} else if (reason != CO_SRDO_R_TX_FAIL) {
		report(in->node, CO_EMCY_SRDO_PROTOCOL, in->number, reason);
	} else {
		/* TX_FAIL: a pair the line could not take; only the state and its reason record it.
		 */
	}
	set_reason(in, reason, time_us);
	LOG_WRN("%s: SRDO %u safe state (reason %u)", in->node->name, in->number, reason);
}

/* --- Configuration -------------------------------------------------------------------------- */

static void params_read(const struct co_od *od, uint8_t n, struct srdo_params *p)
{
	p->dir = co_od_uint(od, comm_idx(n), SUB_DIR, ABSENT);
	p->cycle = co_od_uint(od, comm_idx(n), SUB_CYCLE, ABSENT);
	p->srvt = co_od_uint(od, comm_idx(n), SUB_SRVT, ABSENT);
	p->tt = co_od_uint(od, comm_idx(n), SUB_TT, ABSENT);
	p->cob1 = co_od_uint(od, comm_idx(n), SUB_COB1, ABSENT);
	p->cob2 = co_od_uint(od, comm_idx(n), SUB_COB2, ABSENT);
	p->n_map = co_od_uint(od, map_idx(n), 0, ABSENT);
	for (uint8_t k = 0; k < MAP_MAX; k++) {
		p->map[k] =
			k < p->n_map ? co_od_uint(od, map_idx(n), (uint8_t)(k + 1U), ABSENT) : 0U;
	}
}

static uint16_t params_crc(const struct srdo_params *p)
{
	uint8_t b[1 + 2 + 1 + 4 + 4 + 1];
	uint16_t crc;

	b[0] = (uint8_t)p->dir;
	co_od_le_put(&b[1], 2, p->cycle);
	b[3] = (uint8_t)p->srvt;
	co_od_le_put(&b[4], 4, p->cob1);
	co_od_le_put(&b[8], 4, p->cob2);
	b[12] = (uint8_t)p->n_map;
	crc = crc16_itu_t(0U, b, sizeof(b));
	for (uint8_t k = 0; k < p->n_map && k < MAP_MAX; k++) {
		uint8_t e[5] = {(uint8_t)(k + 1U)};

		co_od_le_put(&e[1], 4, p->map[k]);
		crc = crc16_itu_t(crc, e, sizeof(e));
	}
	return crc;
}

uint16_t co_srdo_crc(uint16_t crc, const uint8_t *data, size_t len)
{
	return crc16_itu_t(crc, data, len);
}

/* Whether a value is allowed in a communication record sub-index (0 also for "absent"). */
static bool comm_value_ok(uint8_t sub, uint32_t v)
{
	switch (sub) {
	case SUB_DIR:
		return v <= CO_SRDO_DIR_RX;
	case SUB_CYCLE:
		return v >= 1U && v <= UINT16_MAX;
	case SUB_SRVT:
		return v >= 1U && v <= UINT8_MAX;
	case SUB_TT:
		return v == CO_SRDO_TT;
	case SUB_COB1:
		return (v & 1U) == 1U && v >= COB1_MIN && v <= COB1_MAX;
	case SUB_COB2:
		return (v & 1U) == 0U && v >= COB2_MIN && v <= COB2_MAX;
	default:
		return true;
	}
}

/* Resolve one mapping entry for the direction; 0 or the cause of a configuration fault. */
static uint8_t ent_resolve(const struct co_od *od, uint32_t entry, bool rx, struct co_srdo_ent *e)
{
	uint16_t index = (uint16_t)(entry >> 16);
	uint8_t sub = (uint8_t)(entry >> 8);
	uint8_t bits = (uint8_t)entry;

	(void)memset(e, 0, sizeof(*e));
	if (co_od_find(od, index, sub, &e->info) != 0U) {
		return CO_SRDO_CFG_NO_OBJECT;
	}
	/* Whole objects of whole bytes, mappable for the direction (the reader's rights). */
	if (bits == 0U || bits % 8U != 0U || bits / 8U != e->info.size ||
	    (e->info.flags & CO_OD_F_MAP) == 0U) {
		return CO_SRDO_CFG_MAPPING;
	}
	if (rx ? (e->info.access == CO_OD_ACCESS_RO || e->info.access == CO_OD_ACCESS_CONST ||
		  e->info.access == CO_OD_ACCESS_RWR)
	       : (e->info.access == CO_OD_ACCESS_WO || e->info.access == CO_OD_ACCESS_RWW)) {
		return CO_SRDO_CFG_MAPPING;
	}
	e->bytes = bits / 8U;
	return 0U;
}

/*
 * Check SRDO n as CiA 304 requires before it may run, and compile it into @p in when @p in is
 * not NULL. Returns 0, or the detail of a configuration fault (index << 16 | sub << 8 | cause).
 * SRDOs of direction 0 pass (they do not run).
 */
static uint32_t srdo_check(struct co_node *node, uint8_t n, struct co_srdo_inst *in)
{
	const struct co_od *od = &node->od;
	struct srdo_params p;
	uint8_t len[2] = {0U, 0U};
	uint8_t n_ent = 0U;

	params_read(od, n, &p);
	if (p.dir == ABSENT) {
		return cfg_err(comm_idx(n), SUB_DIR, CO_SRDO_CFG_MISSING);
	}
	if (p.dir == CO_SRDO_DIR_NONE) {
		return 0U;
	}
	if (co_od_uint(od, comm_idx(n), 0, 0U) != SUB_COB2) {
		return cfg_err(comm_idx(n), 0, CO_SRDO_CFG_VALUE);
	}
	const uint32_t comm[] = {p.dir, p.cycle, p.srvt, p.tt, p.cob1, p.cob2};

	for (uint8_t sub = SUB_DIR; sub <= SUB_COB2; sub++) {
		uint32_t v = comm[sub - SUB_DIR];

		if (v == ABSENT) {
			return cfg_err(comm_idx(n), sub, CO_SRDO_CFG_MISSING);
		}
		if (!comm_value_ok(sub, v)) {
			return cfg_err(comm_idx(n), sub, CO_SRDO_CFG_VALUE);
		}
	}
	if (p.cob2 != p.cob1 + 1U) {
		return cfg_err(comm_idx(n), SUB_COB2, CO_SRDO_CFG_VALUE);
	}
	if (p.n_map == ABSENT) {
		return cfg_err(map_idx(n), 0, CO_SRDO_CFG_MISSING);
	}
	if (p.n_map % 2U != 0U || p.n_map > MAP_MAX) {
		return cfg_err(map_idx(n), 0, CO_SRDO_CFG_VALUE);
	}
	if (p.n_map == 0U) {
		return cfg_err(map_idx(n), 0, CO_SRDO_CFG_EMPTY);
	}
	for (uint8_t k = 0; k < p.n_map; k++) {
		if (p.map[k] == ABSENT) {
			return cfg_err(map_idx(n), (uint8_t)(k + 1U), CO_SRDO_CFG_MISSING);
		}
	}
	if (co_od_uint(od, CO_SRDO_IDX_SIGNATURE, n, ABSENT) != params_crc(&p)) {
		return cfg_err(CO_SRDO_IDX_SIGNATURE, n, CO_SRDO_CFG_CRC);
	}

	/* The mapping: odd sub-indexes fill the normal frame, even ones the inverted frame. */
	for (uint8_t k = 0; k < p.n_map; k++) {
		struct co_srdo_ent tmp;
		struct co_srdo_ent *e = in != NULL ? &in->ent[n_ent] : &tmp;
		uint8_t half = k % 2U;
		uint8_t cause = ent_resolve(od, p.map[k], p.dir == CO_SRDO_DIR_RX, e);

		if (cause != 0U) {
			return cfg_err(map_idx(n), (uint8_t)(k + 1U), cause);
		}
		if (half == 1U && e->bytes != (uint8_t)(p.map[k - 1U] & 0xffU) / 8U) {
			return cfg_err(map_idx(n), (uint8_t)(k + 1U), CO_SRDO_CFG_PAIR_LEN);
		}
		e->offset = len[half];
		if (len[half] + e->bytes > 8U) {
			return cfg_err(map_idx(n), (uint8_t)(k + 1U), CO_SRDO_CFG_TOO_LONG);
		}
		len[half] = (uint8_t)(len[half] + e->bytes);
		n_ent++;
	}
	if (in == NULL) {
		return 0U;
	}

	/* Entries in mapping order: even positions are normal objects, odd ones inverted. */
	in->n_ent = n_ent;
	in->len = len[0];
	in->dir = (uint8_t)p.dir;
	in->cycle_us = p.cycle * 1000U;
	in->srvt_us = p.srvt * 1000U;
	in->cob1 = (uint16_t)p.cob1;
	in->cob2 = (uint16_t)p.cob2;
	return 0U;
}

/* Check every SRDO; returns 0 or the first fault's detail and its SRDO number in *which. */
static uint32_t check_all(struct co_node *node, uint8_t *which)
{
	for (uint8_t n = 1; n <= node->srdo.n_srdo; n++) {
		uint32_t err = srdo_check(node, n, NULL);

		if (err != 0U) {
			*which = n;
			return err;
		}
	}
	return 0U;
}

static bool config_declared_valid(const struct co_node *node)
{
	return co_od_uint(&node->od, CO_SRDO_IDX_VALID, 0, 0U) == CO_SRDO_VALID;
}

/* 13FEh := 0: the configuration must be checked and declared valid again. */
static void invalidate(struct co_node *node)
{
	(void)co_od_set_u8(&node->od, CO_SRDO_IDX_VALID, 0, 0U, CO_OD_WRITER_STORAGE);
}

/* --- Producer ------------------------------------------------------------------------------- */

/* Sample the mapped objects into the normal and inverted frames; false if one is unreadable. */
static bool pack(struct co_node *node, struct co_srdo_inst *in, struct can_frame f[2])
{
	f[0] = (struct can_frame){.id = in->cob1, .dlc = in->len};
	f[1] = (struct can_frame){.id = in->cob2, .dlc = in->len};
	for (uint8_t i = 0; i < in->n_ent; i++) {
		struct co_srdo_ent *e = &in->ent[i];
		size_t len = 0;

		if (co_od_read_info(&node->od, &e->info, 0U, &f[i % 2U].data[e->offset], e->bytes,
				    &len, CO_OD_WRITER_SRDO) != 0U) {
			return false;
		}
	}
	return true;
}

/* Queue one pair: both frames or neither, the normal frame first. */
static int send_pair(struct co_node *node, struct co_srdo_inst *in, uint64_t now_us)
{
	struct can_frame f[2];

	if (!pack(node, in, f) || co_node_tx_space(node, CO_ROUTE_PROCESS) < 2 ||
	    co_node_send(node, CO_ROUTE_PROCESS, &f[0]) != 0 ||
	    co_node_send(node, CO_ROUTE_PROCESS, &f[1]) != 0) {
		fail(in, CO_SRDO_R_TX_FAIL, now_us);
		return -ENOSPC;
	}
	set_reason(in, CO_SRDO_R_NONE, now_us);
	return 0;
}

static void producer_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_srdo_inst *in = timer->user_data;
	uint64_t next = timer->deadline + in->cycle_us;

	if (send_pair(in->node, in, now_us) != 0) {
		return;
	}
	/* Keep the cadence; after a stall start afresh rather than burst. */
	if (co_time_before_eq(next, now_us)) {
		next = now_us + in->cycle_us;
	}
	co_node_timer_start(in->node, timer, next);
}

/* --- Consumer ------------------------------------------------------------------------------- */

/*
 * The timer runs at the earlier deadline plus the hand-over allowance: a frame that arrived by
 * the deadline but still sits in the driver is then judged by its timestamp, not called
 * missing (CONFIG_CANOPEN_SRDO_RX_ALLOWANCE_US).
 */
static void consumer_arm(struct co_srdo_inst *in)
{
	uint64_t at = in->sct_deadline;

	if (in->expect_inverted && co_time_before_eq(in->srvt_deadline, at)) {
		at = in->srvt_deadline;
	}
	co_node_timer_start(in->node, &in->timer, at + CONFIG_CANOPEN_SRDO_RX_ALLOWANCE_US);
}

static void consumer_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_srdo_inst *in = timer->user_data;

	/* The fault happened at its deadline; now_us is when the line got to it. */
	if (in->expect_inverted && co_time_before_eq(in->srvt_deadline, in->sct_deadline)) {
		fail(in, CO_SRDO_R_SRVT, now_us);
	} else {
		fail(in, CO_SRDO_R_SCT, now_us);
	}
}

static bool running_consumer(const struct co_srdo_inst *in)
{
	/* A consumer runs while it waits for its first pair or receives valid ones. */
	return in->dir == CO_SRDO_DIR_RX &&
	       (in->reason == CO_SRDO_R_NONE || in->reason == CO_SRDO_R_STARTING);
}

static void rx_normal(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_srdo_inst *in = rx->user_data;

	/*
	 * A second normal frame while the inverted one is due is not a new pair (SRVT runs); a
	 * frame received before the consumer started belongs to no pair of this run.
	 */
	if (!running_consumer(in) || in->expect_inverted ||
	    (frame->flags & (CAN_FRAME_RTR | CAN_FRAME_IDE)) != 0U ||
	    !co_time_before_eq(in->start_us, now_us)) {
		return;
	}
	if (frame->dlc < in->len) {
		fail(in, CO_SRDO_R_SHORT, now_us);
		return;
	}
	(void)memcpy(in->normal, frame->data, in->len);
	in->expect_inverted = true;
	in->srvt_deadline = now_us + in->srvt_us;
	consumer_arm(in);
}

static void rx_inverted(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_srdo_inst *in = rx->user_data;
	struct co_node *node = in->node;

	/* An inverted frame without its normal frame is ignored. */
	if (!running_consumer(in) || !in->expect_inverted ||
	    (frame->flags & (CAN_FRAME_RTR | CAN_FRAME_IDE)) != 0U) {
		return;
	}
	in->expect_inverted = false;
	if (frame->dlc < in->len) {
		fail(in, CO_SRDO_R_SHORT, now_us);
		return;
	}
	/* Judged by the arrival time, whatever the line thread's delay. */
	if (!co_time_before_eq(now_us, in->srvt_deadline)) {
		fail(in, CO_SRDO_R_SRVT, now_us);
		return;
	}
	if (!co_time_before_eq(now_us, in->sct_deadline)) {
		fail(in, CO_SRDO_R_SCT, now_us);
		return;
	}
	for (uint8_t i = 0; i < in->len; i++) {
		if ((uint8_t)(in->normal[i] ^ frame->data[i]) != 0xffU) {
			fail(in, CO_SRDO_R_NOT_INVERTED, now_us);
			return;
		}
	}
	/* A valid pair: both channels reach the dictionary. */
	for (uint8_t i = 0; i < in->n_ent; i++) {
		struct co_srdo_ent *e = &in->ent[i];
		const uint8_t *src = i % 2U == 0U ? in->normal : frame->data;

		(void)co_od_write_info(&node->od, &e->info, &src[e->offset], e->bytes,
				       CO_OD_WRITER_SRDO);
	}
	in->sct_deadline = now_us + in->cycle_us;
	consumer_arm(in);
	set_reason(in, CO_SRDO_R_NONE, now_us);
}

/* --- Life cycle ----------------------------------------------------------------------------- */

static void inst_stop(struct co_srdo_inst *in)
{
	co_timer_stop(&in->timer);
	co_rx_unregister(&in->rx_normal);
	co_rx_unregister(&in->rx_inverted);
	in->expect_inverted = false;
}

/* Entering Operational: compile and start each SRDO (the configuration was checked). */
static void srdo_start(struct co_node *node, struct co_srdo_inst *in, bool valid, uint64_t now)
{
	uint8_t n = in->number;
	uint32_t err;

	in->dir = (uint8_t)co_od_uint(&node->od, comm_idx(n), SUB_DIR, CO_SRDO_DIR_NONE);
	if (in->dir == CO_SRDO_DIR_NONE || in->dir > CO_SRDO_DIR_RX) {
		/* A deleted SRDO holds nobody in the safe state and reports nothing. */
		in->dir = CO_SRDO_DIR_NONE;
		in->reason = CO_SRDO_R_NONE;
		return;
	}
	if (!valid) {
		set_reason(in, CO_SRDO_R_CONFIG, now);
		return;
	}
	err = srdo_check(node, n, in);
	if (err == 0U && in->dir == CO_SRDO_DIR_RX &&
	    (co_node_rx_set_id(node, CO_LINE_DEFAULT, &in->rx_normal, in->cob1) != 0 ||
	     co_node_rx_set_id(node, CO_LINE_DEFAULT, &in->rx_inverted, in->cob2) != 0)) {
		err = cfg_err(comm_idx(n), SUB_COB1, CO_SRDO_CFG_RX_SLOT);
	}
	if (err != 0U) {
		inst_stop(in);
		report(node, CO_EMCY_SRDO_CONFIG, n, err);
		set_reason(in, CO_SRDO_R_CONFIG, now);
		return;
	}
	set_reason(in, CO_SRDO_R_STARTING, now);
	co_timer_init(&in->timer, in->dir == CO_SRDO_DIR_TX ? producer_timer : consumer_timer,
		      &node->lock, in);
	if (in->dir == CO_SRDO_DIR_TX) {
		/* Stagger the first pairs of a broadcast start: node-ID x 0.5 ms. */
		co_node_timer_start(node, &in->timer,
				    now + (uint64_t)co_node_id(node) *
						    CONFIG_CANOPEN_SRDO_START_STAGGER_US);
	} else {
		in->start_us = now;
		in->sct_deadline = now + in->cycle_us;
		consumer_arm(in);
	}
}

static void srdo_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	struct co_srdo *s = &node->srdo;
	uint64_t now = co_node_time(node);

	if (to == CO_NMT_OPERATIONAL) {
		uint8_t which = 0U;
		bool valid = config_declared_valid(node);
		uint32_t err = valid ? check_all(node, &which) : 0U;

		/* Reached only with the permissive start (the veto refuses otherwise). */
		if (err != 0U) {
			report(node, CO_EMCY_SRDO_CONFIG, which, err);
			invalidate(node);
			valid = false;
		}
		for (uint8_t i = 0; i < s->n_srdo; i++) {
			srdo_start(node, &s->inst[i], valid, now);
		}
		return;
	}
	if (from != CO_NMT_OPERATIONAL) {
		return;
	}
	for (uint8_t i = 0; i < s->n_srdo; i++) {
		struct co_srdo_inst *in = &s->inst[i];

		inst_stop(in);
		if (in->dir != CO_SRDO_DIR_NONE) {
			set_reason(in, CO_SRDO_R_NOT_OPERATIONAL, now);
		}
	}
	/* The faults of this Operational phase are over with it. */
	report_clear(node);
}

/* The veto: Operational only with a consistent configuration when 13FEh declares it valid. */
static int node_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	uint8_t which = 0U;
	uint32_t err;

	ARG_UNUSED(user_data);
	if (ev->type != CO_EV_NMT_VETO || ev->nmt.to != CO_NMT_OPERATIONAL ||
	    !config_declared_valid(node)) {
		return 0;
	}
	err = check_all(node, &which);
	if (err == 0U) {
		return 0;
	}
	LOG_WRN("%s: SRDO %u configuration fault %08x: Operational refused", node->name, which,
		err);
	report(node, CO_EMCY_SRDO_CONFIG, which, err);
	invalidate(node);
	return -EPERM;
}

/* --- GFC ------------------------------------------------------------------------------------ */

static void gfc_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	enum co_nmt_state st = co_node_nmt_state(node);

	if (!node->srdo.gfc_valid || frame->dlc != 0U ||
	    (frame->flags & (CAN_FRAME_RTR | CAN_FRAME_IDE)) != 0U ||
	    (st != CO_NMT_PRE_OPERATIONAL && st != CO_NMT_OPERATIONAL)) {
		return;
	}
	announce(node, 0U, CO_SRDO_R_GFC, now_us);
}

/* --- Hooks ---------------------------------------------------------------------------------- */

static bool locked(const struct co_node *node)
{
	return co_node_nmt_state(node) == CO_NMT_OPERATIONAL;
}

static uint32_t gfc_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	return co_od_req_uint(req) > 1U ? CO_SDO_AB_INVALID_VALUE : 0U;
}

static void gfc_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->srdo.gfc_valid = co_od_req_uint(req) == 1U;
}

static uint32_t comm_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint8_t sub = req->info->sub;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (locked(node)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	return sub >= SUB_DIR && !comm_value_ok(sub, (uint32_t)co_od_req_uint(req))
		       ? CO_SDO_AB_INVALID_VALUE
		       : 0U;
}

static uint32_t map_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint8_t n = (uint8_t)(req->info->index - CO_SRDO_IDX_MAP);
	uint8_t sub = req->info->sub;
	uint32_t v = (uint32_t)co_od_req_uint(req);

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (locked(node)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	/* A mapping changes only while the SRDO is off and its entries are disabled. */
	if (co_od_uint(od, comm_idx(n), SUB_DIR, CO_SRDO_DIR_NONE) != CO_SRDO_DIR_NONE) {
		return CO_SDO_AB_UNSUPP_ACCESS;
	}
	if (sub != 0U) {
		return co_od_uint(od, map_idx(n), 0, 0U) != 0U ? CO_SDO_AB_UNSUPP_ACCESS : 0U;
	}
	if (v % 2U != 0U || v > MAP_MAX) {
		return CO_SDO_AB_MAP_LEN;
	}
	/* Enabling: every entry names a whole object and each frame holds at most 8 bytes. */
	uint32_t bytes[2] = {0U, 0U};

	for (uint8_t k = 1; k <= v; k++) {
		uint32_t e = co_od_uint(od, map_idx(n), k, 0U);
		struct co_od_info info;

		if (co_od_find(od, (uint16_t)(e >> 16), (uint8_t)(e >> 8), &info) != 0U) {
			return CO_SDO_AB_NO_MAP;
		}
		if ((e & 0xffU) == 0U || (e & 7U) != 0U || (e & 0xffU) / 8U != info.size ||
		    (info.flags & CO_OD_F_MAP) == 0U) {
			return CO_SDO_AB_NO_MAP;
		}
		bytes[k % 2U] += (e & 0xffU) / 8U;
		if (k % 2U == 0U &&
		    (e & 0xffU) != (co_od_uint(od, map_idx(n), k - 1U, 0U) & 0xffU)) {
			return CO_SDO_AB_MAP_LEN;
		}
	}
	return bytes[0] > 8U || bytes[1] > 8U ? CO_SDO_AB_MAP_LEN : 0U;
}

static uint32_t sig_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	return locked(node) ? CO_SDO_AB_DATA_DEV_STATE : 0U;
}

static uint32_t valid_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint8_t which = 0U;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (locked(node)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	/* Declaring the configuration valid checks it now, not only at the next start. */
	if (co_od_req_uint(req) == CO_SRDO_VALID && check_all(node, &which) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

/* Any accepted change of the configuration withdraws its declaration of validity. */
static void config_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	if (req->writer != CO_OD_WRITER_STORAGE) {
		invalidate(user_data);
	}
}

/* --- Node interface ------------------------------------------------------------------------- */

static int srdo_init(struct co_node *node)
{
	struct co_srdo *s = &node->srdo;
	struct co_od_info info;
	const struct co_od_hook hooks[] = {
		{
			.index_first = CO_SRDO_IDX_GFC,
			.index_last = CO_SRDO_IDX_GFC,
			.validate = gfc_validate,
			.notify = gfc_notify,
			.user_data = node,
		},
		{
			.index_first = comm_idx(1),
			.index_last = comm_idx(CO_SRDO_MAX),
			.sub_last = 255,
			.validate = comm_validate,
			.notify = config_notify,
			.user_data = node,
		},
		{
			.index_first = map_idx(1),
			.index_last = map_idx(CO_SRDO_MAX),
			.sub_last = 255,
			.validate = map_validate,
			.notify = config_notify,
			.user_data = node,
		},
		{
			.index_first = CO_SRDO_IDX_VALID,
			.index_last = CO_SRDO_IDX_VALID,
			.validate = valid_validate,
			.user_data = node,
		},
		{
			.index_first = CO_SRDO_IDX_SIGNATURE,
			.index_last = CO_SRDO_IDX_SIGNATURE,
			.sub_first = 1,
			.sub_last = 255,
			.validate = sig_validate,
			.notify = config_notify,
			.user_data = node,
		},
	};

	(void)memset(s, 0, sizeof(*s));
	for (uint8_t n = 1; n <= CO_SRDO_MAX; n++) {
		if (co_od_find(&node->od, comm_idx(n), 0, &info) != 0U) {
			continue;
		}
		if (n > CONFIG_CANOPEN_SRDOS) {
			LOG_ERR("%s: SRDO %u beyond CONFIG_CANOPEN_SRDOS", node->name, n);
			return -ENOSPC;
		}
		s->n_srdo = n;
	}
	for (uint8_t i = 0; i < s->n_srdo; i++) {
		struct co_srdo_inst *in = &s->inst[i];
		bool has_comm = co_od_find(&node->od, comm_idx(i + 1U), 0, &info) == 0U;
		bool has_map = co_od_find(&node->od, map_idx(i + 1U), 0, &info) == 0U;

		if (has_comm != has_map) {
			LOG_ERR("%s: SRDO %u has only one of its records", node->name, i + 1U);
			return -EINVAL;
		}
		in->node = node;
		in->number = (uint8_t)(i + 1U);
		co_rx_init(&in->rx_normal, 0U, rx_normal, &node->lock, in);
		co_rx_init(&in->rx_inverted, 0U, rx_inverted, &node->lock, in);
		co_timer_init(&in->timer, consumer_timer, &node->lock, in);
	}
	co_rx_init(&s->gfc_rx, CO_SRDO_GFC_COB_ID, gfc_rx, &node->lock, node);
	co_listener_init(&s->listener, "srdo", CO_EV_BIT(CO_EV_NMT_VETO), node_event, NULL);

	int err = co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));

	if (err == 0 && !IS_ENABLED(CONFIG_CANOPEN_SRDO_PERMISSIVE_START)) {
		err = co_node_listener_add(node, &s->listener);
	}
	if (err == 0 && co_od_find(&node->od, CO_SRDO_IDX_GFC, 0, &info) == 0U) {
		err = co_node_rx_register(node, CO_LINE_DEFAULT, &s->gfc_rx);
	}
	return err;
}

static void srdo_reset_comm(struct co_node *node)
{
	struct co_srdo *s = &node->srdo;
	uint8_t id = co_node_id(node);

	s->gfc_valid = co_od_uint(&node->od, CO_SRDO_IDX_GFC, 0, 0U) == 1U;
	for (uint8_t i = 0; i < s->n_srdo; i++) {
		struct co_srdo_inst *in = &s->inst[i];

		inst_stop(in);
		in->dir = (uint8_t)co_od_uint(&node->od, comm_idx(in->number), SUB_DIR, 0U);
		in->reason =
			in->dir == CO_SRDO_DIR_NONE ? CO_SRDO_R_NONE : CO_SRDO_R_NOT_OPERATIONAL;
	}
	/* SRDO 1's default COB-IDs follow the node-ID (CiA 304: FFh/100h + 2 x node-ID). */
	if (s->n_srdo >= 1U && id >= 1U && id <= 64U &&
	    co_od_uint(&node->od, comm_idx(1), SUB_COB1, 0U) == CO_SRDO_COB1_BASE &&
	    co_od_uint(&node->od, comm_idx(1), SUB_COB2, 0U) == CO_SRDO_COB2_BASE) {
		(void)co_od_set_u32(&node->od, comm_idx(1), SUB_COB1, CO_SRDO_COB1_BASE + 2U * id,
				    CO_OD_WRITER_STORAGE);
		(void)co_od_set_u32(&node->od, comm_idx(1), SUB_COB2, CO_SRDO_COB2_BASE + 2U * id,
				    CO_OD_WRITER_STORAGE);
	}
}

const struct co_service co_service_srdo = {
	.name = "srdo",
	.init = srdo_init,
	.reset_comm = srdo_reset_comm,
	.set_state = srdo_set_state,
};

/* --- API ------------------------------------------------------------------------------------ */

bool co_srdo_may_leave_safe_state(struct co_node *node)
{
	bool ok;

	co_node_lock(node);
	/*
	 * Operational with a configuration declared valid (and so checked on the way in): an
	 * SRDO deleted over SDO withdraws 13FEh, so it cannot release the outputs by its absence.
	 */
	ok = co_node_nmt_state(node) == CO_NMT_OPERATIONAL && config_declared_valid(node);
	for (uint8_t i = 0; i < node->srdo.n_srdo; i++) {
		const struct co_srdo_inst *in = &node->srdo.inst[i];

		if (in->dir != CO_SRDO_DIR_NONE && in->reason != CO_SRDO_R_NONE) {
			ok = false;
		}
	}
	co_node_unlock(node);
	return ok;
}

int co_srdo_get_state(struct co_node *node, uint8_t srdo, enum co_srdo_reason *reason)
{
	int ret;

	co_node_lock(node);
	struct co_srdo_inst *in = inst_of(node, srdo);

	if (in == NULL) {
		ret = -EINVAL;
	} else if (in->dir == CO_SRDO_DIR_NONE) {
		ret = CO_SRDO_STATE_DELETED;
	} else {
		ret = is_safe(in->reason) ? CO_SRDO_STATE_SAFE : CO_SRDO_STATE_VALID;
	}
	if (reason != NULL) {
		*reason = (in != NULL && in->dir != CO_SRDO_DIR_NONE)
				  ? (enum co_srdo_reason)in->reason
				  : CO_SRDO_R_NONE;
	}
	co_node_unlock(node);
	return ret;
}

int co_srdo_send_req(struct co_node *node, uint8_t srdo)
{
	int ret;

	co_node_lock(node);
	struct co_srdo_inst *in = inst_of(node, srdo);
	uint64_t now = co_node_time(node);

	if (in == NULL || co_od_uint(&node->od, comm_idx(srdo), SUB_DIR, 0U) != CO_SRDO_DIR_TX) {
		ret = -EINVAL;
	} else if (co_node_nmt_state(node) != CO_NMT_OPERATIONAL || in->dir != CO_SRDO_DIR_TX ||
		   (in->reason != CO_SRDO_R_NONE && in->reason != CO_SRDO_R_STARTING)) {
		ret = -ENETDOWN;
	} else {
		ret = send_pair(node, in, now);
		if (ret == 0) {
			co_node_timer_start(node, &in->timer, now + in->cycle_us);
		}
	}
	co_node_unlock(node);
	return ret;
}

int co_srdo_gfc_req(struct co_node *node)
{
	const struct can_frame f = {.id = CO_SRDO_GFC_COB_ID, .dlc = 0U};
	enum co_nmt_state st;
	int ret;

	co_node_lock(node);
	st = co_node_nmt_state(node);
	if (!node->srdo.gfc_valid) {
		ret = -EPERM;
	} else if (st != CO_NMT_PRE_OPERATIONAL && st != CO_NMT_OPERATIONAL) {
		ret = -ENETDOWN;
	} else {
		ret = co_node_send(node, CO_ROUTE_PROCESS, &f);
	}
	co_node_unlock(node);
	return ret;
}

void co_srdo_set_ind(struct co_node *node, co_srdo_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->srdo.ind = cb;
	node->srdo.ind_user_data = user_data;
	co_node_unlock(node);
}

int co_srdo_signature(struct co_node *node, uint8_t srdo, uint16_t *crc)
{
	struct srdo_params p;
	int ret = 0;

	co_node_lock(node);
	if (inst_of(node, srdo) == NULL) {
		ret = -EINVAL;
	} else {
		params_read(&node->od, srdo, &p);
		if (p.dir == ABSENT || p.cycle == ABSENT || p.srvt == ABSENT || p.cob1 == ABSENT ||
		    p.cob2 == ABSENT || p.n_map == ABSENT || p.n_map > MAP_MAX) {
			ret = -EINVAL;
		} else {
			*crc = params_crc(&p);
		}
	}
	co_node_unlock(node);
	return ret;
}
