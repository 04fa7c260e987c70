/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO service driven frame by frame on a simulation line (no thread, simulated time). Frames
 * the node sends land in `sent`. Configuration goes through the dictionary as the SDO server
 * would write it (CO_OD_WRITER_SDO), so every abort code is the one a master would see.
 *
 * Dictionary (objdict/pdo_test.eds): RPDO 0 valid on 200h+N mapping 2000h:01 (U8) and 2001h
 * (U16); TPDO 0 valid on 180h+N mapping 2000h:05 (U8) and 2002h (U32); the other PDOs off.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/sdo_abort.h>
#include <canopen/sync.h>

#include "co_sim.h"
#include "pdo_test_od.h"

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define SYNC_ID 0x080
#define MS      1000ULL
#define MAX_TX  256

#define INVALID 0x80000000U
#define NO_RTR  0x40000000U

static struct {
	struct co_node node;
	struct pdo_test_od_ram ram;
	int n_rpdo_ind;
	uint16_t rpdo_ind_num;
	int n_tpdo_ind;
	uint8_t pre_seen;
	uint8_t post_seen;
} t;

static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	t.n_rpdo_ind++;
	t.rpdo_ind_num = num;
}

static void tpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	t.n_tpdo_ind++;
}

static uint8_t get_u8(uint16_t index, uint8_t sub)
{
	uint8_t v = 0xEE;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), index, sub, &v));
	co_node_unlock(&t.node);
	return v;
}

static void pre_sync(struct co_node *node, uint8_t counter, void *user_data)
{
	t.pre_seen = get_u8(0x2000, 1);
}

static void post_sync(struct co_node *node, uint8_t counter, void *user_data)
{
	t.post_seen = get_u8(0x2000, 1);
}

static void rx_rtr(uint32_t id, uint8_t dlc)
{
	struct can_frame f = {.id = id, .dlc = dlc, .flags = CAN_FRAME_RTR};

	co_line_rx(&sim.line, &f, sim.now);
}

static void sync_rx(void)
{
	co_sim_rx(SYNC_ID, 0, NULL);
}

static void sync_rx_counter(uint8_t c)
{
	co_sim_rx(SYNC_ID, 1, &c);
}

static void app_u8(uint16_t index, uint8_t sub, uint8_t v)
{
	co_node_lock(&t.node);
	zassert_ok(co_od_set_u8(co_node_od(&t.node), index, sub, v, CO_OD_WRITER_APP));
	co_node_unlock(&t.node);
}

static void app_u32(uint16_t index, uint8_t sub, uint32_t v)
{
	co_node_lock(&t.node);
	zassert_ok(co_od_set_u32(co_node_od(&t.node), index, sub, v, CO_OD_WRITER_APP));
	co_node_unlock(&t.node);
}

static int count(uint32_t id)
{
	int n = 0;

	for (int i = 0; i < sim.n_sent; i++) {
		n += sim.sent[i].id == id;
	}
	return n;
}

/* The k-th (0-based) frame sent with @p id, or NULL. */
static const struct can_frame *nth(uint32_t id, int k)
{
	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == id && k-- == 0) {
			return &sim.sent[i];
		}
	}
	return NULL;
}

static uint64_t nth_at(uint32_t id, int k)
{
	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == id && k-- == 0) {
			return sim.sent_at[i];
		}
	}
	return UINT64_MAX;
}

static uint16_t emcy_code(int k)
{
	const struct can_frame *f = nth(EMCY_ID, k);

	zassert_not_null(f, "EMCY %d missing", k);
	return (uint16_t)(f->data[0] | (f->data[1] << 8));
}

/* Configure a PDO with the CiA 301 procedure (Pre-operational). */
static void setup_pdo(bool rx_pdo, int n, uint32_t cob, uint8_t type, const uint32_t *map,
		      uint8_t n_map)
{
	uint16_t comm = (rx_pdo ? 0x1400 : 0x1800) + n;
	uint16_t mapi = (rx_pdo ? 0x1600 : 0x1A00) + n;

	zassert_equal(co_sim_write(&t.node, comm, 1, cob | INVALID, 4), 0U);
	zassert_equal(co_sim_write(&t.node, mapi, 0, 0, 1), 0U);
	for (uint8_t i = 0; i < n_map; i++) {
		zassert_equal(co_sim_write(&t.node, mapi, i + 1, map[i], 4), 0U, "entry %u", i + 1);
	}
	zassert_equal(co_sim_write(&t.node, mapi, 0, n_map, 1), 0U);
	zassert_equal(co_sim_write(&t.node, comm, 2, type, 1), 0U);
	zassert_equal(co_sim_write(&t.node, comm, 1, cob, 4), 0U);
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &pdo_test_od_def, &t.ram, NODE_ID));
	co_rpdo_set_ind(&t.node, rpdo_ind, NULL);
	co_tpdo_set_ind(&t.node, tpdo_ind, NULL);
	co_sync_set_ind(&t.node, pre_sync, NULL);
	co_sync_set_post_ind(&t.node, post_sync, NULL);
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

static void go_operational(void)
{
	co_sim_nmt(0x01, NODE_ID);
	sim.n_sent = 0;
}

ZTEST_SUITE(co_pdo, NULL, NULL, before, NULL, NULL);

/* --- RPDO ------------------------------------------------------------------------------- */

ZTEST(co_pdo, test_rpdo_applied_only_in_operational)
{
	const uint8_t d[3] = {0x11, 0x34, 0x12};
	uint16_t w = 0;

	co_sim_rx(0x200 + NODE_ID, 3, d);
	zassert_equal(get_u8(0x2000, 1), 0, "RPDO in Pre-operational is ignored");
	zassert_equal(t.n_rpdo_ind, 0);

	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, d);
	zassert_equal(get_u8(0x2000, 1), 0x11);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u16(co_node_od(&t.node), 0x2001, 0, &w));
	co_node_unlock(&t.node);
	zassert_equal(w, 0x1234, "little endian");
	zassert_equal(t.n_rpdo_ind, 1);
	zassert_equal(t.rpdo_ind_num, 0);

	co_sim_nmt(0x02, NODE_ID); /* Stopped */
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x22, 0, 0});
	zassert_equal(get_u8(0x2000, 1), 0x11, "RPDO in Stopped is ignored");
	zassert_equal(sim.n_sent, 0, "nothing sent");
}

