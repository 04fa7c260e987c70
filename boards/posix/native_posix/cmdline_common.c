/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Parsing and help of option tables (see cmdline_common.h). Host code. */

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cmdline_common.h"
#include "posix_board_if.h"

#define HELP_SWITCH "[--help]"
#define HELP_DESCR  "Print this help and exit"
#define HELP_COLUMN 32  /* where descriptions start */
#define LINE_WIDTH  100 /* wrap the help here */

/*
 * The table being parsed, for the usage printed with a value error (also from the
 * call_when_found callbacks and from checks made right after the parse, before the boot).
 */
static struct args_struct_t *usage_table;

static void print_usage(void)
{
	if (usage_table != NULL) {
		(void)fputs("Usage: ", stdout);
		cmd_print_switches_help(usage_table);
	}
	(void)fflush(stdout);
}

static const char *skip_dashes(const char *arg)
{
	if (arg[0] == '-') {
		arg++;
		if (arg[0] == '-') {
			arg++;
		}
	}

	return arg;
}

int cmd_is_option(const char *arg, const char *option, int with_value)
{
	const char *name = skip_dashes(arg);
	size_t len = strlen(option);
	int offset;

	if (name == arg || strncmp(name, option, len) != 0) {
		return 0;
	}
	offset = (int)(name - arg) + (int)len;
	if (!with_value) {
		return (arg[offset] == '\0') ? offset : 0;
	}
	if (arg[offset] != '=' && arg[offset] != ':') {
		if (arg[offset] == '\0') {
			print_usage();
			posix_print_error_and_exit(
				"Error: option '%s' needs a value: --%s=<value>. "
				"Use --help for the description of every "
				"option.\n",
				arg, option);
		}
		return 0;
	}

	return offset + 1;
}

int cmd_is_help_option(const char *arg)
{
	const char *name = skip_dashes(arg);

	return name != arg && (strcasecmp(name, "help") == 0 || strcasecmp(name, "h") == 0 ||
			       strcmp(name, "?") == 0);
}

static bool is_digit(char c)
{
	return c >= '0' && c <= '9';
}

int cmd_parse_uint(const char *str, uint64_t min, uint64_t max, uint64_t *out)
{
	unsigned long long v;
	char *end = NULL;

	/* strtoull() would skip spaces and take a sign ("-1" is ULLONG_MAX): not here. */
	if (!is_digit(str[0])) {
		return -EINVAL;
	}
	errno = 0;
	v = strtoull(str, &end, 0);
	if (*end != '\0') {
		return -EINVAL;
	}
	if (errno == ERANGE || v < min || v > max) {
		return -ERANGE;
	}
	*out = v;

	return 0;
}

int cmd_parse_int(const char *str, int64_t min, int64_t max, int64_t *out)
{
	long long v;
	char *end = NULL;

	if (!is_digit(str[str[0] == '-' ? 1 : 0])) {
		return -EINVAL;
	}
	errno = 0;
	v = strtoll(str, &end, 0);
	if (*end != '\0') {
		return -EINVAL;
	}
	if (errno == ERANGE || v < min || v > max) {
		return -ERANGE;
	}
	*out = v;

	return 0;
}

int cmd_parse_double(const char *str, double min, double max, double *out)
{
	const char *digits = str + (str[0] == '-' ? 1 : 0);
	char *end = NULL;
	double v;

	/* A digit first: no space, no '+', no "nan", "inf" or "infinity". */
	if (!is_digit(digits[0]) && !(digits[0] == '.' && is_digit(digits[1]))) {
		return -EINVAL;
	}
	errno = 0;
	v = strtod(str, &end);
	if (*end != '\0' || !isfinite(v)) {
		return (*end == '\0') ? -ERANGE : -EINVAL;
	}
	if (errno == ERANGE || !(v >= min && v <= max)) {
		return -ERANGE;
	}
	*out = v;

	return 0;
}

