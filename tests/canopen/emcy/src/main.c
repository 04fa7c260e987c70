/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * EMCY producer, consumer and error behaviour, driven frame by frame on a simulation line
 * (no thread, simulated time). Frames the node sends land in `sent`.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/emcy.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>

#include "line_internal.h"

#include "co_sim.h"
#include "emcy_bare_od.h"
#include "emcy_test_od.h"

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define MS      1000ULL
#define MAX_TX  64

static struct {
	struct co_node node;
	struct emcy_test_od_ram ram;
	/* Consumer indications seen. */
	int n_ind;
	uint16_t ind_cob[8];
	uint8_t ind_remote[8];
	uint16_t ind_code[8];
	uint8_t ind_reg[8];
	uint8_t ind_msef[8][5];
} t;

static void emcy_ind(struct co_node *node, uint16_t cob_id, uint8_t remote_id, uint16_t code,
		     uint8_t reg, const uint8_t msef[5], void *user_data)
{
	zassert_true(t.n_ind < 8);
	t.ind_cob[t.n_ind] = cob_id;
	t.ind_remote[t.n_ind] = remote_id;
	t.ind_code[t.n_ind] = code;
	t.ind_reg[t.n_ind] = reg;
	memcpy(t.ind_msef[t.n_ind], msef, 5);
	t.n_ind++;
}

static uint32_t od_read_u(uint16_t index, uint8_t sub)
{
	uint8_t buf[8] = {0};
	size_t len = 0;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), index, sub, 0, buf, sizeof(buf), &len,
				 CO_OD_WRITER_SDO),
		      0U, "read %04x:%u", index, sub);
	co_node_unlock(&t.node);
	return (uint32_t)co_od_le_get(buf, len);
}

/* The stored value, as the application sees it (no SDO read checks). */
static uint32_t od_read_app(uint16_t index, uint8_t sub)
{
	uint8_t buf[8] = {0};
	size_t len = 0;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), index, sub, 0, buf, sizeof(buf), &len,
				 CO_OD_WRITER_APP),
		      0U, "read %04x:%u", index, sub);
	co_node_unlock(&t.node);
	return (uint32_t)co_od_le_get(buf, len);
}

/* Frames on the EMCY COB-ID only (heartbeats and boot-up are not counted). */
static int emcy_frames(int *idx, int max)
{
	int n = 0;

	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == EMCY_ID && n < max) {
			idx[n++] = i;
		}
	}
	return n;
}

static void assert_emcy(int i, uint32_t id, uint16_t code, uint8_t reg, const uint8_t *msef)
{
	static const uint8_t zero[5];

	zassert_true(i < sim.n_sent, "frame %d missing (sent %d)", i, sim.n_sent);
	zassert_equal(sim.sent[i].id, id, "frame %d id %x", i, sim.sent[i].id);
	zassert_equal(sim.sent[i].dlc, 8, "EMCY DLC is 8");
	zassert_equal(sim.sent[i].data[0], (uint8_t)code, "code low byte first");
	zassert_equal(sim.sent[i].data[1], (uint8_t)(code >> 8));
	zassert_equal(sim.sent[i].data[2], reg, "frame %d register %02x", i, sim.sent[i].data[2]);
	zassert_mem_equal(&sim.sent[i].data[3], msef != NULL ? msef : zero, 5);
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &emcy_test_od_def, &t.ram, NODE_ID));
	co_emcy_set_ind(&t.node, emcy_ind, NULL);
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_emcy, NULL, NULL, before, NULL, NULL);

ZTEST(co_emcy, test_frame_format_cob_80h_plus_node_id_dlc8_code_register_msef)
{
	const uint8_t msef[5] = {0x11, 0x22, 0x33, 0x44, 0x55};

	zassert_equal(od_read_u(0x1014, 0), EMCY_ID, "1014h default $NODEID+80h");
	zassert_ok(co_emcy_raise(&t.node, 0x2310, CO_EMCY_REG_CURRENT, msef));
	zassert_equal(sim.n_sent, 1);
	assert_emcy(0, EMCY_ID, 0x2310, 0x03, msef);

	zassert_ok(co_emcy_raise(&t.node, 0x5000, 0, NULL));
	assert_emcy(1, EMCY_ID, 0x5000, 0x03, NULL);

	zassert_equal(co_emcy_raise(&t.node, 0x0000, 0, NULL), -EINVAL, "0000h is not an error");
	zassert_equal(co_emcy_clear(&t.node, 0x4210), -ENOENT);
	zassert_equal(sim.n_sent, 2);
}

