/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* The line core driven on simulated time: no thread, no CAN device. */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/line.h>

#include "line_internal.h"

#define MAX_LOG 32

struct fixture {
	struct co_line line;
	struct k_mutex node_lock;
	/* What handlers saw, in order. */
	int log[MAX_LOG];
	uint64_t log_time[MAX_LOG];
	int log_len;
	/* Frames the sink accepted. */
	struct can_frame sent[MAX_LOG];
	int sent_len;
	int sink_result;
	/* Take frames without recording them (more than MAX_LOG). */
	bool sink_discard;
	int events[MAX_LOG];
	int event_args[MAX_LOG];
	int event_len;
};

static struct fixture fx;

static void record(int tag, uint64_t now)
{
	zassert_true(fx.log_len < MAX_LOG);
	fx.log_time[fx.log_len] = now;
	fx.log[fx.log_len++] = tag;
}

/* The last frame a receiver got. */
static struct can_frame last_rx;

static void rx_handler(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	last_rx = *frame;
	record((int)(intptr_t)rx->user_data, now_us);
}

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (fx.sink_result != 0) {
		return fx.sink_result;
	}
	if (fx.sink_discard) {
		return 0;
	}
	zassert_true(fx.sent_len < MAX_LOG);
	fx.sent[fx.sent_len++] = *frame;
	return 0;
}

static void event_cb(struct co_line *line, enum co_line_event event, int arg, void *user_data)
{
	fx.events[fx.event_len] = event;
	fx.event_args[fx.event_len++] = arg;
}

static void *setup(void)
{
	return &fx;
}

static void before(void *f)
{
	memset(&fx, 0, sizeof(fx));
	k_mutex_init(&fx.node_lock);
	co_line_init_sim(&fx.line, "sim0", sink, NULL);
	co_line_set_event_cb(&fx.line, event_cb, NULL);
}

ZTEST_SUITE(co_line, NULL, setup, before, NULL, NULL);

static void rx_fill(struct co_rx *rx, uint32_t id, uint32_t mask, bool ext, int tag)
{
	memset(rx, 0, sizeof(*rx));
	rx->id = id;
	rx->mask = mask;
	rx->ext = ext;
	rx->handler = rx_handler;
	rx->lock = &fx.node_lock;
	rx->user_data = (void *)(intptr_t)tag;
}

static bool keep_error_control(const struct can_frame *f, void *arg)
{
	return (f->id & 0x780U) == 0x700U;
}

static struct can_frame std_frame(uint32_t id, uint8_t dlc)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	for (uint8_t i = 0; i < dlc; i++) {
		f.data[i] = i;
	}
	return f;
}

ZTEST(co_line, test_exact_receivers_get_frames_in_registration_order)
{
	struct co_rx a, b, c;
	struct can_frame f = std_frame(0x181, 2);

	rx_fill(&a, 0x181, 0x7ff, false, 1);
	rx_fill(&b, 0x181, 0x7ff, false, 2);
	rx_fill(&c, 0x182, 0x7ff, false, 3);
	zassert_ok(co_rx_register(&fx.line, &a));
	zassert_ok(co_rx_register(&fx.line, &b));
	zassert_ok(co_rx_register(&fx.line, &c));

	zassert_equal(co_line_rx(&fx.line, &f, 1000), 2);
	zassert_equal(fx.log_len, 2);
	zassert_equal(fx.log[0], 1);
	zassert_equal(fx.log[1], 2);
	zassert_equal(fx.log_time[0], 1000, "handler gets the reception time");
}

static struct co_rx *partner[2];

/* Records, then removes the other receiver of the same COB-ID. */
static void rx_unregister_partner(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	int tag = (int)(intptr_t)rx->user_data;

	record(tag, now_us);
	co_rx_unregister(partner[1 - tag]);
}

ZTEST(co_line, test_receiver_removed_during_dispatch_is_not_called)
{
	struct co_rx rx[2];
	struct can_frame f = std_frame(0x181, 0);

	/* Both are collected for the frame; the first one called removes the second. */
	for (int i = 0; i < 2; i++) {
		rx_fill(&rx[i], 0x181, 0x7ff, false, i);
		rx[i].handler = rx_unregister_partner;
		partner[i] = &rx[i];
		zassert_ok(co_rx_register(&fx.line, &rx[i]));
	}
	co_line_rx(&fx.line, &f, 0);
	zassert_equal(fx.log_len, 1, "only the receiver still registered was called");
	co_rx_unregister(&rx[fx.log[0]]);
}

ZTEST(co_line, test_unregister_stops_delivery_and_frees_the_slot)
{
	struct co_rx rx[CONFIG_CANOPEN_LINE_RX_SLOTS + 1];
	struct can_frame f = std_frame(0x200, 0);

	for (int i = 0; i < CONFIG_CANOPEN_LINE_RX_SLOTS; i++) {
		rx_fill(&rx[i], 0x200 + i, 0x7ff, false, i);
		zassert_ok(co_rx_register(&fx.line, &rx[i]));
	}
	rx_fill(&rx[CONFIG_CANOPEN_LINE_RX_SLOTS], 0x300, 0x7ff, false, 99);
	zassert_equal(co_rx_register(&fx.line, &rx[CONFIG_CANOPEN_LINE_RX_SLOTS]), -ENOSPC,
		      "all slots used");

	co_rx_unregister(&rx[0]);
	zassert_equal(co_line_rx(&fx.line, &f, 0), 0);
	zassert_ok(co_rx_register(&fx.line, &rx[CONFIG_CANOPEN_LINE_RX_SLOTS]),
		   "the freed slot is reused");
	co_rx_unregister(&rx[0]); /* not registered: harmless */

	struct co_line_stats st;

	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.rx_unhandled, 1);
}

/*
 * Ids registered in any order, some removed from the middle and moved: each frame reaches the
 * receivers of its id and no other (the table keeps them sorted and searches them).
 */
/* A multiple of three: the test takes the receivers three by three. */
#define SPREAD_N (MIN(24, CONFIG_CANOPEN_LINE_RX_SLOTS) / 3 * 3)

static uint32_t spread_id(int i)
{
	/* Distinct ids over the whole 11-bit range, not in order. */
	return (uint32_t)((i * 1103U + 17U) % 0x7ffU);
}