ZTEST(co_pdo, test_rpdo_length_errors_emcy_8210h_8220h)
{
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 2, (const uint8_t[]){0x55, 0x66});
	zassert_equal(get_u8(0x2000, 1), 0, "a short RPDO is not processed");
	zassert_equal(count(EMCY_ID), 1);
	zassert_equal(emcy_code(0), 0x8210);
	co_sim_rx(0x200 + NODE_ID, 2, (const uint8_t[]){0x55, 0x66});
	zassert_equal(count(EMCY_ID), 1, "raised once while it lasts");

	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x55, 0x66, 0x77});
	zassert_equal(get_u8(0x2000, 1), 0x55);
	zassert_equal(count(EMCY_ID), 2);
	zassert_equal(emcy_code(1), 0x0000, "the right length clears it");

	co_sim_rx(0x200 + NODE_ID, 8, (const uint8_t[]){0x56, 0x66, 0x77, 1, 2, 3, 4, 5});
	zassert_equal(get_u8(0x2000, 1), 0x56, "a long RPDO is processed");
	zassert_equal(count(EMCY_ID), 3);
	zassert_equal(emcy_code(2), 0x8220);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x57, 0x66, 0x77});
	zassert_equal(count(EMCY_ID), 4);
	zassert_equal(emcy_code(3), 0x0000);
}

ZTEST(co_pdo, test_rpdo_timeout_emcy_8250h_and_clear)
{
	zassert_equal(co_sim_write(&t.node, 0x1400, 5, 100, 2), 0U, "event timer 100 ms");
	go_operational();
	co_sim_run_until(500 * MS);
	zassert_equal(count(EMCY_ID), 0, "the monitor arms at the first RPDO");

	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){1, 2, 3});
	co_sim_run_until(599 * MS);
	zassert_equal(count(EMCY_ID), 0);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){1, 2, 3});
	co_sim_run_until(698 * MS);
	zassert_equal(count(EMCY_ID), 0, "restarted by every RPDO");
	co_sim_run_until(699 * MS);
	zassert_equal(count(EMCY_ID), 1);
	zassert_equal(emcy_code(0), 0x8250);
	co_sim_run_until(2000 * MS);
	zassert_equal(count(EMCY_ID), 1, "raised once");

	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){1, 2, 3});
	zassert_equal(count(EMCY_ID), 2);
	zassert_equal(emcy_code(1), 0x0000, "cleared by the next RPDO");
}

ZTEST(co_pdo, test_rpdo_dummy_mapping)
{
	/* U8 dummy, 2000h:02, U16 dummy, 2000h:03. */
	const uint32_t map[] = {0x00050008, 0x20000208, 0x00060010, 0x20000308};

	setup_pdo(true, 1, 0x321, 255, map, 4);
	go_operational();
	co_sim_rx(0x321, 5, (const uint8_t[]){0xAA, 0x11, 0xBB, 0xCC, 0x22});
	zassert_equal(get_u8(0x2000, 2), 0x11);
	zassert_equal(get_u8(0x2000, 3), 0x22);
	zassert_equal(t.rpdo_ind_num, 1);
	zassert_equal(count(EMCY_ID), 0, "5 mapped bytes");
}

ZTEST(co_pdo, test_rpdo_dummy_entry_rules)
{
	zassert_equal(co_sim_write(&t.node, 0x1401, 1, INVALID | 0x321, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x00050010, 4), CO_SDO_AB_NO_MAP,
		      "U8 dummy of 16 bits");
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x00050108, 4), CO_SDO_AB_NO_MAP,
		      "dummy with a sub-index");
#if !defined(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x00010001, 4), CO_SDO_AB_NO_MAP,
		      "BOOLEAN dummy (1 bit) needs bit-wise mapping");
#endif
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, INVALID | 0x2A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1A01, 1, 0x00050008, 4), CO_SDO_AB_NO_MAP,
		      "no dummy in a TPDO");
}

ZTEST(co_pdo, test_sync_rpdo_committed_at_next_sync)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(true, 0, 0x200 + NODE_ID, 1, map, 1);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 1, (const uint8_t[]){0x42});
	zassert_equal(get_u8(0x2000, 1), 0, "held until SYNC");
	zassert_equal(t.n_rpdo_ind, 0);
	sync_rx();
	zassert_equal(get_u8(0x2000, 1), 0x42);
	zassert_equal(t.n_rpdo_ind, 1);
	zassert_equal(t.pre_seen, 0, "the first SYNC indication runs before the commit");
	zassert_equal(t.post_seen, 0x42, "the second one after it");
	sync_rx();
	zassert_equal(t.n_rpdo_ind, 1, "committed once");
}

ZTEST(co_pdo, test_sync_window_discards_late_rpdo)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(true, 0, 0x200 + NODE_ID, 0, map, 1);
	zassert_equal(co_sim_write(&t.node, 0x1007, 0, 5000, 4), 0U, "window 5 ms");
	go_operational();
	sync_rx();
	co_sim_run_until(3 * MS);
	co_sim_rx(0x200 + NODE_ID, 1, (const uint8_t[]){0x10});
	co_sim_run_until(10 * MS);
	sync_rx();
	zassert_equal(get_u8(0x2000, 1), 0x10, "inside the window: committed");
	co_sim_run_until(16 * MS);
	co_sim_rx(0x200 + NODE_ID, 1, (const uint8_t[]){0x20});
	co_sim_run_until(20 * MS);
	sync_rx();
	zassert_equal(get_u8(0x2000, 1), 0x10, "after the window: discarded");
	zassert_equal(t.n_rpdo_ind, 1);
}

/* --- TPDO ------------------------------------------------------------------------------- */

