/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * cost     On a line bound to a controller that takes every frame at once and never
 *          receives one (the bench controller below; no simulated line, so the benchmark
 *          builds with CONFIG_CANOPEN_LINE_SIM off as the footprint's minimal slave has it),
 *          frames are handed to co_line_rx() as the line thread would hand them: the time
 *          to receive one RPDO (line dispatch + unpack + dictionary write + a notify hook),
 *          the same with 40 more exact receivers on other 11-bit ids and with one masked
 *          receiver (700h/780h, the heartbeat range) registered on the line, and the time to
 *          serve one SYNC that triggers three synchronous TPDOs (pack + send to the
 *          controller). scripts/bench runs this part again under callgrind, collecting only
 *          inside one bench_*_loop() function at a time, for instructions per operation.
 * latency  With real threads on the virtual bus: a raw controller sends SYNC, the device's
 *          line thread answers with a synchronous TPDO, the raw controller's receive callback
 *          takes the arrival time. p50/p99/max of SYNC sent -> TPDO received.
 *
 * The dictionary is the pdo_io sample's (the footprint's minimal slave's) with TPDOs 2-4
 * synchronous and mapped in the EDS itself (bench_pdo.eds), so that nothing is remapped at
 * run time (the minimal slave's mapping is static), and with no heartbeat and no event timer,
 * so that the line's thread has no deadline and sleeps while the main thread dispatches.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them into a file.
 * scripts/bench also builds this benchmark with the footprint's configurations.
 */

#include <errno.h>
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
#include "bench_pdo_od.h"

#define NODE_ID     0x20U
#define RPDO1_COBID (0x200U + NODE_ID)
#define TPDO2_COBID (0x280U + NODE_ID)
#define SYNC_COBID  0x080U

#define COST_OPS     20000U
#define BATCHES      7U
#define LATENCY_RUNS 2000U
#define SYNC_GAP_US  1000U
#define ANSWER_WAIT  K_MSEC(200)

/* 40 more exact receivers: SDO request ids of nodes 40h-67h, which nobody on the line uses. */
#define MORE_RX       40U
#define MORE_RX_FIRST 0x6C0U
/* One masked receiver: the heartbeat range 700h-77Fh, as a heartbeat consumer might take it. */
#define MASKED_ID     0x700U
#define MASKED_MASK   0x780U

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

/* --- The bench controller ----------------------------------------------------------------- */

/*
 * A CAN controller that completes every frame at once (its TX callback runs inside
 * can_send()) and receives nothing: the line's send path ends in a driver, as on a target,
 * and nothing arrives behind the main thread's back.
 */
static uint32_t bench_sent;

static int bc_caps(const struct device *dev, can_mode_t *cap)
{
	*cap = CAN_MODE_NORMAL;
	return 0;
}

static int bc_ok(const struct device *dev)
{
	return 0;
}

static int bc_set_mode(const struct device *dev, can_mode_t mode)
{
	return 0;
}

static int bc_set_bitrate(const struct device *dev, uint32_t bitrate)
{
	return 0;
}

static int bc_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
		   can_tx_callback_t callback, void *user_data)
{
	bench_sent++;
	if (callback != NULL) {
		callback(dev, 0, user_data);
	}
	return 0;
}

static int bc_filters;

static int bc_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
			    const struct can_filter *filter)
{
	return bc_filters++;
}

static void bc_remove_rx_filter(const struct device *dev, int filter_id)
{
}

static int bc_recover(const struct device *dev, k_timeout_t timeout)
{
	return 0;
}

static int bc_get_state(const struct device *dev, enum can_state *state,
			struct can_bus_err_cnt *err_cnt)
{
	if (state != NULL) {
		*state = CAN_STATE_ERROR_ACTIVE;
	}
	if (err_cnt != NULL) {
		*err_cnt = (struct can_bus_err_cnt){0};
	}
	return 0;
}

static void bc_set_state_cb(const struct device *dev, can_state_change_callback_t callback,
			    void *user_data)
{
}

static int bc_max_filters(const struct device *dev, bool ide)
{
	return 1024;
}

