/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <zephyr/kernel.h>
#include <zephyr/sys/util.h>

#include <led_virtual.h>

#include "cmdline.h"
#include "led_view.h"
#include "posix_native_task.h"

static bool live;

static void live_found(char *argv, int offset)
{
	live = true;
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.is_switch = true,
			.option = "live",
			.type = 'b',
			.call_when_found = live_found,
			.descript = "draw the LEDs in place with coloured glyphs (a terminal), "
				    "instead of one line per change",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

bool led_view_live(void)
{
	return live;
}

const char *led_view_pattern_name(enum co_led_pattern p)
{
	static const char *const names[] = {
		[CO_LED_OFF] = "off",          [CO_LED_ON] = "on",
		[CO_LED_FLICKER] = "flicker",  [CO_LED_BLINK] = "blink",
		[CO_LED_FLASH1] = "1 flash",   [CO_LED_FLASH2] = "2 flashes",
		[CO_LED_FLASH3] = "3 flashes", [CO_LED_FLASH4] = "4 flashes",
	};

	return (unsigned int)p < ARRAY_SIZE(names) && names[p] != NULL ? names[p] : "?";
}

static bool led(const struct device *leds, uint32_t n)
{
	bool on = false;

	(void)led_virtual_get(leds, n, &on);
	return on;
}

static const char *glyph(bool on, bool red)
{
	if (!on) {
		return "\033[2m\xe2\x97\x8b\033[0m"; /* dim ○ */
	}
	return red ? "\033[1;31m\xe2\x97\x8f\033[0m" : "\033[1;32m\xe2\x97\x8f\033[0m"; /* ● */
}

void led_view_draw(const struct device *leds, bool first, const char *status,
		   const struct led_view_row *rows, int n)
{
	if (!first) {
		printk("\033[%dA", n + 1);
	}
	printk("\r\033[K%s\n", status);
	for (int i = 0; i < n; i++) {
		printk("\r\033[K  %s RUN %s  ERR %s   %s\n", rows[i].label,
		       glyph(led(leds, rows[i].green), false), glyph(led(leds, rows[i].red), true),
		       rows[i].detail);
	}
}