ZTEST(co_emcy, test_error_register_1001h_derived_from_active_errors)
{
	zassert_equal(od_read_u(0x1001, 0), 0x00);
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	zassert_equal(od_read_u(0x1001, 0), 0x09, "generic + temperature");
	zassert_ok(co_emcy_raise(&t.node, 0x3210, CO_EMCY_REG_VOLTAGE, NULL));
	zassert_equal(od_read_u(0x1001, 0), 0x0d);
	zassert_ok(co_emcy_raise(&t.node, 0x6100, 0, NULL));
	zassert_equal(od_read_u(0x1001, 0), 0x0d, "bit 0 alone for an error without class bits");
	zassert_true(co_emcy_is_active(&t.node, 0x3210));

	zassert_ok(co_emcy_clear(&t.node, 0x4210));
	zassert_equal(od_read_u(0x1001, 0), 0x05, "temperature bit gone with its error");
	zassert_ok(co_emcy_clear(&t.node, 0x3210));
	zassert_equal(od_read_u(0x1001, 0), 0x01, "generic stays while 6100h is active");
	zassert_equal(co_emcy_get_reg(&t.node), 0x01);
	zassert_ok(co_emcy_clear(&t.node, 0x6100));
	zassert_equal(od_read_u(0x1001, 0), 0x00);
	zassert_false(co_emcy_is_active(&t.node, 0x6100));

	zassert_equal(co_sim_write(&t.node, 0x1001, 0, 0x00, 1), CO_SDO_AB_READONLY, "1001h is ro");
}

ZTEST(co_emcy, test_active_table_full_keeps_bits_until_last_clear)
{
	for (uint16_t i = 0; i < CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS; i++) {
		zassert_ok(co_emcy_raise(&t.node, 0x9000 + i, 0, NULL));
	}
	zassert_equal(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL), -ENOSPC);
	zassert_equal(sim.n_sent, CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS + 1,
		      "its frame still goes out");
	zassert_equal(od_read_u(0x1001, 0), 0x09, "and its bits show");
	zassert_equal(co_emcy_clear(&t.node, 0x4210), -ENOENT, "not tracked individually");
	for (uint16_t i = 0; i < CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS - 1; i++) {
		zassert_ok(co_emcy_clear(&t.node, 0x9000 + i));
		zassert_equal(od_read_u(0x1001, 0), 0x09);
	}
	zassert_ok(co_emcy_clear(&t.node, 0x9000 + CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS - 1));
	zassert_equal(od_read_u(0x1001, 0), 0x00, "gone with the last clear");
}

ZTEST(co_emcy, test_error_reset_frame_carries_remaining_register_and_zero_after_last)
{
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	zassert_ok(co_emcy_raise(&t.node, 0x2310, CO_EMCY_REG_CURRENT, NULL));
	sim.n_sent = 0;
	zassert_ok(co_emcy_clear(&t.node, 0x4210));
	assert_emcy(0, EMCY_ID, 0x0000, 0x03, NULL);
	zassert_ok(co_emcy_clear(&t.node, 0x2310));
	assert_emcy(1, EMCY_ID, 0x0000, 0x00, NULL);
	zassert_equal(sim.n_sent, 2);
}

ZTEST(co_emcy, test_inhibit_time_defers_frames_spaced_and_none_lost)
{
	int idx[8];

	zassert_equal(co_sim_write(&t.node, 0x1015, 0, 100, 2), 0U, "100 x 100 us = 10 ms");
	co_sim_run_until(1000 * MS);
	zassert_ok(co_emcy_raise(&t.node, 0x1000, 0, NULL));
	co_sim_run_until(1002 * MS);
	zassert_ok(co_emcy_raise(&t.node, 0x2000, 0, NULL), "deferred, not an error");
	zassert_ok(co_emcy_raise(&t.node, 0x3000, 0, NULL));
	zassert_ok(co_emcy_clear(&t.node, 0x1000));

	struct co_emcy_status st;

	co_emcy_get_status(&t.node, &st);
	zassert_equal(st.queued, 3);
	zassert_equal(emcy_frames(idx, 8), 1, "only the first goes out at once");
	co_sim_run_until(1100 * MS);
	zassert_equal(emcy_frames(idx, 8), 4, "every deferred frame is sent");
	zassert_equal(sim.sent[idx[1]].data[1], 0x20, "in order");
	zassert_equal(sim.sent[idx[2]].data[1], 0x30);
	zassert_equal(sim.sent[idx[3]].data[1], 0x00, "then the error reset");
	for (int i = 1; i < 4; i++) {
		zassert_true(sim.sent_at[idx[i]] - sim.sent_at[idx[i - 1]] >= 10 * MS,
			     "frames %d and %d closer than 1015h", i - 1, i);
	}
	zassert_equal(sim.sent_at[idx[1]], 1010 * MS, "sent as soon as the inhibit expires");
	co_emcy_get_status(&t.node, &st);
	zassert_equal(st.queued, 0);
	zassert_equal(st.overflows, 0);
}