ZTEST(co_pdo, test_tpdo_request_packs_mapped_objects)
{
	zassert_equal(co_tpdo_send_req(&t.node, 0), -ENETDOWN, "not in Pre-operational");
	go_operational();
	app_u8(0x2000, 5, 0xAB);
	sim.n_sent = 0;
	app_u32(0x2002, 0, 0x12345678);
	zassert_equal(count(0x180 + NODE_ID), 1, "change of state of a mapped object");
	sim.n_sent = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].id, 0x180 + NODE_ID);
	zassert_equal(sim.sent[0].dlc, 5);
	const uint8_t want[5] = {0xAB, 0x78, 0x56, 0x34, 0x12};

	zassert_mem_equal(sim.sent[0].data, want, 5);
	zassert_true(t.n_tpdo_ind > 0, "the application is asked to refresh the data");
	zassert_equal(co_tpdo_send_req(&t.node, 1), -EINVAL, "TPDO 1 is not valid");
	zassert_equal(co_tpdo_send_req(&t.node, 9), -EINVAL);
}

ZTEST(co_pdo, test_tpdo_change_of_state_only_for_mapped_objects_and_event_types)
{
	go_operational();
	app_u8(0x2000, 6, 1);
	zassert_equal(sim.n_sent, 0, "2000h:06 is not mapped");
	zassert_equal(co_sim_write(&t.node, 0x2000, 5, 7, 1), 0U);
	zassert_equal(sim.n_sent, 1, "an SDO write is a change of state too");
	zassert_equal(sim.sent[0].data[0], 7);

	const uint32_t map[] = {0x20000608};

	co_sim_nmt(0x80, NODE_ID);
	setup_pdo(false, 1, 0x2A1, 1, map, 1);
	go_operational();
	app_u8(0x2000, 6, 2);
	zassert_equal(count(0x2A1), 0, "cyclic TPDOs ignore changes of state");
}

/* The RPDO keeps which OD hooks cover its objects; a hook added later must still run. */
ZTEST(co_pdo, test_rpdo_write_is_change_of_state_of_a_tpdo_mapped_later)
{
	const uint32_t map[] = {0x20000108};

	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x11, 0, 0});
	zassert_equal(sim.n_sent, 0, "2000h:01 is in no TPDO yet");

	co_sim_nmt(0x80, NODE_ID);
	setup_pdo(false, 1, 0x2A1, 254, map, 1);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x22, 0, 0});
	zassert_equal(count(0x2A1), 1, "the RPDO write is a change of state of TPDO 1");
	zassert_equal(nth(0x2A1, 0)->data[0], 0x22);

	co_sim_nmt(0x80, NODE_ID);
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, INVALID | 0x2A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1A01, 0, 0, 1), 0U, "unmapped: its hook goes");
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, 0x2A1, 4), 0U);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x33, 0, 0});
	zassert_equal(count(0x2A1), 0);
	zassert_equal(get_u8(0x2000, 1), 0x33);
}

/*
 * A frame's objects are written one after the other as separate writes would be, also when
 * a hook changes the hook table half way: the notify hook of 2000h:01 adds a validate hook
 * that refuses every write of 2001h, so the second object of that same frame is refused.
 */
static int guard_calls;
static bool guard_arm;

static uint32_t refuse_2001(struct co_od *od, struct co_od_req *req, void *user_data)
{
	guard_calls++;
	return CO_SDO_AB_VALUE_HIGH;
}

static void arm_guard(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	const struct co_od_hook guard = {0x2001, 0x2001, 0, 0, refuse_2001, NULL, &guard_calls};

	if (guard_arm) {
		guard_arm = false;
		zassert_ok(co_od_hook_register(od, &guard));
	}
}

static uint16_t get_u16(uint16_t index, uint8_t sub)
{
	uint16_t v = 0xEEEE;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u16(co_node_od(&t.node), index, sub, &v));
	co_node_unlock(&t.node);
	return v;
}

ZTEST(co_pdo, test_rpdo_hook_that_changes_the_hook_table_mid_frame)
{
	const struct co_od_hook arm = {0x2000, 0x2000, 1, 1, NULL, arm_guard, &guard_arm};

	guard_calls = 0;
	guard_arm = false;
	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &arm));
	co_node_unlock(&t.node);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x11, 0x22, 0x33});
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x12, 0x23, 0x34});
	zassert_equal(get_u8(0x2000, 1), 0x12);
	zassert_equal(get_u16(0x2001, 0), 0x3423);

	guard_arm = true;
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x13, 0x24, 0x35});
	zassert_equal(get_u8(0x2000, 1), 0x13, "written before the hook table changed");
	zassert_equal(guard_calls, 1, "the new hook sees the rest of the frame");
	zassert_equal(get_u16(0x2001, 0), 0x3423, "refused: the old value stays");
	zassert_equal(t.n_rpdo_ind, 3, "the indication still runs");

	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &guard_calls), 1);
	co_node_unlock(&t.node);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x14, 0x25, 0x36});
	zassert_equal(get_u16(0x2001, 0), 0x3625, "and the mapping is plain again");
	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &guard_arm), 1);
	co_node_unlock(&t.node);
}

/*
 * The hooks of a mapped object see it as co_od_find() describes it, whatever the mapping
 * entry keeps (a compact entry rebuilds the description at each frame).
 */
static struct co_od_info seen_info[2];
static int n_seen;

static uint32_t record_info(struct co_od *od, struct co_od_req *req, void *user_data)
{
	if (n_seen < 2) {
		seen_info[n_seen] = *req->info;
	}
	n_seen++;
	zassert_equal(req->writer, CO_OD_WRITER_PDO);
	return 0U;
}

static void assert_info_is_found(const struct co_od_info *seen, uint16_t index, uint8_t sub)
{
	struct co_od_info found;

	zassert_equal(co_od_find(co_node_od(&t.node), index, sub, &found), 0U);
	zassert_equal_ptr(seen->desc, found.desc, "%04Xh:%u", index, sub);
	zassert_equal_ptr(seen->prov, found.prov);
	zassert_equal_ptr(seen->limit, found.limit);
	zassert_equal(seen->size, found.size);
	zassert_equal(seen->index, index);
	zassert_equal(seen->sub, sub);
	zassert_equal(seen->dtype, found.dtype);
	zassert_equal(seen->access, found.access);
	zassert_equal(seen->flags, found.flags);
	zassert_equal(seen->objcode, found.objcode, "%04Xh:%u", index, sub);
	zassert_equal(seen->group, found.group);
	zassert_equal(seen->entry, found.entry);
}

