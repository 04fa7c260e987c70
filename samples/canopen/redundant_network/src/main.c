/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * redundant_network: four nodes on a default and a redundant CAN line (CiA 302-6).
 *
 * - Every node has two controllers, one on virtual bus 0 (its default line) and one on bus 1
 *   (its redundant line), two line threads and the redundancy service: it hears both lines,
 *   sends its heartbeat and process data on both, and chooses the active line from the
 *   heartbeats of the nodes in its 1016h, line by line.
 * - Node 1 is a simple NMT master: it supervises the heartbeats of nodes 2-4, starts them and
 *   consumes their counters (RPDO 1-3 into 2100h:01-03). Nodes 2-4 supervise the master's
 *   heartbeat and send a counter in TPDO 1 every 10 ms (event timer); the application adds 1
 *   to it just before each sample (the TPDO indication), so every frame carries a new value.
 * - The master's application checks each counter sequence: every value must reach it once,
 *   whichever line carried it (the stack drops the copy from the other line).
 * - The run cuts the default line (every controller of bus 0), restores it, cuts the redundant
 *   line and restores it, printing each line switch with the time since the cut or restore,
 *   then stops the slaves and prints, per slave, the values delivered, lost and duplicated.
 *
 * Everything the line threads report reaches the main thread through a message queue, so
 * nothing is printed from a line thread with a node's mutex held.
 */

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/util.h>

#include <can_socketcan.h>
#include <can_virtual.h>
#include <canopen/errctl.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/redundancy.h>

#include "cmdline.h"
#include "hb_options.h"
#include "link.h"
#include "posix_native_task.h"
#include "rdn_master_od.h"
#include "rdn_slave_od.h"

#define N_UNITS        4
#define N_SLAVES       (N_UNITS - 1)
#define MASTER_ID      1U
#define IDX_HB_CONS    0x1016U
#define IDX_HB_PROD    0x1017U
#define IDX_COUNTER    0x2000U /* slave: the counter TPDO 1 carries */
#define IDX_TPDO1_COMM 0x1800U
#define IDX_COUNTS     0x2100U /* master: sub n = the counter of node n + 1 */
/* Values a run may produce per slave (100 per second: almost three hours). */
#define MAX_VALUES     (1U << 20)
#define WAIT_MS        3000

/* --- Options -------------------------------------------------------------------------------- */

static struct {
	double settle_s;
	double cut_s;
	double pause_s;
	uint32_t pdo_ms;
} opt = {
	.settle_s = 0.5, .cut_s = 1.0, .pause_s = 1.0, .pdo_ms = 0U, /* 0: the slaves' 1800h:05 */
};

static void settle_found(char *argv, int offset)
{
	opt.settle_s = cmd_read_double_option("settle", &argv[offset], 0.0, 3600.0);
}

static void cut_found(char *argv, int offset)
{
	opt.cut_s = cmd_read_double_option("cut-for", &argv[offset], 0.01, 3600.0);
}

static void pause_found(char *argv, int offset)
{
	opt.pause_s = cmd_read_double_option("pause", &argv[offset], 0.01, 3600.0);
}

