/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS slave (CiA 305), driven frame by frame on a simulation line (no thread, simulated
 * time). Requests go in on 7E5h; every frame the nodes send lands in `sim.sent`. The tests
 * named test_NN_ check the numbered frame-level behaviours of doc/lss.md ("Behaviours and
 * their tests"); the others cover the error paths and the decisions listed there.
 *
 * The simulation line has no CAN controller, so the tests give the slave a bit rate handler
 * that plays one: it takes 20 kbit/s to 1 Mbit/s, and "stopping" it makes the line's sink
 * push back, so frames wait in the line's TX queue as they would in a stopped controller.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/lss.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "co_sim.h"
#include "lss_peer_od.h"
#include "lss_test_od.h"

#define NODE_ID 0x05
#define MS      1000ULL
#define MAX_EV  16
#define MAX_BR  16

/* The LSS address of lss_test.eds, and the peer's serial number (lss_peer.eds). */
#define VENDOR      0x12345678U
#define PRODUCT     0x00000042U
#define REVISION    0x00020001U
#define SERIAL      0x0000BEEFU
#define PEER_SERIAL 0x0000BEF7U

#define LSS_REQ 0x7E5
#define LSS_ANS 0x7E4

struct lss_ev {
	uint8_t node; /* 0: t.node, 1: t.peer */
	uint8_t from;
	uint8_t to;
	bool fastscan;
};

struct br_step {
	enum co_lss_bitrate_step step;
	uint32_t bitrate;
	uint64_t at;
};

static struct {
	struct co_node node;
	struct lss_test_od_ram ram;
	struct co_node peer;
	struct lss_peer_od_ram peer_ram;
	struct co_listener listener;
	struct co_listener peer_listener;
	struct lss_ev ev[MAX_EV];
	int n_ev;
	int n_ind;
	struct br_step br[MAX_BR];
	int n_br;
	/* The simulated controller's answer to CO_LSS_BITRATE_SWITCH. */
	int switch_result;
} t;

/* A medium survives the per-test reset, as it survives a power cycle. */
static struct co_storage_ram ram_be;
static uint8_t medium[64];

/* --- Harness -------------------------------------------------------------------------------- */

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	zassert_true(t.n_ev < MAX_EV, "too many LSS events");
	zassert_equal(ev->type, CO_EV_LSS);
	t.ev[t.n_ev++] = (struct lss_ev){
		.node = (uint8_t)(uintptr_t)user_data,
		.from = ev->lss.from,
		.to = ev->lss.to,
		.fastscan = ev->lss.fastscan,
	};
	return 0;
}

static void on_ind(struct co_node *node, enum co_lss_state from, enum co_lss_state to,
		   void *user_data)
{
	/* The indication comes before the event of the same change. */
	zassert_equal(t.n_ind, t.n_ev, "indication first");
	t.n_ind++;
}

/* The simulated controller: 20 kbit/s .. 1 Mbit/s; stopped, it holds every frame back. */
static int sim_controller(struct co_node *node, enum co_lss_bitrate_step step, uint32_t bitrate,
			  void *user_data)
{
	zassert_true(t.n_br < MAX_BR);
	t.br[t.n_br++] = (struct br_step){.step = step, .bitrate = bitrate, .at = sim.now};
	switch (step) {
	case CO_LSS_BITRATE_CHECK:
		return bitrate >= 20000U && bitrate <= 1000000U ? 0 : -ENOTSUP;
	case CO_LSS_BITRATE_SILENCE:
		sim.tx_busy = true;
		return 0;
	case CO_LSS_BITRATE_SWITCH:
		return t.switch_result;
	case CO_LSS_BITRATE_RESUME:
		sim.tx_busy = false;
		return 0;
	default:
		return -EINVAL;
	}
}

static void node_up(struct co_node *node, const struct co_od_def *def, void *ram, uint8_t node_id,
		    struct co_listener *l, uintptr_t which)
{
	zassert_ok(co_node_init(node, which == 0U ? "dut" : "peer", &sim.line, def, ram, node_id));
	co_listener_init(l, "test", CO_EV_BIT(CO_EV_LSS), on_event, (void *)which);
	zassert_ok(co_node_listener_add(node, l));
}

/* One node on a fresh line: initialised, optionally given the medium, started. */
static int boot(uint8_t node_id, const struct co_storage_backend *be, struct co_lss_config *cfg)
{
	int attached = 0;

	memset(&t, 0, sizeof(t));
	co_sim_init();
	node_up(&t.node, &lss_test_od_def, &t.ram, node_id, &t.listener, 0U);
	co_lss_set_ind(&t.node, on_ind, NULL);
	co_lss_set_bitrate_handler(&t.node, sim_controller, NULL);
	if (be != NULL) {
		attached = co_lss_store_attach(&t.node, be, cfg);
	}
	zassert_ok(co_node_start(&t.node));
	return attached;
}

/* Two nodes on one line: the test device and its peer (another serial number). */
static void boot_two(uint8_t node_id, uint8_t peer_id)
{
	(void)boot(node_id, NULL, NULL);
	node_up(&t.peer, &lss_peer_od_def, &t.peer_ram, peer_id, &t.peer_listener, 1U);
	zassert_ok(co_node_start(&t.peer));
	co_sim_run_until(sim.now); /* boot-ups reach the other node */
	sim.n_sent = 0;
}

static void *suite_setup(void)
{
	zassert_ok(co_storage_ram_init(&ram_be, medium, sizeof(medium)));
	return NULL;
}

