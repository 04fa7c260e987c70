/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * indicators: four devices (nodes 2..5) on the virtual bus, each with its CiA 303-3 RUN and
 * ERR LEDs on the virtual LED device, go through a scripted story so that a person can watch
 * every pattern change as it happens:
 *
 *   0 s  boot: Pre-operational, green blinking
 *   2 s  NMT start all: green on
 *   4 s  node 3 stopped: single flash
 *   5 s  node 5 cut off the bus: node 5 error passive (red single flash), node 4 loses its
 *        heartbeat (red double flash, and 1029h sends it to Pre-operational)
 *   8 s  node 5 back; node 4 started again
 *   9 s  node 2 bus-off: red on (1029h sends it to Pre-operational)
 *  11 s  node 2 recovers; 11.5 s started again
 *  13 s  end
 *
 * The LEDs are read back from the virtual LED device. --live draws them in place with
 * coloured glyphs; otherwise every change is one line. At the end every LED change and every
 * pattern change is printed (TRACE lines) for scripts/led-timeline, which draws them.
 */

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>

#include <can_virtual.h>
#include <canopen/leds.h>
#include <canopen/line.h>
#include <canopen/node.h>
#include <led_virtual.h>

#include "hello_node_od.h"
#include "led_view.h"

#define N_DEVICES   4
#define FIRST_ID    2
#define HB_TIME_MS  1500U /* node 4 watches node 5 (1017h: 1000 ms) */
#define POLL_MS     10
#define MAX_CHANGES 8192

struct device_node {
	struct co_line line;
	struct co_node node;
	struct hello_node_od_ram ram;
	enum co_led_pattern run;
	enum co_led_pattern err;
};

static struct device_node devs[N_DEVICES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_DEVICES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static const struct device *leds;

/* Pattern changes, kept for the TRACE lines at the end. */
static struct {
	uint64_t t_us;
	uint8_t id;
	uint8_t run;
	uint8_t err;
} patterns[256];
static int n_patterns;

static uint32_t green_led(int i)
{
	return (uint32_t)(2 * i);
}

static uint32_t red_led(int i)
{
	return (uint32_t)(2 * i + 1);
}

/* The live view: one line per device, redrawn in place. */
static void draw(bool first, const char *story)
{
	struct led_view_row rows[N_DEVICES];

	for (int i = 0; i < N_DEVICES; i++) {
		enum co_nmt_state st;

		co_node_lock(&devs[i].node);
		st = co_nmt_get_state(&devs[i].node);
		co_node_unlock(&devs[i].node);
		rows[i].green = green_led(i);
		rows[i].red = red_led(i);
		(void)snprintf(rows[i].label, sizeof(rows[i].label), "node %d ", FIRST_ID + i);
		(void)snprintf(rows[i].detail, sizeof(rows[i].detail), "%-15s RUN %-9s ERR %s",
			       co_nmt_state_str(st), led_view_pattern_name(devs[i].run),
			       led_view_pattern_name(devs[i].err));
	}
	led_view_draw(leds, first, story, rows, N_DEVICES);
}

static void note_patterns(void)
{
	for (int i = 0; i < N_DEVICES; i++) {
		enum co_led_pattern run, err;

		co_leds_get_patterns(&devs[i].node, &run, &err);
		if (run == devs[i].run && err == devs[i].err) {
			continue;
		}
		devs[i].run = run;
		devs[i].err = err;
		if (n_patterns < (int)ARRAY_SIZE(patterns)) {
			patterns[n_patterns++] = (typeof(patterns[0])){
				k_ticks_to_us_floor64((uint64_t)k_uptime_ticks()), FIRST_ID + i,
				run, err};
		}
		if (!led_view_live()) {
			printk("indicators: node %d RUN %s, ERR %s\n", FIRST_ID + i,
			       led_view_pattern_name(run), led_view_pattern_name(err));
		}
	}
}

static void send_nmt(uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, id}};

	/* Node 2 speaks for the master: its own frames do not reach itself, so tell it too. */
	co_node_lock(&devs[0].node);
	(void)co_node_send(&devs[0].node, CO_ROUTE_DEFAULT, &f);
	co_node_unlock(&devs[0].node);
	if (id == 0 || id == FIRST_ID) {
		(void)co_nmt_req(&devs[0].node, (enum co_nmt_cs)cs);
	}
}

