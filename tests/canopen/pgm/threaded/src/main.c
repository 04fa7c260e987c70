/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Program download with real line threads (doc/pgm.md): the manager (node 1) on line M, the
 * slave (node 2) on line S, one virtual bus at 1 Mbit/s with bit timing. The slave's flash
 * holds the old image; the manager's boot would update it to the new one.
 *
 * The manager is cut off in the middle of that: the moment comes from the slave's own thread
 * (its flash has written so many bytes of the download, its program was stopped, it was
 * reset by the manager), which cuts the manager's controller off the bus at once; the test
 * thread then stops the manager's line and switches its controller off, as if the manager's
 * process had gone. The slave must still hold the old image as the one in force, verified in
 * its flash, and boot it again on a restart; a new manager (a fresh node on a fresh line on
 * the same controller) then completes the update.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/pgm.h>

#include "pgm_master_od.h"
#include "pgm_slave_od.h"

#include "pgm_offer.h"

#define MANAGER    1U
#define SLAVE      2U
#define BODY       (16U * 1024U)
#define IMAGE      (CO_PGM_HDR_SIZE + BODY)
#define SLOT       (IMAGE + 64U)
#define OLD_DATE   14000U
#define OLD_TIME   3600000U
#define NEW_DATE   15000U
#define NEW_TIME   7200000U
/* The longest wait for the slave to give up a download: its SDO server timeout (prj.conf)
 * and room for a loaded host.
 */
#define GIVE_UP_MS 20000

/* Where the manager is cut off. */
enum cut_at {
	CUT_AT_RESET,   /* the slave is reset by the manager's NMT startup */
	CUT_AT_STOPPED, /* the slave's program was stopped (1F51h:01 = 0) */
	/*
	 * The slave's flash has written n bytes of the download or more: the SDO server hands
	 * the data over a sub-block (889 bytes) at a time, and the last one at the end request.
	 */
	CUT_AT_BYTE,
};

static const struct device *mdev, *sdev;
/*
 * Each manager and each slave comes up on a line object never used before: a controller's
 * TX-done callback for a frame of a line that was stopped (and its controller stopped) may
 * still run in the bus thread, and must not find that line wiped for its successor.
 */
