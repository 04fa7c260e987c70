/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Logging control, as Zephyr's logging/log_ctrl.h.
 *
 * Messages are written when they are logged (immediate mode), so there is never anything
 * left to process: these calls only flush the console.
 */

#ifndef ZEPHYR_INCLUDE_LOGGING_LOG_CTRL_H_
#define ZEPHYR_INCLUDE_LOGGING_LOG_CTRL_H_

#include <zephyr/sys/util_macro.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Switch logging to panic mode: flush everything now. */
void log_panic(void);

/** @brief Write out pending messages. */
void log_flush(void);

/** Call log_panic() if logging is enabled. */
#define LOG_PANIC()                                                                                \
	do {                                                                                       \
		if (IS_ENABLED(CONFIG_LOG)) {                                                      \
			log_panic();                                                               \
		}                                                                                  \
	} while (false)

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_LOGGING_LOG_CTRL_H_ */
