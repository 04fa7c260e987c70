/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Parsing and help of option tables (see cmdline_common.h). Host code. */

#include <errno.h>
#include <math.h>
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
			posix_print_error_and_exit("Option '%s' needs a value: --%s=<value>\n", arg,
						   option);
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

void cmd_read_option_value(const char *str, void *dest, const char type, const char *option)
{
	char *end = NULL;
	bool error = false;

	errno = 0;
	switch (type) {
	case 'b':
		if (strcasecmp(str, "true") == 0 || strcmp(str, "1") == 0) {
			*(bool *)dest = true;
		} else if (strcasecmp(str, "false") == 0 || strcmp(str, "0") == 0) {
			*(bool *)dest = false;
		} else {
			error = true;
		}
		end = (char *)str + strlen(str);
		break;
	case 's':
		*(char **)dest = (char *)str;
		end = (char *)str + strlen(str);
		break;
	case 'u': {
		unsigned long long v = strtoull(str, &end, 0);

		error = (v > UINT32_MAX) || (str[0] == '-');
		*(uint32_t *)dest = (uint32_t)v;
		break;
	}
	case 'U':
		error = (str[0] == '-');
		*(uint64_t *)dest = strtoull(str, &end, 0);
		break;
	case 'i': {
		long long v = strtoll(str, &end, 0);

		error = (v < INT32_MIN) || (v > INT32_MAX);
		*(int32_t *)dest = (int32_t)v;
		break;
	}
	case 'I':
		*(int64_t *)dest = strtoll(str, &end, 0);
		break;
	case 'd':
		*(double *)dest = strtod(str, &end);
		break;
	default:
		posix_print_error_and_exit("Option %s: unknown type '%c'\n", option, type);
	}

	if (error || errno != 0 || end == str || *end != '\0') {
		posix_print_error_and_exit("Error reading the value of --%s: '%s'. Use --help for "
					   "the usage\n",
					   option, str);
	}
}

void cmd_args_set_defaults(struct args_struct_t args_struct[])
{
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