static void before(void *f)
{
	memset(medium, 0xff, sizeof(medium));
	(void)boot(NODE_ID, NULL, NULL);
	sim.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_lss, NULL, suite_setup, before, NULL, NULL);

/* --- Requests and answers ------------------------------------------------------------------- */

static void req(uint8_t b0, uint8_t b1, uint8_t b2, uint8_t b3, uint8_t b4, uint8_t b5, uint8_t b6,
		uint8_t b7)
{
	const uint8_t d[8] = {b0, b1, b2, b3, b4, b5, b6, b7};

	co_sim_rx(LSS_REQ, 8, d);
}

static void req_cs(uint8_t cs, uint8_t b1, uint8_t b2)
{
	req(cs, b1, b2, 0, 0, 0, 0, 0);
}

static void req_u32(uint8_t cs, uint32_t v)
{
	req(cs, (uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24), 0, 0, 0);
}

static void req_fastscan(uint32_t id, uint8_t bit, uint8_t sub, uint8_t next)
{
	req(CO_LSS_CS_FASTSCAN, (uint8_t)id, (uint8_t)(id >> 8), (uint8_t)(id >> 16),
	    (uint8_t)(id >> 24), bit, sub, next);
}

static void select_node(uint32_t serial)
{
	req_u32(CO_LSS_CS_SWITCH_SEL_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_SWITCH_SEL_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_SWITCH_SEL_REVISION, REVISION);
	req_u32(CO_LSS_CS_SWITCH_SEL_SERIAL, serial);
}

static void identify(uint32_t rev_lo, uint32_t rev_hi, uint32_t ser_lo, uint32_t ser_hi)
{
	req_u32(CO_LSS_CS_IDENT_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_IDENT_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_IDENT_REVISION_LOW, rev_lo);
	req_u32(CO_LSS_CS_IDENT_REVISION_HIGH, rev_hi);
	req_u32(CO_LSS_CS_IDENT_SERIAL_LOW, ser_lo);
	req_u32(CO_LSS_CS_IDENT_SERIAL_HIGH, ser_hi);
}

/* Frame @p i is an LSS answer of 8 bytes with exactly these bytes. */
static void expect_frame(int i, uint8_t b0, uint8_t b1, uint8_t b2, uint8_t b3, uint8_t b4)
{
	const uint8_t want[8] = {b0, b1, b2, b3, b4, 0, 0, 0};

	zassert_true(i < sim.n_sent, "frame %d not sent (%d frames)", i, sim.n_sent);
	zassert_equal(sim.sent[i].id, LSS_ANS, "frame %d on %03x", i, sim.sent[i].id);
	zassert_equal(sim.sent[i].dlc, 8, "every answer has 8 bytes");
	zassert_mem_equal(sim.sent[i].data, want, 8, "frame %d: %02x %02x %02x %02x %02x", i,
			  sim.sent[i].data[0], sim.sent[i].data[1], sim.sent[i].data[2],
			  sim.sent[i].data[3], sim.sent[i].data[4]);
}

static void expect_answer(int i, uint8_t cs, uint8_t b1, uint8_t b2)
{
	expect_frame(i, cs, b1, b2, 0, 0);
}

/* Send one request in configuration state and check its single answer. */
static void ask(uint8_t cs, uint8_t b1, uint8_t b2, uint8_t err)
{
	sim.n_sent = 0;
	req_cs(cs, b1, b2);
	zassert_equal(sim.n_sent, 1, "%02x %02x %02x: one answer", cs, b1, b2);
	expect_answer(0, cs, err, 0);
}

static int count_id(uint32_t id)
{
	int n = 0;

	for (int i = 0; i < sim.n_sent; i++) {
		n += sim.sent[i].id == id ? 1 : 0;
	}
	return n;
}

static void to_configuration(void)
{
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
}

/* --- 22..28: a configured node (05h) ---------------------------------------------------------- */

ZTEST(co_lss, test_22_switch_global_is_silent_then_inquire_node_id_answers)
{
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	zassert_equal(sim.n_sent, 0, "switch state global has no answer");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x5E, NODE_ID, 0);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL, "NMT untouched");
}

ZTEST(co_lss, test_23_waiting_state_answers_no_configuration_request)
{
	to_configuration();
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	req_cs(CO_LSS_CS_CONFIG_NODE_ID, 0x0A, 0);
	req_cs(CO_LSS_CS_INQUIRE_VENDOR, 0, 0);
	zassert_equal(sim.n_sent, 0, "no answer in waiting");
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	zassert_equal(co_node_id(&t.node), NODE_ID, "11h in waiting configured nothing");
}

ZTEST(co_lss, test_24_switch_selective_addresses_one_node_in_order)
{
	select_node(SERIAL);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x44, 0, 0);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);

	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	sim.n_sent = 0;
	select_node(SERIAL + 1U);
	zassert_equal(sim.n_sent, 0, "a wrong serial number selects nothing");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);

	/* 41h before 40h: the sequence never started. */
	req_u32(CO_LSS_CS_SWITCH_SEL_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_SWITCH_SEL_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_SWITCH_SEL_REVISION, REVISION);
	req_u32(CO_LSS_CS_SWITCH_SEL_SERIAL, SERIAL);
	zassert_equal(sim.n_sent, 0, "out of order selects nothing");
	/* 42h skipped. */
	req_u32(CO_LSS_CS_SWITCH_SEL_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_SWITCH_SEL_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_SWITCH_SEL_SERIAL, SERIAL);
	zassert_equal(sim.n_sent, 0);
	/* A switch state global in the middle restarts the sequence. */
	req_u32(CO_LSS_CS_SWITCH_SEL_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_SWITCH_SEL_PRODUCT, PRODUCT);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	req_u32(CO_LSS_CS_SWITCH_SEL_REVISION, REVISION);
	req_u32(CO_LSS_CS_SWITCH_SEL_SERIAL, SERIAL);
	zassert_equal(sim.n_sent, 0);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);

	/* A complete sequence after all that still selects. */
	select_node(SERIAL);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x44, 0, 0);
}