void cmd_option_error(const char *option, const char *str, const char *format, ...)
{
	char reason[512]; /* room for a file path and line in the reason */
	va_list ap;

	va_start(ap, format);
	(void)vsnprintf(reason, sizeof(reason), format, ap);
	va_end(ap);
	print_usage();
	posix_print_error_and_exit("Error: --%s='%s': %s. Use --help for the description of "
				   "every option.\n",
				   option, str, reason);
}

uint64_t cmd_read_uint_option(const char *option, const char *str, uint64_t min, uint64_t max)
{
	uint64_t v = 0;
	int rc = cmd_parse_uint(str, min, max, &v);

	if (rc == -EINVAL) {
		cmd_option_error(option, str,
				 "not an unsigned integer (decimal, 0x hex or 0 octal; no sign)");
	} else if (rc != 0) {
		cmd_option_error(option, str, "out of range (%llu..%llu)", (unsigned long long)min,
				 (unsigned long long)max);
	}

	return v;
}

int64_t cmd_read_int_option(const char *option, const char *str, int64_t min, int64_t max)
{
	int64_t v = 0;
	int rc = cmd_parse_int(str, min, max, &v);

	if (rc == -EINVAL) {
		cmd_option_error(option, str, "not an integer (decimal, 0x hex or 0 octal)");
	} else if (rc != 0) {
		cmd_option_error(option, str, "out of range (%lld..%lld)", (long long)min,
				 (long long)max);
	}

	return v;
}

double cmd_read_double_option(const char *option, const char *str, double min, double max)
{
	double v = 0.0;
	int rc = cmd_parse_double(str, min, max, &v);

	if (rc == -EINVAL) {
		cmd_option_error(option, str, "not a number");
	} else if (rc != 0) {
		cmd_option_error(option, str, "out of range (%g..%g)", min, max);
	}

	return v;
}

void cmd_read_option_value(const char *str, void *dest, const char type, const char *option)
{
	switch (type) {
	case 'b':
		if (strcasecmp(str, "true") == 0 || strcmp(str, "1") == 0) {
			*(bool *)dest = true;
		} else if (strcasecmp(str, "false") == 0 || strcmp(str, "0") == 0) {
			*(bool *)dest = false;
		} else {
			cmd_option_error(option, str, "not a bool (true, false, 1 or 0)");
		}
		break;
	case 's':
		*(char **)dest = (char *)str;
		break;
	case 'u':
		*(uint32_t *)dest = (uint32_t)cmd_read_uint_option(option, str, 0, UINT32_MAX);
		break;
	case 'U':
		*(uint64_t *)dest = cmd_read_uint_option(option, str, 0, UINT64_MAX);
		break;
	case 'i':
		*(int32_t *)dest = (int32_t)cmd_read_int_option(option, str, INT32_MIN, INT32_MAX);
		break;
	case 'I':
		*(int64_t *)dest = cmd_read_int_option(option, str, INT64_MIN, INT64_MAX);
		break;
	case 'd':
		*(double *)dest = cmd_read_double_option(option, str, -DBL_MAX, DBL_MAX);
		break;
	default:
		posix_print_error_and_exit("Option %s: unknown type '%c'\n", option, type);
	}
}

void cmd_args_set_defaults(struct args_struct_t args_struct[])
{
	usage_table = args_struct;
	for (int i = 0; args_struct[i].option != NULL; i++) {
		void *dest = args_struct[i].dest;

		if (dest == NULL) {
			continue;
		}
		switch (args_struct[i].type) {
		case 'b':
			*(bool *)dest = false;
			break;
		case 's':
			*(char **)dest = NULL;
			break;
		case 'u':
			*(uint32_t *)dest = UINT32_MAX;
			break;
		case 'U':
			*(uint64_t *)dest = UINT64_MAX;
			break;
		case 'i':
			*(int32_t *)dest = INT32_MAX;
			break;
		case 'I':
			*(int64_t *)dest = INT64_MAX;
			break;
		case 'd':
			*(double *)dest = NAN;
			break;
		default:
			break;
		}
	}
}

