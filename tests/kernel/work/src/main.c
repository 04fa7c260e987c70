/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Work items, delayable work items and work queues: Zephyr's return values for every state
 * (idle, queued, running, cancelling, scheduled) and the synchronous calls.
 *
 * A "gated" handler reports that it started and then waits for the test to open its gate,
 * so the test can act while the item is known to be running.
 */

#include <zephyr/ztest.h>

#include "test_wait.h"

#define STACK_SIZE 2048
#define QUEUE_PRIO 3

static K_THREAD_STACK_DEFINE(queue_stack, STACK_SIZE);
static struct k_work_q queue;
static K_THREAD_STACK_DEFINE(helper_stack, STACK_SIZE);
static struct k_thread helper_thread;

static K_SEM_DEFINE(started, 0, 100);
static K_SEM_DEFINE(gate, 0, 100);
static atomic_t runs;
static atomic_t other_runs;
static k_tid_t handler_thread;

static void gated_handler(struct k_work *work)
{
	ARG_UNUSED(work);
	handler_thread = k_current_get();
	k_sem_give(&started);
	(void)k_sem_take(&gate, K_FOREVER);
	atomic_inc(&runs);
}

static void counting_handler(struct k_work *work)
{
	ARG_UNUSED(work);
	handler_thread = k_current_get();
	atomic_inc(&other_runs);
	k_sem_give(&started);
}

static K_WORK_DEFINE(static_work, counting_handler);
static K_WORK_DELAYABLE_DEFINE(static_dwork, counting_handler);
static struct k_work work;
static struct k_work other;
static struct k_work_delayable dwork;

static void *setup(void)
{
	const struct k_work_queue_config cfg = {.name = "test_wq"};

	k_work_queue_init(&queue);
	k_work_queue_start(&queue, queue_stack, K_THREAD_STACK_SIZEOF(queue_stack), QUEUE_PRIO,
			   &cfg);

	return NULL;
}

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	k_work_init(&work, gated_handler);
	k_work_init(&other, counting_handler);
	k_work_init_delayable(&dwork, counting_handler);
	k_sem_reset(&started);
	k_sem_reset(&gate);
	atomic_clear(&runs);
	atomic_clear(&other_runs);
	handler_thread = NULL;
}

static void after(void *fixture)
{
	struct k_work_sync sync;

	ARG_UNUSED(fixture);
	/* Leave nothing behind for the next test, even after a failure. */
	k_sem_give(&gate);
	k_sem_give(&gate);
	(void)k_work_cancel_sync(&work, &sync);
	(void)k_work_cancel_sync(&other, &sync);
	(void)k_work_cancel_delayable_sync(&dwork, &sync);
	(void)k_work_queue_drain(&queue, false);
}

static void teardown(void *fixture)
{
	ARG_UNUSED(fixture);
	zassert_true(k_work_queue_drain(&queue, true) >= 0);
	zassert_ok(k_work_queue_stop(&queue, K_SECONDS(10)));
}

ZTEST_SUITE(kernel_work, NULL, setup, before, after, teardown);

ZTEST(kernel_work, test_system_queue)
{
	zassert_equal(k_work_submit(&static_work), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal_ptr(handler_thread, k_work_queue_thread_get(&k_sys_work_q));
	zassert_str_equal(k_thread_name_get(handler_thread), "sysworkq");
}

ZTEST(kernel_work, test_own_queue_thread)
{
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal_ptr(handler_thread, k_work_queue_thread_get(&queue));
	zassert_str_equal(k_thread_name_get(handler_thread), "test_wq");
}

ZTEST(kernel_work, test_submit_states)
{
	zassert_equal(k_work_busy_get(&work), 0);
	zassert_equal(k_work_submit_to_queue(&queue, &work), 1, "idle: queued");
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal(k_work_busy_get(&work), K_WORK_RUNNING);

	zassert_equal(k_work_submit_to_queue(&queue, &work), 2, "running: queued again");
	zassert_equal(k_work_busy_get(&work), K_WORK_RUNNING | K_WORK_QUEUED);
	zassert_equal(k_work_submit_to_queue(&queue, &work), 0, "already queued");
	/* Without a queue it goes back to the one it last used. */
	zassert_equal(k_work_submit_to_queue(NULL, &work), 0);

	k_sem_give(&gate);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)), "ran a second time");
	k_sem_give(&gate);
	zassert_true(WAIT_FOR(k_work_busy_get(&work) == 0));
	zassert_equal(atomic_get(&runs), 2);
	zassert_false(k_work_is_pending(&work));
}