ZTEST(co_lss, test_25_configure_node_id_accepts_1_to_127_and_ffh)
{
	to_configuration();
	ask(0x11, 0x80, 0, CO_LSS_ERR_NODE_ID_RANGE);
	ask(0x11, 0x00, 0, CO_LSS_ERR_NODE_ID_RANGE);
	ask(0x11, 0xFE, 0, CO_LSS_ERR_NODE_ID_RANGE);
	ask(0x11, 0x05, 0, CO_LSS_ERR_OK);
	ask(0x11, 0x7F, 0, CO_LSS_ERR_OK);
	ask(0x11, 0x01, 0, CO_LSS_ERR_OK);
	ask(0x11, 0xFF, 0, CO_LSS_ERR_OK);
	/* Pending only: the active node-ID is still 05h. */
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	expect_answer(0, 0x5E, NODE_ID, 0);
}

ZTEST(co_lss, test_26_configure_bit_timing_table_0)
{
	to_configuration();
	ask(0x13, 0x00, 0x02, CO_LSS_ERR_OK);
	zassert_equal(t.n_br, 1);
	zassert_equal(t.br[0].step, CO_LSS_BITRATE_CHECK);
	zassert_equal(t.br[0].bitrate, 500000U, "index 2 is 500 kbit/s");
	ask(0x13, 0x01, 0x02, CO_LSS_ERR_BIT_TIMING);
	ask(0x13, 0x80, 0x02, CO_LSS_ERR_BIT_TIMING);
	if (IS_ENABLED(CONFIG_CANOPEN_LSS_BIT_TIMING_INDEX5_100K)) {
		ask(0x13, 0x00, 0x05, CO_LSS_ERR_OK);
		zassert_equal(t.br[t.n_br - 1].bitrate, 100000U);
	} else {
		ask(0x13, 0x00, 0x05, CO_LSS_ERR_BIT_TIMING);
	}
	ask(0x13, 0x00, 0x0A, CO_LSS_ERR_BIT_TIMING);
	ask(0x13, 0x00, 0x09, CO_LSS_ERR_BIT_TIMING); /* automatic detection */
	ask(0x13, 0x00, 0xFF, CO_LSS_ERR_BIT_TIMING);

	/* Every rate of the table the controller takes; 10 kbit/s it does not. */
	static const uint32_t rates[] = {1000000U, 800000U, 500000U, 250000U, 125000U,
					 0U,       50000U,  20000U,  10000U};

	for (uint8_t i = 0; i < ARRAY_SIZE(rates); i++) {
		if (rates[i] == 0U) {
			continue;
		}
		t.n_br = 0;
		ask(0x13, 0x00, i, rates[i] >= 20000U ? CO_LSS_ERR_OK : CO_LSS_ERR_BIT_TIMING);
		zassert_equal(t.n_br, 1);
		zassert_equal(t.br[0].bitrate, rates[i], "index %u", i);
	}
}

ZTEST(co_lss, test_26_bit_timing_not_supported_by_a_line_without_controller)
{
	/* No handler: the simulation line has no CAN device to switch. */
	co_lss_set_bitrate_handler(&t.node, NULL, NULL);
	to_configuration();
	ask(0x13, 0x00, 0x02, CO_LSS_ERR_BIT_TIMING);
	ask(0x13, 0x00, 0x00, CO_LSS_ERR_BIT_TIMING);
}

ZTEST(co_lss, test_27_store_configuration_and_boot_with_it)
{
	struct co_lss_config cfg;

	zassert_equal(co_lss_store_attach(&t.node, &ram_be.be, NULL), -ENOENT, "blank medium");
	to_configuration();
	ask(0x11, 0x0A, 0, CO_LSS_ERR_OK);
	ask(0x13, 0x00, 0x03, CO_LSS_ERR_OK);
	ask(0x17, 0x00, 0x00, CO_LSS_ERR_OK);

	/* Power cycle: the node is built with 05h, the medium says 0Ah and 250 kbit/s. */
	zassert_ok(boot(NODE_ID, &ram_be.be, &cfg));
	zassert_equal(cfg.node_id, 0x0A);
	zassert_equal(cfg.bit_timing_index, 3);
	zassert_equal(cfg.bitrate, 250000U);
	zassert_equal(co_node_id(&t.node), 0x0A);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x70A, "boot-up with the stored node-ID");

	/* Stored again (seq 2, the other slot), then FFh: the node comes up without node-ID. */
	to_configuration();
	ask(0x11, 0xFF, 0, CO_LSS_ERR_OK);
	ask(0x17, 0x00, 0x00, CO_LSS_ERR_OK);
	zassert_ok(boot(NODE_ID, &ram_be.be, &cfg));
	zassert_equal(cfg.node_id, CO_NODE_ID_UNCONFIGURED);
	zassert_equal(cfg.bit_timing_index, 3, "the bit timing was stored again");
	zassert_equal(co_node_id(&t.node), CO_NODE_ID_UNCONFIGURED);
	co_sim_run_until(sim.now + 200 * MS);
	zassert_equal(sim.n_sent, 0, "no boot-up, no heartbeat");
}