ZTEST(co_emcy, test_inhibit_queue_overflow_is_counted_and_recorded)
{
	struct co_emcy_status st;
	int idx[16];

	zassert_equal(co_sim_write(&t.node, 0x1015, 0, 100, 2), 0U);
	/* One sent, CONFIG_CANOPEN_EMCY_QUEUE queued, the rest overflow. */
	for (uint16_t i = 0; i < CONFIG_CANOPEN_EMCY_QUEUE + 3; i++) {
		zassert_ok(co_emcy_raise(&t.node, 0x1000 + i, 0, NULL));
	}
	co_emcy_get_status(&t.node, &st);
	zassert_equal(st.queued, CONFIG_CANOPEN_EMCY_QUEUE);
	zassert_equal(st.overflows, 2);
	zassert_equal(od_read_u(0x1003, 1), 0x1000U + CONFIG_CANOPEN_EMCY_QUEUE + 2,
		      "1003h still records the lost frame's error");
	co_sim_run_until(1000 * MS);
	zassert_equal(emcy_frames(idx, 16), CONFIG_CANOPEN_EMCY_QUEUE + 1);
}

ZTEST(co_emcy, test_history_1003h_newest_first_count_and_oldest_drops)
{
	const uint8_t msef[5] = {0xcd, 0xab, 0, 0, 0};

	zassert_equal(od_read_u(0x1003, 0), 0);
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, msef));
	zassert_ok(co_emcy_raise(&t.node, 0x3210, CO_EMCY_REG_VOLTAGE, NULL));
	zassert_equal(od_read_u(0x1003, 0), 2);
	zassert_equal(od_read_u(0x1003, 1), 0x00003210U, "newest at sub1");
	zassert_equal(od_read_u(0x1003, 2), 0xabcd4210U, "manufacturer info in bits 31..16");
	zassert_ok(co_emcy_clear(&t.node, 0x3210));
	zassert_equal(od_read_u(0x1003, 0), 2, "a clear is not an entry");
	zassert_ok(co_emcy_clear(&t.node, 0x4210));

	for (uint16_t i = 0; i < 8; i++) {
		zassert_ok(co_emcy_raise(&t.node, 0x9000 + i, 0, NULL));
	}
	zassert_equal(od_read_u(0x1003, 0), 8, "full at the array size");
	zassert_equal(od_read_u(0x1003, 1), 0x9007);
	zassert_equal(od_read_u(0x1003, 8), 0x9000, "both older entries dropped off");
}

ZTEST(co_emcy, test_history_write_zero_clears_other_writes_refused_06090030h)
{
	zassert_ok(co_emcy_raise(&t.node, 0x4210, 0, NULL));
	zassert_ok(co_emcy_raise(&t.node, 0x4220, 0, NULL));
	zassert_equal(co_sim_write(&t.node, 0x1003, 0, 1, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(od_read_u(0x1003, 0), 2, "refused write changes nothing");
	zassert_equal(co_sim_write(&t.node, 0x1003, 1, 0, 4), CO_SDO_AB_READONLY, "entries are ro");
	zassert_equal(co_sim_write(&t.node, 0x1003, 0, 0, 1), 0U);
	zassert_equal(od_read_u(0x1003, 0), 0);
	zassert_equal(od_read_app(0x1003, 1), 0, "entries cleared");
	zassert_true(co_emcy_is_active(&t.node, 0x4210), "clearing history clears no error");
	zassert_ok(co_emcy_raise(&t.node, 0x5000, 0, NULL));
	zassert_equal(od_read_u(0x1003, 0), 1);
	zassert_equal(od_read_u(0x1003, 1), 0x5000);
}

ZTEST(co_emcy, test_cob_id_1014h_write_rules_and_invalid_bit)
{
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x0a0, 4), CO_SDO_AB_INVALID_VALUE,
		      "CAN-ID cannot change while valid");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, EMCY_ID, 4), 0U, "same value is fine");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x80000000U | EMCY_ID, 4), 0U);
	zassert_ok(co_emcy_raise(&t.node, 0x5000, 0, NULL));
	zassert_equal(sim.n_sent, 0, "no EMCY while 1014h bit 31 is set");
	zassert_equal(od_read_u(0x1001, 0), 0x01, "the error is still recorded");

	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x80000000U | 0x0a0, 4), 0U,
		      "CAN-ID may change while invalid");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x0a0, 4), 0U);
	zassert_ok(co_emcy_raise(&t.node, 0x5001, 0, NULL));
	assert_emcy(0, 0x0a0, 0x5001, 0x01, NULL);

	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x80000000U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x701, 4), CO_SDO_AB_INVALID_VALUE,
		      "restricted");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x581, 4), CO_SDO_AB_INVALID_VALUE,
		      "restricted");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x000, 4), CO_SDO_AB_INVALID_VALUE,
		      "restricted");
	zassert_equal(co_sim_write(&t.node, 0x1014, 0, 0x20000123, 4), CO_SDO_AB_INVALID_VALUE,
		      "29-bit not supported");
}