ZTEST(co_line, test_ids_in_any_order_are_found)
{
	static struct co_rx rx[SPREAD_N];

	for (int i = 0; i < SPREAD_N; i++) {
		rx_fill(&rx[i], spread_id(i), 0x7ff, false, i);
		zassert_ok(co_rx_register(&fx.line, &rx[i]));
	}
	for (int i = 0; i < SPREAD_N; i++) {
		struct can_frame f = std_frame(spread_id(i), 0);

		fx.log_len = 0;
		zassert_equal(co_line_rx(&fx.line, &f, 0), 1, "id %03x", spread_id(i));
		zassert_equal(fx.log[0], i);
	}
	/* Every third one leaves, every third one moves to an id nobody had. */
	for (int i = 0; i < SPREAD_N; i += 3) {
		co_rx_unregister(&rx[i]);
		zassert_ok(co_rx_set_id(&fx.line, &rx[i + 1], 0x7ff - (uint32_t)i));
	}
	for (int i = 0; i < SPREAD_N; i++) {
		struct can_frame f = std_frame(spread_id(i), 0);
		bool gone = i % 3 == 0 || i % 3 == 1;

		fx.log_len = 0;
		zassert_equal(co_line_rx(&fx.line, &f, 0), gone ? 0 : 1, "id %03x", spread_id(i));
		if (i % 3 == 1) {
			f = std_frame(0x7ff - (uint32_t)(i - 1), 0);
			zassert_equal(co_line_rx(&fx.line, &f, 0), 1);
			zassert_equal(fx.log[0], i, "moved");
		}
	}
	for (int i = 0; i < SPREAD_N; i++) {
		co_rx_unregister(&rx[i]);
	}
	for (int i = 0; i < SPREAD_N; i++) {
		struct can_frame f = std_frame(spread_id(i), 0);

		zassert_equal(co_line_rx(&fx.line, &f, 0), 0);
	}
}

ZTEST(co_line, test_register_checks_ids_and_double_registration)
{
	struct co_rx a, b;

	rx_fill(&a, 0x800, 0x7ff, false, 1);
	zassert_equal(co_rx_register(&fx.line, &a), -EINVAL, "11-bit id out of range");
	rx_fill(&b, 0x20000000, 0x1fffffff, true, 2);
	zassert_equal(co_rx_register(&fx.line, &b), -EINVAL, "29-bit id out of range");
	rx_fill(&a, 0x7ff, 0x7ff, false, 1);
	zassert_ok(co_rx_register(&fx.line, &a));
	zassert_equal(co_rx_register(&fx.line, &a), -EALREADY);
}

ZTEST(co_line, test_masked_and_extended_receivers)
{
	struct co_rx lss_any, ext;
	struct can_frame f = std_frame(0x7e5, 8);
	struct can_frame fe = std_frame(0x12345, 1);

	/* All ids 0x7e0..0x7ef. */
	rx_fill(&lss_any, 0x7e0, 0x7f0, false, 1);
	rx_fill(&ext, 0x12345, 0x1fffffff, true, 2);
	zassert_ok(co_rx_register(&fx.line, &lss_any));
	zassert_ok(co_rx_register(&fx.line, &ext));

	zassert_equal(co_line_rx(&fx.line, &f, 0), 1);
	f.id = 0x7f5;
	zassert_equal(co_line_rx(&fx.line, &f, 0), 0, "outside the mask");
	zassert_equal(co_line_rx(&fx.line, &fe, 0), 0, "standard frame with an extended id value");
	fe.flags = CAN_FRAME_IDE;
	zassert_equal(co_line_rx(&fx.line, &fe, 0), 1);
	fe.id = 0x345;
	zassert_equal(co_line_rx(&fx.line, &fe, 0), 0);
	zassert_equal(fx.log_len, 2);
	zassert_equal(fx.log[1], 2);
}

/*
 * A frame meets the exact 11-bit receivers of its id first, then the masked ones, each kind in
 * registration order; a receiver registered again or moved goes to the end of its kind. One
 * table holds both kinds, and this order is its layout.
 */
ZTEST(co_line, test_exact_receivers_come_before_masked_ones)
{
	struct co_rx m1, e1, m2, e2;
	struct can_frame f = std_frame(0x181, 0);
	const int first[] = {2, 4, 1, 3};
	const int later[] = {4, 2, 3, 1};

	rx_fill(&m1, 0x180, 0x780, false, 1);
	rx_fill(&e1, 0x181, 0x7ff, false, 2);
	rx_fill(&m2, 0x100, 0x700, false, 3);
	rx_fill(&e2, 0x181, 0x7ff, false, 4);
	zassert_ok(co_rx_register(&fx.line, &m1));
	zassert_ok(co_rx_register(&fx.line, &e1));
	zassert_ok(co_rx_register(&fx.line, &m2));
	zassert_ok(co_rx_register(&fx.line, &e2));
	zassert_equal(co_line_rx(&fx.line, &f, 0), 4);
	for (int i = 0; i < 4; i++) {
		zassert_equal(fx.log[i], first[i], "receiver %d", i);
	}

	co_rx_unregister(&e1);
	zassert_ok(co_rx_register(&fx.line, &e1));
	zassert_ok(co_rx_set_id(&fx.line, &m1, 0x180));
	fx.log_len = 0;
	zassert_equal(co_line_rx(&fx.line, &f, 0), 4);
	for (int i = 0; i < 4; i++) {
		zassert_equal(fx.log[i], later[i], "receiver %d", i);
	}
	co_rx_unregister(&m1);
	co_rx_unregister(&e1);
	co_rx_unregister(&m2);
	co_rx_unregister(&e2);
}

/*
 * CONFIG_CANOPEN_LINE_RX_SLOTS counts receivers of any kind: that many on one id leave no room
 * for a masked one, nor for a 29-bit one.
 */
ZTEST(co_line, test_every_receiver_takes_an_entry)
{
	static struct co_rx rx[CONFIG_CANOPEN_LINE_RX_SLOTS];
	struct co_rx masked, ext;

	for (int i = 0; i < CONFIG_CANOPEN_LINE_RX_SLOTS; i++) {
		rx_fill(&rx[i], 0x181, 0x7ff, false, i);
		zassert_ok(co_rx_register(&fx.line, &rx[i]), "receiver %d", i);
	}
	rx_fill(&masked, 0x100, 0x700, false, 99);
	rx_fill(&ext, 0x1234, 0x1fffffff, true, 98);
	zassert_equal(co_rx_register(&fx.line, &masked), -ENOSPC);
	zassert_equal(co_rx_register(&fx.line, &ext), -ENOSPC);
	zassert_is_null(masked.line, "a refused receiver is not registered");
	co_rx_unregister(&rx[0]);
	zassert_ok(co_rx_register(&fx.line, &masked), "room after one receiver left");
	zassert_equal(co_rx_register(&fx.line, &ext), -ENOSPC);
	co_rx_unregister(&masked);
	for (int i = 0; i < CONFIG_CANOPEN_LINE_RX_SLOTS; i++) {
		co_rx_unregister(&rx[i]);
	}
	zassert_ok(co_rx_register(&fx.line, &ext), "an empty table again");
	co_rx_unregister(&ext);
}

