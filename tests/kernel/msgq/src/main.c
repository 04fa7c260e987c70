/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_msgq: full and empty return codes, timeouts, peek, purge, attributes, and FIFO order
 * with several producers and consumers.
 */

#include <zephyr/ztest.h>

#include "test_wait.h"

#define STACK_SIZE   2048
#define MAX_MSGS     4
#define PRODUCERS    4
#define PER_PRODUCER 200

struct msg {
	uint32_t producer;
	uint32_t seq;
};

K_MSGQ_DEFINE(static_q, sizeof(uint32_t), 3, 4);

static char __aligned(4) q_buf[MAX_MSGS * sizeof(struct msg)];
static struct k_msgq q;

static K_THREAD_STACK_ARRAY_DEFINE(stacks, PRODUCERS + 2, STACK_SIZE);
static struct k_thread threads[PRODUCERS + 2];
static int thread_ret[PRODUCERS + 2];

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	k_msgq_init(&q, q_buf, sizeof(struct msg), MAX_MSGS);
	for (size_t i = 0; i < ARRAY_SIZE(thread_ret); i++) {
		thread_ret[i] = 1;
	}
}

ZTEST_SUITE(kernel_msgq, NULL, NULL, before, NULL, NULL);

static struct msg m(uint32_t producer, uint32_t seq)
{
	return (struct msg){.producer = producer, .seq = seq};
}

ZTEST(kernel_msgq, test_empty_and_full)
{
	struct msg out;

	zassert_equal(k_msgq_get(&q, &out, K_NO_WAIT), -ENOMSG, "empty + K_NO_WAIT");
	zassert_equal(k_msgq_peek(&q, &out), -ENOMSG);
	zassert_equal(k_msgq_num_used_get(&q), 0);
	zassert_equal(k_msgq_num_free_get(&q), MAX_MSGS);

	for (uint32_t i = 0; i < MAX_MSGS; i++) {
		struct msg in = m(0, i);

		zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	}
	struct msg extra = m(0, 99);

	zassert_equal(k_msgq_put(&q, &extra, K_NO_WAIT), -ENOMSG, "full + K_NO_WAIT");
	zassert_equal(k_msgq_num_used_get(&q), MAX_MSGS);
	zassert_equal(k_msgq_num_free_get(&q), 0);

	/* FIFO, across the ring buffer's wrap. */
	for (uint32_t round = 0; round < 3; round++) {
		for (uint32_t i = 0; i < MAX_MSGS; i++) {
			zassert_ok(k_msgq_get(&q, &out, K_NO_WAIT));
			zassert_equal(out.seq, round * MAX_MSGS + i);
			struct msg in = m(0, (round + 1) * MAX_MSGS + i);

			zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
		}
	}
}

ZTEST(kernel_msgq, test_timeouts)
{
	struct msg out;
	struct msg in = m(1, 1);
	int64_t start = k_uptime_get();

	zassert_equal(k_msgq_get(&q, &out, K_MSEC(40)), -EAGAIN, "empty: timeout is -EAGAIN");
	zassert_true(k_uptime_get() - start >= 40);

	for (int i = 0; i < MAX_MSGS; i++) {
		zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	}
	start = k_uptime_get();
	zassert_equal(k_msgq_put(&q, &in, K_MSEC(40)), -EAGAIN, "full: timeout is -EAGAIN");
	zassert_true(k_uptime_get() - start >= 40);
	zassert_equal(k_msgq_num_used_get(&q), MAX_MSGS, "a timed-out put adds nothing");
}

ZTEST(kernel_msgq, test_peek_and_attrs)
{
	struct k_msgq_attrs attrs;
	struct msg out;

	for (uint32_t i = 0; i < 3; i++) {
		struct msg in = m(2, i);

		zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	}
	zassert_ok(k_msgq_peek(&q, &out));
	zassert_equal(out.seq, 0);
	zassert_ok(k_msgq_peek_at(&q, &out, 2));
	zassert_equal(out.seq, 2);
	zassert_equal(k_msgq_peek_at(&q, &out, 3), -ENOMSG);
	zassert_equal(k_msgq_num_used_get(&q), 3, "peeking removes nothing");

	k_msgq_get_attrs(&q, &attrs);
	zassert_equal(attrs.msg_size, sizeof(struct msg));
	zassert_equal(attrs.max_msgs, MAX_MSGS);
	zassert_equal(attrs.used_msgs, 3);
}

static void blocked_put_entry(void *p1, void *p2, void *p3)
{
	int idx = POINTER_TO_INT(p1);
	struct msg in = m(idx, 1000);

	thread_ret[idx] = k_msgq_put(&q, &in, K_FOREVER);
}

ZTEST(kernel_msgq, test_purge_wakes_writers)
{
	struct msg in = m(3, 0);
	struct msg out;

	for (int i = 0; i < MAX_MSGS; i++) {
		zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	}
	k_thread_create(&threads[0], stacks[0], STACK_SIZE, blocked_put_entry, INT_TO_POINTER(0),
			NULL, NULL, 5, 0, K_NO_WAIT);
	/* k_msgq_cleanup() says -EBUSY once a thread waits on the queue. */
	zassert_true(WAIT_FOR(k_msgq_cleanup(&q) == -EBUSY));

	k_msgq_purge(&q);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_equal(thread_ret[0], -ENOMSG, "a purge fails waiting writers with -ENOMSG");
	zassert_equal(k_msgq_num_used_get(&q), 0);
	zassert_equal(k_msgq_get(&q, &out, K_NO_WAIT), -ENOMSG);
	zassert_ok(k_msgq_cleanup(&q));
}

