/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Boot: init levels and the main thread, in Zephyr's order.
 *
 *   board main()  -> PRE_KERNEL_1, PRE_KERNEL_2 (boot thread, no kernel threads yet)
 *                 -> timeout thread, "main" thread
 *   "main" thread -> POST_KERNEL, boot banner, APPLICATION, K_THREAD_DEFINE threads,
 *                    main(); its return value ends the process (posix_exit()).
 *
 * SYS_INIT() entries register from constructors into one list sorted by level and priority
 * (registration order among equals), so no linker script is needed.
 */

#include <stdio.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

static struct init_entry *init_list;

static struct k_thread main_thread;
static K_KERNEL_STACK_DEFINE(main_stack, CONFIG_MAIN_STACK_SIZE);

void z_init_entry_register(struct init_entry *entry)
{
	struct init_entry **pos = &init_list;

	while (*pos != NULL && ((*pos)->level < entry->level ||
				((*pos)->level == entry->level && (*pos)->prio <= entry->prio))) {
		pos = &(*pos)->next;
	}
	entry->next = *pos;
	*pos = entry;
}

__weak int z_device_init(const struct init_entry *entry)
{
	return entry->init_fn.dev(entry->dev);
}

void z_sys_init_run_level(int level)
{
	for (struct init_entry *entry = init_list; entry != NULL; entry = entry->next) {
		int rc;

		if (entry->level != level) {
			continue;
		}
		if (entry->dev != NULL) {
			rc = z_device_init(entry);
		} else {
			rc = entry->init_fn.sys();
		}
		if (rc != 0 && entry->dev == NULL) {
			/* Zephyr carries on; saying so saves a debugging session. A device that
			 * fails is left not ready (device_is_ready()) and its driver logs why; an
			 * unmapped SocketCAN controller, for one, is no error.
			 */
			printk("init: %s returned %d\n", entry->name, rc);
		}
	}
}

static void bg_thread_main(void *p1, void *p2, void *p3)
{
	int (*app_main)(void) = (int (*)(void))(void (*)(void))p1;
	int ret;

	ARG_UNUSED(p2);
	ARG_UNUSED(p3);

	z_sys_init_run_level(Z_INIT_LEVEL_POST_KERNEL);
	if (IS_ENABLED(CONFIG_BOOT_BANNER)) {
		printk("*** Booting SafeLine on %s ***\n", CONFIG_BOARD);
	}
	z_sys_init_run_level(Z_INIT_LEVEL_APPLICATION);
	z_init_static_threads();

	ret = app_main();
	posix_exit(ret);
}

void z_cstart(int (*app_main)(void))
{
	z_sys_init_run_level(Z_INIT_LEVEL_EARLY);
	z_sys_init_run_level(Z_INIT_LEVEL_PRE_KERNEL_1);
	z_sys_init_run_level(Z_INIT_LEVEL_PRE_KERNEL_2);

	z_timeout_thread_start();

	(void)k_thread_create(&main_thread, main_stack, K_KERNEL_STACK_SIZEOF(main_stack),
			      bg_thread_main, (void *)(void (*)(void))app_main, NULL, NULL,
			      CONFIG_MAIN_THREAD_PRIORITY, K_ESSENTIAL, K_FOREVER);
	(void)k_thread_name_set(&main_thread, "main");
	k_thread_start(&main_thread);
}
