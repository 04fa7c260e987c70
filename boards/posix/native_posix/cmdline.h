/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The native_posix command line, with Zephyr's native board API: modules add their options
 * from a NATIVE_TASK(fn, PRE_BOOT_1, prio) hook with native_add_command_line_opts(); the
 * board parses the command line before PRE_BOOT_2. Every image accepts:
 *
 *   --help                    usage, exit 0
 *   --stop-at=<time>          end the process with exit code 0 after <time> seconds
 *   --seed=<r_seed>           seed of sys_rand32_get() and friends
 *   --testargs <arg>...       the rest of the line is left to the application
 *
 * An unknown option or a malformed value prints the usage and an error on stderr and ends
 * the process with exit code 1.
 */

#ifndef NATIVE_POSIX_CMDLINE_H
#define NATIVE_POSIX_CMDLINE_H

#include "cmdline_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Parse the command line (called by the board's entry point). */
void native_handle_cmd_line(int argc, char *argv[]);
/* The whole command line, as given to the process. */
void native_get_cmd_line_args(int *argc, char ***argv);
/* The arguments after --testargs (argc 0 if there are none). */
void native_get_test_cmd_line_args(int *argc, char ***argv);
/*
 * Add options: args is a table ending with ARG_TABLE_ENDMARKER. It is copied; the
 * variables its entries point to must live until the process ends.
 */
void native_add_command_line_opts(struct args_struct_t *args);
/* Free the option tables (called on exit). */
void native_cleanup_cmd_line(void);

#ifdef __cplusplus
}
#endif

#endif /* NATIVE_POSIX_CMDLINE_H */
