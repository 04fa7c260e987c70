/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * demo_network: four hello_node devices and a monitor on one virtual CAN bus, each on its own
 * controller and line thread. The monitor consumes the devices' heartbeats (1016h), starts
 * them with a broadcast NMT command, stops one, cuts another off the bus and restores it, and
 * prints what it sees. It stands in for the manager until the CiA 302 manager exists.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/node.h>

#include "hello_node_od.h"
#include "monitor_od.h"

#define N_DEVICES  4
#define MONITOR_ID 0x64
#define HB_TIME_MS 1500U /* consumer time; the devices send every 1000 ms (1017h) */
#define WAIT       K_SECONDS(5)

struct device_node {
	struct co_line line;
	struct co_node node;
	struct hello_node_od_ram ram;
};

static struct device_node devices[N_DEVICES];
static K_THREAD_STACK_ARRAY_DEFINE(device_stacks, N_DEVICES, CONFIG_CANOPEN_LINE_STACK_SIZE);

static struct co_line mon_line;
static struct co_node monitor;
static struct monitor_od_ram mon_ram;
static K_THREAD_STACK_DEFINE(mon_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* What the monitor knows, written in its line thread under its node lock. */
static struct {
	enum co_nmt_state state[N_DEVICES + 1];
	bool alive[N_DEVICES + 1];
	uint32_t events;
} seen;
static K_SEM_DEFINE(event_sem, 0, K_SEM_MAX_LIMIT);

static void hb_ind(struct co_node *node, uint8_t id, enum co_hb_event ev, enum co_nmt_state st,
		   void *user_data)
{
	if (id < 1 || id > N_DEVICES) {
		return;
	}
	switch (ev) {
	case CO_HB_EV_BOOTUP:
		printk("monitor: node %u boot-up\n", id);
		break;
	case CO_HB_EV_STARTED:
		printk("monitor: node %u heartbeat started (%s)\n", id, co_nmt_state_str(st));
		break;
	case CO_HB_EV_STATE:
		printk("monitor: node %u is %s\n", id, co_nmt_state_str(st));
		break;
	case CO_HB_EV_LOST:
		printk("monitor: node %u heartbeat lost\n", id);
		break;
	case CO_HB_EV_RECOVERED:
		printk("monitor: node %u heartbeat recovered (%s)\n", id, co_nmt_state_str(st));
		break;
	default:
		/* The per-line events come from a manager on two lines, never from here. */
		return;
	}
	seen.state[id] = ev == CO_HB_EV_BOOTUP ? CO_NMT_INITIALISING : st;
	seen.alive[id] = ev != CO_HB_EV_LOST;
	seen.events++;
	k_sem_give(&event_sem);
}

/* Wait until @p done holds for the monitor's view, or time out. */
static bool wait_for(bool (*done)(void *), void *arg)
{
	int64_t end = k_uptime_get() + 5000;

	for (;;) {
		bool ok;

		co_node_lock(&monitor);
		ok = done(arg);
		co_node_unlock(&monitor);
		if (ok) {
			return true;
		}
		if (k_sem_take(&event_sem, K_TIMEOUT_ABS_MS(end)) != 0) {
			return false;
		}
	}
}

static bool all_in_state(void *arg)
{
	enum co_nmt_state want = (enum co_nmt_state)(intptr_t)arg;

	for (int id = 1; id <= N_DEVICES; id++) {
		if (!seen.alive[id] || seen.state[id] != want) {
			return false;
		}
	}
	return true;
}

static bool node_in_state(void *arg)
{
	const int *want = arg; /* {id, state, alive} */

	return seen.state[want[0]] == (enum co_nmt_state)want[1] && seen.alive[want[0]] == want[2];
}

static void send_nmt(uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, id}};

	co_node_lock(&monitor);
	(void)co_node_send(&monitor, CO_ROUTE_DEFAULT, &f);
	co_node_unlock(&monitor);
}

