/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The ztest testing framework subset, as Zephyr's ztest.h.
 *
 *     ZTEST_SUITE(my_suite, NULL, NULL, NULL, NULL, NULL);
 *
 *     ZTEST(my_suite, test_add)
 *     {
 *             zassert_equal(1 + 1, 2, "arithmetic is broken");
 *     }
 *
 * Tests run one at a time, each in its own thread; a failed zassert_*() ends that test and
 * the suite goes on. The console output is Zephyr's, for Zephyr's twister; the image's exit
 * code is 0 only if every test passed (or was skipped). main() comes from ztest.
 */

#ifndef ZEPHYR_TESTSUITE_ZTEST_H_
#define ZEPHYR_TESTSUITE_ZTEST_H_

#include <zephyr/kernel.h>
#include <zephyr/tc_util.h>
#include <zephyr/ztest_assert.h>
#include <zephyr/ztest_test.h>

#endif /* ZEPHYR_TESTSUITE_ZTEST_H_ */
