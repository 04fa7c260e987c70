/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Program download (CiA 302 §9) on a simulation line: a manager (node 01,
 * objdict/pgm_master.eds) and a slave with the program-download service (node 02,
 * objdict/pgm_slave.eds) and a RAM flash. The tests drive the slave through the manager's
 * spare SDO client, or let the manager's boot update it. A power cut is a cut of the RAM
 * flash at a byte, followed by a restart of everything but the flash's memory.
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/pgm.h>
#include <canopen/sdo_abort.h>
#include <canopen/sdo_cli.h>

#include "pgm_master_od.h"
#include "pgm_slave_od.h"

#define MASTER   0x01
#define SLAVE    0x02
#define MS       1000ULL
#define SLOT     2048U
#define BODY     600U
#define OLD_DATE 14000U
#define OLD_TIME 3600000U
#define NEW_DATE 15000U
#define NEW_TIME 7200000U
#define MAX_CFG  16

struct cfg_entry {
	uint16_t index;
	uint8_t sub;
	uint32_t value;
};

static struct {
	struct co_line line;
	uint64_t now;
	struct co_node master;
	struct pgm_master_od_ram mram;
	struct co_node slave;
	struct pgm_slave_od_ram sram;
	struct co_pgm_flash_ram fl;
	uint8_t mem[2 * SLOT];
	struct cfg_entry cfg[MAX_CFG];
	int n_cfg;
	/* Frames on the bus. */
	int n_frames;
	int n_bootups;     /* 702h#00 */
	int n_pgm_writes;  /* SDO initiate downloads to the slave's 1F50h */
	int n_ctrl_writes; /* ... to its 1F51h */
	/* SDO confirmation. */
	bool done;
	uint32_t abort_code;
	uint8_t up[4];
	/* Boot indication. */
	int n_boot;
	uint8_t boot_status;
	struct co_mgr_boot_error boot_err;
	/* Slave's program indications. */
	int n_ev[CO_PGM_EV_CLEARED + 1];
	/* Armed at the next power_up() (>= 0): the flash loses power after that many bytes. */
	int64_t cut_at_boot;
	/* Manager's image source. */
	const uint8_t *src;
	size_t src_len;
} t;

static uint8_t img_old[CO_PGM_HDR_SIZE + BODY];
static uint8_t img_new[CO_PGM_HDR_SIZE + BODY];
static uint8_t snapshot[2 * SLOT];

/* --- Bus and time --------------------------------------------------------------------------- */

static int sink(struct co_line *line, const struct can_frame *f, void *user_data)
{
	t.n_frames++;
	if (f->id == 0x700U + SLAVE && f->dlc == 1 && f->data[0] == 0U) {
		t.n_bootups++;
	}
	if (f->id == 0x600U + SLAVE && (f->data[0] & 0xe0U) == 0x20U && f->data[2] == 0x1F) {
		/* Initiate download (segmented/expedited) */
		t.n_ctrl_writes += f->data[1] == 0x51 ? 1 : 0;
		t.n_pgm_writes += f->data[1] == 0x50 ? 1 : 0;
	}
	if (f->id == 0x600U + SLAVE && (f->data[0] & 0xe1U) == 0xc0U && f->data[2] == 0x1F &&
	    f->data[1] == 0x50) {
		/* Initiate block download */
		t.n_pgm_writes++;
	}
	return 0;
}

static void settle(void)
{
	for (int guard = 0; guard < 100000; guard++) {
		if (k_msgq_num_used_get(&t.line.rxq) == 0U) {
			return;
		}
		co_line_process(&t.line, t.now);
	}
	zassert_unreachable("the line does not settle");
}

static void run_until(uint64_t at)
{
	settle();
	for (int guard = 0; guard < 1000000; guard++) {
		uint64_t next = co_line_next_deadline(&t.line);

		if (next > at) {
			break;
		}
		if (next > t.now) {
			t.now = next;
		}
		co_line_process(&t.line, t.now);
		settle();
	}
	t.now = at;
	co_line_process(&t.line, t.now);
	settle();
}