static int start_monitor(void)
{
	const struct device *can = device_get_binding("can_virtual4");
	int err = co_line_init(&mon_line, "line-mon", can);

	if (err == 0) {
		err = co_node_init(&monitor, "monitor", &mon_line, &monitor_od_def, &mon_ram,
				   MONITOR_ID);
	}
	co_hb_set_ind(&monitor, hb_ind, NULL);
	if (err == 0) {
		err = co_line_start(&mon_line, mon_stack, K_THREAD_STACK_SIZEOF(mon_stack),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&monitor);
	}
	/* After the start: Reset Communication reloads 1016h with its defaults. */
	for (uint8_t id = 1; err == 0 && id <= N_DEVICES; id++) {
		uint32_t entry = ((uint32_t)id << 16) | HB_TIME_MS;

		co_node_lock(&monitor);
		if (co_od_set_u32(co_node_od(&monitor), 0x1016, id, entry, CO_OD_WRITER_APP) != 0) {
			err = -EIO;
		}
		co_node_unlock(&monitor);
	}
	return err;
}

static int start_device(int i)
{
	static const char *const names[] = {"line1", "line2", "line3", "line4"};
	static const char *const node_names[] = {"dev1", "dev2", "dev3", "dev4"};
	char can_name[16];
	struct device_node *d = &devices[i];
	int err;

	snprintk(can_name, sizeof(can_name), "can_virtual%d", i);
	err = co_line_init(&d->line, names[i], device_get_binding(can_name));
	if (err == 0) {
		err = co_node_init(&d->node, node_names[i], &d->line, &hello_node_od_def, &d->ram,
				   (uint8_t)(i + 1));
	}
	if (err == 0) {
		err = co_line_start(&d->line, device_stacks[i],
				    K_THREAD_STACK_SIZEOF(device_stacks[i]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&d->node);
	}
	return err;
}

static int step(bool ok, const char *what)
{
	if (!ok) {
		printk("demo: FAILED waiting for %s\n", what);
	}
	return ok ? 0 : 1;
}

int main(void)
{
	int failures = 0;

	printk("demo: %d hello_node devices and a monitor (node %u) on one virtual CAN bus\n",
	       N_DEVICES, MONITOR_ID);
	if (start_monitor() != 0) {
		printk("demo: monitor failed to start\n");
		return 1;
	}
	for (int i = 0; i < N_DEVICES; i++) {
		if (start_device(i) != 0) {
			printk("demo: device %d failed to start\n", i + 1);
			return 1;
		}
	}

	failures += step(wait_for(all_in_state, (void *)(intptr_t)CO_NMT_PRE_OPERATIONAL),
			 "all devices PRE-OPERATIONAL");

	printk("monitor: NMT start all nodes\n");
	send_nmt(CO_NMT_CS_START, 0);
	failures += step(wait_for(all_in_state, (void *)(intptr_t)CO_NMT_OPERATIONAL),
			 "all devices OPERATIONAL");

	printk("monitor: NMT stop node 3\n");
	send_nmt(CO_NMT_CS_STOP, 3);
	failures +=
		step(wait_for(node_in_state, (int[]){3, CO_NMT_STOPPED, true}), "node 3 STOPPED");

	printk("demo: cutting node 4 off the bus\n");
	can_virtual_cut(device_get_binding("can_virtual3"));
	failures += step(wait_for(node_in_state, (int[]){4, CO_NMT_OPERATIONAL, false}),
			 "node 4 heartbeat lost");

	printk("demo: reconnecting node 4\n");
	can_virtual_restore(device_get_binding("can_virtual3"));
	failures += step(wait_for(node_in_state, (int[]){4, CO_NMT_OPERATIONAL, true}),
			 "node 4 heartbeat recovered");

	co_node_lock(&monitor);
	printk("\n node  state            heartbeat\n");
	for (int id = 1; id <= N_DEVICES; id++) {
		printk(" %4d  %-15s  %s\n", id, co_nmt_state_str(seen.state[id]),
		       seen.alive[id] ? "ok" : "lost");
	}
	co_node_unlock(&monitor);

	printk("demo: %s\n", failures == 0 ? "done" : "FAILED");
	return failures == 0 ? 0 : 1;
}
