/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Device model: the subset of Zephyr's `<zephyr/device.h>` that SafeLine uses.
 *
 * Devices are defined statically with DEVICE_DEFINE(), initialized at boot by the init levels
 * of `<zephyr/init.h>` and found by name with device_get_binding(). There is no devicetree on
 * native_posix: drivers define their instances from Kconfig counts.
 */

#ifndef ZEPHYR_INCLUDE_DEVICE_H_
#define ZEPHYR_INCLUDE_DEVICE_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/init.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Device model
 * @defgroup device_model Device model
 * @{
 */

/** Runtime state of a device, kept by the device model. */
struct device_state {
	/** Result of the init function (its negated errno), valid once @ref initialized. */
	uint8_t init_res;
	/** The init function has run. */
	bool initialized;
	/** @cond INTERNAL_HIDDEN */
	/* Link in the list device_get_binding() searches. */
	const struct device *next;
	/** @endcond */
};

/** A device instance. */
struct device {
	/** Name, for device_get_binding(). */
	const char *name;
	/** Constant configuration of the instance. */
	const void *config;
	/** Driver operations. */
	const void *api;
	/** Runtime state kept by the device model. */
	struct device_state *state;
	/** Driver-owned mutable data of the instance. */
	void *data;
};

/** The identifier of the device object defined for @p dev_id. */
#define DEVICE_NAME_GET(dev_id) _CONCAT(__device_, dev_id)

/** Pointer to the device defined as @p dev_id. */
#define DEVICE_GET(dev_id) (&DEVICE_NAME_GET(dev_id))

/** Declare a device defined in another file, for DEVICE_GET(). */
#define DEVICE_DECLARE(dev_id) extern const struct device DEVICE_NAME_GET(dev_id)

/** @cond INTERNAL_HIDDEN */
/* Adds @p dev to the list device_get_binding() searches (from a constructor). */
void z_device_register(const struct device *dev);
/** @endcond */

/**
 * @brief Define a device instance, its boot-time initialization and its name binding.
 *
 * @param dev_id Identifier of the instance (a C identifier).
 * @param name Name for device_get_binding() (a string).
 * @param init_fn int fn(const struct device *dev), returning 0 or a negative errno; or NULL.
 * @param pm Power management resources; unused, pass NULL.
 * @param data Pointer to the instance's mutable data, or NULL.
 * @param config Pointer to the instance's constant configuration, or NULL.
 * @param level Init level (PRE_KERNEL_1, PRE_KERNEL_2, POST_KERNEL, APPLICATION).
 * @param prio Priority within the level; lower runs first.
 * @param api Pointer to the driver's operations.
 */
#define DEVICE_DEFINE(dev_id, name, init_fn, pm, data, config, level, prio, api)                   \
	static struct device_state _CONCAT(__devstate_, dev_id);                                   \
	const struct device DEVICE_NAME_GET(dev_id) = {                                            \
		(name), (config), (api), &_CONCAT(__devstate_, dev_id), (data),                    \
	};                                                                                         \
	static int _CONCAT(__devinit_, dev_id)(const struct device *dev)                           \
	{                                                                                          \
		int (*fn)(const struct device *) = (init_fn);                                      \
		return (fn != NULL) ? fn(dev) : 0;                                                 \
	}                                                                                          \
	static void __attribute__((constructor)) _CONCAT(__devreg_, dev_id)(void)                  \
	{                                                                                          \
		z_device_register(&DEVICE_NAME_GET(dev_id));                                       \
	}                                                                                          \
	Z_INIT_ENTRY_DEFINE(_CONCAT(__device_init_, dev_id), _CONCAT(__devinit_, dev_id),          \
			    &DEVICE_NAME_GET(dev_id), level, prio)

/**
 * @brief Find a ready device by name.
 *
 * @param name The name given to DEVICE_DEFINE().
 * @return The device, or NULL if there is none of that name or it failed to initialize.
 */
const struct device *device_get_binding(const char *name);

/**
 * @brief Whether a device initialized successfully and can be used.
 *
 * @param dev A device, or NULL.
 * @retval true Its init function ran and returned 0.
 * @retval false @p dev is NULL, not initialized yet, or its init function failed.
 */
bool device_is_ready(const struct device *dev);

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_DEVICE_H_ */
