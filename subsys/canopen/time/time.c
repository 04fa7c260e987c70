/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * TIME object (CiA 301 §7.2.6): producer (1012h bit 30) and consumer (1012h bit 31) of the
 * TIME_OF_DAY time stamp, plus the calendar conversions.
 *
 * Decisions (doc/time.md):
 * - TIME runs in Pre-operational and Operational only (CiA 301 Table 82).
 * - A TIME frame that is not 6 bytes long is ignored and counted. CiA 301 defines no
 *   reaction and no emergency code for it (8240h is SYNC's length error, 8210h PDO's), so no
 *   EMCY is raised. RTR frames and a millisecond field of a day or more are ignored the same
 *   way; the reserved bits 28..31 are dropped.
 * - 1012h: only 11-bit COB-IDs (bit 29 set -> 06090030h); the CAN-ID may not change while
 *   the object is used (bit 30 or 31 set) and stays used (06090030h), as for 1005h.
 * - The producer does not indicate its own TIME to itself; other nodes on the same line get
 *   it through local delivery.
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/cob_id.h>
#include <canopen/node.h>
#include <canopen/time.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_COB_ID 0x1012U

#define COB_USED (CO_TIME_COB_CONSUME | CO_TIME_COB_PRODUCE)
#define COB_EXT  BIT(29)

/* 1984-01-01 in days since 1970-01-01. */
#define EPOCH_UNIX_DAYS (CO_TIME_EPOCH_UNIX_S / 86400LL)
#define US_PER_MS       1000LL
#define US_PER_DAY      (86400LL * 1000000LL)

/* --- TIME_OF_DAY conversions ------------------------------------------------------------- */

void co_time_encode(const struct co_time *t, uint8_t out[CO_TIME_LEN])
{
	uint32_t ms = t->ms & CO_TIME_MS_MASK;

	out[0] = (uint8_t)ms;
	out[1] = (uint8_t)(ms >> 8);
	out[2] = (uint8_t)(ms >> 16);
	out[3] = (uint8_t)(ms >> 24);
	out[4] = (uint8_t)t->days;
	out[5] = (uint8_t)(t->days >> 8);
}

void co_time_decode(const uint8_t in[CO_TIME_LEN], struct co_time *t)
{
	uint32_t ms = (uint32_t)in[0] | ((uint32_t)in[1] << 8) | ((uint32_t)in[2] << 16) |
		      ((uint32_t)in[3] << 24);

	t->ms = ms & CO_TIME_MS_MASK;
	t->days = (uint16_t)(in[4] | (in[5] << 8));
}

int co_time_from_unix_us(int64_t unix_us, struct co_time *t)
{
	int64_t since = unix_us - CO_TIME_EPOCH_UNIX_S * 1000000LL;
	int64_t days;

	if (unix_us < CO_TIME_EPOCH_UNIX_S * 1000000LL) {
		return -ERANGE;
	}
	days = since / US_PER_DAY;
	if (days > UINT16_MAX) {
		return -ERANGE;
	}
	t->days = (uint16_t)days;
	t->ms = (uint32_t)((since % US_PER_DAY) / US_PER_MS);
	return 0;
}

int co_time_to_unix_us(const struct co_time *t, int64_t *unix_us)
{
	if (t->ms >= CO_TIME_MS_PER_DAY) {
		return -EINVAL;
	}
	*unix_us = CO_TIME_EPOCH_UNIX_S * 1000000LL + (int64_t)t->days * US_PER_DAY +
		   (int64_t)t->ms * US_PER_MS;
	return 0;
}

/*
 * Days since 1970-01-01 of a proleptic Gregorian date, counting years from 1 March so that
 * the leap day is the last day of the year (valid for year >= 1).
 */
static int64_t days_from_civil(int64_t y, unsigned int m, unsigned int d)
{
	int64_t era;
	unsigned int yoe;
	unsigned int doy;
	unsigned int doe;

	y -= (m <= 2U) ? 1 : 0;
	era = y / 400;
	yoe = (unsigned int)(y - era * 400);
	doy = (153U * (m > 2U ? m - 3U : m + 9U) + 2U) / 5U + d - 1U;
	doe = yoe * 365U + yoe / 4U - yoe / 100U + doy;
	return era * 146097 + (int64_t)doe - 719468;
}

