/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO service (CiA 301 §7.2.2): RPDOs and TPDOs configured by 1400h-1BFFh. Writes to those
 * objects are checked by validate hooks and applied by notify hooks at once; the mapping is
 * compiled into a table of resolved objects when sub-index 0 of a mapping record is written.
 *
 * Decisions (doc/pdo.md):
 * - A change that the PDO's present state forbids (CAN-ID, inhibit time, SYNC start value or
 *   mapping while the PDO is valid; mapping entries while sub 0 != 0) is refused with
 *   06090030h. Mapping writes in Operational: 08000022h unless
 *   CONFIG_CANOPEN_PDO_REMAP_IN_OPERATIONAL.
 * - The inhibit time applies to every transmission type. A transmission that falls into it
 *   is remembered and made once when it ends; a synchronous sample that would then leave the
 *   SYNC window (1007h) is dropped.
 * - The SYNC whose counter equals the SYNC start value counts as the first SYNC; a cyclic
 *   TPDO of type n is sent at the n-th SYNC counted from there. Without a start value the
 *   first SYNC in Operational counts as the first.
 * - An RPDO longer than its mapping is processed and raises EMCY 8220h; a shorter one is
 *   dropped and raises 8210h; a frame of the mapped length clears both. The deadline monitor
 *   (event timer) arms at the first reception and raises 8250h, cleared at the next frame.
 * - Change of state: every committed write (except storage restores) to an object mapped
 *   into a valid TPDO of type 0, 254 or 255 is an event. Each mapped object takes one OD
 *   hook while the TPDO has such a type.
 * - MPDOs (mapping sub 0 FEh/FFh, mpdo.c) need type 254/255 (06090030h otherwise, for the
 *   mapping and for the type); they have no event timer, no RTR and no change of state. An
 *   MPDO shorter than 8 bytes is a length error (8210h) as for any RPDO; a DAM-MPDO to a
 *   missing object raises 8230h, cleared by the next DAM-MPDO written.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/cob_id.h>
#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/redundancy.h>

#include "node_internal.h"
#include "pdo_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_RPDO_COMM 0x1400U
#define IDX_RPDO_MAP  0x1600U
#define IDX_TPDO_COMM 0x1800U
#define IDX_TPDO_MAP  0x1A00U

#define SUB_COB_ID     1U
#define SUB_TYPE       2U
#define SUB_INHIBIT    3U
#define SUB_EVENT      5U
#define SUB_SYNC_START 6U

#define MAP_SAM_MPDO CO_MPDO_SAM
#define MAP_DAM_MPDO CO_MPDO_DAM
#define MAP_MAX      64U

/* 8230h: DAM MPDO not processed, destination object not available (CiA 301 table 21). */
#define EMCY_DAM_MISSING 0x8230U

#define ERR_SHORT   BIT(0)
#define ERR_LONG    BIT(1)
#define ERR_TIMEOUT BIT(2)
#define ERR_DAM     BIT(3)

/* A change the PDO's present state forbids (CiA 301 §7.5.2.35-38). */
#define AB_PDO_STATE CO_SDO_AB_INVALID_VALUE

#define CAN_ID_STD 0x7FFU
#define CAN_ID_EXT 0x1FFFFFFFU

/* --- Helpers ------------------------------------------------------------------------------ */

static bool cob_valid(uint32_t cob)
{
	return (cob & CO_PDO_COB_INVALID) == 0U;
}

static uint32_t cob_can_id(uint32_t cob)
{
	return (cob & CO_PDO_COB_FRAME) != 0U ? (cob & CAN_ID_EXT) : (cob & CAN_ID_STD);
}

static bool is_sync_type(uint8_t type)
{
	return type <= CO_PDO_TT_SYNC_MAX;
}

/*
 * Without the SYNC service nothing would ever trigger a synchronous PDO (0..240, and the
 * synchronous RTR type 252): refuse the type.
 */
static bool sync_type_served(uint8_t type)
{
	return IS_ENABLED(CONFIG_CANOPEN_SYNC) ||
	       !(is_sync_type(type) || type == CO_PDO_TT_RTR_SYNC);
}

static bool is_event_type(uint8_t type)
{
	return type == CO_PDO_TT_EVENT_MANUF || type == CO_PDO_TT_EVENT_PROF;
}

static bool is_rtr_type(uint8_t type)
{
	return type == CO_PDO_TT_RTR_SYNC || type == CO_PDO_TT_RTR_EVENT;
}

static bool is_mpdo_map(uint64_t n)
{
	return n == MAP_SAM_MPDO || n == MAP_DAM_MPDO;
}

/* Types that react to application events and changes of state. */
static bool uses_events(uint8_t type)
{
	return type == CO_PDO_TT_SYNC_ACYCLIC || is_event_type(type);
}

static bool before(uint64_t a, uint64_t b)
{
	return !co_time_before_eq(b, a);
}

static struct co_rpdo *rpdo_of(struct co_node *node, uint16_t index, uint16_t base)
{
	uint16_t num = index - base;

	if (num >= CO_RPDOS || !node->pdo.rpdo[num].present) {
		return NULL;
	}
	return &node->pdo.rpdo[num];
}

static struct co_tpdo *tpdo_of(struct co_node *node, uint16_t index, uint16_t base)
{
	uint16_t num = index - base;

	if (num >= CO_TPDOS || !node->pdo.tpdo[num].present) {
		return NULL;
	}
	return &node->pdo.tpdo[num];
}

/*
 * Check (out == NULL) or compile the first n entries of a mapping record. The abort codes
 * are those of CiA 301 §7.5.2.36 step 4.
 */
static uint32_t map_build(struct co_node *node, bool rx, uint16_t num, uint8_t n,
			  struct co_pdo_map *out, uint8_t *runs)
{
	uint16_t index = (rx ? IDX_RPDO_MAP : IDX_TPDO_MAP) + num;
	struct co_pdo_map_ent ent;
	struct co_pdo_map_ent prev = {0};
	unsigned int total = 0;
	bool bytewise = true;

	*runs = 0U;