static void pdo_found(char *argv, int offset)
{
	opt.pdo_ms = (uint32_t)cmd_read_uint_option("pdo-ms", &argv[offset], 1U, 65535U);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "settle",
			.name = "seconds",
			.type = 'd',
			.call_when_found = settle_found,
			.descript =
				"run this long with both lines before the first cut (default 0.5)",
		},
		{
			.option = "cut-for",
			.name = "seconds",
			.type = 'd',
			.call_when_found = cut_found,
			.descript = "how long each line stays cut (default 1)",
		},
		{
			.option = "pause",
			.name = "seconds",
			.type = 'd',
			.call_when_found = pause_found,
			.descript = "how long both lines run after a restore (default 1)",
		},
		HB_OPTIONS("heartbeat period of every node, 1017h (default: the dictionaries', 50)",
			   "heartbeat consumer time of every 1016h entry (default: the "
			   "dictionaries', 125)"),
		{
			.option = "pdo-ms",
			.name = "ms",
			.type = 'u',
			.call_when_found = pdo_found,
			.descript = "period of each slave's counter TPDO, 1800h:05 (default: the "
				    "dictionary's, 10)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

static void check_options(void)
{
	/* 0: the dictionaries' 1017h and 1016h stay. */
	hb_options_check(0U, 0U);
}
NATIVE_TASK(check_options, PRE_BOOT_2, 21);

/* --- Nodes ---------------------------------------------------------------------------------- */

struct unit {
	const char *name;
	uint8_t id;
	struct co_line line[CO_NODE_LINES];
	struct co_node node;
	struct co_listener listener;
	const struct device *can[CO_NODE_LINES];
	/* Slave: the last counter value sampled into TPDO 1 (under the node's mutex). */
	uint32_t produced;
};

/* Master: what arrived of each slave's counter (under the master's mutex). */
struct sequence {
	uint32_t delivered;    /* distinct values */
	uint32_t duplicated;   /* values the application saw a second time */
	uint32_t out_of_order; /* new values that came after a higher one */
	uint32_t highest;
	uint8_t seen[MAX_VALUES / 8U];
};

static struct unit units[N_UNITS] = {
	{.name = "master", .id = MASTER_ID},
	{.name = "node 2", .id = 2},
	{.name = "node 3", .id = 3},
	{.name = "node 4", .id = 4},
};
static struct rdn_master_od_ram master_ram;
static struct rdn_slave_od_ram slave_ram[N_SLAVES];
static struct sequence seq[N_SLAVES];
static K_THREAD_STACK_ARRAY_DEFINE(stacks, N_UNITS *CO_NODE_LINES, CONFIG_CANOPEN_LINE_STACK_SIZE);

#define MASTER (&units[0])

/* What a line thread saw, as the main thread prints it. */
struct app_event {
	struct unit *unit;
	enum co_event_type type;
	uint8_t what; /* CO_EV_REDUNDANCY: enum co_rdn_event; CO_EV_HB: enum co_hb_event */
	uint8_t line;
	uint8_t node_id;
	enum co_nmt_state state;
	uint64_t time_us; /* the stack's time of the event */
	uint64_t seen_us; /* when the application heard of it (printed) */
};

K_MSGQ_DEFINE(events, sizeof(struct app_event), 256, 8);
static atomic_t events_lost;

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct app_event e = {.unit = user_data, .type = ev->type, .seen_us = co_line_now()};

	if (ev->type == CO_EV_REDUNDANCY) {
		e.what = ev->redundancy.what;
		e.line = ev->redundancy.line;
		e.node_id = ev->redundancy.node_id;
		e.time_us = ev->redundancy.time_us;
	} else {
		e.what = (uint8_t)ev->hb.event;
		e.node_id = ev->hb.node_id;
		e.state = ev->hb.state;
		e.time_us = co_node_time(node);
	}
	if (k_msgq_put(&events, &e, K_NO_WAIT) != 0) {
		atomic_inc(&events_lost);
	}
	return 0;
}

/* Slave: a new counter value for every sample of TPDO 1. */
static void tpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	struct unit *u = user_data;

	if (num == 0U && u->produced + 1U < MAX_VALUES) {
		u->produced++;
		(void)co_od_set_u32(co_node_od(node), IDX_COUNTER, 0, u->produced,
				    CO_OD_WRITER_APP);
	}
}

/* Master: RPDO n carried node n + 2's counter into 2100h:n+1. */
static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	struct sequence *s;
	uint32_t v = 0U;

	if (num >= N_SLAVES) {
		return;
	}
	s = &seq[num];
	(void)co_od_get_u32(co_node_od(node), IDX_COUNTS, (uint8_t)(num + 1U), &v);
	if (v == 0U || v >= MAX_VALUES) {
		return;
	}
	if ((s->seen[v / 8U] & BIT(v % 8U)) != 0U) {
		s->duplicated++;
		return;
	}
	s->seen[v / 8U] |= (uint8_t)BIT(v % 8U);
	s->delivered++;
	if (v < s->highest) {
		s->out_of_order++;
	} else {
		s->highest = v;
	}
}

