/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * flying_master: two manager-capable nodes (node 3, priority 0, and node 2, priority 1) and
 * three slaves (10, 11, 12) on one virtual CAN bus (CiA 302 §5.5, doc/flying-master.md).
 * Node 3 wins the negotiation and boots the network; then its controller is cut off the bus
 * (the active master is killed). Node 2 loses its heartbeat, resets the network, negotiates
 * alone, becomes the active master and boots the slaves again. The sample prints who is master
 * and how long the network ran without one.
 *
 * Controllers: 0 = node 3, 1 = node 2, 2 = the slaves (three nodes sharing one line, which
 * delivers their frames to each other): can_virtual<n>, or can_socketcan<n> when --can-if=0:<if>
 * names an interface (all three on it, CONFIG_CAN_SOCKETCAN_IFNAMES). --nodes runs only some of
 * the nodes, so that another process (or a python-canopen peer) can be the rest of the network
 * and the active master can be killed as a process.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>

#include <can_socketcan.h>
#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>

#include "cmdline.h"
#include "fm_manager_od.h"
#include "fm_slave_od.h"
#include "posix_native_task.h"
#include "hb_options.h"
#include "sample_common.h"

#define N_MGR   2
#define N_SLAVE 3

/* 1F90h defaults: master timeout 100 ms, delay 500 ms, slots 1500/10 ms. */
#define BOUND_MS(prio, id) (hb_opt.consumer_ms + 500U + 100U + (prio) * 1500U + (id) * 10U)

static const uint8_t mgr_id[N_MGR] = {3, 2};
static const uint8_t mgr_prio[N_MGR] = {0, 1};
static const uint8_t slave_id[N_SLAVE] = {10, 11, 12};

/*
 * Options: --hb (1017h of every node), --hb-consumer (the candidates' 1016h entry for each
 * other), --nodes (which of the five nodes run here; bit i: mgr[i], bit 2 + s: slave[s]).
 */
static struct {
	uint32_t nodes;
} opt = {.nodes = 0x1FU};

/* The bit of node @p id in opt.nodes, 0 if it is none of the sample's nodes. */
static uint32_t node_bit(unsigned long id)
{
	for (int i = 0; i < N_MGR; i++) {
		if (mgr_id[i] == id) {
			return BIT(i);
		}
	}
	for (int s = 0; s < N_SLAVE; s++) {
		if (slave_id[s] == id) {
			return BIT(N_MGR + s);
		}
	}
	return 0U;
}

static void nodes_found(char *argv, int offset)
{
	const char *str = &argv[offset];
	const char *p = str;
	uint32_t nodes = 0U;

	while (*p != '\0') {
		char *end;
		unsigned long id = strtoul(p, &end, 10);
		uint32_t bit = (end == p) ? 0U : node_bit(id);

		if (bit == 0U || (*end != ',' && *end != '\0')) {
			cmd_option_error("nodes", str,
					 "a comma-separated list of 3, 2, 10, 11, 12");
		}
		nodes |= bit;
		p = (*end == ',') ? end + 1 : end;
	}
	if (nodes == 0U) {
		cmd_option_error("nodes", str, "names no node");
	}
	opt.nodes = nodes;
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		HB_OPTIONS("heartbeat period of every node, 1017h (default 100)",
			   "consumer time of the candidates' 1016h entry for each other "
			   "(default 300)"),
		{
			.option = "nodes",
			.name = "id,id,...",
			.type = 's',
			.call_when_found = nodes_found,
			.descript = "run only these of the nodes 3, 2, 10, 11, 12 (default all); "
				    "without both candidates nothing is killed",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

static void check_options(void)
{
	hb_options_check(100U, 300U);
}
NATIVE_TASK(check_options, PRE_BOOT_2, 0);

static bool runs_mgr(int i)
{
	return (opt.nodes & BIT(i)) != 0U;
}

static bool runs_slave(int s)
{
	return (opt.nodes & BIT(N_MGR + s)) != 0U;
}

static struct co_line lines[3];
static struct co_node mgr[N_MGR];
static struct fm_manager_od_ram mgr_ram[N_MGR];
static struct co_node slave[N_SLAVE];
static struct fm_slave_od_ram slave_ram[N_SLAVE];
static struct co_listener listener[N_MGR];

static K_THREAD_STACK_ARRAY_DEFINE(stacks, 3, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(startup_done, 0, N_MGR);
static K_SEM_DEFINE(new_master, 0, N_MGR);
static int64_t active_at[N_MGR];
static int startup_of = -1;

static void put(struct co_od *od, uint16_t index, uint8_t sub, uint32_t v, size_t len)
{
	uint8_t buf[4];

	sys_put_le32(v, buf);
	(void)co_od_write(od, index, sub, buf, len, CO_OD_WRITER_STORAGE);
}

/* The candidates' configuration, applied at every reset as a storage module would. */
static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	int i = (int)(intptr_t)user_data;
	uint8_t other = mgr_id[1 - i];

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	put(od, 0x1F80, 0, 0x21, 4); /* NMT master, flying master */
	put(od, 0x1F90, 3, mgr_prio[i], 2);
	put(od, 0x1017, 0, hb_opt.hb_ms, 2);
	put(od, 0x1029, 1, 1, 1); /* the manager handles lost heartbeats, not 1029h */
	/* The other candidate is a slave of whoever wins; its heartbeat is watched. */
	put(od, 0x1016, 1, ((uint32_t)other << 16) | hb_opt.consumer_ms, 4);
	put(od, 0x1F81, other, 0x05, 4);
	for (int s = 0; s < N_SLAVE; s++) {
		put(od, 0x1F81, slave_id[s], 0x05, 4); /* slave, boot */
	}
}

/* The slaves' heartbeat, so that a peer on the bus sees their state. */
static void slave_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	ARG_UNUSED(user_data);
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		put(od, 0x1017, 0, hb_opt.hb_ms, 2);
	}
}

