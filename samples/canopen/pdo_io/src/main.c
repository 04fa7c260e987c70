/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * pdo_io: a small CiA 401-style I/O device. Its process data travel in PDOs; the application
 * only reads and writes the dictionary and the stack does the rest:
 *
 * - 6000h sub 1 counts up every 250 ms: TPDO1 (event-driven, 10 ms inhibit, 1 s event timer)
 *   carries each change. 6000h sub 2 echoes output 6200h sub 1 (written by RPDO1).
 * - 6401h analogue inputs (a ramp, the echo of 6411h sub 1, uptime in seconds, -1234) go out
 *   in TPDO2 after every SYNC; 6411h analogue outputs come in RPDO2, applied at the SYNC.
 * - 2011h counts SYNCs, 2010h records the last TIME received. With 1012h bit 30 set the device
 *   sends TIME once a second from its clock (the last TIME received plus the time since).
 * - Simulated fault: while 6411h sub 1 is above the limit in 2012h the device reports EMCY
 *   2310h (continuous over-current); the error clears when the output comes back.
 */

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/emcy.h>
#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/sync.h>
#include <canopen/time.h>

#include "pdo_io_od.h"
#include "sample_common.h"

LOG_MODULE_REGISTER(pdo_io, LOG_LEVEL_INF);

#define DEFAULT_NODE_ID 0x20U

#define LOOP_MS        50
#define COUNT_EVERY    5  /* loops: 250 ms */
#define TIME_EVERY     20 /* loops: 1 s */
#define OVER_CURRENT   0x2310U
#define TIME_COB_PROD  BIT(30)
#define ANALOGUE_CONST (-1234)

static struct co_line line;
static struct co_node node;
static struct pdo_io_od_ram od_ram;
static K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* The device clock: a TIME_OF_DAY at a line time, counted on from there. */
static struct {
	int64_t base_unix_us;
	uint64_t base_line_us;
} clock;

static void on_sync(struct co_node *n, uint8_t counter, void *user_data)
{
	struct co_od *od = co_node_od(n);
	uint32_t count = 0;

	(void)co_od_get_u32(od, 0x2011, 0, &count);
	(void)co_od_set_u32(od, 0x2011, 0, count + 1U, CO_OD_WRITER_APP);
}

static void on_time(struct co_node *n, const struct co_time *t, uint64_t rx_us, void *user_data)
{
	struct co_od *od = co_node_od(n);
	uint32_t count = 0;
	int64_t unix_us;

	(void)co_od_set_u32(od, 0x2010, 1, t->ms & CO_TIME_MS_MASK, CO_OD_WRITER_APP);
	(void)co_od_set_u16(od, 0x2010, 2, t->days, CO_OD_WRITER_APP);
	(void)co_od_get_u32(od, 0x2010, 3, &count);
	(void)co_od_set_u32(od, 0x2010, 3, count + 1U, CO_OD_WRITER_APP);
	if (co_time_to_unix_us(t, &unix_us) == 0) {
		clock.base_unix_us = unix_us;
		clock.base_line_us = rx_us;
	}
}

static int read_clock(struct co_node *n, struct co_time *now, void *user_data)
{
	uint64_t since = co_line_time(co_node_line(n)) - clock.base_line_us;

	return co_time_from_unix_us(clock.base_unix_us + (int64_t)since, now);
}

/* One pass of the I/O "hardware"; called with the node locked. */
static void io_step(unsigned int loop)
{
	struct co_od *od = co_node_od(&node);
	uint8_t in = 0, out = 0, echo = 0;
	int16_t ramp = 0, aout = 0, limit = 0;
	uint32_t time_cob = 0;

	if (loop % COUNT_EVERY == 0U) {
		(void)co_od_get_u8(od, 0x6000, 1, &in);
		(void)co_od_set_u8(od, 0x6000, 1, (uint8_t)(in + 1U), CO_OD_WRITER_APP);
	}
	/* Write inputs only when they change: a write is an event for event-driven TPDOs. */
	(void)co_od_get_u8(od, 0x6200, 1, &out);
	(void)co_od_get_u8(od, 0x6000, 2, &echo);
	if (out != echo) {
		(void)co_od_set_u8(od, 0x6000, 2, out, CO_OD_WRITER_APP);
		printk("pdo_io: output 1 = 0x%02x\n", out);
	}

	(void)co_od_get_i16(od, 0x6401, 1, &ramp);
	(void)co_od_set_i16(od, 0x6401, 1, (int16_t)(ramp + 100), CO_OD_WRITER_APP);
	(void)co_od_get_i16(od, 0x6411, 1, &aout);
	(void)co_od_set_i16(od, 0x6401, 2, aout, CO_OD_WRITER_APP);
	(void)co_od_set_i16(od, 0x6401, 3, (int16_t)(k_uptime_get() / 1000), CO_OD_WRITER_APP);
	/* Written every pass: a reset application brings back the dictionary's defaults. */
	(void)co_od_set_i16(od, 0x6401, 4, ANALOGUE_CONST, CO_OD_WRITER_APP);

	(void)co_od_get_i16(od, 0x2012, 0, &limit);
	if (aout > limit && !co_emcy_is_active(&node, OVER_CURRENT)) {
		printk("pdo_io: analogue output %d above %d: over-current\n", aout, limit);
		(void)co_emcy_raise(&node, OVER_CURRENT, CO_EMCY_REG_CURRENT, NULL);
	} else if (aout <= limit && co_emcy_is_active(&node, OVER_CURRENT)) {
		printk("pdo_io: analogue output back to %d\n", aout);
		(void)co_emcy_clear(&node, OVER_CURRENT);
	}

	(void)co_od_get_u32(od, 0x1012, 0, &time_cob);
	if ((time_cob & TIME_COB_PROD) != 0U && loop % TIME_EVERY == 0U) {
		(void)co_time_req(&node, NULL);
	}
}

int main(void)
{
	const struct device *can = sample_line_device(0);
	int node_id = sample_node_id(DEFAULT_NODE_ID);
	/* Until a TIME arrives the clock starts at 2026-01-01 00:00 UTC. */
	const struct co_time_date start = {.year = 2026, .month = 1, .day = 1};
	struct co_time t0;
	int err;

	if (node_id < 0) {
		return 1;
	}
	if (can == NULL) {
		LOG_ERR("no CAN controller");
		return 1;
	}
	if (co_time_from_date(&start, &t0) != 0 ||
	    co_time_to_unix_us(&t0, &clock.base_unix_us) != 0) {
		return 1;
	}
	err = co_line_init(&line, "line0", can);
	if (err == 0) {
		err = co_node_init(&node, "pdo_io", &line, &pdo_io_od_def, &od_ram,
				   (uint8_t)node_id);
	}
	if (err == 0) {
		co_sync_set_ind(&node, on_sync, NULL);
		co_time_set_ind(&node, on_time, NULL);
		co_time_set_clock(&node, read_clock, NULL);
		err = co_line_start(&line, line_stack, K_THREAD_STACK_SIZEOF(line_stack),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		clock.base_line_us = co_line_time(&line);
		err = co_node_start(&node);
	}
	if (err != 0) {
		LOG_ERR("start failed (%d)", err);
		return 1;
	}
	sample_print_stats_on_exit("pdo_io", &line);
	printk("pdo_io: node %d up on %s\n", node_id, can->name);

	for (unsigned int loop = 1;; loop++) {
		k_sleep(K_MSEC(LOOP_MS));
		co_node_lock(&node);
		io_step(loop);
		co_node_unlock(&node);
	}
	return 0;
}