static void run_for(uint64_t us)
{
	run_until(t.now + us);
}

/* --- Nodes ------------------------------------------------------------------------------------ */

static void cfg(uint16_t index, uint8_t sub, uint32_t value)
{
	zassert_true(t.n_cfg < MAX_CFG);
	t.cfg[t.n_cfg++] = (struct cfg_entry){index, sub, value};
}

static void master_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (int i = 0; i < t.n_cfg; i++) {
		uint8_t buf[4];

		sys_put_le32(t.cfg[i].value, buf);
		zassert_equal(
			co_od_write(od, t.cfg[i].index, t.cfg[i].sub, buf, 4, CO_OD_WRITER_STORAGE),
			0U, "%04X:%02X", t.cfg[i].index, t.cfg[i].sub);
	}
}

static void boot_ind(struct co_node *node, uint8_t id, uint8_t status,
		     const struct co_mgr_boot_error *err, void *user_data)
{
	t.n_boot++;
	t.boot_status = status;
	if (err != NULL) {
		t.boot_err = *err;
	}
}

static void pgm_ind(struct co_node *node, enum co_pgm_event ev, const struct co_pgm_image_info *img,
		    void *user_data)
{
	t.n_ev[ev]++;
}

static int source(struct co_node *node, uint8_t id, const void **image, size_t *len,
		  void *user_data)
{
	if (id != SLAVE || t.src == NULL) {
		return -ENOENT;
	}
	*image = t.src;
	*len = t.src_len;
	return 0;
}

/*
 * (Re)start the whole network: line, manager and slave, with the flash's memory as it is
 * (a device restarting after a power cut). The manager is started by the tests that need
 * its boot; otherwise it is only the SDO client.
 */
static int power_up(void)
{
	int ret;

	memset(&t.line, 0, sizeof(t.line));
	memset(&t.master, 0, sizeof(t.master));
	memset(&t.slave, 0, sizeof(t.slave));
	memset(&t.mram, 0, sizeof(t.mram));
	memset(&t.sram, 0, sizeof(t.sram));
	co_line_init_sim(&t.line, "sim", sink, NULL);
	co_line_process(&t.line, t.now);
	zassert_ok(co_node_init(&t.master, "master", &t.line, &pgm_master_od_def, &t.mram, MASTER));
	co_od_set_restore_cb(co_node_od(&t.master), master_restore, NULL);
	co_mgr_set_boot_ind(&t.master, boot_ind, NULL);
	co_mgr_set_pgm_source(&t.master, source, NULL);
	zassert_ok(co_node_init(&t.slave, "slave", &t.line, &pgm_slave_od_def, &t.sram, SLAVE));
	co_pgm_flash_ram_power_on(&t.fl);
	ret = co_pgm_attach(&t.slave, &t.fl.flash);
	if (t.cut_at_boot >= 0) {
		co_pgm_flash_ram_cut_after(&t.fl, (uint32_t)t.cut_at_boot);
		t.cut_at_boot = -1;
	}
	co_pgm_set_ind(&t.slave, pgm_ind, NULL);
	zassert_ok(co_node_start(&t.slave));
	/* The manager boots the slave when 1F80h says so (manager tests), else it is a client. */
	zassert_ok(co_node_start(&t.master));
	run_for(10 * MS);
	return ret;
}

static struct co_sdo_cli *cli(void)
{
	return &t.master.sdo_cli[1];
}

static void con(struct co_sdo_cli *c, uint32_t abort_code, size_t size, void *user_data)
{
	t.done = true;
	t.abort_code = abort_code;
}

