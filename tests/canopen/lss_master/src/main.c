/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS master (CiA 305) on a simulation line, simulated time: the master (node 1) and up to
 * 8 SafeLine LSS slaves share one line, so every request reaches the slaves and their answers
 * reach the master as on a bus. Frames the tests inject on 7E4h play slaves that answer
 * wrongly. Confirmations are recorded and checked with their time.
 */

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/lss.h>
#include <canopen/lss_master.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "co_bus.h"

#include "lss_test_od.h"

#define MASTER_ID 0x01
#define N_SLAVES  8
#define MS        1000ULL
#define TIMEOUT   CONFIG_CANOPEN_LSS_MASTER_TIMEOUT
#define FS_STEP   CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_TIMEOUT

/* 1018h of lss_test.eds; each slave gets its own serial number. */
#define VENDOR   0x12345678U
#define PRODUCT  0x00000042U
#define REVISION 0x00020001U

static struct {
	struct co_line line;
	/* Frames the line sent: count per kind, and the last few. */
	uint32_t n_req;  /* 7E5h */
	uint32_t n_ans;  /* 7E4h */
	uint32_t n_boot; /* 700h + n, data 0 */
	/* The last request. */
	struct can_frame req;

	struct co_node master;
	struct lss_test_od_ram master_ram;
	struct co_node slave[N_SLAVES];
	struct lss_test_od_ram slave_ram[N_SLAVES];
	uint32_t serial[N_SLAVES];

	/* Confirmations. */
	int n_con;
	int err;
	struct co_lss_master_result res;
	uint64_t con_at;
	/* A request to start from the confirmation (chained), or none. */
	bool chain;
} t;

/* Counts what the line sends (injected frames are not counted). */
static void tap(const struct can_frame *f, int from)
{
	if (from == CO_BUS_INJECTED) {
		return;
	}
	if (f->id == CO_LSS_MASTER_COB_ID) {
		t.req = *f;
		t.n_req++;
	} else if (f->id == CO_LSS_SLAVE_COB_ID) {
		t.n_ans++;
	} else if (f->id > 0x700 && f->id <= 0x77F && f->dlc == 1 && f->data[0] == 0) {
		t.n_boot++;
	}
}

static void con(struct co_node *node, int err, const struct co_lss_master_result *res,
		void *user_data)
{
	zassert_equal(node, &t.master);
	zassert_equal_ptr(user_data, &t);
	t.n_con++;
	t.err = err;
	t.res = *res;
	t.con_at = bus.now;
	if (t.chain) {
		t.chain = false;
		/* A confirmation may start the next request. */
		zassert_ok(co_lss_master_inquire_req(node, CO_LSS_CS_INQUIRE_NODE_ID, 0, con, &t));
	}
}

/* Boot the master and @p n slaves, all without node-ID unless @p configured. */
static void boot(int n, bool configured)
{
	memset(&t, 0, sizeof(t));
	co_bus_init();
	co_bus_attach(0, &t.line, "sim");
	bus.tap = tap;
	bus.no_log = true;
	zassert_ok(co_node_init(&t.master, "master", &t.line, &lss_test_od_def, &t.master_ram,
				MASTER_ID));
	for (int i = 0; i < n; i++) {
		uint8_t buf[4];

		zassert_ok(co_node_init(
			&t.slave[i], "slave", &t.line, &lss_test_od_def, &t.slave_ram[i],
			configured ? (uint8_t)(0x10 + i) : CO_NODE_ID_UNCONFIGURED));
		zassert_ok(co_node_start(&t.slave[i]));
		/* After the start, which loads the defaults. */
		t.serial[i] = 0x100U + (uint32_t)i;
		sys_put_le32(t.serial[i], buf);
		co_node_lock(&t.slave[i]);
		zassert_ok(
			co_od_write(co_node_od(&t.slave[i]), 0x1018, 4, buf, 4, CO_OD_WRITER_APP));
		co_node_unlock(&t.slave[i]);
	}
	zassert_ok(co_node_start(&t.master));
	co_bus_run_ms(1);
	t.n_req = t.n_ans = t.n_boot = 0;
}

