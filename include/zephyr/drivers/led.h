/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The part of Zephyr's LED driver API (<zephyr/drivers/led.h>) the stack uses.
 *
 * Names, signatures and return codes as in Zephyr: a device drives LEDs numbered from 0.
 */

#ifndef ZEPHYR_INCLUDE_DRIVERS_LED_H_
#define ZEPHYR_INCLUDE_DRIVERS_LED_H_

#include <errno.h>
#include <stdint.h>

#include <zephyr/device.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @cond INTERNAL_HIDDEN */
typedef int (*led_api_on)(const struct device *dev, uint32_t led);
typedef int (*led_api_off)(const struct device *dev, uint32_t led);
typedef int (*led_api_set_brightness)(const struct device *dev, uint32_t led, uint8_t value);

/* Driver operations; a driver without brightness control leaves set_brightness NULL. */
struct led_driver_api {
	led_api_on on;
	led_api_off off;
	led_api_set_brightness set_brightness;
};
/** @endcond */

/**
 * @brief Turn an LED on.
 *
 * @param dev LED device.
 * @param led LED number on that device.
 * @retval 0 Done.
 * @retval -EINVAL No such LED.
 */
static inline int led_on(const struct device *dev, uint32_t led)
{
	return ((const struct led_driver_api *)dev->api)->on(dev, led);
}

/**
 * @brief Turn an LED off.
 *
 * @param dev LED device.
 * @param led LED number on that device.
 * @retval 0 Done.
 * @retval -EINVAL No such LED.
 */
static inline int led_off(const struct device *dev, uint32_t led)
{
	return ((const struct led_driver_api *)dev->api)->off(dev, led);
}

/**
 * @brief Set an LED's brightness (0 off .. 100 full).
 *
 * @retval 0 Done.
 * @retval -EINVAL No such LED or a value above 100.
 * @retval -ENOSYS The driver has no brightness control.
 */
static inline int led_set_brightness(const struct device *dev, uint32_t led, uint8_t value)
{
	const struct led_driver_api *api = (const struct led_driver_api *)dev->api;

	if (api->set_brightness == NULL) {
		return -ENOSYS;
	}
	return api->set_brightness(dev, led, value);
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_DRIVERS_LED_H_ */