ZTEST(co_emcy, test_consumer_1028h_indication_and_dlc_check)
{
	const uint8_t good[8] = {0x30, 0x81, 0x11, 1, 2, 3, 4, 5};

	if (CONFIG_CANOPEN_EMCY_CONSUMERS < 2) {
		ztest_test_skip(); /* test_consumer_entries_beyond_the_configured_count */
	}

	co_sim_rx(0x85, 8, good);
	zassert_equal(t.n_ind, 0, "1028h entries invalid by default");
	zassert_equal(co_sim_write(&t.node, 0x1028, 1, 0x85, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1028, 2, 0x0ff, 4), 0U);
	co_sim_rx(0x85, 8, good);
	zassert_equal(t.n_ind, 1);
	zassert_equal(t.ind_cob[0], 0x85);
	zassert_equal(t.ind_remote[0], 5);
	zassert_equal(t.ind_code[0], 0x8130);
	zassert_equal(t.ind_reg[0], 0x11);
	zassert_mem_equal(t.ind_msef[0], &good[3], 5);

	co_sim_rx(0x85, 7, good);
	co_sim_rx(0x85, 0, NULL);
	zassert_equal(t.n_ind, 1, "DLC != 8 ignored");
	co_sim_rx(0x86, 8, good);
	zassert_equal(t.n_ind, 1, "COB-ID not in 1028h ignored");
	co_sim_rx(0xff, 8, good);
	zassert_equal(t.n_ind, 2);
	zassert_equal(t.ind_remote[1], 0x7f);

	zassert_equal(co_sim_write(&t.node, 0x1028, 1, 0x80000085U, 4), 0U);
	co_sim_rx(0x85, 8, good);
	zassert_equal(t.n_ind, 2, "entry made invalid");

	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	co_sim_rx(0xff, 8, good);
	zassert_equal(t.n_ind, 2, "no EMCY consumption in Stopped");
}

/*
 * The dictionary's 1028h has two entries: each is stored and read back, but heard only
 * when CONFIG_CANOPEN_EMCY_CONSUMERS serves it (0: none).
 */
ZTEST(co_emcy, test_consumer_entries_beyond_the_configured_count)
{
	const uint8_t good[8] = {0x30, 0x81, 0x11, 1, 2, 3, 4, 5};

	for (uint8_t sub = 1; sub <= 2U; sub++) {
		uint32_t cob = 0x80U + sub;
		uint32_t back = 0;
		int before = t.n_ind;

		zassert_equal(co_sim_write(&t.node, 0x1028, sub, cob, 4), 0U);
		co_node_lock(&t.node);
		zassert_ok(co_od_get_u32(co_node_od(&t.node), 0x1028, sub, &back));
		co_node_unlock(&t.node);
		zassert_equal(back, cob, "1028h:%u stored", sub);
		co_sim_rx(cob, 8, good);
		zassert_equal(t.n_ind - before, sub <= CONFIG_CANOPEN_EMCY_CONSUMERS ? 1 : 0,
			      "1028h:%u heard only when served", sub);
	}
}

/* Monitor node 5 with 100 ms, see its heartbeat once in Operational, then lose it. */
static void lose_heartbeat(void)
{
	uint8_t op = 0x05;

	zassert_equal(co_sim_write(&t.node, 0x1016, 1, (5U << 16) | 100U, 4), 0U);
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL);
	co_sim_rx(0x705, 1, &op);
	sim.n_sent = 0;
	co_sim_run_until(sim.now + 99 * MS);
	zassert_equal(sim.n_sent, 0, "nothing before the consumer time");
	co_sim_run_until(sim.now + 1 * MS);
}

