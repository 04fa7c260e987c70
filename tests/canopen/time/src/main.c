/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * TIME producer and consumer, driven frame by frame on a simulation line (no thread,
 * simulated time), and the TIME_OF_DAY conversions. Frames the nodes send land in `sent`.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/sdo_abort.h>
#include <canopen/time.h>

#include "time_test_od.h"

#define NODE_ID  0x21
#define NODE2_ID 0x22
#define MS       1000ULL
#define MAX_TX   32

static struct {
	struct co_line line;
	struct co_node node;
	struct co_node node2;
	struct time_test_od_ram ram;
	struct time_test_od_ram ram2;
	struct can_frame sent[MAX_TX];
	int n_sent;
	uint64_t now;
	int n_ind;
	struct co_time ind_time[MAX_TX];
	uint64_t ind_rx_us[MAX_TX];
	struct co_node *ind_node[MAX_TX];
	int clock_calls;
	int clock_err;
} t;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	zassert_true(t.n_sent < MAX_TX, "too many frames");
	t.sent[t.n_sent++] = *frame;
	return 0;
}

static void time_ind(struct co_node *node, const struct co_time *tm, uint64_t rx_us,
		     void *user_data)
{
	zassert_true(t.n_ind < MAX_TX);
	t.ind_node[t.n_ind] = node;
	t.ind_rx_us[t.n_ind] = rx_us;
	t.ind_time[t.n_ind++] = *tm;
}

static int clock_cb(struct co_node *node, struct co_time *now, void *user_data)
{
	t.clock_calls++;
	if (t.clock_err != 0) {
		return t.clock_err;
	}
	/* 2026-11-23 07:45:00.250 */
	now->days = 15667;
	now->ms = (7U * 3600U + 45U * 60U) * 1000U + 250U;
	return 0;
}

static void rx(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}
	co_line_rx(&t.line, &f, t.now);
}

static void nmt(uint8_t cs, uint8_t id)
{
	uint8_t d[2] = {cs, id};

	rx(0x000, 2, d);
}

static uint32_t od_write_u32(struct co_node *node, uint16_t index, uint32_t value)
{
	uint8_t buf[4] = {(uint8_t)value, (uint8_t)(value >> 8), (uint8_t)(value >> 16),
			  (uint8_t)(value >> 24)};
	uint32_t ab;

	co_node_lock(node);
	ab = co_od_write(co_node_od(node), index, 0, buf, 4, CO_OD_WRITER_SDO);
	co_node_unlock(node);
	return ab;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_line_init_sim(&t.line, "sim", sink, NULL);
	zassert_ok(co_node_init(&t.node, "dut", &t.line, &time_test_od_def, &t.ram, NODE_ID));
	co_time_set_ind(&t.node, time_ind, NULL);
	zassert_ok(co_node_start(&t.node));
	t.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_time, NULL, NULL, before, NULL, NULL);

/* --- Encoding ------------------------------------------------------------------------------ */

ZTEST(co_time, test_encode_midnight_of_1984_01_01_is_all_zero)
{
	struct co_time tm = {.ms = 0, .days = 0};
	struct co_time_date d;
	uint8_t b[6];
	int64_t us;

	co_time_encode(&tm, b);
	zassert_mem_equal(b, ((uint8_t[6]){0}), 6);
	zassert_ok(co_time_to_unix_us(&tm, &us));
	zassert_equal(us, 441763200LL * 1000000LL, "the TIME epoch in Unix time");
	zassert_ok(co_time_to_date(&tm, &d));
	zassert_equal(d.year, 1984);
	zassert_equal(d.month, 1);
	zassert_equal(d.day, 1);
	zassert_equal(d.hour + d.minute + d.second + d.millis, 0);
}

