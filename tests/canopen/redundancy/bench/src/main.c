/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Redundancy benchmark (doc/bench.md): the switch-over of a network to its redundant line
 * after a cut of the default line, on the virtual bus in real time (bit timing on, 500 kbit/s).
 * Figures only, nothing is judged.
 *
 * The network is the one of tests/canopen/redundancy/threaded: a master (node 1) and two slaves
 * (nodes 2, 3), each with a controller on bus 0 (default line) and one on bus 1 (redundant
 * line); heartbeats every 50 ms, consumer time 125 ms, a counter in TPDO 1 of each slave every
 * 10 ms. Each node's application also sends a probe frame (7C0h + node-ID, no data) every 2 ms
 * on its active line (CO_ROUTE_ACTIVE), the route of the master's NMT commands and of the SDO
 * client; heartbeats and PDOs go on both lines all the time.
 *
 * Each run: a random point of the heartbeat cycle, cut every controller of bus 0, wait until
 * every node is on the redundant line and 200 ms more, restore, wait until every node is back.
 * A raw controller on bus 1 (can_virtual7) stamps what arrives there. Per node and cut:
 *
 *   switch_event   cut -> the application's CO_EV_REDUNDANCY SWITCH listener ran
 *   active_frame   cut -> the first probe of the node on the redundant line (what goes on the
 *                  active line moved; resolution 2 ms)
 *   any_frame      cut -> the first frame of any kind of the node on the redundant line (its
 *                  EMCY 8120h, as its controller on the cut line turns error passive, or a
 *                  heartbeat or PDO: those go on both lines all the time)
 *   network        cut -> the last node's SWITCH (the network is on the new line)
 *   switch_back    restore -> the SWITCH back (after three heartbeat cycles counted half a
 *                  consumer time apart, the heartbeats the cut controller held back once:
 *                  2-5 heartbeat periods)
 *
 * against the bound "heartbeat consumer time + one heartbeat period" (175 ms); min/median/max.
 * The PDO values: every slave's counter checked by the master's application, values lost
 * (goal 0) and delivered twice.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/random/random.h>
#include <zephyr/sys/atomic.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/redundancy.h>

#include "cmdline.h"
#include "posix_native_task.h"
#include "thr_master_od.h"
#include "thr_slave_od.h"

#define N_UNITS     3
#define N_SLAVES    2
#define D           CO_LINE_DEFAULT
#define R           CO_LINE_REDUNDANT
#define HB_MS       50U
#define CONSUMER_MS 125U
#define BOUND_MS    (CONSUMER_MS + HB_MS)
#define PROBE_ID    0x7C0U
#define PROBE_MS    2
#define HOLD_MS     200
#define MAX_CUTS    200U
#define MAX_VALUES  (1U << 16)
#define IDX_COUNTER 0x2000U
#define IDX_COUNTS  0x2100U

static uint32_t cuts_arg = 20U;

static void cuts_found(char *argv, int offset)
{
	cuts_arg = (uint32_t)cmd_read_uint_option("cuts", &argv[offset], 1U, MAX_CUTS);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "cuts",
			.name = "n",
			.type = 'u',
			.call_when_found = cuts_found,
			.descript = "cuts of the default line to measure (1..200, default 20)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 20);

struct unit {
	const char *name;
	uint8_t id;
	struct co_line line[CO_NODE_LINES];
	struct co_node node;
	struct co_listener listener;
	const struct device *can[CO_NODE_LINES];
	uint32_t produced;   /* slave, under its mutex */
	uint64_t switch_at;  /* the last SWITCH heard [µs], under its mutex */
	uint8_t switch_line; /* ... to this line */
};

static struct unit units[N_UNITS] = {
	{.name = "master", .id = 1},
	{.name = "node2", .id = 2},
	{.name = "node3", .id = 3},
};
#define MASTER (&units[0])

static struct thr_master_od_ram master_ram;
static struct thr_slave_od_ram slave_ram[N_SLAVES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_UNITS *CO_NODE_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);
static uint8_t delivered[N_SLAVES][MAX_VALUES];

/* The observer on bus 1: first frames after `armed` [µs since armed, + 1; 0: none yet]. */
static atomic_t armed_lo;
static atomic_t first_any[N_UNITS];
static atomic_t first_probe[N_UNITS];

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct unit *u = user_data;

	if (ev->redundancy.what == CO_RDN_EV_SWITCH) {
		u->switch_at = co_line_now();
		u->switch_line = ev->redundancy.line;
	}
	return 0;
}

