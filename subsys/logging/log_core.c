/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Immediate-mode log output in Zephyr's text format:
 *
 *   [00:00:01.234,567] <inf> module: message
 *   [00:00:01.234,567] <dbg> module: function: message
 *   [00:00:01.234,567] <inf> module: hexdump title
 *                                    01 02 03 04 05 06 07 08  09 0a 0b |........ ...     |
 *
 * A whole message, hexdump lines included, is formatted into one buffer and written with a
 * single printk(), so concurrent messages never interleave.
 */

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/logging/log_ctrl.h>

#define HEXDUMP_BYTES_IN_LINE 16
#define LOG_BUF_SIZE          2048

#define COLOR_RED    "\x1B[1;31m"
#define COLOR_YELLOW "\x1B[1;33m"
#define COLOR_RESET  "\x1B[0m"

/* Formatting state of one message. */
struct log_line {
	char buf[LOG_BUF_SIZE];
	size_t len;
};

static void append_va(struct log_line *line, const char *fmt, va_list ap)
{
	size_t room = sizeof(line->buf) - line->len;
	int n = vsnprintk(&line->buf[line->len], room, fmt, ap);

	if (n > 0) {
		line->len += MIN((size_t)n, room - 1U);
	}
}

static __printf_like(2, 3) void append(struct log_line *line, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	append_va(line, fmt, ap);
	va_end(ap);
}

static const char *level_str(uint8_t level)
{
	static const char *const names[] = {"", "err", "wrn", "inf", "dbg"};

	return (level < ARRAY_SIZE(names)) ? names[level] : "???";
}

static bool func_prefix(uint8_t level)
{
	switch (level) {
	case LOG_LEVEL_ERR:
		return IS_ENABLED(CONFIG_LOG_FUNC_NAME_PREFIX_ERR);
	case LOG_LEVEL_WRN:
		return IS_ENABLED(CONFIG_LOG_FUNC_NAME_PREFIX_WRN);
	case LOG_LEVEL_INF:
		return IS_ENABLED(CONFIG_LOG_FUNC_NAME_PREFIX_INF);
	case LOG_LEVEL_DBG:
		return IS_ENABLED(CONFIG_LOG_FUNC_NAME_PREFIX_DBG);
	default:
		return false;
	}
}

/* Timestamp, colour, level and source; returns the width of the visible prefix. */
static size_t append_prefix(struct log_line *line, const struct log_source_const_data *source,
			    uint8_t level)
{
	uint64_t us = k_ticks_to_us_floor64((uint64_t)k_uptime_ticks());
	size_t start;

	if (IS_ENABLED(CONFIG_LOG_BACKEND_SHOW_COLOR)) {
		if (level == LOG_LEVEL_ERR) {
			append(line, COLOR_RED);
		} else if (level == LOG_LEVEL_WRN) {
			append(line, COLOR_YELLOW);
		}
	}
	start = line->len;

	if (IS_ENABLED(CONFIG_LOG_BACKEND_FORMAT_TIMESTAMP)) {
		uint64_t total_ms = us / USEC_PER_MSEC;
		uint64_t s = total_ms / MSEC_PER_SEC;

		append(line, "[%02u:%02u:%02u.%03u,%03u] ", (unsigned int)(s / 3600U),
		       (unsigned int)((s / 60U) % 60U), (unsigned int)(s % 60U),
		       (unsigned int)(total_ms % MSEC_PER_SEC), (unsigned int)(us % USEC_PER_MSEC));
	} else {
		append(line, "[%08llu] ", (unsigned long long)us);
	}
	append(line, "<%s> %s: ", level_str(level), source->name);

	return line->len - start;
}

static void emit(struct log_line *line, uint8_t level)
{
	if (IS_ENABLED(CONFIG_LOG_BACKEND_SHOW_COLOR) &&
	    (level == LOG_LEVEL_ERR || level == LOG_LEVEL_WRN)) {
		append(line, COLOR_RESET);
	}
	if (line->len == sizeof(line->buf) - 1U) {
		/* Truncated: still end the line. */
		line->buf[line->len - 1U] = '\n';
	}
	printk("%s", line->buf);
}

void z_log_printf(const struct log_source_const_data *source, uint8_t level, const char *func,
		  const char *fmt, ...)
{
	struct log_line line = {.len = 0};
	va_list ap;

	(void)append_prefix(&line, source, level);
	if (func_prefix(level)) {
		append(&line, "%s: ", func);
	}
	va_start(ap, fmt);
	append_va(&line, fmt, ap);
	va_end(ap);
	append(&line, "\n");
	emit(&line, level);
}

void z_log_hexdump(const struct log_source_const_data *source, uint8_t level, const void *data,
		   size_t length, const char *str)
{
	const uint8_t *bytes = data;
	struct log_line line = {.len = 0};
	size_t indent = append_prefix(&line, source, level);

	append(&line, "%s\n", (str != NULL) ? str : "");
	for (size_t off = 0; off < length; off += HEXDUMP_BYTES_IN_LINE) {
		size_t n = MIN(length - off, (size_t)HEXDUMP_BYTES_IN_LINE);

		append(&line, "%*s", (int)indent, "");
		for (size_t i = 0; i < HEXDUMP_BYTES_IN_LINE; i++) {
			if (i == HEXDUMP_BYTES_IN_LINE / 2U) {
				append(&line, " ");
			}
			if (i < n) {
				append(&line, "%02x ", bytes[off + i]);
			} else {
				append(&line, "   ");
			}
		}
		append(&line, "|");
		for (size_t i = 0; i < HEXDUMP_BYTES_IN_LINE; i++) {
			if (i == HEXDUMP_BYTES_IN_LINE / 2U) {
				append(&line, " ");
			}
			if (i < n) {
				char c = (char)bytes[off + i];

				append(&line, "%c", isprint((unsigned char)c) ? c : '.');
			} else {
				append(&line, " ");
			}
		}
		append(&line, "|\n");
	}
	emit(&line, level);
}

void log_panic(void)
{
	(void)fflush(stdout);
}

void log_flush(void)
{
	(void)fflush(stdout);
}