ZTEST(co_emcy, test_heartbeat_loss_8130h_and_1029h_0_goes_pre_operational)
{
	uint8_t op = 0x05;
	const uint8_t msef[5] = {5};

	zassert_equal(od_read_u(0x1029, 1), 0, "default 0");
	lose_heartbeat();
	assert_emcy(0, EMCY_ID, 0x8130, 0x11, msef);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(od_read_u(0x1001, 0), 0x11, "generic + communication");
	zassert_equal(od_read_u(0x1003, 1), 0x00058130U, "info = the lost node-ID");

	co_sim_rx(0x705, 1, &op);
	zassert_equal(sim.n_sent, 2, "recovery sends the error reset");
	assert_emcy(1, EMCY_ID, 0x0000, 0x00, NULL);
	zassert_false(co_emcy_is_active(&t.node, 0x8130));
}

ZTEST(co_emcy, test_heartbeat_loss_1029h_0_in_pre_operational_stays)
{
	uint8_t op = 0x05;

	zassert_equal(co_sim_write(&t.node, 0x1016, 1, (5U << 16) | 100U, 4), 0U);
	co_sim_rx(0x705, 1, &op);
	co_sim_run_until(200 * MS);
	assert_emcy(0, EMCY_ID, 0x8130, 0x11, (const uint8_t[5]){5});
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
}

ZTEST(co_emcy, test_heartbeat_loss_1029h_1_no_state_change)
{
	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 1, 1), 0U);
	lose_heartbeat();
	assert_emcy(0, EMCY_ID, 0x8130, 0x11, (const uint8_t[5]){5});
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL);
}

ZTEST(co_emcy, test_heartbeat_loss_1029h_2_goes_stopped_after_sending_emcy)
{
	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 2, 1), 0U);
	lose_heartbeat();
	assert_emcy(0, EMCY_ID, 0x8130, 0x11, (const uint8_t[5]){5});
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_STOPPED);
}

ZTEST(co_emcy, test_two_lost_heartbeats_clear_8130h_only_when_both_recover)
{
	uint8_t op = 0x05;

	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 1, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1016, 1, (5U << 16) | 100U, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1016, 2, (6U << 16) | 100U, 4), 0U);
	co_sim_rx(0x705, 1, &op);
	co_sim_rx(0x706, 1, &op);
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 1, "one EMCY for the active code");
	co_sim_rx(0x705, 1, &op);
	zassert_true(co_emcy_is_active(&t.node, 0x8130), "node 6 still lost");
	zassert_equal(sim.n_sent, 1);
	co_sim_rx(0x706, 1, &op);
	zassert_false(co_emcy_is_active(&t.node, 0x8130));
	assert_emcy(1, EMCY_ID, 0x0000, 0x00, NULL);
}

ZTEST(co_emcy, test_life_guarding_event_raises_8130h)
{
	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 1, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x100C, 0, 100, 2), 0U);
	zassert_equal(co_sim_write(&t.node, 0x100D, 0, 3, 1), 0U);
	struct can_frame rtr = {.id = 0x700 + NODE_ID, .flags = CAN_FRAME_RTR, .dlc = 1};

	co_line_rx(&sim.line, &rtr, sim.now);
	sim.n_sent = 0;
	co_sim_run_until(299 * MS);
	zassert_equal(sim.n_sent, 0, "nothing within the node life time");
	co_sim_run_until(300 * MS);
	assert_emcy(0, EMCY_ID, 0x8130, 0x11, NULL);
	zassert_true(co_emcy_is_active(&t.node, 0x8130));

	co_line_rx(&sim.line, &rtr, sim.now);
	zassert_false(co_emcy_is_active(&t.node, 0x8130), "guarding resumed");
	assert_emcy(2, EMCY_ID, 0x0000, 0x00, NULL);
}

ZTEST(co_emcy, test_emcy_silent_in_stopped_but_recorded)
{
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	sim.n_sent = 0;
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	zassert_equal(sim.n_sent, 0, "no EMCY in Stopped");
	zassert_equal(od_read_u(0x1001, 0), 0x09);
	zassert_equal(od_read_u(0x1003, 1), 0x4210);
	zassert_ok(co_emcy_clear(&t.node, 0x4210));
	zassert_equal(sim.n_sent, 0);

	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_equal(sim.n_sent, 0, "not sent later either");
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	assert_emcy(0, EMCY_ID, 0x4210, 0x09, NULL);
}

