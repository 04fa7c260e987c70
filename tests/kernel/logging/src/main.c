/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Logging: compile-time filtering by module level. A filtered call must not evaluate its
 * arguments, so each call increments a counter in its arguments: the counter shows which
 * calls were compiled in. The pytest harness (pytest/) checks the console side.
 */

#include <zephyr/logging/log.h>
#include <zephyr/ztest.h>

#include "logging_test.h"

/* Level from Kconfig: CONFIG_TEST_LOGGING_LOG_LEVEL_WRN=y in prj.conf. */
LOG_MODULE_REGISTER(test_logging, CONFIG_TEST_LOGGING_LOG_LEVEL);

ZTEST_SUITE(kernel_logging, NULL, NULL, NULL, NULL, NULL);

static int evaluated;

static int count(void)
{
	return ++evaluated;
}

static const uint8_t *count_data(const uint8_t *data)
{
	evaluated++;
	return data;
}

ZTEST(kernel_logging, test_kconfig_template)
{
	zassert_equal(CONFIG_TEST_LOGGING_LOG_LEVEL, LOG_LEVEL_WRN);
	zassert_equal(CONFIG_LOG_DEFAULT_LEVEL, LOG_LEVEL_INF);
}

ZTEST(kernel_logging, test_module_level_filters_at_compile_time)
{
	static const uint8_t bytes[4] = {0xde, 0xad, 0xbe, 0xef};

	evaluated = 0;
	LOG_ERR("main err %d", count());
	LOG_WRN("main wrn %d", count());
	zassert_equal(evaluated, 2, "error and warning are compiled in");

	LOG_INF("main inf %d FILTERED", count());
	LOG_DBG("main dbg %d FILTERED", count());
	LOG_HEXDUMP_INF(count_data(bytes), sizeof(bytes), "main hexdump FILTERED");
	zassert_equal(evaluated, 2, "info and debug are compiled out: arguments not evaluated");

	LOG_HEXDUMP_WRN(count_data(bytes), sizeof(bytes), "main hexdump wrn");
	zassert_equal(evaluated, 3);
}

ZTEST(kernel_logging, test_other_files)
{
	/* other.c: the same module at debug level, and a module of its own from LOG_LEVEL. */
	zassert_equal(log_from_declared_module(), 4, "every level of the declaring file");
	zassert_equal(log_from_log_level_module(), 1, "LOG_LEVEL = LOG_LEVEL_ERR: errors only");
	zassert_equal(log_from_default_module(), 3, "default level (info): err, wrn, inf");
}

#define LOGGERS   4
#define LOG_LINES 50

static K_THREAD_STACK_ARRAY_DEFINE(stacks, LOGGERS, 4096);
static struct k_thread threads[LOGGERS];

static void logger_entry(void *p1, void *p2, void *p3)
{
	int id = POINTER_TO_INT(p1);

	for (int i = 0; i < LOG_LINES; i++) {
		LOG_WRN("concurrent thread=%d line=%d payload=%s", id, i,
			"0123456789abcdefghijklmnopqrstuvwxyz");
	}
}

ZTEST(kernel_logging, test_concurrent_logging)
{
	for (int i = 0; i < LOGGERS; i++) {
		k_thread_create(&threads[i], stacks[i], 4096, logger_entry, INT_TO_POINTER(i), NULL,
				NULL, 5, 0, K_NO_WAIT);
	}
	for (int i = 0; i < LOGGERS; i++) {
		zassert_ok(k_thread_join(&threads[i], K_SECONDS(30)));
	}
}
