/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Console output, as Zephyr's sys/printk.h.
 *
 * On native_posix the console is the process's standard output. One printk() call is written
 * with a single write, so lines from different threads do not interleave.
 */

#ifndef ZEPHYR_INCLUDE_SYS_PRINTK_H_
#define ZEPHYR_INCLUDE_SYS_PRINTK_H_

#include <stdarg.h>
#include <stddef.h>

#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(CONFIG_PRINTK)

/** Print a formatted string to the console. */
void printk(const char *fmt, ...) __printf_like(1, 2);

/** Print a formatted string to the console from a va_list. */
void vprintk(const char *fmt, va_list ap);

#else

static inline __printf_like(1, 2) void printk(const char *fmt, ...)
{
	(void)fmt;
}

static inline void vprintk(const char *fmt, va_list ap)
{
	(void)fmt;
	(void)ap;
}

#endif

/**
 * @brief Format into @p str (at most @p size bytes including the terminator).
 *
 * @return The length the full output would have, as snprintf().
 */
int snprintk(char *str, size_t size, const char *fmt, ...) __printf_like(3, 4);

/** snprintk() from a va_list. */
int vsnprintk(char *str, size_t size, const char *fmt, va_list ap);

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_PRINTK_H_ */