static void set_serial(int i, uint32_t serial)
{
	uint8_t buf[4];

	t.serial[i] = serial;
	sys_put_le32(serial, buf);
	co_node_lock(&t.slave[i]);
	zassert_ok(co_od_write(co_node_od(&t.slave[i]), 0x1018, 4, buf, 4, CO_OD_WRITER_APP));
	co_node_unlock(&t.slave[i]);
}

static void inject_answer(uint8_t dlc, uint8_t cs, uint8_t b1, uint8_t b2)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_SLAVE_COB_ID, cs);
	f.dlc = dlc;
	f.data[1] = b1;
	f.data[2] = b2;
	co_bus_inject(&f);
}

static struct co_lss_address address_of(int i)
{
	return (struct co_lss_address){.part = {VENDOR, PRODUCT, REVISION, t.serial[i]}};
}

ZTEST_SUITE(co_lss_master, NULL, NULL, NULL, NULL, NULL);

/* --- Requests without an answer ---------------------------------------------------------- */

ZTEST(co_lss_master, test_switch_global_moves_every_slave)
{
	boot(2, true);
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_CONFIGURATION));
	co_bus_run_ms(1);
	zassert_equal(t.n_req, 1);
	zassert_equal(t.req.data[0], 0x04);
	zassert_equal(t.req.data[1], 0x01);
	zassert_equal(t.req.dlc, 8);
	zassert_equal(co_lss_get_state(&t.slave[0]), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(co_lss_get_state(&t.slave[1]), CO_LSS_STATE_CONFIGURATION);
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_WAITING));
	co_bus_run_ms(1);
	zassert_equal(co_lss_get_state(&t.slave[1]), CO_LSS_STATE_WAITING);
	zassert_equal(co_lss_master_switch_global(&t.master, 2), -EINVAL);
	zassert_equal(t.n_con, 0, "nothing to confirm");
}

ZTEST(co_lss_master, test_activate_bit_timing_frame)
{
	boot(0, true);
	zassert_ok(co_lss_master_activate_bit_timing(&t.master, 0x1234));
	co_bus_run_ms(1);
	zassert_equal(t.n_req, 1);
	zassert_mem_equal(t.req.data, ((uint8_t[8]){0x15, 0x34, 0x12}), 8);
}

/* --- Selective switch, configure, store, inquire ----------------------------------------- */

