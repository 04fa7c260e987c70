/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Scale benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * --lines=N lines (16 to 255, default 255) in one process on one virtual bus, each with its
 * own thread and one node (the pdo_io dictionary: heartbeat every 1000 ms, TPDO 1 every
 * 1000 ms, RPDO 1 taking the next line's TPDO 1). The virtual driver has 8 controllers, so
 * the lines share them, line k on controller k % 8; a controller hears the frames of the 7
 * others, so a line hears about 7/8 of the bus: 2 frames a second from each of those lines.
 * Node-IDs are 1..127 and repeat from the 128th line on (the virtual bus needs no unique
 * identifiers; a repeated heartbeat is one more frame).
 *
 * Printed: resident memory (VmRSS now, VmHWM the peak, from /proc/self/status) before the
 * lines exist and after a window of traffic; the process's CPU time (getrusage) over a
 * fixed wall-clock window, per line and second; the structures' sizes per line; the frames
 * the bus carried and the lines dispatched.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench runs 16, 64 and 255 lines
 * and prints the ratio of the CPU per line at 255 lines to that at 16.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/od.h>

#include "can_virtual.h"
#include "cmdline.h"
#include "posix_native_task.h"
#include "pdo_io_od.h"

#define LINES_MAX 255
#define LINES_MIN 16
#define CTRLS     CONFIG_CAN_VIRTUAL_NUM_CONTROLLERS
#define WINDOW_S  10
#define SETTLE_MS 2500

static struct co_line lines[LINES_MAX];
static struct co_node nodes[LINES_MAX];
static struct pdo_io_od_ram rams[LINES_MAX];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, LINES_MAX, CONFIG_CANOPEN_LINE_STACK_SIZE);
static char names[LINES_MAX][12];
static int32_t lines_arg; /* INT32_MAX when --lines is not given */
static int n_lines;

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "lines",
			.name = "N",
			.type = 'i',
			.dest = &lines_arg,
			.descript = "lines (and nodes) on the bus, 16 to 255 (default 255)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 20);

/* VmRSS and VmHWM in kB. */
static void mem_kb(long *rss, long *hwm)
{
	char buf[256];
	FILE *f = fopen("/proc/self/status", "r");

	*rss = -1;
	*hwm = -1;
	if (f == NULL) {
		return;
	}
	while (fgets(buf, sizeof(buf), f) != NULL) {
		(void)sscanf(buf, "VmRSS: %ld", rss);
		(void)sscanf(buf, "VmHWM: %ld", hwm);
	}
	fclose(f);
}

