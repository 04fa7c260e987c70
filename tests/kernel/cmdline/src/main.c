/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * An image whose behaviour the command line chooses, for pytest/test_cmdline.py:
 *
 *   --node-id=<n>   an option added the way drivers and samples add theirs
 *   --exit=<code>   main() returns <code>
 *   --fatal=<kind>  panic, oops or assert: the fatal-error path
 *   (nothing)       main() sleeps forever: --stop-at or a signal ends the process
 */

#include <stdlib.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/random/random.h>

#include "cmdline.h"
#include "posix_board_if.h"
#include "posix_native_task.h"

static uint32_t node_id;
static int32_t exit_code;
static char *fatal_kind;

static void add_options(void)
{
	static struct args_struct_t options[] = {
		{false, false, false, "node-id", "n", 'u', &node_id, NULL, "CANopen node-ID"},
		{false, false, false, "exit", "code", 'i', &exit_code, NULL,
		 "main() returns <code>"},
		{false, false, false, "fatal", "kind", 's', &fatal_kind, NULL,
		 "Raise a fatal error: panic, oops or assert"},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(options);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 10);

static void on_exit_hook(void)
{
	posix_print_trace("on_exit hook ran\n");
}
NATIVE_TASK(on_exit_hook, ON_EXIT, 0);

int main(void)
{
	int argc;
	char **argv;

	printk("node_id=%u seed=%u\n", node_id, native_get_seed());
	printk("rand=%08x %08x\n", sys_rand32_get(), sys_rand32_get());

	native_get_test_cmd_line_args(&argc, &argv);
	printk("testargs=%d", argc);
	for (int i = 0; i < argc; i++) {
		printk(" %s", argv[i]);
	}
	printk("\n");

	if (fatal_kind != NULL) {
		if (strcmp(fatal_kind, "panic") == 0) {
			k_panic();
		} else if (strcmp(fatal_kind, "oops") == 0) {
			k_oops();
		} else if (strcmp(fatal_kind, "assert") == 0) {
			__ASSERT(node_id == 12345, "node_id is %u", node_id);
		}
		printk("no fatal error\n");
		return 0;
	}
	if (exit_code != INT32_MAX) {
		return exit_code;
	}

	printk("running\n");
	(void)k_sleep(K_FOREVER);

	return 0;
}
