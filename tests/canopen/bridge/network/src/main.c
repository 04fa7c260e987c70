/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A network for the DDS bridge tests (pytest/) and its benchmark (../bench): two buses of the
 * virtual bus, each with a gateway node (node 1, bridged: line 0 and line 1, with the SDO
 * client for requests, a heartbeat consumer and an EMCY consumer of its device) and a device
 * (node 7 on bus 0, node 9 on bus 1, not bridged: the bridge sees it through the gateway).
 *
 * The test drives it through stdin, one command a line, each answered "ok <command>" (or
 * "error <command>: reason") once done:
 *   emcy LINE CODE | clear LINE CODE   the device of LINE raises / clears an EMCY
 *   srdo LINE N SAFE REASON            the gateway of LINE publishes an SRDO event
 *   switch LINE TO                     the gateway of LINE publishes a CiA 302-6 line switch
 *                                      to its line TO (0 default, 1 redundant)
 *   burst N                            N events on gateway 0 as fast as they can be raised
 *   canstate LINE STATE                the gateway's controller enters enum can_state STATE
 *   count LINE VALUE                   the gateway's 2000h := VALUE (a local object value)
 *   cut LINE | restore LINE            the device of LINE leaves the bus / comes back
 *   bench RATE SECONDS                 device 7 sends raw EMCY frames (8F00h) at RATE per
 *                                      second, stamped with CLOCK_MONOTONIC [µs] in bytes 3..6
 *                                      and a sequence number in byte 7
 *   stats                              prints the bridge's counters
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>

#include <can_virtual.h>
#include <canopen/bridge_dds.h>
#include <canopen/emcy.h>
#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/redundancy.h>

#include "bridge_test_od.h"
#include "cmdline.h"
#include "posix_native_task.h"

LOG_MODULE_REGISTER(bridge_net, LOG_LEVEL_INF);

#define GW_ID      1U
#define LINES      2
#define BENCH_CODE 0x8F00U

static const uint8_t dev_ids[LINES] = {7U, 9U};

struct unit {
	struct co_line line;
	struct co_node node;
	struct bridge_test_od_ram ram;
};

static struct unit gw[LINES];
static struct unit dev[LINES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, 2 * LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);

static uint32_t domain_arg = CO_BRIDGE_DDS_DOMAIN_DEFAULT;