ZTEST(co_pdo, test_rpdo_hooks_see_the_mapped_objects_as_found)
{
	const struct co_od_hook rec[2] = {
		{0x2000, 0x2000, 1, 1, record_info, NULL, &n_seen},
		{0x2001, 0x2001, 0, 0, record_info, NULL, &n_seen},
	};

	n_seen = 0;
	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &rec[0]));
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &rec[1]));
	co_node_unlock(&t.node);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x41, 0x42, 0x43});
	zassert_equal(n_seen, 2, "one validate call per mapped object");
	assert_info_is_found(&seen_info[0], 0x2000, 1);
	assert_info_is_found(&seen_info[1], 0x2001, 0);
	zassert_equal(get_u8(0x2000, 1), 0x41);
	zassert_equal(get_u16(0x2001, 0), 0x4342);
	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &n_seen), 2);
	co_node_unlock(&t.node);
}

/* A notify hook alone on each object (the copy path) sees them as co_od_find() does too. */
static void record_notified(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	if (n_seen < 2) {
		seen_info[n_seen] = *req->info;
	}
	n_seen++;
}

ZTEST(co_pdo, test_rpdo_notify_hooks_see_the_mapped_objects_as_found)
{
	const struct co_od_hook rec[2] = {
		{0x2000, 0x2000, 1, 1, NULL, record_notified, &n_seen},
		{0x2001, 0x2001, 0, 0, NULL, record_notified, &n_seen},
	};

	n_seen = 0;
	memset(seen_info, 0xA5, sizeof(seen_info));
	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &rec[0]));
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &rec[1]));
	co_node_unlock(&t.node);
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x51, 0x52, 0x53});
	zassert_equal(n_seen, 2, "one notify call per mapped object");
	assert_info_is_found(&seen_info[0], 0x2000, 1);
	assert_info_is_found(&seen_info[1], 0x2001, 0);
	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &n_seen), 2);
	co_node_unlock(&t.node);
}

/*
 * A mapping entry keeps what an access needs and no more, the same on every board: the
 * object's descriptor, index, entry position, sub-index, size, mapped length, move and hook.
 */
ZTEST(co_pdo, test_map_entry_layout)
{
	zassert_equal(sizeof(struct co_pdo_map_ent),
		      ROUND_UP(sizeof(void *) + 10U, sizeof(void *)));
}

/*
 * The moves of a mapping are resolved when it is mapped and again after the hooks changed: a
 * hook registered on a mapped object once the PDO ran is run by its next frame, and once
 * removed it is run no more.
 */
static int late_notified;
static uint16_t late_value;

static void late_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	late_notified++;
	late_value = (uint16_t)co_od_req_uint(req);
}

static uint32_t late_refuse(struct co_od *od, struct co_od_req *req, void *user_data)
{
	return CO_SDO_AB_DATA_DEV_STATE;
}

ZTEST(co_pdo, test_hooks_registered_after_mapping_run_on_the_next_frame)
{
	const struct co_od_hook notify = {0x2001, 0x2001, 0, 0, NULL, late_notify, &late_notified};
	const struct co_od_hook refuse = {0x2001, 0x2001, 0, 0, late_refuse, NULL, &late_value};

	late_notified = 0;
	go_operational();
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x11, 0x22, 0x33});
	zassert_equal(get_u16(0x2001, 0), 0x3322);

	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &notify));
	co_node_unlock(&t.node);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x12, 0x23, 0x34});
	zassert_equal(late_notified, 1, "the new notify hook runs on the next frame");
	zassert_equal(late_value, 0x3423);

	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &refuse));
	co_node_unlock(&t.node);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x13, 0x24, 0x35});
	zassert_equal(get_u8(0x2000, 1), 0x13);
	zassert_equal(get_u16(0x2001, 0), 0x3423, "the new validate hook refused the write");
	zassert_equal(late_notified, 1, "and nothing was notified");

	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &late_value), 1);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &late_notified), 1);
	co_node_unlock(&t.node);
	co_sim_rx(0x200 + NODE_ID, 3, (const uint8_t[]){0x14, 0x25, 0x36});
	zassert_equal(get_u16(0x2001, 0), 0x3625, "written without the removed hooks");
	zassert_equal(late_notified, 1, "a removed hook no longer runs");
}

#if defined(CONFIG_CANOPEN_OD_PROVIDERS)
/*
 * Objects of a provider mapped into PDOs: 3000h:01 (U16) and 3000h:02 (U8), read, written
 * and described by the provider, whatever the mapping entry keeps of them.
 */
static struct {
	uint16_t u16;
	uint8_t u8;
	int infos;
	int reads;
	int writes;
} pv;

static uint32_t pv_info(const struct co_od_provider *p, struct co_od_info *info)
{
	pv.infos++;
	if (info->sub < 1U || info->sub > 2U) {
		return CO_SDO_AB_NO_SUB;
	}
	info->dtype = info->sub == 1U ? CO_DTYPE_UNSIGNED16 : CO_DTYPE_UNSIGNED8;
	info->size = info->sub == 1U ? 2U : 1U;
	info->access = CO_OD_ACCESS_RW;
	info->flags = CO_OD_F_MAP;
	return 0U;
}

static uint32_t pv_read(const struct co_od_provider *p, const struct co_od_info *info,
			uint32_t offset, void *buf, size_t cap, size_t *len)
{
	uint8_t v[2];

	pv.reads++;
	co_od_le_put(v, info->size, info->sub == 1U ? pv.u16 : pv.u8);
	*len = info->size <= cap ? info->size : cap;
	memcpy(buf, v, *len);
	return 0U;
}

static uint32_t pv_write(const struct co_od_provider *p, const struct co_od_info *info,
			 uint32_t offset, const void *data, size_t len, bool last)
{
	pv.writes++;
	zassert_equal(len, info->size, "the whole object");
	if (info->sub == 1U) {
		pv.u16 = (uint16_t)co_od_le_get(data, 2);
	} else {
		pv.u8 = (uint8_t)co_od_le_get(data, 1);
	}
	return 0U;
}

static const struct co_od_provider_api pv_api = {
	.info = pv_info, .read = pv_read, .write = pv_write};
static const struct co_od_provider pv_prov = {
	.api = &pv_api, .index_first = 0x3000, .index_last = 0x3000};

