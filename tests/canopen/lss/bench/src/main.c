/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS fastscan benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * The LSS master (node 1, alone on controller 0) finds 8 devices without node-ID (random
 * serial numbers, two devices per controller 1..4) one by one: fastscan, configure node-ID,
 * switch global to waiting. Real line threads on the virtual bus with bit timing at 1 Mbit/s,
 * so every frame holds the bus for its real length (stuff bits included).
 *
 * Per device: the time of the fastscan (request to confirmation) and the frames it put on
 * the bus (the master's requests and every device's answers, merged frames not merged: each
 * device sends its own). The protocol's minimum is what the algorithm must send for one
 * device: 1 + 4 x 33 requests and the answers of the selected device alone (the probe, each
 * 0 bit, the four verifies), each at its length in bits at 1 us per bit. No step timeout can
 * be that short: each step waits its whole timeout because any number of devices may answer,
 * so the time is about 133 x the step timeout; "ratio_to_min" says how far that is above the
 * bus.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/lss.h>
#include <canopen/lss_master.h>
#include <canopen/node.h>

#include "lss_test_od.h"

#define N_DEVICES 8
#define N_LINES   5

static struct co_line lines[N_LINES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static struct co_node master;
static struct lss_test_od_ram mram;
static struct co_node devs[N_DEVICES];
static struct lss_test_od_ram dram[N_DEVICES];

static void set_serial(struct co_node *node, uint32_t serial)
{
	uint8_t buf[4];

	sys_put_le32(serial, buf);
	co_node_lock(node);
	(void)co_od_write(co_node_od(node), 0x1018, 4, buf, 4, CO_OD_WRITER_APP);
	co_node_unlock(node);
}

static uint32_t frame_bits(uint8_t cs, uint32_t id_number, uint8_t bit, uint8_t sub, uint8_t next,
			   uint32_t cob)
{
	struct can_frame f;

	co_lss_frame_init(&f, cob, cs);
	co_lss_frame_set_u32(&f, id_number);
	f.data[5] = bit;
	f.data[6] = sub;
	f.data[7] = next;
	return can_virtual_frame_bits(&f);
}

/*
 * The bits the algorithm must put on the bus for one device of address @p a: every request
 * as the master sends it, and the selected device's answers.
 */
static uint64_t min_bits(const struct co_lss_address *a, uint8_t known_mask, uint32_t *frames)
{
	uint32_t answer = frame_bits(CO_LSS_CS_IDENT_SLAVE, 0, 0, 0, 0, CO_LSS_SLAVE_COB_ID);
	uint64_t bits = frame_bits(CO_LSS_CS_FASTSCAN, 0, CO_LSS_FASTSCAN_CONFIRM, 0, 0,
				   CO_LSS_MASTER_COB_ID) +
			answer;

	*frames = 2U;
	for (uint8_t sub = 0; sub < 4U; sub++) {
		uint32_t id = (known_mask & BIT(sub)) != 0U ? a->part[sub] : 0U;

		/* A known part is only verified. */
		for (int bit = 31; (known_mask & BIT(sub)) == 0U && bit >= 0; bit--) {
			bits += frame_bits(CO_LSS_CS_FASTSCAN, id, (uint8_t)bit, sub, sub,
					   CO_LSS_MASTER_COB_ID);
			(*frames)++;
			if ((a->part[sub] & BIT(bit)) != 0U) {
				id |= BIT(bit);
			} else {
				bits += answer;
				(*frames)++;
			}
		}
		bits += frame_bits(CO_LSS_CS_FASTSCAN, id, 0, sub, sub == 3U ? 0U : sub + 1U,
				   CO_LSS_MASTER_COB_ID) +
			answer;
		*frames += 2U;
	}
	return bits;
}

static int setup(void)
{
	for (int l = 0; l < N_LINES; l++) {
		char name[16];

		snprintf(name, sizeof(name), "can_virtual%d", l);
		if (co_line_init(&lines[l], l == 0 ? "master" : "devices",
				 device_get_binding(name)) != 0) {
			return -1;
		}
	}
	if (co_node_init(&master, "master", &lines[0], &lss_test_od_def, &mram, 1) != 0 ||
	    co_node_start(&master) != 0) {
		return -1;
	}
	for (int i = 0; i < N_DEVICES; i++) {
		if (co_node_init(&devs[i], "dev", &lines[1 + i / 2], &lss_test_od_def, &dram[i],
				 CO_NODE_ID_UNCONFIGURED) != 0 ||
		    co_node_start(&devs[i]) != 0) {
			return -1;
		}
	}
	for (int l = 0; l < N_LINES; l++) {
		if (co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
				  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0) {
			return -1;
		}
	}
	return 0;
}

static K_SEM_DEFINE(done_sem, 0, 1);
static int done_err;
static struct co_lss_master_result done_res;

static void done(struct co_node *node, int err, const struct co_lss_master_result *res,
		 void *user_data)
{
	done_err = err;
	done_res = *res;
	k_sem_give(&done_sem);
}

/* Give every device a new random serial number and no node-ID; reset them. */
static void reset_devices(void)
{
	for (int i = 0; i < N_DEVICES; i++) {
		co_node_lock(&devs[i]);
		(void)co_node_set_pending_id(&devs[i], CO_NODE_ID_UNCONFIGURED);
		(void)co_nmt_req(&devs[i], CO_NMT_CS_RESET_NODE);
		co_node_unlock(&devs[i]);
		set_serial(&devs[i], ((uint32_t)rand() << 16) ^ (uint32_t)rand());
	}
	k_msleep(50);
}

static void run(const char *name, uint32_t step_ms, uint8_t known_mask)
{
	const struct co_lss_address known = {.part = {0x12345678U, 0x42U, 0, 0}};
	double sum_ms = 0, sum_min_ms = 0, max_ms = 0;
	uint32_t frames = 0, min_frames = 0, restarts = 0, found = 0;

	reset_devices();
	for (int n = 0; n < N_DEVICES; n++) {
		struct co_lss_master_result res;
		struct co_lss_master_stats before, after;
		uint32_t mf;
		int64_t t0;
		int err;

		co_lss_master_get_stats(&master, &before);
		t0 = k_uptime_ticks();
		/* The step timeout of this run: the _req form, then wait for its confirmation. */
		err = co_lss_master_fastscan_req(&master, &known, known_mask, step_ms, done, NULL);
		if (err == 0) {
			(void)k_sem_take(&done_sem, K_FOREVER);
			err = done_err;
			res = done_res;
		}
		double ms =
			(double)k_ticks_to_us_floor64((uint64_t)(k_uptime_ticks() - t0)) / 1000.0;

		co_lss_master_get_stats(&master, &after);
		if (err != 0) {
			printf("lss_bench: %s: fastscan %d failed (%d)\n", name, n, err);
			break;
		}
		found++;
		sum_ms += ms;
		max_ms = ms > max_ms ? ms : max_ms;
		frames += res.frames + (after.answers - before.answers);
		restarts += res.restarts;
		sum_min_ms += (double)min_bits(&res.address, known_mask, &mf) / 1000.0;
		min_frames += mf;
		(void)co_lss_master_config_node_id(&master, (uint8_t)(0x10 + n), K_SECONDS(1),
						   NULL);
		(void)co_lss_master_switch_global(&master, CO_LSS_MODE_WAITING);
	}
	printf("BENCH {\"name\": \"%s\", \"devices\": %u, \"step_timeout_ms\": %u, "
	       "\"ms_per_device\": %.1f, \"max_ms\": %.1f, \"frames_per_device\": %.1f, "
	       "\"min_frames_per_device\": %.1f, \"min_ms_per_device\": %.2f, "
	       "\"ratio_to_min\": %.1f, \"restarts\": %u}\n",
	       name, found, step_ms, found ? sum_ms / found : 0.0, max_ms,
	       found ? (double)frames / found : 0.0, found ? (double)min_frames / found : 0.0,
	       found ? sum_min_ms / found : 0.0, sum_min_ms > 0 ? sum_ms / sum_min_ms : 0.0,
	       restarts);
}

int main(void)
{
	srand(0x1551);
	if (setup() != 0) {
		printf("lss_bench: setup failed\n");
		return 1;
	}
	k_msleep(100);
	run("lss.fastscan_8_devices", CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_TIMEOUT, 0);
	run("lss.fastscan_8_devices_step_10ms", 10, 0);
	run("lss.fastscan_8_devices_vendor_product_known",
	    CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_TIMEOUT, BIT(0) | BIT(1));
	printf("lss_bench: done\n");
	return 0;
}