static void domain_found(char *argv, int offset)
{
	domain_arg = (uint32_t)cmd_read_uint_option("dds-domain", &argv[offset], 0U, 232U);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "dds-domain",
			.name = "0..232",
			.type = 'u',
			.call_when_found = domain_found,
			.descript = "DDS domain of the bridge",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

static void stop_bridge(void)
{
	co_bridge_dds_stop();
}
NATIVE_TASK(stop_bridge, ON_EXIT, 10);

static int od_put(struct co_node *node, uint16_t index, uint8_t sub, uint32_t v, size_t len)
{
	uint8_t b[4];
	uint32_t ab;

	sys_put_le32(v, b);
	co_node_lock(node);
	ab = co_od_write(co_node_od(node), index, sub, b, len, CO_OD_WRITER_APP);
	co_node_unlock(node);
	return ab == 0U ? 0 : -EIO;
}

static int start_unit(struct unit *u, int ctl, const char *name, uint8_t id, int stack)
{
	char dev_name[16];
	const struct device *can;
	int err;

	(void)snprintf(dev_name, sizeof(dev_name), "can_virtual%d", ctl);
	can = device_get_binding(dev_name);
	if (can == NULL) {
		return -ENODEV;
	}
	err = co_line_init(&u->line, name, can);
	if (err == 0) {
		err = co_node_init(&u->node, name, &u->line, &bridge_test_od_def, &u->ram, id);
	}
	if (err == 0) {
		co_nmt_set_autostart(&u->node, true);
		err = co_line_start(&u->line, stacks[stack], K_THREAD_STACK_SIZEOF(stacks[stack]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	return err;
}

static int start(void)
{
	static const char *const gw_names[LINES] = {"gw0", "gw1"};
	static const char *const dev_names[LINES] = {"dev0", "dev1"};
	struct co_bridge_dds_config cfg = {
		.name = "testnet",
		.domain_id = domain_arg,
		.config_file = BRIDGE_TEST_DIR "/bridge.conf",
		.allow_file = BRIDGE_TEST_DIR "/allow.conf",
	};
	struct co_bridge_dds_node_config ncfg = {.name = "gateway", .sdo_client = 0};
	int err = co_bridge_dds_init(&cfg);

	for (int l = 0; err == 0 && l < LINES; l++) {
		/* Controllers 0, 1: gateways; 2, 3: devices (controller i is on bus i mod 2). */
		err = start_unit(&dev[l], 2 + l, dev_names[l], dev_ids[l], 2 + l);
		if (err == 0) {
			err = start_unit(&gw[l], l, gw_names[l], GW_ID, l);
		}
		if (err == 0) {
			err = co_bridge_dds_add_line(&gw[l].line, (uint8_t)l, gw_names[l]);
		}
		if (err == 0) {
			err = co_bridge_dds_add_node(&gw[l].node, &ncfg);
		}
		if (err == 0) {
			err = co_node_start(&gw[l].node);
		}
		/*
		 * After the start (its reset restores the defaults): the gateway watches its
		 * device's heartbeat (300 ms; the device sends one every 100 ms, 1017h of the
		 * EDS) and consumes its EMCY. Then the device starts.
		 */
		if (err == 0) {
			err = od_put(&gw[l].node, 0x1016, 1, ((uint32_t)dev_ids[l] << 16) | 300U,
				     4);
		}
		if (err == 0) {
			err = od_put(&gw[l].node, 0x1028, 1, 0x80U + dev_ids[l], 4);
		}
		if (err == 0) {
			err = co_node_start(&dev[l].node);
		}
	}
	return err;
}

/* --- Commands ----------------------------------------------------------------------------------
 */

static int cmd_srdo(int line, int srdo, int safe, int reason)
{
	struct co_event ev = {
		.type = CO_EV_SRDO,
		.srdo = {.srdo = (uint8_t)srdo,
			 .safe = safe != 0,
			 .reason = (uint8_t)reason,
			 .time_us = co_line_now()},
	};

	co_node_lock(&gw[line].node);
	(void)co_node_publish(&gw[line].node, &ev, NULL);
	co_node_unlock(&gw[line].node);
	return 0;
}

/* What the redundancy service publishes when it switches (these gateways have one line). */
static int cmd_switch(int line, int to)
{
	struct co_event ev = {
		.type = CO_EV_REDUNDANCY,
		.redundancy = {.what = CO_RDN_EV_SWITCH,
			       .line = (uint8_t)to,
			       .time_us = co_line_now()},
	};

	if (to != CO_LINE_DEFAULT && to != CO_LINE_REDUNDANT) {
		return -EINVAL;
	}
	co_node_lock(&gw[line].node);
	(void)co_node_publish(&gw[line].node, &ev, NULL);
	co_node_unlock(&gw[line].node);
	return 0;
}

static int cmd_burst(int n)
{
	struct co_event ev = {
		.type = CO_EV_EMCY,
		.emcy = {.cob_id = 0x81U, .node_id = GW_ID, .own = true, .code = 0x6200U},
	};

	co_node_lock(&gw[0].node);
	for (int i = 0; i < n; i++) {
		sys_put_le32((uint32_t)i, ev.emcy.msef);
		(void)co_node_publish(&gw[0].node, &ev, NULL);
	}
	co_node_unlock(&gw[0].node);
	return 0;
}

static uint64_t mono_us(void)
{
	struct timespec ts;

	(void)clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000U + (uint64_t)ts.tv_nsec / 1000U;
}

/* Raw EMCY frames of device 7 at @p rate per second, on absolute deadlines. */
static int cmd_bench(int rate, int seconds)
{
	struct can_frame f = {.id = 0x80U + dev_ids[0], .dlc = 8U};
	uint64_t total = (uint64_t)rate * (uint64_t)seconds;
	uint64_t t0 = co_line_now();
	uint32_t refused = 0;
	uint64_t elapsed;

	if (rate <= 0 || seconds <= 0) {
		return -EINVAL;
	}
	for (uint64_t i = 0; i < total; i++) {
		uint64_t at = t0 + i * 1000000U / (uint64_t)rate;

		if (co_line_now() < at) {
			(void)k_sleep(K_TIMEOUT_ABS_US(at));
		}
		sys_put_le16(BENCH_CODE, f.data);
		f.data[2] = 0x01U;
		sys_put_le32((uint32_t)mono_us(), &f.data[3]);
		f.data[7] = (uint8_t)i;
		if (co_line_send(&dev[0].line, &f) != 0) {
			refused++;
		}
	}
	elapsed = co_line_now() - t0;
	printk("bench sent %llu refused %u in %llu us\n", (unsigned long long)(total - refused),
	       refused, (unsigned long long)elapsed);
	return 0;
}

static void print_stats(void)
{
	struct co_bridge_dds_stats st;

	co_bridge_dds_get_stats(&st);
	printk("stats events %u lost %u queue_max %u samples %u requests %u refused %u "
	       "malformed %u\n",
	       st.events, st.events_lost, st.queue_max, st.samples, st.requests, st.refused,
	       st.malformed);
}

static int run(char *line)
{
	char cmd[16];
	long a = 0;
	long b = 0;
	long c = 0;
	long d = 0;
	int n = sscanf(line, "%15s %li %li %li %li", cmd, &a, &b, &c, &d);

	if (n < 1) {
		return -EINVAL;
	}
	if ((a < 0 || a >= LINES) &&
	    (strcmp(cmd, "emcy") == 0 || strcmp(cmd, "clear") == 0 || strcmp(cmd, "srdo") == 0 ||
	     strcmp(cmd, "canstate") == 0 || strcmp(cmd, "count") == 0 || strcmp(cmd, "cut") == 0 ||
	     strcmp(cmd, "restore") == 0 || strcmp(cmd, "switch") == 0)) {
		return -EINVAL;
	}
	if (strcmp(cmd, "emcy") == 0 && n == 3) {
		return co_emcy_raise(&dev[a].node, (uint16_t)b, 0U, NULL);
	}
	if (strcmp(cmd, "clear") == 0 && n == 3) {
		return co_emcy_clear(&dev[a].node, (uint16_t)b);
	}
	if (strcmp(cmd, "srdo") == 0 && n == 5) {
		return cmd_srdo((int)a, (int)b, (int)c, (int)d);
	}
	if (strcmp(cmd, "switch") == 0 && n == 3) {
		return cmd_switch((int)a, (int)b);
	}
	if (strcmp(cmd, "burst") == 0 && n == 2) {
		return cmd_burst((int)a);
	}
	if (strcmp(cmd, "canstate") == 0 && n == 3) {
		return can_virtual_set_state(gw[a].line.dev, (enum can_state)b);
	}
	if (strcmp(cmd, "count") == 0 && n == 3) {
		return od_put(&gw[a].node, 0x2000, 0, (uint32_t)b, 4);
	}
	if (strcmp(cmd, "cut") == 0 && n == 2) {
		return can_virtual_cut(dev[a].line.dev);
	}
	if (strcmp(cmd, "restore") == 0 && n == 2) {
		return can_virtual_restore(dev[a].line.dev);
	}
	if (strcmp(cmd, "bench") == 0 && n == 3) {
		return cmd_bench((int)a, (int)b);
	}
	if (strcmp(cmd, "stats") == 0) {
		print_stats();
		return 0;
	}
	return -EINVAL;
}

int main(void)
{
	char line[128];
	int err = start();

	if (err != 0) {
		LOG_ERR("start failed (%d)", err);
		return 1;
	}
	printk("ready\n");
	while (fgets(line, sizeof(line), stdin) != NULL) {
		line[strcspn(line, "\r\n")] = '\0';
		if (line[0] == '\0') {
			continue;
		}
		err = run(line);
		if (err == 0) {
			printk("ok %s\n", line);
		} else {
			printk("error %s: %d\n", line, err);
		}
	}
	return 0;
}