ZTEST(kernel_msgq, test_blocked_writer_gets_slot)
{
	struct msg in = m(4, 0);
	struct msg out;

	for (uint32_t i = 0; i < MAX_MSGS; i++) {
		in.seq = i;
		zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	}
	k_thread_create(&threads[0], stacks[0], STACK_SIZE, blocked_put_entry, INT_TO_POINTER(0),
			NULL, NULL, 5, 0, K_NO_WAIT);
	zassert_true(WAIT_FOR(k_msgq_cleanup(&q) == -EBUSY));

	/* Taking one message lets the blocked writer append its own, behind the others. */
	zassert_ok(k_msgq_get(&q, &out, K_NO_WAIT));
	zassert_equal(out.seq, 0);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_ok(thread_ret[0]);
	zassert_equal(k_msgq_num_used_get(&q), MAX_MSGS);
	for (uint32_t i = 1; i < MAX_MSGS; i++) {
		zassert_ok(k_msgq_get(&q, &out, K_NO_WAIT));
		zassert_equal(out.seq, i);
	}
	zassert_ok(k_msgq_get(&q, &out, K_NO_WAIT));
	zassert_equal(out.seq, 1000);
}

static void blocked_get_entry(void *p1, void *p2, void *p3)
{
	struct msg out = {0};
	int idx = POINTER_TO_INT(p1);

	thread_ret[idx] = k_msgq_get(&q, &out, K_FOREVER);
	if (thread_ret[idx] == 0 && out.seq != 77) {
		thread_ret[idx] = -EIO;
	}
}

ZTEST(kernel_msgq, test_put_hands_to_waiting_reader)
{
	struct msg in = m(5, 77);

	k_thread_create(&threads[0], stacks[0], STACK_SIZE, blocked_get_entry, INT_TO_POINTER(0),
			NULL, NULL, 5, 0, K_NO_WAIT);
	zassert_true(WAIT_FOR(k_msgq_cleanup(&q) == -EBUSY));
	zassert_ok(k_msgq_put(&q, &in, K_NO_WAIT));
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_ok(thread_ret[0], "the reader got the message (or -EIO: wrong content)");
	zassert_equal(k_msgq_num_used_get(&q), 0, "handed over, not queued");
}

static void producer_entry(void *p1, void *p2, void *p3)
{
	uint32_t id = POINTER_TO_UINT(p1);

	thread_ret[id] = 0;
	for (uint32_t seq = 0; seq < PER_PRODUCER; seq++) {
		struct msg in = m(id, seq);

		if (k_msgq_put(&q, &in, K_FOREVER) != 0) {
			thread_ret[id] = -EIO;
			return;
		}
	}
}

static uint32_t next_seq[PRODUCERS];
static atomic_t consumed;
static atomic_t order_errors;
static struct k_mutex consume_lock;

static void consumer_entry(void *p1, void *p2, void *p3)
{
	struct msg out;

	for (;;) {
		/* Take and check under one lock, so the check sees the queue's order. */
		k_mutex_lock(&consume_lock, K_FOREVER);
		if (atomic_get(&consumed) == PRODUCERS * PER_PRODUCER) {
			k_mutex_unlock(&consume_lock);
			return;
		}
		if (k_msgq_get(&q, &out, K_MSEC(10)) == 0) {
			if (out.producer >= PRODUCERS || out.seq != next_seq[out.producer]) {
				atomic_inc(&order_errors);
			} else {
				next_seq[out.producer]++;
			}
			atomic_inc(&consumed);
		}
		k_mutex_unlock(&consume_lock);
	}
}

ZTEST(kernel_msgq, test_fifo_many_threads)
{
	k_mutex_init(&consume_lock);
	atomic_clear(&consumed);
	atomic_clear(&order_errors);
	memset(next_seq, 0, sizeof(next_seq));

	for (int i = 0; i < 2; i++) {
		k_thread_create(&threads[PRODUCERS + i], stacks[PRODUCERS + i], STACK_SIZE,
				consumer_entry, NULL, NULL, NULL, 4, 0, K_NO_WAIT);
	}
	for (int i = 0; i < PRODUCERS; i++) {
		k_thread_create(&threads[i], stacks[i], STACK_SIZE, producer_entry,
				UINT_TO_POINTER(i), NULL, NULL, 4 + i, 0, K_NO_WAIT);
	}
	for (int i = 0; i < PRODUCERS + 2; i++) {
		zassert_ok(k_thread_join(&threads[i], K_SECONDS(60)));
	}
	for (int i = 0; i < PRODUCERS; i++) {
		zassert_ok(thread_ret[i]);
		zassert_equal(next_seq[i], PER_PRODUCER);
	}
	zassert_equal(atomic_get(&consumed), PRODUCERS * PER_PRODUCER);
	zassert_equal(atomic_get(&order_errors), 0, "each producer's messages arrive in order");
}

ZTEST(kernel_msgq, test_static_queue)
{
	uint32_t v;

	zassert_equal(k_msgq_num_free_get(&static_q), 3);
	for (uint32_t i = 0; i < 3; i++) {
		zassert_ok(k_msgq_put(&static_q, &i, K_NO_WAIT));
	}
	zassert_equal(k_msgq_put(&static_q, &v, K_NO_WAIT), -ENOMSG);
	for (uint32_t i = 0; i < 3; i++) {
		zassert_ok(k_msgq_get(&static_q, &v, K_NO_WAIT));
		zassert_equal(v, i);
	}
}
