/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What the native_posix board offers the rest of the image (Zephyr's posix_board_if.h and
 * posix_trace.h, plus the seed). Plain C: no host header.
 *
 * Exit codes of the process:
 *   0          main() returned 0 (for a test image: every test passed), or --stop-at, --help
 *   1          main() returned 1 (a test failed), a fatal error (k_panic(), k_oops(), a
 *              failed __ASSERT()), or an unknown option / malformed value on the command line
 *   other      main()'s return value
 *   128 + sig  ended by SIGINT or SIGTERM
 */

#ifndef NATIVE_POSIX_POSIX_BOARD_IF_H
#define NATIVE_POSIX_POSIX_BOARD_IF_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* End the process: run the ON_EXIT tasks, flush the console, exit(exit_code). */
void posix_exit(int exit_code) __attribute__((__noreturn__));

/* Print an error on stderr and end the process with exit code 1. */
void posix_print_error_and_exit(const char *format, ...)
	__attribute__((__noreturn__, __format__(__printf__, 1, 2)));

/* Print a warning on stderr. */
void posix_print_warning(const char *format, ...) __attribute__((__format__(__printf__, 1, 2)));

/* Print a message on stdout (the console). */
void posix_print_trace(const char *format, ...) __attribute__((__format__(__printf__, 1, 2)));

/* The --seed value (0x5678 if not given): the seed of sys_rand32_get() and friends. */
uint32_t native_get_seed(void);

#ifdef __cplusplus
}
#endif

#endif /* NATIVE_POSIX_POSIX_BOARD_IF_H */
