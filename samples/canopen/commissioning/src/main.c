/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * commissioning: a CiA 302 manager (node 1) and four devices that start without node-ID
 * (FFh), each on its own controller of the virtual bus. The manager's dictionary expects
 * nodes 2..5 by identity (1F85h..1F88h, serial numbers A001h..A004h). Their boots end with B
 * (nobody answers), so the manager searches each by LSS fastscan, gives it its node-ID,
 * has it stored and switches it back to waiting: the device boots with its node-ID, the
 * manager's boot retry checks its identity and starts it.
 *
 * Every device's CiA 303-3 LEDs: red/green flicker while it has no node-ID (green in LSS
 * configuration), green blinking in Pre-operational, green on in Operational. --live draws
 * them in place with coloured glyphs; otherwise every change is one line.
 */

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <canopen/leds.h>
#include <canopen/line.h>
#include <canopen/lss.h>
#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/storage.h>
#include "commissioning_manager_od.h"
#include "hello_node_od.h"
#include "led_view.h"

#define N_DEVICES  4
#define MANAGER_ID 1U
#define FIRST_ID   2U
#define SERIAL(i)  (0xA001U + (uint32_t)(i))
#define POLL_MS    10
#define RUN_MS     30000

struct device_node {
	struct co_line line;
	struct co_node node;
	struct hello_node_od_ram ram;
	struct co_storage_ram medium;
	uint8_t mem[64];
	enum co_led_pattern run;
	enum co_led_pattern err;
	enum co_nmt_state state;
};

static struct device_node devs[N_DEVICES];
static struct co_line mline;
static struct co_node manager;
static struct commissioning_manager_od_ram mram;
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_DEVICES + 1, CONFIG_CANOPEN_LINE_STACK_SIZE);
static const struct device *leds;
static const char *status = "devices without node-ID; the manager boots";

static uint8_t node_id(int i)
{
	uint8_t id;

	co_node_lock(&devs[i].node);
	id = co_node_id(&devs[i].node);
	co_node_unlock(&devs[i].node);
	return id;
}

/* The live view: one line per device, redrawn in place. */
static void draw(bool first)
{
	struct led_view_row rows[N_DEVICES];

	for (int i = 0; i < N_DEVICES; i++) {
		uint8_t id = node_id(i);
		char ids[8];

		(void)snprintf(ids, sizeof(ids), id == CO_NODE_ID_UNCONFIGURED ? "--" : "%u", id);
		rows[i].green = (uint32_t)(2 * i);
		rows[i].red = (uint32_t)(2 * i + 1);
		(void)snprintf(rows[i].label, sizeof(rows[i].label), "serial %04X  node %-3s",
			       SERIAL(i), ids);
		(void)snprintf(rows[i].detail, sizeof(rows[i].detail),
			       "LSS %-13s %-15s RUN %-9s ERR %s",
			       co_lss_get_state(&devs[i].node) == CO_LSS_STATE_CONFIGURATION
				       ? "configuration"
				       : "waiting",
			       co_nmt_state_str(devs[i].state), led_view_pattern_name(devs[i].run),
			       led_view_pattern_name(devs[i].err));
	}
	led_view_draw(leds, first, status, rows, N_DEVICES);
}

static void note_changes(void)
{
	for (int i = 0; i < N_DEVICES; i++) {
		enum co_led_pattern run, err;
		enum co_nmt_state st;

		co_leds_get_patterns(&devs[i].node, &run, &err);
		co_node_lock(&devs[i].node);
		st = co_nmt_get_state(&devs[i].node);
		co_node_unlock(&devs[i].node);
		if (run == devs[i].run && err == devs[i].err && st == devs[i].state) {
			continue;
		}
		devs[i].run = run;
		devs[i].err = err;
		devs[i].state = st;
		if (!led_view_live()) {
			printk("commissioning: serial %04X node %u %s: RUN %s, ERR %s\n", SERIAL(i),
			       node_id(i), co_nmt_state_str(st), led_view_pattern_name(run),
			       led_view_pattern_name(err));
		}
	}
}

static void say(const char *text)
{
	status = text;
	if (!led_view_live()) {
		printk("commissioning: %s\n", text);
	}
}

/* --- The manager ---------------------------------------------------------------------------- */

static void put(struct co_od *od, uint16_t index, uint8_t sub, uint32_t value)
{
	uint8_t buf[4];

	sys_put_le32(value, buf);
	(void)co_od_write(od, index, sub, buf, sizeof(buf), CO_OD_WRITER_APP);
}

/* The manager's configuration, applied at every reset as a stored one would be. */
static void manager_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	put(od, 0x1F80, 0, 0x01); /* NMT master, start each slave when it booted */
	for (uint8_t i = 0; i < N_DEVICES; i++) {
		uint8_t id = (uint8_t)(FIRST_ID + i);

		put(od, 0x1F81, id, 0x0D); /* slave, may boot, mandatory */
		put(od, 0x1F85, id, 0x00000539);
		put(od, 0x1F86, id, 0x00000001);
		put(od, 0x1F88, id, SERIAL(i));
	}
}