static int set_u32(struct unit *u, uint16_t index, uint8_t sub, uint32_t v)
{
	int err;

	co_node_lock(&u->node);
	err = co_od_set_u32(co_node_od(&u->node), index, sub, v, CO_OD_WRITER_APP) == 0U ? 0 : -EIO;
	co_node_unlock(&u->node);
	return err;
}

static uint32_t get_u32(struct unit *u, uint16_t index, uint8_t sub)
{
	uint32_t v = 0U;

	co_node_lock(&u->node);
	(void)co_od_get_u32(co_node_od(&u->node), index, sub, &v);
	co_node_unlock(&u->node);
	return v;
}

/* The timings of the options, before the line choice starts counting. */
static int apply_timings(struct unit *u)
{
	int err = 0;
	uint8_t n = u == MASTER ? N_SLAVES : 1U;

	if (hb_opt.hb_ms != 0U) {
		co_node_lock(&u->node);
		if (co_od_set_u16(co_node_od(&u->node), IDX_HB_PROD, 0, (uint16_t)hb_opt.hb_ms,
				  CO_OD_WRITER_APP) != 0U) {
			err = -EIO;
		}
		co_node_unlock(&u->node);
	}
	for (uint8_t sub = 1; err == 0 && hb_opt.consumer_ms != 0U && sub <= n; sub++) {
		uint32_t e = get_u32(u, IDX_HB_CONS, sub);

		err = set_u32(u, IDX_HB_CONS, sub, (e & 0xFFFF0000U) | hb_opt.consumer_ms);
	}
	if (err == 0 && opt.pdo_ms != 0U && u != MASTER) {
		co_node_lock(&u->node);
		if (co_od_set_u16(co_node_od(&u->node), IDX_TPDO1_COMM, 5, (uint16_t)opt.pdo_ms,
				  CO_OD_WRITER_APP) != 0U) {
			err = -EIO;
		}
		co_node_unlock(&u->node);
	}
	return err;
}

