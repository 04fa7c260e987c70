/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Assertions (zassert_*: fail and end the test), assumptions (zassume_*: skip the
 *        test) and expectations (zexpect_*: fail the test but go on), as Zephyr's
 *        ztest_assert.h. Every macro takes an optional printf-style message.
 */

#ifndef ZEPHYR_TESTSUITE_ZTEST_ASSERT_H_
#define ZEPHYR_TESTSUITE_ZTEST_ASSERT_H_

#include <stdarg.h>
#include <stdbool.h>
#include <string.h>

#include <zephyr/tc_util.h>
#include <zephyr/ztest_test.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @cond INTERNAL_HIDDEN */
const char *ztest_relative_filename(const char *file);

/* kind: "Assertion", "Assumption" or "Expectation". Prints the failure; returns cond. */
bool z_zcheck_report(bool cond, const char *kind, const char *default_msg, const char *file,
		     int line, const char *func, const char *msg, ...) __printf_like(7, 8);

static inline bool z_zassert_fail_is_fatal(bool ok)
{
	if (!ok) {
		ztest_test_fail();
	}
	return ok;
}

/*
 * The message is optional: with one, the default text is wrapped in parentheses, as Zephyr
 * prints it.
 */
#define Z_ZCHECK(kind, action, cond, default_msg, msg, ...)                                        \
	do {                                                                                       \
		bool _msg = ((msg) != NULL);                                                       \
		bool _ret = z_zcheck_report(                                                       \
			(cond), kind, _msg ? ("(" default_msg ")") : (default_msg), __FILE__,      \
			__LINE__, __func__, _msg ? (msg) : "", ##__VA_ARGS__);                     \
		(void)_msg;                                                                        \
		if (!_ret) {                                                                       \
			action();                                                                  \
		}                                                                                  \
	} while (false)

#define Z_ZCHECK_VA(kind, action, cond, default_msg, msg, ...)                                     \
	Z_ZCHECK(kind, action, cond, default_msg, msg, ##__VA_ARGS__)
/** @endcond */

/**
 * @brief Fail and end the test if @p cond is false, printing @p default_msg and the message.
 */
#define zassert(cond, default_msg, ...)                                                            \
	Z_ZCHECK_VA("Assertion", ztest_test_fail, cond, default_msg,                               \
		    COND_CODE_1(__VA_OPT__(1), (__VA_ARGS__), (NULL)))

/** @brief Skip the test if @p cond is false. */
#define zassume(cond, default_msg, ...)                                                            \
	Z_ZCHECK_VA("Assumption", ztest_skip_failed_assumption, cond, default_msg,                 \
		    COND_CODE_1(__VA_OPT__(1), (__VA_ARGS__), (NULL)))

/** @brief Mark the test failed if @p cond is false, and continue. */
#define zexpect(cond, default_msg, ...)                                                            \
	Z_ZCHECK_VA("Expectation", ztest_test_expect_fail, cond, default_msg,                      \
		    COND_CODE_1(__VA_OPT__(1), (__VA_ARGS__), (NULL)))

/** @name Assertions: the test fails and ends */
/** @{ */
#define zassert_unreachable(...)     zassert(0, "Reached unreachable code", ##__VA_ARGS__)
#define zassert_true(cond, ...)      zassert(cond, #cond " is false", ##__VA_ARGS__)
#define zassert_false(cond, ...)     zassert(!(cond), #cond " is true", ##__VA_ARGS__)
#define zassert_ok(cond, ...)        zassert(!(cond), #cond " is non-zero", ##__VA_ARGS__)
#define zassert_not_ok(cond, ...)    zassert(!!(cond), #cond " is zero", ##__VA_ARGS__)
#define zassert_is_null(ptr, ...)    zassert((ptr) == NULL, #ptr " is not NULL", ##__VA_ARGS__)
#define zassert_not_null(ptr, ...)   zassert((ptr) != NULL, #ptr " is NULL", ##__VA_ARGS__)
#define zassert_equal(a, b, ...)     zassert((a) == (b), #a " not equal to " #b, ##__VA_ARGS__)
#define zassert_not_equal(a, b, ...) zassert((a) != (b), #a " equal to " #b, ##__VA_ARGS__)
#define zassert_equal_ptr(a, b, ...)                                                               \
	zassert((void *)(a) == (void *)(b), #a " not equal to " #b, ##__VA_ARGS__)
#define zassert_within(a, b, d, ...)                                                               \
	zassert(((a) >= ((b) - (d))) && ((a) <= ((b) + (d))), #a " not within " #b " +/- " #d,     \
		##__VA_ARGS__)
#define zassert_between_inclusive(a, l, u, ...)                                                    \
	zassert(((a) >= (l)) && ((a) <= (u)), #a " not between " #l " and " #u " inclusive",       \
		##__VA_ARGS__)
#define zassert_mem_equal(...) zassert_mem_equal__(__VA_ARGS__)
#define zassert_mem_equal__(buf, exp, size, ...)                                                   \
	zassert(memcmp(buf, exp, size) == 0, #buf " not equal to " #exp, ##__VA_ARGS__)
#define zassert_str_equal(s1, s2, ...)                                                             \
	zassert(strcmp(s1, s2) == 0, #s1 " not equal to " #s2, ##__VA_ARGS__)
/** @} */

/** @name Assumptions: the test is skipped */
/** @{ */
#define zassume_true(cond, ...)      zassume(cond, #cond " is false", ##__VA_ARGS__)
#define zassume_false(cond, ...)     zassume(!(cond), #cond " is true", ##__VA_ARGS__)
#define zassume_ok(cond, ...)        zassume(!(cond), #cond " is non-zero", ##__VA_ARGS__)
#define zassume_not_ok(cond, ...)    zassume(!!(cond), #cond " is zero", ##__VA_ARGS__)
#define zassume_is_null(ptr, ...)    zassume((ptr) == NULL, #ptr " is not NULL", ##__VA_ARGS__)
#define zassume_not_null(ptr, ...)   zassume((ptr) != NULL, #ptr " is NULL", ##__VA_ARGS__)
#define zassume_equal(a, b, ...)     zassume((a) == (b), #a " not equal to " #b, ##__VA_ARGS__)
#define zassume_not_equal(a, b, ...) zassume((a) != (b), #a " equal to " #b, ##__VA_ARGS__)
#define zassume_equal_ptr(a, b, ...)                                                               \
	zassume((void *)(a) == (void *)(b), #a " not equal to " #b, ##__VA_ARGS__)
#define zassume_within(a, b, d, ...)                                                               \
	zassume(((a) >= ((b) - (d))) && ((a) <= ((b) + (d))), #a " not within " #b " +/- " #d,     \
		##__VA_ARGS__)
#define zassume_between_inclusive(a, l, u, ...)                                                    \
	zassume(((a) >= (l)) && ((a) <= (u)), #a " not between " #l " and " #u " inclusive",       \
		##__VA_ARGS__)
#define zassume_mem_equal(...) zassume_mem_equal__(__VA_ARGS__)
#define zassume_mem_equal__(buf, exp, size, ...)                                                   \
	zassume(memcmp(buf, exp, size) == 0, #buf " not equal to " #exp, ##__VA_ARGS__)
/** @} */

/** @name Expectations: the test fails at its end but goes on */
/** @{ */
#define zexpect_true(cond, ...)      zexpect(cond, #cond " is false", ##__VA_ARGS__)
#define zexpect_false(cond, ...)     zexpect(!(cond), #cond " is true", ##__VA_ARGS__)
#define zexpect_ok(cond, ...)        zexpect(!(cond), #cond " is non-zero", ##__VA_ARGS__)
#define zexpect_not_ok(cond, ...)    zexpect(!!(cond), #cond " is zero", ##__VA_ARGS__)
#define zexpect_is_null(ptr, ...)    zexpect((ptr) == NULL, #ptr " is not NULL", ##__VA_ARGS__)
#define zexpect_not_null(ptr, ...)   zexpect((ptr) != NULL, #ptr " is NULL", ##__VA_ARGS__)
#define zexpect_equal(a, b, ...)     zexpect((a) == (b), #a " not equal to " #b, ##__VA_ARGS__)
#define zexpect_not_equal(a, b, ...) zexpect((a) != (b), #a " equal to " #b, ##__VA_ARGS__)
#define zexpect_equal_ptr(a, b, ...)                                                               \
	zexpect((void *)(a) == (void *)(b), #a " not equal to " #b, ##__VA_ARGS__)
#define zexpect_within(a, b, d, ...)                                                               \
	zexpect(((a) >= ((b) - (d))) && ((a) <= ((b) + (d))), #a " not within " #b " +/- " #d,     \
		##__VA_ARGS__)
#define zexpect_between_inclusive(a, l, u, ...)                                                    \
	zexpect(((a) >= (l)) && ((a) <= (u)), #a " not between " #l " and " #u " inclusive",       \
		##__VA_ARGS__)
#define zexpect_mem_equal(...) zexpect_mem_equal__(__VA_ARGS__)
#define zexpect_mem_equal__(buf, exp, size, ...)                                                   \
	zexpect(memcmp(buf, exp, size) == 0, #buf " not equal to " #exp, ##__VA_ARGS__)
/** @} */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_TESTSUITE_ZTEST_ASSERT_H_ */
