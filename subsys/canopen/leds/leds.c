/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * CiA 303-3 indicators: the RUN and ERR patterns chosen from the node's events, shown on LEDs
 * through Zephyr's LED API.
 *
 * Decisions (doc/leds.md):
 * - The patterns run on the node's clock in 50 ms ticks counted from time 0, so every node's
 *   LEDs keep one phase and a new pattern starts in the phase of the running cycle. A timer
 *   runs at the tick edges only while a LED shows a changing pattern; steady LEDs cost nothing.
 * - Antiphase: green is on in even slots, red in odd ones (flicker: even and odd ticks). The
 *   flash cycles (6, 8, 10, 12 slots) are even, so the rule holds across cycles.
 * - ERR priority is CANopenNode's order (CiA 303-3's wording was not available): bus-off,
 *   no node-ID, RPDO timeout, SYNC error, error control, warning limit, error register.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/drivers/can.h>
#include <zephyr/drivers/led.h>
#include <zephyr/kernel.h>

#include <canopen/emcy.h>
#include <canopen/leds.h>
#include <canopen/node.h>

#include "node_internal.h"

#define TICKS_PER_SLOT 4U /* 200 ms */
#define OFF_SLOTS      5U /* 1000 ms after the last flash */

static bool steady(uint8_t p)
{
	return p == CO_LED_OFF || p == CO_LED_ON;
}

/* Whether a pattern is on at @p tick; red uses the odd half of every cycle. */
static bool pattern_on(uint8_t p, uint64_t tick, bool red)
{
	uint64_t slot = tick / TICKS_PER_SLOT;
	uint64_t phase = red ? 1U : 0U;

	switch (p) {
	case CO_LED_ON:
		return true;
	case CO_LED_FLICKER:
		return tick % 2U == phase;
	case CO_LED_BLINK:
		return slot % 2U == phase;
	case CO_LED_FLASH1:
	case CO_LED_FLASH2:
	case CO_LED_FLASH3:
	case CO_LED_FLASH4: {
		uint64_t n = (uint64_t)(p - CO_LED_FLASH1) + 1U;
		uint64_t pos = slot % (2U * n - 1U + OFF_SLOTS);

		return pos % 2U == phase && pos <= 2U * n - 2U + phase;
	}
	default:
		return false;
	}
}

static void outputs_at(const struct co_leds *l, uint64_t now_us, bool *green, bool *red)
{
	uint64_t tick = now_us / CO_LEDS_TICK_US;

	*red = pattern_on(l->err, tick, true);
	*green = pattern_on(l->run, tick, false) && !(l->cfg.bicolour && *red);
}

static void drive(struct co_leds *l, uint32_t led, bool on)
{
	if (led != CO_LED_NONE) {
		(void)(on ? led_on(l->cfg.dev, led) : led_off(l->cfg.dev, led));
	}
}

/* Bring the outputs to the patterns at @p now_us and arm the next tick edge if needed. */
static void refresh(struct co_node *node, uint64_t now_us)
{
	struct co_leds *l = &node->leds;
	bool green, red;

	outputs_at(l, now_us, &green, &red);
	if (l->attached) {
		/* Off before on: a bicolour LED never shows both colours. */
		if (!green && l->green_on) {
			drive(l, l->cfg.green, false);
		}
		if (red != l->red_on) {
			drive(l, l->cfg.red, red);
		}
		if (green && !l->green_on) {
			drive(l, l->cfg.green, true);
		}
	}
	l->green_on = green;
	l->red_on = red;
	if (steady(l->run) && steady(l->err)) {
		co_timer_stop(&l->timer);
	} else {
		co_node_timer_start(node, &l->timer,
				    (now_us / CO_LEDS_TICK_US + 1U) * CO_LEDS_TICK_US);
	}
}

static void tick(struct co_timer *timer, uint64_t now_us)
{
	refresh(timer->user_data, now_us);
}

static uint8_t run_pattern(const struct co_node *node)
{
	/* LSS configuration (CiA 305) is shown over the NMT state. */
	if (node->leds.lss_config) {
		return CO_LED_FLICKER;
	}
	switch (co_node_nmt_state(node)) {
	case CO_NMT_OPERATIONAL:
		return CO_LED_ON;
	case CO_NMT_PRE_OPERATIONAL:
		return CO_LED_BLINK;
	case CO_NMT_STOPPED:
		return CO_LED_FLASH1;
	default:
		return CO_LED_OFF;
	}
}

static uint8_t err_pattern(const struct co_node *node)
{
	const struct co_leds *l = &node->leds;
	bool hb_lost = (l->hb_lost[0] | l->hb_lost[1] | l->hb_lost[2] | l->hb_lost[3]) != 0U;

	if (l->bus_off) {
		return CO_LED_ON;
	}
	if (!co_node_is_configured(node)) {
		return CO_LED_FLICKER;
	}
	if (l->rpdo_timeout) {
		return CO_LED_FLASH4;
	}
	if (l->sync_error) {
		return CO_LED_FLASH3;
	}
	if (hb_lost || l->life_lost) {
		return CO_LED_FLASH2;
	}
	if (l->warning) {
		return CO_LED_FLASH1;
	}
	return l->err_reg != 0U ? CO_LED_BLINK : CO_LED_OFF;
}

