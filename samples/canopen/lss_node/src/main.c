/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * lss_node: a device commissioned by an LSS master (CiA 305). It starts without node-ID
 * (FFh), silent but for LSS, unless its LSS medium holds one or --node-id gives one; a master
 * finds it by its LSS address (1018h: vendor 539h, product 105h, revision 10000h, the serial
 * number from --serial), gives it a node-ID and stores it in the medium (--lss-file), after
 * which it boots with it, also after a restart.
 *
 * The line is can_socketcan0 when it has an interface (--can-if=0:vcan0), else can_virtual0.
 */

#include <errno.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/line.h>
#include <canopen/lss.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "cmdline.h"
#include "lss_node_od.h"
#include "posix_native_task.h"
#include "sample_common.h"

LOG_MODULE_REGISTER(lss_node, LOG_LEVEL_INF);

/* The LSS record needs 32 bytes (two copies of 16). */
#define LSS_MEDIUM_SIZE 64U

static struct co_line line;
static struct co_node node;
static struct lss_node_od_ram od_ram;
static struct co_storage_file medium;
static struct co_listener nmt_listener;
static K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

static uint32_t serial_arg = 1U;
static char *lss_file_arg;

static void serial_found(char *argv, int offset)
{
	serial_arg = (uint32_t)cmd_read_uint_option("serial", &argv[offset], 0U, UINT32_MAX);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "serial",
			.name = "u32",
			.type = 'u',
			.call_when_found = serial_found,
			.descript = "serial number, 1018h sub 4 (the last part of the LSS address; "
				    "default 1)",
		},
		{
			.option = "lss-file",
			.name = "path",
			.type = 's',
			.dest = &lss_file_arg,
			.descript =
				"LSS medium: where store configuration keeps the node-ID and bit "
				"timing (created if missing); without it store is answered "
				"'not supported'",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

static void lss_ind(struct co_node *n, enum co_lss_state from, enum co_lss_state to,
		    void *user_data)
{
	printk("lss_node: LSS %s\n",
	       to == CO_LSS_STATE_CONFIGURATION ? "configuration" : "waiting");
}

static int nmt_event(struct co_node *n, const struct co_event *ev, void *user_data)
{
	printk("lss_node: node-ID %u, %s\n", co_node_id(n), co_nmt_state_str(ev->nmt.to));
	return 0;
}

/* Every reset reloads 1018h from the dictionary's defaults: the serial number comes back here. */
static void restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		(void)co_od_set_u32(od, 0x1018, 4, serial_arg, CO_OD_WRITER_STORAGE);
	}
}

/* The LSS medium, attached before the start so a stored node-ID is the first reset's. */
static int attach_medium(void)
{
	struct co_lss_config cfg;
	int err;

	if (lss_file_arg == NULL) {
		return 0;
	}
	err = co_storage_file_open(&medium, lss_file_arg, LSS_MEDIUM_SIZE);
	if (err != 0) {
		LOG_ERR("cannot open %s (%d)", lss_file_arg, err);
		return err;
	}
	err = co_lss_store_attach(&node, &medium.be, &cfg);
	if (err == 0) {
		printk("lss_node: stored node-ID %u loaded from %s\n", cfg.node_id, lss_file_arg);
	} else if (err == -ENOENT) {
		printk("lss_node: nothing stored in %s yet\n", lss_file_arg);
	} else {
		LOG_ERR("LSS medium %s unusable (%d)", lss_file_arg, err);
		return err;
	}
	return 0;
}

int main(void)
{
	const struct device *can = sample_line_device(0);
	int node_id = sample_node_id(CO_NODE_ID_UNCONFIGURED);
	int err;

	if (can == NULL) {
		LOG_ERR("no CAN controller");
		return 1;
	}
	err = co_line_init(&line, "line0", can);
	if (err == 0) {
		err = co_node_init(&node, "lss", &line, &lss_node_od_def, &od_ram,
				   (uint8_t)node_id);
	}
	if (err == 0) {
		err = co_od_set_restore_cb(co_node_od(&node), restore, NULL);
	}
	if (err == 0) {
		co_lss_set_ind(&node, lss_ind, NULL);
		co_listener_init(&nmt_listener, "lss_node", CO_EV_BIT(CO_EV_NMT_STATE), nmt_event,
				 NULL);
		err = co_node_listener_add(&node, &nmt_listener);
	}
	if (err == 0) {
		err = attach_medium();
	}
	if (err == 0) {
		err = co_line_start(&line, line_stack, K_THREAD_STACK_SIZEOF(line_stack),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&node);
	}
	if (err != 0) {
		LOG_ERR("start failed (%d)", err);
		return 1;
	}
	sample_print_stats_on_exit("lss_node", &line);
	co_node_lock(&node);
	node_id = co_node_id(&node);
	co_node_unlock(&node);
	printk("lss_node: serial %08x, node-ID %d%s, up on %s\n", serial_arg, node_id,
	       node_id == CO_NODE_ID_UNCONFIGURED ? " (none: waiting for LSS)" : "", can->name);
	for (;;) {
		k_sleep(K_SECONDS(1));
	}
	return 0;
}
