/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The line thread on the virtual bus in real time (controller 0: the line, controller 1: a
 * raw peer on the same bus).
 *
 * - A frame received before a timer's deadline is handled before that timer, even when the
 *   thread gets to both only after the deadline. The thread is held up deterministically in
 *   the application's event callback (a controller state change) while the deadline passes
 *   with the frame already queued.
 * - co_line_stop() returns only once no TX completion of the line can run any more: every
 *   frame the line handed to the driver has ended on the bus by then, and the line can be
 *   re-initialised in place at once (the TSan variant reports a completion that still runs).
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/printk.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>
#include <canopen/line.h>

#define BUS       0
#define RX_ID     0x123U
#define TIMER_US  20000U
#define WAIT      K_SECONDS(2)
#define ROUNDS    30
#define PER_ROUND 12

static struct co_line line;
static K_THREAD_STACK_DEFINE(stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_MUTEX_DEFINE(owner);
static const struct device *dev_line;
static const struct device *dev_peer;

static void *setup(void)
{
	dev_line = device_get_binding("can_virtual0");
	dev_peer = device_get_binding("can_virtual1");
	zassert_not_null(dev_line);
	zassert_not_null(dev_peer);
	zassert_ok(can_start(dev_peer));
	return NULL;
}

/* --- A frame and a timer both due ------------------------------------------------------- */

static K_SEM_DEFINE(in_report, 0, 1);
static K_SEM_DEFINE(release, 0, 1);
static K_SEM_DEFINE(handled, 0, 2);
static atomic_t hold_next_report;
static char order[2];
static int n_order;
static uint64_t frame_time_us;

/* Holds the line thread in its report of the state change, as a slow host would. */
static void event_cb(struct co_line *l, enum co_line_event event, int arg, void *user_data)
{
	if (event == CO_LINE_EV_CAN_STATE && atomic_cas(&hold_next_report, 1, 0)) {
		k_sem_give(&in_report);
		(void)k_sem_take(&release, WAIT);
	}
}

static void on_frame(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	if (n_order < (int)sizeof(order)) {
		order[n_order++] = 'F';
	}
	frame_time_us = now_us;
	k_sem_give(&handled);
}

static void on_timer(struct co_timer *timer, uint64_t now_us)
{
	if (n_order < (int)sizeof(order)) {
		order[n_order++] = 'T';
	}
	k_sem_give(&handled);
}

static void peer_sent(const struct device *dev, int error, void *user_data)
{
	zassert_ok(error);
}

ZTEST(co_line_thread, test_frame_received_before_a_due_deadline_runs_before_its_timer)
{
	const struct can_frame frame = {.id = RX_ID, .dlc = 1, .data = {0x5A}};
	struct co_rx rx;
	struct co_timer timer;
	uint64_t deadline;

	zassert_ok(co_line_init(&line, "order", dev_line));
	co_line_set_event_cb(&line, event_cb, NULL);
	co_rx_init(&rx, RX_ID, on_frame, &owner, NULL);
	zassert_ok(co_rx_register(&line, &rx));
	co_timer_init(&timer, on_timer, &owner, NULL);
	zassert_ok(co_line_start(&line, stack, K_THREAD_STACK_SIZEOF(stack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));

	deadline = co_line_now() + TIMER_US;
	co_timer_start(&line, &timer, deadline);
	/* The line thread wakes for the state change and stays in its report. */
	atomic_set(&hold_next_report, 1);
	zassert_ok(can_virtual_set_state(dev_line, CAN_STATE_ERROR_WARNING));
	zassert_ok(k_sem_take(&in_report, WAIT), "the line thread did not report the state");
	zassert_true(co_line_now() < deadline, "the host was too slow to set the case up");

	/* The frame arrives before the deadline and waits in the line's queue past it. */
	zassert_ok(can_send(dev_peer, &frame, K_FOREVER, peer_sent, NULL));
	for (int i = 0; i < 2000 && k_msgq_num_used_get(&line.rxq) == 0U; i++) {
		k_msleep(1);
	}
	zassert_true(k_msgq_num_used_get(&line.rxq) > 0U, "the frame did not reach the line");
	while (co_line_now() <= deadline + 2000U) {
		k_msleep(1);
	}
	zassert_equal(n_order, 0, "nothing may run while the thread is held");

	k_sem_give(&release);
	zassert_ok(k_sem_take(&handled, WAIT));
	zassert_ok(k_sem_take(&handled, WAIT));
	zassert_true(frame_time_us < deadline, "the frame was received %llu us before the deadline",
		     (unsigned long long)(deadline - frame_time_us));
	zassert_equal(order[0], 'F', "the timer ran before a frame received before its deadline");
	zassert_equal(order[1], 'T');

	zassert_ok(co_line_stop(&line));
	zassert_ok(can_virtual_set_state(dev_line, CAN_STATE_ERROR_ACTIVE));
}

/* --- Stop while frames are in flight, re-initialise in place ------------------------------ */

ZTEST(co_line_thread, test_stop_waits_for_tx_completions_and_the_line_reinits_in_place)
{
	struct can_virtual_bus_stats before, after;
	struct co_line_stats st;
	struct can_frame frame = {.id = 0x181, .dlc = 8};
	uint32_t handed = 0U, ended = 0U;
	uint64_t worst_stop_us = 0U;

	/* Frames take bus time (about 0.25 ms each at 500 kbit/s): some are in flight at stop. */
	zassert_ok(can_virtual_bus_set_bit_timing(BUS, true));
	for (int r = 0; r < ROUNDS; r++) {
		uint64_t t0;

		/* In place: whatever a late completion would touch is overwritten here. */
		zassert_ok(co_line_init(&line, "reinit", dev_line));
		zassert_ok(co_line_start(&line, stack, K_THREAD_STACK_SIZEOF(stack),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
		zassert_ok(can_virtual_bus_get_stats(BUS, &before));
		for (int i = 0; i < PER_ROUND; i++) {
			frame.data[0] = (uint8_t)r;
			frame.data[1] = (uint8_t)i;
			zassert_ok(co_line_send(&line, &frame));
		}
		/* Vary the point of the stop across the burst. */
		k_busy_wait((uint32_t)(r % 6) * 200U);

		t0 = co_line_now();
		zassert_ok(co_line_stop(&line));
		worst_stop_us = MAX(worst_stop_us, co_line_now() - t0);
		zassert_ok(can_virtual_bus_get_stats(BUS, &after));
		co_line_get_stats(&line, &st);
		zassert_equal(after.frames - before.frames, st.tx_frames,
			      "round %d: %u frames handed to the driver, %u ended before the stop "
			      "returned",
			      r, st.tx_frames, after.frames - before.frames);
		handed += st.tx_frames;
		ended += after.frames - before.frames;
	}
	zassert_ok(can_virtual_bus_set_bit_timing(BUS, false));
	zassert_true(handed > 0U);
	printk("line_thread: %d stops, %u frames in the driver, all %u ended before the stop "
	       "returned; longest stop %llu us\n",
	       ROUNDS, handed, ended, (unsigned long long)worst_stop_us);
}

/* --- Stop while the controller changes state ------------------------------------------- */

#define TOGGLE_ROUNDS 200

static K_THREAD_STACK_DEFINE(toggler_stack, 4096);
static struct k_thread toggler;
static atomic_t toggling;

static void toggle(void *p1, void *p2, void *p3)
{
	bool warn = false;

	while (atomic_get(&toggling) != 0) {
		warn = !warn;
		(void)can_virtual_set_state(dev_line, warn ? CAN_STATE_ERROR_WARNING
							   : CAN_STATE_ERROR_ACTIVE);
		k_yield();
	}
}

ZTEST(co_line_thread, test_no_state_callback_runs_after_stop)
{
	int late = 0;

	atomic_set(&toggling, 1);
	k_thread_create(&toggler, toggler_stack, K_THREAD_STACK_SIZEOF(toggler_stack), toggle, NULL,
			NULL, NULL, K_PRIO_PREEMPT(5), 0, K_NO_WAIT);
	for (int r = 0; r < TOGGLE_ROUNDS; r++) {
		zassert_ok(co_line_init(&line, "state", dev_line));
		zassert_ok(co_line_start(&line, stack, K_THREAD_STACK_SIZEOF(stack),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
		k_busy_wait((uint32_t)(r % 5) * 100U);
		zassert_ok(co_line_stop(&line));
		/*
		 * The line's state callback writes can_state: a plain write here races with a late
		 * one (TSan reports it), and a late one overwrites the mark.
		 */
		line.can_state = -1;
		k_busy_wait(200U);
		late += line.can_state != -1 ? 1 : 0;
	}
	atomic_set(&toggling, 0);
	zassert_ok(k_thread_join(&toggler, K_SECONDS(5)));
	zassert_ok(can_virtual_set_state(dev_line, CAN_STATE_ERROR_ACTIVE));
	zassert_equal(late, 0, "%d state callbacks ran after co_line_stop() returned", late);
}

ZTEST_SUITE(co_line_thread, NULL, setup, NULL, NULL, NULL);
