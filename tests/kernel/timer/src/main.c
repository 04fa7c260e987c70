/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_timer: one-shot and periodic expiry, status counting, k_timer_status_sync(), expiry and
 * stop functions, restart and stop semantics.
 *
 * Timing bounds are one-sided where the kernel guarantees them (never early) and generous
 * where the host decides (late); deadlines are checked exactly through
 * k_timer_expires_ticks(), which does not depend on scheduling.
 */

#include <zephyr/ztest.h>

#include "test_wait.h"

#define PERIOD_MS 10

static atomic_t expiries;
static atomic_t stops;
static atomic_t in_isr_failures;
static struct k_timer timer;

static void expiry_fn(struct k_timer *t)
{
	if (!k_is_in_isr()) {
		atomic_inc(&in_isr_failures);
	}
	atomic_inc(&expiries);
}

static void stop_fn(struct k_timer *t)
{
	atomic_inc(&stops);
}

static int static_expiries;
static void static_expiry(struct k_timer *t)
{
	static_expiries++;
}
K_TIMER_DEFINE(static_timer, static_expiry, NULL);

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	k_timer_init(&timer, expiry_fn, stop_fn);
	atomic_clear(&expiries);
	atomic_clear(&stops);
	atomic_clear(&in_isr_failures);
}

static void after(void *fixture)
{
	ARG_UNUSED(fixture);
	k_timer_stop(&timer);
}

ZTEST_SUITE(kernel_timer, NULL, NULL, before, after, NULL);

ZTEST(kernel_timer, test_one_shot)
{
	int64_t start = k_uptime_get();

	k_timer_start(&timer, K_MSEC(30), K_NO_WAIT);
	zassert_equal(k_timer_status_sync(&timer), 1);
	zassert_true(k_uptime_get() - start >= 30, "expired early");
	zassert_equal(atomic_get(&expiries), 1);
	zassert_equal(atomic_get(&in_isr_failures), 0, "expiry functions run in ISR context");

	/* A one-shot timer is stopped after expiring: no stop function, no more expiries. */
	zassert_equal(k_timer_remaining_ticks(&timer), 0);
	zassert_equal(k_timer_status_sync(&timer), 0, "stopped timer: returns at once");
	k_timer_stop(&timer);
	zassert_equal(atomic_get(&stops), 0, "stop function only for a running timer");
}

ZTEST(kernel_timer, test_periodic_counting)
{
	uint32_t total = 0;
	int64_t start = k_uptime_get();
	k_ticks_t period = k_ms_to_ticks_ceil32(PERIOD_MS);
	k_ticks_t first;

	k_timer_start(&timer, K_MSEC(PERIOD_MS), K_MSEC(PERIOD_MS));
	first = k_timer_expires_ticks(&timer);
	while (total < 10) {
		total += k_timer_status_sync(&timer);
	}
	/* The n-th expiry cannot come before n periods. */
	zassert_true(k_uptime_get() - start >= 10 * PERIOD_MS, "too fast");
	zassert_true(k_uptime_get() - start < 10 * PERIOD_MS + TEST_WAIT_MS, "far too slow");

	/* Deadlines advance by exactly one period per expiry: no drift. */
	k_ticks_t next = k_timer_expires_ticks(&timer);
	uint32_t seen = total + k_timer_status_get(&timer);

	zassert_equal((next - first) % period, 0, "deadline not on the period grid");
	zassert_true((next - first) / period >= (k_ticks_t)seen,
		     "deadline %lld periods ahead after %u expiries",
		     (long long)((next - first) / period), seen);

	k_timer_stop(&timer);
	zassert_equal(atomic_get(&stops), 1);
	uint32_t after_stop = atomic_get(&expiries);

	k_msleep(3 * PERIOD_MS);
	zassert_equal(atomic_get(&expiries), after_stop, "expired after k_timer_stop()");
}

