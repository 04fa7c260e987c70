/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The ztest runner: Zephyr's control flow and console output.
 *
 * Suites and tests register from constructors into lists sorted by name (Zephyr sorts them
 * the same way through its linker sections). Each test runs in ztest_thread; ending a test
 * early (failed assertion, ztest_test_pass/skip) aborts that thread, and from any other
 * thread of the test also aborts the caller. The runner, in the main thread, joins the test
 * thread, runs the suite's after function and prints the result.
 *
 * The result of the running test is shared between the test's threads and the runner:
 * atomic_t, so reads and writes from several threads are defined.
 */

#include <stdio.h>
#include <string.h>

#include <zephyr/random/random.h>
#include <zephyr/ztest.h>

#ifdef CONFIG_ZTEST_SHUFFLE
#define NUM_ITER_PER_SUITE CONFIG_ZTEST_SHUFFLE_SUITE_REPEAT_COUNT
#define NUM_ITER_PER_TEST  CONFIG_ZTEST_SHUFFLE_TEST_REPEAT_COUNT
#else
#define NUM_ITER_PER_SUITE 1
#define NUM_ITER_PER_TEST  1
#endif

#ifdef CONFIG_ZTEST_FAIL_FAST
#define FAIL_FAST 1
#else
#define FAIL_FAST 0
#endif

enum ztest_status {
	ZTEST_STATUS_OK,
	ZTEST_STATUS_HAS_FAILURE,
	ZTEST_STATUS_CRITICAL_ERROR
};

enum ztest_phase {
	TEST_PHASE_SETUP,
	TEST_PHASE_BEFORE,
	TEST_PHASE_TEST,
	TEST_PHASE_AFTER,
	TEST_PHASE_TEARDOWN,
	TEST_PHASE_FRAMEWORK
};

enum ztest_result {
	ZTEST_RESULT_PENDING,
	ZTEST_RESULT_PASS,
	ZTEST_RESULT_FAIL,
	ZTEST_RESULT_SKIP,
	ZTEST_RESULT_SUITE_SKIP,
	ZTEST_RESULT_SUITE_FAIL,
};

static struct ztest_suite_node *suite_list;
static struct ztest_unit_test *test_list;
static struct ztest_expected_result_entry *expectation_list;

static struct k_thread ztest_thread;
static K_THREAD_STACK_DEFINE(ztest_thread_stack, CONFIG_ZTEST_STACK_SIZE);

static atomic_t test_status = ATOMIC_INIT(ZTEST_STATUS_OK);
static atomic_t cur_phase = ATOMIC_INIT(TEST_PHASE_FRAMEWORK);
static atomic_t test_result = ATOMIC_INIT(ZTEST_RESULT_PENDING);
static atomic_t failed_expectation;

/* ------------------------------------------------------------------------------------------ */
/* Registration (constructors, before main()) */

void z_ztest_register_suite(struct ztest_suite_node *suite)
{
	struct ztest_suite_node **pos = &suite_list;

	while (*pos != NULL && strcmp((*pos)->name, suite->name) <= 0) {
		pos = &(*pos)->next;
	}
	suite->next = *pos;
	*pos = suite;
}

static int test_cmp(const struct ztest_unit_test *a, const struct ztest_unit_test *b)
{
	int c = strcmp(a->test_suite_name, b->test_suite_name);

	return (c != 0) ? c : strcmp(a->name, b->name);
}

void z_ztest_register_test(struct ztest_unit_test *test)
{
	struct ztest_unit_test **pos = &test_list;

	while (*pos != NULL && test_cmp(*pos, test) <= 0) {
		pos = &(*pos)->next;
	}
	test->next = *pos;
	*pos = test;
}

void z_ztest_register_expectation(struct ztest_expected_result_entry *entry)
{
	entry->next = expectation_list;
	expectation_list = entry;
}

static struct ztest_suite_node *find_suite(const char *name)
{
	for (struct ztest_suite_node *s = suite_list; s != NULL; s = s->next) {
		if (strcmp(s->name, name) == 0) {
			return s;
		}
	}

	return NULL;
}