	if (out != NULL) {
		out->n = 0U;
		out->bits = 0U;
		out->bytewise = true;
		out->hook_gen = 0U;
	}
	if (n > CO_PDO_MAP_ENTRIES) {
		return CO_SDO_AB_MAP_LEN;
	}
	for (uint8_t i = 1; i <= n; i++) {
		uint8_t buf[4] = {0};
		size_t len = 0;

		/* A record with fewer entries than sub 0 asks for: too many objects. */
		if (co_od_read(&node->od, index, i, 0, buf, sizeof(buf), &len, CO_OD_WRITER_APP) !=
		    0U) {
			return CO_SDO_AB_MAP_LEN;
		}
		uint32_t ab =
			co_pdo_map_check(&node->od, rx, (uint32_t)co_od_le_get(buf, len), &ent);

		if (ab != 0U) {
			return ab;
		}
		total += co_pdo_ent_bits(&ent);
		if (total > CO_PDO_MAX_BITS) {
			return CO_SDO_AB_MAP_LEN;
		}
		if (co_pdo_ent_bits(&ent) % 8U != 0U) {
			bytewise = false;
		}
		/* Consecutive sub-indexes of one object share a change-of-state hook. */
		if (i == 1U || co_pdo_ent_index(&prev) != co_pdo_ent_index(&ent) ||
		    co_pdo_ent_sub(&prev) + 1U != co_pdo_ent_sub(&ent)) {
			(*runs)++;
		}
		prev = ent;
		if (out != NULL) {
			out->ent[i - 1U] = ent;
		}
	}
	if (out != NULL) {
		out->n = n;
		out->bits = (uint8_t)total;
		out->bytewise = bytewise;
	}
	return 0U;
}

/* --- EMCY of RPDOs ------------------------------------------------------------------------ */

static void rpdo_error(struct co_rpdo *r, uint8_t bit, bool on)
{
	if (((r->errors & bit) != 0U) == on) {
		return;
	}
	r->errors ^= bit;
	struct co_node *node = r->node;
	uint16_t code = bit == ERR_SHORT  ? CO_EMCY_PDO_LENGTH
			: bit == ERR_LONG ? CO_EMCY_PDO_LENGTH_EXC
			: bit == ERR_DAM  ? EMCY_DAM_MISSING
					  : CO_EMCY_RPDO_TIMEOUT;

	if (on) {
		co_node_error(node, code, CO_EMCY_REG_COMMUNICATION, 0U, CO_ERROR_F_ACTIVE);
		return;
	}
	/* The code stays active while any other RPDO still has the same fault. */
	for (int i = 0; i < CO_RPDOS; i++) {
		if ((node->pdo.rpdo[i].errors & bit) != 0U) {
			return;
		}
	}
	co_node_error(node, code, CO_EMCY_REG_COMMUNICATION, 0U, 0U);
}

/* --- RPDO --------------------------------------------------------------------------------- */

static void rpdo_indicate(struct co_rpdo *r)
{
	struct co_pdo *pdo = &r->node->pdo;

	if (pdo->rpdo_ind != NULL) {
		pdo->rpdo_ind(r->node, r->num, pdo->rpdo_ind_user_data);
	}
}

/* A received MPDO (DLC 8): the object side is in mpdo.c. */
static void rpdo_mpdo(struct co_rpdo *r, const struct can_frame *frame)
{
#if defined(CONFIG_CANOPEN_MPDO)
	switch (co_mpdo_rx(r->node, r->mpdo, frame->data)) {
	case CO_MPDO_RX_WRITTEN:
		if (r->mpdo == MAP_DAM_MPDO) {
			rpdo_error(r, ERR_DAM, false);
		}
		rpdo_indicate(r);
		break;
	case CO_MPDO_RX_MISSING:
		rpdo_error(r, ERR_DAM, true);
		break;
	default:
		break;
	}
#endif
}

#if defined(CONFIG_CANOPEN_REDUNDANCY)
static bool any_lost(const uint32_t lost[4])
{
	return (lost[0] | lost[1] | lost[2] | lost[3]) != 0U;
}

/*
 * A line on which a supervised node's heartbeat is lost while the other line has them all
 * is failing: what it still delivers comes late (a cut controller's held frame when it comes
 * back, frames a flood held up) and the other line has had every value already.
 */
static bool line_failing(const struct co_pdo *pdo, uint8_t line)
{
	return line < 2U && any_lost(pdo->hb_lost[line]) && !any_lost(pdo->hb_lost[line ^ 1U]);
}

/*
 * A node on two lines hears a PDO on both. A frame is the copy of one of the last frames taken
 * from the other line when it has the same data within the window; each taken frame has one
 * copy. Keeping several (not just the last) lets a line thread that is late by a few frames
 * catch up without its copies passing as new values. Frames on the same line are never
 * copies (a value may repeat), and after a line is lost the other line's frames are taken as
 * they come. Nothing is taken from a failing line (line_failing()).
 */
static bool rpdo_duplicate(struct co_rpdo *r, const struct can_frame *frame, uint64_t now_us)
{
	uint8_t line = co_node_rx_line(r->node);

	if (line_failing(&r->node->pdo, line)) {
		r->node->pdo.rx_duplicates++;
		return true;
	}

	if (co_rdn_is_copy(r->taken, (uint8_t)ARRAY_SIZE(r->taken), &r->taken_next, line, frame,
			   now_us)) {
		r->node->pdo.rx_duplicates++;
		return true;
	}
	return false;
}
#endif

uint32_t co_pdo_rx_duplicates(struct co_node *node)
{
	uint32_t n = 0U;

#if defined(CONFIG_CANOPEN_REDUNDANCY)
	co_node_lock(node);
	n = node->pdo.rx_duplicates;
	co_node_unlock(node);
#else
	ARG_UNUSED(node);
#endif
	return n;
}

static void rpdo_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_rpdo *r = rx->user_data;
	struct co_node *node = r->node;
	struct co_pdo *pdo = &node->pdo;
	/* An MPDO always has 8 bytes (CiA 301 §7.2.3). */
	uint8_t mapped = r->mpdo != 0U ? 8U : (uint8_t)((r->map.bits + 7U) / 8U);

	if ((frame->flags & CAN_FRAME_RTR) != 0U || !pdo->operational || !cob_valid(r->cob_id)) {
		return;
	}
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	if (rpdo_duplicate(r, frame, now_us)) {
		return;
	}