ZTEST(kernel_work, test_submit_errors)
{
	struct k_work_q stopped;
	struct k_work never;

	k_work_init(&never, counting_handler);
	zassert_equal(k_work_submit_to_queue(NULL, &never), -EINVAL, "no queue, never ran");

	k_work_queue_init(&stopped);
	zassert_equal(k_work_submit_to_queue(&stopped, &never), -ENODEV, "queue not started");
	zassert_equal(k_work_busy_get(&never), 0);
}

ZTEST(kernel_work, test_cancel_queued)
{
	zassert_equal(k_work_cancel(&other), 0, "idle: nothing to cancel");

	/* work occupies the queue, so other stays queued behind it. */
	zassert_equal(k_work_submit_to_queue(&queue, &work), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1);
	zassert_equal(k_work_busy_get(&other), K_WORK_QUEUED);
	zassert_equal(k_work_cancel(&other), 0, "a queued item is simply removed");
	zassert_equal(k_work_busy_get(&other), 0);

	k_sem_give(&gate);
	zassert_true(WAIT_FOR(k_work_busy_get(&work) == 0));
	zassert_true(k_work_queue_drain(&queue, false) >= 0);
	zassert_equal(atomic_get(&other_runs), 0, "the cancelled item never ran");
}

static bool helper_result;
static int64_t helper_done_ms;
static long helper_value;

static void cancel_sync_entry(void *p1, void *p2, void *p3)
{
	struct k_work_sync sync;

	helper_result = k_work_cancel_sync(&work, &sync);
	helper_done_ms = k_uptime_get();
}

ZTEST(kernel_work, test_cancel_running)
{
	struct k_work_sync sync;
	int64_t gate_opened;

	zassert_equal(k_work_submit_to_queue(&queue, &work), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));

	zassert_equal(k_work_cancel(&work), K_WORK_RUNNING | K_WORK_CANCELING,
		      "a running handler cannot be stopped: it is marked cancelling");
	zassert_equal(k_work_submit_to_queue(&queue, &work), -EBUSY, "no submit while cancelling");

	k_thread_create(&helper_thread, helper_stack, STACK_SIZE, cancel_sync_entry, NULL, NULL,
			NULL, 5, 0, K_NO_WAIT);
	/* The handler cannot end before the gate opens, nor can the helper's cancel_sync. */
	zassert_equal(k_thread_join(&helper_thread, K_MSEC(30)), -EAGAIN);

	gate_opened = k_uptime_get();
	k_sem_give(&gate);
	zassert_ok(k_thread_join(&helper_thread, K_SECONDS(10)));
	zassert_true(helper_result, "the item was pending when cancel_sync was called");
	zassert_true(helper_done_ms >= gate_opened);
	zassert_equal(atomic_get(&runs), 1, "cancel_sync returned after the handler did");
	zassert_equal(k_work_busy_get(&work), 0);

	zassert_false(k_work_cancel_sync(&work, &sync), "idle: nothing was pending");
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1, "submits work again");
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
}

static void flush_entry(void *p1, void *p2, void *p3)
{
	struct k_work_sync sync;

	helper_result = k_work_flush(&other, &sync);
	/* The flush ends only after the flushed item ran. */
	helper_value = atomic_get(&other_runs);
}