ZTEST(co_emcy, test_stopped_drops_frames_waiting_for_inhibit)
{
	struct co_emcy_status st;

	zassert_equal(co_sim_write(&t.node, 0x1015, 0, 100, 2), 0U);
	zassert_ok(co_emcy_raise(&t.node, 0x1000, 0, NULL));
	zassert_ok(co_emcy_raise(&t.node, 0x2000, 0, NULL));
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	co_emcy_get_status(&t.node, &st);
	zassert_equal(st.queued, 0);
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 1);
}

ZTEST(co_emcy, test_reset_communication_keeps_application_errors_drops_history)
{
	zassert_ok(co_emcy_raise(&t.node, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	zassert_equal(od_read_u(0x1003, 0), 0, "1003h reloaded");
	zassert_equal(od_read_u(0x1001, 0), 0x09, "the error is still there");
	zassert_true(co_emcy_is_active(&t.node, 0x4210));
}

/* A dictionary with only 1001h: errors are tracked, nothing is sent, 1029h defaults to 0. */
ZTEST(co_emcy, test_node_without_emcy_objects_tracks_errors_and_sends_nothing)
{
	static struct co_node bare;
	static struct emcy_bare_od_ram bare_ram;
	uint8_t reg = 0xff;
	size_t len = 0;
	uint8_t op = 0x05;

	zassert_ok(co_node_init(&bare, "bare", &sim.line, &emcy_bare_od_def, &bare_ram, 0x22));
	zassert_ok(co_node_start(&bare));
	co_node_lock(&bare);
	zassert_ok(
		co_od_write(co_node_od(&bare), 0x1017, 0, (uint8_t[]){0, 0}, 2, CO_OD_WRITER_SDO));
	co_node_unlock(&bare);
	sim.n_sent = 0;
	zassert_ok(co_emcy_raise(&bare, 0x4210, CO_EMCY_REG_TEMPERATURE, NULL));
	co_node_lock(&bare);
	zassert_ok(co_od_read(co_node_od(&bare), 0x1001, 0, 0, &reg, 1, &len, CO_OD_WRITER_SDO));
	co_node_unlock(&bare);
	zassert_equal(reg, 0x09);
	zassert_ok(co_emcy_clear(&bare, 0x4210));
	zassert_equal(sim.n_sent, 0, "no 1014h: no EMCY producer");

	/* Lose node 5's heartbeat in Operational: the default 1029h behaviour applies. */
	zassert_equal(co_sim_write(&bare, 0x1016, 1, 0x00050064U, 4), 0U);
	zassert_ok(co_nmt_req(&bare, CO_NMT_CS_START));
	co_sim_rx(0x705, 1, &op);
	co_sim_run_until(sim.now + 100 * MS);
	zassert_true(co_emcy_is_active(&bare, 0x8130));
	zassert_equal(co_nmt_get_state(&bare), CO_NMT_PRE_OPERATIONAL,
		      "without 1029h a communication error leaves Operational");
}

/* --- Line events (injected as the line thread would report them) ------------------------- */

static void line_event(enum co_line_event ev, int arg)
{
	co_line_inject_event(&sim.line, ev, arg);
}

ZTEST(co_emcy, test_rx_overrun_raises_8110h_once_then_clears_after_hold_time)
{
	const uint8_t rx_info[5] = {CO_EMCY_OVERRUN_RX};

	sim.now = 10 * MS;
	co_line_process(&sim.line, sim.now);
	line_event(CO_LINE_EV_RX_OVERRUN, 0);
	assert_emcy(0, EMCY_ID, 0x8110, 0x11, rx_info);
	zassert_equal(od_read_u(0x1001, 0), 0x11, "generic + communication");
	zassert_equal(od_read_u(0x1003, 1), 0x00018110U, "1003h info 01h = RX queue");
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL, "1029h not applied");

	co_sim_run_until(500 * MS);
	line_event(CO_LINE_EV_RX_OVERRUN, 0);
	zassert_equal(sim.n_sent, 1, "one 8110h while it lasts");
	co_sim_run_until(500 * MS + CONFIG_CANOPEN_EMCY_COMM_HOLD_MS * MS - 1);
	zassert_equal(sim.n_sent, 1, "each overrun restarts the hold time");
	co_sim_run_until(500 * MS + CONFIG_CANOPEN_EMCY_COMM_HOLD_MS * MS);
	zassert_equal(sim.n_sent, 2);
	assert_emcy(1, EMCY_ID, 0x0000, 0x00, NULL);
	zassert_false(co_emcy_is_active(&t.node, 0x8110));
}

ZTEST(co_emcy, test_tx_overflow_raises_8110h_from_the_line_thread)
{
	const uint8_t tx_info[5] = {CO_EMCY_OVERRUN_TX};

	/* As co_line_send() reports it: deferred to the line thread's next pass. */
	co_line_report_from_send(&sim.line, CO_LINE_EV_TX_OVERFLOW, 0);
	zassert_equal(sim.n_sent, 0, "not from the sender's context");
	co_line_process(&sim.line, sim.now);
	assert_emcy(0, EMCY_ID, 0x8110, 0x11, tx_info);
	zassert_equal(od_read_u(0x1003, 1), 0x00028110U);
}

ZTEST(co_emcy, test_error_passive_raises_8120h_cleared_when_error_active)
{
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_WARNING);
	zassert_equal(sim.n_sent, 0, "warning is still error active");
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	assert_emcy(0, EMCY_ID, 0x8120, 0x11, NULL);
	zassert_true(co_emcy_is_active(&t.node, 0x8120));
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	zassert_equal(sim.n_sent, 1, "same state, nothing new");
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_WARNING);
	zassert_equal(sim.n_sent, 2);
	assert_emcy(1, EMCY_ID, 0x0000, 0x00, NULL);
	zassert_equal(od_read_u(0x1001, 0), 0x00);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
}