/* Receivers a test looks up, and the frames it sends them. */
#define PROBE_N   6
#define CROWD_N   42
#define CROWD_MIN (PROBE_N + CROWD_N + 1)

/* The tags a frame of @p id reached, in order, as a number (one decimal digit per receiver). */
static int rx_tags(uint32_t id)
{
	struct can_frame f = std_frame(id, 0);
	int tags = 0;

	fx.log_len = 0;
	co_line_rx(&fx.line, &f, 0);
	for (int i = 0; i < fx.log_len; i++) {
		tags = tags * 10 + fx.log[i];
	}
	return tags;
}

/*
 * The per-frame lookup finds the same receivers, in the same order, with six receivers on the
 * line, with 42 more exact ones on ids around theirs (below, between and above, which move
 * theirs up the table) and with a masked one beside them: a receiver's id is found by the
 * search, whatever else the table holds.
 */
ZTEST(co_line, test_lookup_finds_the_same_receivers_however_full_the_table)
{
	static struct co_rx probe[PROBE_N], crowd[CROWD_N];
	struct co_rx masked;
	/* Two of 181h, one each of 000h, 201h, 7ffh and 702h (registration order: tags 1..6). */
	const uint32_t probe_id[PROBE_N] = {0x181, 0x000, 0x7ff, 0x181, 0x201, 0x702};
	const uint32_t probe_expect[][2] = {
		{0x181, 14}, {0x000, 2}, {0x7ff, 3}, {0x201, 5}, {0x702, 6}, {0x182, 0}, {0x703, 0},
	};

	if (CONFIG_CANOPEN_LINE_RX_SLOTS < CROWD_MIN) {
		ztest_test_skip();
	}
	for (int i = 0; i < PROBE_N; i++) {
		rx_fill(&probe[i], probe_id[i], 0x7ff, false, i + 1);
		zassert_ok(co_rx_register(&fx.line, &probe[i]));
	}
	for (size_t k = 0; k < ARRAY_SIZE(probe_expect); k++) {
		zassert_equal(rx_tags(probe_expect[k][0]), (int)probe_expect[k][1], "alone: %03x",
			      probe_expect[k][0]);
	}

	/* The crowd: ids 1..7feh not used by the probes, spread over the range, not in order. */
	for (int i = 0; i < CROWD_N; i++) {
		uint32_t id = 1U + ((uint32_t)i * 977U) % 0x7fdU;

		if (id == 0x181 || id == 0x201 || id == 0x702 || id == 0x182 || id == 0x703) {
			id ^= 0x400U;
		}
		rx_fill(&crowd[i], id, 0x7ff, false, 9);
		zassert_ok(co_rx_register(&fx.line, &crowd[i]), "crowd %d", i);
	}
	for (size_t k = 0; k < ARRAY_SIZE(probe_expect); k++) {
		zassert_equal(rx_tags(probe_expect[k][0]), (int)probe_expect[k][1], "crowd: %03x",
			      probe_expect[k][0]);
	}
	for (int i = 0; i < CROWD_N; i++) {
		zassert_equal(rx_tags(crowd[i].id) % 10, 9, "crowd receiver %d", i);
	}

	/* A masked receiver of the heartbeat range (700h-77Fh): after 702h's exact one. */
	rx_fill(&masked, 0x700, 0x780, false, 7);
	zassert_ok(co_rx_register(&fx.line, &masked));
	zassert_equal(rx_tags(0x702), 67);
	zassert_equal(rx_tags(0x703), 7);
	zassert_equal(rx_tags(0x7ff), 3, "780h-7FFh is outside the mask");
	zassert_equal(rx_tags(0x181), 14);
	zassert_equal(rx_tags(0x000), 2);
	zassert_equal(rx_tags(0x201), 5);

	co_rx_unregister(&masked);
	for (int i = 0; i < CROWD_N; i++) {
		co_rx_unregister(&crowd[i]);
	}
	for (size_t k = 0; k < ARRAY_SIZE(probe_expect); k++) {
		zassert_equal(rx_tags(probe_expect[k][0]), (int)probe_expect[k][1], "after: %03x",
			      probe_expect[k][0]);
	}
	for (int i = 0; i < PROBE_N; i++) {
		co_rx_unregister(&probe[i]);
	}
	zassert_equal(fx.line.rx_used, 0);
}

/*
 * Receivers of one id stay in registration order while receivers of lower ids join and leave
 * (which moves the whole run up and down the table), and a receiver of that id registered
 * after them comes last.
 */
ZTEST(co_line, test_receivers_of_one_id_keep_registration_order_as_the_table_moves)
{
	struct co_rx same[3], low[3], late;

	for (int i = 0; i < 3; i++) {
		rx_fill(&same[i], 0x300, 0x7ff, false, i + 1);
		rx_fill(&low[i], 0x100 + (uint32_t)i, 0x7ff, false, 8);
	}
	rx_fill(&late, 0x300, 0x7ff, false, 4);
	zassert_ok(co_rx_register(&fx.line, &same[0]));
	zassert_ok(co_rx_register(&fx.line, &low[2]));
	zassert_ok(co_rx_register(&fx.line, &same[1]));
	zassert_ok(co_rx_register(&fx.line, &low[0]));
	zassert_ok(co_rx_register(&fx.line, &same[2]));
	zassert_equal(rx_tags(0x300), 123);
	co_rx_unregister(&low[2]);
	zassert_ok(co_rx_register(&fx.line, &low[1]));
	zassert_ok(co_rx_register(&fx.line, &late));
	zassert_equal(rx_tags(0x300), 1234);
	co_rx_unregister(&same[1]);
	zassert_equal(rx_tags(0x300), 134);
	zassert_equal(rx_tags(0x100), 8);
	zassert_equal(rx_tags(0x101), 8);
	zassert_equal(rx_tags(0x102), 0);
}

/*
 * The line's summary of its masked part names the function codes (id >> 7) its masked 11-bit
 * receivers can match, and 29-bit receivers with a bit of their own, and follows every change:
 * frames of other codes do not walk the masked receivers.
 */