static int start_device(int i)
{
	struct device_node *d = &devs[i];
	char name[16];
	const struct co_leds_cfg cfg = {.dev = leds, .green = green_led(i), .red = red_led(i)};
	static const char *const names[N_DEVICES] = {"node-2", "node-3", "node-4", "node-5"};
	int err;

	(void)snprintf(name, sizeof(name), "can_virtual%d", i);
	/* Node 2 leaves bus-off when the story says so, not 128 x 11 bit times later. */
	err = can_set_mode(device_get_binding(name), i == 0 ? CAN_MODE_MANUAL_RECOVERY : 0);
	if (err == 0) {
		err = co_line_init(&d->line, names[i], device_get_binding(name));
	}
	if (err == 0) {
		err = co_node_init(&d->node, names[i], &d->line, &hello_node_od_def, &d->ram,
				   (uint8_t)(FIRST_ID + i));
	}
	if (err == 0) {
		err = co_leds_attach(&d->node, &cfg);
	}
	if (err == 0) {
		err = co_line_start(&d->line, stacks[i], K_THREAD_STACK_SIZEOF(stacks[i]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&d->node);
	}
	return err;
}

/* Node 4 consumes node 5's heartbeat (after the start: Reset Communication reloads 1016h). */
static int watch_node_5(void)
{
	struct co_node *n = &devs[2].node;
	uint32_t ab;

	co_node_lock(n);
	ab = co_od_set_u32(co_node_od(n), 0x1016, 1, (5U << 16) | HB_TIME_MS, CO_OD_WRITER_APP);
	co_node_unlock(n);
	return ab == 0U ? 0 : -EIO;
}

static void print_trace(void)
{
	struct led_virtual_change c[64];
	uint64_t from = 0;
	size_t n;

	for (int i = 0; i < n_patterns; i++) {
		printk("TRACE pattern %llu %u %s %s\n", (unsigned long long)patterns[i].t_us,
		       patterns[i].id, led_view_pattern_name(patterns[i].run),
		       led_view_pattern_name(patterns[i].err));
	}
	while ((n = led_virtual_trace(leds, from, c, ARRAY_SIZE(c), &from)) > 0) {
		for (size_t k = 0; k < n; k++) {
			printk("TRACE led %llu %u %u %d\n", (unsigned long long)c[k].time_us,
			       FIRST_ID + c[k].led / 2, c[k].led % 2, c[k].on ? 1 : 0);
		}
	}
}

/* The story, step by step: at @p t_ms do @p what. */
struct step {
	uint32_t t_ms;
	const char *text;
	void (*what)(void);
};

static void start_all(void)
{
	send_nmt(CO_NMT_CS_START, 0);
}

static void stop_3(void)
{
	send_nmt(CO_NMT_CS_STOP, 3);
}

static void cut_5(void)
{
	(void)can_virtual_cut(device_get_binding("can_virtual3"));
}

static void restore_5(void)
{
	(void)can_virtual_restore(device_get_binding("can_virtual3"));
}

static void start_4(void)
{
	send_nmt(CO_NMT_CS_START, 4);
}

static void bus_off_2(void)
{
	(void)can_virtual_set_state(device_get_binding("can_virtual0"), CAN_STATE_BUS_OFF);
}

static void recover_2(void)
{
	(void)can_recover(device_get_binding("can_virtual0"), K_MSEC(100));
}

static void start_2(void)
{
	send_nmt(CO_NMT_CS_START, FIRST_ID);
}

static const struct step story[] = {
	{0, "boot: every device Pre-operational (green blinking)", NULL},
	{2000, "NMT start all: green on", start_all},
	{4000, "node 3 stopped: green single flash", stop_3},
	{5000, "node 5 cut off the bus: node 5 red single flash, node 4 red double flash", cut_5},
	{8000, "node 5 back on the bus", restore_5},
	{8500, "node 4 started again", start_4},
	{9000, "node 2 bus-off: red on (and 1029h: Pre-operational)", bus_off_2},
	{11000, "node 2 recovers from bus-off", recover_2},
	{11500, "node 2 started again", start_2},
	{13000, "end", NULL},
};

int main(void)
{
	int64_t t0;
	size_t next = 0;
	const char *text = story[0].text;
	bool first = true;

	leds = device_get_binding("led_virtual0");
	if (leds == NULL) {
		printk("indicators: no led_virtual0\n");
		return 1;
	}
	for (int i = 0; i < N_DEVICES; i++) {
		devs[i].run = CO_LED_OFF;
		devs[i].err = CO_LED_OFF;
		if (start_device(i) != 0) {
			printk("indicators: node %d failed to start\n", FIRST_ID + i);
			return 1;
		}
	}
	if (watch_node_5() != 0) {
		printk("indicators: cannot configure node 4's heartbeat consumer\n");
		return 1;
	}
	printk("indicators: 4 devices up on the virtual bus\n");
	t0 = k_uptime_get();
	while (next < ARRAY_SIZE(story)) {
		int64_t now = k_uptime_get() - t0;

		while (next < ARRAY_SIZE(story) && now >= story[next].t_ms) {
			text = story[next].text;
			if (!led_view_live()) {
				printk("indicators: %u.%01u s %s\n", story[next].t_ms / 1000U,
				       story[next].t_ms % 1000U / 100U, text);
			}
			if (story[next].what != NULL) {
				story[next].what();
			}
			next++;
		}
		note_patterns();
		if (led_view_live()) {
			draw(first, text);
			first = false;
		}
		k_msleep(POLL_MS);
	}
	print_trace();
	printk("indicators: done\n");
	return 0;
}
