/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SRDO benchmark (doc/bench.md, doc/srdo-campaign.md): figures only, nothing is judged.
 *
 * On a simulation line (no threads, no driver) a consumer node receives SRDO pairs as raw
 * frames: the normal frame, then the inverted frame 50 µs later, one pair per millisecond
 * (SCT 50 ms, SRVT 20 ms, so every pair is valid). One operation is one pair: line dispatch of
 * both frames, the SRVT/SCT/length/inversion checks, the dictionary writes of both channels
 * and the re-arming of the consumer's timer.
 *   srdo.rx_pair_1+1   SRDO 1: 6200h:01 / 6201h:01, one U8 per frame
 *   srdo.rx_pair_4+4   SRDO 2: 6000h:01-04 / 6001h:01-04, four U8 per frame
 * scripts/bench runs the image again under callgrind, collecting only inside
 * bench_pair_1x1_loop() and bench_pair_4x4_loop(), for instructions per pair.
 *
 * The worst fault detection latency is not a benchmark figure: the fault campaign
 * (tests/canopen/srdo/campaign) measures and prints it.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them into a file.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/srdo.h>

#include "srdo_bench_od.h"

#define NODE_ID 0x10U
#define OPS     20000U
#define BATCHES 7U
#define PAIR_US 1000U
#define GAP_US  50U

static struct srdo_bench_od_ram ram;
static struct co_node node;
static struct co_line line;
static uint32_t sink_frames;

static int sink(struct co_line *l, const struct can_frame *frame, void *user_data)
{
	sink_frames++;
	return 0;
}

static uint64_t now_ns(void)
{
	return k_cycle_get_64() * 1000000000ULL / (uint64_t)sys_clock_hw_cycles_per_sec();
}

static void fail(const char *what)
{
	printf("srdo_bench: %s\n", what);
	exit(1);
}

/* One pair per millisecond of simulated time; @p len data bytes per frame. */
static inline void pair(uint32_t cob1, uint8_t len, uint32_t i, uint64_t *t)
{
	struct can_frame n = {.id = cob1, .dlc = len};
	struct can_frame v = {.id = cob1 + 1U, .dlc = len};

	for (uint8_t k = 0; k < len; k++) {
		n.data[k] = (uint8_t)(i + k);
		v.data[k] = (uint8_t)~n.data[k];
	}
	co_line_rx(&line, &n, *t);
	co_line_rx(&line, &v, *t + GAP_US);
	*t += PAIR_US;
}

/* Kept out of line: callgrind collects inside these two functions only. */
__attribute__((noinline)) void bench_pair_1x1_loop(uint32_t n, uint64_t *t)
{
	for (uint32_t i = 0; i < n; i++) {
		pair(0x101U, 1U, i, t);
	}
}

__attribute__((noinline)) void bench_pair_4x4_loop(uint32_t n, uint64_t *t)
{
	for (uint32_t i = 0; i < n; i++) {
		pair(0x103U, 4U, i, t);
	}
}

/* NMT command @p cs for the node, as a frame at @p t. */
static void nmt(uint8_t cs, uint64_t t)
{
	const struct can_frame f = {.id = 0x000, .dlc = 2, .data = {cs, NODE_ID}};

	co_line_rx(&line, &f, t);
	co_line_process(&line, t);
}

static void setup(uint64_t t)
{
	struct co_od *od = co_node_od(&node);
	uint16_t crc;

	co_line_init_sim(&line, "bench", sink, NULL);
	if (co_node_init(&node, "sim", &line, &srdo_bench_od_def, &ram, NODE_ID) != 0 ||
	    co_node_start(&node) != 0) {
		fail("simulation node failed");
	}
	co_node_lock(&node);
	for (uint8_t n = 1; n <= 2; n++) {
		if (co_srdo_signature(&node, n, &crc) != 0 ||
		    co_od_set_u16(od, 0x13FF, n, crc, CO_OD_WRITER_APP) != 0U) {
			fail("cannot sign the SRDOs");
		}
	}
	if (co_od_set_u8(od, 0x13FE, 0, CO_SRDO_VALID, CO_OD_WRITER_APP) != 0U) {
		fail("configuration refused");
	}
	co_node_unlock(&node);
	nmt(0x01, t);
	if (co_node_nmt_state(&node) != CO_NMT_OPERATIONAL) {
		fail("the node did not enter Operational");
	}
	sink_frames = 0U;
}

static double best_of(void (*loop)(uint32_t, uint64_t *), uint64_t *t)
{
	double best = 1e30;

	for (uint32_t b = 0; b < BATCHES; b++) {
		uint64_t t0 = now_ns();
		double per;

		loop(OPS, t);
		per = (double)(now_ns() - t0) / OPS;
		best = per < best ? per : best;
	}
	return best;
}

/* The SRDO stayed valid and holds the last pair (i = OPS - 1 of the last batch). */
static void check(uint8_t srdo, uint16_t normal, uint16_t inverted)
{
	enum co_srdo_reason reason;
	uint8_t v = 0, w = 0;
	const uint8_t last = (uint8_t)(OPS - 1U);
	const uint8_t last_inv = (uint8_t)~last;
	uint32_t err;

	if (co_srdo_get_state(&node, srdo, &reason) != CO_SRDO_STATE_VALID) {
		printf("srdo_bench: SRDO %u in the safe state (reason %u)\n", srdo, reason);
		exit(1);
	}
	co_node_lock(&node);
	err = co_od_get_u8(co_node_od(&node), normal, 1, &v) |
	      co_od_get_u8(co_node_od(&node), inverted, 1, &w);
	co_node_unlock(&node);
	if (err != 0U || v != last || w != last_inv) {
		printf("srdo_bench: SRDO %u holds %02x/%02x, expected %02x/%02x\n", srdo, v, w,
		       last, last_inv);
		exit(1);
	}
}

#define COLLECT_FMT ", \"collect\": \"%s\", \"total_ops\": %u"

static void print_json(const char *name, double ns, uint8_t bytes, const char *collect)
{
	printf("BENCH {\"name\": \"%s\", \"ops\": %u, \"ns_per_op\": %.1f, \"bytes_per_frame\": "
	       "%u, \"ns_per_frame\": %.1f" COLLECT_FMT "}\n",
	       name, OPS, ns, bytes, ns / 2.0, collect, BATCHES * OPS);
}

int main(void)
{
	uint64_t t = 1000U;
	double small, big;

	setup(t);
	t += PAIR_US;
	small = best_of(bench_pair_1x1_loop, &t);
	check(1, 0x6200, 0x6201);
	/*
	 * SRDO 2 got no pair while SRDO 1 was measured and nobody ran the line's timers: enter
	 * Operational again so that its SCT counts from now (SRDO 1 then waits, unchecked).
	 */
	nmt(0x80, t);
	nmt(0x01, t);
	t += PAIR_US;
	big = best_of(bench_pair_4x4_loop, &t);
	check(2, 0x6000, 0x6001);
	if (sink_frames != 0U) {
		fail("the consumer sent frames (an EMCY?)");
	}
	print_json("srdo.rx_pair_1+1", small, 1U, "bench_pair_1x1_loop");
	print_json("srdo.rx_pair_4+4", big, 4U, "bench_pair_4x4_loop");
	printf("srdo_bench: done\n");
	return 0;
}
