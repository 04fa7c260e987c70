/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_mutex: recursion, ownership errors, timeouts, hand-over order and priority inheritance.
 *
 * A waiter of higher priority boosts the owner, and k_thread_priority_get() shows it: the
 * tests use that to know, without sleeping, that a waiter has blocked.
 */

#include <zephyr/ztest.h>

#include "test_wait.h"

#define STACK_SIZE 2048
#define PRIO_LOW   10
#define PRIO_MID   6
#define PRIO_HIGH  2

static K_THREAD_STACK_DEFINE(owner_stack, STACK_SIZE);
static K_THREAD_STACK_DEFINE(waiter1_stack, STACK_SIZE);
static K_THREAD_STACK_DEFINE(waiter2_stack, STACK_SIZE);
static struct k_thread owner_thread;
static struct k_thread waiter1_thread;
static struct k_thread waiter2_thread;

static K_MUTEX_DEFINE(static_mutex);
static struct k_mutex mutex;
static K_SEM_DEFINE(owner_locked, 0, 1);
static K_SEM_DEFINE(owner_release, 0, 1);

/* What the threads saw, read by the test after joining them. */
static int owner_prio_after_unlock;
static int waiter_ret[2];
static int order[2];
static atomic_t order_idx;

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	k_mutex_init(&mutex);
	k_sem_reset(&owner_locked);
	k_sem_reset(&owner_release);
	atomic_clear(&order_idx);
	waiter_ret[0] = waiter_ret[1] = 1;
	order[0] = order[1] = -1;
}

ZTEST_SUITE(kernel_mutex, NULL, NULL, before, NULL, NULL);

/* Locks the mutex, reports, holds it until released, then records its priority. */
static void owner_entry(void *p1, void *p2, void *p3)
{
	zassert_ok(k_mutex_lock(&mutex, K_FOREVER));
	k_sem_give(&owner_locked);
	zassert_ok(k_sem_take(&owner_release, K_FOREVER));
	zassert_ok(k_mutex_unlock(&mutex));
	owner_prio_after_unlock = k_thread_priority_get(k_current_get());
}

static void start_owner(void)
{
	k_thread_create(&owner_thread, owner_stack, STACK_SIZE, owner_entry, NULL, NULL, NULL,
			PRIO_LOW, 0, K_NO_WAIT);
	zassert_ok(k_sem_take(&owner_locked, K_SECONDS(10)));
}

/* p1: index for the results, p2: timeout in ms (0: forever). */
static void waiter_entry(void *p1, void *p2, void *p3)
{
	int idx = POINTER_TO_INT(p1);
	int ms = POINTER_TO_INT(p2);
	int ret = k_mutex_lock(&mutex, (ms == 0) ? K_FOREVER : K_MSEC(ms));

	waiter_ret[idx] = ret;
	if (ret == 0) {
		order[atomic_inc(&order_idx)] = idx;
		zassert_ok(k_mutex_unlock(&mutex));
	}
}

static void start_waiter(int idx, int prio, int timeout_ms)
{
	struct k_thread *t = (idx == 0) ? &waiter1_thread : &waiter2_thread;
	k_thread_stack_t *s = (idx == 0) ? waiter1_stack : waiter2_stack;

	k_thread_create(t, s, STACK_SIZE, waiter_entry, INT_TO_POINTER(idx),
			INT_TO_POINTER(timeout_ms), NULL, prio, 0, K_NO_WAIT);
}

static void try_lock_entry(void *p1, void *p2, void *p3)
{
	int ret = k_mutex_lock(&mutex, K_NO_WAIT);

	waiter_ret[0] = ret;
	if (ret == 0) {
		zassert_ok(k_mutex_unlock(&mutex));
	}
}

/* Result of k_mutex_lock(K_NO_WAIT) from another thread. */
static int try_lock_from_other_thread(void)
{
	k_thread_create(&waiter1_thread, waiter1_stack, STACK_SIZE, try_lock_entry, NULL, NULL,
			NULL, PRIO_MID, 0, K_NO_WAIT);
	zassert_ok(k_thread_join(&waiter1_thread, K_SECONDS(10)));

	return waiter_ret[0];
}

ZTEST(kernel_mutex, test_recursive_lock)
{
	zassert_ok(k_mutex_lock(&mutex, K_NO_WAIT));
	zassert_ok(k_mutex_lock(&mutex, K_NO_WAIT));
	zassert_ok(k_mutex_lock(&mutex, K_FOREVER));
	zassert_ok(k_mutex_unlock(&mutex));
	zassert_ok(k_mutex_unlock(&mutex));
	/* Still owned after two of three unlocks. */
	zassert_equal(try_lock_from_other_thread(), -EBUSY);
	zassert_ok(k_mutex_unlock(&mutex));
	zassert_ok(try_lock_from_other_thread(), "free after the last unlock");
	zassert_equal(k_mutex_unlock(&mutex), -EINVAL, "unlocked mutex must give -EINVAL");
}

