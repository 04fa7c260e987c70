/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The application scripts/footprint links the stack with: one node on one line (two lines
 * with redundancy), its dictionary, and the calls an application of the configuration makes
 * (so that --gc-sections keeps what such an application needs and no more). Counted apart
 * from the stack.
 */

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/services.h>
#if defined(CONFIG_CANOPEN_STORAGE)
#include <canopen/storage.h>
#endif

#include "fp_od.h"

static struct co_line line;
static struct co_node node;
static struct fp_od_ram od_ram;
K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
#if defined(CONFIG_CANOPEN_REDUNDANCY)
static struct co_line line2;
K_THREAD_STACK_DEFINE(line2_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
#endif
#if defined(CONFIG_CANOPEN_STORAGE)
static uint8_t store_mem[512];
static struct co_storage_ram store_ram;
static struct co_storage store;
#endif

static void on_pdo(struct co_node *n, uint16_t num, void *user_data)
{
}

static int on_state(struct co_node *n, enum co_nmt_state from, enum co_nmt_state to,
		    void *user_data)
{
	return 0;
}

int main(void)
{
	const struct device *can = device_get_binding("can0");
	int err;

	err = co_line_init(&line, "line0", can);
	err = err ?: co_node_init(&node, "node", &line, &fp_od_def, &od_ram, 5);
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	err = err ?: co_line_init(&line2, "line1", device_get_binding("can1"));
	err = err ?: co_node_attach_line(&node, CO_LINE_REDUNDANT, &line2);
	err = err
		      ?: co_line_start(&line2, line2_stack, K_THREAD_STACK_SIZEOF(line2_stack),
				       CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
#endif
	co_nmt_set_state_ind(&node, on_state, NULL);
#if defined(CONFIG_CANOPEN_STORAGE)
	err = err ?: co_storage_ram_init(&store_ram, store_mem, sizeof(store_mem));
	co_node_lock(&node);
	err = err ?: co_storage_init(&store, co_node_od(&node), &store_ram.be);
	co_node_unlock(&node);
#endif
#if defined(CONFIG_CANOPEN_PDO)
	co_rpdo_set_ind(&node, on_pdo, NULL);
	co_tpdo_set_ind(&node, on_pdo, NULL);
#endif
#if defined(CONFIG_CANOPEN_LEDS)
	static const struct co_leds_cfg leds = {.green = 0, .red = 1};

	err = err ?: co_leds_attach(&node, &leds);
#endif
	err = err
		      ?: co_line_start(&line, line_stack, K_THREAD_STACK_SIZEOF(line_stack),
				       CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	err = err ?: co_node_start(&node);

	for (uint32_t n = 0; err == 0; n++) {
		k_sleep(K_MSEC(10));
		co_node_lock(&node);
		(void)co_od_set_u32(co_node_od(&node), 0x2000, 0, n, CO_OD_WRITER_APP);
		co_node_unlock(&node);
#if defined(CONFIG_CANOPEN_PDO)
		(void)co_tpdo_send_req(&node, 0);
#endif
#if defined(CONFIG_CANOPEN_EMCY)
		if ((n & 0xffU) == 0U) {
			(void)co_emcy_raise(&node, 0x5000, 0x80, NULL);
		} else {
			(void)co_emcy_clear(&node, 0x5000);
		}
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
		static uint32_t value;

		(void)co_sdo_cli_upload_req(co_sdo_cli_get(&node, 0), 0x1017, 0, &value,
					    sizeof(value), CO_SDO_CLI_AUTO, 500, NULL, NULL);
#endif
#if defined(CONFIG_CANOPEN_MPDO)
		(void)co_mpdo_dam_req(&node, 1, 0, 0x6200, 1, &n, 1);
#endif
#if defined(CONFIG_CANOPEN_SRDO)
		if (!co_srdo_may_leave_safe_state(&node)) {
			continue;
		}
		(void)co_srdo_send_req(&node, 1);
#endif
#if defined(CONFIG_CANOPEN_TIME)
		struct co_time t = {.ms = n, .days = 1};

		(void)co_time_req(&node, &t);
#endif
	}
	return err;
}