ZTEST(co_line, test_masked_summary_names_the_codes_masked_receivers_can_match)
{
	struct co_rx hb, lss, any, ext;

	zassert_equal(fx.line.rx_masked_codes, 0U);
	rx_fill(&hb, 0x700, 0x780, false, 1);
	zassert_ok(co_rx_register(&fx.line, &hb));
	zassert_equal(fx.line.rx_masked_codes, BIT(0x700 >> 7), "heartbeats: code 14 only");
	rx_fill(&lss, 0x7e0, 0x7f0, false, 2);
	zassert_ok(co_rx_register(&fx.line, &lss));
	zassert_equal(fx.line.rx_masked_codes, BIT(14) | BIT(15));
	rx_fill(&ext, 0x12345, 0x1fffff00, true, 3);
	zassert_ok(co_rx_register(&fx.line, &ext));
	zassert_equal(fx.line.rx_masked_codes, BIT(14) | BIT(15) | CO_LINE_MASKED_EXT);
	co_rx_unregister(&hb);
	zassert_equal(fx.line.rx_masked_codes, BIT(15) | CO_LINE_MASKED_EXT);
	/* The low bits of a mask say nothing of the code: every 11-bit id. */
	rx_fill(&any, 0x005, 0x00f, false, 4);
	zassert_ok(co_rx_register(&fx.line, &any));
	zassert_equal(fx.line.rx_masked_codes, 0xffffU | CO_LINE_MASKED_EXT);
	zassert_ok(co_rx_set_id(&fx.line, &any, 0x005), "moved within the masked part");
	zassert_equal(fx.line.rx_masked_codes, 0xffffU | CO_LINE_MASKED_EXT);
	co_rx_unregister(&any);
	co_rx_unregister(&ext);
	zassert_equal(fx.line.rx_masked_codes, BIT(15));
	zassert_equal(rx_tags(0x7e5), 2);
	co_rx_unregister(&lss);
	zassert_equal(fx.line.rx_masked_codes, 0U);
}

ZTEST(co_line, test_set_id_moves_a_receiver)
{
	struct co_rx a;
	struct can_frame f = std_frame(0x181, 1);

	rx_fill(&a, 0x181, 0x7ff, false, 7);
	zassert_ok(co_rx_register(&fx.line, &a));
	zassert_ok(co_rx_set_id(&fx.line, &a, 0x281));
	zassert_equal(co_line_rx(&fx.line, &f, 0), 0);
	f.id = 0x281;
	zassert_equal(co_line_rx(&fx.line, &f, 0), 1);
	zassert_equal(co_rx_set_id(&fx.line, &a, 0x900), -EINVAL);
	zassert_equal(co_line_rx(&fx.line, &f, 0), 1, "a refused move keeps the old id");
}

struct tagged_timer {
	struct co_timer t;
	int tag;
	uint64_t rearm_period;
	int fired;
};

static void timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct tagged_timer *tt = CONTAINER_OF(timer, struct tagged_timer, t);

	tt->fired++;
	record(tt->tag, now_us);
	if (tt->rearm_period != 0U) {
		co_timer_start(&fx.line, timer, timer->deadline + tt->rearm_period);
	}
}

ZTEST(co_line, test_timers_run_in_deadline_order_and_report_the_next)
{
	struct tagged_timer a = {.tag = 1}, b = {.tag = 2}, c = {.tag = 3};

	co_timer_init(&a.t, timer_handler, &fx.node_lock, NULL);
	co_timer_init(&b.t, timer_handler, &fx.node_lock, NULL);
	co_timer_init(&c.t, timer_handler, NULL, NULL);
	zassert_equal(co_line_next_deadline(&fx.line), UINT64_MAX);

	co_timer_start(&fx.line, &a.t, 3000);
	co_timer_start(&fx.line, &b.t, 1000);
	co_timer_start(&fx.line, &c.t, 1000); /* same deadline: after b */
	zassert_equal(co_line_next_deadline(&fx.line), 1000);

	zassert_equal(co_line_process(&fx.line, 999), 1000, "nothing due yet");
	zassert_equal(fx.log_len, 0);
	zassert_equal(co_line_process(&fx.line, 2000), 3000);
	zassert_equal(fx.log_len, 2);
	zassert_equal(fx.log[0], 2);
	zassert_equal(fx.log[1], 3);
	zassert_false(co_timer_is_armed(&b.t));
	zassert_true(co_timer_is_armed(&a.t));
	zassert_equal(co_line_process(&fx.line, 5000), UINT64_MAX);
	zassert_equal(fx.log[2], 1);
	zassert_equal(fx.log_time[2], 5000, "handler gets the current time");
}

ZTEST(co_line, test_restart_replaces_the_deadline_and_stop_disarms)
{
	struct tagged_timer a = {.tag = 1};

	co_timer_init(&a.t, timer_handler, &fx.node_lock, NULL);
	co_timer_start(&fx.line, &a.t, 1000);
	co_timer_start(&fx.line, &a.t, 4000);
	zassert_equal(co_line_process(&fx.line, 2000), 4000);
	zassert_equal(a.fired, 0);
	co_timer_stop(&a.t);
	zassert_false(co_timer_is_armed(&a.t));
	zassert_equal(co_line_process(&fx.line, 10000), UINT64_MAX);
	zassert_equal(a.fired, 0);
	co_timer_stop(&a.t); /* stopping twice is harmless */
}

static bool armed_in_handler;

static void armed_handler(struct co_timer *timer, uint64_t now_us)
{
	armed_in_handler = co_timer_is_armed(timer);
}

/*
 * Armed means in the line's list, wherever: at the head, in the middle, or last (which has
 * no successor, as a timer outside the list); a timer whose handler runs is not armed.
 */
ZTEST(co_line, test_a_timer_is_armed_wherever_it_is_in_the_list)
{
	struct tagged_timer a = {.tag = 1}, b = {.tag = 2}, c = {.tag = 3};
	struct co_timer d;

	co_timer_init(&a.t, timer_handler, &fx.node_lock, NULL);
	co_timer_init(&b.t, timer_handler, &fx.node_lock, NULL);
	co_timer_init(&c.t, timer_handler, &fx.node_lock, NULL);
	co_timer_init(&d, armed_handler, &fx.node_lock, NULL);
	zassert_false(co_timer_is_armed(&a.t), "never started");
	co_timer_start(&fx.line, &a.t, 1000);
	zassert_true(co_timer_is_armed(&a.t), "alone in the list");
	co_timer_start(&fx.line, &b.t, 2000);
	co_timer_start(&fx.line, &c.t, 3000);
	zassert_true(co_timer_is_armed(&a.t) && co_timer_is_armed(&b.t) && co_timer_is_armed(&c.t));
	co_timer_stop(&b.t);
	zassert_false(co_timer_is_armed(&b.t), "taken from the middle");
	zassert_true(co_timer_is_armed(&a.t) && co_timer_is_armed(&c.t));
	co_timer_stop(&c.t);
	zassert_false(co_timer_is_armed(&c.t), "taken from the end");
	zassert_true(co_timer_is_armed(&a.t), "now the last one");
	co_timer_start(&fx.line, &c.t, 500);
	zassert_true(co_timer_is_armed(&c.t) && co_timer_is_armed(&a.t));
	zassert_equal(co_line_process(&fx.line, 1000), UINT64_MAX);
	zassert_equal(fx.log_len, 2);
	zassert_false(co_timer_is_armed(&a.t) || co_timer_is_armed(&c.t), "run: disarmed");

	armed_in_handler = true;
	co_timer_start(&fx.line, &d, 2000);
	co_timer_start(&fx.line, &b.t, 2000);
	zassert_equal(co_line_process(&fx.line, 2000), UINT64_MAX);
	zassert_false(armed_in_handler, "not armed while its handler runs");
	zassert_equal(b.fired, 1, "the next one still runs");
}