#endif
	if (frame->dlc < mapped) {
		rpdo_error(r, ERR_SHORT, true);
		return;
	}
	/* Nothing to raise or clear for a frame of the mapped length on an RPDO without one. */
	if (unlikely((r->errors & (ERR_SHORT | ERR_LONG)) != 0U || frame->dlc > mapped)) {
		rpdo_error(r, ERR_SHORT, false);
		rpdo_error(r, ERR_LONG, frame->dlc > mapped);
	}
	if (r->event_ms != 0U) {
		co_node_timer_start(node, &r->timer, now_us + (uint64_t)r->event_ms * 1000U);
		rpdo_error(r, ERR_TIMEOUT, false);
	}
	if (r->mpdo != 0U) {
		rpdo_mpdo(r, frame);
		return;
	}
	if (is_sync_type(r->type)) {
		/* Outside the SYNC window the frame belongs to no SYNC (CiA 301 §7.5.2.7). */
		if (pdo->window && before(pdo->window_end, now_us)) {
			return;
		}
		memcpy(r->sync_data, frame->data, mapped);
		r->sync_dlc = mapped;
		r->sync_pending = true;
		pdo->rx_sync_pending = true;
		return;
	}
	(void)co_pdo_map_unpack(&node->od, &r->map, frame->data);
	rpdo_indicate(r);
}

/* A synchronous RPDO at its SYNC: out of line, the frame path keeps the inlined copy. */
static __attribute__((noinline)) void rpdo_commit(struct co_rpdo *r, const uint8_t *data)
{
	(void)co_pdo_map_unpack(&r->node->od, &r->map, data);
	rpdo_indicate(r);
}

static void rpdo_timeout(struct co_timer *timer, uint64_t now_us)
{
	struct co_rpdo *r = timer->user_data;

	if (r->node->pdo.operational && cob_valid(r->cob_id) && r->event_ms != 0U) {
		rpdo_error(r, ERR_TIMEOUT, true);
	}
}

static void rpdo_configure(struct co_rpdo *r)
{
	struct co_node *node = r->node;

#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/* Nothing taken yet: no frame is anybody's copy. */
	(void)memset(r->taken, 0, sizeof(r->taken));
#endif

	co_timer_stop(&r->timer);
	r->sync_pending = false;
	co_rx_unregister(&r->rx);
	if (!cob_valid(r->cob_id)) {
		rpdo_error(r, ERR_SHORT, false);
		rpdo_error(r, ERR_LONG, false);
		rpdo_error(r, ERR_TIMEOUT, false);
		rpdo_error(r, ERR_DAM, false);
		return;
	}
	r->rx.ext = (r->cob_id & CO_PDO_COB_FRAME) != 0U;
	r->rx.mask = r->rx.ext ? CAN_ID_EXT : CAN_ID_STD;
	if (co_node_rx_set_id(node, CO_LINE_DEFAULT, &r->rx, cob_can_id(r->cob_id)) != 0) {
		LOG_ERR("%s: no receive slot for RPDO %u", node->name, r->num);
	}
}

/* --- TPDO --------------------------------------------------------------------------------- */

static CO_HOT_INLINE void tpdo_sample_now(struct co_tpdo *t)
{
	struct co_pdo *pdo = &t->node->pdo;

	if (pdo->tpdo_ind != NULL) {
		t->sampling = true;
		pdo->tpdo_ind(t->node, t->num, pdo->tpdo_ind_user_data);
		t->sampling = false;
	}
	t->dlc = co_pdo_map_pack(&t->node->od, &t->map, t->buf);
}

/* Inlined where a SYNC samples (the hot path), a call elsewhere. */
static __attribute__((noinline)) void tpdo_sample(struct co_tpdo *t)
{
	tpdo_sample_now(t);
}

static bool tpdo_inhibited(const struct co_tpdo *t, uint64_t now)
{
	return t->inhibit_us != 0U && before(now, t->inhibit_end);
}

static void tpdo_event_timer_restart(struct co_tpdo *t, uint64_t now)
{
	co_timer_stop(&t->event_timer);
	if (t->node->pdo.operational && cob_valid(t->cob_id) && is_event_type(t->type) &&
	    t->event_ms != 0U && t->mpdo == 0U) {
		co_node_timer_start(t->node, &t->event_timer, now + (uint64_t)t->event_ms * 1000U);
	}
}

/* Send the sample in buf now. */
static void tpdo_transmit(struct co_tpdo *t, uint64_t now)
{
	struct can_frame f = {
		.id = cob_can_id(t->cob_id),
		.dlc = t->dlc,
		.flags = (t->cob_id & CO_PDO_COB_FRAME) != 0U ? CAN_FRAME_IDE : 0U,
	};

	memcpy(f.data, t->buf, sizeof(t->buf));
	int err = co_node_send(t->node, CO_ROUTE_PROCESS, &f);

	/* Redundancy supervises TPDO 1's sends (CiA 302-6); nobody listening costs one test. */
	if ((t->node->listen_mask & CO_EV_BIT(CO_EV_TPDO)) != 0U) {
		struct co_event ev = {.type = CO_EV_TPDO, .tpdo = {.num = t->num, .err = err}};

		(void)co_node_publish(t->node, &ev, NULL);
	}
	t->deferred = false;
	t->inhibit_end = now + t->inhibit_us;
	if (is_event_type(t->type)) {
		tpdo_event_timer_restart(t, now);
	}
}

static void tpdo_defer(struct co_tpdo *t)
{
	if (!co_timer_is_armed(&t->inhibit_timer)) {
		co_node_timer_start(t->node, &t->inhibit_timer, t->inhibit_end);
	}
}

/* A synchronous sample is ready in buf: send it, or when the inhibit time ends. */
static void tpdo_send_sample(struct co_tpdo *t, uint64_t now)
{
	if (tpdo_inhibited(t, now)) {
		t->deferred = true;
		tpdo_defer(t);
		return;
	}
	tpdo_transmit(t, now);
}

