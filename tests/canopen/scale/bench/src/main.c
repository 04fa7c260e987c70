/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Scale benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * 255 lines in one process, each with its own thread and one node (the pdo_io dictionary:
 * heartbeat every 1000 ms, TPDO 1 every 1000 ms, RPDO 1 taking a neighbour's TPDO 1). The
 * virtual driver has 8 controllers, so the lines share them, 32 to a controller: a line
 * hears the lines on the other controller of its bus (controllers i and i + 4 share bus
 * i % 4), 32 heartbeats and 32 TPDOs a second, each frame a wake of its thread. Node-IDs
 * are unique per bus (1..64).
 *
 * Printed: resident memory (VmRSS now, VmHWM the peak, from /proc/self/status) before the
 * lines exist, with all of them running, and after a window of traffic; the process's CPU
 * time in that window (getrusage) per line; the structures' sizes per line; the frames the
 * buses carried and the lines dispatched.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them.
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
#include "pdo_io_od.h"

#define LINES     255
#define CTRLS     CONFIG_CAN_VIRTUAL_NUM_CONTROLLERS
#define BUSES     CONFIG_CAN_VIRTUAL_NUM_BUSES
#define WINDOW_S  10
#define SETTLE_MS 2500

static struct co_line lines[LINES];
static struct co_node nodes[LINES];
static struct pdo_io_od_ram rams[LINES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static char names[LINES][8];

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

/* Line k: controller k % CTRLS, node-ID unique on its bus. */
static uint8_t node_id(int k)
{
	return (uint8_t)(k / BUSES + 1);
}

/* The node whose TPDO 1 line k takes: on the other controller of the same bus. */
static uint8_t neighbour_id(int k)
{
	int other = (k / BUSES) % 2 == 0 ? k + BUSES : k - BUSES;

	if (other >= LINES) {
		other = k - BUSES;
	}
	return node_id(other);
}

static void bus_frames(uint64_t *frames)
{
	*frames = 0;
	for (int b = 0; b < BUSES; b++) {
		struct can_virtual_bus_stats s;

		(void)can_virtual_bus_get_stats(b, &s);
		*frames += s.frames;
	}
}

static void line_totals(struct co_line_stats *sum)
{
	memset(sum, 0, sizeof(*sum));
	for (int k = 0; k < LINES; k++) {
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
	long rss0, hwm0, rss1, hwm1, rss2, hwm2;
	struct co_line_stats l0, l1;
	uint64_t f0, f1;
	double c0, c1, cpu_per_line_us;
	int th0, th1;

	mem_kb(&rss0, &hwm0);
	th0 = threads();
	for (int c = 0; c < CTRLS; c++) {
		char name[16];

		snprintf(name, sizeof(name), "can_virtual%d", c);
		devs[c] = device_get_binding(name);
	}
	for (int k = 0; k < LINES; k++) {
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
	mem_kb(&rss1, &hwm1);
	line_totals(&l0);
	bus_frames(&f0);
	c0 = cpu_s();
	k_msleep(WINDOW_S * 1000);
	c1 = cpu_s();
	bus_frames(&f1);
	line_totals(&l1);
	mem_kb(&rss2, &hwm2);

	for (int k = 0; k < LINES; k++) {
		if (co_nmt_get_state(&nodes[k]) != CO_NMT_OPERATIONAL) {
			printf("scale_bench: node %d not operational\n", k);
			return 1;
		}
	}
	cpu_per_line_us = (c1 - c0) * 1e6 / WINDOW_S / LINES;
	printf("BENCH {\"name\": \"scale.lines_255\", \"lines\": %d, \"nodes\": %d, "
	       "\"controllers\": %d, \"buses\": %d, \"window_s\": %d, "
	       "\"rss_mb\": %.1f, \"hwm_mb\": %.1f, \"rss_before_mb\": %.1f, "
	       "\"rss_per_line_kb\": %.1f, \"host_threads\": %d, "
	       "\"cpu_pct\": %.1f, \"cpu_us_per_line_per_s\": %.1f, "
	       "\"bus_frames_per_s\": %.0f, \"line_rx_per_s\": %.0f, \"cpu_us_per_rx\": %.2f, "
	       "\"rx_overruns\": %u, \"tx_dropped\": %u, \"tx_errors\": %u, "
	       "\"sizeof_line\": %zu, \"sizeof_node\": %zu, \"od_ram\": %zu, "
	       "\"line_stack\": %d, \"rx_queue\": %d, \"tx_queue\": %d}\n",
	       LINES, LINES, CTRLS, BUSES, WINDOW_S, rss2 / 1024.0, hwm2 / 1024.0, rss0 / 1024.0,
	       (double)(rss2 - rss0) / LINES, th1, 100.0 * (c1 - c0) / WINDOW_S, cpu_per_line_us,
	       (double)(f1 - f0) / WINDOW_S, (double)(l1.rx_frames - l0.rx_frames) / WINDOW_S,
	       (c1 - c0) * 1e6 / (double)MAX(1U, l1.rx_frames - l0.rx_frames), l1.rx_overruns,
	       l1.tx_dropped, l1.tx_errors, sizeof(struct co_line), sizeof(struct co_node),
	       sizeof(struct pdo_io_od_ram), CONFIG_CANOPEN_LINE_STACK_SIZE,
	       CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	(void)th0;
	(void)rss1;
	(void)hwm0;
	(void)hwm1;
	printf("scale_bench: done\n");
	return 0;
}
