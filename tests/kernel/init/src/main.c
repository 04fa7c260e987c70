/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Boot order: native tasks, SYS_INIT levels and priorities, K_THREAD_DEFINE threads, then
 * main(). Each step appends its mark to a log; the test compares the log with the order
 * Zephyr defines. The entries are declared out of order on purpose.
 */

#include <string.h>

#include <zephyr/ztest.h>

#include "posix_native_task.h"

#define MAX_STEPS 32

static const char *steps[MAX_STEPS];
static k_tid_t step_thread[MAX_STEPS];
static int n_steps;
static K_MUTEX_DEFINE(log_lock);

static void mark(const char *step)
{
	k_mutex_lock(&log_lock, K_FOREVER);
	if (n_steps < MAX_STEPS) {
		step_thread[n_steps] = k_current_get();
		steps[n_steps++] = step;
	}
	k_mutex_unlock(&log_lock);
}

#define INIT_FN(name)                                                                              \
	static int name(void)                                                                      \
	{                                                                                          \
		mark(#name);                                                                       \
		return 0;                                                                          \
	}

INIT_FN(app_50)
INIT_FN(post_kernel_90)
INIT_FN(post_kernel_10)
INIT_FN(pre_kernel_2_0)
INIT_FN(pre_kernel_1_99)
INIT_FN(pre_kernel_1_5)
INIT_FN(post_kernel_10b)

static int failing_init(void)
{
	mark("failing_init");
	/* Reported on the console; boot goes on. */
	return -EIO;
}

SYS_INIT(app_50, APPLICATION, 50);
SYS_INIT(post_kernel_90, POST_KERNEL, 90);
SYS_INIT(post_kernel_10, POST_KERNEL, 10);
SYS_INIT(failing_init, POST_KERNEL, 20);
SYS_INIT(pre_kernel_2_0, PRE_KERNEL_2, 0);
SYS_INIT(pre_kernel_1_99, PRE_KERNEL_1, 99);
SYS_INIT(pre_kernel_1_5, PRE_KERNEL_1, 5);
SYS_INIT_NAMED(post_kernel_10b_named, post_kernel_10b, POST_KERNEL, 10);

static void native_pre_boot(void)
{
	mark("native_pre_boot_1");
}
NATIVE_TASK(native_pre_boot, PRE_BOOT_1, 0);

static void native_pre_boot_3(void)
{
	mark("native_pre_boot_3");
}
NATIVE_TASK(native_pre_boot_3, PRE_BOOT_3, 0);

static void boot_thread_entry(void *p1, void *p2, void *p3)
{
	mark("k_thread_define");
}
K_THREAD_DEFINE(boot_thread, 2048, boot_thread_entry, NULL, NULL, NULL, 5, 0, 0);

static void *setup(void)
{
	/* The boot thread may still be on its way: wait for it. */
	(void)k_thread_join(boot_thread, K_SECONDS(10));
	mark("ztest_setup");

	return NULL;
}

ZTEST_SUITE(kernel_init, NULL, setup, NULL, NULL, NULL);

static int index_of(const char *step)
{
	for (int i = 0; i < n_steps; i++) {
		if (strcmp(steps[i], step) == 0) {
			return i;
		}
	}

	return -1;
}

ZTEST(kernel_init, test_order)
{
	static const char *const expected[] = {
		"native_pre_boot_1", "native_pre_boot_3",
		"pre_kernel_1_5",    "pre_kernel_1_99",
		"pre_kernel_2_0",    "post_kernel_10",
		"post_kernel_10b",   "failing_init",
		"post_kernel_90",    "app_50",
	};

	k_mutex_lock(&log_lock, K_FOREVER);
	for (size_t i = 0; i < ARRAY_SIZE(expected); i++) {
		zassert_true(i < (size_t)n_steps, "only %d steps", n_steps);
		zassert_str_equal(steps[i], expected[i], "step %zu", i);
	}
	/* The boot-time thread starts after APPLICATION; main() (ztest) comes after that. */
	zassert_true(index_of("k_thread_define") > index_of("app_50"));
	zassert_true(index_of("ztest_setup") > index_of("app_50"));
	k_mutex_unlock(&log_lock);
}

ZTEST(kernel_init, test_contexts)
{
	k_tid_t boot_ctx = step_thread[index_of("pre_kernel_1_5")];
	k_tid_t main_ctx = step_thread[index_of("post_kernel_10")];

	/* PRE_KERNEL runs on the boot thread, POST_KERNEL and APPLICATION in "main". */
	zassert_equal_ptr(step_thread[index_of("native_pre_boot_1")], boot_ctx);
	zassert_str_equal(k_thread_name_get(main_ctx), "main");
	zassert_not_equal(boot_ctx, main_ctx);
	zassert_equal_ptr(step_thread[index_of("app_50")], main_ctx);
	zassert_equal_ptr(step_thread[index_of("k_thread_define")], boot_thread);
}
