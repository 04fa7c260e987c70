/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT slave, heartbeat producer/consumer, node and life guarding, driven frame by frame on a
 * simulation line (no thread, simulated time). Frames the node sends land in `sent`.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>

#include "co_sim.h"
#include "nmt_test_od.h"

#define NODE_ID 0x21
#define MS      1000ULL
#define MAX_TX  64

static struct {
	struct co_node node;
	struct nmt_test_od_ram ram;
	/* Indications seen. */
	int hb_events[16];
	uint8_t hb_ids[16];
	uint8_t hb_states[16];
	int n_hb;
	int life[8];
	int n_life;
	enum co_nmt_state veto_to;
	int n_state_ind;
} t;

static void hb_ind(struct co_node *node, uint8_t remote_id, enum co_hb_event event,
		   enum co_nmt_state state, void *user_data)
{
	t.hb_events[t.n_hb] = event;
	t.hb_ids[t.n_hb] = remote_id;
	t.hb_states[t.n_hb++] = (uint8_t)state;
}

static void life_ind(struct co_node *node, bool lost, void *user_data)
{
	t.life[t.n_life++] = lost;
}

static int state_ind(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
		     void *user_data)
{
	t.n_state_ind++;
	return to == t.veto_to ? -EACCES : 0;
}

static void clear_sent(void)
{
	sim.n_sent = 0;
}

static void assert_state_frame(int i, uint32_t id, uint8_t byte)
{
	zassert_true(i < sim.n_sent, "frame %d missing (sent %d)", i, sim.n_sent);
	zassert_equal(sim.sent[i].id, id, "frame %d id %x", i, sim.sent[i].id);
	zassert_equal(sim.sent[i].dlc, 1);
	zassert_equal(sim.sent[i].data[0], byte, "frame %d byte %02x", i, sim.sent[i].data[0]);
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	t.veto_to = CO_NMT_INITIALISING; /* veto nothing */
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &nmt_test_od_def, &t.ram, NODE_ID));
	co_hb_set_ind(&t.node, hb_ind, NULL);
	co_life_set_ind(&t.node, life_ind, NULL);
	co_nmt_set_state_ind(&t.node, state_ind, NULL);
	zassert_ok(co_node_start(&t.node));
}

ZTEST_SUITE(co_nmt, NULL, NULL, before, NULL, NULL);

ZTEST(co_nmt, test_boot_up_then_pre_operational_heartbeat_after_one_period)
{
	assert_state_frame(0, 0x700 + NODE_ID, 0x00);
	zassert_equal(sim.n_sent, 1, "only the boot-up message at start");
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(co_node_start(&t.node), -EALREADY);

	co_sim_run_until(999 * MS);
	zassert_equal(sim.n_sent, 1, "no heartbeat before 1017h = 1000 ms");
	co_sim_run_until(1000 * MS);
	assert_state_frame(1, 0x700 + NODE_ID, 0x7f);
	co_sim_run_until(3000 * MS);
	zassert_equal(sim.n_sent, 4, "one heartbeat per period");
}

ZTEST(co_nmt, test_commands_change_state_and_heartbeat_shows_it_at_once)
{
	clear_sent();
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL);
	assert_state_frame(0, 0x700 + NODE_ID, 0x05);

	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_STOPPED);
	assert_state_frame(1, 0x700 + NODE_ID, 0x04);
	co_sim_run_until(1000 * MS);
	assert_state_frame(2, 0x700 + NODE_ID, 0x04);

	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, 0);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	assert_state_frame(3, 0x700 + NODE_ID, 0x7f);

	co_sim_nmt(CO_NMT_CS_START, 0);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL, "broadcast");
	co_sim_nmt(CO_NMT_CS_START, 0);
	zassert_equal(sim.n_sent, 5, "a command for the current state changes nothing");
}

ZTEST(co_nmt, test_frames_that_are_not_for_us_or_malformed_are_ignored)
{
	uint8_t three[3] = {CO_NMT_CS_START, NODE_ID, 0};
	uint8_t two[2] = {CO_NMT_CS_START, NODE_ID};

	clear_sent();
	co_sim_nmt(CO_NMT_CS_START, NODE_ID + 1);
	co_sim_rx_flags(0x000, 3, three, 0);
	co_sim_rx_flags(0x000, 1, two, 0);
	co_sim_rx_flags(0x000, 2, two, CAN_FRAME_RTR);
	co_sim_nmt(0x03, NODE_ID); /* unknown command specifier */
	co_sim_nmt(0x83, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(sim.n_sent, 0, "no reaction at all");
}

ZTEST(co_nmt, test_application_can_refuse_operational)
{
	t.veto_to = CO_NMT_OPERATIONAL;
	clear_sent();
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(sim.n_sent, 0);
	zassert_equal(co_nmt_req(&t.node, CO_NMT_CS_START), -EPERM);
	zassert_equal(co_nmt_req(&t.node, CO_NMT_CS_STOP), 0, "other changes still allowed");
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_STOPPED);
	zassert_equal(co_nmt_req(&t.node, (enum co_nmt_cs)0x42), -EINVAL);
}