ZTEST(co_time, test_encode_2026_date_wire_bytes_and_round_trip)
{
	const struct co_time_date in = {2026, 11, 23, 7, 45, 12, 345};
	struct co_time_date out;
	struct co_time tm;
	struct co_time back;
	uint8_t b[6];
	/* 07:45:12.345 = 27912345 ms = 0x01A9_E899; 2026-11-23 = day 15667 = 0x3D33. */
	const uint8_t want[6] = {0x99, 0xE8, 0xA9, 0x01, 0x33, 0x3D};
	int64_t us;

	zassert_ok(co_time_from_date(&in, &tm));
	zassert_equal(tm.days, 15667);
	zassert_equal(tm.ms, 27912345U);
	co_time_encode(&tm, b);
	zassert_mem_equal(b, want, 6);
	co_time_decode(b, &back);
	zassert_equal(back.ms, tm.ms);
	zassert_equal(back.days, tm.days);
	zassert_ok(co_time_to_date(&back, &out));
	zassert_equal(out.year, in.year);
	zassert_equal(out.month, in.month);
	zassert_equal(out.day, in.day);
	zassert_equal(out.hour, in.hour);
	zassert_equal(out.minute, in.minute);
	zassert_equal(out.second, in.second);
	zassert_equal(out.millis, in.millis);

	/* 2026-11-23T07:45:12.345Z = 1795419912 s (date -u -d ... +%s). */
	zassert_ok(co_time_to_unix_us(&tm, &us));
	zassert_equal(us, 1795419912345000LL);
	zassert_ok(co_time_from_unix_us(1795419912345999LL, &back), "sub-ms truncated");
	zassert_equal(back.ms, tm.ms);
	zassert_equal(back.days, tm.days);
}

ZTEST(co_time, test_last_ms_of_day_and_midnight_wrap)
{
	struct co_time tm;
	struct co_time_date d;
	const int64_t day0 = 441763200LL * 1000000LL;

	zassert_ok(co_time_from_unix_us(day0 + 86400LL * 1000000LL - 1, &tm));
	zassert_equal(tm.days, 0);
	zassert_equal(tm.ms, 86399999U);
	zassert_ok(co_time_to_date(&tm, &d));
	zassert_equal(d.hour, 23);
	zassert_equal(d.minute, 59);
	zassert_equal(d.second, 59);
	zassert_equal(d.millis, 999);
	zassert_ok(co_time_from_unix_us(day0 + 86400LL * 1000000LL, &tm));
	zassert_equal(tm.days, 1, "midnight starts the next day");
	zassert_equal(tm.ms, 0U);

	tm.ms = CO_TIME_MS_PER_DAY;
	zassert_equal(co_time_to_date(&tm, &d), -EINVAL, "a day has 86400000 ms");
	zassert_equal(co_time_to_unix_us(&tm, &(int64_t){0}), -EINVAL);
}

ZTEST(co_time, test_day_65535_is_the_last_day)
{
	struct co_time tm = {.ms = 86399999U, .days = 65535};
	struct co_time_date d;
	const struct co_time_date after = {2163, 6, 7, 0, 0, 0, 0};
	const struct co_time_date before_epoch = {1983, 12, 31, 23, 59, 59, 999};
	int64_t us;
	uint8_t b[6];

	co_time_encode(&tm, b);
	zassert_equal(b[4], 0xff);
	zassert_equal(b[5], 0xff);
	zassert_ok(co_time_to_date(&tm, &d));
	zassert_equal(d.year, 2163);
	zassert_equal(d.month, 6);
	zassert_equal(d.day, 6);
	zassert_ok(co_time_to_unix_us(&tm, &us));
	zassert_ok(co_time_from_unix_us(us, &tm));
	zassert_equal(tm.days, 65535);
	zassert_equal(co_time_from_unix_us(us + 1000, &tm), -ERANGE, "day 65536 does not fit");
	zassert_equal(co_time_from_date(&after, &tm), -ERANGE);
	zassert_equal(co_time_from_unix_us(441763200LL * 1000000LL - 1, &tm), -ERANGE);
	zassert_equal(co_time_from_date(&before_epoch, &tm), -ERANGE);
	zassert_equal(co_time_from_unix_us(0, &tm), -ERANGE, "1970 is before the epoch");
}

ZTEST(co_time, test_leap_days_and_invalid_dates)
{
	struct co_time tm;
	struct co_time_date d;

	zassert_ok(co_time_from_date(&(struct co_time_date){2024, 2, 29, 0, 0, 0, 0}, &tm));
	zassert_ok(
		co_time_to_date(&(struct co_time){.ms = 0, .days = (uint16_t)(tm.days + 1)}, &d));
	zassert_equal(d.month, 3);
	zassert_equal(d.day, 1);
	zassert_ok(co_time_from_date(&(struct co_time_date){2000, 2, 29, 0, 0, 0, 0}, &tm),
		   "2000 is a leap year");
	zassert_equal(co_time_from_date(&(struct co_time_date){2100, 2, 29, 0, 0, 0, 0}, &tm),
		      -EINVAL, "2100 is not");
	zassert_equal(co_time_from_date(&(struct co_time_date){2026, 2, 29, 0, 0, 0, 0}, &tm),
		      -EINVAL);
	zassert_equal(co_time_from_date(&(struct co_time_date){2026, 4, 31, 0, 0, 0, 0}, &tm),
		      -EINVAL);
	zassert_equal(co_time_from_date(&(struct co_time_date){2026, 13, 1, 0, 0, 0, 0}, &tm),
		      -EINVAL);
	zassert_equal(co_time_from_date(&(struct co_time_date){2026, 1, 1, 24, 0, 0, 0}, &tm),
		      -EINVAL);
	zassert_equal(co_time_from_date(&(struct co_time_date){2026, 1, 1, 0, 0, 0, 1000}, &tm),
		      -EINVAL);
	/* Every day of 1984..2163 converts to a date and back. */
	for (uint32_t day = 0; day <= 65535U; day += 7U) {
		struct co_time back;

		zassert_ok(co_time_to_date(&(struct co_time){.ms = 0, .days = (uint16_t)day}, &d));
		zassert_ok(co_time_from_date(&d, &back));
		zassert_equal(back.days, day, "day %u", day);
	}
}

