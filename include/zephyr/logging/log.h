/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Logging API, as Zephyr's logging/log.h.
 *
 * A file registers (or joins) a log module and logs with LOG_ERR()..LOG_DBG():
 *
 *     LOG_MODULE_REGISTER(canopen_sdo, CONFIG_CANOPEN_LOG_LEVEL);
 *     LOG_INF("node %u booted", node_id);
 *
 * prints "[00:00:01.234,567] <inf> canopen_sdo: node 5 booted" on the console. Messages
 * above the module's level are removed at compile time: their arguments are not evaluated.
 * Messages are written at once by the calling thread (Zephyr's immediate mode), each with a
 * single write, so lines from different threads never mix.
 */

#ifndef ZEPHYR_INCLUDE_LOGGING_LOG_H_
#define ZEPHYR_INCLUDE_LOGGING_LOG_H_

#include <zephyr/logging/log_core.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @defgroup logging_api Logging
 * @{
 */

/** Log an error (printf-style). */
#define LOG_ERR(...) Z_LOG(LOG_LEVEL_ERR, __VA_ARGS__)
/** Log a warning (printf-style). */
#define LOG_WRN(...) Z_LOG(LOG_LEVEL_WRN, __VA_ARGS__)
/** Log an informational message (printf-style). */
#define LOG_INF(...) Z_LOG(LOG_LEVEL_INF, __VA_ARGS__)
/** Log a debug message (printf-style), prefixed with the function name. */
#define LOG_DBG(...) Z_LOG(LOG_LEVEL_DBG, __VA_ARGS__)

/** Log @p _str and @p _length bytes of @p _data in hex and ASCII, as an error. */
#define LOG_HEXDUMP_ERR(_data, _length, _str) Z_LOG_HEXDUMP(LOG_LEVEL_ERR, _data, _length, _str)
/** As LOG_HEXDUMP_ERR(), as a warning. */
#define LOG_HEXDUMP_WRN(_data, _length, _str) Z_LOG_HEXDUMP(LOG_LEVEL_WRN, _data, _length, _str)
/** As LOG_HEXDUMP_ERR(), as information. */
#define LOG_HEXDUMP_INF(_data, _length, _str) Z_LOG_HEXDUMP(LOG_LEVEL_INF, _data, _length, _str)
/** As LOG_HEXDUMP_ERR(), as debug. */
#define LOG_HEXDUMP_DBG(_data, _length, _str) Z_LOG_HEXDUMP(LOG_LEVEL_DBG, _data, _length, _str)

#if defined(CONFIG_LOG)

/**
 * @brief Register a log module and use it in this file.
 *
 * @param ... The module name (a C identifier), optionally followed by its level (e.g.
 *            CONFIG_FOO_LOG_LEVEL); without one, LOG_LEVEL if the file defines it, else
 *            CONFIG_LOG_DEFAULT_LEVEL.
 */
#define LOG_MODULE_REGISTER(...)                                                                   \
	const struct log_source_const_data Z_LOG_ITEM_CONST_DATA(Z_LOG_ARG1(__VA_ARGS__, _)) = {   \
		.name = STRINGIFY(Z_LOG_ARG1(__VA_ARGS__, _)),                                      \
				  .level = Z_LOG_RESOLVED_LEVEL(__VA_ARGS__),                      \
	};                                                                                         \
	LOG_MODULE_DECLARE(__VA_ARGS__)

/**
 * @brief Use in this file a log module registered in another file.
 *
 * @param ... The module name, optionally followed by this file's level.
 */
#define LOG_MODULE_DECLARE(...)                                                                    \
	extern const struct log_source_const_data Z_LOG_ITEM_CONST_DATA(                           \
		Z_LOG_ARG1(__VA_ARGS__, _));                                                       \
	static const struct log_source_const_data *const __log_current_const_data __unused =       \
		&Z_LOG_ITEM_CONST_DATA(Z_LOG_ARG1(__VA_ARGS__, _));                                \
	static const uint32_t __log_level __unused = Z_LOG_RESOLVED_LEVEL(__VA_ARGS__)

#else /* !CONFIG_LOG */

#define LOG_MODULE_REGISTER(...) struct z_log_module_unused
#define LOG_MODULE_DECLARE(...)  struct z_log_module_unused

#endif /* CONFIG_LOG */

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_LOGGING_LOG_H_ */
