/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Helpers shared by the kernel tests.
 *
 * WAIT_FOR() waits until a condition holds, checking every millisecond, for at most
 * TEST_WAIT_MS. Tests use it to wait for an effect that another thread causes (a thread has
 * blocked, a priority was inherited) instead of sleeping a fixed time: fast when the machine
 * is idle, still correct when it is loaded or runs under a sanitizer.
 */

#ifndef TESTS_KERNEL_COMMON_TEST_WAIT_H_
#define TESTS_KERNEL_COMMON_TEST_WAIT_H_

#include <zephyr/kernel.h>

#define TEST_WAIT_MS 10000

#define WAIT_FOR(cond)                                                                             \
	({                                                                                         \
		int64_t _end = k_uptime_get() + TEST_WAIT_MS;                                      \
		bool _ok;                                                                          \
		while (!(_ok = (cond)) && k_uptime_get() < _end) {                                 \
			(void)k_msleep(1);                                                         \
		}                                                                                  \
		_ok;                                                                               \
	})

#endif /* TESTS_KERNEL_COMMON_TEST_WAIT_H_ */