/* Deadlines of the heap tests: not in order, with repeats (equal ones keep arming order). */
#define HEAP_N 15
static const uint16_t heap_deadline[HEAP_N] = {700, 300,  900, 300, 100, 800, 500, 300,
					       200, 1000, 600, 100, 400, 900, 300};

static struct tagged_timer heap_timers[HEAP_N];

static void heap_arm_all(void)
{
	for (int i = 0; i < HEAP_N; i++) {
		heap_timers[i] = (struct tagged_timer){.tag = i};
		co_timer_init(&heap_timers[i].t, timer_handler, &fx.node_lock, NULL);
		co_timer_start(&fx.line, &heap_timers[i].t, heap_deadline[i]);
	}
}

/* Whether the log holds the timers in deadline order, equal deadlines in tag order. */
static void assert_log_in_order(int n)
{
	for (int i = 1; i < n; i++) {
		uint16_t a = heap_deadline[fx.log[i - 1]];
		uint16_t b = heap_deadline[fx.log[i]];

		zassert_true(a < b || (a == b && fx.log[i - 1] < fx.log[i]), "position %d: %d, %d",
			     i, fx.log[i - 1], fx.log[i]);
	}
}

/* Fifteen timers armed out of order run by deadline, equal deadlines in arming order. */
ZTEST(co_line, test_timer_heap_runs_by_deadline_then_arming_order)
{
	heap_arm_all();
	zassert_equal(co_line_next_deadline(&fx.line), 100);
	zassert_equal(co_line_process(&fx.line, 2000), UINT64_MAX);
	zassert_equal(fx.log_len, HEAP_N);
	assert_log_in_order(HEAP_N);
	zassert_equal(fx.log[0], 4, "first of the two at 100");
	zassert_equal(fx.log[1], 11);
}

/*
 * Timers stopped from the middle of the heap and from its end, and timers restarted earlier
 * and later, leave the others in order: each runs once at its new deadline or not at all.
 */
ZTEST(co_line, test_timer_heap_stop_and_restart_in_the_middle)
{
	/* Stopped: 6 (500), 2 (900) and 14 (the last armed); restarted: 9 to 50, 4 to 950. */
	heap_arm_all();
	co_timer_stop(&heap_timers[6].t);
	co_timer_stop(&heap_timers[2].t);
	co_timer_stop(&heap_timers[14].t);
	co_timer_start(&fx.line, &heap_timers[9].t, 50);
	co_timer_start(&fx.line, &heap_timers[4].t, 950);
	zassert_equal(co_line_next_deadline(&fx.line), 50);
	zassert_false(co_timer_is_armed(&heap_timers[6].t));
	zassert_equal(co_line_process(&fx.line, 60), 100);
	zassert_equal(fx.log_len, 1);
	zassert_equal(fx.log[0], 9, "restarted earlier");
	zassert_equal(co_line_process(&fx.line, 900), 950);
	zassert_equal(co_line_process(&fx.line, 2000), UINT64_MAX);
	zassert_equal(fx.log_len, HEAP_N - 3);
	zassert_equal(fx.log[HEAP_N - 4], 4, "restarted later: last");
	for (int i = 0; i < fx.log_len; i++) {
		zassert_true(fx.log[i] != 6 && fx.log[i] != 2 && fx.log[i] != 14, "stopped %d ran",
			     fx.log[i]);
	}
	/* Between the first (9) and the last (4), the rest in order. */
	for (int i = 2; i < HEAP_N - 4; i++) {
		uint16_t a = heap_deadline[fx.log[i - 1]];
		uint16_t b = heap_deadline[fx.log[i]];

		zassert_true(a < b || (a == b && fx.log[i - 1] < fx.log[i]), "position %d", i);
	}
}

/*
 * A line arms CONFIG_CANOPEN_LINE_TIMERS timers at once; one more stays disarmed, counted and
 * logged, and the others are unharmed. Once one has run there is room again.
 */
ZTEST(co_line, test_timer_heap_full_leaves_the_timer_disarmed_and_counts_it)
{
	static struct tagged_timer t[CONFIG_CANOPEN_LINE_TIMERS + 1];
	struct co_line_stats st;

	for (int i = 0; i <= CONFIG_CANOPEN_LINE_TIMERS; i++) {
		t[i] = (struct tagged_timer){.tag = i};
		co_timer_init(&t[i].t, timer_handler, &fx.node_lock, NULL);
	}
	for (int i = 0; i < CONFIG_CANOPEN_LINE_TIMERS; i++) {
		co_timer_start(&fx.line, &t[i].t, 1000U + (uint64_t)i);
	}
	co_timer_start(&fx.line, &t[CONFIG_CANOPEN_LINE_TIMERS].t, 10);
	zassert_false(co_timer_is_armed(&t[CONFIG_CANOPEN_LINE_TIMERS].t));
	co_timer_stop(&t[CONFIG_CANOPEN_LINE_TIMERS].t); /* harmless */
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.timer_overflows, 1);
	zassert_equal(co_line_next_deadline(&fx.line), 1000, "the others are unharmed");
	zassert_true(co_timer_is_armed(&t[0].t));

	zassert_equal(co_line_process(&fx.line, 1000), 1001);
	co_timer_start(&fx.line, &t[CONFIG_CANOPEN_LINE_TIMERS].t, 1000);
	zassert_true(co_timer_is_armed(&t[CONFIG_CANOPEN_LINE_TIMERS].t), "room again");
	zassert_equal(co_line_process(&fx.line, 5000), UINT64_MAX);
	zassert_equal(fx.log_len, CONFIG_CANOPEN_LINE_TIMERS + 1);
	zassert_equal(fx.log[1], CONFIG_CANOPEN_LINE_TIMERS, "at 1000: before 1001");
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.timer_overflows, 1);
}