static void civil_from_days(int64_t z, struct co_time_date *dt)
{
	int64_t era;
	unsigned int doe;
	unsigned int yoe;
	unsigned int doy;
	unsigned int mp;
	int64_t y;

	z += 719468;
	era = z / 146097;
	doe = (unsigned int)(z - era * 146097);
	yoe = (doe - doe / 1460U + doe / 36524U - doe / 146096U) / 365U;
	y = (int64_t)yoe + era * 400;
	doy = doe - (365U * yoe + yoe / 4U - yoe / 100U);
	mp = (5U * doy + 2U) / 153U;
	dt->day = (uint8_t)(doy - (153U * mp + 2U) / 5U + 1U);
	dt->month = (uint8_t)(mp < 10U ? mp + 3U : mp - 9U);
	dt->year = (uint16_t)(y + (dt->month <= 2U ? 1 : 0));
}

static bool leap_year(unsigned int y)
{
	return (y % 4U == 0U && y % 100U != 0U) || y % 400U == 0U;
}

int co_time_from_date(const struct co_time_date *d, struct co_time *t)
{
	static const uint8_t mdays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
	unsigned int last;
	int64_t days;

	if (d->month < 1U || d->month > 12U || d->hour > 23U || d->minute > 59U ||
	    d->second > 59U || d->millis > 999U || d->day < 1U) {
		return -EINVAL;
	}
	last = mdays[d->month - 1U] + ((d->month == 2U && leap_year(d->year)) ? 1U : 0U);
	if (d->day > last) {
		return -EINVAL;
	}
	days = days_from_civil(d->year, d->month, d->day) - EPOCH_UNIX_DAYS;
	if (days < 0 || days > UINT16_MAX) {
		return -ERANGE;
	}
	t->days = (uint16_t)days;
	t->ms = ((uint32_t)d->hour * 3600U + (uint32_t)d->minute * 60U + d->second) * 1000U +
		d->millis;
	return 0;
}

int co_time_to_date(const struct co_time *t, struct co_time_date *d)
{
	uint32_t ms = t->ms;

	if (ms >= CO_TIME_MS_PER_DAY) {
		return -EINVAL;
	}
	civil_from_days(EPOCH_UNIX_DAYS + t->days, d);
	d->millis = (uint16_t)(ms % 1000U);
	ms /= 1000U;
	d->second = (uint8_t)(ms % 60U);
	ms /= 60U;
	d->minute = (uint8_t)(ms % 60U);
	d->hour = (uint8_t)(ms / 60U);
	return 0;
}

/* --- Consumer ------------------------------------------------------------------------------ */

static void time_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_time_svc *ts = &node->time;
	struct co_time t;

	/* A node on two lines hears SYNC/TIME on both and acts on the active line's. */
	if (co_node_rx_line(node) != co_node_active_line(node)) {
		return;
	}
	if (!ts->enabled) {
		return;
	}
	/* CiA 301 defines no reaction to a malformed TIME: drop it, count it, no EMCY. */
	if ((frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc != CO_TIME_LEN) {
		ts->ignored++;
		LOG_DBG("%s: TIME with DLC %u ignored", node->name, frame->dlc);
		return;
	}
	co_time_decode(frame->data, &t);
	if (t.ms >= CO_TIME_MS_PER_DAY) {
		ts->ignored++;
		return;
	}
	if (ts->ind != NULL) {
		ts->ind(node, &t, now_us, ts->ind_user_data);
	}
}

static void rx_configure(struct co_node *node)
{
	struct co_time_svc *ts = &node->time;

	if ((ts->cob_id & CO_TIME_COB_CONSUME) == 0U || (ts->cob_id & COB_EXT) != 0U) {
		co_rx_unregister(&ts->rx);
		return;
	}
	if (co_node_rx_set_id(node, CO_LINE_DEFAULT, &ts->rx, ts->cob_id & 0x7ffU) != 0) {
		LOG_ERR("%s: no receive slot for TIME", node->name);
	}
}

/* --- 1012h ------------------------------------------------------------------------------- */