/* Event-driven transmission: sample and send now, or once when the inhibit time ends. */
static void tpdo_send_event(struct co_tpdo *t, uint64_t now)
{
	if (tpdo_inhibited(t, now)) {
		t->event = true;
		tpdo_defer(t);
		return;
	}
	t->event = false;
	tpdo_sample(t);
	tpdo_transmit(t, now);
}

/* An application event, a change of state or a remote request on an event-driven TPDO. */
static void tpdo_event(struct co_tpdo *t, uint64_t now)
{
	if (t->type == CO_PDO_TT_SYNC_ACYCLIC) {
		t->event = true;
	} else if (is_event_type(t->type)) {
		tpdo_send_event(t, now);
	}
}

int co_tpdo_mpdo_send(struct co_tpdo *t, const uint8_t data[8])
{
	if (t->deferred) {
		/* One frame waits for the inhibit time already; MPDOs of different objects
		 * cannot be merged into one.
		 */
		return -EBUSY;
	}
	memcpy(t->buf, data, sizeof(t->buf));
	t->dlc = 8U;
	tpdo_send_sample(t, co_node_time(t->node));
	return 0;
}

static void tpdo_inhibit_expired(struct co_timer *timer, uint64_t now_us)
{
	struct co_tpdo *t = timer->user_data;
	struct co_pdo *pdo = &t->node->pdo;

	if (!pdo->operational || !cob_valid(t->cob_id)) {
		return;
	}
	if (t->deferred) {
		/* A sample that missed its SYNC window is stale (CiA 301 §7.5.2.7). */
		if (is_sync_type(t->type) && pdo->window && before(pdo->window_end, now_us)) {
			t->deferred = false;
		} else {
			tpdo_transmit(t, now_us);
		}
	}
	if (t->event && is_event_type(t->type)) {
		tpdo_send_event(t, now_us);
	}
}

static void tpdo_event_expired(struct co_timer *timer, uint64_t now_us)
{
	struct co_tpdo *t = timer->user_data;

	if (t->node->pdo.operational && cob_valid(t->cob_id) && is_event_type(t->type)) {
		tpdo_send_event(t, now_us);
	}
}

#if defined(CONFIG_CANOPEN_PDO_RTR)
static void tpdo_rtr(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_tpdo *t = rx->user_data;

	if ((frame->flags & CAN_FRAME_RTR) == 0U || !t->node->pdo.operational ||
	    !cob_valid(t->cob_id) || (t->cob_id & CO_PDO_COB_NO_RTR) != 0U || t->mpdo != 0U) {
		return;
	}
	switch (t->type) {
	case CO_PDO_TT_RTR_SYNC:
		if (t->sampled) {
			tpdo_send_sample(t, now_us);
		}
		break;
	case CO_PDO_TT_RTR_EVENT:
		tpdo_sample(t);
		tpdo_send_sample(t, now_us);
		break;
	default:
		tpdo_event(t, now_us);
		break;
	}
}
#endif /* CONFIG_CANOPEN_PDO_RTR */

static void tpdo_reset_state(struct co_tpdo *t)
{
	co_timer_stop(&t->inhibit_timer);
	co_timer_stop(&t->event_timer);
	t->started = false;
	t->sync_count = 0U;
	t->event = false;
	t->deferred = false;
	t->sampled = false;
	t->inhibit_end = co_node_time(t->node);
}

static void tpdo_configure(struct co_tpdo *t)
{
	struct co_node *node = t->node;

	tpdo_reset_state(t);
#if defined(CONFIG_CANOPEN_PDO_RTR)
	co_rx_unregister(&t->rx);
#endif
	if (!cob_valid(t->cob_id)) {
		return;
	}
#if defined(CONFIG_CANOPEN_PDO_RTR)
	if ((t->cob_id & CO_PDO_COB_NO_RTR) == 0U) {
		t->rx.ext = (t->cob_id & CO_PDO_COB_FRAME) != 0U;
		t->rx.mask = t->rx.ext ? CAN_ID_EXT : CAN_ID_STD;
		if (co_node_rx_set_id(node, CO_LINE_DEFAULT, &t->rx, cob_can_id(t->cob_id)) != 0) {
			LOG_ERR("%s: no receive slot for TPDO %u RTR", node->name, t->num);
		}
	}
#endif
	tpdo_event_timer_restart(t, co_node_time(node));
}

/* --- Change of state ---------------------------------------------------------------------- */

static void cos_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_tpdo *t = user_data;

	if (req->writer == CO_OD_WRITER_STORAGE || t->sampling || !t->node->pdo.operational ||
	    !cob_valid(t->cob_id)) {
		return;
	}
	tpdo_event(t, co_node_time(t->node));
}

/*
 * Whether @p n change-of-state hooks fit in place of the TPDO's present ones: a hook each,
 * and at most a link each (one index of the dictionary, none for a provider's object).
 */
static bool cos_hooks_room(const struct co_node *node, const struct co_tpdo *t, uint32_t n)
{
	const struct co_od *od = &node->od;

	return n <= (uint32_t)CO_OD_HOOKS_MAX - od->n_hooks + t->n_hooks &&
	       n <= (uint32_t)CO_OD_HOOK_LINKS - od->n_links + t->n_hooks;
}

/* Hooks a mapping needs: one per run of consecutive sub-indexes of one object. */
static uint8_t cos_hooks_needed(const struct co_pdo_map *map, uint8_t type)
{
	uint8_t n = 0U;

	if (!uses_events(type)) {
		return 0U;
	}
	for (uint8_t i = 0; i < map->n; i++) {
		const struct co_pdo_map_ent *a = &map->ent[i];
		const struct co_pdo_map_ent *p = i > 0U ? &map->ent[i - 1U] : NULL;

		if (p == NULL || co_pdo_ent_index(p) != co_pdo_ent_index(a) ||
		    co_pdo_ent_sub(p) + 1U != co_pdo_ent_sub(a)) {
			n++;
		}
	}
	return n;
}

static uint32_t cos_hooks_fit(struct co_node *node, const struct co_tpdo *t,
			      const struct co_pdo_map *map, uint8_t type)
{
	return cos_hooks_room(node, t, cos_hooks_needed(map, type)) ? 0U : CO_SDO_AB_DEV_INCOMPAT;
}

