/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* A module registered without a level: CONFIG_LOG_DEFAULT_LEVEL (info). */

#include <zephyr/logging/log.h>

#include "logging_test.h"

LOG_MODULE_REGISTER(test_log_default);

int log_from_default_module(void)
{
	int n = 0;

	LOG_ERR("default err %d", ++n);
	LOG_WRN("default wrn %d", ++n);
	LOG_INF("default inf %d", ++n);
	LOG_DBG("default dbg %d FILTERED", ++n);

	return n;
}
