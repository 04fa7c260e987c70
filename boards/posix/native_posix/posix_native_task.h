/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NATIVE_TASK(fn, level, prio): run void fn(void) at a given moment of the process's life,
 * as on Zephyr's native boards. Levels, in order:
 *
 *   PRE_BOOT_1   before the command line is parsed: register options here
 *   PRE_BOOT_2   after the command line is parsed
 *   PRE_BOOT_3   right before the kernel starts (before PRE_KERNEL_1)
 *   FIRST_SLEEP  once the kernel runs (the main thread has been started)
 *   ON_EXIT      when the process ends through posix_exit() (main() returning, --stop-at,
 *                a fatal error, SIGINT/SIGTERM): close host resources here
 *
 * Within a level, a lower prio runs first. At the PRE_BOOT and ON_EXIT levels no kernel
 * thread may be waited for. Tasks register from constructors, so no linker script is needed.
 */

#ifndef NATIVE_POSIX_POSIX_NATIVE_TASK_H
#define NATIVE_POSIX_POSIX_NATIVE_TASK_H

#ifdef __cplusplus
extern "C" {
#endif

#define _NATIVE_PRE_BOOT_1_LEVEL  0
#define _NATIVE_PRE_BOOT_2_LEVEL  1
#define _NATIVE_PRE_BOOT_3_LEVEL  2
#define _NATIVE_FIRST_SLEEP_LEVEL 3
#define _NATIVE_ON_EXIT_LEVEL     4

struct native_task_entry {
	void (*fn)(void);
	int level;
	int prio;
	const char *name;
	struct native_task_entry *next;
};

void native_task_register(struct native_task_entry *entry);

#define NATIVE_TASK(fn, level, prio)                                                               \
	static struct native_task_entry __native_task_##fn = {                                     \
		(fn), _NATIVE_##level##_LEVEL, (prio), #fn, 0,                                     \
	};                                                                                         \
	static void __attribute__((constructor)) __native_task_reg_##fn(void)                      \
	{                                                                                          \
		native_task_register(&__native_task_##fn);                                         \
	}

/* Run the tasks of one level (_NATIVE_*_LEVEL). */
void run_native_tasks(int level);

#ifdef __cplusplus
}
#endif

#endif /* NATIVE_POSIX_POSIX_NATIVE_TASK_H */