ZTEST(co_pdo, test_provider_objects_in_rpdo_and_tpdo)
{
	const uint32_t rmap[] = {0x30000110, 0x30000208};
	const uint32_t tmap[] = {0x30000208, 0x30000110};

	memset(&pv, 0, sizeof(pv));
	co_node_lock(&t.node);
	zassert_ok(co_od_provider_register(co_node_od(&t.node), &pv_prov));
	co_node_unlock(&t.node);
	setup_pdo(true, 1, 0x321, 255, rmap, 2);
	setup_pdo(false, 1, 0x2A1, 255, tmap, 2);
	go_operational();

	co_sim_rx(0x321, 3, (const uint8_t[]){0x34, 0x12, 0x56});
	zassert_equal(pv.u16, 0x1234);
	zassert_equal(pv.u8, 0x56);
	zassert_equal(pv.writes, 2);
	co_sim_rx(0x321, 3, (const uint8_t[]){0x78, 0x9A, 0xBC});
	zassert_equal(pv.u16, 0x9A78);
	zassert_equal(pv.u8, 0xBC);
	zassert_equal(pv.writes, 4);

	/* Each object an RPDO wrote was a change of state of the TPDO (no inhibit time). */
	zassert_equal(count(0x2A1), 4);
	zassert_mem_equal(nth(0x2A1, 3)->data, ((const uint8_t[]){0xBC, 0x78, 0x9A}), 3);
	sim.n_sent = 0;
	pv.reads = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 1));
	zassert_equal(count(0x2A1), 1);
	zassert_equal(nth(0x2A1, 0)->dlc, 3);
	zassert_mem_equal(nth(0x2A1, 0)->data, ((const uint8_t[]){0xBC, 0x78, 0x9A}), 3);
	zassert_equal(pv.reads, 2);
	zassert_equal(t.n_rpdo_ind, 2);
}
#endif

/* A read check registered on a mapped object after the TPDO went out is heard: zeros. */
static uint32_t no_read_2002(const struct co_od *od, const struct co_od_info *info,
			     enum co_od_writer reader, void *user_data)
{
	return CO_SDO_AB_NO_DATA;
}

static void no_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
}

ZTEST(co_pdo, test_tpdo_read_check_registered_later)
{
	const struct co_od_hook check = {0x2002, 0x2002, 0, 0, NULL, no_notify, &sim, no_read_2002};
	const uint8_t want[5] = {0xAB, 0x78, 0x56, 0x34, 0x12};
	const uint8_t zeros[5] = {0xAB, 0, 0, 0, 0};

	go_operational();
	app_u8(0x2000, 5, 0xAB);
	app_u32(0x2002, 0, 0x12345678);
	sim.n_sent = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(sim.n_sent, 2);
	zassert_mem_equal(sim.sent[1].data, want, 5);

	co_node_lock(&t.node);
	zassert_ok(co_od_hook_register(co_node_od(&t.node), &check));
	co_node_unlock(&t.node);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(sim.n_sent, 3);
	zassert_mem_equal(sim.sent[2].data, zeros, 5, "a refused read sends zeros");

	co_node_lock(&t.node);
	zassert_equal(co_od_hook_unregister(co_node_od(&t.node), &sim), 1);
	co_node_unlock(&t.node);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_mem_equal(sim.sent[3].data, want, 5);
}

ZTEST(co_pdo, test_tpdo_inhibit_defers_and_merges)
{
	zassert_equal(co_sim_write(&t.node, 0x1800, 3, 100, 2), CO_SDO_AB_INVALID_VALUE,
		      "inhibit while valid");
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, INVALID | (0x180 + NODE_ID), 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 3, 100, 2), 0U, "10 ms");
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, 0x180 + NODE_ID, 4), 0U);
	go_operational();
	co_sim_run_until(1 * MS);
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(sim.n_sent, 1);
	co_sim_run_until(3 * MS);
	app_u8(0x2000, 5, 1);
	zassert_ok(co_tpdo_send_req(&t.node, 0), "no error while inhibited");
	co_sim_run_until(5 * MS);
	app_u8(0x2000, 5, 2);
	zassert_equal(sim.n_sent, 1, "held back by the inhibit time");
	co_sim_run_until(10 * MS);
	zassert_equal(sim.n_sent, 1);
	co_sim_run_until(11 * MS);
	zassert_equal(sim.n_sent, 2, "one frame when the inhibit time ends");
	zassert_equal(sim.sent_at[1], 11 * MS);
	zassert_equal(sim.sent[1].data[0], 2, "with the latest data");
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 2, "requests were merged");
	for (int i = 0; i < 20; i++) {
		app_u8(0x2000, 5, (uint8_t)i);
		co_sim_run_until(sim.now + 300);
	}
	for (int i = 1; i < sim.n_sent; i++) {
		zassert_true(sim.sent_at[i] - sim.sent_at[i - 1] >= 10 * MS, "frames %d, %d", i - 1,
			     i);
	}
}

ZTEST(co_pdo, test_tpdo_event_timer)
{
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 254, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 5, 100, 2), 0U,
		      "event timer may change while valid");
	co_sim_run_until(500 * MS);
	zassert_equal(sim.n_sent, 0, "not in Pre-operational");
	go_operational();
	co_sim_run_until(850 * MS);
	zassert_equal(count(0x180 + NODE_ID), 3);
	zassert_equal(nth_at(0x180 + NODE_ID, 0), 600 * MS);
	zassert_equal(nth_at(0x180 + NODE_ID, 2), 800 * MS);
	app_u8(0x2000, 5, 9);
	zassert_equal(count(0x180 + NODE_ID), 4, "event at 850 ms");
	co_sim_run_until(949 * MS);
	zassert_equal(count(0x180 + NODE_ID), 4, "the event timer restarts at each frame");
	co_sim_run_until(950 * MS);
	zassert_equal(count(0x180 + NODE_ID), 5);
	co_sim_nmt(0x80, NODE_ID);
	co_sim_run_until(2000 * MS);
	zassert_equal(count(0x180 + NODE_ID), 5, "stops outside Operational");
}

