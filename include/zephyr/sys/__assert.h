/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Run-time assertions (CONFIG_ASSERT), as Zephyr's sys/__assert.h.
 *
 * A failed assertion prints "ASSERTION FAIL [test] @ file:line", the message, and calls
 * assert_post_action(), which by default raises a kernel panic (the image prints the fatal
 * error marker and exits non-zero).
 */

#ifndef ZEPHYR_INCLUDE_SYS___ASSERT_H_
#define ZEPHYR_INCLUDE_SYS___ASSERT_H_

#include <stdbool.h>

#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(CONFIG_ASSERT)
#define __ASSERT_ON 1
#else
#define __ASSERT_ON 0
#endif

/**
 * @brief Called after a failed assertion has been printed.
 *
 * Weak: an application or a test may replace it. The default raises k_panic().
 *
 * @param file Source file of the assertion.
 * @param line Line of the assertion.
 */
void assert_post_action(const char *file, unsigned int line);

/** Print a failed assertion's header line (internal). */
void assert_print(const char *fmt, ...) __printf_like(1, 2);

#if __ASSERT_ON

#define __ASSERT_LOC(test)                                                                         \
	assert_print("ASSERTION FAIL [%s] @ %s:%d\n", Z_STRINGIFY(test), __FILE__, __LINE__)

#define __ASSERT_MSG_INFO(fmt, ...) assert_print("\t" fmt "\n", ##__VA_ARGS__)

#define __ASSERT_POST_ACTION() assert_post_action(__FILE__, __LINE__)

/**
 * @brief Check @p test; on failure print it with the printf-style message and panic.
 */
#define __ASSERT(test, fmt, ...)                                                                   \
	do {                                                                                       \
		if (!(test)) {                                                                     \
			__ASSERT_LOC(test);                                                        \
			__ASSERT_MSG_INFO(fmt, ##__VA_ARGS__);                                     \
			__ASSERT_POST_ACTION();                                                    \
		}                                                                                  \
	} while (false)

/** Evaluate @p expr1 (assertions on) or @p expr2 (off), then assert @p test. */
#define __ASSERT_EVAL(expr1, expr2, test, fmt, ...)                                                \
	do {                                                                                       \
		expr2;                                                                             \
		__ASSERT(test, fmt, ##__VA_ARGS__);                                                \
	} while (false)

/** __ASSERT() without a message. */
#define __ASSERT_NO_MSG(test) __ASSERT(test, "")

#else /* !__ASSERT_ON */

#define __ASSERT(test, fmt, ...)                                                                   \
	do {                                                                                       \
	} while (false)
#define __ASSERT_EVAL(expr1, expr2, test, fmt, ...) expr1
#define __ASSERT_NO_MSG(test)                       __ASSERT(test, "")

#endif /* __ASSERT_ON */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS___ASSERT_H_ */