static void cos_hooks_update(struct co_tpdo *t)
{
	struct co_od *od = &t->node->od;

	(void)co_od_hook_unregister(od, t);
	t->n_hooks = 0U;
	if (!uses_events(t->type)) {
		return;
	}
	for (uint8_t i = 0; i < t->map.n; i++) {
		uint16_t index = co_pdo_ent_index(&t->map.ent[i]);
		uint8_t sub = co_pdo_ent_sub(&t->map.ent[i]);
		struct co_od_hook h = {index, index, sub, sub, NULL, cos_notify, t};

		while (i + 1U < t->map.n && co_pdo_ent_index(&t->map.ent[i + 1U]) == index &&
		       co_pdo_ent_sub(&t->map.ent[i + 1U]) == h.sub_last + 1U) {
			h.sub_last++;
			i++;
		}
		if (co_od_hook_register(od, &h) != 0) {
			LOG_ERR("%s: no OD hook for change of state of %04Xh", t->node->name,
				index);
			continue;
		}
		t->n_hooks++;
	}
}

/* --- SYNC --------------------------------------------------------------------------------- */

static void tpdo_sync(struct co_tpdo *t, uint8_t counter, uint64_t now)
{
	if (t->type == CO_PDO_TT_SYNC_ACYCLIC) {
		if (!t->event) {
			return;
		}
		t->event = false;
	} else if (t->type <= CO_PDO_TT_SYNC_MAX) {
		if (!t->started) {
			/* With a counter and a start value, counting starts at the matching SYNC.
			 */
			if (t->sync_start != 0U && counter != 0U && counter != t->sync_start) {
				return;
			}
			t->started = true;
			t->sync_count = 0U;
		}
		if (++t->sync_count < t->type) {
			return;
		}
		t->sync_count = 0U;
	} else {
		if (t->type == CO_PDO_TT_RTR_SYNC) {
			tpdo_sample(t);
			t->sampled = true;
		}
		return;
	}
	tpdo_sample_now(t);
	tpdo_send_sample(t, now);
}

/* A SYNC: synchronous TPDOs sampled and sent, synchronous RPDOs committed (CiA 301 §7.2.2.2). */
static void pdo_sync(struct co_node *node, uint8_t counter, uint64_t now_us, uint32_t window_us)
{
	struct co_pdo *pdo = &node->pdo;

	if (!pdo->operational) {
		return;
	}
	pdo->window = window_us != 0U;
	pdo->window_end = now_us + window_us;
	/* Inputs are sampled before the outputs of this SYNC are applied. */
	for (int i = 0; i < CO_TPDOS; i++) {
		struct co_tpdo *t = &pdo->tpdo[i];

		if (t->present && cob_valid(t->cob_id)) {
			tpdo_sync(t, counter, now_us);
		}
	}
	if (!pdo->rx_sync_pending) {
		return;
	}
	pdo->rx_sync_pending = false;
	for (int i = 0; i < CO_RPDOS; i++) {
		struct co_rpdo *r = &pdo->rpdo[i];

		if (r->present && r->sync_pending && cob_valid(r->cob_id) &&
		    is_sync_type(r->type)) {
			r->sync_pending = false;
			rpdo_commit(r, r->sync_data);
		}
		/* One that cannot be committed now stays counted (and an indication may have
		 * received another).
		 */
		pdo->rx_sync_pending |= r->sync_pending;
	}
}

static int sync_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	ARG_UNUSED(user_data);
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	if (ev->type == CO_EV_REDUNDANCY) {
		uint8_t id = ev->redundancy.node_id;
		uint32_t *word = &node->pdo.hb_lost[ev->redundancy.line & 1U][(id / 32U) & 3U];

		if (ev->redundancy.what == CO_RDN_EV_HB_ERROR) {
			*word |= BIT(id % 32U);
		} else if (ev->redundancy.what == CO_RDN_EV_HB_OK) {
			*word &= ~BIT(id % 32U);
		}
		return 0;
	}
#endif
	pdo_sync(node, ev->sync.counter, ev->sync.time_us, ev->sync.window_us);
	return 0;
}

/* --- Hooks on 1400h-1BFFh ----------------------------------------------------------------- */

/*
 * A new COB-ID (sub-index 1) of an RPDO or TPDO whose COB-ID is @p cur: the CAN-ID changes only
 * while the PDO is invalid, an 11-bit ID has no bits above 10 and is not a restricted one.
 */