ZTEST(co_pdo, test_tpdo_cyclic_every_nth_sync)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(false, 1, 0x2A1, 1, map, 1);
	setup_pdo(false, 2, 0x3A1, 3, map, 1);
	go_operational();
	for (int i = 1; i <= 9; i++) {
		app_u8(0x2000, 1, (uint8_t)i);
		sync_rx();
		zassert_equal(count(0x2A1), i, "type 1 at every SYNC");
		zassert_equal(count(0x3A1), i / 3, "type 3 at every 3rd SYNC (SYNC %d)", i);
	}
	zassert_equal(nth(0x3A1, 0)->data[0], 3, "sampled at its SYNC");
	zassert_equal(nth(0x3A1, 2)->data[0], 9);
	zassert_equal(count(0x180 + NODE_ID), 0, "event-driven TPDO 0 ignores SYNC");
}

ZTEST(co_pdo, test_tpdo_acyclic_sync_type_0)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(false, 1, 0x2A1, 0, map, 1);
	go_operational();
	sync_rx();
	zassert_equal(count(0x2A1), 0, "no event, no frame");
	zassert_ok(co_tpdo_send_req(&t.node, 1));
	zassert_equal(count(0x2A1), 0, "waits for SYNC");
	sync_rx();
	zassert_equal(count(0x2A1), 1);
	sync_rx();
	zassert_equal(count(0x2A1), 1, "once per event");
	app_u8(0x2000, 1, 5);
	zassert_equal(count(0x2A1), 0 + 1);
	sync_rx();
	zassert_equal(count(0x2A1), 2, "a change of state is an event");
	zassert_equal(nth(0x2A1, 1)->data[0], 5);
}

ZTEST(co_pdo, test_tpdo_sync_start_value)
{
	const uint32_t map[] = {0x20000108};
	uint8_t c = 0;

	setup_pdo(false, 1, 0x2A1, 2, map, 1);
	setup_pdo(false, 2, 0x3A1, 2, map, 1);
	zassert_equal(co_sim_write(&t.node, 0x1802, 6, 3, 1), CO_SDO_AB_INVALID_VALUE,
		      "not while valid");
	zassert_equal(co_sim_write(&t.node, 0x1802, 1, INVALID | 0x3A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1802, 6, 241, 1), CO_SDO_AB_INVALID_VALUE, "1..240");
	zassert_equal(co_sim_write(&t.node, 0x1802, 6, 3, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1802, 1, 0x3A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1019, 0, 5, 1), 0U);
	go_operational();
	/* Counters 1 2 3 4 5 1 2 3 4. */
	int sent_start[9];
	int sent_plain[9];

	for (int i = 0; i < 9; i++) {
		c = (uint8_t)(i % 5 + 1);
		app_u8(0x2000, 1, c);
		sync_rx_counter(c);
		sent_start[i] = count(0x3A1);
		sent_plain[i] = count(0x2A1);
	}
	/* Start value 3: SYNC 3 counts as the first, so frames at counters 4, 1, 3. */
	const int want_start[9] = {0, 0, 0, 1, 1, 2, 2, 3, 3};
	/* No start value: the first SYNC counts as the first, frames at 2, 4, 1, 3. */
	const int want_plain[9] = {0, 1, 1, 2, 2, 3, 3, 4, 4};

	for (int i = 0; i < 9; i++) {
		zassert_equal(sent_start[i], want_start[i], "start value, SYNC %d", i);
		zassert_equal(sent_plain[i], want_plain[i], "no start value, SYNC %d", i);
	}
	zassert_equal(nth(0x3A1, 0)->data[0], 4);
	zassert_equal(nth(0x3A1, 1)->data[0], 1);
}

ZTEST(co_pdo, test_sync_window_drops_late_tpdo)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(false, 1, INVALID | 0x2A1, 1, map, 1);
	zassert_equal(co_sim_write(&t.node, 0x1801, 3, 80, 2), 0U, "inhibit 8 ms");
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, 0x2A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1007, 0, 5000, 4), 0U, "window 5 ms");
	go_operational();
	sync_rx();
	zassert_equal(count(0x2A1), 1);
	co_sim_run_until(1 * MS);
	sync_rx();
	co_sim_run_until(9 * MS);
	zassert_equal(count(0x2A1), 1, "inhibited until 8 ms, window closed at 6 ms: dropped");

	zassert_equal(co_sim_write(&t.node, 0x1007, 0, 0, 4), 0U, "no window");
	co_sim_run_until(10 * MS);
	sync_rx();
	zassert_equal(count(0x2A1), 2);
	co_sim_run_until(11 * MS);
	sync_rx();
	co_sim_run_until(17 * MS);
	zassert_equal(count(0x2A1), 2);
	co_sim_run_until(18 * MS);
	zassert_equal(count(0x2A1), 3, "without a window the sample goes out late");
	zassert_equal(nth_at(0x2A1, 2), 18 * MS);
}

ZTEST(co_pdo, test_tpdo_rtr)
{
	const uint32_t map[] = {0x20000108};

	if (!IS_ENABLED(CONFIG_CANOPEN_PDO_RTR)) {
		ztest_test_skip();
	}
	setup_pdo(false, 1, 0x2A1, 253, map, 1);
	setup_pdo(false, 2, 0x3A1, 252, map, 1);
	go_operational();
	app_u8(0x2000, 1, 0x31);
	zassert_equal(sim.n_sent, 0, "RTR-only TPDOs ignore changes of state");
	rx_rtr(0x2A1, 1);
	zassert_equal(count(0x2A1), 1, "253: sampled and sent on RTR");
	zassert_equal(nth(0x2A1, 0)->data[0], 0x31);

	rx_rtr(0x3A1, 1);
	zassert_equal(count(0x3A1), 0, "252: nothing sampled yet");
	sync_rx();
	zassert_equal(count(0x3A1), 0, "252: SYNC only samples");
	app_u8(0x2000, 1, 0x32);
	rx_rtr(0x3A1, 1);
	zassert_equal(count(0x3A1), 1);
	zassert_equal(nth(0x3A1, 0)->data[0], 0x31, "252: the sample of the SYNC");

	co_sim_rx(0x2A1, 1, (const uint8_t[]){0});
	zassert_equal(count(0x2A1), 1, "a data frame is not a request");

	/* Bit 30 = 1: no RTR; refused for the RTR-only types. */
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, 0x2A1 | NO_RTR, 4), CO_SDO_AB_INVALID_VALUE,
		      "bit 30 may not change while valid");
	co_sim_nmt(0x80, NODE_ID);
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, INVALID | NO_RTR | 0x2A1, 4),
		      CO_SDO_AB_INVALID_VALUE, "253 needs RTR");
	zassert_equal(co_sim_write(&t.node, 0x1801, 2, 255, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, INVALID | NO_RTR | 0x2A1, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1801, 2, 253, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1801, 1, NO_RTR | 0x2A1, 4), 0U);
	go_operational();
	rx_rtr(0x2A1, 1);
	zassert_equal(sim.n_sent, 0, "RTR not allowed");
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 255, 1), 0U);
	rx_rtr(0x180 + NODE_ID, 0);
	zassert_equal(count(0x180 + NODE_ID), 1, "an RTR is an event for 254/255");
}