static uint32_t sdo_dn(uint16_t index, uint8_t sub, const void *data, size_t len,
		       enum co_sdo_cli_mode mode)
{
	t.done = false;
	zassert_ok(co_sdo_cli_set_server(cli(), SLAVE));
	zassert_ok(co_sdo_cli_download_req(cli(), index, sub, data, len, mode, 500, con, NULL));
	for (int i = 0; i < 10000 && !t.done; i++) {
		run_for(MS);
	}
	zassert_true(t.done, "no confirmation");
	return t.abort_code;
}

static uint32_t ctrl(uint8_t cmd)
{
	uint32_t ab = sdo_dn(0x1F51, 1, &cmd, 1, CO_SDO_CLI_AUTO);

	/* A switch restarts the slave: let its boot-up go out. */
	run_for(10 * MS);
	return ab;
}

static uint32_t sdo_up(uint16_t index, uint8_t sub, uint32_t *value)
{
	memset(t.up, 0, sizeof(t.up));
	t.done = false;
	zassert_ok(co_sdo_cli_set_server(cli(), SLAVE));
	zassert_ok(co_sdo_cli_upload_req(cli(), index, sub, t.up, sizeof(t.up), CO_SDO_CLI_AUTO,
					 500, con, NULL));
	for (int i = 0; i < 1000 && !t.done; i++) {
		run_for(MS);
	}
	zassert_true(t.done);
	*value = sys_get_le32(t.up);
	return t.abort_code;
}

static uint32_t read_u32(uint16_t index, uint8_t sub)
{
	uint32_t v = 0;

	zassert_equal(sdo_up(index, sub, &v), 0U, "%04X:%02X", index, sub);
	return v;
}

static uint32_t download(const void *img, size_t len)
{
	return sdo_dn(0x1F50, 1, img, len, CO_SDO_CLI_BLOCK);
}

static void make_image(uint8_t *img, uint32_t body_len, uint32_t date, uint32_t time, uint8_t seed)
{
	uint8_t *body = img + CO_PGM_HDR_SIZE;

	for (uint32_t i = 0; i < body_len; i++) {
		body[i] = (uint8_t)(seed + i * 7U + (i >> 5));
	}
	co_pgm_image_header(img, body, body_len, date, time);
}

/* The slave's flash holds the old image, committed, and the slave runs it. */
static void factory(void)
{
	/* The manager stays a plain node (its SDO client) until a test configures it. */
	t.n_cfg = 0;
	cfg(0x1F80, 0, 0x00);
	zassert_ok(co_pgm_flash_ram_init(&t.fl, t.mem, SLOT));
	zassert_equal(power_up(), -ENOENT);
	zassert_equal(download(img_old, sizeof(img_old)), 0U);
	zassert_equal(ctrl(CO_PGM_START), 0U);
	zassert_equal(power_up(), 0);
	memset(t.n_ev, 0, sizeof(t.n_ev));
	t.n_bootups = 0;
	t.n_pgm_writes = 0;
	t.n_ctrl_writes = 0;
}

static void expect_running(uint32_t date, uint32_t time, const uint8_t *img)
{
	struct co_pgm_image_info info;
	int slot;

	zassert_equal(read_u32(0x1F52, 1), date);
	zassert_equal(read_u32(0x1F52, 2), time);
	zassert_equal(read_u32(0x1F56, 1), sys_get_le32(&img[12]));
	zassert_ok(co_pgm_get_running(&t.slave, &info, &slot));
	zassert_ok(co_pgm_slot_verify(&t.fl.flash, (uint8_t)slot, NULL, NULL));
	zassert_equal(info.date, date);
}

static void before(void *unused)
{
	memset(&t, 0, sizeof(t));
	t.cut_at_boot = -1;
	make_image(img_old, BODY, OLD_DATE, OLD_TIME, 1);
	make_image(img_new, BODY, NEW_DATE, NEW_TIME, 2);
}

ZTEST_SUITE(co_pgm, NULL, NULL, before, NULL, NULL);