static struct ztest_unit_test *next_test(const char *suite, struct ztest_unit_test *prev)
{
	for (struct ztest_unit_test *t = (prev == NULL) ? test_list : prev->next; t != NULL;
	     t = t->next) {
		if (strcmp(t->test_suite_name, suite) == 0) {
			return t;
		}
	}

	return NULL;
}

/* ------------------------------------------------------------------------------------------ */
/* Assertions */

const char *ztest_relative_filename(const char *file)
{
	static const char *const roots[] = {"/tests/", "/samples/", "/subsys/", "/drivers/"};

	/* Print paths from the tree's top folders, not the build machine's absolute path. */
	for (size_t i = 0; i < ARRAY_SIZE(roots); i++) {
		const char *p = strstr(file, roots[i]);

		if (p != NULL) {
			return p + 1;
		}
	}

	return file;
}

bool z_zcheck_report(bool cond, const char *kind, const char *default_msg, const char *file,
		     int line, const char *func, const char *msg, ...)
{
	char text[512];
	va_list ap;
	int len;

	if (cond) {
		return true;
	}

	/* One printk per report, so that it stays in one piece among other threads' output. */
	len = snprintk(text, sizeof(text), "\n    %s failed at %s:%d: %s: %s\n", kind,
		       ztest_relative_filename(file), line, func, default_msg);
	if (len >= 0 && (size_t)len < sizeof(text)) {
		va_start(ap, msg);
		(void)vsnprintk(&text[len], sizeof(text) - (size_t)len, msg, ap);
		va_end(ap);
	}
	printk("%s\n", text);

	return false;
}

static const char *phase_name(long phase)
{
	switch (phase) {
	case TEST_PHASE_SETUP:
		return "setup";
	case TEST_PHASE_BEFORE:
		return "before";
	case TEST_PHASE_TEST:
		return "test";
	case TEST_PHASE_AFTER:
		return "after";
	case TEST_PHASE_TEARDOWN:
		return "teardown";
	default:
		return "framework";
	}
}

/* End the test: its thread, and the calling thread if that is another one. */
static void test_finalize(void)
{
	k_thread_abort(&ztest_thread);
	if (k_is_in_isr()) {
		return;
	}
	k_thread_abort(k_current_get());
	CODE_UNREACHABLE;
}

static void bad_phase(const char *what)
{
	PRINT_DATA(" ERROR: cannot %s in test phase '%s()', bailing\n", what,
		   phase_name(atomic_get(&cur_phase)));
	atomic_set(&test_status, ZTEST_STATUS_CRITICAL_ERROR);
}

void ztest_test_fail(void)
{
	switch (atomic_get(&cur_phase)) {
	case TEST_PHASE_SETUP:
		atomic_set(&test_result, ZTEST_RESULT_SUITE_FAIL);
		break;
	case TEST_PHASE_BEFORE:
	case TEST_PHASE_TEST:
		atomic_set(&test_result, ZTEST_RESULT_FAIL);
		test_finalize();
		break;
	default:
		bad_phase("fail");
		break;
	}
}

void ztest_test_pass(void)
{
	if (atomic_get(&cur_phase) == TEST_PHASE_TEST) {
		atomic_set(&test_result, ZTEST_RESULT_PASS);
		test_finalize();
	} else {
		bad_phase("pass");
	}
}

void ztest_test_skip(void)
{
	switch (atomic_get(&cur_phase)) {
	case TEST_PHASE_SETUP:
		atomic_set(&test_result, ZTEST_RESULT_SUITE_SKIP);
		break;
	case TEST_PHASE_BEFORE:
	case TEST_PHASE_TEST:
		atomic_set(&test_result, ZTEST_RESULT_SKIP);
		test_finalize();
		break;
	default:
		bad_phase("skip");
		break;
	}
}

void ztest_test_expect_fail(void)
{
	atomic_set(&failed_expectation, 1);
}

void ztest_skip_failed_assumption(void)
{
	ztest_test_skip();
}

/* ------------------------------------------------------------------------------------------ */
/* Running */

static void test_cb(void *a, void *b, void *c)
{
	struct ztest_suite_node *suite = a;
	struct ztest_unit_test *test = b;

	atomic_set(&test_result, ZTEST_RESULT_PENDING);
	if (suite->before != NULL) {
		suite->before(c);
	}
	atomic_set(&cur_phase, TEST_PHASE_TEST);
	test->test(c);
	atomic_set(&test_result, ZTEST_RESULT_PASS);
}

