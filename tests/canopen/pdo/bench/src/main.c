/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * cost     On a simulation line (no threads, no driver): the time to receive one RPDO
 *          (line dispatch + unpack + dictionary write + a notify hook) and to serve one SYNC
 *          that triggers three synchronous TPDOs (pack + send to the line's sink).
 *          scripts/bench runs this part again under callgrind, collecting only inside
 *          bench_rpdo_loop() and bench_sync_loop(), for instructions per operation.
 * latency  With real threads on the virtual bus: a raw controller sends SYNC, the device's
 *          line thread answers with a synchronous TPDO, the raw controller's receive callback
 *          takes the arrival time. p50/p99/max of SYNC sent -> TPDO received.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them into a file.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/node.h>

#include "cmdline.h"
#include "posix_native_task.h"
#include "pdo_io_od.h"

#define NODE_ID     0x20U
#define RPDO1_COBID (0x200U + NODE_ID)
#define TPDO2_COBID (0x280U + NODE_ID)
#define SYNC_COBID  0x080U

#define COST_OPS     20000U
#define LATENCY_RUNS 2000U
#define SYNC_GAP_US  1000U
#define ANSWER_WAIT  K_MSEC(200)

static char *part_arg;

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "bench",
			.name = "cost|latency|all",
			.type = 's',
			.dest = &part_arg,
			.descript = "which figures to measure (default all)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 20);

static uint64_t now_ns(void)
{
	return k_cycle_get_64() * 1000000000ULL / (uint64_t)sys_clock_hw_cycles_per_sec();
}

static struct pdo_io_od_ram ram_sim, ram_thr;
static struct co_node node_sim, node_thr;
static struct co_line line_sim, line_thr;
static uint32_t sink_frames;
static uint32_t hook_calls;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	sink_frames++;
	return 0;
}

static void count_write(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	hook_calls++;
}

static void od_w32(struct co_node *n, uint16_t idx, uint8_t sub, uint32_t v)
{
	uint32_t ab = co_od_set_u32(co_node_od(n), idx, sub, v, CO_OD_WRITER_SDO);

	if (ab != 0U) {
		printf("pdo_bench: write %04x:%02x = %08x refused (%08x)\n", idx, sub, v, ab);
		exit(1);
	}
}

static void od_w8(struct co_node *n, uint16_t idx, uint8_t sub, uint8_t v)
{
	uint32_t ab = co_od_set_u8(co_node_od(n), idx, sub, v, CO_OD_WRITER_SDO);

	if (ab != 0U) {
		printf("pdo_bench: write %04x:%02x = %02x refused (%08x)\n", idx, sub, v, ab);
		exit(1);
	}
}

/* TPDO n (0-based) to transmission type 1 with @p map, the CiA 301 way. */
static void make_sync_tpdo(struct co_node *n, uint8_t pdo, uint32_t map)
{
	uint32_t cob = 0x180U + 0x100U * pdo + NODE_ID;

	od_w32(n, 0x1800 + pdo, 1, cob | BIT(31) | BIT(30));
	od_w8(n, 0x1800 + pdo, 2, 1);
	od_w8(n, 0x1A00 + pdo, 0, 0);
	od_w32(n, 0x1A00 + pdo, 1, map);
	od_w8(n, 0x1A00 + pdo, 0, 1);
	od_w32(n, 0x1800 + pdo, 1, cob | BIT(30));
}

static void nmt_start(struct co_line *line, uint64_t t)
{
	struct can_frame f = {.id = 0x000, .dlc = 2, .data = {0x01, NODE_ID}};

	co_line_rx(line, &f, t);
	co_line_process(line, t);
}

/* For scripts/bench: run again with --bench=cost under callgrind, collecting in a function. */
#define COLLECT_FMT ", \"collect\": \"%s\", \"collect_args\": [\"--bench=cost\"], \"total_ops\": %u"

static void print_json(const char *name, uint32_t ops, double ns, const char *extra)
{
	printf("BENCH {\"name\": \"%s\", \"ops\": %u, \"ns_per_op\": %.1f%s}\n", name, ops, ns,
	       extra);
}

/* Kept out of line: callgrind collects inside these two functions only. */
__attribute__((noinline)) void bench_rpdo_loop(uint32_t n, uint64_t *t)
{
	struct can_frame f = {.id = RPDO1_COBID, .dlc = 2};

	for (uint32_t i = 0; i < n; i++) {
		f.data[0] = (uint8_t)i;
		f.data[1] = (uint8_t)(i >> 8);
		co_line_rx(&line_sim, &f, *t);
		*t += 100U;
	}
}

__attribute__((noinline)) void bench_sync_loop(uint32_t n, uint64_t *t)
{
	const struct can_frame f = {.id = SYNC_COBID, .dlc = 0};

	for (uint32_t i = 0; i < n; i++) {
		co_line_rx(&line_sim, &f, *t);
		*t += SYNC_GAP_US;
	}
}