/* --- Image format ----------------------------------------------------------------------------- */

ZTEST(co_pgm, test_crc32_and_header)
{
	struct co_pgm_image_info info;
	uint8_t hdr[CO_PGM_HDR_SIZE];

	/* The check value of CRC-32/ISO-HDLC. */
	zassert_equal(co_pgm_crc32(0U, "123456789", 9), 0xCBF43926U);
	zassert_equal(co_pgm_crc32(co_pgm_crc32(0U, "1234", 4), "56789", 5), 0xCBF43926U);
	zassert_ok(co_pgm_image_parse(img_new, &info));
	zassert_equal(info.length, BODY);
	zassert_equal(info.date, NEW_DATE);
	zassert_equal(info.time, NEW_TIME);
	memcpy(hdr, img_new, sizeof(hdr));
	hdr[17] ^= 1U;
	zassert_equal(co_pgm_image_parse(hdr, &info), -EBADMSG);
	hdr[0] = 'X';
	zassert_equal(co_pgm_image_parse(hdr, &info), -ENOTSUP);
}

ZTEST(co_pgm, test_flash_rules)
{
	uint8_t b = 0x0f;

	zassert_ok(co_pgm_flash_ram_init(&t.fl, t.mem, SLOT));
	zassert_ok(t.fl.flash.api->write(&t.fl.flash, 0, 5, &b, 1));
	b = 0xf0;
	/* A bit cleared cannot be set again without an erase. */
	zassert_equal(t.fl.flash.api->write(&t.fl.flash, 0, 5, &b, 1), -EROFS);
	zassert_equal(t.fl.flash.api->write(&t.fl.flash, 1, SLOT - 1, t.mem, 2), -EINVAL);
	co_pgm_flash_ram_cut_after(&t.fl, 3);
	zassert_equal(t.fl.flash.api->write(&t.fl.flash, 1, 0, img_old, 8), -EIO);
	zassert_mem_equal(&t.mem[SLOT], img_old, 3);
	zassert_equal(t.mem[SLOT + 3], 0xff);
	zassert_equal(t.fl.flash.api->read(&t.fl.flash, 1, 0, &b, 1), -EIO);
	co_pgm_flash_ram_power_on(&t.fl);
	zassert_ok(t.fl.flash.api->read(&t.fl.flash, 1, 0, &b, 1));
	zassert_equal(co_pgm_flash_ram_init(&t.fl, t.mem, 40), -EINVAL);
}

ZTEST(co_pgm, test_slot_program)
{
	struct co_pgm_image_info info;
	uint32_t seq;
	static uint8_t bad[sizeof(img_old)];

	zassert_ok(co_pgm_flash_ram_init(&t.fl, t.mem, SLOT));
	zassert_ok(co_pgm_slot_program(&t.fl.flash, 1, img_old, sizeof(img_old), 7));
	zassert_ok(co_pgm_slot_verify(&t.fl.flash, 1, &info, &seq));
	zassert_equal(seq, 7U);
	zassert_equal(info.date, OLD_DATE);
	zassert_equal(co_pgm_slot_verify(&t.fl.flash, 0, NULL, NULL), -ENOENT);
	memcpy(bad, img_old, sizeof(bad));
	bad[CO_PGM_HDR_SIZE] ^= 1U;
	zassert_equal(co_pgm_slot_program(&t.fl.flash, 0, bad, sizeof(bad), 8), -EBADMSG);
	zassert_equal(co_pgm_slot_program(&t.fl.flash, 0, img_old, sizeof(img_old) - 1, 8),
		      -EBADMSG);
	zassert_equal(co_pgm_slot_program(&t.fl.flash, 2, img_old, sizeof(img_old), 8), -EINVAL);
	/* The newest commit boots. */
	zassert_ok(co_pgm_slot_program(&t.fl.flash, 0, img_new, sizeof(img_new), 8));
	cfg(0x1F80, 0, 0x00);
	zassert_equal(power_up(), 0);
	expect_running(NEW_DATE, NEW_TIME, img_new);
}

