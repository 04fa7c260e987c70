/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * printk() on the process's standard output. A message is formatted first and written with
 * one stdio call, which locks the stream, so concurrent messages do not interleave.
 */

#include <stdarg.h>
#include <stdio.h>

#include <zephyr/sys/printk.h>

#if defined(CONFIG_PRINTK)

void vprintk(const char *fmt, va_list ap)
{
	char buf[256];
	va_list ap2;
	int len;

	va_copy(ap2, ap);
	len = vsnprintf(buf, sizeof(buf), fmt, ap);
	if (len >= 0 && (size_t)len < sizeof(buf)) {
		(void)fwrite(buf, 1, (size_t)len, stdout);
	} else if (len >= 0) {
		/* Too long for the buffer: print it under the stream's lock instead. */
		flockfile(stdout);
		(void)vfprintf(stdout, fmt, ap2);
		funlockfile(stdout);
	}
	va_end(ap2);
}

void printk(const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vprintk(fmt, ap);
	va_end(ap);
}

#endif /* CONFIG_PRINTK */

int vsnprintk(char *str, size_t size, const char *fmt, va_list ap)
{
	return vsnprintf(str, size, fmt, ap);
}

int snprintk(char *str, size_t size, const char *fmt, ...)
{
	va_list ap;
	int ret;

	va_start(ap, fmt);
	ret = vsnprintk(str, size, fmt, ap);
	va_end(ap);

	return ret;
}