ZTEST(kernel_work, test_flush)
{
	struct k_work_sync sync;

	zassert_false(k_work_flush(&other, &sync), "idle: nothing to wait for");

	zassert_equal(k_work_submit_to_queue(&queue, &work), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1);

	helper_value = -1;
	k_thread_create(&helper_thread, helper_stack, STACK_SIZE, flush_entry, NULL, NULL, NULL, 5,
			0, K_NO_WAIT);
	zassert_equal(k_thread_join(&helper_thread, K_MSEC(30)), -EAGAIN, "flush must wait");
	k_sem_give(&gate);
	zassert_ok(k_thread_join(&helper_thread, K_SECONDS(10)));
	zassert_true(helper_result);
	zassert_equal(helper_value, 1, "the item had run when the flush returned");
}

ZTEST(kernel_work, test_schedule_vs_reschedule)
{
	k_ticks_t t200 = k_ms_to_ticks_ceil32(200);
	k_ticks_t left;

	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_MSEC(200)), 1);
	zassert_equal(k_work_delayable_busy_get(&dwork), K_WORK_DELAYED);
	left = k_work_delayable_remaining_get(&dwork);
	zassert_true(left > 0 && left <= t200, "remaining %lld", (long long)left);

	/* schedule keeps an earlier schedule... */
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_SECONDS(100)), 0);
	zassert_true(k_work_delayable_remaining_get(&dwork) <= t200);
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_NO_WAIT), 0,
		      "even K_NO_WAIT does not override a schedule");

	/* ...reschedule replaces it. */
	zassert_equal(k_work_reschedule_for_queue(&queue, &dwork, K_SECONDS(100)), 1);
	left = k_work_delayable_remaining_get(&dwork);
	zassert_true(left > k_ms_to_ticks_ceil32(50000), "remaining %lld", (long long)left);
	zassert_true(k_work_delayable_expires_get(&dwork) >= k_uptime_ticks() + left - 1);

	zassert_equal(k_work_cancel_delayable(&dwork), 0, "a scheduled item just stops");
	zassert_equal(k_work_delayable_busy_get(&dwork), 0);
	zassert_equal(k_work_delayable_remaining_get(&dwork), 0);
	zassert_false(k_work_delayable_is_pending(&dwork));
	zassert_equal(atomic_get(&other_runs), 0);
}

ZTEST(kernel_work, test_schedule_no_wait_and_queued)
{
	/* Keep the queue busy so the item stays queued. */
	zassert_equal(k_work_submit_to_queue(&queue, &work), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));

	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_NO_WAIT), 1, "queued at once");
	zassert_equal(k_work_delayable_busy_get(&dwork), K_WORK_QUEUED);
	zassert_equal(k_work_reschedule_for_queue(&queue, &dwork, K_NO_WAIT), 0, "already queued");
	/* A queued item that is rescheduled stays queued and also gets a timer. */
	zassert_equal(k_work_reschedule_for_queue(&queue, &dwork, K_SECONDS(100)), 1);
	zassert_equal(k_work_delayable_busy_get(&dwork), K_WORK_QUEUED | K_WORK_DELAYED);
	zassert_equal(k_work_cancel_delayable(&dwork), 0, "both the timer and the queue entry go");

	k_sem_give(&gate);
	zassert_true(k_work_queue_drain(&queue, false) >= 0);
	zassert_equal(atomic_get(&other_runs), 0);
}

ZTEST(kernel_work, test_delayable_runs_after_delay)
{
	int64_t start = k_uptime_get();

	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_MSEC(50)), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_true(k_uptime_get() - start >= 50, "ran before its delay");
	zassert_equal_ptr(handler_thread, k_work_queue_thread_get(&queue));
	zassert_true(WAIT_FOR(k_work_delayable_busy_get(&dwork) == 0));
}

ZTEST(kernel_work, test_flush_delayable)
{
	struct k_work_sync sync;
	int64_t start = k_uptime_get();

	zassert_false(k_work_flush_delayable(&dwork, &sync), "idle");
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_SECONDS(100)), 1);
	zassert_true(k_work_flush_delayable(&dwork, &sync), "submitted now and waited for");
	zassert_equal(atomic_get(&other_runs), 1);
	zassert_true(k_uptime_get() - start < 50000, "did not wait for the delay");
	zassert_equal(k_work_delayable_busy_get(&dwork), 0);
}