ZTEST(kernel_mutex, test_unlock_errors)
{
	zassert_equal(k_mutex_unlock(&mutex), -EINVAL);

	start_owner();
	zassert_equal(k_mutex_unlock(&mutex), -EPERM, "only the owner may unlock");
	zassert_equal(k_mutex_lock(&mutex, K_NO_WAIT), -EBUSY);
	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));

	zassert_ok(k_mutex_lock(&mutex, K_NO_WAIT), "free again after the owner unlocked");
	zassert_ok(k_mutex_unlock(&mutex));
}

ZTEST(kernel_mutex, test_lock_timeout)
{
	int64_t start;

	start_owner();
	start = k_uptime_get();
	zassert_equal(k_mutex_lock(&mutex, K_MSEC(50)), -EAGAIN);
	zassert_true(k_uptime_get() - start >= 50, "returned before the timeout");

	/* An absolute timeout in the past does not wait. */
	zassert_equal(k_mutex_lock(&mutex, K_TIMEOUT_ABS_MS(0)), -EAGAIN);

	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));
}

ZTEST(kernel_mutex, test_static_mutex)
{
	zassert_ok(k_mutex_lock(&static_mutex, K_NO_WAIT));
	zassert_ok(k_mutex_lock(&static_mutex, K_NO_WAIT));
	zassert_ok(k_mutex_unlock(&static_mutex));
	zassert_ok(k_mutex_unlock(&static_mutex));
	zassert_equal(k_mutex_unlock(&static_mutex), -EINVAL);
}

ZTEST(kernel_mutex, test_priority_inheritance)
{
	start_owner();
	zassert_equal(k_thread_priority_get(&owner_thread), PRIO_LOW);

	start_waiter(0, PRIO_HIGH, 0);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_HIGH),
		     "owner did not inherit the waiter's priority");

	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));
	zassert_ok(k_thread_join(&waiter1_thread, K_SECONDS(10)));
	zassert_equal(owner_prio_after_unlock, PRIO_LOW, "priority not restored on unlock");
	zassert_ok(waiter_ret[0]);
}

ZTEST(kernel_mutex, test_inheritance_ends_with_timeout)
{
	start_owner();

	/* Mid waits forever, high gives up after a while. */
	start_waiter(0, PRIO_MID, 0);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_MID));
	start_waiter(1, PRIO_HIGH, 200);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_HIGH));

	/* High's timeout ends its boost: the owner falls back to the remaining waiter's. */
	zassert_ok(k_thread_join(&waiter2_thread, K_SECONDS(10)));
	zassert_equal(waiter_ret[1], -EAGAIN);
	zassert_equal(k_thread_priority_get(&owner_thread), PRIO_MID);

	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));
	zassert_ok(k_thread_join(&waiter1_thread, K_SECONDS(10)));
	zassert_equal(owner_prio_after_unlock, PRIO_LOW);
	zassert_ok(waiter_ret[0]);
}

ZTEST(kernel_mutex, test_handover_by_priority)
{
	start_owner();

	/* The lower-priority waiter blocks first. */
	start_waiter(0, PRIO_MID, 0);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_MID));
	start_waiter(1, PRIO_HIGH, 0);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_HIGH));

	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&waiter1_thread, K_SECONDS(10)));
	zassert_ok(k_thread_join(&waiter2_thread, K_SECONDS(10)));
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));

	zassert_equal(order[0], 1, "the higher-priority waiter must get the mutex first");
	zassert_equal(order[1], 0);
}

ZTEST(kernel_mutex, test_timeout_then_success)
{
	start_owner();
	start_waiter(0, PRIO_HIGH, 0);
	zassert_true(WAIT_FOR(k_thread_priority_get(&owner_thread) == PRIO_HIGH));

	/* The test thread's own timed lock fails while the owner holds on... */
	zassert_equal(k_mutex_lock(&mutex, K_MSEC(20)), -EAGAIN);
	/* ...and the waiter that was there first gets it once released. */
	k_sem_give(&owner_release);
	zassert_ok(k_thread_join(&waiter1_thread, K_SECONDS(10)));
	zassert_ok(waiter_ret[0]);
	zassert_ok(k_thread_join(&owner_thread, K_SECONDS(10)));
}