static K_THREAD_STACK_DEFINE(processor_stack, 4096);
static struct k_thread processor;

/* The line thread's part: process the line at the time *p1. */
static void process_at(void *p1, void *p2, void *p3)
{
	ARG_UNUSED(p2);
	ARG_UNUSED(p3);
	(void)co_line_process(&fx.line, *(const uint64_t *)p1);
}

/*
 * Process the line at @p now in another thread while this one holds the timer's lock, and
 * return once that thread has taken @p timer off the list (it then waits for the lock).
 */
static void process_while_locked(const struct co_timer *timer, const uint64_t *now)
{
	k_mutex_lock(&fx.node_lock, K_FOREVER);
	k_thread_create(&processor, processor_stack, K_THREAD_STACK_SIZEOF(processor_stack),
			process_at, (void *)now, NULL, NULL, K_PRIO_PREEMPT(1), 0, K_NO_WAIT);
	for (int i = 0; i < 5000 && co_timer_is_armed(timer); i++) {
		k_msleep(1);
	}
	zassert_false(co_timer_is_armed(timer), "the timer was taken off the list");
}

ZTEST(co_line, test_a_timer_changed_after_it_was_taken_off_the_list_does_not_run)
{
	static const uint64_t t2000 = 2000, t7000 = 7000;
	struct tagged_timer a = {.tag = 1};

	/*
	 * The line thread takes a due timer off the list, then waits for the owner's lock;
	 * the owner restarts or stops the timer meanwhile: it is not due any more.
	 */
	co_timer_init(&a.t, timer_handler, &fx.node_lock, NULL);
	co_timer_start(&fx.line, &a.t, 1000);
	process_while_locked(&a.t, &t2000);
	co_timer_start(&fx.line, &a.t, 4000);
	zassert_true(co_timer_is_armed(&a.t));
	k_mutex_unlock(&fx.node_lock);
	zassert_ok(k_thread_join(&processor, K_SECONDS(5)));
	zassert_equal(a.fired, 0, "restarted: not run at its old deadline");
	zassert_true(co_timer_is_armed(&a.t), "armed for the new deadline");
	zassert_equal(co_line_process(&fx.line, 4000), UINT64_MAX);
	zassert_equal(a.fired, 1, "run at the new deadline");

	co_timer_start(&fx.line, &a.t, 6000);
	process_while_locked(&a.t, &t7000);
	co_timer_stop(&a.t);
	k_mutex_unlock(&fx.node_lock);
	zassert_ok(k_thread_join(&processor, K_SECONDS(5)));
	zassert_equal(a.fired, 1, "stopped: not run");
	zassert_false(co_timer_is_armed(&a.t));
	zassert_equal(co_line_process(&fx.line, 8000), UINT64_MAX);
	zassert_equal(a.fired, 1);

	/* Unchanged after it was taken off: it runs. */
	co_timer_start(&fx.line, &a.t, 9000);
	zassert_equal(co_line_process(&fx.line, 9000), UINT64_MAX);
	zassert_equal(a.fired, 2);
}

ZTEST(co_line, test_periodic_timer_rearmed_from_its_handler_catches_up)
{
	struct tagged_timer hb = {.tag = 5, .rearm_period = 100};

	co_timer_init(&hb.t, timer_handler, &fx.node_lock, NULL);
	co_timer_start(&fx.line, &hb.t, 100);
	/* Late by 3.5 periods: the handler runs for each missed deadline, then waits. */
	zassert_equal(co_line_process(&fx.line, 450), 500);
	zassert_equal(hb.fired, 4);
}

static struct can_frame tx_frame(uint32_t id)
{
	struct can_frame f = {.id = id, .dlc = 1, .data = {(uint8_t)id}};

	return f;
}

ZTEST(co_line, test_send_goes_straight_to_the_sink)
{
	struct can_frame f = tx_frame(0x701);

	zassert_ok(co_line_send(&fx.line, &f));
	zassert_equal(fx.sent_len, 1);
	zassert_equal(fx.sent[0].id, 0x701);
}

ZTEST(co_line, test_back_pressure_queues_frames_in_order)
{
	struct co_line_stats st;

	fx.sink_result = -EAGAIN;
	for (uint32_t i = 0; i < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE; i++) {
		struct can_frame f = tx_frame(0x580 + i);

		zassert_ok(co_line_send(&fx.line, &f), "queued, not an error");
	}
	zassert_equal(fx.sent_len, 0);

	/* Driver still full: nothing moves. */
	co_line_process(&fx.line, 0);
	zassert_equal(fx.sent_len, 0);

	fx.sink_result = 0;
	co_line_process(&fx.line, 0);
	zassert_equal(fx.sent_len, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	for (int i = 0; i < fx.sent_len; i++) {
		zassert_equal(fx.sent[i].id, 0x580 + i, "order kept");
	}
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.tx_queued, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	zassert_equal(st.tx_queue_max, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	zassert_equal(st.tx_frames, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	zassert_equal(st.tx_dropped, 0);
}

ZTEST(co_line, test_a_frame_sent_while_others_wait_queues_behind_them)
{
	struct can_frame f1 = tx_frame(0x181), f2 = tx_frame(0x182);

	fx.sink_result = -ENOBUFS;
	zassert_ok(co_line_send(&fx.line, &f1));
	fx.sink_result = 0;
	/* The driver would take f2 now, but f1 must go first. */
	zassert_ok(co_line_send(&fx.line, &f2));
	zassert_equal(fx.sent_len, 0);
	co_line_process(&fx.line, 0);
	zassert_equal(fx.sent_len, 2);
	zassert_equal(fx.sent[0].id, 0x181);
	zassert_equal(fx.sent[1].id, 0x182);
}

ZTEST(co_line, test_full_tx_queue_drops_counts_and_reports)
{
	struct co_line_stats st;
	struct can_frame f = tx_frame(0x281);

	fx.sink_result = -EAGAIN;
	for (int i = 0; i < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE; i++) {
		zassert_ok(co_line_send(&fx.line, &f));
	}
	zassert_equal(co_line_send(&fx.line, &f), -ENOBUFS);
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.tx_dropped, 1);
	zassert_equal(fx.event_len, 1);
	zassert_equal(fx.events[0], CO_LINE_EV_TX_OVERFLOW);
}

ZTEST(co_line, test_driver_error_is_returned_and_reported)
{
	struct can_frame f = tx_frame(0x181);
	struct co_line_stats st;

	fx.sink_result = -ENETDOWN;
	zassert_equal(co_line_send(&fx.line, &f), -ENETDOWN);
	zassert_equal(fx.event_len, 1);
	zassert_equal(fx.events[0], CO_LINE_EV_TX_ERROR);
	zassert_equal(fx.event_args[0], -ENETDOWN);
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.tx_errors, 1);
	zassert_equal(st.tx_frames, 0);
}

ZTEST(co_line, test_wrap_safe_time_comparison)
{
	zassert_true(co_time_before_eq(5, 5));
	zassert_true(co_time_before_eq(UINT64_MAX - 10, 5), "across the wrap");
	zassert_false(co_time_before_eq(5, UINT64_MAX - 10));
}

ZTEST(co_line, test_receivers_beyond_the_fanout_are_counted)
{
	static struct co_rx rx[CONFIG_CANOPEN_LINE_RX_FANOUT + 2];
	struct can_frame f = std_frame(0x080, 0);
	struct co_line_stats st;

	/* A table of fewer receivers cannot exceed the fanout (minimal_tables: 16 and 16). */
	if (CONFIG_CANOPEN_LINE_RX_SLOTS < (int)ARRAY_SIZE(rx)) {
		ztest_test_skip();
	}
	for (int i = 0; i < (int)ARRAY_SIZE(rx); i++) {
		rx_fill(&rx[i], 0x080, 0x7ff, false, i);
		zassert_ok(co_rx_register(&fx.line, &rx[i]));
	}
	zassert_equal(co_line_rx(&fx.line, &f, 1), CONFIG_CANOPEN_LINE_RX_FANOUT);
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.rx_fanout_drops, 2, "the two receivers the frame missed");
	zassert_equal(fx.log[0], 0, "the first registered get it");
	for (int i = 0; i < (int)ARRAY_SIZE(rx); i++) {
		co_rx_unregister(&rx[i]);
	}
}

