/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The ztest framework tested with itself. Suites run in name order (a_*, b_*, c_*), and so do
 * the tests of a suite, so later tests can check what earlier ones left behind. Tests that
 * must fail or skip are declared with ZTEST_EXPECT_FAIL/SKIP: they count as passed only if
 * they do fail or skip.
 */

#include <zephyr/ztest.h>

/* ---- a_fixture: setup/before/after/teardown and the fixture pointer ---- */

struct a_fixture_fixture {
	int setup_calls;
	int before_calls;
	int after_calls;
	k_tid_t before_thread;
};

static struct a_fixture_fixture fixture_storage;
static bool a_teardown_done;

static void *a_setup(void)
{
	fixture_storage.setup_calls++;
	return &fixture_storage;
}

static void a_before(void *f)
{
	struct a_fixture_fixture *fx = f;

	fx->before_calls++;
	fx->before_thread = k_current_get();
}

static void a_after(void *f)
{
	((struct a_fixture_fixture *)f)->after_calls++;
}

static void a_teardown(void *f)
{
	zassert_equal_ptr(f, &fixture_storage);
	a_teardown_done = true;
}

ZTEST_SUITE(a_fixture, NULL, a_setup, a_before, a_after, a_teardown);

ZTEST_F(a_fixture, test_1_first)
{
	zassert_equal_ptr(fixture, &fixture_storage, "setup's return value is the fixture");
	zassert_equal(fixture->setup_calls, 1);
	zassert_equal(fixture->before_calls, 1);
	zassert_equal(fixture->after_calls, 0);
	zassert_equal_ptr(fixture->before_thread, k_current_get(),
			  "before runs in the test thread");
}

ZTEST_F(a_fixture, test_2_second)
{
	zassert_equal(fixture->setup_calls, 1, "setup runs once per suite");
	zassert_equal(fixture->before_calls, 2);
	zassert_equal(fixture->after_calls, 1, "after ran after the first test");
}

ZTEST_USER_F(a_fixture, test_3_user)
{
	zassert_equal(fixture->before_calls, 3);
}

/* ---- b_endings: how a test ends ---- */

static bool reached_after_assert;
static bool reached_after_expect;
static bool reached_after_pass;
static bool reached_after_helper_failure;
static int b_after_calls;

static void b_after(void *f)
{
	ARG_UNUSED(f);
	b_after_calls++;
}

ZTEST_SUITE(b_endings, NULL, NULL, NULL, b_after, NULL);

ZTEST(b_endings, test_1_assert_ends_test)
{
	zassert_equal(1, 2, "deliberate: %d", 42);
	reached_after_assert = true;
}
ZTEST_EXPECT_FAIL(b_endings, test_1_assert_ends_test);

ZTEST(b_endings, test_2_expect_goes_on)
{
	zexpect_equal(1, 2, "deliberate");
	zexpect_true(false);
	reached_after_expect = true;
}
ZTEST_EXPECT_FAIL(b_endings, test_2_expect_goes_on);

ZTEST(b_endings, test_3_assume_skips)
{
	zassume_true(false, "deliberate");
	ztest_test_fail();
}
ZTEST_EXPECT_SKIP(b_endings, test_3_assume_skips);

ZTEST(b_endings, test_4_explicit_skip)
{
	ztest_test_skip();
	ztest_test_fail();
}
ZTEST_EXPECT_SKIP(b_endings, test_4_explicit_skip);

ZTEST(b_endings, test_5_explicit_pass)
{
	ztest_test_pass();
	reached_after_pass = true;
	ztest_test_fail();
}

static K_THREAD_STACK_DEFINE(helper_stack, 2048);
static struct k_thread helper;

static void failing_helper(void *p1, void *p2, void *p3)
{
	zassert_unreachable("deliberate failure in a helper thread");
}

ZTEST(b_endings, test_6_helper_thread_failure)
{
	k_thread_create(&helper, helper_stack, K_THREAD_STACK_SIZEOF(helper_stack), failing_helper,
			NULL, NULL, NULL, 5, 0, K_NO_WAIT);
	/* The helper's failure ends this thread while it waits here. */
	(void)k_thread_join(&helper, K_FOREVER);
	reached_after_helper_failure = true;
}
ZTEST_EXPECT_FAIL(b_endings, test_6_helper_thread_failure);

ZTEST(b_endings, test_7_check)
{
	zassert_false(reached_after_assert, "a failed assertion ends the test");
	zassert_true(reached_after_expect, "a failed expectation does not");
	zassert_false(reached_after_pass, "ztest_test_pass() ends the test");
	zassert_false(reached_after_helper_failure, "a helper's failure ends the test thread");
	zassert_equal(b_after_calls, 6, "after runs after every test, failed or not");
	zassert_true(a_teardown_done, "the previous suite's teardown ran");
}

/* ---- c_rejected: a suite whose predicate says no ---- */

static bool never(const void *state)
{
	ARG_UNUSED(state);
	return false;
}

ZTEST_SUITE(c_rejected, never, NULL, NULL, NULL, NULL);

ZTEST(c_rejected, test_never_runs)
{
	ztest_test_fail();
}

/* ---- d_asserts: every assertion macro, passing ---- */

ZTEST_SUITE(d_asserts, NULL, NULL, NULL, NULL, NULL);

ZTEST(d_asserts, test_all_pass)
{
	int x = 5;
	const char buf[] = "abc";

	zassert_true(x == 5);
	zassert_false(x == 4, "with a message %d", x);
	zassert_ok(0);
	zassert_not_ok(-EIO);
	zassert_is_null(NULL);
	zassert_not_null(&x);
	zassert_equal(x, 5);
	zassert_not_equal(x, 6);
	zassert_equal_ptr(&x, &x);
	zassert_within(x, 7, 2);
	zassert_between_inclusive(x, 5, 5);
	zassert_mem_equal(buf, "abc", 4);
	zassert_str_equal(buf, "abc");
	zassume_true(true);
	zexpect_equal(x, 5);
	TC_PRINT("TC_PRINT reaches the console\n");
}