static int final_result(const struct ztest_unit_test *test, int ret)
{
	for (struct ztest_expected_result_entry *e = expectation_list; e != NULL; e = e->next) {
		if (strcmp(e->test_name, test->name) != 0 ||
		    strcmp(e->test_suite_name, test->test_suite_name) != 0) {
			continue;
		}
		if (e->expected_result == ZTEST_EXPECTED_RESULT_FAIL) {
			return (ret == TC_FAIL) ? TC_PASS : TC_FAIL;
		}
		return (ret == TC_SKIP) ? TC_PASS : TC_FAIL;
	}

	return ret;
}

static int run_test(struct ztest_suite_node *suite, struct ztest_unit_test *test, void *data)
{
	long result = atomic_get(&test_result);
	uint64_t start;
	uint32_t duration_ms;
	int ret = TC_PASS;

	TC_START(test->name);
	atomic_set(&cur_phase, TEST_PHASE_BEFORE);
	start = k_cycle_get_64();

	/* A setup function that skipped or failed the suite leaves its tests unrun. */
	if (result != ZTEST_RESULT_SUITE_SKIP && result != ZTEST_RESULT_SUITE_FAIL) {
		(void)k_thread_create(&ztest_thread, ztest_thread_stack,
				      K_THREAD_STACK_SIZEOF(ztest_thread_stack), test_cb, suite,
				      test, data, CONFIG_ZTEST_THREAD_PRIORITY,
				      test->thread_options | K_INHERIT_PERMS, K_FOREVER);
		(void)k_thread_name_set(&ztest_thread, test->name);
		k_thread_start(&ztest_thread);
		(void)k_thread_join(&ztest_thread, K_FOREVER);
	}

	atomic_set(&cur_phase, TEST_PHASE_AFTER);
	if (suite->after != NULL) {
		suite->after(data);
	}
	duration_ms = (uint32_t)k_cyc_to_ms_ceil64(k_cycle_get_64() - start);
	if (duration_ms > test->stats->duration_worst_ms) {
		test->stats->duration_worst_ms = duration_ms;
	}
	atomic_set(&cur_phase, TEST_PHASE_FRAMEWORK);

	result = atomic_get(&test_result);
	if (atomic_set(&failed_expectation, 0) != 0 || result == ZTEST_RESULT_FAIL ||
	    result == ZTEST_RESULT_SUITE_FAIL) {
		ret = TC_FAIL;
	} else if (result == ZTEST_RESULT_SKIP || result == ZTEST_RESULT_SUITE_SKIP) {
		ret = TC_SKIP;
	}

	ret = final_result(test, ret);
	Z_TC_END_RESULT(ret, test->name, duration_ms);

	return ret;
}

static void shuffle(void **items, size_t n)
{
	for (size_t i = n; i > 1U; i--) {
		size_t j = sys_rand32_get() % i;
		void *tmp = items[i - 1U];

		items[i - 1U] = items[j];
		items[j] = tmp;
	}
}