static void update(struct co_node *node)
{
	struct co_leds *l = &node->leds;
	uint8_t run = run_pattern(node);
	uint8_t err = err_pattern(node);

	if (run != l->run || err != l->err) {
		l->run = run;
		l->err = err;
		refresh(node, co_node_time(node));
	}
}

static void hb_event(struct co_leds *l, uint8_t id, enum co_hb_event ev)
{
	uint32_t bit = BIT(id % 32U);
	uint32_t *word = &l->hb_lost[(id / 32U) % ARRAY_SIZE(l->hb_lost)];

	if (ev == CO_HB_EV_LOST) {
		*word |= bit;
	} else if (ev == CO_HB_EV_RECOVERED || ev == CO_HB_EV_BOOTUP || ev == CO_HB_EV_STARTED) {
		*word &= ~bit;
	} else {
		/* A state change of a running consumer does not change its lost flag. */
	}
}

static int node_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct co_leds *l = &node->leds;

	ARG_UNUSED(user_data);
	switch (ev->type) {
	case CO_EV_HB:
		hb_event(l, ev->hb.node_id, ev->hb.event);
		break;
	case CO_EV_LIFE:
		l->life_lost = ev->life.lost;
		break;
	case CO_EV_ERROR:
		if (ev->error.code == CO_EMCY_RPDO_TIMEOUT) {
			l->rpdo_timeout = (ev->error.flags & CO_ERROR_F_ACTIVE) != 0U;
		} else if (ev->error.code == CO_EMCY_SYNC_LENGTH) {
			l->sync_error = (ev->error.flags & CO_ERROR_F_ACTIVE) != 0U;
		} else {
			/* Other errors have no LED pattern of their own. */
		}
		break;
	case CO_EV_EMCY:
		if (ev->emcy.own) {
			l->err_reg = ev->emcy.reg;
		}
		break;
	case CO_EV_LINE:
		if (ev->line.idx == CO_LINE_DEFAULT && ev->line.event == CO_LINE_EV_CAN_STATE &&
		    ev->line.arg != CAN_STATE_STOPPED) {
			l->bus_off = ev->line.arg == CAN_STATE_BUS_OFF;
			l->warning = ev->line.arg == CAN_STATE_ERROR_WARNING ||
				     ev->line.arg == CAN_STATE_ERROR_PASSIVE;
		}
		break;
	case CO_EV_LSS:
		/* enum co_lss_state: 0 waiting, 1 configuration. */
		l->lss_config = ev->lss.to != 0U;
		break;
	case CO_EV_NMT_RESET:
		/* A reset drops the stack's own errors; the controller's state stays. */
		(void)memset(l->hb_lost, 0, sizeof(l->hb_lost));
		l->life_lost = false;
		l->rpdo_timeout = false;
		l->sync_error = false;
		l->err_reg = 0U;
		break;
	default:
		break;
	}
	update(node);
	return 0;
}

static int leds_init(struct co_node *node)
{
	struct co_leds *l = &node->leds;

	(void)memset(l, 0, sizeof(*l));
	co_timer_init(&l->timer, tick, &node->lock, node);
	co_listener_init(&l->listener, "leds",
			 CO_EV_BIT(CO_EV_NMT_STATE) | CO_EV_BIT(CO_EV_NMT_RESET) |
				 CO_EV_BIT(CO_EV_HB) | CO_EV_BIT(CO_EV_LIFE) |
				 CO_EV_BIT(CO_EV_ERROR) | CO_EV_BIT(CO_EV_EMCY) |
				 CO_EV_BIT(CO_EV_LINE) | CO_EV_BIT(CO_EV_LSS),
			 node_event, NULL);
	l->run = run_pattern(node);
	l->err = err_pattern(node);
	return co_node_listener_add(node, &l->listener);
}

const struct co_service co_service_leds = {
	.name = "leds",
	.flags = CO_SERVICE_F_UNCONFIGURED,
	.init = leds_init,
};

int co_leds_attach(struct co_node *node, const struct co_leds_cfg *cfg)
{
	struct co_leds *l;

	if (node == NULL || cfg == NULL || cfg->dev == NULL ||
	    (cfg->green == CO_LED_NONE && cfg->red == CO_LED_NONE)) {
		return -EINVAL;
	}
	if (!device_is_ready(cfg->dev)) {
		return -ENODEV;
	}
	co_node_lock(node);
	l = &node->leds;
	l->cfg = *cfg;
	l->attached = true;
	/* Start from dark LEDs: drive both to what they show now. */
	drive(l, cfg->green, false);
	drive(l, cfg->red, false);
	l->green_on = false;
	l->red_on = false;
	refresh(node, co_node_time(node));
	co_node_unlock(node);
	return 0;
}

void co_leds_get_patterns(struct co_node *node, enum co_led_pattern *run, enum co_led_pattern *err)
{
	co_node_lock(node);
	if (run != NULL) {
		*run = (enum co_led_pattern)node->leds.run;
	}
	if (err != NULL) {
		*err = (enum co_led_pattern)node->leds.err;
	}
	co_node_unlock(node);
}

void co_leds_get(struct co_node *node, bool *green, bool *red)
{
	bool g, r;

	co_node_lock(node);
	outputs_at(&node->leds, co_node_time(node), &g, &r);
	co_node_unlock(node);
	if (green != NULL) {
		*green = g;
	}
	if (red != NULL) {
		*red = r;
	}
}
