/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * firmware_update: a manager (node 1) and an updatable slave (node 2) on one line, in one
 * process (CiA 302 §9, doc/pgm.md).
 *
 * 1. The slave's flash holds program 1 (date 15000, time 3600000) in slot 0; the manager
 *    expects program 2 (1F53h/1F54h: date 15100, time 7200000) and may update it (1F81h
 *    bits 5 and 6). At boot it stops the slave's program, downloads program 2 by block SDO,
 *    starts it; the slave verifies it, switches and restarts; the manager reads 1F52h again.
 * 2. The application then downloads a corrupted image through its own SDO client: the slave
 *    refuses it (abort 06060000h, 1F57h says why) and keeps running program 2.
 *
 * The line is can_socketcan0 when it has an interface (--can-if=0:vcan0), else can_virtual0.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/pgm.h>
#include <canopen/sdo_cli.h>

#include "fw_manager_od.h"
#include "fw_slave_od.h"
#include "pgm_offer.h"
#include "sample_common.h"

#define MANAGER  1U
#define SLAVE    2U
#define BODY     (16U * 1024U)
#define SLOT     (BODY + 64U)
#define OLD_DATE 15000U
#define OLD_TIME 3600000U
#define NEW_DATE 15100U
#define NEW_TIME 7200000U