ZTEST(co_lss, test_27_store_without_medium_is_not_supported)
{
	to_configuration();
	ask(0x17, 0x00, 0x00, CO_LSS_ERR_STORE_SUPPORTED);
	zassert_equal(co_lss_store_attach(&t.node, &ram_be.be, NULL), -ENOENT);
	ask(0x17, 0x00, 0x00, CO_LSS_ERR_OK);
	zassert_ok(co_lss_store_attach(&t.node, NULL, NULL), "detached");
	ask(0x17, 0x00, 0x00, CO_LSS_ERR_STORE_SUPPORTED);
}

/* A medium that takes @p budget more bytes, then fails: a write cut off (power loss). */
static struct {
	struct co_storage_backend be;
	int budget; /* < 0: never fails */
	bool failed;
} cut;

static int cut_read(const struct co_storage_backend *be, uint32_t off, void *buf, size_t len)
{
	return ram_be.be.api->read(&ram_be.be, off, buf, len);
}

static int cut_write(const struct co_storage_backend *be, uint32_t off, const void *buf, size_t len)
{
	if (cut.failed) {
		return -EIO;
	}
	if (cut.budget >= 0 && (size_t)cut.budget < len) {
		(void)ram_be.be.api->write(&ram_be.be, off, buf, (size_t)cut.budget);
		cut.budget = 0;
		cut.failed = true;
		return -EIO;
	}
	if (cut.budget >= 0) {
		cut.budget -= (int)len;
	}
	return ram_be.be.api->write(&ram_be.be, off, buf, len);
}

static int cut_sync(const struct co_storage_backend *be)
{
	return cut.failed ? -EIO : 0;
}

static uint32_t cut_size(const struct co_storage_backend *be)
{
	return ram_be.be.api->size(&ram_be.be);
}

static const struct co_storage_backend_api cut_api = {
	.read = cut_read,
	.write = cut_write,
	.sync = cut_sync,
	.size = cut_size,
};

ZTEST(co_lss, test_27_store_write_failure_answers_2_and_keeps_the_old_record)
{
	struct co_lss_config cfg;
	int full = -1;

	cut.be.api = &cut_api;
	/* Generation 1 (0Ah) in force; then generation 2 (0Bh) cut after 0, 1, 2, ... bytes. */
	for (int budget = 0; full < 0; budget++) {
		zassert_true(budget < 64, "the store never completed");
		memset(medium, 0xff, sizeof(medium));
		(void)boot(NODE_ID, &ram_be.be, NULL);
		to_configuration();
		ask(0x11, 0x0A, 0, CO_LSS_ERR_OK);
		ask(0x17, 0x00, 0x00, CO_LSS_ERR_OK);

		cut.budget = budget;
		cut.failed = false;
		zassert_ok(co_lss_store_attach(&t.node, &cut.be, NULL));
		ask(0x11, 0x0B, 0, CO_LSS_ERR_OK);
		sim.n_sent = 0;
		req_cs(CO_LSS_CS_STORE, 0, 0);
		zassert_equal(sim.n_sent, 1);
		if (sim.sent[0].data[1] == CO_LSS_ERR_OK) {
			full = budget;
		} else {
			expect_answer(0, 0x17, CO_LSS_ERR_STORE_MEDIUM, 0);
		}

		zassert_ok(boot(NODE_ID, &ram_be.be, &cfg), "budget %d", budget);
		zassert_equal(cfg.node_id, full < 0 ? 0x0A : 0x0B, "budget %d: node-ID %02x",
			      budget, cfg.node_id);
	}
	zassert_equal(full, 20, "a store writes 4 + 12 + 4 bytes");
}

ZTEST(co_lss, test_28_inquire_identity_answers_1018h)
{
	to_configuration();
	static const struct {
		uint8_t cs;
		uint32_t v;
	} q[] = {{0x5A, VENDOR}, {0x5B, PRODUCT}, {0x5C, REVISION}, {0x5D, SERIAL}};

	for (size_t i = 0; i < ARRAY_SIZE(q); i++) {
		sim.n_sent = 0;
		req_cs(q[i].cs, 0, 0);
		zassert_equal(sim.n_sent, 1);
		expect_frame(0, q[i].cs, (uint8_t)q[i].v, (uint8_t)(q[i].v >> 8),
			     (uint8_t)(q[i].v >> 16), (uint8_t)(q[i].v >> 24));
	}
}

/* --- 29..30: node-ID change ------------------------------------------------------------------ */

ZTEST(co_lss, test_29_unconfigured_node_boots_with_the_node_id_lss_gave_it)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	co_sim_nmt(CO_NMT_CS_START, 0);
	co_sim_run_until(300 * MS);
	zassert_equal(sim.n_sent, 0, "no boot-up, no heartbeat");
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_INITIALISING);

	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	ask(0x11, 0x0A, 0, CO_LSS_ERR_OK);
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x70A, "boot-up on 700h + new node-ID");
	zassert_equal(sim.sent[0].dlc, 1);
	zassert_equal(sim.sent[0].data[0], 0x00);
	zassert_equal(co_node_id(&t.node), 0x0A);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	co_sim_run_until(sim.now + 60 * MS);
	zassert_equal(sim.n_sent, 2);
	zassert_equal(sim.sent[1].id, 0x70A, "heartbeat");
	zassert_equal(sim.sent[1].data[0], 0x7F);

	zassert_equal(t.n_ev, 2);
	zassert_equal(t.ev[0].from, CO_LSS_STATE_WAITING);
	zassert_equal(t.ev[0].to, CO_LSS_STATE_CONFIGURATION);
	zassert_equal(t.ev[1].to, CO_LSS_STATE_WAITING);
	zassert_equal(t.n_ind, 2);
}

