/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Virtual LEDs (native_posix): Zephyr's LED API over an array of states, with every change
 * recorded in a ring for tests, a terminal view and scripts/led-timeline.
 */

#include <errno.h>

#include <zephyr/device.h>
#include <zephyr/drivers/led.h>
#include <zephyr/kernel.h>

#include "led_virtual.h"

struct lv_data {
	struct k_mutex lock;
	uint32_t on_mask;
	uint64_t n_changes;
	struct led_virtual_change trace[CONFIG_LED_VIRTUAL_TRACE_SIZE];
	led_virtual_cb_t cb;
	void *cb_user_data;
};

BUILD_ASSERT(CONFIG_LED_VIRTUAL_COUNT <= 32, "one bit per LED");

static int lv_set(const struct device *dev, uint32_t led, bool on)
{
	struct lv_data *d = dev->data;
	struct led_virtual_change c = {.led = led, .on = on};
	led_virtual_cb_t cb;
	void *user_data;

	if (led >= CONFIG_LED_VIRTUAL_COUNT) {
		return -EINVAL;
	}
	k_mutex_lock(&d->lock, K_FOREVER);
	if (((d->on_mask >> led) & 1U) == (on ? 1U : 0U)) {
		k_mutex_unlock(&d->lock);
		return 0;
	}
	d->on_mask ^= BIT(led);
	c.time_us = k_ticks_to_us_floor64((uint64_t)k_uptime_ticks());
	d->trace[d->n_changes % CONFIG_LED_VIRTUAL_TRACE_SIZE] = c;
	d->n_changes++;
	cb = d->cb;
	user_data = d->cb_user_data;
	k_mutex_unlock(&d->lock);
	if (cb != NULL) {
		cb(dev, &c, user_data);
	}
	return 0;
}

static int lv_on(const struct device *dev, uint32_t led)
{
	return lv_set(dev, led, true);
}

static int lv_off(const struct device *dev, uint32_t led)
{
	return lv_set(dev, led, false);
}

static int lv_set_brightness(const struct device *dev, uint32_t led, uint8_t value)
{
	if (value > 100U) {
		return -EINVAL;
	}
	return lv_set(dev, led, value != 0U);
}

int led_virtual_get(const struct device *dev, uint32_t led, bool *on)
{
	struct lv_data *d = dev->data;

	if (led >= CONFIG_LED_VIRTUAL_COUNT || on == NULL) {
		return -EINVAL;
	}
	k_mutex_lock(&d->lock, K_FOREVER);
	*on = ((d->on_mask >> led) & 1U) != 0U;
	k_mutex_unlock(&d->lock);
	return 0;
}

size_t led_virtual_trace(const struct device *dev, uint64_t from, struct led_virtual_change *out,
			 size_t max, uint64_t *next)
{
	struct lv_data *d = dev->data;
	size_t n = 0;

	k_mutex_lock(&d->lock, K_FOREVER);
	if (d->n_changes > CONFIG_LED_VIRTUAL_TRACE_SIZE &&
	    from < d->n_changes - CONFIG_LED_VIRTUAL_TRACE_SIZE) {
		from = d->n_changes - CONFIG_LED_VIRTUAL_TRACE_SIZE;
	}
	for (; from < d->n_changes && n < max; from++) {
		out[n++] = d->trace[from % CONFIG_LED_VIRTUAL_TRACE_SIZE];
	}
	if (next != NULL) {
		*next = from;
	}
	k_mutex_unlock(&d->lock);
	return n;
}

void led_virtual_set_callback(const struct device *dev, led_virtual_cb_t cb, void *user_data)
{
	struct lv_data *d = dev->data;

	k_mutex_lock(&d->lock, K_FOREVER);
	d->cb = cb;
	d->cb_user_data = user_data;
	k_mutex_unlock(&d->lock);
}

static int lv_init(const struct device *dev)
{
	struct lv_data *d = dev->data;

	k_mutex_init(&d->lock);
	return 0;
}

static const struct led_driver_api lv_api = {
	.on = lv_on,
	.off = lv_off,
	.set_brightness = lv_set_brightness,
};

static struct lv_data lv_data_0;

DEVICE_DEFINE(led_virtual0, "led_virtual0", lv_init, NULL, &lv_data_0, NULL, POST_KERNEL, 50,
	      &lv_api);
