/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The SocketCAN driver's in-flight queue (drivers/can/socketcan/socketcan_txq.h): which entry
 * an echo completes, which entries a lost echo releases, and when an entry without echo is
 * released. Times are made-up nanoseconds; nothing here waits.
 */

#include <string.h>

#include <zephyr/ztest.h>

#include "socketcan_txq.h"

#define SIZE 4
#define T    100000000ULL /* the bound: 100 ms */
#define MS   1000000ULL

static struct sc_txq q;
static struct sc_txq_entry entries[SIZE];
static struct sc_txq_entry out[SIZE];
static struct sc_txq_entry done;
static int n_lost;
/* each entry's user_data is its tag, to tell which entry came out */
static int tags[8];

static struct socketcan_host_frame frame(uint32_t id, uint8_t dlc, uint8_t first_byte)
{
	struct socketcan_host_frame f = {.id = id, .dlc = dlc};

	memset(f.data, 0xEE, sizeof(f.data));
	if (dlc > 0U) {
		f.data[0] = first_byte;
	}

	return f;
}

static void push(const struct socketcan_host_frame *f, int tag, uint64_t at)
{
	zassert_true(sc_txq_push(&q, f, NULL, &tags[tag], at), "push of tag %d refused", tag);
}

static int tag_of(const struct sc_txq_entry *e)
{
	return (int)((int *)e->user_data - tags);
}

static void expect_echo_completes(const struct socketcan_host_frame *f, uint64_t at, int tag,
				  int lost_expected)
{
	zassert_equal(sc_txq_echo(&q, f, at, &done, out, &n_lost), SC_TXQ_ECHO_MATCHED,
		      "echo of 0x%x matched nothing", f->id);
	zassert_equal(tag_of(&done), tag, "the echo completed tag %d, expected %d", tag_of(&done),
		      tag);
	zassert_equal(n_lost, lost_expected, "%d entries lost, expected %d", n_lost, lost_expected);
}

static void before(void *fixture)
{
	sc_txq_init(&q, entries, SIZE, T);
}

ZTEST_SUITE(socketcan_txq, NULL, NULL, before, NULL, NULL);

ZTEST(socketcan_txq, test_echoes_complete_their_frames_in_order)
{
	const struct socketcan_host_frame a = frame(0x701, 1, 5);
	const struct socketcan_host_frame b = frame(0x181, 2, 7);

	push(&a, 0, 0);
	push(&b, 1, 0);
	expect_echo_completes(&a, 1 * MS, 0, 0);
	expect_echo_completes(&b, 2 * MS, 1, 0);
	zassert_equal(sc_txq_count(&q), 0);
}

ZTEST(socketcan_txq, test_a_later_frames_echo_releases_the_frames_written_before_it)
{
	const struct socketcan_host_frame a = frame(0x701, 1, 5);
	const struct socketcan_host_frame b = frame(0x181, 2, 7);
	const struct socketcan_host_frame c = frame(0x581, 8, 0x43);

	push(&a, 0, 0);
	push(&b, 1, 0);
	push(&c, 2, 0);
	/* the echoes of a and b were dropped: the kernel would have queued them before c's */
	expect_echo_completes(&c, 1 * MS, 2, 2);
	zassert_equal(tag_of(&out[0]), 0, "lost entries come oldest first");
	zassert_equal(tag_of(&out[1]), 1);
	zassert_equal(sc_txq_count(&q), 0);
}

