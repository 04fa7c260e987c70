/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The process entry point of a native_posix image. Host code.
 *
 * The image is linked with --wrap=main: the C runtime calls __wrap_main() below, and the
 * firmware's own int main(void) (the application's, ztest's, or the kernel's weak one) is
 * reached as __real_main(), run by the kernel in the thread named "main". When it returns,
 * its value is the process's exit code.
 *
 * This thread then waits for --stop-at or a SIGINT/SIGTERM, whichever comes first.
 */

#include <errno.h>
#include <math.h>
#include <semaphore.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "cmdline.h"
#include "posix_board_if.h"
#include "posix_native_task.h"

int __real_main(void);
void z_cstart(int (*app_main)(void));

/* The longest --stop-at, in seconds (about 31 years). */
#define STOP_AT_MAX 1e9

static double stop_at;
static uint32_t seed;
/* UINT32_MAX is the table's "not given" value but also a seed like any other. */
static bool seed_given;
static sem_t wake_sem;
static volatile sig_atomic_t caught_signal;

static void stop_at_found(char *argv, int offset)
{
	stop_at = cmd_read_double_option("stop-at", &argv[offset], 0.0, STOP_AT_MAX);
}

static void seed_found(char *argv, int offset)
{
	seed_given = true;
}

static void add_board_options(void)
{
	static struct args_struct_t board_options[] = {
		{false, false, false, "stop-at", "time", 'd', &stop_at, stop_at_found,
		 "End the process with exit code 0 after <time> seconds (host time, from the "
		 "start; 0 to 1e9, fractions allowed)"},
		{false, false, false, "seed", "r_seed", 'u', &seed, seed_found,
		 "Seed of the pseudo-random generator sys_rand32_get(), e.g. 97229 or 0x17BCD "
		 "(default 0x5678)"},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(board_options);
}
NATIVE_TASK(add_board_options, PRE_BOOT_1, 0);

uint32_t native_get_seed(void)
{
	return seed_given ? seed : 0x5678U;
}

static void vprint(FILE *stream, const char *format, va_list ap)
{
	(void)vfprintf(stream, format, ap);
	(void)fflush(stream);
}

void posix_print_error_and_exit(const char *format, ...)
{
	va_list ap;

	va_start(ap, format);
	vprint(stderr, format, ap);
	va_end(ap);
	posix_exit(1);
}

void posix_print_warning(const char *format, ...)
{
	va_list ap;

	va_start(ap, format);
	vprint(stderr, format, ap);
	va_end(ap);
}

void posix_print_trace(const char *format, ...)
{
	va_list ap;

	va_start(ap, format);
	vprint(stdout, format, ap);
	va_end(ap);
}

void posix_exit(int exit_code)
{
	static atomic_flag exiting = ATOMIC_FLAG_INIT;

	if (atomic_flag_test_and_set(&exiting)) {
		/* Another thread is already ending the process. */
		for (;;) {
			(void)pause();
		}
	}
	run_native_tasks(_NATIVE_ON_EXIT_LEVEL);
	native_cleanup_cmd_line();
	(void)fflush(stdout);
	(void)fflush(stderr);
	exit(exit_code);
}

static void on_signal(int signo)
{
	/* Only async-signal-safe calls here: the boot thread does the rest. */
	caught_signal = signo;
	(void)sem_post(&wake_sem);
}

static void catch_signals(void)
{
	struct sigaction sa = {.sa_handler = on_signal, .sa_flags = SA_RESTART};

	(void)sigemptyset(&sa.sa_mask);
	(void)sigaction(SIGINT, &sa, NULL);
	(void)sigaction(SIGTERM, &sa, NULL);
}

/* Sleep until --stop-at (if given) or a signal. */
static void wait_for_the_end(void)
{
	struct timespec deadline;
	int ret;

	if (isnan(stop_at)) {
		while (sem_wait(&wake_sem) != 0 && errno == EINTR) {
		}
		return;
	}

	(void)clock_gettime(CLOCK_MONOTONIC, &deadline);
	deadline.tv_sec += (time_t)stop_at;
	deadline.tv_nsec += (long)((stop_at - floor(stop_at)) * 1e9);
	if (deadline.tv_nsec >= 1000000000L) {
		deadline.tv_sec++;
		deadline.tv_nsec -= 1000000000L;
	}
	do {
		ret = sem_clockwait(&wake_sem, CLOCK_MONOTONIC, &deadline);
	} while (ret != 0 && errno == EINTR);
}

int __wrap_main(int argc, char *argv[])
{
	/* The console is line-buffered even into a pipe, so a runner sees lines as they come. */
	(void)setvbuf(stdout, NULL, _IOLBF, 0);
	(void)sem_init(&wake_sem, 0, 0);

	run_native_tasks(_NATIVE_PRE_BOOT_1_LEVEL);
	native_handle_cmd_line(argc, argv);
	run_native_tasks(_NATIVE_PRE_BOOT_2_LEVEL);
	catch_signals();
	run_native_tasks(_NATIVE_PRE_BOOT_3_LEVEL);

	z_cstart(__real_main);
	run_native_tasks(_NATIVE_FIRST_SLEEP_LEVEL);

	wait_for_the_end();
	if (caught_signal != 0) {
		posix_exit(128 + caught_signal);
	}
	posix_print_trace("\nStopped at %.3fs\n", stop_at);
	posix_exit(0);
}