ZTEST(co_emcy, test_bus_off_applies_1029h_and_recovery_raises_8140h)
{
	co_sim_nmt(0x01, NODE_ID); /* Operational */
	sim.n_sent = 0;
	sim.now = 20 * MS;
	co_line_process(&sim.line, sim.now);
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	assert_emcy(0, EMCY_ID, 0x8120, 0x11, NULL);
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL,
		      "1029h sub1 = 0: bus-off sends Operational to Pre-operational");
	zassert_equal(sim.n_sent, 1, "nothing to send while bus-off");

	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_ACTIVE);
	zassert_equal(sim.n_sent, 3);
	assert_emcy(1, EMCY_ID, 0x8140, 0x11, NULL);
	assert_emcy(2, EMCY_ID, 0x0000, 0x11, NULL); /* 8120h cleared, 8140h still held */
	zassert_equal(od_read_u(0x1003, 1), 0x00008140U);
	zassert_true(co_emcy_is_active(&t.node, 0x8140));
	zassert_false(co_emcy_is_active(&t.node, 0x8120));

	co_sim_run_until(20 * MS + CONFIG_CANOPEN_EMCY_COMM_HOLD_MS * MS);
	zassert_equal(sim.n_sent, 4);
	assert_emcy(3, EMCY_ID, 0x0000, 0x00, NULL);
	zassert_equal(od_read_u(0x1001, 0), 0x00);
}

ZTEST(co_emcy, test_bus_off_1029h_1_and_2)
{
	co_sim_nmt(0x01, NODE_ID);
	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 1, 1), 0U);
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL, "1: no change");
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	zassert_true(co_emcy_is_active(&t.node, 0x8140), "recovered into error passive");
	zassert_true(co_emcy_is_active(&t.node, 0x8120));

	zassert_equal(co_sim_write(&t.node, 0x1029, 1, 2, 1), 0U);
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_STOPPED, "2: Stopped");
}

ZTEST(co_emcy, test_reset_communication_keeps_8120h_while_still_passive)
{
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	line_event(CO_LINE_EV_RX_OVERRUN, 0);
	zassert_equal(od_read_u(0x1001, 0), 0x11);
	co_sim_nmt(0x82, NODE_ID); /* Reset communication */
	zassert_true(co_emcy_is_active(&t.node, 0x8120), "still passive");
	zassert_false(co_emcy_is_active(&t.node, 0x8110), "an event error restarts");
	zassert_equal(od_read_u(0x1001, 0), 0x11);
	sim.n_sent = 0;
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_ACTIVE);
	assert_emcy(0, EMCY_ID, 0x0000, 0x00, NULL);
}

static void app_event_cb(struct co_line *line, enum co_line_event event, int arg, void *user_data)
{
	int *calls = user_data;

	/* The application's callback runs first, without the node's lock. */
	zassert_equal(sim.n_sent, 0);
	calls[0]++;
	calls[1] = arg;
}

