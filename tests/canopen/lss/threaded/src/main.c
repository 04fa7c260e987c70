/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The LSS bit rate switch without any handler: the slave uses the line's CAN device through
 * Zephyr's CAN API. The node runs on a real line thread over the virtual bus (controller 0);
 * controller 1 plays the master and listens. The virtual bus delivers a frame only to
 * controllers at the sender's bit rate, so the switch is seen on the bus itself.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>
#include <canopen/lss.h>
#include <canopen/node.h>

#include "lss_test_od.h"

#define NODE_ID 0x05
#define HB_ID   (0x700 + NODE_ID)
#define WAIT_MS 1000

static struct co_line line;
static struct co_node node;
static struct lss_test_od_ram ram;
static const struct device *dut;
static const struct device *master;
static K_THREAD_STACK_DEFINE(stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
CAN_MSGQ_DEFINE(master_q, 64);

static void send(uint8_t cs, uint8_t b1, uint8_t b2)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, cs);
	f.data[1] = b1;
	f.data[2] = b2;
	zassert_ok(can_send(master, &f, K_MSEC(WAIT_MS), NULL, NULL));
}

/* The next frame with @p id the master hears within @p ms, skipping others. */
static bool next_frame(uint32_t id, int ms, struct can_frame *f)
{
	int64_t end = k_uptime_get() + ms;

	while (k_uptime_get() < end) {
		if (k_msgq_get(&master_q, f, K_MSEC(end - k_uptime_get())) != 0) {
			return false;
		}
		if (f->id == id) {
			return true;
		}
	}
	return false;
}

static void master_bitrate(uint32_t bitrate)
{
	zassert_ok(can_stop(master));
	zassert_ok(can_set_bitrate(master, bitrate));
	zassert_ok(can_start(master));
}

static void *setup(void)
{
	const struct can_filter all = {.id = 0, .mask = 0};

	dut = device_get_binding("can_virtual0");
	master = device_get_binding("can_virtual1");
	zassert_not_null(dut);
	zassert_not_null(master);
	zassert_true(can_add_rx_filter_msgq(master, &master_q, &all) >= 0);
	zassert_ok(can_start(master));

	zassert_ok(co_line_init(&line, "line", dut));
	zassert_ok(co_node_init(&node, "dut", &line, &lss_test_od_def, &ram, NODE_ID));
	zassert_ok(co_node_start(&node));
	zassert_ok(co_line_start(&line, stack, K_THREAD_STACK_SIZEOF(stack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	return NULL;
}

static void teardown(void *f)
{
	co_line_stop(&line);
}

ZTEST_SUITE(co_lss_threaded, NULL, setup, NULL, NULL, teardown);

ZTEST(co_lss_threaded, test_38_activate_bit_timing_switches_the_virtual_controller)
{
	struct can_frame f;
	int64_t t0;

	zassert_true(next_frame(HB_ID, WAIT_MS, &f), "heartbeat at 500 kbit/s");

	send(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	send(CO_LSS_CS_CONFIG_BIT_TIMING, CO_LSS_BIT_TIMING_TABLE_CIA, 9);
	zassert_true(next_frame(CO_LSS_SLAVE_COB_ID, WAIT_MS, &f));
	zassert_equal(f.data[1], CO_LSS_ERR_BIT_TIMING, "automatic detection: not supported");
	send(CO_LSS_CS_CONFIG_BIT_TIMING, CO_LSS_BIT_TIMING_TABLE_CIA, 3);
	zassert_true(next_frame(CO_LSS_SLAVE_COB_ID, WAIT_MS, &f));
	zassert_equal(f.data[0], CO_LSS_CS_CONFIG_BIT_TIMING);
	zassert_equal(f.data[1], CO_LSS_ERR_OK, "the virtual controller can run at 250 kbit/s");

	/* Activate with 100 ms: silent at the old rate, switch, silent at the new one. */
	send(CO_LSS_CS_ACTIVATE_BIT_TIMING, 100, 0);
	t0 = k_uptime_get();
	/* A heartbeat sent before the node took the request may still be on its way. */
	k_msleep(10);
	k_msgq_purge(&master_q);
	k_msleep(80);
	zassert_equal(k_msgq_num_used_get(&master_q), 0,
		      "silent during the first delay (heartbeats every 50 ms otherwise)");

	/* The master follows to 250 kbit/s; the node's first frame comes after both delays. */
	master_bitrate(250000U);
	zassert_true(next_frame(HB_ID, WAIT_MS, &f), "heartbeat at 250 kbit/s");
	zassert_true(k_uptime_get() - t0 >= 195, "silent during the second delay (%lld ms)",
		     (long long)(k_uptime_get() - t0));

	send(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	zassert_true(next_frame(CO_LSS_SLAVE_COB_ID, WAIT_MS, &f));
	zassert_equal(f.data[0], CO_LSS_CS_INQUIRE_NODE_ID);
	zassert_equal(f.data[1], NODE_ID);

	/* A controller left at 500 kbit/s hears nothing of the node any more. */
	master_bitrate(500000U);
	k_msgq_purge(&master_q);
	k_msleep(200);
	zassert_equal(k_msgq_num_used_get(&master_q), 0, "no frame at the old rate");
}