/* --- Slave ------------------------------------------------------------------------------------ */

ZTEST(co_pgm, test_empty_flash)
{
	cfg(0x1F80, 0, 0x00);
	zassert_ok(co_pgm_flash_ram_init(&t.fl, t.mem, SLOT));
	zassert_equal(power_up(), -ENOENT);
	zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_NO_PROGRAM);
	zassert_equal(read_u32(0x1F52, 1), 0U);
	zassert_equal(read_u32(0x1F52, 2), 0U);
	zassert_equal(read_u32(0x1F51, 1), 0U);
	zassert_equal(read_u32(0x1F52, 0) & 0xff, 2U);
	/* Nothing to start: "no data available". */
	zassert_equal(ctrl(CO_PGM_START), CO_SDO_AB_NO_DATA);
	zassert_equal(ctrl(CO_PGM_RESET), CO_SDO_AB_NO_DATA);
}

ZTEST(co_pgm, test_download_verify_start)
{
	factory();
	expect_running(OLD_DATE, OLD_TIME, img_old);
	zassert_equal(read_u32(0x1F51, 1), 1U);
	zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_OK);

	zassert_equal(ctrl(CO_PGM_STOP), 0U);
	zassert_equal(read_u32(0x1F51, 1), 0U);
	zassert_equal(download(img_new, sizeof(img_new)), 0U);
	zassert_equal(t.n_ev[CO_PGM_EV_VERIFIED], 1);
	zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_OK);
	/* Verified, not started: the old image still runs and still boots. */
	expect_running(OLD_DATE, OLD_TIME, img_old);
	zassert_equal(t.n_bootups, 0);

	zassert_equal(ctrl(CO_PGM_START), 0U);
	zassert_equal(t.n_ev[CO_PGM_EV_SWITCHED], 1);
	zassert_equal(t.n_bootups, 1, "the slave restarts with the new image");
	expect_running(NEW_DATE, NEW_TIME, img_new);
	zassert_equal(read_u32(0x1F51, 1), 1U);

	/* A real restart boots the new one too. */
	zassert_equal(power_up(), 0);
	expect_running(NEW_DATE, NEW_TIME, img_new);
}

ZTEST(co_pgm, test_download_refused_while_running)
{
	factory();
	zassert_equal(download(img_new, sizeof(img_new)), CO_SDO_AB_DATA_DEV_STATE);
	expect_running(OLD_DATE, OLD_TIME, img_old);
	zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_OK);
}

/* Download a broken image into a stopped slave: refused, the old image keeps running. */
static void refused(const uint8_t *img, size_t len, uint32_t status)
{
	factory();
	zassert_equal(ctrl(CO_PGM_STOP), 0U);
	zassert_equal(download(img, len), CO_SDO_AB_HW);
	zassert_equal(read_u32(0x1F57, 1), status);
	zassert_equal(t.n_ev[CO_PGM_EV_REFUSED], 1);
	/* Start runs the old image again, without a restart. */
	zassert_equal(ctrl(CO_PGM_START), 0U);
	zassert_equal(t.n_bootups, 0);
	zassert_equal(t.n_ev[CO_PGM_EV_STARTED], 1);
	zassert_equal(read_u32(0x1F51, 1), 1U);
	expect_running(OLD_DATE, OLD_TIME, img_old);
	zassert_equal(power_up(), 0);
	expect_running(OLD_DATE, OLD_TIME, img_old);
}

ZTEST(co_pgm, test_corrupted_body_refused)
{
	static uint8_t bad[sizeof(img_new)];

	memcpy(bad, img_new, sizeof(bad));
	bad[CO_PGM_HDR_SIZE + 100] ^= 0x10;
	refused(bad, sizeof(bad), CO_PGM_FLASH_CRC);
}

