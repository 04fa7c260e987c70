/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Test case console output, as Zephyr's tc_util.h. The formats are the ones Zephyr's
 *        twister parses; do not change them.
 */

#ifndef ZEPHYR_TESTSUITE_INCLUDE_TC_UTIL_H_
#define ZEPHYR_TESTSUITE_INCLUDE_TC_UTIL_H_

#include <zephyr/kernel.h>
#include <zephyr/sys/printk.h>

#ifdef __cplusplus
extern "C" {
#endif

#ifndef PRINT_DATA
#define PRINT_DATA(fmt, ...) printk(fmt, ##__VA_ARGS__)
#endif

/** The 67-character rule between test cases. */
#define PRINT_LINE                                                                                 \
	PRINT_DATA("============================================================"                  \
		   "=======\n")

#define TC_PASS  0
#define TC_FAIL  1
#define TC_SKIP  2
#define TC_FLAKY 3

#define TC_PASS_STR  "PASS"
#define TC_FAIL_STR  "FAIL"
#define TC_SKIP_STR  "SKIP"
#define TC_FLAKY_STR "FLAKY"

static inline const char *TC_RESULT_TO_STR(int result)
{
	switch (result) {
	case TC_PASS:
		return TC_PASS_STR;
	case TC_FAIL:
		return TC_FAIL_STR;
	case TC_SKIP:
		return TC_SKIP_STR;
	case TC_FLAKY:
		return TC_FLAKY_STR;
	default:
		return "?";
	}
}

static inline void tc_print_nothing(const char *fmt, ...)
{
	ARG_UNUSED(fmt);
}

/** Print from a test (only with CONFIG_ZTEST_VERBOSE_OUTPUT). */
#if defined(CONFIG_ZTEST_VERBOSE_OUTPUT)
#define TC_PRINT(fmt, ...) PRINT_DATA(fmt, ##__VA_ARGS__)
#else
#define TC_PRINT(fmt, ...) tc_print_nothing(fmt, ##__VA_ARGS__)
#endif

/** Print a summary line (only with CONFIG_ZTEST_SUMMARY). */
#define TC_SUMMARY_PRINT(fmt, ...) PRINT_DATA(fmt, ##__VA_ARGS__)

#if defined(CONFIG_ZTEST_VERBOSE_OUTPUT)
#define TC_START(name) PRINT_DATA("START - %s\n", name)
#define Z_TC_END_RESULT(result, name, duration_ms)                                                 \
	do {                                                                                       \
		PRINT_DATA(" %s - %s in %u.%03u seconds\n", TC_RESULT_TO_STR(result), name,        \
			   (unsigned int)(duration_ms) / 1000U,                                    \
			   (unsigned int)(duration_ms) % 1000U);                                   \
		PRINT_LINE;                                                                        \
	} while (false)
#else
#define TC_START(name) tc_print_nothing(name)
#define Z_TC_END_RESULT(result, name, duration_ms)                                                 \
	do {                                                                                       \
		ARG_UNUSED(duration_ms);                                                           \
		tc_print_nothing(name);                                                            \
	} while (false)
#endif

#define TC_SUITE_START(name)                                                                       \
	do {                                                                                       \
		PRINT_DATA("Running TESTSUITE %s\n", name);                                        \
		PRINT_LINE;                                                                        \
	} while (false)

#define TC_SUITE_END(name, result)                                                                 \
	do {                                                                                       \
		if ((result) != TC_FAIL) {                                                         \
			PRINT_DATA("TESTSUITE %s succeeded\n", name);                              \
		} else {                                                                           \
			PRINT_DATA("TESTSUITE %s failed.\n", name);                                \
		}                                                                                  \
	} while (false)

#define TC_END_REPORT(result)                                                                      \
	do {                                                                                       \
		PRINT_LINE;                                                                        \
		PRINT_DATA("PROJECT EXECUTION %s\n",                                               \
			   (result) == TC_PASS ? "SUCCESSFUL" : "FAILED");                         \
	} while (false)

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_TESTSUITE_INCLUDE_TC_UTIL_H_ */
