/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* k_sem: counting, limit, the exact error codes, timeouts, reset, and gives from a timer. */

#include <zephyr/ztest.h>

#include "test_wait.h"

#define STACK_SIZE 2048

static K_THREAD_STACK_DEFINE(helper_stack, STACK_SIZE);
static struct k_thread helper_thread;

static K_SEM_DEFINE(static_sem, 2, 3);
static struct k_sem sem;
static int helper_ret;

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	zassert_ok(k_sem_init(&sem, 0, 3));
	helper_ret = 1;
}

ZTEST_SUITE(kernel_sem, NULL, NULL, before, NULL, NULL);

ZTEST(kernel_sem, test_init_rejects_bad_limits)
{
	struct k_sem s;

	zassert_equal(k_sem_init(&s, 0, 0), -EINVAL, "limit 0");
	zassert_equal(k_sem_init(&s, 4, 3), -EINVAL, "initial count above limit");
	zassert_ok(k_sem_init(&s, 3, 3));
	zassert_equal(k_sem_count_get(&s), 3);
	zassert_ok(k_sem_init(&s, 0, K_SEM_MAX_LIMIT));
}

ZTEST(kernel_sem, test_give_take_and_limit)
{
	zassert_equal(k_sem_take(&sem, K_NO_WAIT), -EBUSY, "empty + K_NO_WAIT must be -EBUSY");

	for (int i = 0; i < 5; i++) {
		k_sem_give(&sem);
	}
	zassert_equal(k_sem_count_get(&sem), 3, "the count stops at the limit");

	for (int i = 0; i < 3; i++) {
		zassert_ok(k_sem_take(&sem, K_NO_WAIT));
	}
	zassert_equal(k_sem_take(&sem, K_NO_WAIT), -EBUSY);
	zassert_equal(k_sem_count_get(&sem), 0);
}

ZTEST(kernel_sem, test_take_timeout)
{
	int64_t start = k_uptime_get();

	zassert_equal(k_sem_take(&sem, K_MSEC(50)), -EAGAIN, "timeout must be -EAGAIN");
	zassert_true(k_uptime_get() - start >= 50, "returned before the timeout");

	start = k_uptime_get();
	zassert_equal(k_sem_take(&sem, K_TIMEOUT_ABS_MS(k_uptime_get() + 30)), -EAGAIN);
	zassert_true(k_uptime_get() - start >= 29, "absolute timeout ended early");
}

static void taker_entry(void *p1, void *p2, void *p3)
{
	helper_ret = k_sem_take(&sem, K_FOREVER);
}

ZTEST(kernel_sem, test_give_wakes_waiter)
{
	k_thread_create(&helper_thread, helper_stack, STACK_SIZE, taker_entry, NULL, NULL, NULL, 5,
			0, K_NO_WAIT);
	/* Not done until given. */
	zassert_equal(k_thread_join(&helper_thread, K_MSEC(20)), -EAGAIN);
	k_sem_give(&sem);
	zassert_ok(k_thread_join(&helper_thread, K_SECONDS(10)));
	zassert_ok(helper_ret);
	zassert_equal(k_sem_count_get(&sem), 0, "the give went to the waiter, not the count");
}

ZTEST(kernel_sem, test_reset)
{
	k_sem_give(&sem);
	k_sem_give(&sem);
	zassert_equal(k_sem_count_get(&sem), 2);
	k_sem_reset(&sem);
	zassert_equal(k_sem_count_get(&sem), 0);
	zassert_equal(k_sem_take(&sem, K_NO_WAIT), -EBUSY);
}

ZTEST(kernel_sem, test_reset_wakes_waiters)
{
	k_thread_create(&helper_thread, helper_stack, STACK_SIZE, taker_entry, NULL, NULL, NULL, 5,
			0, K_NO_WAIT);
	/* Nothing is ever given: only a reset issued while it waits can end the helper. */
	zassert_true(WAIT_FOR((k_sem_reset(&sem), k_thread_join(&helper_thread, K_MSEC(1)) == 0)));
	zassert_equal(helper_ret, -EAGAIN, "a reset wakes waiters with -EAGAIN");
}

static void give_from_timer(struct k_timer *timer)
{
	zassert_true(k_is_in_isr(), "timer expiry runs in interrupt context");
	k_sem_give(&sem);
}

ZTEST(kernel_sem, test_give_from_timer)
{
	struct k_timer timer;

	k_timer_init(&timer, give_from_timer, NULL);
	k_timer_start(&timer, K_MSEC(10), K_NO_WAIT);
	zassert_ok(k_sem_take(&sem, K_SECONDS(10)));
	k_timer_stop(&timer);
}

ZTEST(kernel_sem, test_static_sem)
{
	zassert_equal(k_sem_count_get(&static_sem), 2);
	zassert_ok(k_sem_take(&static_sem, K_NO_WAIT));
	zassert_ok(k_sem_take(&static_sem, K_NO_WAIT));
	zassert_equal(k_sem_take(&static_sem, K_NO_WAIT), -EBUSY);
	for (int i = 0; i < 5; i++) {
		k_sem_give(&static_sem);
	}
	zassert_equal(k_sem_count_get(&static_sem), 3);
	k_sem_reset(&static_sem);
	k_sem_give(&static_sem);
	k_sem_give(&static_sem);
}