static uint32_t cob_id_check(uint32_t cur, uint64_t v)
{
	if (cob_valid(cur) && cob_valid((uint32_t)v) &&
	    ((v ^ cur) & ~(uint64_t)CO_PDO_COB_INVALID) != 0U) {
		return AB_PDO_STATE;
	}
	if ((v & CO_PDO_COB_FRAME) == 0U && (v & 0x1FFFF800U) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (cob_valid((uint32_t)v) && (v & CO_PDO_COB_FRAME) == 0U &&
	    co_cob_id_restricted((uint32_t)v & CAN_ID_STD)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

/*
 * One validate for the RPDO (1400h..) and TPDO (1800h..) communication records: the checks
 * they share are written once; the TPDO-only ones follow the shared ones as before.
 */
static uint32_t comm_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint16_t index = req->info->index;
	bool rx = index < IDX_TPDO_COMM;
	struct co_rpdo *r = rx ? rpdo_of(node, index, IDX_RPDO_COMM) : NULL;
	struct co_tpdo *t = rx ? NULL : tpdo_of(node, index, IDX_TPDO_COMM);
	uint64_t v = co_od_req_uint(req);
	uint32_t cob_id;
	uint8_t mpdo;

	if ((r == NULL && t == NULL) || req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	cob_id = rx ? r->cob_id : t->cob_id;
	mpdo = rx ? r->mpdo : t->mpdo;
	switch (req->info->sub) {
	case SUB_COB_ID: {
		uint32_t ab = cob_id_check(cob_id, v);

		/* An RTR-only TPDO needs remote requests. */
		if (!rx && ab == 0U && (v & CO_PDO_COB_NO_RTR) != 0U && is_rtr_type(t->type)) {
			ab = CO_SDO_AB_INVALID_VALUE;
		}
		return ab;
	}
	case SUB_TYPE:
		/* 241..253 are reserved for RPDOs, 241..251 for TPDOs (CiA 301 §7.5.2.35). */
		if (v > CO_PDO_TT_SYNC_MAX &&
		    v < (rx ? CO_PDO_TT_EVENT_MANUF : CO_PDO_TT_RTR_SYNC)) {
			return CO_SDO_AB_INVALID_VALUE;
		}
		if (!sync_type_served((uint8_t)v)) {
			return CO_SDO_AB_INVALID_VALUE;
		}
		if (!rx && is_rtr_type((uint8_t)v) &&
		    (!IS_ENABLED(CONFIG_CANOPEN_PDO_RTR) || (cob_id & CO_PDO_COB_NO_RTR) != 0U)) {
			return CO_SDO_AB_INVALID_VALUE;
		}
		if (mpdo != 0U && !is_event_type((uint8_t)v)) {
			return AB_PDO_STATE; /* MPDOs are event-driven only */
		}
		return rx ? 0U : cos_hooks_fit(node, t, &t->map, (uint8_t)v);
	case SUB_INHIBIT:
		return !rx && cob_valid(cob_id) ? AB_PDO_STATE : 0U;
	case SUB_SYNC_START:
		if (rx) {
			return 0U;
		}
		if (cob_valid(cob_id)) {
			return AB_PDO_STATE;
		}
		return v > CO_PDO_TT_SYNC_MAX ? CO_SDO_AB_INVALID_VALUE : 0U;
	default:
		return 0U;
	}
}

/* One notify for the RPDO and TPDO communication records (one prologue). */
static void comm_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	uint16_t index = req->info->index;
	uint64_t v = co_od_req_uint(req);

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return;
	}
	if (index < IDX_TPDO_COMM) {
		struct co_rpdo *r = rpdo_of(user_data, index, IDX_RPDO_COMM);

		if (r == NULL) {
			return;
		}
		switch (req->info->sub) {
		case SUB_COB_ID:
			r->cob_id = (uint32_t)v;
			rpdo_configure(r);
			break;
		case SUB_TYPE:
			r->type = (uint8_t)v;
			r->sync_pending = false;
			break;
		case SUB_EVENT:
			r->event_ms = (uint16_t)v;
			if (r->event_ms == 0U) {
				co_timer_stop(&r->timer);
				rpdo_error(r, ERR_TIMEOUT, false);
			} else if (co_timer_is_armed(&r->timer)) {
				co_node_timer_start(r->node, &r->timer,
						    co_node_time(r->node) +
							    (uint64_t)r->event_ms * 1000U);
			}
			break;
		default:
			break;
		}
		return;
	}
	struct co_tpdo *t = tpdo_of(user_data, index, IDX_TPDO_COMM);

	if (t == NULL) {
		return;
	}
	switch (req->info->sub) {
	case SUB_COB_ID:
		t->cob_id = (uint32_t)v;
		tpdo_configure(t);
		break;
	case SUB_TYPE: {
		bool hooks_change = uses_events(t->type) != uses_events((uint8_t)v);

		t->type = (uint8_t)v;
		/* Re-hook only when needed (od.c copes with changes from inside its loop). */
		if (hooks_change) {
			cos_hooks_update(t);
		}
		tpdo_configure(t);
		break;
	}
	case SUB_INHIBIT:
		t->inhibit_us = (uint32_t)v * 100U;
		break;
	case SUB_EVENT:
		t->event_ms = (uint16_t)v;
		tpdo_event_timer_restart(t, co_node_time(t->node));
		break;
	case SUB_SYNC_START:
		t->sync_start = (uint8_t)v;
		t->started = false;
		break;
	default:
		break;
	}
}

#if defined(CONFIG_CANOPEN_PDO_DYNAMIC_MAPPING)
static uint32_t map_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint16_t index = req->info->index;
	bool rx = index < IDX_TPDO_MAP;
	struct co_rpdo *r = rx ? rpdo_of(node, index, IDX_RPDO_MAP) : NULL;
	struct co_tpdo *t = rx ? NULL : tpdo_of(node, index, IDX_TPDO_MAP);
	uint16_t num = rx ? index - IDX_RPDO_MAP : index - IDX_TPDO_MAP;
	uint64_t v = co_od_req_uint(req);

	if ((r == NULL && t == NULL) || req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	if (node->pdo.operational && !IS_ENABLED(CONFIG_CANOPEN_PDO_REMAP_IN_OPERATIONAL)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (cob_valid(rx ? r->cob_id : t->cob_id)) {
		return AB_PDO_STATE;
	}
	if (req->info->sub != 0U) {
		struct co_pdo_map_ent ent;

		/* Entries change only while the mapping is off (sub 0 = 0). */
		if (co_od_uint(&node->od, index, 0, 0U) != 0U) {
			return AB_PDO_STATE;
		}
		return v == 0U ? 0U : co_pdo_map_check(&node->od, rx, (uint32_t)v, &ent);
	}
	if (is_mpdo_map(v)) {
		/* MPDOs are event-driven only (CiA 301 §7.2.3). */
		if (!IS_ENABLED(CONFIG_CANOPEN_MPDO) || !is_event_type(rx ? r->type : t->type)) {
			return CO_SDO_AB_INVALID_VALUE;
		}
		return 0U;
	}
	if (v > MAP_MAX) {
		return CO_SDO_AB_MAP_LEN;
	}
	uint8_t runs;
	uint32_t ab = map_build(node, rx, num, (uint8_t)v, NULL, &runs);

	if (ab == 0U && t != NULL && uses_events(t->type) && !cos_hooks_room(node, t, runs)) {
		/* No OD hook left for change-of-state detection of these objects. */
		ab = CO_SDO_AB_DEV_INCOMPAT;
	}
	return ab;
}

static void map_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint16_t index = req->info->index;
	bool rx = index < IDX_TPDO_MAP;
	struct co_rpdo *r = rx ? rpdo_of(node, index, IDX_RPDO_MAP) : NULL;
	struct co_tpdo *t = rx ? NULL : tpdo_of(node, index, IDX_TPDO_MAP);
	uint8_t n = (uint8_t)co_od_req_uint(req);

	if ((r == NULL && t == NULL) || req->writer == CO_OD_WRITER_STORAGE ||
	    req->info->sub != 0U) {
		return;
	}
	uint8_t runs;
	uint8_t mpdo = is_mpdo_map(n) ? n : 0U;

	/* An MPDO has no compiled mapping: each frame names its object. */
	if (r != NULL) {
		r->mpdo = mpdo;
		(void)map_build(node, true, r->num, mpdo != 0U ? 0U : n, &r->map, &runs);
		r->sync_pending = false;
	} else {
		t->mpdo = mpdo;
		(void)map_build(node, false, t->num, mpdo != 0U ? 0U : n, &t->map, &runs);
		t->sampled = false;
		t->deferred = false;
		cos_hooks_update(t);
	}
}
#define MAP_NOTIFY map_notify
#else /* !CONFIG_CANOPEN_PDO_DYNAMIC_MAPPING */
/* Static mapping: a restore from storage takes effect at the next reset of communication. */
static uint32_t map_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	return req->writer == CO_OD_WRITER_STORAGE ? 0U : CO_SDO_AB_READONLY;
}
#define MAP_NOTIFY NULL
#endif /* CONFIG_CANOPEN_PDO_DYNAMIC_MAPPING */

