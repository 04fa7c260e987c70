/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The line's paths that take no lock, raced by real threads (the TSan variant checks the
 * memory model): receivers looked up while others are registered, moved and removed; frames
 * sent from several threads while the driver pushes back and the queue drains.
 *
 * Simulation lines: a test thread plays the line thread (co_line_rx(), co_line_process()),
 * other threads change the table or send at the same time.
 */

#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>

#define FRAMES     20000U
#define MOVERS     3
#define SENDERS    2
#define SENT_EACH  3000U
#define STABLE_ID  0x181U
#define MASKED_ID  0x705U
#define MOVE_BASE  0x201U
#define MOVE_SPAN  8U
#define STACK_SIZE 4096

static struct co_line line;
static atomic_t stop;

static struct co_rx stable_a, stable_b, masked, movers[MOVERS], masked_mover;
static atomic_t got_a, got_b, got_masked, got_movers;

static void count_a(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	atomic_inc(&got_a);
}

static void count_b(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	/* Registered after A on the same id: always called after it. */
	zassert_equal(atomic_get(&got_b) + 1, atomic_get(&got_a), "order of receivers");
	atomic_inc(&got_b);
}

static void count_masked(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	atomic_inc(&got_masked);
}

static void count_mover(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	atomic_inc(&got_movers);
}

static int null_sink(struct co_line *l, const struct can_frame *frame, void *user_data)
{
	return 0;
}

static K_THREAD_STACK_ARRAY_DEFINE(mover_stacks, MOVERS + 1, STACK_SIZE);
static struct k_thread mover_threads[MOVERS + 1];

/* Moves a receiver between ids, and now and then out of the table and back. */
static void mover(void *p1, void *p2, void *p3)
{
	struct co_rx *rx = p1;
	uint32_t n = (uint32_t)(uintptr_t)p2;

	while (!atomic_get(&stop)) {
		n = n * 1103515245U + 12345U;
		if ((n >> 16) % 8U == 0U) {
			co_rx_unregister(rx);
		} else {
			(void)co_rx_set_id(&line, rx, MOVE_BASE + (n >> 16) % MOVE_SPAN);
		}
		k_yield();
	}
}

/* A masked receiver joining and leaving the list of masked ones. */
static void masked_churn(void *p1, void *p2, void *p3)
{
	while (!atomic_get(&stop)) {
		(void)co_rx_register(&line, &masked_mover);
		k_yield();
		co_rx_unregister(&masked_mover);
		k_yield();
	}
}

ZTEST(co_line_races, test_lookups_while_receivers_move)
{
	struct can_frame f = {.dlc = 0};
	struct co_line_stats st;
	uint32_t sent_movers = 0;

	co_line_init_sim(&line, "races", null_sink, NULL);
	atomic_set(&stop, 0);
	co_rx_init(&stable_a, STABLE_ID, count_a, NULL, NULL);
	co_rx_init(&stable_b, STABLE_ID, count_b, NULL, NULL);
	co_rx_init(&masked, MASKED_ID & 0x780U, count_masked, NULL, NULL);
	masked.mask = 0x780U;
	co_rx_init(&masked_mover, 0x700U, count_mover, NULL, NULL);
	masked_mover.mask = 0x780U;
	zassert_ok(co_rx_register(&line, &stable_a));
	zassert_ok(co_rx_register(&line, &stable_b));
	zassert_ok(co_rx_register(&line, &masked));
	for (int i = 0; i < MOVERS; i++) {
		co_rx_init(&movers[i], MOVE_BASE, count_mover, NULL, NULL);
		k_thread_create(&mover_threads[i], mover_stacks[i],
				K_THREAD_STACK_SIZEOF(mover_stacks[i]), mover, &movers[i],
				(void *)(uintptr_t)(i + 1), NULL, K_PRIO_PREEMPT(5), 0, K_NO_WAIT);
	}
	k_thread_create(&mover_threads[MOVERS], mover_stacks[MOVERS],
			K_THREAD_STACK_SIZEOF(mover_stacks[MOVERS]), masked_churn, NULL, NULL, NULL,
			K_PRIO_PREEMPT(5), 0, K_NO_WAIT);

	/* This thread is the line's dispatcher. */
	for (uint32_t i = 0; i < FRAMES; i++) {
		switch (i % 4U) {
		case 0:
		case 1:
			f.id = STABLE_ID;
			break;
		case 2:
			f.id = MASKED_ID;
			break;
		default:
			f.id = MOVE_BASE + i % MOVE_SPAN;
			sent_movers++;
			break;
		}
		(void)co_line_rx(&line, &f, i);
		if (i % 64U == 0U) {
			k_yield();
		}
	}
	atomic_set(&stop, 1);
	for (int i = 0; i <= MOVERS; i++) {
		zassert_ok(k_thread_join(&mover_threads[i], K_SECONDS(10)));
	}

	/* Receivers that never moved got every frame of theirs, once, in order. */
	zassert_equal(atomic_get(&got_a), FRAMES / 2U);
	zassert_equal(atomic_get(&got_b), FRAMES / 2U);
	/* The churning masked receiver matches 700h-77Fh too; the steady one every time. */
	zassert_equal(atomic_get(&got_masked), FRAMES / 4U);
	/* Moving receivers get at most one copy each of the frames on their ids. */
	zassert_true(atomic_get(&got_movers) <= (atomic_val_t)(sent_movers * MOVERS + FRAMES / 4U));
	co_line_get_stats(&line, &st);
	zassert_equal(st.rx_frames, FRAMES);
	for (int i = 0; i < MOVERS; i++) {
		co_rx_unregister(&movers[i]);
	}
}