ZTEST(kernel_work, test_cancel_delayable_sync)
{
	struct k_work_sync sync;

	zassert_false(k_work_cancel_delayable_sync(&dwork, &sync));
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_SECONDS(100)), 1);
	zassert_true(k_work_cancel_delayable_sync(&dwork, &sync), "it was scheduled");
	zassert_equal(k_work_delayable_busy_get(&dwork), 0);
	zassert_equal(atomic_get(&other_runs), 0);
}

ZTEST(kernel_work, test_schedule_running_item)
{
	k_work_init_delayable(&dwork, gated_handler);
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_NO_WAIT), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal(k_work_delayable_busy_get(&dwork), K_WORK_RUNNING);

	/* A running item may be scheduled again: with K_NO_WAIT it is queued behind itself. */
	zassert_equal(k_work_schedule_for_queue(&queue, &dwork, K_NO_WAIT), 2);
	zassert_equal(k_work_delayable_busy_get(&dwork), K_WORK_RUNNING | K_WORK_QUEUED);
	k_sem_give(&gate);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	k_sem_give(&gate);
	zassert_true(WAIT_FOR(k_work_delayable_busy_get(&dwork) == 0));
	zassert_equal(atomic_get(&runs), 2);
}

ZTEST(kernel_work, test_static_items)
{
	struct k_work_sync sync;

	zassert_equal(k_work_schedule(&static_dwork, K_MSEC(1)), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_equal_ptr(handler_thread, k_work_queue_thread_get(&k_sys_work_q));
	zassert_true(k_work_reschedule(&static_dwork, K_NO_WAIT) >= 0);
	(void)k_work_flush_delayable(&static_dwork, &sync);
	(void)k_work_flush(&static_work, &sync);
}

ZTEST(kernel_work, test_drain_plug_unplug)
{
	zassert_equal(k_work_queue_unplug(&queue), -EALREADY, "not plugged");
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1);
	zassert_equal(k_work_queue_drain(&queue, true), 1, "drain waits, plug refuses new work");
	zassert_equal(atomic_get(&other_runs), 1, "drained: the item ran");
	zassert_equal(k_work_submit_to_queue(&queue, &other), -EBUSY, "plugged");
	zassert_ok(k_work_queue_unplug(&queue));
	zassert_equal(k_work_queue_unplug(&queue), -EALREADY);
	zassert_equal(k_work_submit_to_queue(&queue, &other), 1);
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
	zassert_ok(k_sem_take(&started, K_SECONDS(10)));
}

ZTEST(kernel_work, test_stop_and_restart)
{
	static K_THREAD_STACK_DEFINE(q2_stack, STACK_SIZE);
	static struct k_work_q q2;

	k_work_queue_init(&q2);
	zassert_equal(k_work_queue_stop(&q2, K_NO_WAIT), -EALREADY, "never started");
	k_work_queue_start(&q2, q2_stack, K_THREAD_STACK_SIZEOF(q2_stack), QUEUE_PRIO, NULL);
	zassert_equal(k_work_queue_stop(&q2, K_SECONDS(1)), -EBUSY, "must be plugged first");

	zassert_equal(k_work_submit_to_queue(&q2, &other), 1);
	zassert_true(k_work_queue_drain(&q2, true) >= 0);
	zassert_ok(k_work_queue_stop(&q2, K_SECONDS(10)));
	zassert_equal(k_work_submit_to_queue(&q2, &other), -ENODEV, "stopped");
	zassert_equal(k_work_queue_stop(&q2, K_SECONDS(1)), -EALREADY);

	/* A stopped queue can be started again. */
	k_work_queue_start(&q2, q2_stack, K_THREAD_STACK_SIZEOF(q2_stack), QUEUE_PRIO, NULL);
	zassert_equal(k_work_submit_to_queue(&q2, &other), 1);
	zassert_true(k_work_queue_drain(&q2, true) >= 0);
	zassert_equal(atomic_get(&other_runs), 2);
	zassert_ok(k_work_queue_stop(&q2, K_SECONDS(10)));
}
