/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Test suites and test cases, as Zephyr's ztest_test.h (the "new" ztest API).
 */

#ifndef ZEPHYR_TESTSUITE_ZTEST_TEST_H_
#define ZEPHYR_TESTSUITE_ZTEST_TEST_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/kernel.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Statistics of one test case. */
struct ztest_unit_test_stats {
	/** Times the test ran. */
	uint32_t run_count;
	/** Times it was skipped. */
	uint32_t skip_count;
	/** Times it failed. */
	uint32_t fail_count;
	/** Times it passed. */
	uint32_t pass_count;
	/** Longest run in milliseconds. */
	uint32_t duration_worst_ms;
};

/** A test case (created by ZTEST() and friends). */
struct ztest_unit_test {
	const char *test_suite_name;
	const char *name;
	void (*test)(void *data);
	uint32_t thread_options;
	struct ztest_unit_test_stats *stats;
	/** @cond INTERNAL_HIDDEN */
	struct ztest_unit_test *next;
	/** @endcond */
};

/** Statistics of one test suite. */
struct ztest_suite_stats {
	/** Times the suite ran. */
	uint32_t run_count;
	/** Times its predicate said no. */
	uint32_t skip_count;
	/** Times it had a failure. */
	uint32_t fail_count;
};

/** Suite setup: runs once before the suite's tests; returns the fixture (or NULL). */
typedef void *(*ztest_suite_setup_t)(void);
/** Runs before each test, in the test's thread, with the fixture. */
typedef void (*ztest_suite_before_t)(void *fixture);
/** Runs after each test (also after a failed one), with the fixture. */
typedef void (*ztest_suite_after_t)(void *fixture);
/** Suite teardown: runs once after the suite's tests, with the fixture. */
typedef void (*ztest_suite_teardown_t)(void *fixture);
/** Whether the suite should run (given the global state passed to ztest_run_all()). */
typedef bool (*ztest_suite_predicate_t)(const void *global_state);

/** A test suite (created by ZTEST_SUITE()). */
struct ztest_suite_node {
	const char *const name;
	const ztest_suite_setup_t setup;
	const ztest_suite_before_t before;
	const ztest_suite_after_t after;
	const ztest_suite_teardown_t teardown;
	const ztest_suite_predicate_t predicate;
	struct ztest_suite_stats *const stats;
	/** @cond INTERNAL_HIDDEN */
	struct ztest_suite_node *next;
	/** @endcond */
};

/** Expected outcome of a test (ZTEST_EXPECT_FAIL(), ZTEST_EXPECT_SKIP()). */
enum ztest_expected_result {
	ZTEST_EXPECTED_RESULT_FAIL = 0,
	ZTEST_EXPECTED_RESULT_SKIP,
};

/** @cond INTERNAL_HIDDEN */
struct ztest_expected_result_entry {
	const char *test_suite_name;
	const char *test_name;
	enum ztest_expected_result expected_result;
	struct ztest_expected_result_entry *next;
};

void z_ztest_register_suite(struct ztest_suite_node *suite);
void z_ztest_register_test(struct ztest_unit_test *test);
void z_ztest_register_expectation(struct ztest_expected_result_entry *entry);
/** @endcond */

/**
 * @brief Define a test suite.
 *
 * @param SUITE_NAME Name (a C identifier).
 * @param PREDICATE Run the suite only if this returns true (NULL: always).
 * @param setup_fn Run once before the tests; returns the fixture (NULL: none).
 * @param before_fn Run before each test, in the test's thread (NULL: none).
 * @param after_fn Run after each test, also after a failure (NULL: none).
 * @param teardown_fn Run once after the tests (NULL: none).
 */
#define ZTEST_SUITE(SUITE_NAME, PREDICATE, setup_fn, before_fn, after_fn, teardown_fn)             \
	static struct ztest_suite_stats UTIL_CAT(z_ztest_suite_node_stats_, SUITE_NAME);           \
	static struct ztest_suite_node UTIL_CAT(z_ztest_test_node_, SUITE_NAME) = {                \
		.name = STRINGIFY(SUITE_NAME), .setup = (setup_fn), .before = (before_fn),         \
				  .after = (after_fn), .teardown = (teardown_fn),                  \
				  .predicate = (PREDICATE),                                        \
				  .stats = &UTIL_CAT(z_ztest_suite_node_stats_, SUITE_NAME),       \
	};                                                                                         \
	static void __attribute__((constructor)) UTIL_CAT(z_ztest_reg_suite_, SUITE_NAME)(void)    \
	{                                                                                          \
		z_ztest_register_suite(&UTIL_CAT(z_ztest_test_node_, SUITE_NAME));                 \
	}

