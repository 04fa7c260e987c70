/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SRDO (CiA 304) on a simulation line, frame by frame on simulated time. The device under
 * test is node 5: SRDO 1 produces 6200h/6201h sub 1 on 109h/10Ah (its COB-IDs are the bare
 * defaults), SRDO 2 consumes 101h/102h into 6210h/6211h sub 1 (SCT 50 ms, SRVT 20 ms),
 * SRDO 3 is off. Test names follow the frame-level behaviours of doc/srdo.md.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/crc.h>
#include <zephyr/ztest.h>

#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>
#include <canopen/srdo.h>
#include <canopen/storage.h>

#include "co_sim.h"
#include "srdo_signed_od.h"
#include "srdo_test_od.h"

#define NODE_ID 5
#define MS      1000ULL
#define MAX_EV  64

struct srdo_ev {
	uint8_t srdo;
	bool safe;
	uint8_t reason;
	uint64_t time_us;
};

static struct {
	struct co_node node;
	union {
		struct srdo_test_od_ram test;
		struct srdo_signed_od_ram signed_;
	} ram;
	struct co_listener listener;
	struct co_storage st;
	struct srdo_ev ev[MAX_EV];
	int n_ev;
} t;

/* Storage survives the per-test reset, as a medium survives a power cycle. */
static struct co_storage_ram ram_be;
static uint8_t medium[4096];

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	zassert_true(t.n_ev < MAX_EV, "too many SRDO events");
	t.ev[t.n_ev++] =
		(struct srdo_ev){ev->srdo.srdo, ev->srdo.safe, ev->srdo.reason, ev->srdo.time_us};
	return 0;
}

static void boot(const struct co_od_def *def, uint8_t node_id)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, def, &t.ram, node_id));
	co_node_lock(&t.node);
	zassert_ok(co_storage_init(&t.st, co_node_od(&t.node), &ram_be.be));
	co_node_unlock(&t.node);
	co_listener_init(&t.listener, "test", CO_EV_BIT(CO_EV_SRDO), on_event, NULL);
	zassert_ok(co_node_listener_add(&t.node, &t.listener));
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

static void *suite_setup(void)
{
	zassert_ok(co_storage_ram_init(&ram_be, medium, sizeof(medium)));
	return NULL;
}

static void before(void *f)
{
	memset(medium, 0xff, sizeof(medium));
	boot(&srdo_test_od_def, NODE_ID);
}

ZTEST_SUITE(co_srdo, NULL, suite_setup, before, NULL, NULL);

/* --- Helpers -------------------------------------------------------------------------------- */

static uint32_t wr(uint16_t index, uint8_t sub, uint64_t value, size_t len)
{
	return co_sim_write(&t.node, index, sub, value, len);
}

static uint32_t rd(uint16_t index, uint8_t sub)
{
	uint32_t v;

	co_node_lock(&t.node);
	v = co_od_uint(co_node_od(&t.node), index, sub, 0xDEADBEEFU);
	co_node_unlock(&t.node);
	return v;
}

static void app_set(uint16_t index, uint8_t sub, uint8_t v)
{
	co_node_lock(&t.node);
	zassert_ok(co_od_set_u8(co_node_od(&t.node), index, sub, v, CO_OD_WRITER_APP));
	co_node_unlock(&t.node);
}

/* Sign every SRDO with the signature the stack computes and declare the configuration valid. */
static void sign(void)
{
	for (uint8_t n = 1; n <= 3; n++) {
		uint16_t crc;

		zassert_ok(co_srdo_signature(&t.node, n, &crc));
		zassert_equal(wr(0x13FF, n, crc, 2), 0U);
	}
	zassert_equal(wr(0x13FE, 0, CO_SRDO_VALID, 1), 0U, "valid configuration accepted");
}

static void start(void)
{
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
}

static void rx1(uint32_t id, uint8_t b)
{
	co_sim_rx(id, 1, &b);
}

/* A good pair from the producer on 101h/102h. */
static void rx_pair(uint8_t b)
{
	rx1(0x101, b);
	rx1(0x102, (uint8_t)~b);
}

static int count_id(uint32_t id)
{
	int n = 0;

	for (int i = 0; i < sim.n_sent; i++) {
		n += sim.sent[i].id == id;
	}
	return n;
}

static const struct can_frame *find_id(uint32_t id, int nth)
{
	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == id && nth-- == 0) {
			return &sim.sent[i];
		}
	}
	return NULL;
}

