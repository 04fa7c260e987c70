/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief System initialization levels and SYS_INIT(), as Zephyr's init.h.
 *
 * Init functions run once at boot, before main(), level by level: PRE_KERNEL_1, PRE_KERNEL_2
 * (before any thread exists), POST_KERNEL, APPLICATION (in the main thread, with the kernel
 * running). Within a level, a lower priority number runs first. A function returning non-zero
 * is reported on the console; boot continues, as in Zephyr.
 */

#ifndef ZEPHYR_INCLUDE_INIT_H_
#define ZEPHYR_INCLUDE_INIT_H_

#include <stdint.h>

#include <zephyr/sys/util.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

struct device;

/** @cond INTERNAL_HIDDEN */
/* Level tokens as used in SYS_INIT(fn, POST_KERNEL, prio). */
#define Z_INIT_LEVEL_EARLY        0
#define Z_INIT_LEVEL_PRE_KERNEL_1 1
#define Z_INIT_LEVEL_PRE_KERNEL_2 2
#define Z_INIT_LEVEL_POST_KERNEL  3
#define Z_INIT_LEVEL_APPLICATION  4
#define Z_INIT_LEVEL_SMP          5
/** @endcond */

/** An init function: a plain one, or a device's (with the device it initializes). */
union init_function {
	/** System init function. */
	int (*sys)(void);
	/** Device init function. */
	int (*dev)(const struct device *dev);
};

/**
 * @brief One boot-time initialization step.
 *
 * Created by SYS_INIT() or by the device model; never by hand.
 */
struct init_entry {
	/** The function to call. */
	union init_function init_fn;
	/** The device @ref init_function::dev initializes; NULL for SYS_INIT() entries. */
	const struct device *dev;
	/** @cond INTERNAL_HIDDEN */
	/* Where the entry runs and a link in the boot list (filled in before main()). */
	uint8_t level;
	int prio;
	const char *name;
	struct init_entry *next;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
/* Adds an entry to the boot list; called by the constructors that SYS_INIT() generates. */
void z_init_entry_register(struct init_entry *entry);

/*
 * Runs a device entry's init function. Weak in the kernel (it just calls init_fn.dev); the
 * device model overrides it to record the result in the device's state.
 */
int z_device_init(const struct init_entry *entry);

/*
 * Defines an init entry and registers it from a constructor, so that it needs no linker
 * script. @p _dev is NULL for system init functions, whose @p _init_fn is int fn(void); for a
 * device it is int fn(const struct device *). The cast through void (*)(void) stores either
 * kind in the union without a warning; the kernel calls it through the matching member.
 */
#define Z_INIT_ENTRY_DEFINE(_entry_name, _init_fn, _dev, _level, _prio)                            \
	static struct init_entry _CONCAT(__init_, _entry_name) = {                                 \
		.init_fn = {.sys = (int (*)(void))(void (*)(void))(_init_fn)},                     \
		.dev = (_dev),                                                                     \
		.level = _CONCAT(Z_INIT_LEVEL_, _level),                                           \
		.prio = (_prio),                                                                   \
		.name = STRINGIFY(_init_fn),                                                       \
	};                                                                                         \
	static void __attribute__((constructor)) _CONCAT(__init_reg_, _entry_name)(void)           \
	{                                                                                          \
		z_init_entry_register(&_CONCAT(__init_, _entry_name));                             \
	}

/** @endcond */

/**
 * @brief Run @p init_fn (int fn(void)) at boot in @p level with priority @p prio.
 *
 * @param init_fn Function returning 0 on success or a negative errno.
 * @param level PRE_KERNEL_1, PRE_KERNEL_2, POST_KERNEL or APPLICATION (a bare token).
 * @param prio Priority within the level; lower runs first.
 */
#define SYS_INIT(init_fn, level, prio) SYS_INIT_NAMED(init_fn, init_fn, level, prio)

/**
 * @brief As SYS_INIT(), with an explicit entry @p name so one function can be used twice.
 */
#define SYS_INIT_NAMED(name, init_fn, level, prio)                                                 \
	Z_INIT_ENTRY_DEFINE(_CONCAT(__sys_init_, name), init_fn, NULL, level, prio)

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_INIT_H_ */