ZTEST(co_time, test_reserved_bits_dropped)
{
	const uint8_t in[6] = {0x01, 0x00, 0x00, 0xf0, 0x02, 0x00};
	struct co_time tm;
	uint8_t out[6];

	co_time_decode(in, &tm);
	zassert_equal(tm.ms, 1U, "bits 28..31 are reserved");
	zassert_equal(tm.days, 2);
	tm.ms |= 0xf0000000U;
	co_time_encode(&tm, out);
	zassert_equal(out[3], 0x00, "and sent as 0");
}

/* --- Producer ------------------------------------------------------------------------------ */

ZTEST(co_time, test_producer_sends_the_given_time)
{
	const struct co_time tm = {.ms = 0x01234567U, .days = 0x1234};
	const struct co_time late = {.ms = CO_TIME_MS_PER_DAY, .days = 1};

	zassert_equal(co_time_req(&t.node, &tm), -ENOTSUP, "1012h bit 30 clear");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x40000100U), 0U);
	zassert_ok(co_time_req(&t.node, &tm));
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.sent[0].id, 0x100);
	zassert_equal(t.sent[0].dlc, 6);
	zassert_mem_equal(t.sent[0].data, ((uint8_t[6]){0x67, 0x45, 0x23, 0x01, 0x34, 0x12}), 6);
	zassert_equal(co_time_req(&t.node, &late), -EINVAL);
	zassert_equal(co_time_req(&t.node, NULL), -EINVAL, "no clock");
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.n_ind, 0, "the producer does not indicate its own TIME");
}

ZTEST(co_time, test_producer_reads_the_clock_callback)
{
	struct co_time tm;

	zassert_equal(od_write_u32(&t.node, 0x1012, 0x40000100U), 0U);
	co_time_set_clock(&t.node, clock_cb, NULL);
	zassert_ok(co_time_req(&t.node, NULL));
	zassert_equal(t.clock_calls, 1);
	zassert_equal(t.n_sent, 1);
	co_time_decode(t.sent[0].data, &tm);
	zassert_equal(tm.days, 15667);
	zassert_equal(tm.ms, 27900250U);
	t.clock_err = -EAGAIN;
	zassert_equal(co_time_req(&t.node, NULL), -EAGAIN, "the clock's error");
	zassert_equal(t.n_sent, 1);
}

/* --- Consumer ------------------------------------------------------------------------------ */

ZTEST(co_time, test_consumer_indicates_time_with_rx_timestamp)
{
	const uint8_t d[6] = {0x99, 0xE8, 0xA9, 0x01, 0x33, 0x3D};

	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 0, "1012h bit 31 clear: not a consumer");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000100U), 0U);
	t.now = 1234 * MS;
	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.ind_time[0].days, 15667);
	zassert_equal(t.ind_time[0].ms, 27912345U);
	zassert_equal(t.ind_rx_us[0], 1234 * MS, "the line's reception time");
	zassert_equal(t.n_sent, 0);
}

ZTEST(co_time, test_consumer_ignores_wrong_length_without_emcy)
{
	const uint8_t d[8] = {1, 0, 0, 0, 1, 0, 0, 0};
	const uint8_t bad_ms[6] = {0x00, 0x5c, 0x26, 0x05, 0, 0}; /* 86400000 */

	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000100U), 0U);
	rx(0x100, 0, NULL);
	rx(0x100, 5, d);
	rx(0x100, 7, d);
	rx(0x100, 8, d);
	rx(0x100, 6, bad_ms);
	zassert_equal(t.n_ind, 0);
	zassert_equal(co_time_get_ignored(&t.node), 5U);
	zassert_equal(t.n_sent, 0, "CiA 301 has no EMCY for a malformed TIME");
	zassert_equal(co_emcy_get_reg(&t.node), 0U);
	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.ind_time[0].ms, 1U);
	zassert_equal(t.ind_time[0].days, 1);
}