static void tpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	struct unit *u = user_data;

	if (num == 0U && u->produced + 1U < MAX_VALUES) {
		u->produced++;
		(void)co_od_set_u32(co_node_od(node), IDX_COUNTER, 0, u->produced,
				    CO_OD_WRITER_APP);
	}
}

static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	uint32_t v = 0U;

	if (num < N_SLAVES &&
	    co_od_get_u32(co_node_od(node), IDX_COUNTS, (uint8_t)(num + 1U), &v) == 0U &&
	    v < MAX_VALUES && delivered[num][v] < UINT8_MAX) {
		delivered[num][v]++;
	}
}

static void observe(const struct device *dev, struct can_frame *frame, void *user_data)
{
	bool probe = frame->id > PROBE_ID && frame->id <= PROBE_ID + N_UNITS;
	uint32_t fn = frame->id & 0x780U;
	uint32_t id = probe ? frame->id - PROBE_ID : frame->id & 0x7FU;
	atomic_val_t t = (atomic_val_t)((uint32_t)co_line_now() - (uint32_t)atomic_get(&armed_lo));

	if (id < 1U || id > N_UNITS) {
		return;
	}
	if (probe) {
		(void)atomic_cas(&first_probe[id - 1U], 0, t + 1);
	}
	if (probe || fn == 0x080U || fn == 0x180U || fn == 0x700U) {
		(void)atomic_cas(&first_any[id - 1U], 0, t + 1);
	}
}

static void fail(const char *what)
{
	printf("redundancy_bench: %s\n", what);
	exit(1);
}

static void unit_start(struct unit *u, int index)
{
	const struct co_od_def *def = index == 0 ? &thr_master_od_def : &thr_slave_od_def;
	void *ram = index == 0 ? (void *)&master_ram : (void *)&slave_ram[index - 1];
	static const char *const names[N_UNITS][CO_NODE_LINES] = {
		{"m-D", "m-R"}, {"n2-D", "n2-R"}, {"n3-D", "n3-R"}};
	char dev_name[16];
	int err = 0;

	for (int l = 0; l < (int)CO_NODE_LINES && err == 0; l++) {
		snprintf(dev_name, sizeof(dev_name), "can_virtual%d", 2 * index + l);
		u->can[l] = device_get_binding(dev_name);
		err = u->can[l] == NULL ? -ENODEV
					: co_line_init(&u->line[l], names[index][l], u->can[l]);
	}
	err = err ?: co_node_init(&u->node, u->name, &u->line[D], def, ram, u->id);
	err = err ?: co_node_attach_line(&u->node, CO_LINE_REDUNDANT, &u->line[R]);
	if (err == 0) {
		co_listener_init(&u->listener, u->name, CO_EV_BIT(CO_EV_REDUNDANCY), on_event, u);
		err = co_node_listener_add(&u->node, &u->listener);
	}
	if (index == 0) {
		co_rpdo_set_ind(&u->node, rpdo_ind, NULL);
	} else {
		co_tpdo_set_ind(&u->node, tpdo_ind, u);
	}
	for (int l = 0; l < (int)CO_NODE_LINES && err == 0; l++) {
		err = co_line_start(&u->line[l], stacks[index * CO_NODE_LINES + l],
				    K_THREAD_STACK_SIZEOF(stacks[0]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	err = err ?: co_node_start(&u->node);
	if (err != 0) {
		fail("set-up failed");
	}
}

/* Each node's probe on its active line, every PROBE_MS. */
static void prober(void *p1, void *p2, void *p3)
{
	for (;;) {
		for (int i = 0; i < N_UNITS; i++) {
			struct can_frame f = {.id = PROBE_ID + units[i].id, .dlc = 0};

			co_node_lock(&units[i].node);
			(void)co_node_send(&units[i].node, CO_ROUTE_ACTIVE, &f);
			co_node_unlock(&units[i].node);
		}
		k_msleep(PROBE_MS);
	}
}
static K_THREAD_STACK_DEFINE(prober_stack, 2048);
static struct k_thread prober_thread;

static bool all_on(int l, int64_t timeout_ms)
{
	int64_t end = k_uptime_get() + timeout_ms;

	do {
		bool all = true;

		for (int i = 0; i < N_UNITS; i++) {
			all = all && co_redundancy_get(&units[i].node, NULL, NULL) == l;
		}
		if (all) {
			return true;
		}
		k_msleep(1);
	} while (k_uptime_get() < end);
	return false;
}

static uint64_t switched_at(struct unit *u, int l)
{
	uint64_t at;

	co_node_lock(&u->node);
	at = u->switch_line == l ? u->switch_at : 0U;
	co_node_unlock(&u->node);
	return at;
}

static void nmt_send(uint8_t cs)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, 0}};

	co_node_lock(&MASTER->node);
	(void)co_node_send(&MASTER->node, CO_ROUTE_ACTIVE, &f);
	co_node_unlock(&MASTER->node);
}

