/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Threads: creation (at once, delayed, on demand, at boot), join and its error codes, names,
 * priorities, abort, and reuse of thread objects.
 */

#include <string.h>

#include <zephyr/ztest.h>

#include "test_wait.h"

#define STACK_SIZE  2048
#define NUM_THREADS 32

static K_THREAD_STACK_ARRAY_DEFINE(stacks, NUM_THREADS, STACK_SIZE);
static struct k_thread threads[NUM_THREADS];

static atomic_t counter;
static atomic_t ran[NUM_THREADS];
static k_tid_t seen_self[NUM_THREADS];
static int64_t started_at_ms;
static K_SEM_DEFINE(block, 0, 1);

/* Boot-time threads: one starts before main(), one waits for k_thread_start(). */
static atomic_t boot_thread_ran;
static atomic_t lazy_thread_ran;

static void boot_entry(void *p1, void *p2, void *p3)
{
	zassert_equal(POINTER_TO_INT(p1), 11);
	zassert_equal(POINTER_TO_INT(p3), 33);
	atomic_set(&boot_thread_ran, 1);
}

static void lazy_entry(void *p1, void *p2, void *p3)
{
	atomic_set(&lazy_thread_ran, 1);
}

K_THREAD_DEFINE(boot_thread, STACK_SIZE, boot_entry, 11, 22, 33, 7, 0, 0);
K_THREAD_DEFINE(lazy_thread, STACK_SIZE, lazy_entry, NULL, NULL, NULL, 7, 0, SYS_FOREVER_MS);

/* Threads of the running test, aborted after it so that a failed test leaves none behind. */
static bool created[NUM_THREADS];

static k_tid_t spawn(int idx, k_thread_entry_t entry, void *p1, int prio, k_timeout_t delay)
{
	created[idx] = true;

	return k_thread_create(&threads[idx], stacks[idx], STACK_SIZE, entry, p1, NULL, NULL, prio,
			       0, delay);
}

static void after(void *fixture)
{
	ARG_UNUSED(fixture);
	for (int i = 0; i < NUM_THREADS; i++) {
		if (created[i]) {
			k_thread_abort(&threads[i]);
			created[i] = false;
		}
	}
}

static void before(void *fixture)
{
	ARG_UNUSED(fixture);
	atomic_clear(&counter);
	for (int i = 0; i < NUM_THREADS; i++) {
		atomic_clear(&ran[i]);
		seen_self[i] = NULL;
	}
	k_sem_reset(&block);
}

ZTEST_SUITE(kernel_threads, NULL, NULL, before, after, NULL);

static void count_entry(void *p1, void *p2, void *p3)
{
	int idx = POINTER_TO_INT(p1);

	seen_self[idx] = k_current_get();
	atomic_inc(&counter);
	atomic_set(&ran[idx], 1);
}

ZTEST(kernel_threads, test_many_threads)
{
	for (int i = 0; i < NUM_THREADS; i++) {
		k_tid_t tid = spawn(i, count_entry, INT_TO_POINTER(i), i % 10, K_NO_WAIT);

		zassert_equal_ptr(tid, &threads[i], "the ID is the thread object");
	}
	for (int i = 0; i < NUM_THREADS; i++) {
		zassert_ok(k_thread_join(&threads[i], K_SECONDS(30)));
		zassert_equal_ptr(seen_self[i], &threads[i], "k_current_get() in the thread");
	}
	zassert_equal(atomic_get(&counter), NUM_THREADS);
}

ZTEST(kernel_threads, test_reuse_thread_object)
{
	for (int i = 0; i < 100; i++) {
		spawn(0, count_entry, INT_TO_POINTER(0), 5, K_NO_WAIT);
		zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	}
	zassert_equal(atomic_get(&counter), 100);
}

static void blocked_entry(void *p1, void *p2, void *p3)
{
	int idx = POINTER_TO_INT(p1);

	(void)k_sem_take(&block, K_FOREVER);
	atomic_set(&ran[idx], 1);
}

static int join_ret;

static void join_entry(void *p1, void *p2, void *p3)
{
	join_ret = k_thread_join((struct k_thread *)p1, K_FOREVER);
}

ZTEST(kernel_threads, test_join_errors)
{
	zassert_equal(k_thread_join(k_current_get(), K_FOREVER), -EDEADLK, "joining oneself");

	spawn(0, blocked_entry, INT_TO_POINTER(0), 5, K_NO_WAIT);
	zassert_equal(k_thread_join(&threads[0], K_NO_WAIT), -EBUSY);
	zassert_equal(k_thread_join(&threads[0], K_MSEC(20)), -EAGAIN);

	/*
	 * threads[1] joins the test thread while the test thread joins it: whichever of the two
	 * comes second is refused with -EDEADLK (the other one then still waits: abort it).
	 */
	join_ret = 1;
	spawn(1, join_entry, k_current_get(), 5, K_NO_WAIT);
	k_msleep(10);
	int ret = k_thread_join(&threads[1], K_SECONDS(10));

	zassert_true(ret == -EDEADLK || join_ret == -EDEADLK, "ret %d, join_ret %d", ret, join_ret);
	k_thread_abort(&threads[1]);

	k_sem_give(&block);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_ok(k_thread_join(&threads[0], K_NO_WAIT), "an ended thread joins at once");
	zassert_equal(atomic_get(&ran[0]), 1);
}