static void handle_matched_arg(char *argv, int offset, struct args_struct_t *arg)
{
	if (arg->dest != NULL) {
		if (arg->is_switch) {
			if (arg->type != 'b') {
				posix_print_error_and_exit("Switch --%s: only bool switches can "
							   "store a value\n",
							   arg->option);
			}
			*(bool *)arg->dest = true;
		} else {
			cmd_read_option_value(&argv[offset], arg->dest, arg->type, arg->option);
		}
	}
	if (arg->call_when_found != NULL) {
		arg->call_when_found(argv, offset);
	}
}

bool cmd_parse_one_arg(char *argv, struct args_struct_t args_struct[])
{
	usage_table = args_struct;
	if (cmd_is_help_option(argv)) {
		cmd_print_long_help(args_struct);
		posix_exit(0);
	}

	for (int i = 0; args_struct[i].option != NULL; i++) {
		int offset;

		if (args_struct[i].manual) {
			continue;
		}
		offset = cmd_is_option(argv, args_struct[i].option, !args_struct[i].is_switch);
		if (offset > 0) {
			handle_matched_arg(argv, offset, &args_struct[i]);
			return true;
		}
	}

	return false;
}

/* "[--name=<value>]" (brackets when optional) into buf. */
static void switch_syntax(char *buf, size_t size, const struct args_struct_t *arg)
{
	const char *open = arg->is_mandatory ? "" : "[";
	const char *close = arg->is_mandatory ? "" : "]";

	if (arg->is_switch) {
		(void)snprintf(buf, size, "%s--%s%s", open, arg->option, close);
	} else if (arg->type == 'l') {
		(void)snprintf(buf, size, "%s--%s <%s>...%s", open, arg->option, arg->name, close);
	} else {
		(void)snprintf(buf, size, "%s--%s=<%s>%s", open, arg->option, arg->name, close);
	}
}

void cmd_print_switches_help(struct args_struct_t args_struct[])
{
	size_t column = strlen(HELP_SWITCH);

	(void)fputs(HELP_SWITCH, stdout);
	for (int i = 0; args_struct[i].option != NULL; i++) {
		char syntax[128];

		switch_syntax(syntax, sizeof(syntax), &args_struct[i]);
		if (column + 1 + strlen(syntax) > LINE_WIDTH) {
			(void)fputs("\n", stdout);
			column = 0;
		} else {
			(void)fputs(" ", stdout);
			column++;
		}
		(void)fputs(syntax, stdout);
		column += strlen(syntax);
	}
	(void)fputs("\n", stdout);
}

/* Print text from column HELP_COLUMN, wrapped at word boundaries. */
static void print_description(const char *text)
{
	size_t width = LINE_WIDTH - HELP_COLUMN;
	bool first = true;

	while (*text != '\0') {
		size_t len = strlen(text);

		if (len > width) {
			len = width;
			while (len > 0 && text[len] != ' ') {
				len--;
			}
			if (len == 0) {
				len = width;
			}
		}
		(void)printf("%*s%.*s\n", first ? 0 : HELP_COLUMN, "", (int)len, text);
		first = false;
		text += len;
		while (*text == ' ') {
			text++;
		}
	}
	if (first) {
		(void)printf("\n");
	}
}

void cmd_print_long_help(struct args_struct_t args_struct[])
{
	(void)printf("Usage: ");
	cmd_print_switches_help(args_struct);
	(void)printf("\n  %-*s", HELP_COLUMN - 2, HELP_SWITCH);
	print_description(HELP_DESCR);
	for (int i = 0; args_struct[i].option != NULL; i++) {
		char syntax[128];

		switch_syntax(syntax, sizeof(syntax), &args_struct[i]);
		if (strlen(syntax) + 2 >= HELP_COLUMN) {
			(void)printf("  %s\n%*s", syntax, HELP_COLUMN, "");
		} else {
			(void)printf("  %-*s", HELP_COLUMN - 2, syntax);
		}
		print_description(args_struct[i].descript);
	}
	(void)printf("\nOptions may start with - or --; values follow = or :.\n");
}