/** @cond INTERNAL_HIDDEN */
#define Z_TEST_P(suite, fn, t_options, use_fixture)                                                  \
	static struct ztest_unit_test_stats z_ztest_unit_test_stats_##suite##_##fn;                  \
	static void _##suite##_##fn##_wrapper(void *wrapper_data);                                   \
	static void suite##_##fn(COND_CODE_1(use_fixture, (struct suite##_fixture *fixture),       \
					     (void)));   \
	static struct ztest_unit_test z_ztest_unit_test__##suite##__##fn = {                         \
		.test_suite_name = STRINGIFY(suite),                                                                      \
			.name = STRINGIFY(fn), .test = (_##suite##_##fn##_wrapper),                  \
					  .thread_options = (t_options),                             \
					  .stats = &z_ztest_unit_test_stats_##suite##_##fn,          \
	};                                                                                           \
	static void __attribute__((constructor)) z_ztest_reg_test_##suite##_##fn(void)               \
	{                                                                                            \
		z_ztest_register_test(&z_ztest_unit_test__##suite##__##fn);                          \
	}                                                                                            \
	static void _##suite##_##fn##_wrapper(void *wrapper_data)                                    \
	{                                                                                            \
		COND_CODE_1(use_fixture, (suite##_##fn((struct suite##_fixture *)wrapper_data);),  \
			    (ARG_UNUSED(wrapper_data); suite##_##fn();)) \
	}                                                                                            \
	static inline void suite##_##fn(                                                             \
		COND_CODE_1(use_fixture, (struct suite##_fixture *fixture),\
						    (void)))
/** @endcond */

/**
 * @brief Define a test case of suite @p suite; the body follows.
 */
#define ZTEST(suite, fn) Z_TEST_P(suite, fn, 0, 0)

/** A test case for user mode; the same as ZTEST() on native_posix. */
#define ZTEST_USER(suite, fn) Z_TEST_P(suite, fn, K_USER, 0)

/**
 * @brief Define a test case that receives the suite's fixture as
 *        `struct <suite>_fixture *fixture`.
 */
#define ZTEST_F(suite, fn) Z_TEST_P(suite, fn, 0, 1)

/** ZTEST_F() for user mode; the same as ZTEST_F() on native_posix. */
#define ZTEST_USER_F(suite, fn) Z_TEST_P(suite, fn, K_USER, 1)

/**
 * @brief Expect test @p _test_name of @p _suite_name to fail: it passes if it fails.
 */
#define ZTEST_EXPECT_FAIL(_suite_name, _test_name)                                                 \
	Z_ZTEST_EXPECT(_suite_name, _test_name, ZTEST_EXPECTED_RESULT_FAIL)

/**
 * @brief Expect test @p _test_name of @p _suite_name to be skipped: it passes if it is.
 */
#define ZTEST_EXPECT_SKIP(_suite_name, _test_name)                                                 \
	Z_ZTEST_EXPECT(_suite_name, _test_name, ZTEST_EXPECTED_RESULT_SKIP)

/** @cond INTERNAL_HIDDEN */
#define Z_ZTEST_EXPECT(_suite_name, _test_name, _result)                                           \
	static struct ztest_expected_result_entry                                                  \
		z_ztest_expected_result_##_suite_name##_##_test_name = {                           \
			.test_suite_name = STRINGIFY(_suite_name),                                                      \
				.test_name = STRINGIFY(_test_name), .expected_result = (_result),  \
	};                                                                                         \
	static void                                                                                \
		__attribute__((constructor)) z_ztest_reg_expect_##_suite_name##_##_test_name(void) \
	{                                                                                          \
		z_ztest_register_expectation(                                                      \
			&z_ztest_expected_result_##_suite_name##_##_test_name);                    \
	}
/** @endcond */

/**
 * @brief Fail the running test (from the test, a before function or a thread it started).
 */
void ztest_test_fail(void);

/** @brief End the running test as passed. */
void ztest_test_pass(void);

/** @brief End the running test (or, from setup, the suite) as skipped. */
void ztest_test_skip(void);

/** @brief Record a failed expectation; the test continues and fails at its end. */
void ztest_test_expect_fail(void);

/** @brief Skip the test after a failed zassume_*(). */
void ztest_skip_failed_assumption(void);

/**
 * @brief Run every suite whose predicate accepts @p state.
 *
 * @param state Passed to the predicates.
 * @param shuffle Run suites and tests in random order (seeded by --seed).
 * @param suite_iter Times each suite runs.
 * @param case_iter Times each test runs within a suite run.
 */
void ztest_run_all(const void *state, bool shuffle, int suite_iter, int case_iter);

/**
 * @brief Run one suite by name.
 *
 * @return Number of failed tests, or -1 if there is no such suite.
 */
int z_ztest_run_test_suite(const char *name, bool shuffle, int suite_iter, int case_iter,
			   void *param);

/** @brief Fail the image if a suite did not run (CONFIG_ZTEST_VERIFY_RUN_ALL). */
void ztest_verify_all_test_suites_ran(void);

/**
 * @brief The tests' main function: runs every suite. Weak; a test image may provide its own
 *        to run suites selectively with ztest_run_all() or z_ztest_run_test_suite().
 */
void test_main(void);

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_TESTSUITE_ZTEST_TEST_H_ */