ZTEST(kernel_threads, test_names)
{
	char buf[8];
	char long_name[CONFIG_THREAD_MAX_NAME_LEN + 10];

	spawn(0, blocked_entry, INT_TO_POINTER(0), 5, K_FOREVER);
	zassert_str_equal(k_thread_name_get(&threads[0]), "", "no name by default");
	zassert_ok(k_thread_name_set(&threads[0], "worker"));
	zassert_str_equal(k_thread_name_get(&threads[0]), "worker");
	zassert_ok(k_thread_name_copy(&threads[0], buf, sizeof(buf)));
	zassert_str_equal(buf, "worker");
	zassert_ok(k_thread_name_copy(&threads[0], buf, 4));
	zassert_str_equal(buf, "wor", "copy truncated to the buffer");

	memset(long_name, 'x', sizeof(long_name) - 1);
	long_name[sizeof(long_name) - 1] = '\0';
	zassert_ok(k_thread_name_set(&threads[0], long_name));
	zassert_equal(strlen(k_thread_name_get(&threads[0])), CONFIG_THREAD_MAX_NAME_LEN - 1);

	zassert_ok(k_thread_name_set(NULL, "renamed"), "NULL names the caller");
	zassert_str_equal(k_thread_name_get(k_current_get()), "renamed");
	zassert_str_equal(k_thread_name_get(boot_thread), "boot_thread",
			  "K_THREAD_DEFINE names the thread after its symbol");

	k_thread_abort(&threads[0]);
}

ZTEST(kernel_threads, test_priorities)
{
	spawn(0, blocked_entry, INT_TO_POINTER(0), K_PRIO_PREEMPT(4), K_NO_WAIT);
	zassert_equal(k_thread_priority_get(&threads[0]), 4);
	k_thread_priority_set(&threads[0], K_PRIO_COOP(2));
	zassert_equal(k_thread_priority_get(&threads[0]), K_PRIO_COOP(2));
	zassert_true(K_PRIO_COOP(2) < 0, "cooperative priorities are negative");
	zassert_equal(k_thread_priority_get(k_current_get()), CONFIG_ZTEST_THREAD_PRIORITY);
	zassert_equal(K_HIGHEST_THREAD_PRIO, -CONFIG_NUM_COOP_PRIORITIES);
	zassert_equal(K_LOWEST_APPLICATION_THREAD_PRIO, CONFIG_NUM_PREEMPT_PRIORITIES - 1);

	k_sem_give(&block);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
}

static void stamp_entry(void *p1, void *p2, void *p3)
{
	started_at_ms = k_uptime_get();
	atomic_set(&ran[0], 1);
}

ZTEST(kernel_threads, test_delayed_start)
{
	int64_t created = k_uptime_get();

	spawn(0, stamp_entry, NULL, 5, K_MSEC(50));
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_true(started_at_ms - created >= 50, "started after %lld ms",
		     (long long)(started_at_ms - created));

	atomic_clear(&ran[0]);
	spawn(0, stamp_entry, NULL, 5, K_FOREVER);
	zassert_equal(k_thread_join(&threads[0], K_MSEC(30)), -EAGAIN);
	zassert_equal(atomic_get(&ran[0]), 0, "K_FOREVER: waits for k_thread_start()");
	k_thread_start(&threads[0]);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_equal(atomic_get(&ran[0]), 1);
}

static void self_abort_entry(void *p1, void *p2, void *p3)
{
	k_thread_abort(k_current_get());
	atomic_set(&ran[0], 1);
}

ZTEST(kernel_threads, test_abort)
{
	/* A blocked thread ends without returning from its wait. */
	spawn(0, blocked_entry, INT_TO_POINTER(0), 5, K_NO_WAIT);
	k_thread_abort(&threads[0]);
	zassert_ok(k_thread_join(&threads[0], K_NO_WAIT), "ended when k_thread_abort() returns");
	k_sem_give(&block);
	k_msleep(10);
	zassert_equal(atomic_get(&ran[0]), 0, "the aborted thread ran on");
	k_sem_reset(&block);

	/* A thread that never started. */
	spawn(1, count_entry, INT_TO_POINTER(1), 5, K_FOREVER);
	k_thread_abort(&threads[1]);
	zassert_ok(k_thread_join(&threads[1], K_NO_WAIT));
	k_thread_start(&threads[1]);
	k_msleep(10);
	zassert_equal(atomic_get(&ran[1]), 0, "an aborted thread cannot be started");

	/* A thread that ends itself. */
	spawn(0, self_abort_entry, NULL, 5, K_NO_WAIT);
	zassert_ok(k_thread_join(&threads[0], K_SECONDS(10)));
	zassert_equal(atomic_get(&ran[0]), 0, "k_thread_abort(self) returned");

	/* Aborting an ended thread does nothing. */
	k_thread_abort(&threads[0]);
}

ZTEST(kernel_threads, test_boot_threads)
{
	zassert_true(WAIT_FOR(atomic_get(&boot_thread_ran) == 1), "K_THREAD_DEFINE, delay 0");
	zassert_ok(k_thread_join(boot_thread, K_SECONDS(10)));

	zassert_equal(k_thread_join(lazy_thread, K_MSEC(20)), -EAGAIN);
	zassert_equal(atomic_get(&lazy_thread_ran), 0, "SYS_FOREVER_MS: not started");
	k_thread_start(lazy_thread);
	zassert_ok(k_thread_join(lazy_thread, K_SECONDS(10)));
	zassert_equal(atomic_get(&lazy_thread_ran), 1);
}

ZTEST(kernel_threads, test_yield)
{
	for (int i = 0; i < 10; i++) {
		k_yield();
	}
	zassert_false(k_is_in_isr());
}