static int run_suite(struct ztest_suite_node *suite, bool shuffled, int case_iter)
{
	struct ztest_unit_test *tests[CONFIG_ZTEST_MAX_TESTS_PER_SUITE];
	size_t count = 0;
	void *data = NULL;
	int fail = 0;

	if (FAIL_FAST && atomic_get(&test_status) != ZTEST_STATUS_OK) {
		return 0;
	}

	for (struct ztest_unit_test *t = next_test(suite->name, NULL); t != NULL;
	     t = next_test(suite->name, t)) {
		if (count == ARRAY_SIZE(tests)) {
			PRINT_DATA("ERROR: suite %s has more than CONFIG_ZTEST_MAX_TESTS_PER_SUITE "
				   "tests\n",
				   suite->name);
			atomic_set(&test_status, ZTEST_STATUS_CRITICAL_ERROR);
			return 1;
		}
		tests[count++] = t;
	}

	TC_SUITE_START(suite->name);
	atomic_set(&test_result, ZTEST_RESULT_PENDING);
	atomic_set(&cur_phase, TEST_PHASE_SETUP);
	if (suite->setup != NULL) {
		data = suite->setup();
	}

	for (int i = 0; i < case_iter; i++) {
		if (shuffled) {
			shuffle((void **)tests, count);
		}
		for (size_t j = 0; j < count; j++) {
			struct ztest_unit_test *test = tests[j];
			int rc;

			test->stats->run_count++;
			rc = run_test(suite, test, data);
			if (rc == TC_PASS) {
				test->stats->pass_count++;
			} else if (rc == TC_SKIP) {
				test->stats->skip_count++;
			} else {
				test->stats->fail_count++;
				fail++;
			}
			if ((fail != 0 && FAIL_FAST) ||
			    atomic_get(&test_status) == ZTEST_STATUS_CRITICAL_ERROR) {
				break;
			}
		}
		if (fail != 0) {
			(void)atomic_cas(&test_status, ZTEST_STATUS_OK, ZTEST_STATUS_HAS_FAILURE);
		}
	}

	TC_SUITE_END(suite->name, (fail > 0) ? TC_FAIL : TC_PASS);
	atomic_set(&cur_phase, TEST_PHASE_TEARDOWN);
	if (suite->teardown != NULL) {
		suite->teardown(data);
	}
	atomic_set(&cur_phase, TEST_PHASE_FRAMEWORK);

	return fail;
}

int z_ztest_run_test_suite(const char *name, bool shuffled, int suite_iter, int case_iter,
			   void *param)
{
	struct ztest_suite_node *suite = find_suite(name);
	int fail = 0;

	ARG_UNUSED(param);
	if (suite == NULL) {
		atomic_set(&test_status, ZTEST_STATUS_CRITICAL_ERROR);
		return -1;
	}
	for (int i = 0; i < suite_iter; i++) {
		int f = run_suite(suite, shuffled, case_iter);

		suite->stats->run_count++;
		suite->stats->fail_count += (f != 0) ? 1U : 0U;
		fail += f;
	}

	return fail;
}

void ztest_run_all(const void *state, bool shuffled, int suite_iter, int case_iter)
{
	struct ztest_suite_node *suites[CONFIG_ZTEST_MAX_SUITES];
	size_t count = 0;

	for (struct ztest_suite_node *s = suite_list; s != NULL && count < ARRAY_SIZE(suites);
	     s = s->next) {
		suites[count++] = s;
	}
	if (shuffled) {
		shuffle((void **)suites, count);
	}

	for (size_t i = 0; i < count; i++) {
		struct ztest_suite_node *suite = suites[i];

		for (int j = 0; j < suite_iter; j++) {
			if (suite->predicate == NULL || suite->predicate(state)) {
				int fail = run_suite(suite, shuffled, case_iter);

				suite->stats->run_count++;
				suite->stats->fail_count += (fail != 0) ? 1U : 0U;
			} else {
				suite->stats->skip_count++;
			}
		}
		if (atomic_get(&test_status) == ZTEST_STATUS_CRITICAL_ERROR ||
		    (atomic_get(&test_status) == ZTEST_STATUS_HAS_FAILURE && FAIL_FAST)) {
			break;
		}
	}
}

void ztest_verify_all_test_suites_ran(void)
{
	bool all_ran = true;

	if (IS_ENABLED(CONFIG_ZTEST_VERIFY_RUN_ALL)) {
		for (struct ztest_suite_node *s = suite_list; s != NULL; s = s->next) {
			if (s->stats->run_count < 1U) {
				PRINT_DATA("ERROR: Test suite '%s' did not run.\n", s->name);
				all_ran = false;
			}
		}
		for (struct ztest_unit_test *t = test_list; t != NULL; t = t->next) {
			if (find_suite(t->test_suite_name) == NULL) {
				PRINT_DATA("ERROR: Test '%s' assigned to test suite '%s' which "
					   "doesn't exist\n",
					   t->name, t->test_suite_name);
				all_ran = false;
			}
		}
		if (!all_ran) {
			(void)atomic_cas(&test_status, ZTEST_STATUS_OK, ZTEST_STATUS_HAS_FAILURE);
		}
	}
}