#define MAX_MLINES 24
#define MAX_SLINES 12
static struct co_line mlines[MAX_MLINES], slines[MAX_SLINES];
static struct co_line *mline, *sline;
static int n_mlines, n_slines;
static struct co_node mgr, slave;
static struct pgm_master_od_ram mram;
static struct pgm_slave_od_ram sram;
static K_THREAD_STACK_DEFINE(mstack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_THREAD_STACK_DEFINE(sstack, CONFIG_CANOPEN_LINE_STACK_SIZE);

static uint8_t img_old[IMAGE], img_new[IMAGE];
static struct pgm_offer offer = {
	.slave = SLAVE, .image = img_new, .len = IMAGE, .date = NEW_DATE, .time = NEW_TIME};

/* The slave's flash: a RAM flash that counts the bytes of the download and cuts there. */
static struct {
	struct co_pgm_flash flash;
	struct co_pgm_flash_ram ram;
	uint8_t mem[2 * SLOT];
	uint32_t written; /* since the last erase; under the slave's lock */
} fl;

/* The cut: armed by the test, done once by the slave's thread. */
static enum cut_at cut_kind;
static uint32_t cut_byte;
static atomic_t cut_armed;
static K_SEM_DEFINE(cut_sem, 0, 1);
static K_SEM_DEFINE(boot_sem, 0, 1);
static uint8_t boot_status; /* written before boot_sem is given */

static void cut_now(void)
{
	if (atomic_cas(&cut_armed, 1, 0)) {
		/* From the slave's thread: the manager hears nothing more and says nothing more. */
		(void)can_virtual_cut(mdev);
		k_sem_give(&cut_sem);
	}
}

static int fl_erase(struct co_pgm_flash *f, uint8_t slot)
{
	fl.written = 0U;
	return fl.ram.flash.api->erase(&fl.ram.flash, slot);
}

static int fl_write(struct co_pgm_flash *f, uint8_t slot, uint32_t off, const void *data,
		    size_t len)
{
	int err = fl.ram.flash.api->write(&fl.ram.flash, slot, off, data, len);

	fl.written += (uint32_t)len;
	if (cut_kind == CUT_AT_BYTE && fl.written >= cut_byte) {
		cut_now();
	}
	return err;
}

static int fl_read(struct co_pgm_flash *f, uint8_t slot, uint32_t off, void *buf, size_t len)
{
	return fl.ram.flash.api->read(&fl.ram.flash, slot, off, buf, len);
}

static const struct co_pgm_flash_api fl_api = {
	.erase = fl_erase,
	.write = fl_write,
	.read = fl_read,
};

static void pgm_ind(struct co_node *node, enum co_pgm_event ev, const struct co_pgm_image_info *img,
		    void *user_data)
{
	if (ev == CO_PGM_EV_STOPPED && cut_kind == CUT_AT_STOPPED) {
		cut_now();
	}
}

static void slave_reset(struct co_node *node, enum co_nmt_cs cs, void *user_data)
{
	/* The manager's NMT startup resets the slave before it checks its software. */
	if (cut_kind == CUT_AT_RESET) {
		cut_now();
	}
}

/* --- The manager ----------------------------------------------------------------------------- */

static void boot_ind(struct co_node *node, uint8_t id, uint8_t status,
		     const struct co_mgr_boot_error *err, void *user_data)
{
	if (id == SLAVE) {
		boot_status = status;
		k_sem_give(&boot_sem);
	}
}

/* A manager process comes up: a fresh line on its controller, a fresh node. */
static void manager_up(void)
{
	zassert_true(n_mlines < MAX_MLINES);
	mline = &mlines[n_mlines++];
	memset(&mgr, 0, sizeof(mgr));
	memset(&mram, 0, sizeof(mram));
	k_sem_reset(&boot_sem);
	zassert_ok(co_line_init(mline, "mline", mdev));
	zassert_ok(co_node_init(&mgr, "manager", mline, &pgm_master_od_def, &mram, MANAGER));
	co_od_set_restore_cb(co_node_od(&mgr), pgm_offer_restore, &offer);
	co_mgr_set_boot_ind(&mgr, boot_ind, NULL);
	co_mgr_set_pgm_source(&mgr, pgm_offer_source, &offer);
	zassert_ok(co_line_start(mline, mstack, K_THREAD_STACK_SIZEOF(mstack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	zassert_ok(co_node_start(&mgr));
}

/* The manager's process goes: its line thread ends and its controller is switched off. */
static void manager_gone(void)
{
	zassert_ok(co_line_stop(mline));
	(void)can_stop(mdev); /* what it still had queued is lost with it */
	zassert_ok(can_virtual_restore(mdev));
}

/* --- Set-up ------------------------------------------------------------------------------------
 */

static void *suite_setup(void)
{
	mdev = device_get_binding("can_virtual0");
	sdev = device_get_binding("can_virtual1");
	zassert_not_null(mdev);
	zassert_not_null(sdev);
	pgm_offer_make_image(img_old, BODY, OLD_DATE, OLD_TIME, 1);
	pgm_offer_make_image(img_new, BODY, NEW_DATE, NEW_TIME, 2);
	return NULL;
}

/* The slave, freshly started on its own line, runs the old image from slot 0. */
static void before(void *unused)
{
	atomic_set(&cut_armed, 0);
	k_sem_reset(&cut_sem);
	zassert_ok(co_pgm_flash_ram_init(&fl.ram, fl.mem, SLOT));
	zassert_ok(co_pgm_slot_program(&fl.ram.flash, 0, img_old, sizeof(img_old), 1));
	fl.flash = (struct co_pgm_flash){.api = &fl_api, .slot_size = SLOT};
	zassert_true(n_slines < MAX_SLINES);
	sline = &slines[n_slines++];
	memset(&slave, 0, sizeof(slave));
	memset(&sram, 0, sizeof(sram));
	zassert_ok(co_line_init(sline, "sline", sdev));
	zassert_ok(co_node_init(&slave, "slave", sline, &pgm_slave_od_def, &sram, SLAVE));
	zassert_ok(co_pgm_attach(&slave, &fl.flash));
	co_pgm_set_ind(&slave, pgm_ind, NULL);
	co_nmt_set_reset_ind(&slave, slave_reset, NULL);
	zassert_ok(co_line_start(sline, sstack, K_THREAD_STACK_SIZEOF(sstack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	zassert_ok(co_node_start(&slave));
}

static void after(void *unused)
{
	atomic_set(&cut_armed, 0);
	if (mline != NULL) {
		(void)co_line_stop(mline);
	}
	(void)co_line_stop(sline);
	(void)can_stop(mdev);
	(void)can_virtual_restore(mdev);
}

ZTEST_SUITE(co_pgm_threaded, NULL, suite_setup, before, after, NULL);

/* --- The cut -----------------------------------------------------------------------------------
 */

struct slave_view {
	struct co_pgm_image_info run;
	int slot;
	int verify; /* co_pgm_slot_verify() of that slot */
	uint32_t status;
	bool running;
};

static void look(struct slave_view *v)
{
	co_node_lock(&slave);
	zassert_ok(co_pgm_get_running(&slave, &v->run, &v->slot));
	v->verify = co_pgm_slot_verify(&fl.flash, (uint8_t)v->slot, NULL, NULL);
	v->status = co_pgm_flash_status(&slave);
	v->running = co_pgm_is_running(&slave);
	co_node_unlock(&slave);
}

static void cut_and_recover(enum cut_at kind, uint32_t byte, uint32_t status_after,
			    bool running_after)
{
	struct slave_view v;

	cut_kind = kind;
	cut_byte = byte;
	atomic_set(&cut_armed, 1);
	manager_up();
	zassert_ok(k_sem_take(&cut_sem, K_SECONDS(20)), "the cut point was never reached");
	manager_gone();
	zassert_equal(k_sem_take(&boot_sem, K_NO_WAIT), -EBUSY, "the boot ended before the cut");

	/*
	 * The slave gives up the transfer of a client that went silent, after its SDO server
	 * timeout; a loaded host may run its line thread late, so wait for the end of the
	 * download (1F57h no longer 01h) rather than for a fixed time.
	 */
	look(&v);
	for (int i = 0; i < GIVE_UP_MS / 10 && v.status == CO_PGM_FLASH_BUSY; i++) {
		k_msleep(10);
		look(&v);
	}
	zassert_equal(v.run.date, OLD_DATE, "the old image is the one in force");
	zassert_equal(v.run.time, OLD_TIME);
	zassert_equal(v.slot, 0);
	zassert_ok(v.verify, "and it verifies in the flash");
	zassert_equal(v.status, status_after, "1F57h %02Xh", v.status);
	zassert_equal(v.running, running_after);

	/* A restart of the slave (its boot from the flash) runs the old image. */
	zassert_ok(co_pgm_attach(&slave, &fl.flash));
	look(&v);
	zassert_equal(v.run.date, OLD_DATE);
	zassert_true(v.running);
	zassert_equal(v.status, CO_PGM_FLASH_OK);

	/* A later manager run completes the update. */
	manager_up();
	zassert_ok(k_sem_take(&boot_sem, K_SECONDS(30)), "no end of the boot");
	zassert_equal(boot_status, CO_MGR_ST_OK, "boot status %c", boot_status);
	look(&v);
	zassert_equal(v.run.date, NEW_DATE);
	zassert_equal(v.run.time, NEW_TIME);
	zassert_equal(v.slot, 1);
	zassert_ok(v.verify);
	zassert_true(v.running);
	zassert_equal(v.status, CO_PGM_FLASH_OK);
}

ZTEST(co_pgm_threaded, test_cut_mid_boot_at_the_reset)
{
	/* Before the software check: the program was never stopped. */
	cut_and_recover(CUT_AT_RESET, 0, CO_PGM_FLASH_OK, true);
}

ZTEST(co_pgm_threaded, test_cut_mid_boot_after_the_stop)
{
	/* The manager stopped the program and went: it stays stopped, the old image in force. */
	cut_and_recover(CUT_AT_STOPPED, 0, CO_PGM_FLASH_OK, false);
}

ZTEST(co_pgm_threaded, test_cut_mid_download)
{
	/* The first sub-block, the second, the middle, the last before the end request. */
	static const uint32_t at[] = {1U, 7U * 127U + 1U, IMAGE / 2U, IMAGE - 7U * 127U - 8U};

	for (size_t i = 0; i < ARRAY_SIZE(at); i++) {
		if (i > 0U) {
			after(NULL);
			before(NULL);
		}
		TC_PRINT("cut after %u of %u bytes\n", at[i], IMAGE);
		/* The slave's SDO server times out: an incomplete image, 1F57h 06h. */
		cut_and_recover(CUT_AT_BYTE, at[i], CO_PGM_FLASH_CRC, false);
	}
}

ZTEST(co_pgm_threaded, test_cut_after_the_verify)
{
	/*
	 * The last bytes (the end request): the image verifies, the manager never hears it and
	 * nobody starts it; the old one stays in force.
	 */
	cut_and_recover(CUT_AT_BYTE, IMAGE, CO_PGM_FLASH_OK, false);
}
