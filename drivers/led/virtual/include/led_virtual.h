/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Virtual LEDs on native_posix: what only a simulated LED can do (not Zephyr API).
 *
 * The device "led_virtual0" implements <zephyr/drivers/led.h> for CONFIG_LED_VIRTUAL_COUNT
 * LEDs. It keeps each LED's state and records every change with its time (the kernel's
 * uptime in microseconds), so a test or a person can see the pattern a firmware shows: a
 * terminal view follows the changes through a callback, scripts/led-timeline draws a trace.
 */

#ifndef SAFELINE_DRIVERS_LED_VIRTUAL_H_
#define SAFELINE_DRIVERS_LED_VIRTUAL_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/device.h>

#ifdef __cplusplus
extern "C" {
#endif

/** One change of one LED. */
struct led_virtual_change {
	/** When [µs of uptime]. */
	uint64_t time_us;
	/** LED number. */
	uint32_t led;
	/** The LED's new state. */
	bool on;
};

/**
 * @brief Called after every change, in the thread that changed the LED. Must not block.
 */
typedef void (*led_virtual_cb_t)(const struct device *dev, const struct led_virtual_change *c,
				 void *user_data);

/**
 * @brief Whether an LED is on.
 *
 * @retval 0 Done.
 * @retval -EINVAL No such LED.
 */
int led_virtual_get(const struct device *dev, uint32_t led, bool *on);

/**
 * @brief Copy recorded changes, oldest first, starting with change number @p from.
 *
 * Changes are numbered from 0 since boot; the device keeps the last
 * CONFIG_LED_VIRTUAL_TRACE_SIZE of them.
 *
 * @param dev The device.
 * @param from Number of the first change wanted (older ones that were overwritten are
 *        skipped).
 * @param out Where to copy.
 * @param max Capacity of @p out.
 * @param next If not NULL, gets the number of the change after the last one copied.
 * @return Changes copied.
 */
size_t led_virtual_trace(const struct device *dev, uint64_t from, struct led_virtual_change *out,
			 size_t max, uint64_t *next);

/** @brief Follow changes (NULL stops). One callback per device. */
void led_virtual_set_callback(const struct device *dev, led_virtual_cb_t cb, void *user_data);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_DRIVERS_LED_VIRTUAL_H_ */