static enum co_srdo_reason reason_of(uint8_t n)
{
	enum co_srdo_reason r;

	zassert_true(co_srdo_get_state(&t.node, n, &r) >= 0);
	return r;
}

static const struct srdo_ev *last_event(uint8_t srdo)
{
	for (int i = t.n_ev - 1; i >= 0; i--) {
		if (t.ev[i].srdo == srdo) {
			return &t.ev[i];
		}
	}
	return NULL;
}

static enum co_nmt_state nmt_state(void)
{
	enum co_nmt_state st;

	co_node_lock(&t.node);
	st = co_node_nmt_state(&t.node);
	co_node_unlock(&t.node);
	return st;
}

/* --- Producer (behaviours 1, 2) ------------------------------------------------------------- */

ZTEST(co_srdo, test_1_producer_sends_normal_then_inverted_after_stagger_every_refresh_time)
{
	app_set(0x6200, 1, 0x5A);
	app_set(0x6201, 1, 0xA5);
	sign();
	start();
	zassert_equal(nmt_state(), CO_NMT_OPERATIONAL);
	co_sim_run_until(100 * MS);
	zassert_equal(count_id(0x109), 5, "pairs at 2.5, 22.5 ... 82.5 ms");
	zassert_equal(count_id(0x10A), 5);
	for (int k = 0; k < 5; k++) {
		const struct can_frame *n = find_id(0x109, k);
		const struct can_frame *i = find_id(0x10A, k);

		zassert_true(i > n, "pair %d: normal frame first", k);
		zassert_equal(n->dlc, 1);
		zassert_equal(i->dlc, 1);
		zassert_equal(n->data[0], 0x5A);
		zassert_equal(i->data[0], 0xA5);
		zassert_equal(sim.sent_at[n - sim.sent], 2500 + k * 20 * MS,
			      "stagger node-ID x 0.5 ms, then the refresh time");
	}
	zassert_equal(co_srdo_get_state(&t.node, 1, NULL), CO_SRDO_STATE_VALID);
}

ZTEST(co_srdo, test_2_inverted_frame_never_without_its_normal_frame)
{
	sign();
	start();
	co_sim_run_until(300 * MS);
	/* Every 10Ah directly follows a 109h. */
	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == 0x10A) {
			zassert_true(i > 0 && sim.sent[i - 1].id == 0x109, "frame %d", i);
		}
	}
	zassert_true(count_id(0x10A) >= 14);
}

ZTEST(co_srdo, test_producer_on_demand_pair_restarts_refresh_time)
{
	sign();
	start();
	co_sim_run_until(10 * MS); /* first pair at 2.5 ms */
	zassert_ok(co_srdo_send_req(&t.node, 1));
	zassert_equal(count_id(0x109), 2);
	zassert_equal(sim.sent_at[sim.n_sent - 1], 10 * MS);
	co_sim_run_until(29 * MS);
	zassert_equal(count_id(0x109), 2, "no pair 20 ms after the first one any more");
	co_sim_run_until(30 * MS);
	zassert_equal(count_id(0x109), 3, "20 ms after the on-demand pair");
	zassert_equal(co_srdo_send_req(&t.node, 2), -EINVAL, "a consumer");
	zassert_equal(co_srdo_send_req(&t.node, 9), -EINVAL, "no such SRDO");
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_equal(co_srdo_send_req(&t.node, 1), -ENETDOWN);
}

/* --- COB-IDs and the signature (3, 4, 5) ---------------------------------------------------- */

ZTEST(co_srdo, test_3_default_cob_ids_carry_the_node_id)
{
	zassert_equal(rd(0x1301, 5), 0x109);
	zassert_equal(rd(0x1301, 6), 0x10A);
	zassert_ok(co_node_set_pending_id(&t.node, 6));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(rd(0x1301, 5), 0x10B);
	zassert_equal(rd(0x1301, 6), 0x10C);
}