static uint32_t cob_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t old = node->time.cob_id;

	if (req->writer == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	/* Only 11-bit TIME is served (CiA 301 §7.5.2.12: bit 29 set -> 06090030h). */
	if ((v & COB_EXT) != 0U || (v & 0x1ffff800U) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* CiA 301 §7.3.5: not on another service's identifier. */
	if (co_cob_id_restricted(v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (!IS_ENABLED(CONFIG_CANOPEN_TIME_PRODUCER) && (v & CO_TIME_COB_PRODUCE) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* The CAN-ID is kept while the object is used and stays used. */
	if ((old & COB_USED) != 0U && (v & COB_USED) != 0U && (old & 0x7ffU) != (v & 0x7ffU)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static void cob_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_node *node = user_data;

	node->time.cob_id = (uint32_t)co_od_req_uint(req);
	rx_configure(node);
}

/* --- Node interface ----------------------------------------------------------------------- */

static int time_init(struct co_node *node)
{
	struct co_time_svc *ts = &node->time;
	const struct co_od_hook hooks[] = {
		{
			.index_first = IDX_COB_ID,
			.index_last = IDX_COB_ID,
			.validate = cob_validate,
			.notify = cob_notify,
			.user_data = node,
		},
	};

	co_rx_init(&ts->rx, 0U, time_rx, &node->lock, node);
	ts->cob_id = 0U;
	ts->enabled = false;
	ts->ignored = 0U;
	return co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));
}

static void time_reset_comm(struct co_node *node)
{
	struct co_time_svc *ts = &node->time;

	/* Without 1012h the node neither produces nor consumes TIME. */
	ts->cob_id = co_od_uint(&node->od, IDX_COB_ID, 0, 0U);
	if (!IS_ENABLED(CONFIG_CANOPEN_TIME_PRODUCER)) {
		ts->cob_id &= ~CO_TIME_COB_PRODUCE;
	}
	ts->ignored = 0U;
	rx_configure(node);
}

static void time_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	ARG_UNUSED(from);
	/* CiA 301 Table 82: TIME in Pre-operational and Operational only. */
	node->time.enabled = to == CO_NMT_PRE_OPERATIONAL || to == CO_NMT_OPERATIONAL;
}

const struct co_service co_service_time = {
	.name = "time",
	.init = time_init,
	.reset_comm = time_reset_comm,
	.set_state = time_set_state,
};

/* --- API ---------------------------------------------------------------------------------- */

int co_time_req(struct co_node *node, const struct co_time *t)
{
	struct co_time_svc *ts;
	struct co_time now;
	struct can_frame f = {.dlc = CO_TIME_LEN};
	int err;

	if (node == NULL) {
		return -EINVAL;
	}
	ts = &node->time;
	co_node_lock(node);
	if ((ts->cob_id & CO_TIME_COB_PRODUCE) == 0U || (ts->cob_id & COB_EXT) != 0U) {
		err = -ENOTSUP;
		goto out;
	}
	if (!ts->enabled) {
		err = -ENETDOWN;
		goto out;
	}
	if (t == NULL) {
		if (ts->clock == NULL) {
			err = -EINVAL;
			goto out;
		}
		err = ts->clock(node, &now, ts->clock_user_data);
		if (err != 0) {
			goto out;
		}
		t = &now;
	}
	if (t->ms >= CO_TIME_MS_PER_DAY) {
		err = -EINVAL;
		goto out;
	}
	f.id = ts->cob_id & 0x7ffU;
	co_time_encode(t, f.data);
	err = co_node_send(node, CO_ROUTE_PROCESS, &f);
out:
	co_node_unlock(node);
	return err;
}

void co_time_set_clock(struct co_node *node, co_time_clock_t cb, void *user_data)
{
	co_node_lock(node);
	node->time.clock = cb;
	node->time.clock_user_data = user_data;
	co_node_unlock(node);
}

void co_time_set_ind(struct co_node *node, co_time_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->time.ind = cb;
	node->time.ind_user_data = user_data;
	co_node_unlock(node);
}

uint32_t co_time_get_ignored(struct co_node *node)
{
	uint32_t n;

	co_node_lock(node);
	n = node->time.ignored;
	co_node_unlock(node);
	return n;
}
