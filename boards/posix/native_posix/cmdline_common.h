/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Command-line option tables, with the names and layout of Zephyr's native boards
 * (cmdline_common.h), so drivers written for Zephyr's native_posix register options the same
 * way here. Plain C: no host header, usable from firmware and host files alike.
 *
 * An option matches "-name", "--name" (switches) or "-name=value", "--name=value",
 * "--name:value" (options with a value).
 */

#ifndef NATIVE_POSIX_CMDLINE_COMMON_H
#define NATIVE_POSIX_CMDLINE_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Called when an option is found.
 *   argv: the whole argument as given on the command line
 *   offset: index in argv of the value (after '=' or ':'); for a switch, of its end
 */
typedef void (*option_found_callback_f)(char *argv, int offset);

/* One command-line option. */
struct args_struct_t {
	/* Not parsed by the table parser (only shown in the help and given its default). */
	bool manual;
	/* Shown without "[]" in the help. */
	bool is_mandatory;
	/* A switch: no value follows. */
	bool is_switch;
	/* Name, without dashes: matched as -<option> or --<option>. */
	char *option;
	/* Name of the value in the help: --<option>=<name>. */
	char *name;
	/*
	 * Type of *dest: 'b' bool, 's' char * (points into argv), 'u' uint32_t, 'U' uint64_t,
	 * 'i' int32_t, 'I' int64_t, 'd' double; 0 for no storage; 'l' a list (manual only).
	 */
	char type;
	/* Where the value goes; may be NULL. */
	void *dest;
	/* Called after the value has been stored; may be NULL. */
	option_found_callback_f call_when_found;
	/* Description for the help. */
	char *descript;
};

/* Last entry of every table. */
#define ARG_TABLE_ENDMARKER {false, false, false, NULL, NULL, 0, NULL, NULL, NULL}

/* Offset of the value in arg if arg is the option (with a value or not), else 0. */
int cmd_is_option(const char *arg, const char *option, int with_value);
/* Whether arg is -h, --h, -help, --help, -? or --? (any case). */
int cmd_is_help_option(const char *arg);
/*
 * Parse str as type into dest; on a malformed value print the usage and an error naming the
 * option, and exit(1) (see cmd_read_uint_option() for what a number may look like).
 */
void cmd_read_option_value(const char *str, void *dest, const char type, const char *option);

/*
 * Strict values (a SafeLine extension: Zephyr's parser takes whatever strtoul() makes of it).
 * The whole of str is the number: decimal, 0x hex or 0 octal, no space, no '+', a '-' only
 * for a signed number, nothing after it, no wrap-around; a double is finite (no NaN, no inf).
 * These return 0, -EINVAL (not a number) or -ERANGE (outside [min, max]).
 */
int cmd_parse_uint(const char *str, uint64_t min, uint64_t max, uint64_t *out);
int cmd_parse_int(const char *str, int64_t min, int64_t max, int64_t *out);
int cmd_parse_double(const char *str, double min, double max, double *out);

/*
 * The same, for the value of --option (e.g. from a call_when_found callback that checks a
 * range): a value that does not fit ends the process as a malformed value does.
 */
uint64_t cmd_read_uint_option(const char *option, const char *str, uint64_t min, uint64_t max);
int64_t cmd_read_int_option(const char *option, const char *str, int64_t min, int64_t max);
double cmd_read_double_option(const char *option, const char *str, double min, double max);

/*
 * Refuse the value str of --option: print the usage (stdout), then
 * "Error: --<option>=<str>: <reason>" (stderr), and exit(1) before the firmware boots.
 */
void cmd_option_error(const char *option, const char *str, const char *format, ...)
	__attribute__((__noreturn__, __format__(__printf__, 3, 4)));
/* Give every dest of the table its "not set" default (false, NULL, max values, NaN). */
void cmd_args_set_defaults(struct args_struct_t args_struct[]);
/* Parse one argument against the table; false if no option matched. */
bool cmd_parse_one_arg(char *argv, struct args_struct_t args_struct[]);
/* Print the one-line usage of every option. */
void cmd_print_switches_help(struct args_struct_t args_struct[]);
/* Print the usage and the description of every option. */
void cmd_print_long_help(struct args_struct_t args_struct[]);

#ifdef __cplusplus
}
#endif

#endif /* NATIVE_POSIX_CMDLINE_COMMON_H */