ZTEST(co_lss, test_30_configured_node_takes_new_id_at_reset_communication)
{
	to_configuration();
	ask(0x11, 0x0A, 0, CO_LSS_ERR_OK);
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(sim.n_sent, 0, "no boot-up");
	co_sim_run_until(sim.now + 60 * MS);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x705, "heartbeat still on 705h");

	sim.n_sent = 0;
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x70A, "boot-up on 70Ah");
	co_sim_run_until(sim.now + 60 * MS);
	zassert_equal(sim.sent[1].id, 0x70A);
}

/* --- 31..35: fastscan ---------------------------------------------------------------------- */

ZTEST(co_lss, test_31_fastscan_probe_answered_by_unconfigured_nodes_only)
{
	boot_two(NODE_ID, CO_NODE_ID_UNCONFIGURED);
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0);
	zassert_equal(sim.n_sent, 1, "the peer (FFh) answers, node 05h does not");
	expect_answer(0, 0x4F, 0, 0);
	zassert_equal(t.n_ev, 0, "a probe changes no state");

	/* A pending node-ID is enough to stay out of the scan. */
	zassert_ok(co_node_set_pending_id(&t.peer, 0x0A));
	sim.n_sent = 0;
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0);
	zassert_equal(sim.n_sent, 0);
}

ZTEST(co_lss, test_32_fastscan_checks_bits_31_down_to_bitcheck)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	req_fastscan(0x00000000U, 0x1F, 0, 0);
	zassert_equal(sim.n_sent, 1, "bit 31 of 12345678h is 0");
	expect_answer(0, 0x4F, 0, 0);
	sim.n_sent = 0;
	req_fastscan(0x00000000U, 0x1C, 0, 0);
	zassert_equal(sim.n_sent, 0, "bits 31..28 are 0001b");
	req_fastscan(0x10000000U, 0x1C, 0, 0);
	zassert_equal(sim.n_sent, 1);
	/* Bits below BitCheck do not count. */
	req_fastscan(0x1234FFFFU, 0x10, 0, 0);
	zassert_equal(sim.n_sent, 2);
	req_fastscan(0x1235FFFFU, 0x10, 0, 0);
	zassert_equal(sim.n_sent, 2);
}

ZTEST(co_lss, test_33_fastscan_advances_to_lssnext)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	req(0x51, 0x78, 0x56, 0x34, 0x12, 0x00, 0x00, 0x01);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x4F, 0, 0);
	req(0x51, 0x78, 0x56, 0x34, 0x12, 0x00, 0x00, 0x01);
	zassert_equal(sim.n_sent, 1, "position 1 now: LSSSub 0 is not answered");
	req_fastscan(PRODUCT, 0, CO_LSS_FASTSCAN_PRODUCT, CO_LSS_FASTSCAN_REVISION);
	zassert_equal(sim.n_sent, 2, "the product code at position 1");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);
	/* The probe starts over. */
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0);
	req(0x51, 0x78, 0x56, 0x34, 0x12, 0x00, 0x00, 0x01);
	zassert_equal(sim.n_sent, 4);
}

ZTEST(co_lss, test_34_fastscan_completion_enters_configuration)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0);
	req_fastscan(VENDOR, 0, 0, 1);
	req_fastscan(PRODUCT, 0, 1, 2);
	req_fastscan(REVISION, 0, 2, 3);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);
	req_fastscan(SERIAL, 0, 3, 0);
	zassert_equal(sim.n_sent, 5, "every step answered");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(t.n_ev, 1);
	zassert_equal(t.ev[0].to, CO_LSS_STATE_CONFIGURATION);
	zassert_true(t.ev[0].fastscan, "the change ends a fastscan");

	sim.n_sent = 0;
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	expect_answer(0, 0x5E, 0xFF, 0);
	ask(0x11, 0x0B, 0, CO_LSS_ERR_OK);
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(sim.sent[0].id, 0x70B);
	zassert_false(t.ev[1].fastscan);
}

/* One fastscan step: whether any slave answered. */
static bool fs_step(uint32_t id, uint8_t bit, uint8_t sub, uint8_t next)
{
	sim.n_sent = 0;
	req_fastscan(id, bit, sub, next);
	co_sim_run_until(sim.now); /* the answers reach the other node, as on a bus */
	return count_id(LSS_ANS) > 0;
}

/* The master's side of fastscan, step by step: true when it selected a slave. */
static bool fastscan_master(uint32_t found[4])
{
	if (!fs_step(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0)) {
		return false;
	}
	for (uint8_t sub = 0; sub < 4U; sub++) {
		uint32_t id = 0U;

		for (int bit = 31; bit >= 0; bit--) {
			/* No slave with a 0 there: the bit is 1. */
			if (!fs_step(id, (uint8_t)bit, sub, sub)) {
				id |= BIT(bit);
			}
		}
		if (!fs_step(id, 0, sub, sub == 3U ? 0U : (uint8_t)(sub + 1U))) {
			return false;
		}
		found[sub] = id;
	}
	return true;
}