static int fm_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	int i = (int)(intptr_t)user_data;
	uint8_t me = co_node_id(node);

	switch (ev->fm.what) {
	case CO_MGR_FM_EV_ACTIVE:
		printk("node %u: active master (priority %u)\n", me, ev->fm.priority);
		active_at[i] = k_uptime_get();
		k_sem_give(&new_master);
		break;
	case CO_MGR_FM_EV_MASTER:
		printk("node %u: node %u is the active master (priority %u)\n", me,
		       ev->fm.master_id, ev->fm.priority);
		break;
	case CO_MGR_FM_EV_LOST:
		printk("node %u: active master node %u lost: Reset Communication, negotiation\n",
		       me, ev->fm.master_id);
		break;
	default:
		break;
	}
	return 0;
}

static void startup_ind(struct co_node *node, enum co_mgr_startup result,
			const struct co_mgr_boot_error *err, void *user_data)
{
	ARG_UNUSED(node);
	ARG_UNUSED(err);
	if (result == CO_MGR_STARTUP_DONE) {
		startup_of = (int)(intptr_t)user_data;
		k_sem_give(&startup_done);
	}
}

/*
 * After the startup the winner's individual starts are still queued: give them a moment. Only
 * the slaves of this process are listed (with --nodes the others run elsewhere).
 */
static void print_network(int i)
{
	char list[32] = "";
	size_t n = 0;

	k_sleep(K_MSEC(200));
	for (int s = 0; s < N_SLAVE; s++) {
		if (runs_slave(s) && co_nmt_get_state(&slave[s]) == CO_NMT_OPERATIONAL) {
			n += (size_t)snprintf(&list[n], sizeof(list) - n, " %u", slave_id[s]);
		}
	}
	if ((opt.nodes >> N_MGR) == 0U) {
		printk("manager node %u: NMT startup done (no slave in this process)\n", mgr_id[i]);
		return;
	}
	printk("manager node %u: NMT startup done, slaves%s Operational\n", mgr_id[i], list);
}

/*
 * Kill the active master: its controller leaves the bus. On the virtual bus the controller is
 * cut; on SocketCAN it is stopped (it sends and receives nothing more), the interface stays up
 * for everyone else.
 */
static int kill_master(void)
{
	const struct device *dev = sample_line_device(0);

	if (can_socketcan_ifname(dev) != NULL) {
		return can_stop(dev);
	}
	return can_virtual_cut(dev);
}

/* Line 0 serves node 3, line 1 node 2, line 2 the slaves: only the lines in use here. */
static bool line_used(int l)
{
	return l < N_MGR ? runs_mgr(l) : (opt.nodes >> N_MGR) != 0U;
}