ZTEST(co_srdo, test_3_signed_dcf_refuses_operational_after_node_id_change)
{
	const struct can_frame *emcy;
	int err;

	boot(&srdo_signed_od_def, NODE_ID);
	zassert_equal(rd(0x13FE, 0), 0xA5, "the DCF declares its configuration valid");
	start();
	zassert_equal(nmt_state(), CO_NMT_OPERATIONAL, "signed for node 5");

	zassert_ok(co_node_set_pending_id(&t.node, 6));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(rd(0x1301, 5), 0x10B);
	sim.n_sent = 0;
	co_sim_nmt(CO_NMT_CS_START, 6);
	/* 11: refused, EMCY 6300h naming 13FFh sub 1 (CRC), 13FEh cleared. */
#if defined(CONFIG_CANOPEN_SRDO_PERMISSIVE_START)
	ARG_UNUSED(err);
	zassert_equal(nmt_state(), CO_NMT_OPERATIONAL, "the permissive rule starts anyway");
	zassert_equal(reason_of(1), CO_SRDO_R_CONFIG);
#else
	zassert_equal(nmt_state(), CO_NMT_PRE_OPERATIONAL);
	zassert_str_equal(co_nmt_get_refusal(&t.node, &err), "srdo");
#endif
	emcy = find_id(0x86, 0);
	zassert_not_null(emcy, "EMCY of node 6");
	const uint8_t want[8] = {0x00, 0x63, 0x11, 0x01, 0x03, 0x01, 0xFF, 0x13};

	zassert_mem_equal(emcy->data, want, 8, "6300h, communication, SRDO 1, 13FF0103h");
	zassert_equal(rd(0x13FE, 0), 0x00);
	co_sim_run_until(100 * MS);
	zassert_equal(count_id(0x10B) + count_id(0x109), 0, "no SRDO frames");
}

/* Byte streams of CiA 304's signature, as published, and their CRCs. */
ZTEST(co_srdo, test_4_crc_vectors)
{
	static const uint8_t sick[] = {0x02, 0x32, 0x00, 0x14, 0x11, 0x01, 0x00, 0x00, 0x12,
				       0x01, 0x00, 0x00, 0x04, 0x01, 0x08, 0x01, 0x10, 0x60,
				       0x02, 0x08, 0x01, 0x11, 0x60, 0x03, 0x08, 0x02, 0x10,
				       0x60, 0x04, 0x08, 0x02, 0x11, 0x60};
	static const uint8_t a[] = {0x01, 0x19, 0x00, 0x14, 0x01, 0x01, 0x00, 0x00,
				    0x02, 0x01, 0x00, 0x00, 0x02, 0x01, 0x08, 0x01,
				    0x00, 0x62, 0x02, 0x08, 0x01, 0x01, 0x62};
	static const uint8_t b[] = {0x02, 0x32, 0x00, 0x14, 0x03, 0x01, 0x00, 0x00,
				    0x04, 0x01, 0x00, 0x00, 0x02, 0x01, 0x10, 0x01,
				    0x00, 0x62, 0x02, 0x10, 0x01, 0x01, 0x62};

	zassert_equal(co_srdo_crc(0, sick, sizeof(sick)), 0x4370);
	zassert_equal(co_srdo_crc(0, a, sizeof(a)), 0xB218);
	zassert_equal(co_srdo_crc(0, b, sizeof(b)), 0x0172);
	zassert_equal(co_srdo_crc(0, (const uint8_t *)"123456789", 9), 0x31C3);
}

ZTEST(co_srdo, test_4_signature_from_the_dictionary_matches_vector_a)
{
	uint16_t crc;

	/* Vector A: SRDO 1 of node 1, refresh 25 ms, 6200h:01 / 6201h:01. */
	boot(&srdo_test_od_def, 1);
	zassert_equal(wr(0x1301, 2, 25, 2), 0U);
	zassert_ok(co_srdo_signature(&t.node, 1, &crc));
	zassert_equal(crc, 0xB218);
}

ZTEST(co_srdo, test_4_signature_from_the_dictionary_matches_the_sick_vector)
{
	static const uint32_t map[] = {0x60100108, 0x60110108, 0x60100208, 0x60110208};
	uint16_t crc;

	for (uint8_t k = 0; k < 4; k++) {
		zassert_equal(wr(0x1383, k + 1, map[k], 4), 0U);
	}
	zassert_equal(wr(0x1383, 0, 4, 1), 0U);
	zassert_equal(wr(0x1303, 1, 2, 1), 0U);
	zassert_equal(wr(0x1303, 2, 50, 2), 0U);
	zassert_equal(wr(0x1303, 3, 20, 1), 0U);
	zassert_equal(wr(0x1303, 5, 0x111, 4), 0U);
	zassert_equal(wr(0x1303, 6, 0x112, 4), 0U);
	zassert_ok(co_srdo_signature(&t.node, 3, &crc));
	zassert_equal(crc, 0x4370);
}

