/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * One life of a device whose program flash is a host file (CONFIG_CANOPEN_PGM_FLASH_FILE),
 * for pytest/test_flash_file.py, which runs this image several times on one file:
 *
 *   --testargs factory FILE       erase the file's flash, program the old image, commit it
 *   --testargs boot FILE          boot from the file and say what runs
 *   --testargs update FILE [CUT]  boot, then update to the new image over SDO (stop,
 *                                 block download, start); with CUT the power goes after CUT
 *                                 more bytes written to the flash, and the process ends there
 *
 * A slave (node 2) with the program-download service and a client (node 1) share a
 * simulation line. Each run prints `pgm_flash: ...` lines; the exit status is 0 unless the
 * run could not do what it was asked (2: bad arguments or flash, 3: the update failed
 * without a cut).
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/node.h>
#include <canopen/pgm.h>
#include <canopen/sdo_cli.h>

#include "cmdline.h"
#include "pgm_master_od.h"
#include "pgm_slave_od.h"

#define CLIENT   1U
#define SLAVE    2U
#define BODY     600U
#define IMAGE    (CO_PGM_HDR_SIZE + BODY)
#define SLOT     1024U
#define OLD_DATE 14000U
#define OLD_TIME 3600000U
#define NEW_DATE 15000U
#define NEW_TIME 7200000U
#define MS       1000ULL

static struct co_line line;
static uint64_t now;
static struct co_node client, slave;
static struct pgm_master_od_ram cram;
static struct pgm_slave_od_ram sram;
static struct co_pgm_flash_file fl;
static uint8_t img_old[IMAGE], img_new[IMAGE];
static bool done;
static uint32_t abort_code;

static int sink(struct co_line *l, const struct can_frame *f, void *user_data)
{
	return 0;
}

static void settle(void)
{
	for (int guard = 0; guard < 100000 && k_msgq_num_used_get(&line.rxq) != 0U; guard++) {
		co_line_process(&line, now);
	}
}

static void run_for(uint64_t us)
{
	const uint64_t at = now + us;

	settle();
	for (int guard = 0; guard < 1000000; guard++) {
		uint64_t next = co_line_next_deadline(&line);

		if (next > at) {
			break;
		}
		now = MAX(now, next);
		co_line_process(&line, now);
		settle();
	}
	now = at;
	co_line_process(&line, now);
	settle();
}

/* The client is a plain node (1F80h = 0): no NMT master, only its SDO client. */
static void client_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	uint8_t zero[4] = {0};

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		(void)co_od_write(od, 0x1F80, 0, zero, 4, CO_OD_WRITER_STORAGE);
	}
}

static void con(struct co_sdo_cli *c, uint32_t code, size_t size, void *user_data)
{
	done = true;
	abort_code = code;
}

static uint32_t sdo_dn(uint16_t index, uint8_t sub, const void *data, size_t len,
		       enum co_sdo_cli_mode mode)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&client, 1);

	done = false;
	if (co_sdo_cli_set_server(cli, SLAVE) != 0 ||
	    co_sdo_cli_download_req(cli, index, sub, data, len, mode, 500, con, NULL) != 0) {
		return CO_SDO_AB_GENERAL;
	}
	for (int i = 0; i < 10000 && !done; i++) {
		run_for(MS);
	}
	run_for(10 * MS); /* a switch restarts the slave: its boot-up goes out */
	return done ? abort_code : CO_SDO_AB_TIMEOUT;
}

static void make_image(uint8_t *img, uint32_t date, uint32_t time, uint8_t seed)
{
	for (uint32_t i = 0; i < BODY; i++) {
		img[CO_PGM_HDR_SIZE + i] = (uint8_t)(seed + i * 7U + (i >> 5));
	}
	co_pgm_image_header(img, img + CO_PGM_HDR_SIZE, BODY, date, time);
}