static struct co_line line;
static struct co_node mgr;
static struct fw_manager_od_ram mgr_ram;
static struct co_node slave;
static struct fw_slave_od_ram slave_ram;
static K_THREAD_STACK_DEFINE(line_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

static struct co_pgm_flash_ram flash;
static uint8_t flash_mem[2 * SLOT];
static uint8_t img_old[CO_PGM_HDR_SIZE + BODY];
static uint8_t img_new[CO_PGM_HDR_SIZE + BODY];
static uint8_t img_bad[CO_PGM_HDR_SIZE + BODY];
static struct pgm_offer offer = {.slave = SLAVE,
				 .image = img_new,
				 .len = sizeof(img_new),
				 .date = NEW_DATE,
				 .time = NEW_TIME};

static K_SEM_DEFINE(booted, 0, 1);
static uint8_t boot_status;

static void boot_ind(struct co_node *node, uint8_t id, uint8_t status,
		     const struct co_mgr_boot_error *err, void *user_data)
{
	if (id == SLAVE) {
		boot_status = status;
		k_sem_give(&booted);
	}
}

static void pgm_ind(struct co_node *node, enum co_pgm_event ev, const struct co_pgm_image_info *img,
		    void *user_data)
{
	switch (ev) {
	case CO_PGM_EV_STOPPED:
		printk("slave: program stopped\n");
		break;
	case CO_PGM_EV_STARTED:
		printk("slave: program runs again (date %u time %u)\n", img->date, img->time);
		break;
	case CO_PGM_EV_VERIFIED:
		printk("slave: image verified in slot 1 (date %u time %u, %u bytes, CRC-32 %08X)\n",
		       img->date, img->time, img->length, img->crc);
		break;
	case CO_PGM_EV_SWITCHED:
		printk("slave: switched to date %u time %u, restarting\n", img->date, img->time);
		break;
	case CO_PGM_EV_REFUSED:
		printk("slave: image refused, 1F57h %08Xh\n", co_pgm_flash_status(node));
		break;
	default:
		break;
	}
}

static uint32_t read_u32(struct co_sdo_cli *cli, uint16_t index, uint8_t sub)
{
	uint8_t buf[4] = {0};
	size_t len = 0;
	uint32_t ab = 0;

	if (co_sdo_cli_upload(cli, index, sub, buf, sizeof(buf), &len, CO_SDO_CLI_AUTO,
			      K_SECONDS(2), &ab) != 0) {
		printk("application: upload of %04Xh:%02Xh failed, abort %08Xh\n", index, sub, ab);
	}
	return sys_get_le32(buf);
}

static uint32_t write_ctrl(struct co_sdo_cli *cli, uint8_t cmd)
{
	uint32_t ab = 0;

	(void)co_sdo_cli_download(cli, 0x1F51, 1, &cmd, 1, CO_SDO_CLI_AUTO, K_SECONDS(2), &ab);
	return ab;
}

int main(void)
{
	const struct device *can = sample_line_device(0);
	struct co_sdo_cli *cli = &mgr.sdo_cli[1];
	struct co_pgm_image_info info;
	uint32_t ab = 0;
	int slot = -1;
	int err;

	if (can == NULL) {
		printk("firmware_update: no CAN controller\n");
		return 1;
	}
	pgm_offer_make_image(img_old, BODY, OLD_DATE, OLD_TIME, 1);
	pgm_offer_make_image(img_new, BODY, NEW_DATE, NEW_TIME, 2);
	memcpy(img_bad, img_new, sizeof(img_bad));
	img_bad[CO_PGM_HDR_SIZE + BODY / 2] ^= 0x04; /* one bit flipped in transit */

	/* The factory programmed slot 0 with program 1. */
	err = co_pgm_flash_ram_init(&flash, flash_mem, SLOT);
	if (err == 0) {
		err = co_pgm_slot_program(&flash.flash, 0, img_old, sizeof(img_old), 1);
	}
	if (err == 0) {
		err = co_line_init(&line, "line0", can);
	}
	if (err == 0) {
		err = co_node_init(&mgr, "manager", &line, &fw_manager_od_def, &mgr_ram, MANAGER);
	}
	if (err == 0) {
		err = co_node_init(&slave, "slave", &line, &fw_slave_od_def, &slave_ram, SLAVE);
	}
	if (err == 0) {
		err = co_pgm_attach(&slave, &flash.flash);
	}
	if (err != 0) {
		printk("firmware_update: set-up failed (%d)\n", err);
		return 1;
	}
	(void)co_pgm_get_running(&slave, &info, &slot);
	printk("slave: boots program date %u time %u from slot %d\n", info.date, info.time, slot);
	co_pgm_set_ind(&slave, pgm_ind, NULL);
	co_od_set_restore_cb(co_node_od(&mgr), pgm_offer_restore, &offer);
	co_mgr_set_boot_ind(&mgr, boot_ind, NULL);
	co_mgr_set_pgm_source(&mgr, pgm_offer_source, &offer);
	printk("manager: node 2 has program date %u time %u, expected date %u time %u\n", info.date,
	       info.time, NEW_DATE, NEW_TIME);

	err = co_line_start(&line, line_stack, K_THREAD_STACK_SIZEOF(line_stack),
			    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	if (err == 0) {
		err = co_node_start(&slave);
	}
	if (err == 0) {
		err = co_node_start(&mgr);
	}
	if (err != 0) {
		printk("firmware_update: start failed (%d)\n", err);
		return 1;
	}
	sample_print_stats_on_exit("firmware_update", &line);

	/* 1. The manager's boot updates the slave. */
	if (k_sem_take(&booted, K_SECONDS(30)) != 0) {
		printk("manager: no boot result for node 2\n");
		return 1;
	}
	err = co_sdo_cli_set_server(cli, SLAVE);
	if (err != 0) {
		printk("application: no SDO client (%d)\n", err);
		return 1;
	}
	printk("manager: node 2 booted (status %s), 1F52h date %u time %u\n",
	       boot_status == CO_MGR_ST_OK ? "OK" : "error", read_u32(cli, 0x1F52, 1),
	       read_u32(cli, 0x1F52, 2));

	/* 2. A corrupted image is refused; the slave keeps program 2. */
	(void)write_ctrl(cli, 0);
	(void)co_sdo_cli_download(cli, 0x1F50, 1, img_bad, sizeof(img_bad), CO_SDO_CLI_BLOCK,
				  K_SECONDS(10), &ab);
	printk("application: corrupted image refused: abort %08Xh, 1F57h %08Xh\n", ab,
	       read_u32(cli, 0x1F57, 1));
	ab = write_ctrl(cli, 1);
	if (ab != 0U) {
		printk("application: start refused, abort %08Xh\n", ab);
	}
	printk("application: node 2 keeps running date %u time %u, 1F51h %u\n",
	       read_u32(cli, 0x1F52, 1), read_u32(cli, 0x1F52, 2), read_u32(cli, 0x1F51, 1));
	printk("firmware_update: done\n");
	for (;;) {
		k_sleep(K_SECONDS(1));
	}
	return 0;
}
