/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The device model behind <zephyr/device.h>: a list of defined devices for lookup by name and
 * the init hook that records each device's init result.
 *
 * Devices register from constructors before main(); init runs at boot in one thread. Lookups
 * happen afterwards and only read, so the list needs no lock.
 */

#include <errno.h>
#include <stddef.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/init.h>

static const struct device *device_list;

void z_device_register(const struct device *dev)
{
	dev->state->next = device_list;
	device_list = dev;
}

/* Overrides the kernel's weak hook, so device_is_ready() knows how init went. */
int z_device_init(const struct init_entry *entry)
{
	const struct device *dev = entry->dev;
	int rc = entry->init_fn.dev(dev);

	if (rc < 0) {
		rc = -rc;
	}
	dev->state->init_res = (rc > UINT8_MAX) ? UINT8_MAX : (uint8_t)rc;
	dev->state->initialized = true;

	return (rc == 0) ? 0 : -(int)dev->state->init_res;
}

bool device_is_ready(const struct device *dev)
{
	return dev != NULL && dev->state->initialized && dev->state->init_res == 0U;
}

const struct device *device_get_binding(const char *name)
{
	if (name == NULL || name[0] == '\0') {
		return NULL;
	}
	/* Pointer comparison first: callers usually pass the same literal. */
	for (const struct device *dev = device_list; dev != NULL; dev = dev->state->next) {
		if (dev->name == name && device_is_ready(dev)) {
			return dev;
		}
	}
	for (const struct device *dev = device_list; dev != NULL; dev = dev->state->next) {
		if (strcmp(dev->name, name) == 0 && device_is_ready(dev)) {
			return dev;
		}
	}

	return NULL;
}
