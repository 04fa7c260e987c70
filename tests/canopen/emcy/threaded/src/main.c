/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A node on a real line thread over the virtual bus. The test puts the node's controller into
 * error passive, bus-off and back with can_virtual_set_state(); a second controller on the
 * same bus receives the EMCY frames the node sends (8120h, 8140h, error resets).
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>

#include <canopen/emcy.h>
#include <canopen/line.h>
#include <canopen/node.h>

#include "emcy_test_od.h"

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define WAIT_MS 2000

static struct co_line line;
static struct co_node node;
static struct emcy_test_od_ram ram;
static const struct device *dut;
static const struct device *obs;
static K_THREAD_STACK_DEFINE(stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
CAN_MSGQ_DEFINE(obs_q, 32);
static atomic_t app_events;

static void app_event_cb(struct co_line *l, enum co_line_event event, int arg, void *user_data)
{
	if (event == CO_LINE_EV_CAN_STATE) {
		atomic_inc(&app_events);
	}
}

/* Next EMCY frame seen on the bus, or fail. */
static void expect_emcy(uint16_t code, uint8_t reg)
{
	struct can_frame f;

	zassert_ok(k_msgq_get(&obs_q, &f, K_MSEC(WAIT_MS)), "no EMCY %04x on the bus", code);
	zassert_equal(f.id, EMCY_ID);
	zassert_equal(f.dlc, 8);
	zassert_equal(f.data[0] | (f.data[1] << 8), code, "got %02x%02x, want %04x", f.data[1],
		      f.data[0], code);
	zassert_equal(f.data[2], reg, "register %02x", f.data[2]);
}

static enum co_nmt_state nmt_state(void)
{
	enum co_nmt_state s;

	co_node_lock(&node);
	s = co_nmt_get_state(&node);
	co_node_unlock(&node);
	return s;
}

static bool wait_state(enum co_nmt_state want)
{
	for (int i = 0; i < WAIT_MS; i++) {
		if (nmt_state() == want) {
			return true;
		}
		k_msleep(1);
	}
	return false;
}

static void *setup(void)
{
	const struct can_filter f = {.id = EMCY_ID, .mask = CAN_STD_ID_MASK};

	dut = device_get_binding("can_virtual0");
	obs = device_get_binding("can_virtual1");
	zassert_not_null(dut);
	zassert_not_null(obs);
	zassert_true(can_add_rx_filter_msgq(obs, &obs_q, &f) >= 0);
	zassert_ok(can_start(obs));

	zassert_ok(co_line_init(&line, "line", dut));
	co_line_set_event_cb(&line, app_event_cb, NULL);
	zassert_ok(co_node_init(&node, "dut", &line, &emcy_test_od_def, &ram, NODE_ID));
	zassert_ok(co_node_start(&node));
	zassert_ok(co_line_start(&line, stack, K_THREAD_STACK_SIZEOF(stack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	return NULL;
}

static void teardown(void *f)
{
	co_line_stop(&line);
}

ZTEST_SUITE(co_emcy_threaded, NULL, setup, NULL, NULL, teardown);

ZTEST(co_emcy_threaded, test_passive_bus_off_recovery_emcy_on_the_bus)
{
	zassert_ok(co_nmt_req(&node, CO_NMT_CS_START));
	zassert_true(wait_state(CO_NMT_OPERATIONAL));
	k_msgq_purge(&obs_q);

	zassert_ok(can_virtual_set_state(dut, CAN_STATE_ERROR_PASSIVE));
	expect_emcy(0x8120, 0x11);

	zassert_ok(can_virtual_set_state(dut, CAN_STATE_BUS_OFF));
	zassert_true(wait_state(CO_NMT_PRE_OPERATIONAL), "1029h sub1 = 0 on bus-off");

	zassert_ok(can_virtual_set_state(dut, CAN_STATE_ERROR_ACTIVE));
	expect_emcy(0x8140, 0x11);
	expect_emcy(0x0000, 0x11); /* 8120h cleared; 8140h held */
	zassert_true(co_emcy_is_active(&node, CO_EMCY_BUS_OFF_RECOV));
	zassert_false(co_emcy_is_active(&node, CO_EMCY_CAN_PASSIVE));
	zassert_true(atomic_get(&app_events) >= 3, "the application's callback still runs");

	/* 8140h ends after the hold time without another bus-off. */
	expect_emcy(0x0000, 0x00);
	zassert_equal(co_emcy_get_reg(&node), 0x00);
}