ZTEST(kernel_timer, test_status_get_resets)
{
	k_timer_start(&timer, K_MSEC(1), K_MSEC(1));
	zassert_true(WAIT_FOR(atomic_get(&expiries) >= 3));
	k_timer_stop(&timer);
	zassert_equal(k_timer_status_get(&timer), atomic_get(&expiries),
		      "status counts every expiry since the start");
	zassert_equal(k_timer_status_get(&timer), 0, "reading the status resets it");
}

static K_THREAD_STACK_DEFINE(helper_stack, 2048);
static struct k_thread helper_thread;
static uint32_t sync_result;

static void sync_entry(void *p1, void *p2, void *p3)
{
	sync_result = k_timer_status_sync(&timer);
}

ZTEST(kernel_timer, test_stop_releases_status_sync)
{
	sync_result = 99;
	k_timer_start(&timer, K_SECONDS(100), K_NO_WAIT);
	k_thread_create(&helper_thread, helper_stack, K_THREAD_STACK_SIZEOF(helper_stack),
			sync_entry, NULL, NULL, NULL, 5, 0, K_NO_WAIT);
	zassert_equal(k_thread_join(&helper_thread, K_MSEC(20)), -EAGAIN, "waits for expiry");
	/* Whether the helper already waits or comes later, it returns 0 once stopped. */
	k_timer_stop(&timer);
	zassert_ok(k_thread_join(&helper_thread, K_SECONDS(10)));
	zassert_equal(sync_result, 0, "a stop ends the wait with status 0");
	zassert_equal(atomic_get(&stops), 1);
	zassert_equal(atomic_get(&expiries), 0);
}

ZTEST(kernel_timer, test_restart_and_no_wait)
{
	k_timer_start(&timer, K_SECONDS(100), K_NO_WAIT);
	zassert_true(k_timer_remaining_get(&timer) > 50000);
	/* Restarting replaces the deadline and clears the status. */
	k_timer_start(&timer, K_NO_WAIT, K_NO_WAIT);
	zassert_equal(k_timer_status_sync(&timer), 1, "K_NO_WAIT expires at once");

	/* K_FOREVER as duration does not start the timer. */
	k_timer_start(&timer, K_FOREVER, K_MSEC(1));
	zassert_equal(k_timer_remaining_ticks(&timer), 0);
	zassert_equal(k_timer_status_sync(&timer), 0);
}

ZTEST(kernel_timer, test_absolute_start)
{
	int64_t at = k_uptime_get() + 40;

	k_timer_start(&timer, K_TIMEOUT_ABS_MS(at), K_NO_WAIT);
	zassert_equal(k_timer_expires_ticks(&timer), (k_ticks_t)k_ms_to_ticks_ceil64(at));
	zassert_equal(k_timer_status_sync(&timer), 1);
	zassert_true(k_uptime_get() >= at);
}

ZTEST(kernel_timer, test_user_data_and_static_timer)
{
	int cookie;

	zassert_is_null(k_timer_user_data_get(&timer));
	k_timer_user_data_set(&timer, &cookie);
	zassert_equal_ptr(k_timer_user_data_get(&timer), &cookie);

	k_timer_start(&static_timer, K_MSEC(5), K_NO_WAIT);
	zassert_equal(k_timer_status_sync(&static_timer), 1);
	zassert_equal(static_expiries, 1, "expiry function of a K_TIMER_DEFINE timer");
}

static void self_stopping_expiry(struct k_timer *t)
{
	atomic_inc(&expiries);
	k_timer_stop(t);
}

ZTEST(kernel_timer, test_stop_from_expiry)
{
	k_timer_init(&timer, self_stopping_expiry, stop_fn);
	k_timer_start(&timer, K_MSEC(1), K_MSEC(1));
	zassert_true(WAIT_FOR(atomic_get(&stops) == 1));
	k_msleep(10);
	zassert_equal(atomic_get(&expiries), 1, "a periodic timer stopped in its expiry function");
	zassert_equal(atomic_get(&stops), 1);
}