static int setup(void)
{
	int err = 0;

	for (int l = 0; l < 3 && err == 0; l++) {
		const struct device *dev = sample_line_device(l);
		char name[8] = "line0";

		name[4] = (char)('0' + l);
		if (line_used(l)) {
			err = dev == NULL ? -ENODEV : co_line_init(&lines[l], name, dev);
		}
	}
	for (int i = 0; i < N_MGR && err == 0; i++) {
		if (!runs_mgr(i)) {
			continue;
		}
		err = co_node_init(&mgr[i], i == 0 ? "mgr3" : "mgr2", &lines[i], &fm_manager_od_def,
				   &mgr_ram[i], mgr_id[i]);
		if (err == 0) {
			co_od_set_restore_cb(co_node_od(&mgr[i]), mgr_restore, (void *)(intptr_t)i);
			co_mgr_set_startup_ind(&mgr[i], startup_ind, (void *)(intptr_t)i);
			co_listener_init(&listener[i], "sample", CO_EV_BIT(CO_EV_FM), fm_event,
					 (void *)(intptr_t)i);
			err = co_node_listener_add(&mgr[i], &listener[i]);
		}
	}
	for (int s = 0; s < N_SLAVE && err == 0; s++) {
		static const char *const names[] = {"s10", "s11", "s12"};

		if (runs_slave(s)) {
			err = co_node_init(&slave[s], names[s], &lines[2], &fm_slave_od_def,
					   &slave_ram[s], slave_id[s]);
		}
		if (err == 0 && runs_slave(s)) {
			co_od_set_restore_cb(co_node_od(&slave[s]), slave_restore, NULL);
		}
	}
	for (int l = 0; l < 3 && err == 0; l++) {
		if (line_used(l)) {
			err = co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
					    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
		}
	}
	for (int s = 0; s < N_SLAVE && err == 0; s++) {
		err = runs_slave(s) ? co_node_start(&slave[s]) : 0;
	}
	for (int i = 0; i < N_MGR && err == 0; i++) {
		err = runs_mgr(i) ? co_node_start(&mgr[i]) : 0;
	}
	return err;
}

/* Where the nodes are: "can_virtual0..2" or the interface. */
static const char *where(void)
{
	for (int l = 0; l < 3; l++) {
		const char *ifname =
			line_used(l) ? can_socketcan_ifname(sample_line_device(l)) : NULL;

		if (ifname != NULL) {
			return ifname;
		}
	}
	return "the virtual bus";
}

/* Part of the network (--nodes): report every startup this process's candidate runs. */
static void run_part(void)
{
	char list[40] = "";
	size_t n = 0;

	for (int i = 0; i < N_MGR + N_SLAVE; i++) {
		if ((opt.nodes & BIT(i)) != 0U) {
			n += (size_t)snprintf(&list[n], sizeof(list) - n, " %u",
					      i < N_MGR ? mgr_id[i] : slave_id[i - N_MGR]);
		}
	}
	printk("flying_master: nodes%s on %s (no kill here: the rest of the network is "
	       "elsewhere)\n",
	       list, where());
	for (;;) {
		(void)k_sem_take(&startup_done, K_FOREVER);
		print_network(startup_of);
	}
}

int main(void)
{
	int64_t killed;
	int err = setup();

	if (err != 0) {
		printk("flying_master: set-up failed (%d)\n", err);
		return 1;
	}
	sample_print_stats_on_exit("flying_master",
				   &lines[line_used(2) ? 2 : (runs_mgr(0) ? 0 : 1)]);
	if (!runs_mgr(0) || !runs_mgr(1)) {
		run_part();
		return 0;
	}
	printk("flying_master: nodes 3 2 10 11 12 on %s\n", where());

	/* 1. Node 3 (priority 0) wins and boots the network. */
	if (k_sem_take(&startup_done, K_SECONDS(20)) != 0 || startup_of != 0) {
		printk("flying_master: node 3 did not become the master\n");
		return 1;
	}
	print_network(0);
	k_sleep(K_SECONDS(1));

	/* 2. Kill the active master: its controller leaves the bus. */
	k_sem_reset(&new_master);
	killed = k_uptime_get();
	printk("killing the active master (node %u)\n", mgr_id[0]);
	err = kill_master();
	if (err != 0) {
		printk("flying_master: cut failed (%d)\n", err);
		return 1;
	}
	/* 3. Node 2 takes over. */
	if (k_sem_take(&new_master, K_SECONDS(20)) != 0 || active_at[1] < killed) {
		printk("flying_master: nobody took over\n");
		return 1;
	}
	printk("network without a master for %lld ms (bound %u ms from the last heartbeat)\n",
	       (long long)(active_at[1] - killed), BOUND_MS(mgr_prio[1], mgr_id[1]));
	if (k_sem_take(&startup_done, K_SECONDS(20)) != 0 || startup_of != 1) {
		printk("flying_master: node 2's startup did not end\n");
		return 1;
	}
	print_network(1);
	printk("flying_master: done\n");
	for (;;) {
		k_sleep(K_SECONDS(1));
	}
	return 0;
}