ZTEST(co_pgm, test_bad_header_refused)
{
	static uint8_t bad[sizeof(img_new)];

	memcpy(bad, img_new, sizeof(bad));
	bad[0] = 'X';
	refused(bad, sizeof(bad), CO_PGM_FLASH_FORMAT);
	memcpy(bad, img_new, sizeof(bad));
	bad[20] ^= 1U; /* time, under the header CRC */
	refused(bad, sizeof(bad), CO_PGM_FLASH_CRC);
}

ZTEST(co_pgm, test_short_and_long_images_refused)
{
	static uint8_t big[CO_PGM_HDR_SIZE + SLOT];
	static uint8_t extra[sizeof(img_new) + 1];

	refused(img_new, sizeof(img_new) - 1, CO_PGM_FLASH_CRC);
	memcpy(extra, img_new, sizeof(img_new));
	refused(extra, sizeof(extra), CO_PGM_FLASH_FORMAT);
	/* A body that cannot fit a slot: refused at the header, before it is written. */
	make_image(big, SLOT, NEW_DATE, NEW_TIME, 3);
	refused(big, sizeof(big), CO_PGM_FLASH_ADDRESS);
}

ZTEST(co_pgm, test_control_values)
{
	uint32_t v;

	factory();
	zassert_equal(ctrl(4), CO_SDO_AB_VALUE_HIGH);
	/* Clear: not while the program runs. */
	zassert_equal(ctrl(CO_PGM_CLEAR), CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(ctrl(CO_PGM_STOP), 0U);
	zassert_equal(download(img_new, sizeof(img_new)), 0U);
	/* Clear erases the verified image not yet started: a start then runs the old one. */
	zassert_equal(ctrl(CO_PGM_CLEAR), 0U);
	zassert_equal(t.n_ev[CO_PGM_EV_CLEARED], 1);
	zassert_equal(ctrl(CO_PGM_START), 0U);
	zassert_equal(t.n_bootups, 0);
	expect_running(OLD_DATE, OLD_TIME, img_old);
	/* Reset: the program stops (reads 0). */
	zassert_equal(ctrl(CO_PGM_RESET), 0U);
	zassert_equal(t.n_ev[CO_PGM_EV_RESET], 1);
	zassert_equal(read_u32(0x1F51, 1), 0U);
	/* 1F50h is write only; 1F52h, 1F56h, 1F57h are read only. */
	zassert_equal(sdo_up(0x1F50, 1, &v), CO_SDO_AB_WRITEONLY);
	v = 1;
	zassert_equal(sdo_dn(0x1F52, 1, &v, 4, CO_SDO_CLI_AUTO), CO_SDO_AB_READONLY);
	zassert_equal(sdo_dn(0x1F57, 1, &v, 4, CO_SDO_CLI_AUTO), CO_SDO_AB_READONLY);
	zassert_equal(sdo_up(0x1F53, 1, &v), CO_SDO_AB_NO_OBJECT);
	zassert_equal(sdo_up(0x1F51, 2, &v), CO_SDO_AB_NO_SUB);
	/* One program (doc/pgm.md): sub-index 0 says 1 and program 2 does not exist. */
	zassert_equal(read_u32(0x1F50, 0) & 0xff, 1U);
	zassert_equal(read_u32(0x1F51, 0) & 0xff, 1U);
	zassert_equal(sdo_dn(0x1F50, 2, img_new, sizeof(img_new), CO_SDO_CLI_BLOCK),
		      CO_SDO_AB_NO_SUB);
	zassert_equal(sdo_up(0x1F56, 2, &v), CO_SDO_AB_NO_SUB);
	zassert_equal(sdo_up(0x1F57, 2, &v), CO_SDO_AB_NO_SUB);
}

/*
 * Done when of the issue: a download cut at any point leaves the slave running a verified
 * image. The power goes at every byte of the erase, the download and the commit record in
 * turn; after the restart the slave runs the old image or (cut after the commit) the new
 * one, never anything else, and a new update then succeeds.
 */
ZTEST(co_pgm, test_power_cut_at_every_byte)
{
	const uint32_t total = sizeof(img_new) + 16U; /* image, then the commit record */
	int n_old = 0;
	int n_new = 0;

	factory();
	memcpy(snapshot, t.mem, sizeof(snapshot));
	for (uint32_t cut = 0; cut <= total; cut++) {
		struct co_pgm_image_info info;
		int slot;

		memcpy(t.mem, snapshot, sizeof(snapshot));
		zassert_equal(power_up(), 0);
		zassert_equal(ctrl(CO_PGM_STOP), 0U);
		co_pgm_flash_ram_cut_after(&t.fl, cut);
		if (download(img_new, sizeof(img_new)) == 0U) {
			(void)ctrl(CO_PGM_START);
		}
		zassert_equal(t.fl.off, cut < total, "cut %u", cut);

		zassert_equal(power_up(), 0, "cut %u: no valid image", cut);
		zassert_ok(co_pgm_get_running(&t.slave, &info, &slot));
		zassert_ok(co_pgm_slot_verify(&t.fl.flash, (uint8_t)slot, NULL, NULL));
		zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_OK);
		if (cut < total) {
			/* The commit record is the last byte written: before it, the old image. */
			zassert_equal(info.date, OLD_DATE, "cut %u", cut);
			zassert_equal(read_u32(0x1F52, 1), OLD_DATE);
			n_old++;
		} else {
			zassert_equal(info.date, NEW_DATE);
			n_new++;
		}
		if (cut % 97U == 0U) {
			/* After the restart an update works. */
			zassert_equal(ctrl(CO_PGM_STOP), 0U);
			zassert_equal(download(img_new, sizeof(img_new)), 0U);
			zassert_equal(ctrl(CO_PGM_START), 0U);
			expect_running(NEW_DATE, NEW_TIME, img_new);
		}
	}
	zassert_equal(n_old, (int)total);
	zassert_equal(n_new, 1);
}