/* --- Sends without the TX lock while the queue fills and drains --------------------------- */

struct tx_record {
	struct k_mutex lock;
	uint32_t n;
	uint32_t next_seq[SENDERS];
	uint32_t out_of_order;
	uint32_t pushes;
	uint32_t calls;
};

static struct tx_record rec;

/* A controller that takes about two frames in three and pushes back otherwise. */
static int busy_sink(struct co_line *l, const struct can_frame *frame, void *user_data)
{
	int ret = 0;

	k_mutex_lock(&rec.lock, K_FOREVER);
	rec.calls++;
	if (rec.calls % 3U == 0U) {
		rec.pushes++;
		ret = -EAGAIN;
	} else {
		uint32_t sender = frame->data[0];
		uint32_t seq = sys_get_le32(&frame->data[1]);

		if (seq != rec.next_seq[sender]) {
			rec.out_of_order++;
		}
		rec.next_seq[sender] = seq + 1U;
		rec.n++;
	}
	k_mutex_unlock(&rec.lock);
	return ret;
}

static K_THREAD_STACK_ARRAY_DEFINE(sender_stacks, SENDERS, STACK_SIZE);
static struct k_thread sender_threads[SENDERS];

static void sender(void *p1, void *p2, void *p3)
{
	uint8_t who = (uint8_t)(uintptr_t)p1;
	struct can_frame f = {.id = 0x300U + who, .dlc = 5, .data = {who}};

	for (uint32_t seq = 0; seq < SENT_EACH;) {
		sys_put_le32(seq, &f.data[1]);
		if (co_line_send(&line, &f) == 0) {
			seq++;
		} else {
			/* Queue full: let the drain catch up, then send the same frame again. */
			k_yield();
		}
	}
}

ZTEST(co_line_races, test_sends_from_threads_keep_each_senders_order)
{
	struct co_line_stats st;
	uint64_t t = 0;

	memset(&rec, 0, sizeof(rec));
	k_mutex_init(&rec.lock);
	co_line_init_sim(&line, "tx", busy_sink, NULL);
	for (int i = 0; i < SENDERS; i++) {
		k_thread_create(&sender_threads[i], sender_stacks[i],
				K_THREAD_STACK_SIZEOF(sender_stacks[i]), sender,
				(void *)(uintptr_t)i, NULL, NULL, K_PRIO_PREEMPT(5), 0, K_NO_WAIT);
	}
	/* This thread drains the queue as the line thread does after a TX completion. */
	for (int joined = 0; joined < SENDERS;) {
		(void)co_line_process(&line, t++);
		if (k_thread_join(&sender_threads[joined], K_NO_WAIT) == 0) {
			joined++;
		}
		k_yield();
	}
	while (co_line_tx_space(&line) < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE) {
		(void)co_line_process(&line, t++);
	}
	k_mutex_lock(&rec.lock, K_FOREVER);
	zassert_equal(rec.n, SENDERS * SENT_EACH, "every frame went out once");
	zassert_equal(rec.out_of_order, 0, "each sender's frames in its order");
	zassert_true(rec.pushes > 0U, "the controller pushed back");
	k_mutex_unlock(&rec.lock);
	co_line_get_stats(&line, &st);
	zassert_equal(st.tx_frames, SENDERS * SENT_EACH);
	zassert_true(st.tx_queued > 0U, "frames waited in the queue");
}

ZTEST_SUITE(co_line_races, NULL, NULL, NULL, NULL, NULL);