/* --- Figures -------------------------------------------------------------------------------- */

static int cmp_u32(const void *a, const void *b)
{
	uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;

	return x < y ? -1 : (x > y ? 1 : 0);
}

/* One BENCH line: min/median/max of @p n samples [µs], against @p bound_ms (0: none). */
static void figure(const char *name, uint32_t *us, uint32_t n, uint32_t bound_ms, const char *extra)
{
	uint32_t within = 0U;

	if (n == 0U) {
		printf("BENCH {\"name\": \"%s\", \"ops\": 0, \"ns_per_op\": 0.0, \"samples\": "
		       "0%s}\n",
		       name, extra);
		return;
	}
	qsort(us, n, sizeof(us[0]), cmp_u32);
	for (uint32_t i = 0; i < n; i++) {
		within += bound_ms != 0U && us[i] <= bound_ms * 1000U;
	}
	printf("BENCH {\"name\": \"%s\", \"ops\": %u, \"ns_per_op\": %.1f, \"min_ms\": %.1f, "
	       "\"median_ms\": %.1f, \"max_ms\": %.1f",
	       name, n, us[n / 2U] * 1e3, us[0] / 1e3, us[n / 2U] / 1e3, us[n - 1U] / 1e3);
	if (bound_ms != 0U) {
		printf(", \"bound_ms\": %u, \"within_bound\": %u", bound_ms, within);
	}
	printf("%s}\n", extra);
}

static uint32_t s_event[MAX_CUTS * N_UNITS], s_active[MAX_CUTS * N_UNITS];
static uint32_t s_any[MAX_CUTS * N_UNITS], s_network[MAX_CUTS], s_back[MAX_CUTS * N_UNITS];