static void bench_cost(void)
{
	const struct co_od_hook hook = {0x6200, 0x6200, 1, 2, NULL, count_write, NULL};
	uint64_t t = 1000U;
	double best_rpdo = 1e30, best_sync = 1e30;
	char extra[192];

	co_line_init_sim(&line_sim, "bench", sink, NULL);
	if (co_node_init(&node_sim, "sim", &line_sim, &pdo_io_od_def, &ram_sim, NODE_ID) != 0 ||
	    co_od_hooks_register(co_node_od(&node_sim), &hook, 1) != 0 ||
	    co_node_start(&node_sim) != 0) {
		printf("pdo_bench: simulation node failed\n");
		exit(1);
	}
	/* Three synchronous TPDOs: TPDO2 as in the EDS (4 x I16), TPDO3 and TPDO4 remapped. */
	make_sync_tpdo(&node_sim, 2, 0x60000108U);
	make_sync_tpdo(&node_sim, 3, 0x64010110U);
	nmt_start(&line_sim, t);

	/* Best of 7 batches: the cost of the code, not of a preemption inside a batch. */
	for (int batch = 0; batch < 7; batch++) {
		uint64_t t0 = now_ns();
		double per;

		bench_rpdo_loop(COST_OPS, &t);
		per = (double)(now_ns() - t0) / COST_OPS;
		best_rpdo = per < best_rpdo ? per : best_rpdo;
	}
	sink_frames = 0U;
	for (int batch = 0; batch < 7; batch++) {
		uint64_t t0 = now_ns();
		double per;

		bench_sync_loop(COST_OPS, &t);
		per = (double)(now_ns() - t0) / COST_OPS;
		best_sync = per < best_sync ? per : best_sync;
	}
	if (hook_calls < 7U * COST_OPS || sink_frames != 7U * 3U * COST_OPS) {
		printf("pdo_bench: expected at least %u hook calls and %u TPDOs, got %u and %u\n",
		       7U * COST_OPS, 7U * 3U * COST_OPS, hook_calls, sink_frames);
		exit(1);
	}
	snprintf(extra, sizeof(extra), COLLECT_FMT, "bench_rpdo_loop", 7U * COST_OPS);
	print_json("pdo.rpdo_rx", COST_OPS, best_rpdo, extra);
	snprintf(extra, sizeof(extra), ", \"tpdos_per_sync\": 3, \"ns_per_tpdo\": %.1f" COLLECT_FMT,
		 best_sync / 3.0, "bench_sync_loop", 7U * COST_OPS);
	print_json("pdo.sync_3tpdo", COST_OPS, best_sync, extra);
}

/* --- Latency with real threads ------------------------------------------------------------ */

static K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(answered, 0, 1);
static uint64_t arrived_ns;

static void tpdo_seen(const struct device *dev, struct can_frame *frame, void *user_data)
{
	arrived_ns = now_ns();
	k_sem_give(&answered);
}

static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;

	return x < y ? -1 : (x > y ? 1 : 0);
}

static void bench_latency(void)
{
	static uint64_t lat[LATENCY_RUNS];
	const struct device *dut_dev = device_get_binding("can_virtual0");
	const struct device *raw = device_get_binding("can_virtual1");
	const struct can_filter filter = {.id = TPDO2_COBID, .mask = CAN_STD_ID_MASK};
	const struct can_frame nmt = {.id = 0x000, .dlc = 2, .data = {0x01, NODE_ID}};
	const struct can_frame sync = {.id = SYNC_COBID, .dlc = 0};
	uint32_t got = 0;
	char extra[160];

	if (dut_dev == NULL || raw == NULL || co_line_init(&line_thr, "dut", dut_dev) != 0 ||
	    co_node_init(&node_thr, "dut", &line_thr, &pdo_io_od_def, &ram_thr, NODE_ID) != 0 ||
	    co_line_start(&line_thr, line_stack, K_THREAD_STACK_SIZEOF(line_stack),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_node_start(&node_thr) != 0 || can_start(raw) != 0 ||
	    can_add_rx_filter(raw, tpdo_seen, NULL, &filter) < 0) {
		printf("pdo_bench: threaded setup failed\n");
		exit(1);
	}
	(void)can_send(raw, &nmt, K_MSEC(100), NULL, NULL);
	k_sleep(K_MSEC(20));
	for (uint32_t i = 0; i < LATENCY_RUNS; i++) {
		uint64_t sent;

		k_sem_reset(&answered);
		sent = now_ns();
		if (can_send(raw, &sync, K_MSEC(100), NULL, NULL) != 0) {
			continue;
		}
		if (k_sem_take(&answered, ANSWER_WAIT) == 0) {
			lat[got++] = arrived_ns - sent;
		}
		k_sleep(K_USEC(SYNC_GAP_US));
	}
	(void)co_line_stop(&line_thr);
	if (got == 0U) {
		printf("pdo_bench: no TPDO answered a SYNC\n");
		exit(1);
	}
	qsort(lat, got, sizeof(lat[0]), cmp_u64);
	snprintf(extra, sizeof(extra),
		 ", \"answered\": %u, \"p50_us\": %.1f, \"p99_us\": %.1f, \"max_us\": %.1f", got,
		 lat[got / 2U] / 1e3, lat[(got * 99U) / 100U] / 1e3, lat[got - 1U] / 1e3);
	print_json("pdo.sync_to_tpdo_latency", LATENCY_RUNS, (double)lat[got / 2U], extra);
}

int main(void)
{
	const char *part = part_arg != NULL ? part_arg : "all";

	if (strcmp(part, "all") != 0 && strcmp(part, "cost") != 0 && strcmp(part, "latency") != 0) {
		printf("pdo_bench: --bench must be cost, latency or all\n");
		return 1;
	}
	if (strcmp(part, "latency") != 0) {
		bench_cost();
	}
	if (strcmp(part, "cost") != 0) {
		bench_latency();
	}
	printf("pdo_bench: done\n");
	return 0;
}