ZTEST(co_srdo, test_4_any_covered_change_breaks_the_signature)
{
	/* One field of SRDO 2 at a time: each must make 13FEh := A5h fail. */
	static const struct {
		uint16_t index;
		uint8_t sub;
		uint32_t value;
		uint8_t len;
	} change[] = {
		{0x1302, 1, 1, 1},     {0x1302, 2, 51, 2},    {0x1302, 3, 21, 1},
		{0x1302, 5, 0x103, 4}, {0x1302, 6, 0x104, 4},
	};

	for (size_t i = 0; i < ARRAY_SIZE(change); i++) {
		uint32_t old = rd(change[i].index, change[i].sub);

		sign();
		zassert_equal(wr(change[i].index, change[i].sub, change[i].value, change[i].len),
			      0U, "change %zu", i);
		zassert_equal(rd(0x13FE, 0), 0, "the change withdraws A5h");
		zassert_equal(wr(0x13FE, 0, 0xA5, 1), CO_SDO_AB_INVALID_VALUE, "change %zu", i);
		zassert_equal(wr(change[i].index, change[i].sub, old, change[i].len), 0U);
	}
	/* The mapping: dir 0 to change it, then back; the count and an entry. */
	sign();
	zassert_equal(wr(0x1302, 1, 0, 1), 0U);
	zassert_equal(wr(0x1382, 0, 0, 1), 0U);
	zassert_equal(wr(0x1382, 2, 0x60110108, 4), 0U);
	zassert_equal(wr(0x1382, 0, 2, 1), 0U);
	zassert_equal(wr(0x1302, 1, 2, 1), 0U);
	zassert_equal(wr(0x13FE, 0, 0xA5, 1), CO_SDO_AB_INVALID_VALUE, "mapping entry changed");
	/* Signed again, it is accepted. */
	sign();
	zassert_equal(rd(0x13FE, 0), 0xA5);
}