static int unit_start(struct unit *u, int index)
{
	const struct co_od_def *def = u == MASTER ? &rdn_master_od_def : &rdn_slave_od_def;
	void *ram = u == MASTER ? (void *)&master_ram : (void *)&slave_ram[index - 1];
	static const char *const line_names[N_UNITS][CO_NODE_LINES] = {
		{"m-D", "m-R"}, {"n2-D", "n2-R"}, {"n3-D", "n3-R"}, {"n4-D", "n4-R"}};
	int err = 0;

	for (int l = 0; l < (int)CO_NODE_LINES && err == 0; l++) {
		char dev_name[16];

		/*
		 * Controller 2i is the node's default line, 2i + 1 its redundant line: SocketCAN
		 * when it has an interface (--can-if=0:vcan0 --can-if=1:vcan1 put every even
		 * controller on vcan0 and every odd one on vcan1, CONFIG_CAN_SOCKETCAN_IFNAMES),
		 * else virtual bus 0 and bus 1.
		 */
		(void)snprintf(dev_name, sizeof(dev_name), "can_socketcan%d", 2 * index + l);
		u->can[l] = device_get_binding(dev_name);
		if (u->can[l] == NULL || !device_is_ready(u->can[l])) {
			(void)snprintf(dev_name, sizeof(dev_name), "can_virtual%d", 2 * index + l);
			u->can[l] = device_get_binding(dev_name);
		}
		err = u->can[l] == NULL
			      ? -ENODEV
			      : co_line_init(&u->line[l], line_names[index][l], u->can[l]);
	}
	if (err == 0) {
		err = co_node_init(&u->node, u->name, &u->line[0], def, ram, u->id);
	}
	if (err == 0) {
		err = co_node_attach_line(&u->node, CO_LINE_REDUNDANT, &u->line[1]);
	}
	if (err == 0) {
		co_listener_init(&u->listener, u->name,
				 CO_EV_BIT(CO_EV_REDUNDANCY) |
					 (u == MASTER ? CO_EV_BIT(CO_EV_HB) : 0U),
				 on_event, u);
		err = co_node_listener_add(&u->node, &u->listener);
	}
	if (u == MASTER) {
		co_rpdo_set_ind(&u->node, rpdo_ind, NULL);
	} else {
		co_tpdo_set_ind(&u->node, tpdo_ind, u);
	}
	for (int l = 0; l < (int)CO_NODE_LINES && err == 0; l++) {
		k_thread_stack_t *stack = stacks[index * CO_NODE_LINES + l];

		err = co_line_start(&u->line[l], stack, K_THREAD_STACK_SIZEOF(stacks[0]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&u->node);
	}
	if (err == 0) {
		err = apply_timings(u);
	}
	if (err != 0) {
		printk("%s: start failed (%d)\n", u->name, err);
	}
	return err;
}

/* --- Printing ------------------------------------------------------------------------------- */

static const char *const line_word[CO_NODE_LINES] = {"default", "redundant"};

/* The fault the times are counted from. */
static struct {
	const char *what; /* "the cut", ... */
	uint64_t at_us;
	/* Per unit: when it switched after this fault, 0 for not yet. */
	uint64_t switched_us[N_UNITS];
} fault = {.what = "the start"};

/* "12.3" for @p to - @p from in ms, with a sign when negative. */
static const char *ms(char *buf, size_t size, uint64_t from_us, uint64_t to_us)
{
	bool neg = to_us < from_us;
	uint64_t d = neg ? from_us - to_us : to_us - from_us;

	(void)snprintf(buf, size, "%s%u.%u", neg ? "-" : "", (unsigned int)(d / 1000U),
		       (unsigned int)(d % 1000U / 100U));
	return buf;
}

static void print_event(const struct app_event *e)
{
	char t[24];
	const char *l = e->line < CO_NODE_LINES ? line_word[e->line] : "?";

	/*
	 * Counted from when the listener ran: the stack's time of an event that a frame caused
	 * is the frame's receive stamp, and the virtual bus stamps the frames that a restored
	 * controller had queued with the (past) time they would have started at.
	 */
	ms(t, sizeof(t), fault.at_us, e->seen_us);
	if (e->type == CO_EV_HB) {
		if (e->what == CO_HB_EV_LOST) {
			printk("%s: node %u heartbeat lost on both lines, %s ms after %s\n",
			       e->unit->name, e->node_id, t, fault.what);
		} else if (e->what == CO_HB_EV_RECOVERED) {
			printk("%s: node %u heartbeat back (%s)\n", e->unit->name, e->node_id,
			       co_nmt_state_str(e->state));
		}
		return;
	}
	switch (e->what) {
	case CO_RDN_EV_SWITCH:
		fault.switched_us[e->unit - units] = e->seen_us;
		printk("%s: SWITCH to line %u (%s) %s ms after %s\n", e->unit->name, e->line, l, t,
		       fault.what);
		break;
	case CO_RDN_EV_HB_ERROR:
		printk("%s: heartbeat of node %u lost on line %u (%s), %s ms after %s\n",
		       e->unit->name, e->node_id, e->line, l, t, fault.what);
		break;
	case CO_RDN_EV_HB_OK:
		printk("%s: heartbeat of node %u back on line %u (%s), %s ms after %s\n",
		       e->unit->name, e->node_id, e->line, l, t, fault.what);
		break;
	case CO_RDN_EV_DEFAULT_LINE_OK:
		printk("%s: default line OK (three heartbeats of every supervised node)\n",
		       e->unit->name);
		break;
	case CO_RDN_EV_EVAL_TIMEOUT:
		printk("%s: evaluation timer ended without the default line\n", e->unit->name);
		break;
	case CO_RDN_EV_VETOED:
		printk("%s: switch to line %u vetoed\n", e->unit->name, e->line);
		break;
	case CO_RDN_EV_TPDO_FAILED:
		printk("%s: TPDO 1 failed too often: heartbeat stopped, %s ms after %s\n",
		       e->unit->name, t, fault.what);
		break;
	case CO_RDN_EV_TPDO_OK:
		printk("%s: TPDO 1 good again: heartbeat resumed, %s ms after %s\n", e->unit->name,
		       t, fault.what);
		break;
	default:
		break;
	}
}

/* Print what the line threads reported until @p until_ms (uptime). */
static void run_until(int64_t until_ms)
{
	struct app_event e;

	while (k_msgq_get(&events, &e, K_TIMEOUT_ABS_MS(until_ms)) == 0) {
		print_event(&e);
	}
	if (atomic_set(&events_lost, 0) != 0) {
		printk("redundant_network: events lost (queue full)\n");
	}
}

static void run_for(double seconds)
{
	run_until(k_uptime_get() + (int64_t)(seconds * 1000.0));
}

/* Print events until every node's line choice is in @p want, or a timeout. */
static bool wait_state(enum co_rdn_state want)
{
	int64_t end = k_uptime_get() + WAIT_MS;

	for (;;) {
		bool all = true;

		for (int i = 0; i < N_UNITS; i++) {
			enum co_rdn_state st;

			(void)co_redundancy_get(&units[i].node, &st, NULL);
			all = all && st == want;
		}
		if (all) {
			return true;
		}
		if (k_uptime_get() >= end) {
			return false;
		}
		run_until(MIN(k_uptime_get() + 10, end));
	}
}

/* --- The run -------------------------------------------------------------------------------- */

/* Switches that came before the heartbeats could have made them due (restore). */
static int early_switches;

static void nmt_send(uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, id}};

	/* The master's commands go on its active line, as the CiA 302 manager's do. */
	co_node_lock(&MASTER->node);
	(void)co_node_send(&MASTER->node, CO_ROUTE_ACTIVE, &f);
	co_node_unlock(&MASTER->node);
}