ZTEST(co_line, test_set_id_moves_a_receiver_to_another_line)
{
	static struct co_line other;
	struct can_frame f = std_frame(0x181, 1);
	struct co_rx rx;

	co_line_init_sim(&other, "sim1", sink, NULL);
	rx_fill(&rx, 0x181, 0x7ff, false, 7);
	zassert_ok(co_rx_register(&fx.line, &rx));
	zassert_ok(co_rx_set_id(&other, &rx, 0x181));
	zassert_equal(co_line_rx(&fx.line, &f, 1), 0, "gone from the first line's table");
	zassert_equal(co_line_rx(&other, &f, 2), 1, "and in the other's");
	zassert_ok(co_rx_set_id(&other, &rx, 0x182), "moved within the line");
	zassert_equal(co_line_rx(&other, &f, 3), 0);
	co_rx_unregister(&rx);
	zassert_equal(fx.log_len, 1);
}

ZTEST(co_line, test_line_knows_whether_a_node_lock_is_held)
{
	struct co_line_member m;

	zassert_false(co_line_owner_held(&fx.line), "no node attached");
	co_line_attach(&fx.line, &m, &fx.node_lock);
	zassert_false(co_line_owner_held(&fx.line));
	k_mutex_lock(&fx.node_lock, K_FOREVER);
	zassert_true(co_line_owner_held(&fx.line));
	k_mutex_unlock(&fx.node_lock);
	zassert_false(co_line_owner_held(&fx.line));
	zassert_is_null(co_line_current(), "the test thread is no line thread");
	co_line_detach(&fx.line, &m);
	co_line_detach(&fx.line, &m); /* safe twice */
}

ZTEST(co_line, test_purge_withdraws_one_nodes_queued_frames_in_order)
{
	struct k_mutex a, b;
	struct co_line_stats st;
	/* Odd IDs from node a, even ones from b; the test line queues 4 frames. */
	static const uint32_t ids[] = {0x705, 0x585, 0x586, 0x187};

	k_mutex_init(&a);
	k_mutex_init(&b);
	fx.sink_result = -EAGAIN; /* back-pressure: everything waits in the queue */
	for (size_t i = 0; i < ARRAY_SIZE(ids); i++) {
		struct can_frame f = std_frame(ids[i], 1);

		zassert_ok(co_line_send_from(&fx.line, &f, (ids[i] & 1U) ? &a : &b));
	}
	/* Node a withdraws what it queued except its error control. */
	zassert_equal(co_line_tx_purge(&fx.line, &a, keep_error_control, NULL), 2);
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.tx_purged, 2);

	fx.sink_result = 0;
	co_line_process(&fx.line, 10);
	zassert_equal(fx.sent_len, 2);
	zassert_equal(fx.sent[0].id, 0x705, "a's heartbeat stays");
	zassert_equal(fx.sent[1].id, 0x586, "b's frame stays, behind it");
}

ZTEST(co_line, test_frames_of_one_node_reach_the_other_nodes_of_the_line)
{
	struct k_mutex node_a, node_b;
	struct co_line_member ma, mb;
	struct co_rx ra, rb;
	struct can_frame f = std_frame(0x701, 1);

	k_mutex_init(&node_a);
	k_mutex_init(&node_b);
	rx_fill(&ra, 0x701, 0x7ff, false, 1);
	ra.lock = &node_a;
	rx_fill(&rb, 0x701, 0x7ff, false, 2);
	rb.lock = &node_b;
	zassert_ok(co_rx_register(&fx.line, &ra));
	zassert_ok(co_rx_register(&fx.line, &rb));

	/* One node on the line: nothing to deliver locally. */
	co_line_attach(&fx.line, &ma, &node_a);
	zassert_ok(co_line_send_from(&fx.line, &f, &node_a));
	zassert_equal(co_line_process(&fx.line, 10), UINT64_MAX);
	zassert_equal(fx.log_len, 0);

	co_line_attach(&fx.line, &mb, &node_b);
	zassert_ok(co_line_send_from(&fx.line, &f, &node_a));
	zassert_equal(fx.sent_len, 2, "the frame still goes to the bus");
	zassert_equal(fx.log_len, 0, "delivered in the line's context, not inside the send");
	co_line_process(&fx.line, 20);
	zassert_equal(fx.log_len, 1);
	zassert_equal(fx.log[0], 2, "only the other node gets it");
	zassert_equal(fx.log_time[0], 10, "reception time = send time");
	zassert_mem_equal(&last_rx, &f, sizeof(f), "the frame as sent (dlc, flags, data)");

	/* Through the line's queue as the sent frame: dlc 8 and the RTR flag come out as they went.
	 */
	f = std_frame(0x701, 8);
	f.flags = CAN_FRAME_RTR;
	zassert_ok(co_line_send_from(&fx.line, &f, &node_a));
	co_line_process(&fx.line, 30);
	zassert_equal(fx.log_len, 2);
	zassert_mem_equal(&last_rx, &f, sizeof(f));

	struct co_line_stats st;

	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.rx_frames, 0, "local frames are not counted as received from the bus");
}