/* Power on: the network comes up and the slave boots from the file. */
static int power_on(const char *path)
{
	struct co_pgm_image_info info;
	int slot = -1;
	int err;

	err = co_pgm_flash_file_open(&fl, path, SLOT);
	if (err != 0) {
		printf("pgm_flash: cannot open the flash file: %d\n", err);
		return -1;
	}
	co_line_init_sim(&line, "sim", sink, NULL);
	co_line_process(&line, now);
	if (co_node_init(&client, "client", &line, &pgm_master_od_def, &cram, CLIENT) != 0 ||
	    co_node_init(&slave, "slave", &line, &pgm_slave_od_def, &sram, SLAVE) != 0) {
		printf("pgm_flash: node set-up failed\n");
		return -1;
	}
	co_od_set_restore_cb(co_node_od(&client), client_restore, NULL);
	err = co_pgm_attach(&slave, &fl.flash);
	if (co_node_start(&slave) != 0 || co_node_start(&client) != 0) {
		printf("pgm_flash: start failed\n");
		return -1;
	}
	run_for(10 * MS);
	if (err != 0 || co_pgm_get_running(&slave, &info, &slot) != 0) {
		printf("pgm_flash: boot: no valid program, 1F57h %02Xh\n",
		       co_pgm_flash_status(&slave));
		return 0;
	}
	printf("pgm_flash: boot: slot %d date %u time %u verified %d running %d\n", slot, info.date,
	       info.time, co_pgm_slot_verify(&fl.flash, (uint8_t)slot, NULL, NULL) == 0,
	       co_pgm_is_running(&slave));
	return 0;
}

static int update(int64_t cut)
{
	uint8_t cmd = CO_PGM_STOP;
	uint32_t ab = sdo_dn(0x1F51, 1, &cmd, 1, CO_SDO_CLI_AUTO);

	if (ab != 0U) {
		printf("pgm_flash: stop refused: %08X\n", ab);
		return 3;
	}
	if (cut >= 0) {
		co_pgm_flash_file_cut_after(&fl, (uint32_t)cut);
	}
	ab = sdo_dn(0x1F50, 1, img_new, sizeof(img_new), CO_SDO_CLI_BLOCK);
	printf("pgm_flash: download: %08X\n", ab);
	if (ab == 0U) {
		cmd = CO_PGM_START;
		ab = sdo_dn(0x1F51, 1, &cmd, 1, CO_SDO_CLI_AUTO);
		printf("pgm_flash: start: %08X\n", ab);
	}
	if (fl.off) {
		/* The device has no power: this process ends here, as the device would. */
		printf("pgm_flash: power cut after %u bytes written\n", fl.bytes_written);
		return 0;
	}
	return ab == 0U ? 0 : 3;
}

int main(void)
{
	int argc = 0;
	char **argv = NULL;
	int64_t cut = -1;
	int ret = 0;

	native_get_test_cmd_line_args(&argc, &argv);
	make_image(img_old, OLD_DATE, OLD_TIME, 1);
	make_image(img_new, NEW_DATE, NEW_TIME, 2);
	if (argc < 2 || argc > 3 || (argc == 3 && strcmp(argv[0], "update") != 0)) {
		printf("pgm_flash: usage: --testargs factory|boot|update FILE [CUT]\n");
		return 2;
	}
	if (argc == 3) {
		char *end;

		cut = strtoll(argv[2], &end, 0);
		if (*end != '\0' || cut < 0 || cut > UINT32_MAX) {
			printf("pgm_flash: bad cut '%s'\n", argv[2]);
			return 2;
		}
	}
	if (strcmp(argv[0], "factory") == 0) {
		ret = co_pgm_flash_file_open(&fl, argv[1], SLOT);
		if (ret == 0) {
			ret = fl.flash.api->erase(&fl.flash, 1);
		}
		if (ret == 0) {
			ret = co_pgm_slot_program(&fl.flash, 0, img_old, sizeof(img_old), 1U);
		}
		printf("pgm_flash: factory: %d\n", ret);
		co_pgm_flash_file_close(&fl);
		return ret == 0 ? 0 : 2;
	}
	if (strcmp(argv[0], "boot") != 0 && strcmp(argv[0], "update") != 0) {
		printf("pgm_flash: unknown command '%s'\n", argv[0]);
		return 2;
	}
	if (power_on(argv[1]) != 0) {
		return 2;
	}
	if (strcmp(argv[0], "update") == 0) {
		ret = update(cut);
	}
	co_pgm_flash_file_close(&fl);
	printf("pgm_flash: end\n");
	return ret;
}