ZTEST(co_lss, test_34_fastscan_master_finds_each_unconfigured_node_in_turn)
{
	uint32_t found[4];

	boot_two(CO_NODE_ID_UNCONFIGURED, CO_NODE_ID_UNCONFIGURED);
	zassert_true(fastscan_master(found));
	zassert_equal(found[0], VENDOR);
	zassert_equal(found[1], PRODUCT);
	zassert_equal(found[2], REVISION);
	zassert_equal(found[3], SERIAL, "the lower LSS address first");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(co_lss_get_state(&t.peer), CO_LSS_STATE_WAITING);
	ask(0x11, 0x0B, 0, CO_LSS_ERR_OK);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(co_node_id(&t.node), 0x0B);

	zassert_true(fastscan_master(found));
	zassert_equal(found[3], PEER_SERIAL);
	zassert_equal(co_lss_get_state(&t.peer), CO_LSS_STATE_CONFIGURATION);
	ask(0x11, 0x0C, 0, CO_LSS_ERR_OK);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(co_node_id(&t.peer), 0x0C);

	zassert_false(fastscan_master(found), "nobody left without node-ID");
}

ZTEST(co_lss, test_35_bad_fastscan_fields_are_ignored)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	req_fastscan(0, 0x20, 0, 0);
	req_fastscan(0, 0x7F, 0, 0);
	req_fastscan(0, 0x81, 0, 0);
	req_fastscan(0, 0xFF, 0, 0);
	req_fastscan(0, 0x1F, 4, 0);
	req_fastscan(0, 0x1F, 0, 4);
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 4);
	zassert_equal(sim.n_sent, 0);
	req_fastscan(0, 0x1F, 0, 0);
	zassert_equal(sim.n_sent, 1, "the position was not disturbed");
}

/* --- 36..37: identification ------------------------------------------------------------------ */

ZTEST(co_lss, test_36_identify_non_configured_answered_by_unconfigured_nodes_only)
{
	boot_two(NODE_ID, CO_NODE_ID_UNCONFIGURED);
	req_cs(CO_LSS_CS_IDENT_NON_CONFIGURED, 0, 0);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x50, 0, 0);
	/* In configuration too. */
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	req_cs(CO_LSS_CS_IDENT_NON_CONFIGURED, 0, 0);
	zassert_equal(sim.n_sent, 2);
	/* A pending node-ID counts as configured. */
	sim.n_sent = 0;
	zassert_ok(co_node_set_pending_id(&t.peer, 0x0A));
	req_cs(CO_LSS_CS_IDENT_NON_CONFIGURED, 0, 0);
	zassert_equal(sim.n_sent, 0);
}

ZTEST(co_lss, test_37_identify_remote_slave_answers_inside_the_ranges)
{
	boot_two(NODE_ID, CO_NODE_ID_UNCONFIGURED);
	identify(0, UINT32_MAX, SERIAL, PEER_SERIAL);
	zassert_equal(count_id(LSS_ANS), 2, "both nodes are in the ranges");
	expect_answer(0, 0x4F, 0, 0);
	sim.n_sent = 0;
	identify(REVISION, REVISION, SERIAL, SERIAL);
	zassert_equal(sim.n_sent, 1, "bounds included");
	sim.n_sent = 0;
	identify(REVISION, REVISION, SERIAL + 1U, PEER_SERIAL);
	zassert_equal(sim.n_sent, 1, "only the peer");
	sim.n_sent = 0;
	identify(REVISION + 1U, UINT32_MAX, 0, UINT32_MAX);
	identify(0, REVISION - 1U, 0, UINT32_MAX);
	identify(0, UINT32_MAX, 0, SERIAL - 1U);
	identify(0, UINT32_MAX, PEER_SERIAL + 1U, UINT32_MAX);
	zassert_equal(sim.n_sent, 0, "ranges that exclude both");

	/* Vendor or product different, or a step missing: nothing. */
	req_u32(CO_LSS_CS_IDENT_VENDOR, VENDOR + 1U);
	req_u32(CO_LSS_CS_IDENT_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_IDENT_REVISION_LOW, 0);
	req_u32(CO_LSS_CS_IDENT_REVISION_HIGH, UINT32_MAX);
	req_u32(CO_LSS_CS_IDENT_SERIAL_LOW, 0);
	req_u32(CO_LSS_CS_IDENT_SERIAL_HIGH, UINT32_MAX);
	req_u32(CO_LSS_CS_IDENT_VENDOR, VENDOR);
	req_u32(CO_LSS_CS_IDENT_PRODUCT, PRODUCT);
	req_u32(CO_LSS_CS_IDENT_REVISION_HIGH, UINT32_MAX);
	req_u32(CO_LSS_CS_IDENT_SERIAL_LOW, 0);
	req_u32(CO_LSS_CS_IDENT_SERIAL_HIGH, UINT32_MAX);
	zassert_equal(sim.n_sent, 0);

	/* Both LSS states take it. */
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	identify(0, UINT32_MAX, SERIAL, SERIAL);
	zassert_equal(sim.n_sent, 1);
	zassert_equal(t.n_ev, 2, "identification changes no state");
}

/* --- 38: activate bit timing ----------------------------------------------------------------- */

