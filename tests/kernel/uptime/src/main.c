/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Kernel time: uptime counters, unit conversions (exact values for the board's
 * 100000 ticks/s), timeout encodings, timepoints, sleeping and waking.
 */

#include <zephyr/ztest.h>

#include "test_wait.h"

ZTEST_SUITE(kernel_uptime, NULL, NULL, NULL, NULL, NULL);

ZTEST(kernel_uptime, test_monotonic)
{
	int64_t t0 = k_uptime_ticks();
	int64_t ms0 = k_uptime_get();
	uint64_t c0 = k_cycle_get_64();

	for (int i = 0; i < 1000; i++) {
		int64_t t = k_uptime_ticks();
		int64_t ms = k_uptime_get();
		uint64_t c = k_cycle_get_64();

		zassert_true(t >= t0 && ms >= ms0 && c >= c0, "time went backwards");
		t0 = t;
		ms0 = ms;
		c0 = c;
	}
	zassert_equal(k_uptime_get_32(), (uint32_t)k_uptime_get());
	zassert_true(k_uptime_seconds() <= k_uptime_get() / 1000 + 1);
}

ZTEST(kernel_uptime, test_delta)
{
	int64_t ref = k_uptime_get();
	int64_t d;

	k_msleep(20);
	d = k_uptime_delta(&ref);
	zassert_true(d >= 20, "delta %lld", (long long)d);
	zassert_true(ref <= k_uptime_get());
	zassert_true(k_uptime_delta(&ref) < d + TEST_WAIT_MS);
}

ZTEST(kernel_uptime, test_tick_rate)
{
	zassert_equal(CONFIG_SYS_CLOCK_TICKS_PER_SEC, 100000, "board defconfig sets 100000");
	zassert_equal(sys_clock_hw_cycles_per_sec(), CONFIG_SYS_CLOCK_HW_CYCLES_PER_SEC);
}

ZTEST(kernel_uptime, test_conversions)
{
	/* 100000 ticks/s: 1 tick = 10 us. */
	zassert_equal(k_ms_to_ticks_ceil32(10), 1000);
	zassert_equal(k_ms_to_ticks_floor64(1234), 123400);
	zassert_equal(k_us_to_ticks_ceil32(15), 2, "rounds up to whole ticks");
	zassert_equal(k_us_to_ticks_floor32(15), 1);
	zassert_equal(k_us_to_ticks_near32(15), 2, "15 us is 1.5 ticks: nearest rounds half up");
	zassert_equal(k_us_to_ticks_near32(14), 1);
	zassert_equal(k_ns_to_ticks_ceil64(1), 1);
	zassert_equal(k_ns_to_ticks_floor64(9999), 0);
	zassert_equal(k_ticks_to_us_floor64(3), 30);
	zassert_equal(k_ticks_to_ms_floor32(99999), 999);
	zassert_equal(k_ticks_to_ms_ceil32(99901), 1000);
	zassert_equal(k_ticks_to_ms_near32(150), 2);
	zassert_equal(k_ticks_to_ns_floor64(7), 70000);
	zassert_equal(k_ticks_to_us_floor64(UINT64_C(100000) * 3600 * 24 * 365),
		      UINT64_C(1000000) * 3600 * 24 * 365, "a year of ticks does not overflow");
	/* Hardware cycles are nanoseconds on native_posix. */
	zassert_equal(k_cyc_to_us_floor64(1999), 1);
	zassert_equal(k_cyc_to_us_ceil64(1001), 2);
	zassert_equal(k_cyc_to_ms_ceil32(1000001), 2);
	zassert_equal(k_ticks_to_cyc_floor64(1), 10000);
	zassert_equal(k_cyc_to_ticks_floor64(19999), 1);
	zassert_equal(k_ms_to_cyc_ceil64(1), 1000000);
}

ZTEST(kernel_uptime, test_timeout_encoding)
{
	zassert_equal(K_MSEC(10).ticks, 1000);
	zassert_equal(K_USEC(15).ticks, 2);
	zassert_equal(K_NSEC(1).ticks, 1);
	zassert_equal(K_SECONDS(2).ticks, 200000);
	zassert_equal(K_MINUTES(1).ticks, 6000000);
	zassert_equal(K_TICKS(7).ticks, 7);
	zassert_equal(K_MSEC(-5).ticks, 0, "negative durations are K_NO_WAIT");
	zassert_true(K_TIMEOUT_EQ(K_MSEC(0), K_NO_WAIT));
	zassert_true(K_TIMEOUT_EQ(K_FOREVER, K_TICKS(K_TICKS_FOREVER)));
	zassert_false(K_TIMEOUT_EQ(K_FOREVER, K_NO_WAIT));
	zassert_true(K_TIMEOUT_EQ(SYS_TIMEOUT_MS(SYS_FOREVER_MS), K_FOREVER));
	zassert_true(K_TIMEOUT_EQ(SYS_TIMEOUT_MS(3), K_MSEC(3)));

	/* Absolute timeouts sit below K_TICKS_FOREVER and decode back exactly. */
	k_timeout_t abs = K_TIMEOUT_ABS_TICKS(12345);

	zassert_true(abs.ticks < K_TICKS_FOREVER);
	zassert_equal(Z_TICK_ABS(abs.ticks), 12345);
	zassert_equal(Z_TICK_ABS(K_TIMEOUT_ABS_MS(5).ticks), 500);
	zassert_equal(Z_TICK_ABS(K_TIMEOUT_ABS_US(15).ticks), 2);
	zassert_equal(Z_TICK_ABS(K_TIMEOUT_ABS_TICKS(-3).ticks), 0, "clamped to 0");
}