/* CONFIG_CANOPEN_PDO_RTR=n (scenario canopen.pdo.no_rtr): no receiver for remote frames. */
ZTEST(co_pdo, test_tpdo_rtr_disabled)
{
	const uint32_t map[] = {0x20000108};

	if (IS_ENABLED(CONFIG_CANOPEN_PDO_RTR)) {
		ztest_test_skip();
	}
	setup_pdo(false, 1, 0x2A1, 254, map, 1);
	zassert_equal(co_sim_write(&t.node, 0x1801, 2, 253, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1801, 2, 252, 1), CO_SDO_AB_INVALID_VALUE);
	go_operational();
	co_sim_run_until(10 * MS);
	int before_rtr = count(0x2A1);

	rx_rtr(0x2A1, 1);
	co_sim_run_until(20 * MS);
	zassert_equal(count(0x2A1), before_rtr, "a remote frame is not an event without RTR");
	app_u8(0x2000, 1, 0x33);
	co_sim_run_until(30 * MS);
	zassert_equal(count(0x2A1), before_rtr + 1, "a change of state still is");
}

ZTEST(co_pdo, test_nmt_gating)
{
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 254, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 5, 10, 2), 0U);
	co_sim_run_until(100 * MS);
	zassert_equal(sim.n_sent, 0, "Pre-operational");
	go_operational();
	co_sim_run_until(200 * MS);
	zassert_equal(count(0x180 + NODE_ID), 10);
	co_sim_nmt(0x02, NODE_ID);
	sim.n_sent = 0;
	co_sim_run_until(300 * MS);
	zassert_equal(sim.n_sent, 0, "Stopped");
	zassert_equal(co_tpdo_send_req(&t.node, 0), -ENETDOWN);
	co_sim_nmt(0x01, NODE_ID);
	co_sim_run_until(400 * MS);
	zassert_equal(count(0x180 + NODE_ID), 10, "Operational again");
}

ZTEST(co_pdo, test_29_bit_pdos)
{
	const uint32_t map[] = {0x20000108};
	struct can_frame f = {.id = 0x12345, .dlc = 1, .flags = CAN_FRAME_IDE, .data = {0x77}};

	setup_pdo(true, 1, 0x20012345, 255, map, 1);
	setup_pdo(false, 1, 0x20054321, 254, map, 1);
	go_operational();
	co_sim_rx(0x12345, 1, (const uint8_t[]){0x66});
	zassert_equal(get_u8(0x2000, 1), 0, "an 11-bit frame is another CAN-ID");
	co_line_rx(&sim.line, &f, sim.now);
	zassert_equal(get_u8(0x2000, 1), 0x77);
	zassert_equal(count(0x54321), 1, "the change of state goes out on the 29-bit id");
	zassert_true((nth(0x54321, 0)->flags & CAN_FRAME_IDE) != 0U);
}

/* --- Communication parameters ----------------------------------------------------------- */

ZTEST(co_pdo, test_comm_param_abort_codes)
{
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, 0x301 + NODE_ID, 4), CO_SDO_AB_INVALID_VALUE,
		      "CAN-ID change while valid");
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, INVALID | (0x200 + NODE_ID), 4), 0U,
		      "bit 31 may change");
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, INVALID | 0x305, 4), 0U, "then the CAN-ID");
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, 0x701, 4), CO_SDO_AB_INVALID_VALUE,
		      "restricted CAN-ID");
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, 0x0000FFFF, 4), CO_SDO_AB_INVALID_VALUE,
		      "not 11-bit");
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 241, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 252, 1), CO_SDO_AB_INVALID_VALUE,
		      "RTR types are TPDO only");
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 254, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 245, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 251, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 240, 1), 0U, "type may change while valid");
	zassert_equal(co_sim_write(&t.node, 0x1800, 3, 1, 2), CO_SDO_AB_INVALID_VALUE,
		      "inhibit while valid");
	zassert_equal(co_sim_write(&t.node, 0x1800, 6, 1, 1), CO_SDO_AB_INVALID_VALUE,
		      "start value while valid");
}

/* --- Mapping procedure ------------------------------------------------------------------ */

ZTEST(co_pdo, test_mapping_procedure_abort_codes)
{
	uint8_t n = 0xEE;

	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), CO_SDO_AB_INVALID_VALUE,
		      "sub 0 while valid");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20000108, 4), CO_SDO_AB_INVALID_VALUE,
		      "entry while valid");
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, INVALID | (0x180 + NODE_ID), 4), 0U,
		      "step 1");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20000108, 4), CO_SDO_AB_INVALID_VALUE,
		      "entry while sub 0 != 0");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), 0U, "step 2");

	/* Step 3: entries are checked as they are written. */
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x30000008, 4), CO_SDO_AB_NO_OBJECT,
		      "missing object");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20000908, 4), CO_SDO_AB_NO_SUB,
		      "missing sub-index");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20030020, 4), CO_SDO_AB_NO_MAP,
		      "PDOMapping=0");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x10000020, 4), CO_SDO_AB_NO_MAP, "1000h");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20080008, 4), CO_SDO_AB_NO_MAP,
		      "rww into a TPDO");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20020028, 4), CO_SDO_AB_NO_MAP,
		      "40 bits of a U32");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20000100, 4), CO_SDO_AB_NO_MAP,
		      "length 0");
#if !defined(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20020010, 4), CO_SDO_AB_NO_MAP,
		      "part of an object");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 1, 0x20000104, 4), CO_SDO_AB_NO_MAP,
		      "not whole bytes");