/* The SocketCAN interface of line @p l, NULL when it is on the virtual bus. */
static const char *line_ifname(int l)
{
	return can_socketcan_ifname(units[0].can[l]);
}

/* "bus 0" or "vcan0": where line @p l is. */
static const char *line_where(int l, char *buf, size_t size)
{
	const char *ifname = line_ifname(l);

	if (ifname != NULL) {
		return ifname;
	}
	(void)snprintf(buf, size, "bus %d", can_virtual_get_bus(units[0].can[l]));
	return buf;
}

/*
 * Cut or restore line @p l of every node: every controller of virtual bus @p l, or the
 * SocketCAN interface itself (down/up as ip link set does: every socket on it, ours and any
 * other program's, loses the bus; needs root, e.g. inside scripts/vcan-vm).
 */
static int line_fault(int l, bool cut, const char *what)
{
	const char *ifname = line_ifname(l);
	char where[16];

	memset(fault.switched_us, 0, sizeof(fault.switched_us));
	fault.what = what;
	if (ifname == NULL) {
		fault.at_us = co_line_now();
		printk("redundant_network: %s %s line (%s)\n",
		       cut ? "cutting the" : "restoring the", line_word[l],
		       line_where(l, where, sizeof(where)));
		for (int i = 0; i < N_UNITS; i++) {
			(void)(cut ? can_virtual_cut(units[i].can[l])
				   : can_virtual_restore(units[i].can[l]));
		}
		return 0;
	}

	int rc = link_set(ifname, !cut);

	fault.at_us = co_line_now();
	printk("redundant_network: %s %s line (%s, as ip link set %s %s)\n",
	       cut ? "cutting the" : "restoring the", line_word[l], ifname, ifname,
	       cut ? "down" : "up");
	if (rc != 0) {
		printk("redundant_network: FAILED: link %s %s: %d\n", ifname, cut ? "down" : "up",
		       rc);
		return 1;
	}
	return 0;
}

/*
 * After a fault: every node must be on @p want_line. @p min_ms..@p max_ms is when a switch is
 * due (0..0: none is); a switch outside it is reported as early or late.
 */
static int check_switches(uint8_t want_line, uint32_t min_ms, uint32_t max_ms)
{
	int missing = 0;
	int switched = 0;
	char t[24];

	for (int i = 0; i < N_UNITS; i++) {
		uint8_t active = co_redundancy_get(&units[i].node, NULL, NULL);
		uint64_t at = fault.switched_us[i];
		uint64_t d = at > fault.at_us ? at - fault.at_us : 0U;

		if (active != want_line) {
			printk("%s: still on line %u after %s\n", units[i].name, active,
			       fault.what);
			missing++;
			continue;
		}
		if (at == 0U) {
			continue;
		}
		switched++;
		ms(t, sizeof(t), fault.at_us, at);
		printk("redundant_network: %s switched %s ms after %s (due %u-%u ms)%s\n",
		       units[i].name, t, fault.what, min_ms, max_ms,
		       d < min_ms * 1000U ? ": EARLY" : (d > max_ms * 1000U ? ": LATE" : ""));
		if (d < min_ms * 1000U) {
			early_switches++;
		}
	}
	if (switched == 0 && missing == 0) {
		printk("redundant_network: no node switched after %s (line %u stays active)\n",
		       fault.what, want_line);
	}
	return missing;
}