/* --- Node interface ----------------------------------------------------------------------- */

static bool od_has(struct co_node *node, uint16_t index)
{
	struct co_od_info info;

	return co_od_find(&node->od, index, 0, &info) == 0U;
}

/*
 * The service's hooks, RPDO communication and mapping records first, then the TPDOs' (the
 * order pdo_init() registers them in); index_last and user_data are filled in there.
 */
static const struct co_od_hook pdo_hooks[] = {
	{
		.index_first = IDX_RPDO_COMM,
		.sub_first = 1,
		.sub_last = 6,
		.validate = comm_validate,
		.notify = comm_notify,
	},
	{
		.index_first = IDX_RPDO_MAP,
		.sub_first = 0,
		.sub_last = MAP_MAX,
		.validate = map_validate,
		.notify = MAP_NOTIFY,
	},
	{
		.index_first = IDX_TPDO_COMM,
		.sub_first = 1,
		.sub_last = 6,
		.validate = comm_validate,
		.notify = comm_notify,
	},
	{
		.index_first = IDX_TPDO_MAP,
		.sub_first = 0,
		.sub_last = MAP_MAX,
		.validate = map_validate,
		.notify = MAP_NOTIFY,
	},
};

/* Instances of RPDOs or TPDOs the node has. */
static uint16_t pdo_count(bool rx)
{
	return rx ? (uint16_t)CO_RPDOS : (uint16_t)CO_TPDOS;
}

static int pdo_init(struct co_node *node)
{
	struct co_pdo *pdo = &node->pdo;
	int err = 0;

	for (uint16_t i = 0; i < CO_RPDOS; i++) {
		struct co_rpdo *r = &pdo->rpdo[i];

		r->node = node;
		r->num = i;
		r->present = true; /* cleared below unless both records exist */
		r->cob_id = CO_PDO_COB_INVALID;
		co_rx_init(&r->rx, 0U, rpdo_rx, &node->lock, r);
		co_timer_init(&r->timer, rpdo_timeout, &node->lock, r);
	}
	for (uint16_t i = 0; i < CO_TPDOS; i++) {
		struct co_tpdo *t = &pdo->tpdo[i];

		t->node = node;
		t->num = i;
		t->present = true;
		t->cob_id = CO_PDO_COB_INVALID;
#if defined(CONFIG_CANOPEN_PDO_RTR)
		co_rx_init(&t->rx, 0U, tpdo_rtr, &node->lock, t);
#endif
		co_timer_init(&t->inhibit_timer, tpdo_inhibit_expired, &node->lock, t);
		co_timer_init(&t->event_timer, tpdo_event_expired, &node->lock, t);
	}
	/*
	 * One scan per record kind: an instance is present with both its records; more PDOs in
	 * the dictionary than instances are refused rather than ignored.
	 */
	for (size_t h = 0; h < ARRAY_SIZE(pdo_hooks); h++) {
		bool rx = h < 2U;

		for (uint16_t i = 0; i < 512U; i++) {
			bool has = od_has(node, pdo_hooks[h].index_first + i);

			if (i < pdo_count(rx)) {
				if (!has && rx) {
					pdo->rpdo[i].present = false;
				} else if (!has) {
					pdo->tpdo[i].present = false;
				}
			} else if (has) {
				LOG_ERR("%s: %cPDO %u in the dictionary, CONFIG_CANOPEN_%cPDOS=%d",
					node->name, rx ? 'R' : 'T', i, rx ? 'R' : 'T',
					rx ? CO_RPDOS : CO_TPDOS);
				return -ENOSPC;
			}
		}
	}
	/* One batch from the table above, ranges cut to the instances the node has. */
	struct co_od_hook hooks[ARRAY_SIZE(pdo_hooks)];
	size_t n = 0;

	for (size_t h = 0; h < ARRAY_SIZE(pdo_hooks); h++) {
		uint16_t count = pdo_count(h < 2U);

		if (count > 0U) {
			hooks[n] = pdo_hooks[h];
			hooks[n].index_last = hooks[n].index_first + count - 1U;
			hooks[n].user_data = node;
			n++;
		}
	}
	if (n > 0U) {
		err = co_od_hooks_register(&node->od, hooks, n);
	}
#if defined(CONFIG_CANOPEN_MPDO)
	if (err == 0) {
		err = co_mpdo_init(node);
	}
#endif
	if (err == 0) {
		/* With redundancy also the heartbeats lost per line (rpdo_duplicate()). */
		co_listener_init(&pdo->sync_listener, "pdo",
				 CO_EV_BIT(CO_EV_SYNC) | (IS_ENABLED(CONFIG_CANOPEN_REDUNDANCY)
								  ? CO_EV_BIT(CO_EV_REDUNDANCY)
								  : 0U),
				 sync_event, NULL);
		err = co_node_listener_add(node, &pdo->sync_listener);
	}
	return err;
}

