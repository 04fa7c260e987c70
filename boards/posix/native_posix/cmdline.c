/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* The native_posix command line (see cmdline.h). Host code. */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmdline.h"
#include "posix_board_if.h"

static int s_argc;
static char **s_argv;
static int test_argc;
static char **test_argv;

/* All registered options, one table ending with ARG_TABLE_ENDMARKER. */
static struct args_struct_t *args_struct;
static int used_args;
static int args_aval;

void native_cleanup_cmd_line(void)
{
	free(args_struct);
	args_struct = NULL;
	used_args = 0;
	args_aval = 0;
}

void native_add_command_line_opts(struct args_struct_t *args)
{
	int count = 0;

	while (args[count].option != NULL) {
		count++;
	}
	count++; /* the end marker */

	if (used_args + count > args_aval) {
		int grow = (count > 16) ? count : 16;
		struct args_struct_t *bigger =
			realloc(args_struct, (size_t)(args_aval + grow) * sizeof(*args_struct));

		if (bigger == NULL) {
			posix_print_error_and_exit("Out of memory for command-line options\n");
		}
		args_struct = bigger;
		args_aval += grow;
	}
	(void)memcpy(&args_struct[used_args], args, (size_t)count * sizeof(*args_struct));
	/* The next table overwrites this end marker. */
	used_args += count - 1;
}

void native_handle_cmd_line(int argc, char *argv[])
{
	static struct args_struct_t testargs_options[] = {
		{true, false, false, "testargs", "arg", 'l', NULL, NULL,
		 "Everything after it is left to the application (see "
		 "native_get_test_cmd_line_args())"},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(testargs_options);
	s_argc = argc;
	s_argv = argv;
	cmd_args_set_defaults(args_struct);

	for (int i = 1; i < argc; i++) {
		if (cmd_is_option(argv[i], "testargs", 0) != 0) {
			test_argc = argc - i - 1;
			test_argv = &argv[i + 1];
			break;
		}
		if (!cmd_parse_one_arg(argv[i], args_struct)) {
			(void)fputs("Usage: ", stdout);
			cmd_print_switches_help(args_struct);
			(void)fflush(stdout);
			posix_print_error_and_exit(
				"Unknown option '%s'. Use --help for the list of "
				"options of this image.\n",
				argv[i]);
		}
	}
}

void native_get_cmd_line_args(int *argc, char ***argv)
{
	*argc = s_argc;
	*argv = s_argv;
}

void native_get_test_cmd_line_args(int *argc, char ***argv)
{
	*argc = test_argc;
	*argv = test_argv;
}