static bool all_slaves_operational(void)
{
	for (uint8_t id = 2; id <= N_UNITS; id++) {
		enum co_nmt_state st = CO_NMT_INITIALISING;

		if (co_hb_get_remote_state(&MASTER->node, id, &st) != 0 ||
		    st != CO_NMT_OPERATIONAL) {
			return false;
		}
	}
	return true;
}

/* Whether the master holds every value the slaves produced (nothing left on its way). */
static bool all_values_in(void)
{
	bool in = true;

	for (int i = 0; i < N_SLAVES; i++) {
		struct unit *u = &units[i + 1];
		uint32_t produced;

		co_node_lock(&u->node);
		produced = u->produced;
		co_node_unlock(&u->node);
		co_node_lock(&MASTER->node);
		in = in && seq[i].delivered >= produced;
		co_node_unlock(&MASTER->node);
	}
	return in;
}

static int summary(void)
{
	int lost_total = 0;
	int dup_total = 0;

	printk("\n node  sent  delivered  lost  duplicated  out of order\n");
	for (int i = 0; i < N_SLAVES; i++) {
		struct unit *u = &units[i + 1];
		uint32_t sent;
		struct sequence s;

		co_node_lock(&u->node);
		sent = u->produced;
		co_node_unlock(&u->node);
		co_node_lock(&MASTER->node);
		s.delivered = seq[i].delivered;
		s.duplicated = seq[i].duplicated;
		s.out_of_order = seq[i].out_of_order;
		co_node_unlock(&MASTER->node);
		printk(" %4u  %4u  %9u  %4u  %10u  %12u\n", u->id, sent, s.delivered,
		       sent - s.delivered, s.duplicated, s.out_of_order);
		lost_total += (int)(sent - s.delivered);
		dup_total += (int)s.duplicated;
	}
	for (int i = 0; i < N_SLAVES; i++) {
		struct unit *u = &units[i + 1];

		co_node_lock(&MASTER->node);
		printk("redundant_network: node %u: %u values delivered, lost %u, duplicated %u\n",
		       u->id, seq[i].delivered, u->produced - seq[i].delivered, seq[i].duplicated);
		co_node_unlock(&MASTER->node);
	}
	printk("redundant_network: the master dropped %u copies from the other line\n",
	       co_pdo_rx_duplicates(&MASTER->node));
	if (dup_total != 0) {
		printk("redundant_network: KNOWN PROBLEM: %d values reached the application twice: "
		       "copies a late line thread delivered after the duplicate window (a loaded "
		       "host, doc/redundancy.md)\n",
		       dup_total);
	}
	if (early_switches != 0) {
		printk("redundant_network: KNOWN PROBLEM: %d switches back came before three "
		       "heartbeat cycles: the heartbeats queued during the cut count "
		       "(doc/redundancy.md)\n",
		       early_switches);
	}
	for (int i = 0; i < N_UNITS; i++) {
		for (int l = 0; l < (int)CO_NODE_LINES; l++) {
			struct co_line_stats st;

			co_line_get_stats(&units[i].line[l], &st);
			if (st.tx_dropped != 0U || st.tx_queue_max > 8U) {
				printk("redundant_network: %s line %d: TX queue up to %u frames, "
				       "%u dropped\n",
				       units[i].name, l, st.tx_queue_max, st.tx_dropped);
			}
		}
	}
	return lost_total != 0 ? 1 : 0;
}

