/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Joins main.c's module at its own (debug) level. */

#include <zephyr/logging/log.h>

#include "logging_test.h"

LOG_MODULE_DECLARE(test_logging, LOG_LEVEL_DBG);

static const uint8_t frame[20] = "SafeLine hexdump!\x01\x02\x7f";

int log_from_declared_module(void)
{
	int n = 0;

	LOG_ERR("declared err %d", ++n);
	LOG_WRN("declared wrn %d", ++n);
	LOG_INF("declared inf %d", ++n);
	LOG_DBG("declared dbg %d", ++n);
	LOG_HEXDUMP_DBG(frame, sizeof(frame), "declared hexdump");

	return n;
}