int main(void)
{
	const struct can_filter all = {.id = 0, .mask = 0};
	const struct device *observer = device_get_binding("can_virtual7");
	uint32_t n_event = 0U, n_active = 0U, n_any = 0U, n_net = 0U, n_back = 0U;
	uint32_t sent = 0U, got = 0U, twice = 0U, missing_switch = 0U;
	char extra[200];

	for (int bus = 0; bus < 2; bus++) {
		(void)can_virtual_bus_set_bit_timing(bus, true);
	}
	if (observer == NULL || can_virtual_get_bus(observer) != 1 || can_start(observer) != 0 ||
	    can_add_rx_filter(observer, observe, NULL, &all) < 0) {
		fail("observer set-up failed");
	}
	for (int i = 0; i < N_UNITS; i++) {
		unit_start(&units[i], i);
	}
	if (!all_on(D, 2000)) {
		fail("the default line did not become active");
	}
	(void)co_nmt_req(&MASTER->node, CO_NMT_CS_START);
	nmt_send(CO_NMT_CS_START);
	k_thread_create(&prober_thread, prober_stack, K_THREAD_STACK_SIZEOF(prober_stack), prober,
			NULL, NULL, NULL, 5, 0, K_NO_WAIT);
	k_msleep(300);

	for (uint32_t c = 0; c < cuts_arg; c++) {
		uint64_t cut, back, last = 0U;

		k_msleep(sys_rand32_get() % HB_MS);
		for (int i = 0; i < N_UNITS; i++) {
			atomic_set(&first_any[i], 0);
			atomic_set(&first_probe[i], 0);
		}
		cut = co_line_now();
		atomic_set(&armed_lo, (atomic_val_t)(uint32_t)cut);
		for (int i = 0; i < N_UNITS; i++) {
			(void)can_virtual_cut(units[i].can[D]);
		}
		if (!all_on(R, 2000)) {
			missing_switch++;
		}
		k_msleep(HOLD_MS);
		for (int i = 0; i < N_UNITS; i++) {
			uint64_t at = switched_at(&units[i], R);
			atomic_val_t p = atomic_get(&first_probe[i]);
			atomic_val_t a = atomic_get(&first_any[i]);

			if (at > cut) {
				s_event[n_event++] = (uint32_t)(at - cut);
				last = MAX(last, at);
			}
			if (p != 0) {
				s_active[n_active++] = (uint32_t)(p - 1);
			}
			if (a != 0) {
				s_any[n_any++] = (uint32_t)(a - 1);
			}
		}
		if (last != 0U) {
			s_network[n_net++] = (uint32_t)(last - cut);
		}
		back = co_line_now();
		for (int i = 0; i < N_UNITS; i++) {
			(void)can_virtual_restore(units[i].can[D]);
		}
		if (!all_on(D, 2000)) {
			missing_switch++;
		}
		k_msleep(3 * HB_MS);
		for (int i = 0; i < N_UNITS; i++) {
			uint64_t at = switched_at(&units[i], D);

			if (at >= back) {
				s_back[n_back++] = (uint32_t)(at - back);
			}
		}
		k_msleep(100);
	}

	nmt_send(CO_NMT_CS_ENTER_PRE_OPERATIONAL);
	k_msleep(200);
	for (int s = 0; s < N_SLAVES; s++) {
		co_node_lock(&units[s + 1].node);
		sent += units[s + 1].produced;
		co_node_unlock(&units[s + 1].node);
		co_node_lock(&MASTER->node);
		for (uint32_t v = 1; v < MAX_VALUES; v++) {
			got += delivered[s][v] > 0U;
			twice += delivered[s][v] > 1U ? delivered[s][v] - 1U : 0U;
		}
		co_node_unlock(&MASTER->node);
	}

	snprintf(extra, sizeof(extra), ", \"cuts\": %u, \"nodes\": %u, \"no_switch\": %u", cuts_arg,
		 N_UNITS, missing_switch);
	figure("redundancy.switch_event", s_event, n_event, BOUND_MS, extra);
	figure("redundancy.network_switched", s_network, n_net, BOUND_MS, extra);
	snprintf(extra, sizeof(extra), ", \"cuts\": %u, \"probe_every_ms\": %d", cuts_arg,
		 PROBE_MS);
	figure("redundancy.first_active_frame", s_active, n_active, BOUND_MS, extra);
	snprintf(extra, sizeof(extra),
		 ", \"cuts\": %u, \"what\": \"EMCY, heartbeat, PDO or probe\"", cuts_arg);
	figure("redundancy.first_frame_new_line", s_any, n_any, 0U, extra);
	snprintf(extra, sizeof(extra),
		 ", \"cuts\": %u, \"expected_ms\": \"%u-%u (three heartbeat cycles)\"", cuts_arg,
		 2U * HB_MS, 5U * HB_MS);
	figure("redundancy.switch_back", s_back, n_back, 0U, extra);
	printf("BENCH {\"name\": \"redundancy.pdo_values\", \"ops\": %u, \"ns_per_op\": 0.0, "
	       "\"sent\": %u, \"delivered\": %u, \"lost\": %u, \"duplicated\": %u, \"cuts\": %u, "
	       "\"pdo_period_ms\": 10}\n",
	       sent, sent, got, sent - got, twice, cuts_arg);
	printf("redundancy_bench: done\n");
	return 0;
}
