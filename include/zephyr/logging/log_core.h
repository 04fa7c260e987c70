/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Logging internals behind log.h, as Zephyr's logging/log_core.h.
 */

#ifndef ZEPHYR_INCLUDE_LOGGING_LOG_CORE_H_
#define ZEPHYR_INCLUDE_LOGGING_LOG_CORE_H_

#include <stddef.h>
#include <stdint.h>

#include <zephyr/sys/util.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @name Log levels */
/** @{ */
#define LOG_LEVEL_NONE 0U
#define LOG_LEVEL_ERR  1U
#define LOG_LEVEL_WRN  2U
#define LOG_LEVEL_INF  3U
#define LOG_LEVEL_DBG  4U
/** @} */

/** @cond INTERNAL_HIDDEN */

/* Constant data of a log source (one per LOG_MODULE_REGISTER()). */
struct log_source_const_data {
	const char *name;
	uint8_t level;
};

#define Z_LOG_ITEM_CONST_DATA(_name) UTIL_CAT(log_const_, _name)

/*
 * Whether LOG_LEVEL is defined to a level (0..4, with or without U): selects LOG_LEVEL as a
 * module's default level over CONFIG_LOG_DEFAULT_LEVEL, as in Zephyr.
 */
#define Z_LOG_ISNUM_0             Z_YYYY,
#define Z_LOG_ISNUM_1             Z_YYYY,
#define Z_LOG_ISNUM_2             Z_YYYY,
#define Z_LOG_ISNUM_3             Z_YYYY,
#define Z_LOG_ISNUM_4             Z_YYYY,
#define Z_LOG_ISNUM_0U            Z_YYYY,
#define Z_LOG_ISNUM_1U            Z_YYYY,
#define Z_LOG_ISNUM_2U            Z_YYYY,
#define Z_LOG_ISNUM_3U            Z_YYYY,
#define Z_LOG_ISNUM_4U            Z_YYYY,
#define Z_LOG_EVAL1(_lvl, _t, _f) Z_COND_CODE(Z_LOG_ISNUM_##_lvl, _t, _f)
#define Z_LOG_EVAL(_lvl, _t, _f)  Z_LOG_EVAL1(_lvl, _t, _f)

#define Z_LOG_DEFAULT_LEVEL Z_LOG_EVAL(LOG_LEVEL, (LOG_LEVEL), (CONFIG_LOG_DEFAULT_LEVEL))

/* The level given to LOG_MODULE_REGISTER(name[, level]), else the default one, raised to
 * CONFIG_LOG_OVERRIDE_LEVEL.
 */
#define Z_LOG_ARG2(_a, _b, ...) _b
#define Z_LOG_RESOLVED_LEVEL(...)                                                                  \
	MAX(Z_LOG_ARG2(__VA_ARGS__, Z_LOG_DEFAULT_LEVEL, _), CONFIG_LOG_OVERRIDE_LEVEL)
#define Z_LOG_ARG1(_a, ...) _a

/* Compile-time filter: false folds the call away, arguments unevaluated. */
#define Z_LOG_CONST_LEVEL_CHECK(_level)                                                            \
	(IS_ENABLED(CONFIG_LOG) && ((uint32_t)(_level) <= __log_level) &&                          \
	 ((_level) <= CONFIG_LOG_MAX_LEVEL))

/* Never called: keeps the arguments type-checked (and "used") when logging is off. */
static inline __printf_like(1, 2) void z_log_printf_arg_checker(const char *fmt, ...)
{
	ARG_UNUSED(fmt);
}

void z_log_printf(const struct log_source_const_data *source, uint8_t level, const char *func,
		  const char *fmt, ...) __printf_like(4, 5);
void z_log_hexdump(const struct log_source_const_data *source, uint8_t level, const void *data,
		   size_t length, const char *str);

#if defined(CONFIG_LOG)

#define Z_LOG(_level, ...)                                                                         \
	do {                                                                                       \
		if (Z_LOG_CONST_LEVEL_CHECK(_level)) {                                             \
			z_log_printf(__log_current_const_data, (_level), __func__, __VA_ARGS__);   \
		}                                                                                  \
	} while (false)

#define Z_LOG_HEXDUMP(_level, _data, _length, _str)                                                \
	do {                                                                                       \
		if (Z_LOG_CONST_LEVEL_CHECK(_level)) {                                             \
			z_log_hexdump(__log_current_const_data, (_level), (_data), (_length),      \
				      (_str));                                                     \
		}                                                                                  \
	} while (false)

#else /* !CONFIG_LOG */

#define Z_LOG(_level, ...)                                                                         \
	do {                                                                                       \
		if (false) {                                                                       \
			z_log_printf_arg_checker(__VA_ARGS__);                                     \
		}                                                                                  \
	} while (false)

#define Z_LOG_HEXDUMP(_level, _data, _length, _str)                                                \
	do {                                                                                       \
		if (false) {                                                                       \
			(void)(_data);                                                             \
			(void)(_length);                                                           \
			z_log_printf_arg_checker("%s", (_str));                                    \
		}                                                                                  \
	} while (false)

#endif /* CONFIG_LOG */

/** @endcond */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_LOGGING_LOG_CORE_H_ */