int main(void)
{
	uint32_t hb_ms, consumer_ms, bound_ms;
	uint16_t hb16 = 0U;
	uint16_t pdo16 = 0U;
	int failures = 0;
	char w0[16];
	char w1[16];

	for (int i = 0; i < N_UNITS; i++) {
		if (unit_start(&units[i], i) != 0) {
			return 1;
		}
	}
	co_node_lock(&MASTER->node);
	(void)co_od_get_u16(co_node_od(&MASTER->node), IDX_HB_PROD, 0, &hb16);
	co_node_unlock(&MASTER->node);
	hb_ms = hb16;
	consumer_ms = get_u32(MASTER, IDX_HB_CONS, 1) & 0xFFFFU;
	bound_ms = consumer_ms + hb_ms;
	printk("redundant_network: master (node 1) and nodes 2-4 on two lines each: %s/%s on %s "
	       "(default), %s/%s on %s (redundant)\n",
	       units[0].can[0]->name, units[3].can[0]->name, line_where(0, w0, sizeof(w0)),
	       units[0].can[1]->name, units[3].can[1]->name, line_where(1, w1, sizeof(w1)));
	printk("redundant_network: heartbeat %u ms, consumer time %u ms: a switch is due within "
	       "%u ms of a cut\n",
	       hb_ms, consumer_ms, bound_ms);

	if (!wait_state(CO_RDN_DEFAULT_ACTIVE)) {
		printk("redundant_network: FAILED: the default line did not become active\n");
		return 1;
	}
	printk("redundant_network: every node on the default line\n");

	/* A simple NMT master: itself first (so that it takes the first values), then all. */
	(void)co_nmt_req(&MASTER->node, CO_NMT_CS_START);
	nmt_send(CO_NMT_CS_START, 0);
	printk("master: NMT start all nodes\n");
	for (int64_t end = k_uptime_get() + WAIT_MS; !all_slaves_operational();) {
		if (k_uptime_get() >= end) {
			printk("redundant_network: FAILED: the slaves did not start\n");
			return 1;
		}
		run_until(k_uptime_get() + 10);
	}
	co_node_lock(&units[1].node);
	(void)co_od_get_u16(co_node_od(&units[1].node), IDX_TPDO1_COMM, 5, &pdo16);
	co_node_unlock(&units[1].node);
	printk("master: nodes 2-4 OPERATIONAL, counters every %u ms on both lines\n", pdo16);
	run_for(opt.settle_s);

	/*
	 * The last heartbeat before a cut came at most one period earlier, so the first node's
	 * loss is due within the consumer time; the bound allows one more period. Back on the
	 * default line after three heartbeat cycles there, counted half a consumer time apart
	 * (the heartbeats a cut controller held back count once): two to five periods after a
	 * restore.
	 */
	failures += line_fault(CO_LINE_DEFAULT, true, "the cut");
	run_for(opt.cut_s);
	failures += check_switches(CO_LINE_REDUNDANT, consumer_ms - hb_ms, bound_ms);

	failures += line_fault(CO_LINE_DEFAULT, false, "the restore");
	run_for(opt.pause_s);
	failures += check_switches(CO_LINE_DEFAULT, 2U * hb_ms, 5U * hb_ms);

	failures += line_fault(CO_LINE_REDUNDANT, true, "the cut of the redundant line");
	run_for(opt.cut_s);
	failures += check_switches(CO_LINE_DEFAULT, 0U, 0U);

	failures += line_fault(CO_LINE_REDUNDANT, false, "the restore of the redundant line");
	run_for(opt.pause_s);
	failures += check_switches(CO_LINE_DEFAULT, 0U, 0U);

	/* The slaves stop sending; what is on its way arrives, then the counts. */
	nmt_send(CO_NMT_CS_ENTER_PRE_OPERATIONAL, 0);
	printk("master: NMT pre-operational all nodes\n");
	/*
	 * A loaded host can hold the last frames for hundreds of milliseconds (the VM starved):
	 * wait until they are in, or 2 s, rather than a fixed time that counts them as lost.
	 */
	run_for(0.2);
	for (int i = 0; i < 36 && !all_values_in(); i++) {
		run_for(0.05);
	}
	failures += summary();
	/* Lost values and missing switches fail the run; the known problems are printed above. */
	printk("redundant_network: %s\n", failures == 0 ? "done" : "FAILED");
	return failures == 0 ? 0 : 1;
}