/* --- Manager ------------------------------------------------------------------------------------
 */

static void manager_run(void)
{
	t.n_boot = 0;
	t.n_bootups = 0;
	zassert_equal(power_up(), 0);
	for (int i = 0; i < 200 && t.n_boot == 0; i++) {
		run_for(10 * MS);
	}
	zassert_equal(t.n_boot, 1);
}

static void manager(uint32_t assign)
{
	cfg(0x1F80, 0, 0x01);
	cfg(0x1F81, SLAVE, assign);
	cfg(0x1F53, SLAVE, NEW_DATE);
	cfg(0x1F54, SLAVE, NEW_TIME);
	manager_run();
}

/* 1F81h: slave, boot, software check (bit 5), update allowed (bit 6). */
#define AS_UPDATE 0x65U
#define AS_CHECK  0x25U

ZTEST(co_pgm, test_manager_updates_old_slave)
{
	factory();
	t.src = img_new;
	t.src_len = sizeof(img_new);
	manager(AS_UPDATE);
	zassert_equal(t.boot_status, CO_MGR_ST_OK, "status %c step %s abort %08x", t.boot_status,
		      co_mgr_step_str(t.boot_err.step), t.boot_err.abort_code);
	zassert_equal(t.n_pgm_writes, 1);
	zassert_equal(t.n_ctrl_writes, 2, "stop, then start");
	zassert_equal(t.n_ev[CO_PGM_EV_STOPPED], 1);
	zassert_equal(t.n_ev[CO_PGM_EV_SWITCHED], 1);
	zassert_true(t.n_bootups >= 2, "the manager's reset, then the restart");
	expect_running(NEW_DATE, NEW_TIME, img_new);
}