ZTEST(socketcan_txq, test_an_echo_compares_identifier_type_dlc_and_data)
{
	const struct socketcan_host_frame a = frame(0x123, 2, 1);
	struct socketcan_host_frame other_data = frame(0x123, 2, 2);
	struct socketcan_host_frame other_dlc = frame(0x123, 3, 1);
	struct socketcan_host_frame other_type = frame(0x123, 2, 1);
	struct socketcan_host_frame same_beyond_dlc = frame(0x123, 2, 1);

	other_type.flags = SOCKETCAN_HOST_F_IDE;
	same_beyond_dlc.data[5] = 0x55; /* bytes past the DLC are not part of the frame */
	push(&a, 0, 0);
	zassert_equal(sc_txq_echo(&q, &other_data, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	zassert_equal(sc_txq_echo(&q, &other_dlc, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	zassert_equal(sc_txq_echo(&q, &other_type, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	zassert_equal(sc_txq_count(&q), 1, "an echo of another frame took the entry");
	expect_echo_completes(&same_beyond_dlc, 1, 0, 0);
}

ZTEST(socketcan_txq, test_a_remote_frames_echo_matches_whatever_its_data_bytes)
{
	struct socketcan_host_frame rtr = frame(0x456, 3, 0);
	struct socketcan_host_frame echo = frame(0x456, 3, 0);

	rtr.flags = SOCKETCAN_HOST_F_RTR;
	echo.flags = SOCKETCAN_HOST_F_RTR;
	memset(echo.data, 0, sizeof(echo.data)); /* the kernel returns none */
	push(&rtr, 0, 0);
	expect_echo_completes(&echo, 1, 0, 0);
}

ZTEST(socketcan_txq, test_identical_frames_complete_oldest_first)
{
	const struct socketcan_host_frame hb = frame(0x701, 1, 5);

	push(&hb, 0, 0);
	push(&hb, 1, 10 * MS);
	expect_echo_completes(&hb, 11 * MS, 0, 0);
	expect_echo_completes(&hb, 12 * MS, 1, 0);
}

ZTEST(socketcan_txq, test_an_echo_of_no_frame_in_flight_is_late_and_changes_nothing)
{
	const struct socketcan_host_frame a = frame(0x701, 1, 5);
	const struct socketcan_host_frame gone = frame(0x181, 1, 1);

	zassert_equal(sc_txq_echo(&q, &gone, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	push(&a, 0, 0);
	zassert_equal(sc_txq_echo(&q, &gone, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	zassert_equal(n_lost, 0);
	zassert_equal(sc_txq_count(&q), 1);
}

ZTEST(socketcan_txq, test_a_frame_without_echo_is_released_at_the_bound_not_before)
{
	const struct socketcan_host_frame a = frame(0x701, 1, 5);

	zassert_equal(sc_txq_expire(&q, UINT64_MAX, out), 0, "an empty queue released something");
	push(&a, 0, 5 * MS);
	zassert_equal(sc_txq_expire(&q, 5 * MS + T - 1, out), 0, "released before the bound");
	zassert_equal(sc_txq_expire(&q, 5 * MS + T, out), 1, "not released at the bound");
	zassert_equal(tag_of(&out[0]), 0);
	zassert_equal(sc_txq_count(&q), 0);
}

ZTEST(socketcan_txq, test_echoes_of_other_frames_postpone_the_bound)
{
	/* A slow bus drains a queue of our frames one echo at a time: none of them is late. */
	const struct socketcan_host_frame f[3] = {frame(0x181, 1, 1), frame(0x182, 1, 2),
						  frame(0x183, 1, 3)};

	push(&f[0], 0, 0);
	push(&f[1], 1, 0);
	push(&f[2], 2, 0);
	expect_echo_completes(&f[0], 90 * MS, 0, 0);
	zassert_equal(sc_txq_expire(&q, 150 * MS, out), 0,
		      "released while echoes still come (last one 60 ms ago)");
	expect_echo_completes(&f[1], 180 * MS, 1, 0);
	/* a late echo (of a frame gone already) is news from the bus too */
	zassert_equal(sc_txq_echo(&q, &f[0], 250 * MS, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	zassert_equal(sc_txq_expire(&q, 349 * MS, out), 0);
	zassert_equal(sc_txq_expire(&q, 350 * MS, out), 1);
	zassert_equal(tag_of(&out[0]), 2);
}

ZTEST(socketcan_txq, test_expiry_releases_every_frame_past_the_bound_and_keeps_the_rest)
{
	const struct socketcan_host_frame a = frame(0x181, 1, 1);

	push(&a, 0, 0);
	push(&a, 1, 10 * MS);
	push(&a, 2, 60 * MS);
	zassert_equal(sc_txq_expire(&q, 10 * MS + T, out), 2);
	zassert_equal(tag_of(&out[0]), 0);
	zassert_equal(tag_of(&out[1]), 1);
	zassert_equal(sc_txq_count(&q), 1);
	zassert_equal(sc_txq_expire(&q, 60 * MS + T - 1, out), 0);
	zassert_equal(sc_txq_expire(&q, 60 * MS + T, out), 1);
	zassert_equal(tag_of(&out[0]), 2);
}

ZTEST(socketcan_txq, test_a_full_queue_refuses_and_the_ring_wraps)
{
	const struct socketcan_host_frame f = frame(0x100, 1, 0);

	for (int round = 0; round < 3; round++) {
		for (int i = 0; i < SIZE; i++) {
			struct socketcan_host_frame g = frame(0x100 + i, 1, (uint8_t)round);

			push(&g, i, 0);
		}
		zassert_false(sc_txq_push(&q, &f, NULL, NULL, 0), "a full queue took a frame");
		for (int i = 0; i < SIZE; i++) {
			struct socketcan_host_frame g = frame(0x100 + i, 1, (uint8_t)round);

			expect_echo_completes(&g, 1, i, 0);
		}
		push(&f, 0, 0); /* shift the ring by one each round */
		expect_echo_completes(&f, 1, 0, 0);
	}
}

ZTEST(socketcan_txq, test_a_failed_write_takes_back_the_newest_entry_only)
{
	const struct socketcan_host_frame a = frame(0x181, 1, 1);
	const struct socketcan_host_frame b = frame(0x182, 1, 2);

	push(&a, 0, 0);
	push(&b, 1, 0);
	sc_txq_drop_newest(&q);
	zassert_equal(sc_txq_count(&q), 1);
	zassert_equal(sc_txq_echo(&q, &b, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
	expect_echo_completes(&a, 1, 0, 0);
}

ZTEST(socketcan_txq, test_take_all_empties_the_queue_oldest_first)
{
	const struct socketcan_host_frame a = frame(0x181, 1, 1);

	push(&a, 0, 0);
	push(&a, 1, 0);
	push(&a, 2, 0);
	zassert_equal(sc_txq_take_all(&q, out), 3);
	for (int i = 0; i < 3; i++) {
		zassert_equal(tag_of(&out[i]), i);
	}
	zassert_equal(sc_txq_count(&q), 0);
	zassert_equal(sc_txq_echo(&q, &a, 1, &done, out, &n_lost), SC_TXQ_ECHO_LATE);
}