static const struct can_driver_api bench_can_api = {
	.get_capabilities = bc_caps,
	.start = bc_ok,
	.stop = bc_ok,
	.set_mode = bc_set_mode,
	.set_bitrate = bc_set_bitrate,
	.send = bc_send,
	.add_rx_filter = bc_add_rx_filter,
	.remove_rx_filter = bc_remove_rx_filter,
	.recover = bc_recover,
	.get_state = bc_get_state,
	.set_state_change_callback = bc_set_state_cb,
	.get_max_filters = bc_max_filters,
};

DEVICE_DEFINE(bench_can, "bench_can", NULL, NULL, NULL, NULL, POST_KERNEL, 50, &bench_can_api);

/* --- Cost on one line --------------------------------------------------------------------- */

static struct bench_pdo_od_ram ram_cost, ram_thr;
static struct co_node node_cost, node_thr;
static struct co_line line_cost, line_thr;
static K_THREAD_STACK_DEFINE(cost_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static uint32_t hook_calls;
static struct co_rx more_rx[MORE_RX];
static struct co_rx masked_rx;

static void count_write(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	hook_calls++;
}

static void never_called(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	printf("pdo_bench: frame %03x reached the receiver of %03x/%03x\n", frame->id, rx->id,
	       rx->mask);
	exit(1);
}

/* For scripts/bench: run again with --bench=cost under callgrind, collecting in a function. */
#define COLLECT_FMT ", \"collect\": \"%s\", \"collect_args\": [\"--bench=cost\"], \"total_ops\": %u"
/*
 * The same, but not inside the CAN driver's can_send() (Zephyr's part, not the stack's, as the
 * footprint leaves it out too). callgrind toggles collection at each entry and exit of a
 * function it is told of, so this is for a loop outside of which can_send() runs only before
 * it (the node's boot-up, one frame: < 0.001 instructions per operation).
 */
#define COLLECT_NO_DRIVER_FMT                                                                      \
	", \"collect\": \"%s\", \"collect_exclude\": [\"can_send\"], "                             \
	"\"collect_args\": [\"--bench=cost\"], \"total_ops\": %u"

static void print_json(const char *name, uint32_t ops, double ns, const char *extra)
{
	printf("BENCH {\"name\": \"%s\", \"ops\": %u, \"ns_per_op\": %.1f%s}\n", name, ops, ns,
	       extra);
}

static inline void rpdo_batch(uint32_t n, uint64_t *t)
{
	struct can_frame f = {.id = RPDO1_COBID, .dlc = 2};

	for (uint32_t i = 0; i < n; i++) {
		f.data[0] = (uint8_t)i;
		f.data[1] = (uint8_t)(i >> 8);
		co_line_rx(&line_cost, &f, *t);
		*t += 100U;
	}
}

/* Kept out of line: callgrind collects inside one of these functions at a time. */
__attribute__((noinline)) void bench_rpdo_loop(uint32_t n, uint64_t *t)
{
	rpdo_batch(n, t);
}

__attribute__((noinline)) void bench_rpdo_more_rx_loop(uint32_t n, uint64_t *t)
{
	rpdo_batch(n, t);
}

__attribute__((noinline)) void bench_rpdo_masked_loop(uint32_t n, uint64_t *t)
{
	rpdo_batch(n, t);
}

__attribute__((noinline)) void bench_sync_loop(uint32_t n, uint64_t *t)
{
	const struct can_frame f = {.id = SYNC_COBID, .dlc = 0};

	for (uint32_t i = 0; i < n; i++) {
		co_line_rx(&line_cost, &f, *t);
		*t += SYNC_GAP_US;
	}
}

/* Best of BATCHES batches: the cost of the code, not of a preemption inside a batch. */
static double best_ns(void (*loop)(uint32_t, uint64_t *), uint64_t *t)
{
	double best = 1e30;

	for (uint32_t batch = 0; batch < BATCHES; batch++) {
		uint64_t t0 = now_ns();
		double per;

		loop(COST_OPS, t);
		per = (double)(now_ns() - t0) / COST_OPS;
		best = per < best ? per : best;
	}
	return best;
}

static void print_rpdo(const char *name, const char *loop, double ns, const char *more)
{
	char extra[512];

	snprintf(extra, sizeof(extra), "%s" COLLECT_FMT, more, loop, BATCHES * COST_OPS);
	print_json(name, COST_OPS, ns, extra);
}

static void bench_cost(void)
{
	const struct co_od_hook hook = {0x6200, 0x6200, 1, 2, NULL, count_write, NULL};
	const struct can_frame nmt = {.id = 0x000, .dlc = 2, .data = {0x01, NODE_ID}};
	const struct device *dev = device_get_binding("bench_can");
	uint32_t registered = 0;
	uint32_t rpdo_loops = 1;
	uint64_t t;
	double ns;
	int err = 0;
	char more[320];

	if (dev == NULL || co_line_init(&line_cost, "bench", dev) != 0 ||
	    co_line_start(&line_cost, cost_stack, K_THREAD_STACK_SIZEOF(cost_stack),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_node_init(&node_cost, "cost", &line_cost, &bench_pdo_od_def, &ram_cost, NODE_ID) !=
		    0 ||
	    co_od_hooks_register(co_node_od(&node_cost), &hook, 1) != 0 ||
	    co_node_start(&node_cost) != 0) {
		printf("pdo_bench: the node on the bench controller failed\n");
		exit(1);
	}
	/* Times as the line thread would pass them: the line's clock, then 100 µs a frame. */
	t = co_line_now();
	(void)co_line_rx(&line_cost, &nmt, t);

	ns = best_ns(bench_rpdo_loop, &t);
	print_rpdo("pdo.rpdo_rx", "bench_rpdo_loop", ns, "");

	co_rx_init(&masked_rx, MASKED_ID, never_called, NULL, NULL);
	masked_rx.mask = MASKED_MASK;
	err = co_rx_register(&line_cost, &masked_rx);
	if (err == 0) {
		ns = best_ns(bench_rpdo_masked_loop, &t);
		rpdo_loops++;
		co_rx_unregister(&masked_rx);
		snprintf(more, sizeof(more), ", \"receivers_added\": 1, \"id\": %u, \"mask\": %u",
			 MASKED_ID, MASKED_MASK);
		print_rpdo("pdo.rpdo_rx_masked", "bench_rpdo_masked_loop", ns, more);
	} else {
		printf("BENCH {\"name\": \"pdo.rpdo_rx_masked\", \"error\": \"co_rx_register() "
		       "returned %d for the masked receiver\"}\n",
		       err);
	}

	for (; registered < MORE_RX; registered++) {
		co_rx_init(&more_rx[registered], MORE_RX_FIRST + registered, never_called, NULL,
			   NULL);
		err = co_rx_register(&line_cost, &more_rx[registered]);
		if (err != 0) {
			break;
		}
	}
	if (registered == MORE_RX) {
		ns = best_ns(bench_rpdo_more_rx_loop, &t);
		rpdo_loops++;
		snprintf(more, sizeof(more), ", \"receivers_added\": %u", MORE_RX);
		print_rpdo("pdo.rpdo_rx_40_more", "bench_rpdo_more_rx_loop", ns, more);
	} else {
		/* scripts/bench builds again with more receive slots. */
		printf("BENCH {\"name\": \"pdo.rpdo_rx_40_more\", \"error\": \"co_rx_register() "
		       "returned %d after %u of %u receivers\", \"registered\": %u}\n",
		       err, registered, MORE_RX, registered);
	}
	for (uint32_t i = 0; i < registered; i++) {
		co_rx_unregister(&more_rx[i]);
	}

	bench_sent = 0U;
	ns = best_ns(bench_sync_loop, &t);
	if (hook_calls < rpdo_loops * BATCHES * COST_OPS || bench_sent != BATCHES * 3U * COST_OPS) {
		printf("pdo_bench: expected at least %u hook calls and %u TPDOs, got %u and %u\n",
		       rpdo_loops * BATCHES * COST_OPS, BATCHES * 3U * COST_OPS, hook_calls,
		       bench_sent);
		exit(1);
	}
	snprintf(more, sizeof(more),
		 ", \"tpdos_per_sync\": 3, \"ns_per_tpdo\": %.1f" COLLECT_NO_DRIVER_FMT, ns / 3.0,
		 "bench_sync_loop", BATCHES * COST_OPS);
	print_json("pdo.sync_3tpdo", COST_OPS, ns, more);
	(void)co_line_stop(&line_cost);
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
	    co_node_init(&node_thr, "dut", &line_thr, &bench_pdo_od_def, &ram_thr, NODE_ID) != 0 ||
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