ZTEST(co_time, test_producer_reaches_consumer_on_same_line)
{
	zassert_ok(co_node_init(&t.node2, "peer", &t.line, &time_test_od_def, &t.ram2, NODE2_ID));
	co_time_set_ind(&t.node2, time_ind, NULL);
	zassert_ok(co_node_start(&t.node2));
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x40000100U), 0U);
	zassert_equal(od_write_u32(&t.node2, 0x1012, 0x80000100U), 0U);
	t.n_sent = 0;
	t.now = 5 * MS;
	co_line_process(&t.line, t.now);
	zassert_ok(co_time_req(&t.node, &(struct co_time){.ms = 42, .days = 7}));
	co_line_process(&t.line, t.now);
	zassert_equal(t.n_sent, 1);
	zassert_equal(t.n_ind, 1);
	zassert_equal_ptr(t.ind_node[0], &t.node2);
	zassert_equal(t.ind_time[0].ms, 42U);
	zassert_equal(t.ind_time[0].days, 7);
	zassert_equal(t.ind_rx_us[0], 5 * MS);
}

/* --- 1012h write rules ---------------------------------------------------------------------- */

ZTEST(co_time, test_1012h_refuses_restricted_can_ids_06090030h)
{
	static const uint32_t restricted[] = {0x000, 0x040, 0x07F, 0x101, 0x180,
					      0x581, 0x601, 0x6E0, 0x701, 0x7FF};

	for (size_t i = 0; i < ARRAY_SIZE(restricted); i++) {
		zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000000U | restricted[i]),
			      CO_SDO_AB_INVALID_VALUE, "%03x", restricted[i]);
	}
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000100U), 0U, "100h is TIME's own");
}

ZTEST(co_time, test_1012h_write_rules)
{
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x00000190U), 0U, "unused: id may change");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000190U), 0U);
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000191U), CO_SDO_AB_INVALID_VALUE,
		      "consumer keeps its CAN-ID");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x40000190U), 0U, "same id, other role");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x40000191U), CO_SDO_AB_INVALID_VALUE,
		      "producer keeps its CAN-ID");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0xC0000190U), 0U, "both roles");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x00000190U), 0U, "off");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000100U), 0U, "then a new id");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x20000100U), CO_SDO_AB_INVALID_VALUE,
		      "29-bit frames are not supported");
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x00000900U), CO_SDO_AB_INVALID_VALUE,
		      "id above 7FFh");

	/* The consumer follows the last accepted value. */
	rx(0x101, 6, (const uint8_t[6]){0});
	zassert_equal(t.n_ind, 0);
	rx(0x100, 6, (const uint8_t[6]){0});
	zassert_equal(t.n_ind, 1);
}

/* --- NMT ---------------------------------------------------------------------------------- */

ZTEST(co_time, test_time_only_in_pre_operational_and_operational)
{
	const uint8_t d[6] = {5, 0, 0, 0, 0, 0};
	const struct co_time tm = {.ms = 5, .days = 0};

	zassert_equal(od_write_u32(&t.node, 0x1012, 0xC0000100U), 0U);
	nmt(0x02, NODE_ID); /* Stopped */
	t.n_sent = 0;
	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 0, "no TIME consumed in Stopped");
	zassert_equal(co_time_req(&t.node, &tm), -ENETDOWN, "none produced");
	zassert_equal(t.n_sent, 0);

	nmt(0x01, NODE_ID); /* Operational */
	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 1);
	zassert_ok(co_time_req(&t.node, &tm));
	zassert_equal(t.n_sent, 1);

	nmt(0x80, NODE_ID); /* Pre-operational */
	rx(0x100, 6, d);
	zassert_equal(t.n_ind, 2);
	zassert_ok(co_time_req(&t.node, &tm));
	zassert_equal(t.n_sent, 2);
}

ZTEST(co_time, test_reset_communication_reloads_1012h)
{
	zassert_equal(od_write_u32(&t.node, 0x1012, 0x80000100U), 0U);
	nmt(0x82, NODE_ID); /* Reset communication: 1012h back to its default, 100h unused */
	t.n_sent = 0;
	rx(0x100, 6, (const uint8_t[6]){0});
	zassert_equal(t.n_ind, 0, "default 1012h consumes nothing");
}
