/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* A module whose level comes from LOG_LEVEL, defined before including log.h. */

#define LOG_LEVEL LOG_LEVEL_ERR
#include <zephyr/logging/log.h>

#include "logging_test.h"

LOG_MODULE_REGISTER(test_log_level);

int log_from_log_level_module(void)
{
	int n = 0;

	LOG_ERR("log_level err %d", ++n);
	LOG_WRN("log_level wrn %d FILTERED", ++n);
	LOG_INF("log_level inf %d FILTERED", ++n);
	LOG_DBG("log_level dbg %d FILTERED", ++n);

	return n;
}
