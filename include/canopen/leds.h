/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen indicators: the green RUN and red ERR LEDs of CiA 303-3.
 *
 * The service follows the node's events (NMT state, heartbeat and life guarding, errors,
 * emergencies, the CAN controller's state) and shows them with CiA 303-3's patterns:
 *
 * | LED | pattern (highest priority first) |
 * |---|---|
 * | RUN (green) | on: Operational; blinking: Pre-operational; single flash: Stopped; off:
 * Initialising | | ERR (red) | on: bus-off; flickering: no node-ID; quadruple flash: RPDO timeout
 * (8250h); triple flash: SYNC error (8240h); double flash: a heartbeat consumer or life guarding
 * event; single flash: CAN warning limit (error warning or passive); blinking: any other error in
 * the error register; off |
 *
 * Flicker is 50 ms on / 50 ms off; blinking 200/200 ms; an n-fold flash is n times 200 ms on
 * with 200 ms between, then 1000 ms off. When both LEDs show a pattern they run in antiphase
 * (never on in the same slot); on a bicolour LED red wins over green. The LEDs are driven
 * through Zephyr's LED API (led_on()/led_off() on a device), so a firmware wires its GPIO
 * LEDs without changing the stack; on native_posix "led_virtual0" records every change.
 *
 * @defgroup co_leds Indicators
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_LEDS_H_
#define SAFELINE_INCLUDE_CANOPEN_LEDS_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/device.h>

#include <canopen/event.h>
#include <canopen/line.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** An LED pattern of CiA 303-3. */
enum co_led_pattern {
	CO_LED_OFF,     /**< constantly off */
	CO_LED_ON,      /**< constantly on */
	CO_LED_FLICKER, /**< 50 ms on, 50 ms off */
	CO_LED_BLINK,   /**< 200 ms on, 200 ms off */
	CO_LED_FLASH1,  /**< single flash: 200 ms on, 1000 ms off */
	CO_LED_FLASH2,  /**< double flash */
	CO_LED_FLASH3,  /**< triple flash */
	CO_LED_FLASH4,  /**< quadruple flash */
};

/** Tick of the patterns [µs]: flicker slots are one tick, the other slots four. */
#define CO_LEDS_TICK_US 50000U

/** An LED number that is not there (a device with only one of the two LEDs). */
#define CO_LED_NONE UINT32_MAX

/** Where a node's indicators are. */
struct co_leds_cfg {
	/** LED device (Zephyr LED API). */
	const struct device *dev;
	/** Number of the green RUN LED on @ref dev, or CO_LED_NONE. */
	uint32_t green;
	/** Number of the red ERR LED on @ref dev, or CO_LED_NONE. */
	uint32_t red;
	/** One bicolour LED: green is off whenever red is on. */
	bool bicolour;
};

/** @cond INTERNAL_HIDDEN */
#if defined(CONFIG_CANOPEN_LEDS)
struct co_leds {
	struct co_listener listener;
	struct co_timer timer;
	struct co_leds_cfg cfg;
	bool attached;
	/* The node's LSS slave is in configuration state (RUN flickers). */
	bool lss_config;
	/* What the ERR LED shows, from the node's events. */
	bool bus_off;
	bool warning;
	bool life_lost;
	bool rpdo_timeout;
	bool sync_error;
	uint8_t err_reg;
	uint32_t hb_lost[4]; /* one bit per remote node-ID */
	uint8_t run;         /* enum co_led_pattern */
	uint8_t err;
	/* Outputs as last driven (after the bicolour rule). */
	bool green_on;
	bool red_on;
};
#endif
/** @endcond */

/**
 * @brief Drive the node's indicators on LEDs of a device.
 *
 * May be called before or after co_node_start(); the LEDs show the current patterns at once.
 *
 * @retval 0 Done.
 * @retval -EINVAL A NULL argument, or neither LED given.
 * @retval -ENODEV The device is not ready.
 */
int co_leds_attach(struct co_node *node, const struct co_leds_cfg *cfg);

/**
 * @brief The patterns the node's RUN and ERR LEDs show now.
 *
 * @param node The node.
 * @param run If not NULL, gets the RUN (green) pattern.
 * @param err If not NULL, gets the ERR (red) pattern.
 */
void co_leds_get_patterns(struct co_node *node, enum co_led_pattern *run, enum co_led_pattern *err);

/**
 * @brief Whether the node's green and red LEDs are on now (after the bicolour rule).
 *
 * The state at the node's current time, as the outputs are driven.
 */
void co_leds_get(struct co_node *node, bool *green, bool *red);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_LEDS_H_ */
