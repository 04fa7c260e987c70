/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The live LED view the indicators and commissioning samples share: the --live option, the
 * names of the CiA 303-3 patterns, and a table of one status line plus one line per device,
 * its RUN and ERR LEDs read back from the virtual LED device as coloured glyphs, redrawn in
 * place in a terminal.
 */

#ifndef SAFELINE_SAMPLES_CANOPEN_COMMON_LED_VIEW_H_
#define SAFELINE_SAMPLES_CANOPEN_COMMON_LED_VIEW_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/device.h>

#include <canopen/leds.h>

/* One device's line: "  <label> RUN <glyph>  ERR <glyph>   <detail>". */
struct led_view_row {
	/* The device's LEDs on the virtual LED device. */
	uint32_t green;
	uint32_t red;
	char label[32];
	char detail[96];
};

/* Whether --live was given (the option is registered by linking this file). */
bool led_view_live(void);

/* "off", "on", "flicker", "blink", "1 flash" .. "4 flashes"; "?" for another value. */
const char *led_view_pattern_name(enum co_led_pattern p);

/*
 * Draw @p status and @p n rows; after the first call (@p first false) the cursor goes back
 * up over the previous table first, so the view stays in place.
 */
void led_view_draw(const struct device *leds, bool first, const char *status,
		   const struct led_view_row *rows, int n);

#endif /* SAFELINE_SAMPLES_CANOPEN_COMMON_LED_VIEW_H_ */