ZTEST(co_nmt, test_reset_communication_reloads_comm_objects_only)
{
	uint16_t v;

	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 500, 2));
	zassert_ok(co_sim_write(&t.node, 0x2001, 0, 700, 2));
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	clear_sent();

	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	assert_state_frame(0, 0x700 + NODE_ID, 0x00);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u16(co_node_od(&t.node), 0x1017, 0, &v));
	zassert_equal(v, 1000, "1017h back to its default");
	zassert_ok(co_od_get_u16(co_node_od(&t.node), 0x2001, 0, &v));
	zassert_equal(v, 700, "2001h kept by Reset Communication");
	co_node_unlock(&t.node);

	co_sim_nmt(CO_NMT_CS_RESET_NODE, 0);
	assert_state_frame(1, 0x700 + NODE_ID, 0x00);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u16(co_node_od(&t.node), 0x2001, 0, &v));
	zassert_equal(v, 100, "2001h back to its default after Reset Node");
	co_node_unlock(&t.node);
}

ZTEST(co_nmt, test_new_node_id_takes_effect_at_reset_communication)
{
	zassert_equal(co_node_set_pending_id(&t.node, 0), -EINVAL);
	zassert_ok(co_node_set_pending_id(&t.node, 0x05));
	zassert_equal(co_node_id(&t.node), NODE_ID);
	clear_sent();
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	assert_state_frame(0, 0x705, 0x00);
	co_sim_nmt(CO_NMT_CS_START, 0x05);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL);
}

ZTEST(co_nmt, test_heartbeat_period_write_takes_effect_at_once)
{
	sim.now = 10 * MS;
	co_line_process(&sim.line, sim.now);
	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 100, 2));
	clear_sent();
	co_sim_run_until(109 * MS);
	zassert_equal(sim.n_sent, 0);
	co_sim_run_until(110 * MS);
	zassert_equal(sim.n_sent, 1, "next heartbeat one new period after the write");
	co_sim_run_until(410 * MS);
	zassert_equal(sim.n_sent, 4);
	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	co_sim_run_until(5000 * MS);
	zassert_equal(sim.n_sent, 4, "1017h = 0 stops the heartbeat");
}

static void hb_from(uint8_t id, uint8_t state)
{
	co_sim_rx_flags(0x700 + id, 1, &state, 0);
}

ZTEST(co_nmt, test_heartbeat_consumer_events)
{
	zassert_ok(co_sim_write(&t.node, 0x1016, 1, (5U << 16) | 200U, 4));
	enum co_nmt_state st;

	zassert_equal(co_hb_get_remote_state(&t.node, 5, &st), -EAGAIN);
	zassert_equal(co_hb_get_remote_state(&t.node, 6, &st), -ENOENT);

	co_sim_run_until(1000 * MS);
	zassert_equal(t.n_hb, 0, "a node that never sent a heartbeat raises nothing");

	hb_from(5, 0x7f);
	zassert_equal(t.hb_events[0], CO_HB_EV_STARTED);
	zassert_equal(t.hb_ids[0], 5);
	zassert_ok(co_hb_get_remote_state(&t.node, 5, &st));
	zassert_equal(st, CO_NMT_PRE_OPERATIONAL);

	co_sim_run_until(1150 * MS);
	hb_from(5, 0x05);
	zassert_equal(t.hb_events[1], CO_HB_EV_STATE);
	zassert_equal(t.hb_states[1], 0x05);

	co_sim_run_until(1349 * MS);
	zassert_equal(t.n_hb, 2, "within the consumer time since the last heartbeat");
	co_sim_run_until(1351 * MS);
	zassert_equal(t.hb_events[2], CO_HB_EV_LOST);

	hb_from(5, 0x05);
	zassert_equal(t.hb_events[3], CO_HB_EV_RECOVERED);

	hb_from(5, 0x00);
	zassert_equal(t.hb_events[4], CO_HB_EV_BOOTUP);
	co_sim_run_until(3000 * MS);
	zassert_equal(t.n_hb, 5, "after a boot-up, monitoring waits for the first heartbeat");
}

ZTEST(co_nmt, test_heartbeat_consumer_ignores_guarding_frames_and_bad_lengths)
{
	uint8_t two[2] = {0x05, 0};
	uint8_t toggled = 0x85;

	zassert_ok(co_sim_write(&t.node, 0x1016, 2, (7U << 16) | 100U, 4));
	co_sim_rx_flags(0x707, 1, NULL, CAN_FRAME_RTR);
	co_sim_rx_flags(0x707, 2, two, 0);
	co_sim_rx_flags(0x707, 1, &toggled, 0);
	zassert_equal(t.n_hb, 0);
	hb_from(7, 0x05);
	zassert_equal(t.n_hb, 1);
}

/*
 * The dictionary's 1016h has four entries: each is stored, but only the first
 * CONFIG_CANOPEN_HB_CONSUMERS are monitored (their heartbeats heard).
 */