/* ------------------------------------------------------------------------------------------ */
/* Summary */

static int test_summary_result(const struct ztest_unit_test_stats *st)
{
	if (st->skip_count == st->run_count) {
		return TC_SKIP;
	}
	if (st->pass_count + st->skip_count == st->run_count) {
		return TC_PASS;
	}

	return (st->pass_count == 0U) ? TC_FAIL : TC_FLAKY;
}

static void show_suite_summary(struct ztest_suite_node *suite)
{
	int pass = 0;
	int fail = 0;
	int skip = 0;
	int total = 0;
	int major = 0;
	int minor = 0;
	int suite_result;
	unsigned int duration_ms = 0;

	for (struct ztest_unit_test *t = next_test(suite->name, NULL); t != NULL;
	     t = next_test(suite->name, t)) {
		int r = test_summary_result(t->stats);

		total++;
		duration_ms += t->stats->duration_worst_ms;
		if (r == TC_SKIP) {
			skip++;
		} else if (r == TC_PASS) {
			pass++;
		} else {
			fail++;
		}
	}

	if (skip == total) {
		suite_result = TC_SKIP;
	} else {
		/* Pass rate with two decimals, rounded half up: %3d.%02d%%. */
		int rate = pass * 100000 / (total - skip);

		suite_result = (fail > 0) ? TC_FAIL : TC_PASS;
		major = rate / 1000;
		minor = (rate % 1000) / 10;
		if (rate % 10 >= 5) {
			minor++;
		}
		if (minor == 100) {
			major++;
			minor = 0;
		}
	}

	TC_SUMMARY_PRINT("SUITE %s - %3d.%02d%% [%s]: pass = %d, fail = %d, skip = %d, total = %d "
			 "duration = %u.%03u seconds\n",
			 TC_RESULT_TO_STR(suite_result), major, minor, suite->name, pass, fail,
			 skip, total, duration_ms / 1000U, duration_ms % 1000U);

	if (!IS_ENABLED(CONFIG_ZTEST_VERBOSE_SUMMARY)) {
		return;
	}
	for (struct ztest_unit_test *t = next_test(suite->name, NULL); t != NULL;
	     t = next_test(suite->name, t)) {
		const struct ztest_unit_test_stats *st = t->stats;
		int r = test_summary_result(st);

		if (r == TC_FLAKY) {
			TC_SUMMARY_PRINT(
				" - %s - [%s.%s] - (Failed %u of %u attempts) - duration = "
				"%u.%03u seconds\n",
				TC_RESULT_TO_STR(r), t->test_suite_name, t->name,
				st->run_count - st->pass_count, st->run_count,
				st->duration_worst_ms / 1000U, st->duration_worst_ms % 1000U);
		} else {
			TC_SUMMARY_PRINT(" - %s - [%s.%s] duration = %u.%03u seconds\n",
					 TC_RESULT_TO_STR(r), t->test_suite_name, t->name,
					 st->duration_worst_ms / 1000U,
					 st->duration_worst_ms % 1000U);
		}
	}
	TC_SUMMARY_PRINT("\n");
}

static void end_report(void)
{
	if (IS_ENABLED(CONFIG_ZTEST_SUMMARY)) {
		TC_SUMMARY_PRINT("\n------ TESTSUITE SUMMARY START ------\n\n");
		for (struct ztest_suite_node *s = suite_list; s != NULL; s = s->next) {
			show_suite_summary(s);
		}
		TC_SUMMARY_PRINT("------ TESTSUITE SUMMARY END ------\n\n");
	}
	TC_END_REPORT((atomic_get(&test_status) == ZTEST_STATUS_OK) ? TC_PASS : TC_FAIL);
}

__weak void test_main(void)
{
	ztest_run_all(NULL, IS_ENABLED(CONFIG_ZTEST_SHUFFLE), NUM_ITER_PER_SUITE,
		      NUM_ITER_PER_TEST);
	ztest_verify_all_test_suites_ran();
}

int main(void)
{
	test_main();
	end_report();

	/* The image's exit code is the verdict: 0 only if nothing failed. */
	return (atomic_get(&test_status) == ZTEST_STATUS_OK) ? 0 : 1;
}