static double cpu_s(void)
{
	struct rusage ru;

	getrusage(RUSAGE_SELF, &ru);
	return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec +
	       (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
}

static int threads(void)
{
	char buf[256];
	int n = -1;
	FILE *f = fopen("/proc/self/status", "r");

	if (f == NULL) {
		return -1;
	}
	while (fgets(buf, sizeof(buf), f) != NULL) {
		(void)sscanf(buf, "Threads: %d", &n);
	}
	fclose(f);
	return n;
}

/* Line k: controller k % CTRLS, node-ID 1..127, repeating from the 128th line on. */
static uint8_t node_id(int k)
{
	return (uint8_t)(k % 127 + 1);
}

/* The node whose TPDO 1 line k takes: the next line's, on the next controller. */
static uint8_t neighbour_id(int k)
{
	return node_id((k + 1) % n_lines);
}

static uint64_t bus_frames(void)
{
	struct can_virtual_bus_stats s;

	(void)can_virtual_bus_get_stats(0, &s);
	return s.frames;
}

static void line_totals(struct co_line_stats *sum)
{
	memset(sum, 0, sizeof(*sum));
	for (int k = 0; k < n_lines; k++) {
		struct co_line_stats s;

		co_line_get_stats(&lines[k], &s);
		sum->rx_frames += s.rx_frames;
		sum->rx_overruns += s.rx_overruns;
		sum->tx_frames += s.tx_frames;
		sum->tx_dropped += s.tx_dropped;
		sum->tx_errors += s.tx_errors;
	}
}

int main(void)
{
	const struct device *devs[CTRLS];
	long rss0, hwm0, rss2, hwm2;
	struct co_line_stats l0, l1;
	uint64_t f0, f1;
	double c0, c1, cpu_per_line_us;
	int th1;

	n_lines = lines_arg == INT32_MAX ? LINES_MAX : lines_arg;
	if (n_lines < LINES_MIN || n_lines > LINES_MAX) {
		printf("scale_bench: --lines must be %d to %d, not %d\n", LINES_MIN, LINES_MAX,
		       n_lines);
		return 1;
	}
	mem_kb(&rss0, &hwm0);
	for (int c = 0; c < CTRLS; c++) {
		char name[16];

		snprintf(name, sizeof(name), "can_virtual%d", c);
		devs[c] = device_get_binding(name);
	}
	for (int k = 0; k < n_lines; k++) {
		struct co_node *n = &nodes[k];
		uint32_t ab;

		snprintf(names[k], sizeof(names[k]), "l%d", k);
		if (co_line_init(&lines[k], names[k], devs[k % CTRLS]) != 0 ||
		    co_line_start(&lines[k], stacks[k], K_THREAD_STACK_SIZEOF(stacks[k]),
				  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
		    co_node_init(n, names[k], &lines[k], &pdo_io_od_def, &rams[k], node_id(k)) !=
			    0) {
			printf("scale_bench: line %d failed\n", k);
			return 1;
		}
		/* RPDO 1 takes the neighbour's TPDO 1 (invalid while it changes, CiA 301). */
		co_node_lock(n);
		ab = co_od_set_u32(co_node_od(n), 0x1400, 1, BIT(31) | (0x200U + node_id(k)),
				   CO_OD_WRITER_SDO);
		ab = ab != 0U ? ab
			      : co_od_set_u32(co_node_od(n), 0x1400, 1, 0x180U + neighbour_id(k),
					      CO_OD_WRITER_SDO);
		co_node_unlock(n);
		if (ab != 0U) {
			printf("scale_bench: line %d: RPDO 1 refused (%08x)\n", k, ab);
			return 1;
		}
		if (co_node_start(n) != 0 || co_nmt_req(n, CO_NMT_CS_START) != 0) {
			printf("scale_bench: node %d did not start\n", k);
			return 1;
		}
	}
	th1 = threads();
	k_msleep(SETTLE_MS);
	line_totals(&l0);
	f0 = bus_frames();
	c0 = cpu_s();
	k_msleep(WINDOW_S * 1000);
	c1 = cpu_s();
	f1 = bus_frames();
	line_totals(&l1);
	mem_kb(&rss2, &hwm2);

	for (int k = 0; k < n_lines; k++) {
		if (co_nmt_get_state(&nodes[k]) != CO_NMT_OPERATIONAL) {
			printf("scale_bench: node %d not operational\n", k);
			return 1;
		}
	}
	cpu_per_line_us = (c1 - c0) * 1e6 / WINDOW_S / n_lines;
	printf("BENCH {\"name\": \"scale.lines_%d\", \"lines\": %d, \"nodes\": %d, "
	       "\"controllers\": %d, \"buses\": 1, \"window_s\": %d, "
	       "\"rss_mb\": %.1f, \"hwm_mb\": %.1f, \"rss_before_mb\": %.1f, "
	       "\"rss_per_line_kb\": %.1f, \"host_threads\": %d, "
	       "\"cpu_pct\": %.1f, \"cpu_us_per_line_per_s\": %.1f, "
	       "\"bus_frames_per_s\": %.0f, \"line_rx_per_s\": %.0f, \"cpu_us_per_rx\": %.2f, "
	       "\"rx_overruns\": %u, \"tx_dropped\": %u, \"tx_errors\": %u, "
	       "\"sizeof_line\": %zu, \"sizeof_node\": %zu, \"od_ram\": %zu, "
	       "\"line_stack\": %d, \"rx_queue\": %d, \"tx_queue\": %d}\n",
	       n_lines, n_lines, n_lines, CTRLS, WINDOW_S, rss2 / 1024.0, hwm2 / 1024.0,
	       rss0 / 1024.0, (double)(rss2 - rss0) / n_lines, th1, 100.0 * (c1 - c0) / WINDOW_S,
	       cpu_per_line_us, (double)(f1 - f0) / WINDOW_S,
	       (double)(l1.rx_frames - l0.rx_frames) / WINDOW_S,
	       (c1 - c0) * 1e6 / (double)MAX(1U, l1.rx_frames - l0.rx_frames), l1.rx_overruns,
	       l1.tx_dropped, l1.tx_errors, sizeof(struct co_line), sizeof(struct co_node),
	       sizeof(struct pdo_io_od_ram), CONFIG_CANOPEN_LINE_STACK_SIZE,
	       CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	printf("scale_bench: done\n");
	return 0;
}