ZTEST(co_lss_master, test_switch_selective_selects_one_slave)
{
	struct co_lss_address a;

	boot(3, true);
	a = address_of(1);
	zassert_ok(co_lss_master_switch_selective_req(&t.master, &a, 0, con, &t));
	zassert_equal(co_lss_master_switch_selective_req(&t.master, &a, 0, con, &t), -EBUSY);
	co_bus_run_ms(1);
	zassert_equal(t.n_req, 4, "40h, 41h, 42h, 43h");
	zassert_equal(t.n_con, 1);
	zassert_ok(t.err);
	zassert_equal(co_lss_get_state(&t.slave[1]), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(co_lss_get_state(&t.slave[0]), CO_LSS_STATE_WAITING);
	zassert_equal(co_lss_get_state(&t.slave[2]), CO_LSS_STATE_WAITING);
	zassert_false(co_lss_master_busy(&t.master));
}

ZTEST(co_lss_master, test_switch_selective_without_answer_times_out)
{
	struct co_lss_address a;

	boot(2, true);
	a = address_of(0);
	a.part[3] = 0xDEAD;
	zassert_ok(co_lss_master_switch_selective_req(&t.master, &a, 0, con, &t));
	co_bus_run_ms(TIMEOUT - 1);
	zassert_equal(t.n_con, 0, "still waiting");
	co_bus_run_ms(2);
	zassert_equal(t.n_con, 1);
	zassert_equal(t.err, -ETIMEDOUT);
	zassert_equal(t.con_at, (uint64_t)TIMEOUT * MS + 1 * MS, "after exactly the timeout");
	/* A timeout of the request's own. */
	zassert_ok(co_lss_master_switch_selective_req(&t.master, &a, 7, con, &t));
	co_bus_run_ms(6);
	zassert_equal(t.n_con, 1);
	co_bus_run_ms(1);
	zassert_equal(t.n_con, 2);
	zassert_equal(t.err, -ETIMEDOUT);
}

ZTEST(co_lss_master, test_config_node_id_store_and_inquire)
{
	static struct co_storage_ram ram_be;
	static uint8_t medium[64];
	uint8_t cs;

	boot(1, false);
	memset(medium, 0, sizeof(medium));
	zassert_ok(co_storage_ram_init(&ram_be, medium, sizeof(medium)));
	zassert_equal(co_lss_store_attach(&t.slave[0], &ram_be.be, NULL), -ENOENT);
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_CONFIGURATION));

	for (cs = CO_LSS_CS_INQUIRE_VENDOR; cs <= CO_LSS_CS_INQUIRE_NODE_ID; cs++) {
		static const uint32_t expect[] = {VENDOR, PRODUCT, REVISION, 0x100, 0xFF};

		zassert_ok(co_lss_master_inquire_req(&t.master, cs, 0, con, &t));
		co_bus_run_ms(1);
		zassert_ok(t.err);
		zassert_equal(t.res.cs, cs);
		zassert_equal(t.res.value, expect[cs - CO_LSS_CS_INQUIRE_VENDOR], "cs %02x", cs);
	}
	zassert_equal(t.n_con, 5);
	zassert_equal(co_lss_master_inquire_req(&t.master, 0x5F, 0, con, &t), -EINVAL);

	zassert_equal(co_lss_master_config_node_id_req(&t.master, 0, 0, con, &t), -EINVAL);
	zassert_equal(co_lss_master_config_node_id_req(&t.master, 0x80, 0, con, &t), -EINVAL);
	zassert_ok(co_lss_master_config_node_id_req(&t.master, 0x0A, 0, con, &t));
	co_bus_run_ms(1);
	zassert_ok(t.err);
	zassert_equal(t.res.lss_err, CO_LSS_ERR_OK);
	zassert_equal(co_node_pending_id(&t.slave[0]), 0x0A);

	zassert_ok(co_lss_master_store_req(&t.master, 0, con, &t));
	co_bus_run_ms(1);
	zassert_ok(t.err);
	zassert_equal(t.res.cs, CO_LSS_CS_STORE);

	/* Back to waiting: the slave boots with its new node-ID. */
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_WAITING));
	co_bus_run_ms(1);
	zassert_equal(co_node_id(&t.slave[0]), 0x0A);
	zassert_equal(t.n_boot, 1);
}

ZTEST(co_lss_master, test_slave_error_codes_are_confirmed_as_eremoteio)
{
	boot(1, true);
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_CONFIGURATION));
	/* No medium attached: storing not supported. */
	zassert_ok(co_lss_master_store_req(&t.master, 0, con, &t));
	co_bus_run_ms(1);
	zassert_equal(t.err, -EREMOTEIO);
	zassert_equal(t.res.lss_err, CO_LSS_ERR_STORE_SUPPORTED);
	/* A simulation line has no controller: bit timing not supported. */
	zassert_ok(co_lss_master_config_bit_timing_req(&t.master, 0, 2, 0, con, &t));
	co_bus_run_ms(1);
	zassert_equal(t.err, -EREMOTEIO);
	zassert_equal(t.res.cs, CO_LSS_CS_CONFIG_BIT_TIMING);
	zassert_equal(t.res.lss_err, CO_LSS_ERR_BIT_TIMING);
	zassert_equal(t.n_con, 2);
}

/* --- Identification ---------------------------------------------------------------------- */