ZTEST(co_lss, test_38_activate_bit_timing_silent_switch_silent_resume)
{
	uint64_t t0;

	to_configuration();
	ask(0x13, 0x00, 0x03, CO_LSS_ERR_OK); /* 250 kbit/s */
	co_sim_run_until(1000 * MS);          /* heartbeats every 50 ms */
	t0 = sim.now;
	sim.n_sent = 0;
	t.n_br = 0;
	req(0x15, 0x64, 0x00, 0, 0, 0, 0, 0); /* 100 ms */
	zassert_equal(sim.n_sent, 0, "activate has no answer");
	zassert_equal(t.n_br, 1);
	zassert_equal(t.br[0].step, CO_LSS_BITRATE_SILENCE);
	zassert_equal(t.br[0].at, t0);

	co_sim_run_until(t0 + 199 * MS);
	zassert_equal(sim.n_sent, 0, "silent: the heartbeats are held");
	zassert_equal(t.n_br, 2);
	zassert_equal(t.br[1].step, CO_LSS_BITRATE_SWITCH);
	zassert_equal(t.br[1].bitrate, 250000U);
	zassert_equal(t.br[1].at, t0 + 100 * MS, "switch after the first delay");

	co_sim_run_until(t0 + 200 * MS);
	zassert_equal(t.n_br, 3);
	zassert_equal(t.br[2].step, CO_LSS_BITRATE_RESUME);
	zassert_equal(t.br[2].bitrate, 250000U);
	zassert_equal(t.br[2].at, t0 + 200 * MS, "resume after the second delay");
	zassert_true(sim.n_sent > 0, "the held heartbeats go out at the new rate");
	for (int i = 0; i < sim.n_sent; i++) {
		zassert_equal(sim.sent_at[i], t0 + 200 * MS);
		zassert_equal(sim.sent[i].id, 0x705);
	}
	int held = sim.n_sent;

	co_sim_run_until(t0 + 260 * MS);
	zassert_equal(sim.n_sent, held + 1, "and the heartbeat keeps its period");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
}

/*
 * Found by the lss fuzzing harness: a Reset Communication during the switch gives the node
 * its new node-ID, yet the heartbeats held for the old one used to go out at the resume, as
 * if node 05h were still there. The reset withdraws what the node had queued.
 */
ZTEST(co_lss, test_38_reset_during_the_switch_drops_the_frames_held_for_the_old_node_id)
{
	uint64_t t0;

	to_configuration();
	ask(0x11, 0x0A, 0x00, CO_LSS_ERR_OK); /* node-ID 0Ah, pending */
	ask(0x13, 0x00, 0x03, CO_LSS_ERR_OK);
	co_sim_run_until(1000 * MS);
	t0 = sim.now;
	sim.n_sent = 0;
	req(0x15, 0x64, 0x00, 0, 0, 0, 0, 0); /* 100 ms each delay */
	co_sim_run_until(t0 + 120 * MS);      /* heartbeats of 05h held */
	zassert_equal(sim.n_sent, 0);
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	zassert_equal(co_node_id(&t.node), 0x0A);
	co_sim_run_until(t0 + 200 * MS);
	zassert_true(sim.n_sent > 0, "the node speaks again after the switch");
	zassert_equal(count_id(0x700 + NODE_ID), 0, "nothing of the old node-ID");
	zassert_equal(sim.sent[0].id, 0x70A, "the boot-up of 0Ah comes first");
	zassert_equal(sim.sent[0].data[0], 0x00);
}

ZTEST(co_lss, test_38_requests_during_the_switch_are_ignored)
{
	to_configuration();
	ask(0x13, 0x00, 0x04, CO_LSS_ERR_OK);
	sim.n_sent = 0;
	req(0x15, 0x0A, 0x00, 0, 0, 0, 0, 0); /* 10 ms */
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	co_sim_run_until(sim.now + 15 * MS);
	req(0x15, 0x0A, 0x00, 0, 0, 0, 0, 0);
	co_sim_run_until(sim.now + 10 * MS);
	zassert_equal(count_id(LSS_ANS), 0, "nothing answered, not even held");
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
	zassert_equal(t.n_br, 4, "check, silence, switch, resume: one activation");
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	expect_answer(0, 0x5E, NODE_ID, 0);
}

ZTEST(co_lss, test_38_activate_without_configured_bit_timing_is_ignored)
{
	to_configuration();
	ask(0x13, 0x00, 0x08, CO_LSS_ERR_BIT_TIMING); /* 10 kbit/s: refused, nothing configured */
	t.n_br = 0;
	req(0x15, 0x0A, 0x00, 0, 0, 0, 0, 0);
	co_sim_run_until(sim.now + 100 * MS);
	zassert_equal(t.n_br, 0, "no switch");
	zassert_false(sim.tx_busy);
}

ZTEST(co_lss, test_38_failed_switch_resumes_at_the_old_rate)
{
	to_configuration();
	ask(0x13, 0x00, 0x00, CO_LSS_ERR_OK);
	t.switch_result = -EIO;
	t.n_br = 0;
	req(0x15, 0x01, 0x00, 0, 0, 0, 0, 0);
	co_sim_run_until(sim.now + 2 * MS);
	zassert_equal(t.n_br, 3);
	zassert_equal(t.br[2].step, CO_LSS_BITRATE_RESUME);
	zassert_equal(t.br[2].bitrate, 0U, "the line's own rate");
	zassert_false(sim.tx_busy, "resumed");
}

/* --- 39 and the other error paths ------------------------------------------------------------ */