ZTEST(co_pgm, test_manager_same_version_no_download)
{
	factory();
	t.src = img_old;
	t.src_len = sizeof(img_old);
	t.n_cfg = 0;
	cfg(0x1F80, 0, 0x01);
	cfg(0x1F81, SLAVE, AS_UPDATE);
	cfg(0x1F53, SLAVE, OLD_DATE);
	cfg(0x1F54, SLAVE, OLD_TIME);
	manager_run();
	zassert_equal(t.boot_status, CO_MGR_ST_OK);
	zassert_equal(t.n_pgm_writes, 0);
	zassert_equal(t.n_ctrl_writes, 0);
}

ZTEST(co_pgm, test_manager_update_not_allowed_h)
{
	factory();
	t.src = img_new;
	t.src_len = sizeof(img_new);
	manager(AS_CHECK);
	zassert_equal(t.boot_status, CO_MGR_ST_H);
	zassert_equal(t.n_pgm_writes, 0, "no write to 1F50h");
	zassert_equal(t.n_ctrl_writes, 0);
	expect_running(OLD_DATE, OLD_TIME, img_old);
}

ZTEST(co_pgm, test_manager_failing_download_i)
{
	static uint8_t bad[sizeof(img_new)];

	factory();
	memcpy(bad, img_new, sizeof(bad));
	bad[CO_PGM_HDR_SIZE + 5] ^= 0x80;
	t.src = bad;
	t.src_len = sizeof(bad);
	manager(AS_UPDATE);
	zassert_equal(t.boot_status, CO_MGR_ST_I);
	zassert_equal(t.boot_err.index, 0x1F50);
	zassert_equal(t.boot_err.abort_code, CO_SDO_AB_HW);
	zassert_equal(t.boot_err.step, CO_MGR_STEP_PGM_RESUME);
	/* Stop, then the start that resumes the old program. */
	zassert_equal(t.n_ctrl_writes, 2);
	zassert_equal(read_u32(0x1F57, 1), CO_PGM_FLASH_CRC);
	zassert_equal(read_u32(0x1F51, 1), 1U, "the old program runs again");
	expect_running(OLD_DATE, OLD_TIME, img_old);
}

ZTEST(co_pgm, test_manager_wrong_image_version_i)
{
	static uint8_t other[sizeof(img_new)];

	factory();
	/* A valid image, but not the version 1F53h/1F54h expect. */
	make_image(other, BODY, NEW_DATE, NEW_TIME + 1U, 4);
	t.src = other;
	t.src_len = sizeof(other);
	manager(AS_UPDATE);
	zassert_equal(t.boot_status, CO_MGR_ST_I);
	zassert_equal(t.boot_err.index, 0x1F52);
	zassert_equal(t.boot_err.sub, 2);
	zassert_equal(t.boot_err.expected, NEW_TIME);
	zassert_equal(t.boot_err.actual, NEW_TIME + 1U);
}

ZTEST(co_pgm, test_manager_power_cut_during_download_i)
{
	factory();
	t.src = img_new;
	t.src_len = sizeof(img_new);
	/* The slave's flash loses power 100 bytes into the download. */
	t.cut_at_boot = 100;
	manager(AS_UPDATE);
	zassert_equal(t.boot_status, CO_MGR_ST_I, "status %c step %s", t.boot_status,
		      co_mgr_step_str(t.boot_err.step));
	zassert_equal(t.boot_err.index, 0x1F50);
	/* Restarted without the manager: the old image runs. */
	cfg(0x1F80, 0, 0x00);
	zassert_equal(power_up(), 0);
	expect_running(OLD_DATE, OLD_TIME, img_old);
	/* Restarted with it: the next boot updates the slave. */
	cfg(0x1F80, 0, 0x01);
	manager_run();
	zassert_equal(t.boot_status, CO_MGR_ST_OK);
	expect_running(NEW_DATE, NEW_TIME, img_new);
}