/* Local frames that find the line's RX queue full are lost and counted as overruns. */
ZTEST(co_line, test_local_frames_beyond_the_rx_queue_are_counted_as_overruns)
{
	struct k_mutex node_a, node_b;
	struct co_line_member ma, mb;
	struct can_frame f = std_frame(0x701, 1);
	struct co_line_stats st;

	if (!IS_ENABLED(CONFIG_CANOPEN_LINE_SHARED)) {
		ztest_test_skip();
	}
	k_mutex_init(&node_a);
	k_mutex_init(&node_b);
	zassert_ok(co_line_attach(&fx.line, &ma, &node_a));
	zassert_ok(co_line_attach(&fx.line, &mb, &node_b));
	fx.sink_discard = true;
	for (int i = 0; i < CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE + 2; i++) {
		zassert_ok(co_line_send_from(&fx.line, &f, &node_a));
	}
	co_line_get_stats(&fx.line, &st);
	zassert_equal(st.rx_overruns, 2, "the two frames the queue had no room for");
	zassert_equal(st.tx_frames, CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE + 2, "all went to the bus");
	co_line_process(&fx.line, 0);
	co_line_detach(&fx.line, &mb);
	co_line_detach(&fx.line, &ma);
}

/*
 * A queued message keeps the low 32 bits of its time: the reader extends them from its own
 * time, on either side of a wrap of those bits, and for a message from after the reader's time.
 */
ZTEST(co_line, test_a_queued_frame_keeps_its_time_across_a_32_bit_wrap)
{
	const uint64_t wrap = 0x100000000ULL;
	struct co_line_rx_msg m = {.time_lo = (uint32_t)(wrap - 3U)};

	zassert_equal(co_line_msg_time(&m, wrap + 7U), wrap - 3U);
	zassert_equal(co_line_msg_time(&m, wrap - 3U), wrap - 3U);
	zassert_equal(co_line_msg_time(&m, wrap - 10U), wrap - 3U, "a time after the reader's");
	m.time_lo = 2U;
	zassert_equal(co_line_msg_time(&m, wrap - 10U), wrap + 2U);
	zassert_equal(co_line_msg_time(&m, 5U * wrap + 1000000U), 5U * wrap + 2U);
	zassert_equal(co_line_msg_time(&m, 3U), 2U);

	/* Through the queue: a local frame sent just before the wrap, delivered after it. */
	struct k_mutex node_a, node_b;
	struct co_line_member ma, mb;
	struct co_rx rb;
	struct can_frame f = std_frame(0x702, 1);

	k_mutex_init(&node_a);
	k_mutex_init(&node_b);
	rx_fill(&rb, 0x702, 0x7ff, false, 2);
	rb.lock = &node_b;
	zassert_ok(co_rx_register(&fx.line, &rb));
	co_line_attach(&fx.line, &ma, &node_a);
	co_line_attach(&fx.line, &mb, &node_b);
	co_line_process(&fx.line, 5U * wrap - 1U);
	zassert_ok(co_line_send_from(&fx.line, &f, &node_a));
	co_line_process(&fx.line, 5U * wrap + 20U);
	zassert_equal(fx.log_len, 1);
	zassert_equal(fx.log_time[0], 5U * wrap - 1U, "reception time = send time");
}

/* --- Listeners ------------------------------------------------------------------------------ */

struct listener_log {
	struct co_line_listener l;
	int tag;
};

static void listener_cb(struct co_line_listener *l, enum co_line_event event, int arg)
{
	struct listener_log *ll = CONTAINER_OF(l, struct listener_log, l);

	/* Called with the owner's lock held (recursive: lock again succeeds at once). */
	zassert_ok(k_mutex_lock(l->lock, K_NO_WAIT));
	k_mutex_unlock(l->lock);
	record(ll->tag * 100 + (int)event * 10 + (arg & 7), 0);
}

ZTEST(co_line, test_listeners_hear_events_after_the_application_in_order)
{
	static struct listener_log a = {.tag = 1};
	static struct listener_log b = {.tag = 2};

	co_line_listener_init(&a.l, listener_cb, &fx.node_lock, NULL);
	co_line_listener_init(&b.l, listener_cb, &fx.node_lock, NULL);
	zassert_ok(co_line_listener_add(&fx.line, &a.l));
	zassert_ok(co_line_listener_add(&fx.line, &b.l));
	zassert_ok(co_line_listener_add(&fx.line, &a.l), "adding twice is harmless");

	co_line_inject_event(&fx.line, CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	zassert_equal(fx.event_len, 1, "the application's callback as before");
	zassert_equal(fx.event_args[0], CAN_STATE_ERROR_PASSIVE);
	zassert_equal(fx.log_len, 2, "each listener once");
	zassert_equal(fx.log[0], 100 + CO_LINE_EV_CAN_STATE * 10 + CAN_STATE_ERROR_PASSIVE);
	zassert_equal(fx.log[1], 200 + CO_LINE_EV_CAN_STATE * 10 + CAN_STATE_ERROR_PASSIVE);

	co_line_listener_remove(&a.l);
	co_line_listener_remove(&a.l);
	co_line_inject_event(&fx.line, CO_LINE_EV_RX_OVERRUN, 0);
	zassert_equal(fx.log_len, 3);
	zassert_equal(fx.log[2], 200 + CO_LINE_EV_RX_OVERRUN * 10);
	co_line_listener_remove(&b.l);
}

ZTEST(co_line, test_send_side_events_reach_listeners_in_process_only)
{
	static struct listener_log a = {.tag = 1};
	struct can_frame f = tx_frame(0x281);

	co_line_listener_init(&a.l, listener_cb, &fx.node_lock, NULL);
	zassert_ok(co_line_listener_add(&fx.line, &a.l));
	fx.sink_result = -EAGAIN;
	for (int i = 0; i < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE; i++) {
		zassert_ok(co_line_send(&fx.line, &f));
	}
	zassert_equal(co_line_send(&fx.line, &f), -ENOBUFS);
	zassert_equal(co_line_send(&fx.line, &f), -ENOBUFS);
	zassert_equal(fx.event_len, 2, "application: at once, each time");
	zassert_equal(fx.log_len, 0, "listeners: not in the sender's context");
	co_line_process(&fx.line, 0);
	zassert_equal(fx.log_len, 1, "listeners: once, from the line's pass");
	zassert_equal(fx.log[0], 100 + CO_LINE_EV_TX_OVERFLOW * 10);
	co_line_process(&fx.line, 0);
	zassert_equal(fx.log_len, 1);
	co_line_listener_remove(&a.l);
}