ZTEST(kernel_uptime, test_sleep)
{
	int64_t start = k_uptime_ticks();

	zassert_equal(k_msleep(15), 0, "a full sleep returns 0");
	zassert_true(k_uptime_ticks() - start >= k_ms_to_ticks_ceil32(15), "woke early");

	start = k_uptime_ticks();
	zassert_equal(k_usleep(250), 0);
	zassert_true(k_uptime_ticks() - start >= 25);

	start = k_uptime_ticks();
	zassert_equal(k_sleep(K_TIMEOUT_ABS_TICKS(start + 500)), 0);
	zassert_true(k_uptime_ticks() >= start + 500, "absolute sleep woke early");

	zassert_equal(k_sleep(K_TIMEOUT_ABS_MS(0)), 0, "a past deadline returns at once");
	zassert_equal(k_sleep(K_NO_WAIT), 0);

	start = k_uptime_ticks();
	k_busy_wait(300);
	zassert_true(k_uptime_ticks() - start >= 30, "busy wait shorter than asked");
}

static K_THREAD_STACK_DEFINE(sleeper_stack, 2048);
static struct k_thread sleeper;
static int32_t sleep_ret;

static void sleeper_entry(void *p1, void *p2, void *p3)
{
	sleep_ret = k_sleep((p1 != NULL) ? K_FOREVER : K_SECONDS(100));
}

ZTEST(kernel_uptime, test_wakeup)
{
	k_thread_create(&sleeper, sleeper_stack, K_THREAD_STACK_SIZEOF(sleeper_stack),
			sleeper_entry, NULL, NULL, NULL, 5, 0, K_NO_WAIT);
	/* k_wakeup() has no effect until the thread sleeps: repeat until it is woken. */
	zassert_true(WAIT_FOR((k_wakeup(&sleeper), k_thread_join(&sleeper, K_MSEC(1)) == 0)));
	zassert_true(sleep_ret > 90000 && sleep_ret <= 100000, "ms left: %d", sleep_ret);

	k_thread_create(&sleeper, sleeper_stack, K_THREAD_STACK_SIZEOF(sleeper_stack),
			sleeper_entry, INT_TO_POINTER(1), NULL, NULL, 5, 0, K_NO_WAIT);
	zassert_true(WAIT_FOR((k_wakeup(&sleeper), k_thread_join(&sleeper, K_MSEC(1)) == 0)));
	zassert_equal(sleep_ret, K_TICKS_FOREVER, "a woken K_FOREVER sleep");
}

ZTEST(kernel_uptime, test_timepoints)
{
	k_timepoint_t never = sys_timepoint_calc(K_FOREVER);
	k_timepoint_t now = sys_timepoint_calc(K_NO_WAIT);
	k_timepoint_t soon = sys_timepoint_calc(K_MSEC(20));
	k_timepoint_t later = sys_timepoint_calc(K_SECONDS(100));
	k_timepoint_t at = sys_timepoint_calc(K_TIMEOUT_ABS_TICKS(777));

	zassert_true(K_TIMEOUT_EQ(sys_timepoint_timeout(never), K_FOREVER));
	zassert_true(K_TIMEOUT_EQ(sys_timepoint_timeout(now), K_NO_WAIT));
	zassert_true(sys_timepoint_expired(now));
	zassert_false(sys_timepoint_expired(never));
	zassert_equal(at.tick, 777);
	zassert_true(sys_timepoint_cmp(soon, later) < 0);
	zassert_true(sys_timepoint_cmp(later, soon) > 0);
	zassert_equal(sys_timepoint_cmp(soon, soon), 0);
	zassert_true(sys_timepoint_timeout(later).ticks <= K_SECONDS(100).ticks);

	k_msleep(25);
	zassert_true(sys_timepoint_expired(soon));
	zassert_false(sys_timepoint_expired(later));
}
