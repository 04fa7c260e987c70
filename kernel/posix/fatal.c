/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Fatal errors and failed assertions. The report starts with ">>> SAFELINE FATAL ERROR",
 * the marker the test runner looks for (Zephyr prints "ZEPHYR FATAL ERROR"), and goes to the
 * console (stdout) like every other message, even in an image built without printk().
 */

#include <stdarg.h>
#include <stdio.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

static __printf_like(1, 2) void fatal_print(const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	flockfile(stdout);
	(void)vfprintf(stdout, fmt, ap);
	funlockfile(stdout);
	(void)fflush(stdout);
	va_end(ap);
}

static const char *reason_to_str(unsigned int reason)
{
	switch (reason) {
	case K_ERR_CPU_EXCEPTION:
		return "CPU exception";
	case K_ERR_SPURIOUS_IRQ:
		return "Unhandled interrupt";
	case K_ERR_STACK_CHK_FAIL:
		return "Stack overflow";
	case K_ERR_KERNEL_OOPS:
		return "Kernel oops";
	case K_ERR_KERNEL_PANIC:
		return "Kernel panic";
	default:
		return "Unknown error";
	}
}

void k_fatal_halt(unsigned int reason)
{
	ARG_UNUSED(reason);
	posix_exit(1);
}

__weak void k_sys_fatal_error_handler(unsigned int reason, const struct arch_esf *esf)
{
	ARG_UNUSED(esf);

	fatal_print("Halting system\n");
	k_fatal_halt(reason);
}

void z_fatal_error(unsigned int reason, const struct arch_esf *esf)
{
	struct k_thread *cur = k_current_get();
	const char *name = k_thread_name_get(cur);

	fatal_print(">>> SAFELINE FATAL ERROR %u: %s on CPU 0\n", reason, reason_to_str(reason));
	fatal_print("Current thread: %p (%s)\n", (void *)cur, (name[0] != '\0') ? name : "unknown");
	k_sys_fatal_error_handler(reason, esf);
}

void z_except_reason(unsigned int reason)
{
	z_fatal_error(reason, NULL);
	/* The handler chose to let the system run on: only the faulting thread ends. */
	k_thread_abort(k_current_get());
	CODE_UNREACHABLE;
}

void assert_print(const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	flockfile(stdout);
	(void)vfprintf(stdout, fmt, ap);
	funlockfile(stdout);
	va_end(ap);
}

__weak void assert_post_action(const char *file, unsigned int line)
{
	ARG_UNUSED(file);
	ARG_UNUSED(line);

	k_panic();
}