#endif
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, INVALID | (0x200 + NODE_ID), 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1600, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1600, 1, 0x20040008, 4), CO_SDO_AB_NO_MAP,
		      "ro into an RPDO");
	zassert_equal(co_sim_write(&t.node, 0x1600, 1, 0x20080008, 4), 0U, "rww into an RPDO");

	/* Step 4: the whole mapping is checked when sub 0 is written. */
	for (uint8_t i = 1; i <= 3; i++) {
		zassert_equal(co_sim_write(&t.node, 0x1A00, i, 0x20020020, 4), 0U);
	}
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 3, 1), CO_SDO_AB_MAP_LEN, "96 bits");
	for (uint8_t i = 1; i <= 9; i++) {
		zassert_equal(co_sim_write(&t.node, 0x1A00, i,
					   0x20000008 | (uint32_t)(i <= 8 ? i : 1) << 8, 4),
			      0U);
	}
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 9, 1), CO_SDO_AB_MAP_LEN, "9 x 8 bits");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 65, 1), CO_SDO_AB_MAP_LEN,
		      "more than 64 entries");
#if defined(CONFIG_CANOPEN_MPDO)
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0xFE, 1), 0U,
		      "SAM-MPDO on a type 255 TPDO (src/mpdo.c)");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), 0U);
#else
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0xFE, 1), CO_SDO_AB_INVALID_VALUE,
		      "MPDO not built in");
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0xFF, 1), CO_SDO_AB_INVALID_VALUE,
		      "MPDO not built in");
#endif
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 8, 1), 0U, "8 x 8 bits");
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), 0x1A00, 0, &n));
	co_node_unlock(&t.node);
	zassert_equal(n, 8);
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, 0x180 + NODE_ID, 4), 0U, "step 5");

	go_operational();
	for (uint8_t i = 1; i <= 8; i++) {
		app_u8(0x2000, i, (uint8_t)(0x10 + i));
	}
	sim.n_sent = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 0));
	zassert_equal(sim.n_sent, 1);
	zassert_equal(sim.sent[0].dlc, 8);
	zassert_equal(sim.sent[0].data[0], 0x11);
	zassert_equal(sim.sent[0].data[7], 0x18);

	zassert_equal(co_sim_write(&t.node, 0x1800, 1, INVALID | (0x180 + NODE_ID), 4), 0U);
#if defined(CONFIG_CANOPEN_PDO_REMAP_IN_OPERATIONAL)
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), 0U,
		      "remapping allowed in Operational");
#else
	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), CO_SDO_AB_DATA_DEV_STATE,
		      "no remapping in Operational");
#endif
}

ZTEST(co_pdo, test_reset_communication_restores_mapping)
{
	const uint32_t map[] = {0x20000108};

	setup_pdo(false, 0, 0x2A1, 254, map, 1);
	co_sim_nmt(0x82, NODE_ID);
	go_operational();
	app_u32(0x2002, 0, 0x01020304);
	zassert_equal(count(0x180 + NODE_ID), 1, "the default TPDO 0 is back");
	zassert_equal(nth(0x180 + NODE_ID, 0)->dlc, 5);
}

#if !defined(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)
ZTEST(co_pdo, test_bitwise_mapping)
{
	zassert_equal(co_sim_write(&t.node, 0x1401, 1, INVALID | 0x321, 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1601, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x20050101, 4), CO_SDO_AB_NO_MAP,
		      "1 bit of a BOOLEAN");
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x2006000C, 4), CO_SDO_AB_NO_MAP,
		      "12 bits of an INTEGER16");
	zassert_equal(co_sim_write(&t.node, 0x1601, 1, 0x20050108, 4), 0U,
		      "a BOOLEAN as a whole byte");
}
#else
ZTEST(co_pdo, test_bitwise_mapping)
{
	/* RPDO: 2005h:01 (1 bit), 2005h:02 (1 bit), BOOLEAN dummy, 2006h (12 of 16 bits, signed),
	 * 2000h:04 (8 bits): 23 bits, 3 bytes.
	 */
	const uint32_t rmap[] = {0x20050101, 0x20050201, 0x00010001, 0x2006000C, 0x20000408};
	/* TPDO: 2005h:01, 2005h:02, 2001h (10 of 16 bits), 2000h:01: 20 bits, 3 bytes. */
	const uint32_t tmap[] = {0x20050101, 0x20050201, 0x2001000A, 0x20000108};
	uint32_t v = 1U | (0U << 1) | (1U << 2) | (0xFFBU << 3) | (0x5AU << 15);
	uint8_t d[3] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16)};
	int16_t s = 0;
	bool b = false;

	setup_pdo(true, 1, 0x321, 255, rmap, 5);
	setup_pdo(false, 1, 0x2A1, 254, tmap, 4);
	go_operational();
	co_sim_rx(0x321, 3, d);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_bool(co_node_od(&t.node), 0x2005, 1, &b));
	co_node_unlock(&t.node);
	zassert_true(b);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_bool(co_node_od(&t.node), 0x2005, 2, &b));
	co_node_unlock(&t.node);
	zassert_false(b);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_i16(co_node_od(&t.node), 0x2006, 0, &s));
	co_node_unlock(&t.node);
	zassert_equal(s, -5, "12-bit two's complement, sign-extended");
	zassert_equal(get_u8(0x2000, 4), 0x5A);
	zassert_equal(count(EMCY_ID), 0, "23 bits need 3 bytes");

	co_node_lock(&t.node);
	zassert_ok(co_od_set_u16(co_node_od(&t.node), 0x2001, 0, 0x7FF, CO_OD_WRITER_APP));
	zassert_ok(co_od_set_u8(co_node_od(&t.node), 0x2000, 1, 0xA5, CO_OD_WRITER_APP));
	co_node_unlock(&t.node);
	sim.n_sent = 0;
	zassert_ok(co_tpdo_send_req(&t.node, 1));
	zassert_equal(sim.n_sent, 1);
	v = 1U | (0U << 1) | (0x3FFU << 2) | (0xA5U << 12);
	zassert_equal(sim.sent[0].dlc, 3);
	zassert_equal(sim.sent[0].data[0], (uint8_t)v);
	zassert_equal(sim.sent[0].data[1], (uint8_t)(v >> 8));
	zassert_equal(sim.sent[0].data[2], (uint8_t)(v >> 16), "bit 10 of 2001h is not mapped");
}
#endif