ZTEST(co_lss_master, test_identify_remote_counts_answers_in_range)
{
	boot(4, true);
	zassert_ok(co_lss_master_identify_remote_req(&t.master, VENDOR, PRODUCT, 0, UINT32_MAX,
						     0x101, 0x102, 0, con, &t));
	co_bus_run_ms(1);
	zassert_equal(t.n_req, 6, "46h..4Bh");
	zassert_equal(t.n_con, 0, "waits the whole timeout: any number may answer");
	co_bus_run_ms(TIMEOUT);
	zassert_equal(t.n_con, 1);
	zassert_ok(t.err);
	zassert_equal(t.res.answers, 2, "serials 101h and 102h");

	zassert_ok(co_lss_master_identify_remote_req(&t.master, VENDOR, PRODUCT + 1, 0, UINT32_MAX,
						     0, UINT32_MAX, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ENODEV);
	zassert_equal(co_lss_master_identify_remote_req(&t.master, VENDOR, PRODUCT, 2, 1, 0, 1, 0,
							con, &t),
		      -EINVAL);
}

ZTEST(co_lss_master, test_identify_non_configured)
{
	boot(3, false);
	zassert_ok(co_lss_master_identify_non_configured_req(&t.master, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_ok(t.err);
	zassert_equal(t.res.answers, 3);

	boot(3, true);
	zassert_ok(co_lss_master_identify_non_configured_req(&t.master, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ENODEV);
	zassert_equal(t.res.answers, 0);
}

/* --- Timeouts, wrong answers, cancel ----------------------------------------------------- */

ZTEST(co_lss_master, test_every_answered_request_times_out_without_answer)
{
	boot(1, true); /* the slave stays in waiting: it answers none of these */
	zassert_ok(co_lss_master_config_node_id_req(&t.master, 5, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ETIMEDOUT);
	zassert_ok(co_lss_master_config_bit_timing_req(&t.master, 0, 0, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ETIMEDOUT);
	zassert_ok(co_lss_master_store_req(&t.master, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ETIMEDOUT);
	zassert_ok(co_lss_master_inquire_req(&t.master, CO_LSS_CS_INQUIRE_SERIAL, 0, con, &t));
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.err, -ETIMEDOUT);
	zassert_equal(t.n_con, 4);
	{
		struct co_lss_master_stats st;

		co_lss_master_get_stats(&t.master, &st);
		zassert_equal(st.timeouts, 4);
		zassert_equal(st.requests, 4);
	}
}

ZTEST(co_lss_master, test_wrong_answers_are_ignored)
{
	struct co_lss_master_stats st;

	boot(0, true);
	zassert_ok(co_lss_master_config_node_id_req(&t.master, 5, 0, con, &t));
	co_bus_run_ms(1);
	inject_answer(7, CO_LSS_CS_CONFIG_NODE_ID, 0, 0);  /* DLC 7 */
	inject_answer(8, CO_LSS_CS_STORE, 0, 0);           /* another request's answer */
	inject_answer(8, CO_LSS_CS_INQUIRE_NODE_ID, 5, 0); /* another request's answer */
	inject_answer(8, CO_LSS_CS_IDENT_SLAVE, 0, 0);     /* a fastscan answer */
	zassert_equal(t.n_con, 0, "still waiting for 11h");
	inject_answer(8, CO_LSS_CS_CONFIG_NODE_ID, CO_LSS_ERR_NODE_ID_RANGE, 0);
	zassert_equal(t.n_con, 1);
	zassert_equal(t.err, -EREMOTEIO);
	zassert_equal(t.res.lss_err, CO_LSS_ERR_NODE_ID_RANGE);
	/* An answer while nothing runs. */
	inject_answer(8, CO_LSS_CS_CONFIG_NODE_ID, 0, 0);
	zassert_equal(t.n_con, 1);
	co_lss_master_get_stats(&t.master, &st);
	zassert_equal(st.ignored, 5);
	zassert_equal(st.answers, 1);
}

ZTEST(co_lss_master, test_cancel_reset_and_chained_request)
{
	boot(1, true);
	zassert_equal(co_lss_master_cancel(&t.master), -EALREADY);
	zassert_ok(co_lss_master_store_req(&t.master, 0, con, &t));
	zassert_equal(co_lss_master_switch_global(&t.master, 1), -EBUSY);
	zassert_ok(co_lss_master_cancel(&t.master));
	zassert_equal(t.n_con, 1, "confirmed at once");
	zassert_equal(t.err, -ECANCELED);
	co_bus_run_ms(TIMEOUT + 1);
	zassert_equal(t.n_con, 1, "and only once");

	/* A reset of the master's node ends the request. */
	zassert_ok(co_lss_master_store_req(&t.master, 0, con, &t));
	zassert_ok(co_nmt_req(&t.master, CO_NMT_CS_RESET_COMMUNICATION));
	co_bus_run_ms(1);
	zassert_equal(t.n_con, 2);
	zassert_equal(t.err, -ECANCELED);

	/* The confirmation starts the next request. */
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_CONFIGURATION));
	t.chain = true;
	zassert_ok(co_lss_master_inquire_req(&t.master, CO_LSS_CS_INQUIRE_VENDOR, 0, con, &t));
	co_bus_run_ms(1);
	zassert_equal(t.n_con, 4);
	zassert_ok(t.err);
	zassert_equal(t.res.cs, CO_LSS_CS_INQUIRE_NODE_ID);
	zassert_equal(t.res.value, 0x10);
}

/* --- Fastscan ---------------------------------------------------------------------------- */

/* Run one fastscan to its confirmation. */
static int fastscan(const struct co_lss_address *known, uint8_t mask)
{
	int n = t.n_con;

	zassert_ok(co_lss_master_fastscan_req(&t.master, known, mask, 0, con, &t));
	for (int i = 0; i < 1000 && t.n_con == n; i++) {
		co_bus_run_ms(FS_STEP);
	}
	zassert_equal(t.n_con, n + 1, "fastscan confirmed");
	return t.err;
}

ZTEST(co_lss_master, test_fastscan_of_8_devices_with_random_serials)
{
	bool found[N_SLAVES] = {false};
	uint32_t prev_serial = 0;

	boot(N_SLAVES, false);
	srand(0x5AFE);
	for (int i = 0; i < N_SLAVES; i++) {
		uint32_t s;
		bool dup;

		do {
			s = ((uint32_t)rand() << 16) ^ (uint32_t)rand();
			dup = false;
			for (int j = 0; j < i; j++) {
				dup = dup || t.serial[j] == s;
			}
		} while (dup);
		set_serial(i, s);
	}

	for (int n = 0; n < N_SLAVES; n++) {
		uint64_t t0 = bus.now;
		uint32_t req0 = t.n_req;
		int who = -1;

		zassert_ok(fastscan(NULL, 0), "device %d", n);
		zassert_equal(t.res.frames, t.n_req - req0);
		zassert_equal(t.res.frames, 133, "1 + 4 x 33 frames per device");
		zassert_equal(t.con_at - t0, 133ULL * FS_STEP * MS, "each step waits its timeout");
		zassert_equal(t.res.address.part[0], VENDOR);
		zassert_equal(t.res.address.part[1], PRODUCT);
		zassert_equal(t.res.address.part[2], REVISION);
		for (int i = 0; i < N_SLAVES; i++) {
			if (t.serial[i] == t.res.address.part[3]) {
				who = i;
			}
		}
		zassert_true(who >= 0, "a device with serial %08x", t.res.address.part[3]);
		zassert_false(found[who], "found once");
		zassert_true(t.res.address.part[3] > prev_serial || n == 0,
			     "the lowest address first");
		prev_serial = t.res.address.part[3];
		found[who] = true;
		zassert_equal(co_lss_get_state(&t.slave[who]), CO_LSS_STATE_CONFIGURATION);

		zassert_ok(co_lss_master_config_node_id_req(&t.master, (uint8_t)(0x20 + n), 0, con,
							    &t));
		co_bus_run_ms(1);
		zassert_ok(t.err);
		zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_WAITING));
		co_bus_run_ms(1);
		zassert_equal(co_node_id(&t.slave[who]), 0x20 + n, "booted with its node-ID");
	}
	zassert_equal(t.n_boot, N_SLAVES, "every device sent its boot-up");
	zassert_equal(fastscan(NULL, 0), -ENODEV, "nobody left");
	zassert_equal(t.res.frames, 1, "the probe only");
}

ZTEST(co_lss_master, test_fastscan_with_known_parts)
{
	struct co_lss_address known = {.part = {VENDOR, PRODUCT, REVISION, 0}};

	boot(3, false);
	set_serial(1, 0x42);
	known.part[3] = 0x100; /* slave 0 */
	zassert_ok(fastscan(&known, BIT(0) | BIT(1) | BIT(2) | BIT(3)));
	zassert_equal(t.res.frames, 5, "probe and four verifies");
	zassert_equal(t.res.address.part[3], 0x100, "not the lowest address: the known one");
	zassert_equal(co_lss_get_state(&t.slave[0]), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(co_lss_get_state(&t.slave[1]), CO_LSS_STATE_WAITING);
	zassert_ok(co_lss_master_switch_global(&t.master, CO_LSS_MODE_WAITING));
	co_bus_run_ms(1);

	/* Vendor-ID and product known: 1 + 2 + 2 x 33. */
	zassert_ok(fastscan(&known, BIT(0) | BIT(1)));
	zassert_equal(t.res.frames, 69);
	zassert_equal(t.res.address.part[3], 0x42);
	zassert_equal(co_lss_master_fastscan_req(&t.master, NULL, BIT(0), 0, con, &t), -EINVAL);
	zassert_equal(co_lss_master_fastscan_req(&t.master, &known, 0x10, 0, con, &t), -EINVAL);
}

ZTEST(co_lss_master, test_fastscan_restarts_then_gives_up)
{
	struct co_lss_address known = {.part = {VENDOR, PRODUCT, REVISION, 0xDEAD}};

	boot(2, false);
	/* A known serial number no device has: every verify of it fails. */
	zassert_equal(fastscan(&known, 0x0F), -EIO);
	zassert_equal(t.res.restarts, CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_RESTARTS);
	zassert_equal(t.res.frames, 5 * (CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_RESTARTS + 1));
	zassert_equal(co_lss_get_state(&t.slave[0]), CO_LSS_STATE_WAITING);
	zassert_equal(co_lss_get_state(&t.slave[1]), CO_LSS_STATE_WAITING);

	/* The slave being scanned gets a node-ID on the way: the scan restarts and ends. */
	zassert_ok(co_lss_master_fastscan_req(&t.master, NULL, 0, 0, con, &t));
	co_bus_run_ms(FS_STEP * 40); /* into the product code */
	zassert_ok(co_node_set_pending_id(&t.slave[0], 0x30));
	zassert_ok(co_node_set_pending_id(&t.slave[1], 0x31));
	for (int i = 0; i < 200 && t.n_con == 1; i++) {
		co_bus_run_ms(FS_STEP);
	}
	zassert_equal(t.n_con, 2);
	zassert_equal(t.err, -ENODEV, "the new probe finds nobody");
	zassert_equal(t.res.restarts, 1);
}

ZTEST(co_lss_master, test_blocking_calls_refuse_where_they_would_deadlock)
{
	struct co_lss_master_result res;

	boot(1, true);
	zassert_equal(co_lss_master_store(&t.master, K_NO_WAIT, &res), -EINVAL);
	zassert_equal(co_lss_master_store(NULL, K_MSEC(10), &res), -EINVAL);
	co_node_lock(&t.slave[0]);
	zassert_equal(co_lss_master_store(&t.master, K_MSEC(10), &res), -EDEADLK,
		      "a node mutex of the line held");
	co_node_unlock(&t.slave[0]);
	zassert_false(co_lss_master_busy(&t.master), "nothing started");
}