ZTEST(co_srdo, test_5_transmission_type_is_not_in_the_signature)
{
	uint16_t before_crc, after_crc;

	zassert_ok(co_srdo_signature(&t.node, 2, &before_crc));
	zassert_equal(wr(0x1302, 4, 0xFE, 1), 0U);
	zassert_ok(co_srdo_signature(&t.node, 2, &after_crc));
	zassert_equal(before_crc, after_crc);
	zassert_equal(wr(0x1302, 4, 0xFF, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(wr(0x1302, 4, 0x01, 1), CO_SDO_AB_INVALID_VALUE);
}

/* --- Write rules (6, 7, 8, 9) --------------------------------------------------------------- */

ZTEST(co_srdo, test_6_configuration_locked_in_operational)
{
	sign();
	start();
	zassert_equal(wr(0x1301, 2, 30, 2), CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(wr(0x1381, 0, 0, 1), CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(wr(0x13FE, 0, 0, 1), CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(wr(0x13FF, 1, 0x1234, 2), CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(rd(0x13FE, 0), 0xA5, "nothing changed");
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	zassert_equal(wr(0x1301, 2, 30, 2), 0U, "Stopped allows it (SDO aside)");
}

ZTEST(co_srdo, test_7_range_checks)
{
	zassert_equal(wr(0x1301, 4, 0x01, 1), CO_SDO_AB_INVALID_VALUE, "transmission type");
	zassert_equal(wr(0x1301, 5, 0x100, 4), CO_SDO_AB_INVALID_VALUE, "below 101h");
	zassert_equal(wr(0x1301, 5, 0x181, 4), CO_SDO_AB_INVALID_VALUE, "above 17Fh");
	zassert_equal(wr(0x1301, 5, 0x10C, 4), CO_SDO_AB_INVALID_VALUE, "even COB-ID 1");
	zassert_equal(wr(0x1301, 5, 0x80000109, 4), CO_SDO_AB_INVALID_VALUE, "flag bits");
	zassert_equal(wr(0x1301, 6, 0x10B, 4), CO_SDO_AB_INVALID_VALUE, "odd COB-ID 2");
	zassert_equal(wr(0x1301, 1, 0x03, 1), CO_SDO_AB_INVALID_VALUE, "direction");
	zassert_equal(wr(0x1301, 3, 0x00, 1), CO_SDO_AB_INVALID_VALUE, "SRVT 0");
	zassert_equal(wr(0x1301, 2, 0x00, 2), CO_SDO_AB_INVALID_VALUE, "refresh time 0");
	zassert_equal(rd(0x1301, 5), 0x109, "nothing written");
	zassert_equal(wr(0x1301, 5, 0x17F, 4), 0U, "highest COB-ID 1");
	zassert_equal(wr(0x1301, 6, 0x180, 4), 0U, "highest COB-ID 2");
}

ZTEST(co_srdo, test_8_accepted_writes_withdraw_the_valid_declaration)
{
	sign();
	zassert_equal(wr(0x1301, 2, 20, 2), 0U, "same value, still a write");
	zassert_equal(rd(0x13FE, 0), 0x00);
	sign();
	zassert_equal(wr(0x1383, 0, 0, 1), 0U);
	zassert_equal(rd(0x13FE, 0), 0x00);
	sign();
	zassert_equal(wr(0x13FF, 3, 0x0001, 2), 0U);
	zassert_equal(rd(0x13FE, 0), 0x00);
	sign();
	zassert_equal(wr(0x1301, 4, 0x01, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(rd(0x13FE, 0), 0xA5, "a refused write changes nothing");
}

ZTEST(co_srdo, test_9_mapping_guards)
{
	zassert_equal(wr(0x1381, 1, 0x62000108, 4), CO_SDO_AB_UNSUPP_ACCESS, "SRDO 1 is on");
	zassert_equal(wr(0x1383, 0, 2, 1), CO_SDO_AB_NO_MAP, "entries 0: nothing to map");
	zassert_equal(wr(0x1383, 1, 0x60100108, 4), 0U);
	zassert_equal(wr(0x1383, 2, 0x60110108, 4), 0U);
	zassert_equal(wr(0x1383, 0, 2, 1), 0U);
	zassert_equal(wr(0x1383, 1, 0x60100208, 4), CO_SDO_AB_UNSUPP_ACCESS,
		      "entries change only while sub 0 is 0");
	zassert_equal(wr(0x1383, 0, 3, 1), CO_SDO_AB_MAP_LEN, "odd count");
	zassert_equal(wr(0x1383, 0, 18, 1), CO_SDO_AB_MAP_LEN, "above 16");
	zassert_equal(wr(0x1383, 0, 0, 1), 0U);
	zassert_equal(wr(0x1383, 2, 0x60110110, 4), 0U);
	zassert_equal(wr(0x1383, 0, 2, 1), CO_SDO_AB_NO_MAP, "16 bits of an 8-bit object");
	zassert_equal(wr(0x1383, 2, 0x70000108, 4), 0U);
	zassert_equal(wr(0x1383, 0, 2, 1), CO_SDO_AB_NO_MAP, "no such object");
}

/* --- Start-up (10, 11) ---------------------------------------------------------------------- */

ZTEST(co_srdo, test_10_without_valid_declaration_operational_without_srdo)
{
	start();
	zassert_equal(nmt_state(), CO_NMT_OPERATIONAL);
	co_sim_run_until(200 * MS);
	zassert_equal(count_id(0x109) + count_id(0x10A), 0);
	zassert_equal(reason_of(1), CO_SRDO_R_CONFIG);
	zassert_equal(reason_of(2), CO_SRDO_R_CONFIG);
	zassert_equal(co_srdo_get_state(&t.node, 3, NULL), CO_SRDO_STATE_DELETED);
	zassert_false(co_srdo_may_leave_safe_state(&t.node));
}

/* 11 with the default rule: see test_3_signed_dcf_...; here with a mapping gone bad. */
ZTEST(co_srdo, test_11_inconsistent_configuration_refuses_operational)
{
	struct co_emcy_status st;

	sign();
	/* 6210h sub 1 becomes unmappable behind the signature's back: no hook sees it. */
	co_node_lock(&t.node);
	zassert_ok(co_od_set_u32(co_node_od(&t.node), 0x1382, 1, 0, CO_OD_WRITER_STORAGE));
	co_node_unlock(&t.node);
	start();
#if defined(CONFIG_CANOPEN_SRDO_PERMISSIVE_START)
	zassert_equal(nmt_state(), CO_NMT_OPERATIONAL, "the permissive rule starts anyway");
	zassert_equal(reason_of(1), CO_SRDO_R_CONFIG);
	zassert_equal(reason_of(2), CO_SRDO_R_CONFIG);
	co_sim_run_until(100 * MS);
	zassert_equal(count_id(0x109), 0, "no SRDO runs");
#else
	zassert_equal(nmt_state(), CO_NMT_PRE_OPERATIONAL);
#endif
	zassert_equal(rd(0x13FE, 0), 0x00);
	co_emcy_get_status(&t.node, &st);
	zassert_not_null(find_id(0x85, 0), "EMCY");
	zassert_equal(find_id(0x85, 0)->data[1], 0x63);
	zassert_equal(find_id(0x85, 0)->data[3], 2, "SRDO 2");
}

/* --- Consumer (12-18) ----------------------------------------------------------------------- */

static void start_consumer(void)
{
	sign();
	start();
	zassert_equal(reason_of(2), CO_SRDO_R_STARTING);
}

ZTEST(co_srdo, test_12_good_pair_reaches_both_objects)
{
	start_consumer();
	co_sim_run_until(10 * MS);
	rx_pair(0x12);
	zassert_equal(rd(0x6210, 1), 0x12);
	zassert_equal(rd(0x6211, 1), 0xED);
	zassert_equal(co_srdo_get_state(&t.node, 2, NULL), CO_SRDO_STATE_VALID);
	zassert_equal(last_event(2)->reason, CO_SRDO_R_NONE);
	zassert_false(last_event(2)->safe);
	zassert_equal(last_event(2)->time_us, 10 * MS);
	zassert_true(co_srdo_may_leave_safe_state(&t.node), "producer sent, consumer valid");
}

ZTEST(co_srdo, test_13_not_inverted_writes_nothing_and_latches)
{
	start_consumer();
	rx_pair(0x33);
	rx1(0x101, 0x12);
	rx1(0x102, 0xEC);
	zassert_equal(rd(0x6210, 1), 0x33, "the bad pair is not written");
	zassert_equal(reason_of(2), CO_SRDO_R_NOT_INVERTED);
	zassert_true(last_event(2)->safe);
	zassert_false(co_srdo_may_leave_safe_state(&t.node));
	/* EMCY 8200h [SRDO 2, reason]. */
	zassert_equal(find_id(0x85, 0)->data[0], 0x00);
	zassert_equal(find_id(0x85, 0)->data[1], 0x82);
	zassert_equal(find_id(0x85, 0)->data[3], 2);
	zassert_equal(find_id(0x85, 0)->data[4], CO_SRDO_R_NOT_INVERTED);
	/* Good pairs do not release the latch ... */
	co_sim_run_until(5 * MS);
	rx_pair(0x44);
	zassert_equal(rd(0x6210, 1), 0x33);
	zassert_equal(reason_of(2), CO_SRDO_R_NOT_INVERTED);
	/* ... an NMT round through Pre-operational does. */
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_equal(reason_of(2), CO_SRDO_R_NOT_OPERATIONAL);
	zassert_equal(find_id(0x85, 1)->data[1], 0x00, "EMCY reset on leaving Operational");
	start();
	rx_pair(0x44);
	zassert_equal(rd(0x6210, 1), 0x44);
	zassert_equal(reason_of(2), CO_SRDO_R_NONE);
}

ZTEST(co_srdo, test_14_srvt_expires_and_a_late_inverted_frame_is_ignored)
{
	start_consumer();
	co_sim_run_until(10 * MS);
	rx1(0x101, 0x12);
	co_sim_run_until(29 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_STARTING);
	co_sim_run_until(35 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_SRVT);
	zassert_equal(last_event(2)->time_us, 30 * MS, "detected at SRVT after the normal frame");
	rx1(0x102, 0xED);
	zassert_equal(rd(0x6210, 1), 0x00, "nothing written");
	zassert_equal(reason_of(2), CO_SRDO_R_SRVT);
}

ZTEST(co_srdo, test_15_sct_counts_from_the_last_inverted_frame)
{
	start_consumer();
	for (int k = 1; k <= 4; k++) {
		co_sim_run_until(k * 30 * MS);
		rx1(0x101, (uint8_t)k);
		co_sim_run_until(k * 30 * MS + 2 * MS);
		rx1(0x102, (uint8_t)~k);
		zassert_equal(reason_of(2), CO_SRDO_R_NONE, "pair %d", k);
	}
	co_sim_run_until(171 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_NONE, "SCT runs 50 ms from 122 ms");
	co_sim_run_until(173 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_SCT);
	zassert_equal(last_event(2)->time_us, 172 * MS);
}

ZTEST(co_srdo, test_15_first_pair_within_sct_of_the_start)
{
	start_consumer();
	co_sim_run_until(49 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_STARTING);
	co_sim_run_until(51 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_SCT);
}

ZTEST(co_srdo, test_16_orphan_inverted_frame_is_ignored)
{
	start_consumer();
	rx1(0x102, 0xED);
	zassert_equal(reason_of(2), CO_SRDO_R_STARTING);
	zassert_equal(rd(0x6211, 1), 0x00);
	rx_pair(0x12);
	zassert_equal(reason_of(2), CO_SRDO_R_NONE);
}

ZTEST(co_srdo, test_17_interleaved_frames_within_srvt_make_a_pair)
{
	start_consumer();
	rx1(0x101, 0x12);
	co_sim_run_until(1 * MS);
	rx1(0x103, 0x99);
	rx1(0x104, 0x66);
	co_sim_run_until(3 * MS);
	rx1(0x102, 0xED);
	zassert_equal(reason_of(2), CO_SRDO_R_NONE);
	zassert_equal(rd(0x6210, 1), 0x12);
}

ZTEST(co_srdo, test_18_short_frame_raises_8210h)
{
	start_consumer();
	co_sim_rx(0x101, 0, NULL);
	zassert_equal(reason_of(2), CO_SRDO_R_SHORT);
	zassert_not_null(find_id(0x85, 0));
	zassert_equal(find_id(0x85, 0)->data[0], 0x10);
	zassert_equal(find_id(0x85, 0)->data[1], 0x82);
	zassert_equal(find_id(0x85, 0)->data[3], 2, "SRDO 2");
}

ZTEST(co_srdo, test_short_inverted_frame_is_short_too)
{
	start_consumer();
	rx1(0x101, 0x12);
	co_sim_rx(0x102, 0, NULL);
	zassert_equal(reason_of(2), CO_SRDO_R_SHORT);
	zassert_equal(rd(0x6210, 1), 0x00);
}

/* Timing is judged on the frames' receive timestamps, not on when the line got to them. */
ZTEST(co_srdo, test_frames_are_judged_by_their_receive_time)
{
	struct can_frame n = {.id = 0x101, .dlc = 1, .data = {0x12}};
	struct can_frame i = {.id = 0x102, .dlc = 1, .data = {0xED}};

	start_consumer();
	/* Both frames handed over at 40 ms, received at 10 ms and 25 ms: within SRVT. */
	sim.now = 40 * MS;
	co_line_rx(&sim.line, &n, 10 * MS);
	co_line_rx(&sim.line, &i, 25 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_NONE);
	/* Next pair: received 21 ms apart, handed over together: SRVT exceeded. */
	co_line_rx(&sim.line, &n, 50 * MS);
	co_line_rx(&sim.line, &i, 71 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_SRVT);
	zassert_equal(last_event(2)->time_us, 71 * MS);
}

ZTEST(co_srdo, test_frames_received_before_the_start_are_ignored)
{
	struct can_frame n = {.id = 0x101, .dlc = 1, .data = {0x12}};
	struct can_frame i = {.id = 0x102, .dlc = 1, .data = {0xED}};

	co_sim_run_until(20 * MS);
	start_consumer();
	/* A pair stamped before Operational, handed over after it: not a pair of this run. */
	co_line_rx(&sim.line, &n, 19 * MS);
	co_line_rx(&sim.line, &i, 20 * MS);
	zassert_equal(reason_of(2), CO_SRDO_R_STARTING);
	zassert_equal(rd(0x6210, 1), 0x00);
}

/* --- NMT, GFC, restore (19, 20, 21) --------------------------------------------------------- */

ZTEST(co_srdo, test_19_leaving_operational_stops_both_directions)
{
	start_consumer();
	co_sim_run_until(10 * MS);
	rx_pair(0x12);
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	int pairs = count_id(0x109);

	zassert_equal(reason_of(1), CO_SRDO_R_NOT_OPERATIONAL);
	zassert_equal(reason_of(2), CO_SRDO_R_NOT_OPERATIONAL);
	zassert_true(last_event(2)->safe);
	co_sim_run_until(200 * MS);
	zassert_equal(count_id(0x109), pairs, "the producer stopped");
	rx_pair(0x34);
	zassert_equal(rd(0x6210, 1), 0x12, "the consumer stopped");
	zassert_false(co_srdo_may_leave_safe_state(&t.node));
}

ZTEST(co_srdo, test_20_gfc)
{
	static const uint8_t one = 0;

	co_sim_rx(0x001, 0, NULL);
	zassert_is_null(last_event(0), "1300h = 0: ignored");
	zassert_equal(co_srdo_gfc_req(&t.node), -EPERM);
	zassert_equal(count_id(0x001), 0);
	zassert_equal(wr(0x1300, 0, 2, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(wr(0x1300, 0, 1, 1), 0U);
	co_sim_run_until(3 * MS);
	co_sim_rx(0x001, 0, NULL);
	zassert_not_null(last_event(0));
	zassert_equal(last_event(0)->reason, CO_SRDO_R_GFC);
	zassert_equal(last_event(0)->time_us, 3 * MS);
	int n = t.n_ev;

	co_sim_rx(0x001, 1, &one);
	zassert_equal(t.n_ev, n, "DLC 1: ignored");
	zassert_ok(co_srdo_gfc_req(&t.node));
	zassert_equal(count_id(0x001), 1);
	zassert_equal(find_id(0x001, 0)->dlc, 0);
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	zassert_equal(co_srdo_gfc_req(&t.node), -ENETDOWN);
}

ZTEST(co_srdo, test_21_restore_defaults_drops_the_configuration)
{
	sign();
	zassert_equal(wr(0x1010, 1, CO_STORAGE_SIGNATURE_SAVE, 4), 0U);
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(rd(0x13FE, 0), 0xA5, "restored from storage");
	start();
	co_sim_run_until(10 * MS);
	zassert_equal(count_id(0x109), 1, "the stored configuration runs");

	zassert_equal(wr(0x1011, 1, CO_STORAGE_SIGNATURE_LOAD, 4), 0U);
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(rd(0x13FE, 0), 0x00, "defaults");
	zassert_equal(rd(0x13FF, 1), 0x0000);
	sim.n_sent = 0;
	start();
	co_sim_run_until(100 * MS);
	zassert_equal(count_id(0x109), 0, "no SRDO without a valid configuration");
	zassert_equal(reason_of(1), CO_SRDO_R_CONFIG);
}

ZTEST(co_srdo, test_safe_state_needs_operational_and_a_declared_configuration)
{
	start_consumer();
	co_sim_run_until(10 * MS); /* the producer's first pair */
	rx_pair(0x12);
	zassert_true(co_srdo_may_leave_safe_state(&t.node));
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_false(co_srdo_may_leave_safe_state(&t.node), "not Operational");
	/* Deleting every SRDO over SDO withdraws 13FEh: nothing left does not mean safe. */
	zassert_equal(wr(0x1301, 1, 0, 1), 0U);
	zassert_equal(wr(0x1302, 1, 0, 1), 0U);
	int n = t.n_ev;

	start();
	zassert_equal(t.n_ev, n, "deleted SRDOs report nothing");
	zassert_equal(co_srdo_get_state(&t.node, 2, NULL), CO_SRDO_STATE_DELETED);
	zassert_false(co_srdo_may_leave_safe_state(&t.node), "13FEh withdrawn");
	/* Declared valid with no SRDO: nothing to supervise. */
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_equal(wr(0x13FE, 0, CO_SRDO_VALID, 1), 0U);
	start();
	zassert_true(co_srdo_may_leave_safe_state(&t.node));
}

ZTEST(co_srdo, test_indication_reports_each_transition)
{
	start_consumer();
	rx_pair(0x01);
	co_sim_run_until(60 * MS);
	/* SRDO 2: not operational -> starting -> valid -> SCT. */
	int n2 = 0;
	uint8_t seen[4];

	for (int i = 0; i < t.n_ev; i++) {
		if (t.ev[i].srdo == 2 && n2 < 4) {
			seen[n2++] = t.ev[i].reason;
		}
	}
	zassert_equal(n2, 3);
	zassert_equal(seen[0], CO_SRDO_R_STARTING);
	zassert_equal(seen[1], CO_SRDO_R_NONE);
	zassert_equal(seen[2], CO_SRDO_R_SCT);
}

ZTEST(co_srdo, test_producer_tx_queue_full_is_a_tx_failure_and_never_half_a_pair)
{
	sign();
	sim.tx_busy = true;
	start();
	/* CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE=8: pairs queue up until one no longer fits. */
	co_sim_run_until(200 * MS);
	zassert_equal(reason_of(1), CO_SRDO_R_TX_FAIL);
	zassert_true(last_event(1)->safe);
	sim.tx_busy = false;
	co_sim_run_until(300 * MS);
	zassert_true(count_id(0x109) >= 2, "the queued pairs went out");
	zassert_equal(count_id(0x109), count_id(0x10A), "whole pairs only");
	zassert_equal(co_srdo_send_req(&t.node, 1), -ENETDOWN, "latched");
}