ZTEST(co_lss, test_39_requests_without_dlc_8_are_ignored)
{
	const uint8_t sw[8] = {CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION};
	const uint8_t inq[8] = {CO_LSS_CS_INQUIRE_NODE_ID};

	for (uint8_t dlc = 0; dlc < 8; dlc++) {
		co_sim_rx(LSS_REQ, dlc, sw);
	}
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);
	co_sim_rx_flags(LSS_REQ, 8, sw, CAN_FRAME_RTR);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING, "remote frame");
	co_sim_rx_flags(LSS_REQ, 8, sw, CAN_FRAME_IDE);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING, "29-bit 7E5h");
	co_sim_rx(LSS_REQ, 8, sw);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
	co_sim_rx(LSS_REQ, 7, inq);
	co_sim_rx(LSS_REQ, 0, inq);
	zassert_equal(sim.n_sent, 0);
	co_sim_rx(LSS_REQ, 8, inq);
	zassert_equal(sim.n_sent, 1);
	expect_answer(0, 0x5E, NODE_ID, 0);
}

static bool known_cs(uint8_t cs)
{
	return cs == 0x04 || cs == 0x11 || cs == 0x13 || cs == 0x15 || cs == 0x17 ||
	       (cs >= 0x40 && cs <= 0x43) || (cs >= 0x46 && cs <= 0x4C) || cs == 0x51 ||
	       (cs >= 0x5A && cs <= 0x5E);
}

ZTEST(co_lss, test_unknown_command_specifiers_are_ignored)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	for (int state = 0; state < 2; state++) {
		for (int cs = 0; cs < 256; cs++) {
			if (!known_cs((uint8_t)cs)) {
				req((uint8_t)cs, 0x01, 0x02, 0, 0, 0, 0, 0);
			}
		}
		zassert_equal(sim.n_sent, 0, "no answer (state %d)", state);
		zassert_equal(t.n_ev, state, "no state change");
		req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_CONFIGURATION, 0);
	}
	/* Nor an unknown mode of switch state global. */
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, 0x02, 0);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, 0xFF, 0);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION);
}

ZTEST(co_lss, test_configuration_requests_in_waiting_are_ignored)
{
	static const uint8_t cs[] = {0x11, 0x13, 0x15, 0x17, 0x5A, 0x5B, 0x5C, 0x5D, 0x5E};

	co_lss_store_attach(&t.node, &ram_be.be, NULL);
	for (size_t i = 0; i < ARRAY_SIZE(cs); i++) {
		req_cs(cs[i], 0x0A, 0x02);
	}
	zassert_equal(sim.n_sent, 0);
	zassert_equal(t.n_br, 0, "no bit timing checked");
	zassert_equal(co_lss_store_attach(&t.node, &ram_be.be, NULL), -ENOENT, "nothing stored");
}

ZTEST(co_lss, test_selective_switch_and_fastscan_are_ignored_in_configuration)
{
	(void)boot(CO_NODE_ID_UNCONFIGURED, NULL, NULL);
	to_configuration();
	select_node(SERIAL);
	req_fastscan(0, CO_LSS_FASTSCAN_CONFIRM, 0, 0);
	req_fastscan(VENDOR, 0, 0, 1);
	zassert_equal(sim.n_sent, 0);
}

ZTEST(co_lss, test_lss_works_in_every_nmt_state)
{
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	to_configuration();
	sim.n_sent = 0;
	req_cs(CO_LSS_CS_INQUIRE_NODE_ID, 0, 0);
	expect_answer(0, 0x5E, NODE_ID, 0);
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_CONFIGURATION, "NMT leaves LSS");
	ask(0x11, 0x0A, 0, CO_LSS_ERR_OK);
	req_cs(CO_LSS_CS_SWITCH_GLOBAL, CO_LSS_MODE_WAITING, 0);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_STOPPED, "and LSS leaves NMT");
}

ZTEST(co_lss, test_nmt_reset_returns_the_slave_to_waiting)
{
	to_configuration();
	co_sim_nmt(CO_NMT_CS_RESET_NODE, NODE_ID);
	zassert_equal(co_lss_get_state(&t.node), CO_LSS_STATE_WAITING);
	zassert_equal(t.n_ev, 2);
	zassert_equal(t.ev[1].from, CO_LSS_STATE_CONFIGURATION);
	zassert_equal(t.ev[1].to, CO_LSS_STATE_WAITING);
	zassert_false(t.ev[1].fastscan);
	zassert_equal(t.n_ind, 2);
}

ZTEST(co_lss, test_frame_helpers_build_what_the_slave_reads)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, CO_LSS_CS_SWITCH_SEL_SERIAL);
	co_lss_frame_set_u32(&f, 0xA1B2C3D4U);
	zassert_equal(f.id, 0x7E5);
	zassert_equal(f.dlc, 8);
	zassert_true(co_lss_frame_valid(&f));
	zassert_equal(f.data[0], 0x43);
	zassert_equal(f.data[1], 0xD4, "little-endian");
	zassert_equal(f.data[4], 0xA1);
	zassert_equal(co_lss_frame_get_u32(&f), 0xA1B2C3D4U);
	zassert_equal(co_lss_bit_timing_bps(5, false), 0U);
	zassert_equal(co_lss_bit_timing_bps(5, true), 100000U);
	zassert_equal(co_lss_bit_timing_bps(9, true), 0U);
	zassert_equal(co_lss_bit_timing_bps(8, false), 10000U);
}