static void on_lss(struct co_node *node, uint8_t id, int err, const struct co_lss_address *addr,
		   void *user_data)
{
	static char text[96];

	if (err == 0) {
		(void)snprintf(text, sizeof(text),
			       "node %u found by fastscan (serial %04X): node-ID given and stored",
			       id, addr->part[3]);
	} else {
		(void)snprintf(text, sizeof(text), "node %u not found by LSS (%d)", id, err);
	}
	say(text);
}

static void on_boot(struct co_node *node, uint8_t id, uint8_t st,
		    const struct co_mgr_boot_error *err, void *user_data)
{
	static char text[64];

	if (st == CO_MGR_ST_OK) {
		(void)snprintf(text, sizeof(text), "node %u booted by the manager", id);
	} else {
		(void)snprintf(text, sizeof(text), "node %u boot status %c", id, st);
	}
	say(text);
}

static int start_manager(void)
{
	int err = co_line_init(&mline, "manager", device_get_binding("can_virtual0"));

	if (err == 0) {
		err = co_node_init(&manager, "manager", &mline, &commissioning_manager_od_def,
				   &mram, MANAGER_ID);
	}
	if (err == 0) {
		co_od_set_restore_cb(co_node_od(&manager), manager_restore, NULL);
		co_mgr_set_lss_ind(&manager, on_lss, NULL);
		co_mgr_set_boot_ind(&manager, on_boot, NULL);
		err = co_line_start(&mline, stacks[N_DEVICES], K_THREAD_STACK_SIZEOF(stacks[0]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&manager);
	}
	return err;
}

/* --- The devices ---------------------------------------------------------------------------- */

/* The serial number of device @p user_data (1018h:04), kept over every reset. */
static void device_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	put(od, 0x1018, 4, SERIAL((int)(intptr_t)user_data));
}

static int start_device(int i)
{
	struct device_node *d = &devs[i];
	static const char *const names[N_DEVICES] = {"dev-A001", "dev-A002", "dev-A003",
						     "dev-A004"};
	const struct co_leds_cfg cfg = {
		.dev = leds, .green = (uint32_t)(2 * i), .red = (uint32_t)(2 * i + 1)};
	char dev[16];
	int err;

	(void)snprintf(dev, sizeof(dev), "can_virtual%d", i + 1);
	err = co_line_init(&d->line, names[i], device_get_binding(dev));
	if (err == 0) {
		err = co_node_init(&d->node, names[i], &d->line, &hello_node_od_def, &d->ram,
				   CO_NODE_ID_UNCONFIGURED);
	}
	if (err == 0) {
		co_od_set_restore_cb(co_node_od(&d->node), device_restore, (void *)(intptr_t)i);
		err = co_leds_attach(&d->node, &cfg);
	}
	if (err == 0) {
		/* A fresh medium: nothing stored yet (-ENOENT); store configuration writes it. */
		err = co_storage_ram_init(&d->medium, d->mem, sizeof(d->mem));
	}
	if (err == 0) {
		err = co_lss_store_attach(&d->node, &d->medium.be, NULL);
		err = err == -ENOENT ? 0 : err;
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

static int operational(void)
{
	int n = 0;

	for (int i = 0; i < N_DEVICES; i++) {
		n += devs[i].state == CO_NMT_OPERATIONAL ? 1 : 0;
	}
	return n;
}

static void print_stored(void)
{
	for (int i = 0; i < N_DEVICES; i++) {
		struct co_lss_config cfg = {.node_id = CO_NODE_ID_UNCONFIGURED};

		/* Read back what store configuration wrote (it boots with it next time). */
		(void)co_lss_store_attach(&devs[i].node, &devs[i].medium.be, &cfg);
		printk("commissioning: serial %04X stored node-ID %u\n", SERIAL(i), cfg.node_id);
	}
}

int main(void)
{
	int64_t t0;
	bool first = true;

	leds = device_get_binding("led_virtual0");
	if (leds == NULL) {
		printk("commissioning: no led_virtual0\n");
		return 1;
	}
	for (int i = 0; i < N_DEVICES; i++) {
		devs[i].run = CO_LED_OFF;
		devs[i].err = CO_LED_OFF;
		devs[i].state = CO_NMT_INITIALISING;
		if (start_device(i) != 0) {
			printk("commissioning: device %d failed to start\n", i);
			return 1;
		}
	}
	printk("commissioning: %d devices without node-ID, serial numbers %04X..%04X\n", N_DEVICES,
	       SERIAL(0), SERIAL(N_DEVICES - 1));
	if (start_manager() != 0) {
		printk("commissioning: the manager failed to start\n");
		return 1;
	}
	t0 = k_uptime_get();
	while (k_uptime_get() - t0 < RUN_MS) {
		note_changes();
		if (led_view_live()) {
			draw(first);
			first = false;
		}
		if (operational() == N_DEVICES) {
			break;
		}
		k_msleep(POLL_MS);
	}
	if (operational() == N_DEVICES) {
		say("all 4 devices Operational");
	} else {
		say("not every device became Operational");
	}
	if (led_view_live()) {
		/* Let the person see the final state for a moment. */
		for (int k = 0; k < 100; k++) {
			note_changes();
			draw(false);
			k_msleep(POLL_MS);
		}
	}
	printk("commissioning: done in %lld ms\n", (long long)(k_uptime_get() - t0));
	print_stored();
	return operational() == N_DEVICES ? 0 : 1;
}