ZTEST(co_nmt, test_consumer_entries_beyond_the_configured_count_are_not_monitored)
{
	for (uint8_t sub = 1; sub <= 4U; sub++) {
		uint8_t remote = (uint8_t)(20U + sub);
		uint32_t v = ((uint32_t)remote << 16) | 100U;
		uint32_t back = 0;
		int before = t.n_hb;

		zassert_ok(co_sim_write(&t.node, 0x1016, sub, v, 4));
		co_node_lock(&t.node);
		zassert_ok(co_od_get_u32(co_node_od(&t.node), 0x1016, sub, &back));
		co_node_unlock(&t.node);
		zassert_equal(back, v, "1016h:%u stored", sub);
		hb_from(remote, 0x05);
		zassert_equal(t.n_hb - before, sub <= CONFIG_CANOPEN_HB_CONSUMERS ? 1 : 0,
			      "1016h:%u monitored only when served", sub);
	}
}

ZTEST(co_nmt, test_two_entries_for_one_node_are_refused)
{
	zassert_ok(co_sim_write(&t.node, 0x1016, 1, (9U << 16) | 100U, 4));
	zassert_equal(co_sim_write(&t.node, 0x1016, 2, (9U << 16) | 300U, 4),
		      CO_SDO_AB_PARAM_INCOMPAT);
	zassert_ok(co_sim_write(&t.node, 0x1016, 2, (9U << 16) | 0U, 4), "time 0: entry unused");
	zassert_ok(co_sim_write(&t.node, 0x1016, 1, (9U << 16) | 150U, 4),
		   "rewriting the same entry");
	zassert_ok(co_sim_write(&t.node, 0x1016, 3, (10U << 16) | 300U, 4));
}

ZTEST(co_nmt, test_node_guarding_answers_toggle_and_only_without_heartbeat)
{
	if (!IS_ENABLED(CONFIG_CANOPEN_NODE_GUARDING)) {
		ztest_test_skip(); /* test_guarding_only_with_node_guarding */
	}
	clear_sent();
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	zassert_equal(sim.n_sent, 0, "1017h != 0: heartbeat node, no guarding answers");

	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	assert_state_frame(0, 0x700 + NODE_ID, 0x7f);
	assert_state_frame(1, 0x700 + NODE_ID, 0xff);
	assert_state_frame(2, 0x700 + NODE_ID, 0x7f);

	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, 0);
	zassert_equal(sim.n_sent, 3, "a data frame is not a guarding request");

	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	assert_state_frame(3, 0x700 + NODE_ID, 0x85);

	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, NODE_ID);
	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	assert_state_frame(5, 0x700 + NODE_ID, 0x7f); /* [4] is the boot-up */
}

ZTEST(co_nmt, test_life_guarding_event_and_resolution)
{
	if (!IS_ENABLED(CONFIG_CANOPEN_NODE_GUARDING)) {
		ztest_test_skip(); /* test_guarding_only_with_node_guarding */
	}
	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	zassert_ok(co_sim_write(&t.node, 0x100C, 0, 100, 2));
	zassert_ok(co_sim_write(&t.node, 0x100D, 0, 3, 1));
	co_sim_run_until(5000 * MS);
	zassert_equal(t.n_life, 0, "life guarding starts with the first request");

	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	co_sim_run_until(5299 * MS);
	zassert_equal(t.n_life, 0);
	co_sim_run_until(5300 * MS);
	zassert_equal(t.n_life, 1);
	zassert_equal(t.life[0], true, "life time 100 ms x 3 passed");

	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	zassert_equal(t.n_life, 2);
	zassert_equal(t.life[1], false, "a new request resolves the event");

	zassert_ok(co_sim_write(&t.node, 0x100D, 0, 0, 1));
	co_sim_run_until(9000 * MS);
	zassert_equal(t.n_life, 2, "life time factor 0 turns life guarding off");
}

ZTEST(co_nmt, test_stopped_node_keeps_error_control)
{
	if (!IS_ENABLED(CONFIG_CANOPEN_NODE_GUARDING)) {
		ztest_test_skip(); /* test_guarding_only_with_node_guarding */
	}
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	clear_sent();
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	assert_state_frame(0, 0x700 + NODE_ID, 0x04);
}

/*
 * Guarding requests are answered, and their end is a life guarding event, only with
 * CONFIG_CANOPEN_NODE_GUARDING; without it 100Ch/100Dh are plain objects.
 */
ZTEST(co_nmt, test_guarding_only_with_node_guarding)
{
	bool guarding = IS_ENABLED(CONFIG_CANOPEN_NODE_GUARDING);

	zassert_ok(co_sim_write(&t.node, 0x1017, 0, 0, 2));
	zassert_ok(co_sim_write(&t.node, 0x100C, 0, 100, 2));
	zassert_ok(co_sim_write(&t.node, 0x100D, 0, 3, 1));
	clear_sent();
	co_sim_rx_flags(0x700 + NODE_ID, 1, NULL, CAN_FRAME_RTR);
	zassert_equal(sim.n_sent, guarding ? 1 : 0, "answered only with guarding");
	co_sim_run_until(sim.now + 400 * MS);
	zassert_equal(t.n_life, guarding ? 1 : 0, "life guarding event only with guarding");
}
