/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The SDO manager's interop image: the manager (node 01h, 1F80h = 01h) on line 0 and a slave
 * (node 0Ah, one free server entry 1201h, 2000h = 12345678h) on line 1, with the dictionaries
 * of tests/canopen/mgr_sdom. Run with --can-if=0:vcan0 --can-if=1:vcan0 both are sockets on
 * the same interface; the SDO requesting device is the python test (pytest/).
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/line.h>
#include <canopen/node.h>

#include "sample_common.h"
#include "sdom_mgr_od.h"
#include "sdom_slave_od.h"

LOG_MODULE_REGISTER(interop_sdom, LOG_LEVEL_INF);

#define MGR_ID   0x01U
#define SLAVE_ID 0x0AU

static struct co_line lines[2];
static struct co_node mgr;
static struct co_node slave;
static struct sdom_mgr_od_ram mgr_ram;
static struct sdom_slave_od_ram slave_ram;
K_THREAD_STACK_ARRAY_DEFINE(stacks, 2, 4096);

/* The manager's 1F80h at every Reset Communication: it is the NMT master and SDO manager. */
static void mgr_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	uint8_t b[4];

	ARG_UNUSED(user_data);
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	sys_put_le32(0x01U, b);
	(void)co_od_write(od, 0x1F80, 0, b, 4, CO_OD_WRITER_STORAGE);
}

static int bring_up(unsigned int n, struct co_node *node, const char *name,
		    const struct co_od_def *def, void *ram, uint8_t id)
{
	const struct device *can = sample_line_device(n);
	char lname[8] = "line0";
	int err;

	if (can == NULL) {
		return -ENODEV;
	}
	lname[4] = (char)('0' + n);
	err = co_line_init(&lines[n], lname, can);
	if (err == 0) {
		err = co_node_init(node, name, &lines[n], def, ram, id);
	}
	if (err == 0 && node == &mgr) {
		err = co_od_set_restore_cb(co_node_od(node), mgr_restore, NULL);
	}
	if (err == 0) {
		err = co_line_start(&lines[n], stacks[n], K_THREAD_STACK_SIZEOF(stacks[n]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	return err;
}

int main(void)
{
	int err = bring_up(1, &slave, "slave", &sdom_slave_od_def, &slave_ram, SLAVE_ID);

	if (err == 0) {
		err = co_node_start(&slave);
	}
	if (err == 0) {
		err = bring_up(0, &mgr, "mgr", &sdom_mgr_od_def, &mgr_ram, MGR_ID);
	}
	if (err == 0) {
		err = co_node_start(&mgr);
	}
	if (err != 0) {
		LOG_ERR("start failed (%d)", err);
		return 1;
	}
	sample_print_stats_on_exit("sdom manager", &lines[0]);
	printk("sdom: manager %u and slave %u up\n", MGR_ID, SLAVE_ID);
	for (;;) {
		k_sleep(K_SECONDS(1));
	}
	return 0;
}
