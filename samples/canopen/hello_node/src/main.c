/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * hello_node: one CANopen device on one line. Heartbeat producer, node guarding, SDO server,
 * an uptime counter (2000h) that the application updates every second, a setpoint (2001h)
 * and a 128 KiB data buffer (2100h, DOMAIN) served by an object provider.
 *
 * Parameters are stored (1010h "save", 1011h "load") in the file --storage=FILE names; without
 * it the node has no medium and says so: 1010h/1011h read 0 and requests are refused with
 * 08000020h.
 *
 * The line is can_socketcan0 when it has an interface (--can-if=0:vcan0), else can_virtual0.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "cmdline.h"
#include "hello_node_od.h"
#include "posix_native_task.h"
#include "sample_common.h"

LOG_MODULE_REGISTER(hello_node, LOG_LEVEL_INF);

#define DATA_INDEX    0x2100U
#define DATA_CAPACITY (128U * 1024U)

#define DEFAULT_NODE_ID 0x10U
/* Two image slots of the storage module, each holding every stored value of the dictionary. */
#define STORAGE_SIZE    8192U

static struct co_line line;
static struct co_node node;
static struct hello_node_od_ram od_ram;
static K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static struct co_storage storage;
static struct co_storage_file medium;
static char *storage_arg;

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "storage",
			.name = "path",
			.type = 's',
			.dest = &storage_arg,
			.descript = "parameter storage medium (1010h/1011h), created if missing; "
				    "without it the node does not store parameters",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

/* Before the start, so that the first reset restores what is stored. */
static int attach_storage(void)
{
	int err;

	if (storage_arg == NULL) {
		printk("hello_node: no storage medium (--storage=FILE): 1010h/1011h read 0\n");
		co_node_lock(&node);
		err = co_storage_init_absent(&storage, co_node_od(&node));
		co_node_unlock(&node);
		return err;
	}
	err = co_storage_file_open(&medium, storage_arg, STORAGE_SIZE);
	if (err == 0) {
		co_node_lock(&node);
		err = co_storage_init(&storage, co_node_od(&node), &medium.be);
		co_node_unlock(&node);
	}
	if (err != 0) {
		LOG_ERR("storage medium %s unusable (%d)", storage_arg, err);
		return err;
	}
	printk("hello_node: parameters stored in %s\n", storage_arg);
	return 0;
}

/*
 * 2100h: a DOMAIN larger than any staging buffer. Chunks stream into a shadow buffer that
 * becomes the value only when the last chunk arrived, so an aborted download leaves the old
 * value intact.
 */
static struct {
	uint8_t value[DATA_CAPACITY];
	uint8_t shadow[DATA_CAPACITY];
	uint32_t len;
	uint32_t shadow_len;
} data_buf;

static uint32_t data_info(const struct co_od_provider *p, struct co_od_info *info)
{
	if (info->sub != 0U) {
		return CO_SDO_AB_NO_SUB;
	}
	info->dtype = CO_DTYPE_DOMAIN;
	info->access = CO_OD_ACCESS_RW;
	info->flags = CO_OD_F_STREAM;
	info->objcode = CO_OD_OBJ_VAR;
	info->size = DATA_CAPACITY;
	return 0;
}

static uint32_t data_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	return data_buf.len;
}

static uint32_t data_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	size_t n = 0;

	if (offset < data_buf.len) {
		n = MIN(cap, (size_t)(data_buf.len - offset));
		memcpy(buf, &data_buf.value[offset], n);
	}
	*len = n;
	return 0;
}

static uint32_t data_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	if (data == NULL) {
		/* The transfer was aborted: forget the shadow, keep the value. */
		data_buf.shadow_len = 0U;
		return 0;
	}
	if (offset == 0U) {
		data_buf.shadow_len = 0U;
	}
	if (offset != data_buf.shadow_len || len > DATA_CAPACITY - offset) {
		return CO_SDO_AB_DATA_LONG;
	}
	memcpy(&data_buf.shadow[offset], data, len);
	data_buf.shadow_len = offset + (uint32_t)len;
	if (last) {
		memcpy(data_buf.value, data_buf.shadow, data_buf.shadow_len);
		data_buf.len = data_buf.shadow_len;
	}
	return 0;
}

static const struct co_od_provider_api data_api = {
	.info = data_info,
	.length = data_length,
	.read = data_read,
	.write = data_write,
};

static const struct co_od_provider data_provider = {
	.api = &data_api,
	.index_first = DATA_INDEX,
	.index_last = DATA_INDEX,
};

int main(void)
{
	const struct device *can = sample_line_device(0);
	int node_id = sample_node_id(DEFAULT_NODE_ID);
	uint32_t seconds = 0;
	int err;

	if (node_id < 0) {
		return 1;
	}
	if (can == NULL) {
		LOG_ERR("no CAN controller");
		return 1;
	}
	err = co_line_init(&line, "line0", can);
	if (err == 0) {
		err = co_node_init(&node, "hello", &line, &hello_node_od_def, &od_ram,
				   (uint8_t)node_id);
	}
	if (err == 0) {
		err = co_od_provider_register(co_node_od(&node), &data_provider);
	}
	if (err == 0) {
		err = attach_storage();
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
	sample_print_stats_on_exit("hello_node", &line);
	printk("hello_node: node %d up on %s\n", node_id, can->name);

	for (;;) {
		k_sleep(K_SECONDS(1));
		seconds++;
		co_node_lock(&node);
		(void)co_od_set_u32(co_node_od(&node), 0x2000, 0, seconds, CO_OD_WRITER_APP);
		co_node_unlock(&node);
	}
	return 0;
}
