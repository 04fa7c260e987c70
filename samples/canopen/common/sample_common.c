/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <stdio.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include "cmdline.h"
#include "posix_native_task.h"
#include "sample_common.h"

LOG_MODULE_REGISTER(sample, LOG_LEVEL_INF);

/* 0: --node-id not given. Checked while the command line is parsed, before the boot. */
static uint8_t node_id_arg;

static void node_id_found(char *argv, int offset)
{
	node_id_arg = (uint8_t)cmd_read_uint_option("node-id", &argv[offset], 1U, 127U);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "node-id",
			.name = "1..127",
			.type = 'u',
			.call_when_found = node_id_found,
			.descript = "CANopen node-ID of this device",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 20);

int sample_node_id(uint8_t dflt)
{
	return (node_id_arg == 0U) ? dflt : node_id_arg;
}

const struct device *sample_line_device(unsigned int n)
{
	char name[24];
	const struct device *dev;

	snprintf(name, sizeof(name), "can_socketcan%u", n);
	dev = device_get_binding(name);
	if (dev != NULL && device_is_ready(dev)) {
		return dev;
	}
	snprintf(name, sizeof(name), "can_virtual%u", n);
	return device_get_binding(name);
}

static const char *stats_prefix;
/* Read by the exit task in whatever thread ends the process: published atomically, after the
 * prefix.
 */
static atomic_ptr_t stats_line;

void sample_print_stats_on_exit(const char *prefix, struct co_line *line)
{
	stats_prefix = prefix;
	(void)atomic_ptr_set(&stats_line, line);
}

static void print_line_stats(void)
{
	struct co_line *line = atomic_ptr_get(&stats_line);
	struct co_line_stats st;

	if (line == NULL) {
		return;
	}
	co_line_get_stats(line, &st);
	printk("%s: line0 rx %u tx %u queued %u queue_max %u dropped %u errors %u overruns %u\n",
	       stats_prefix, st.rx_frames, st.tx_frames, st.tx_queued, st.tx_queue_max,
	       st.tx_dropped, st.tx_errors, st.rx_overruns);
}
NATIVE_TASK(print_line_stats, ON_EXIT, 10);