ZTEST(co_emcy, test_application_line_callback_still_called)
{
	int calls[2] = {0};

	co_line_set_event_cb(&sim.line, app_event_cb, calls);
	line_event(CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	zassert_equal(calls[0], 1);
	zassert_equal(calls[1], CAN_STATE_ERROR_PASSIVE);
	zassert_equal(sim.n_sent, 1, "and the node's listener too");
	co_line_set_event_cb(&sim.line, NULL, NULL);
}

ZTEST(co_emcy, test_history_read_beyond_count_aborts_08000024h)
{
#if defined(CO_OD_HOOK_READ_CHECK)
	uint8_t buf[4];
	size_t len;
	uint32_t ab;

	zassert_ok(co_emcy_raise(&t.node, 0x5000, 0, NULL));
	zassert_ok(co_emcy_raise(&t.node, 0x6000, 0, NULL));
	zassert_equal(od_read_u(0x1003, 0), 2);
	zassert_equal(od_read_u(0x1003, 2), 0x5000U);
	co_node_lock(&t.node);
	ab = co_od_read(co_node_od(&t.node), 0x1003, 3, 0, buf, sizeof(buf), &len,
			CO_OD_WRITER_SDO);
	co_node_unlock(&t.node);
	zassert_equal(ab, CO_SDO_AB_NO_DATA, "sub3 > count 2: %08x", ab);
	zassert_equal(co_sim_write(&t.node, 0x1003, 0, 0, 1), 0U);
	co_node_lock(&t.node);
	ab = co_od_read(co_node_od(&t.node), 0x1003, 1, 0, buf, sizeof(buf), &len,
			CO_OD_WRITER_SDO);
	co_node_unlock(&t.node);
	zassert_equal(ab, CO_SDO_AB_NO_DATA, "empty history");
	co_node_lock(&t.node);
	ab = co_od_read(co_node_od(&t.node), 0x1003, 9, 0, buf, sizeof(buf), &len,
			CO_OD_WRITER_SDO);
	co_node_unlock(&t.node);
	zassert_equal(ab, CO_SDO_AB_NO_SUB, "beyond the array: no sub-index");
#else
	/* Needs the dictionary's read-check hook (CO_OD_HOOK_READ_CHECK, doc/emcy.md). */
	ztest_test_skip();
#endif
}

/* --- Two lines (CiA 302-6): an EMCY goes on both and waits until both have room ---------- */

static struct {
	struct co_line line;
	bool busy;
	int n_emcy;
} red;

static int red_sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (red.busy) {
		return -EAGAIN;
	}
	red.n_emcy += frame->id == EMCY_ID;
	return 0;
}

static void before_two_lines(void *f)
{
	memset(&t, 0, sizeof(t));
	memset(&red, 0, sizeof(red));
	co_sim_init();
	co_line_init_sim(&red.line, "red", red_sink, NULL);
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &emcy_test_od_def, &t.ram, NODE_ID));
	zassert_ok(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &red.line));
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

/* Both lines' deadlines run on the default line; the redundant one only drains its queue. */
static void run_two_lines_until(uint64_t at_us)
{
	co_sim_run_until(at_us);
	co_line_process(&red.line, sim.now);
}

/* A node that can have one line only (scenario canopen.emcy.one_line) has no second line. */
static void *two_lines_setup(void)
{
	if (!IS_ENABLED(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST_SUITE(co_emcy_two_lines, NULL, two_lines_setup, before_two_lines, NULL, NULL);

ZTEST(co_emcy_two_lines, test_redundant_line_tx_queue_full_emcy_waits_then_goes_on_both)
{
	const struct can_frame filler = {.id = 0x7ff, .dlc = 0};
	struct co_emcy_status st;
	int idx[4];

	/* The redundant line's controller pushes back until its TX queue is full. */
	red.busy = true;
	while (co_line_tx_space(&red.line) > 0) {
		zassert_ok(co_line_send(&red.line, &filler));
	}
	zassert_true(co_line_tx_space(&sim.line) > 0, "the default line has room");

	zassert_ok(co_emcy_raise(&t.node, 0x5000, 0, NULL), "kept, not an error");
	zassert_equal(emcy_frames(idx, 4), 0, "not sent on the default line alone");
	run_two_lines_until(sim.now + 25 * MS);
	zassert_equal(emcy_frames(idx, 4), 0, "still waiting while the redundant queue is full");
	co_emcy_get_status(&t.node, &st);
	zassert_equal(st.overflows, 0U);

	/* The redundant controller takes frames again: the EMCY goes on both at the next try. */
	red.busy = false;
	co_line_process(&red.line, sim.now);
	zassert_equal(red.n_emcy, 0);
	run_two_lines_until(sim.now + 10 * MS);
	zassert_equal(emcy_frames(idx, 4), 1, "one EMCY on the default line");
	assert_emcy(idx[0], EMCY_ID, 0x5000, 0x01, NULL);
	zassert_equal(red.n_emcy, 1, "and its copy on the redundant line");
}