static uint8_t map_load(struct co_node *node, bool rx, uint16_t num, uint8_t type,
			struct co_pdo_map *map, uint8_t *mpdo)
{
	uint16_t index = (rx ? IDX_RPDO_MAP : IDX_TPDO_MAP) + num;
	uint8_t n = (uint8_t)co_od_uint(&node->od, index, 0, 0U);
	uint8_t runs;

	*mpdo = 0U;
	if (is_mpdo_map(n) && IS_ENABLED(CONFIG_CANOPEN_MPDO) && is_event_type(type)) {
		*mpdo = n;
		n = 0U;
	}
	if (n > MAP_MAX || map_build(node, rx, num, n, map, &runs) != 0U) {
		LOG_ERR("%s: invalid mapping in %04Xh; the PDO stays off", node->name, index);
		return 1U;
	}
	return 0U;
}

/*
 * What RPDOs and TPDOs read alike from their records at a reset of communication: type,
 * event time and mapping. Returns the COB-ID, with the invalid bit when the node cannot
 * serve the type (no SYNC) or hold the mapping: the PDO then stays off.
 */
static uint32_t comm_load(struct co_node *node, bool rx, uint16_t num, uint8_t *type,
			  uint16_t *event_ms, struct co_pdo_map *map, uint8_t *mpdo)
{
	uint16_t comm = (rx ? IDX_RPDO_COMM : IDX_TPDO_COMM) + num;
	uint32_t cob_id = (uint32_t)co_od_uint(&node->od, comm, SUB_COB_ID, CO_PDO_COB_INVALID);

	*type = (uint8_t)co_od_uint(&node->od, comm, SUB_TYPE, CO_PDO_TT_EVENT_PROF);
	if (!sync_type_served(*type)) {
		LOG_ERR("%s: %cPDO %u is synchronous, the node has no SYNC; it stays off",
			node->name, rx ? 'R' : 'T', num + 1U);
		cob_id |= (uint32_t)CO_PDO_COB_INVALID;
	}
	*event_ms = (uint16_t)co_od_uint(&node->od, comm, SUB_EVENT, 0U);
	if (map_load(node, rx, num, *type, map, mpdo) != 0U) {
		cob_id |= (uint32_t)CO_PDO_COB_INVALID;
	}
	return cob_id;
}

static void pdo_reset_comm(struct co_node *node)
{
	struct co_pdo *pdo = &node->pdo;

	pdo->window = false;
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/* The redundancy service supervises afresh from here, without HB_OK events. */
	memset(pdo->hb_lost, 0, sizeof(pdo->hb_lost));
#endif
	for (uint16_t i = 0; i < CO_RPDOS; i++) {
		struct co_rpdo *r = &pdo->rpdo[i];

		if (!r->present) {
			continue;
		}
		r->cob_id = comm_load(node, true, i, &r->type, &r->event_ms, &r->map, &r->mpdo);
		rpdo_configure(r);
	}
	for (uint16_t i = 0; i < CO_TPDOS; i++) {
		struct co_tpdo *t = &pdo->tpdo[i];
		uint16_t comm = IDX_TPDO_COMM + i;

		if (!t->present) {
			continue;
		}
		t->cob_id = comm_load(node, false, i, &t->type, &t->event_ms, &t->map, &t->mpdo);
		t->inhibit_us = (uint32_t)co_od_uint(&node->od, comm, SUB_INHIBIT, 0U) * 100U;
		t->sync_start = (uint8_t)co_od_uint(&node->od, comm, SUB_SYNC_START, 0U);
		cos_hooks_update(t);
		tpdo_configure(t);
	}
}

static void pdo_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	ARG_UNUSED(from);

	struct co_pdo *pdo = &node->pdo;
	bool op = to == CO_NMT_OPERATIONAL;

	if (op == pdo->operational) {
		return;
	}
	pdo->operational = op;
	pdo->window = false;
	for (int i = 0; i < CO_RPDOS; i++) {
		/* The deadline monitor arms again at the first frame. */
		co_timer_stop(&pdo->rpdo[i].timer);
		pdo->rpdo[i].sync_pending = false;
	}
	for (int i = 0; i < CO_TPDOS; i++) {
		struct co_tpdo *t = &pdo->tpdo[i];

		if (t->present) {
			tpdo_reset_state(t);
			tpdo_event_timer_restart(t, co_node_time(node));
		}
	}
}

const struct co_service co_service_pdo = {
	.name = "pdo",
	.init = pdo_init,
	.reset_comm = pdo_reset_comm,
	.set_state = pdo_set_state,
};

/* --- API ---------------------------------------------------------------------------------- */

int co_tpdo_send_req(struct co_node *node, uint16_t num)
{
	int err = 0;

	if (node == NULL || num >= CO_TPDOS) {
		return -EINVAL;
	}
	co_node_lock(node);
	struct co_tpdo *t = &node->pdo.tpdo[num];

	if (!t->present || !cob_valid(t->cob_id)) {
		err = -EINVAL;
	} else if (!node->pdo.operational) {
		err = -ENETDOWN;
	} else if (!uses_events(t->type) || t->mpdo != 0U) {
		err = -ENOTSUP;
	} else {
		tpdo_event(t, co_node_time(node));
	}
	co_node_unlock(node);
	return err;
}

void co_rpdo_set_ind(struct co_node *node, co_rpdo_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->pdo.rpdo_ind = cb;
	node->pdo.rpdo_ind_user_data = user_data;
	co_node_unlock(node);
}

void co_tpdo_set_ind(struct co_node *node, co_tpdo_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->pdo.tpdo_ind = cb;
	node->pdo.tpdo_ind_user_data = user_data;
	co_node_unlock(node);
}

#if !defined(CONFIG_CANOPEN_MPDO)
int co_mpdo_dam_req(struct co_node *node, uint16_t num, uint8_t dest_id, uint16_t index,
		    uint8_t sub, const void *data, size_t len)
{
	return -ENOTSUP;
}

int co_mpdo_sam_req(struct co_node *node, uint16_t num, uint16_t index, uint8_t sub)
{
	return -ENOTSUP;
}

void co_mpdo_get_stats(struct co_node *node, struct co_mpdo_stats *stats)
{
	memset(stats, 0, sizeof(*stats));
}
#endif
