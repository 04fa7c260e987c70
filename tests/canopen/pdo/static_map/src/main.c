/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Static PDO mapping (CONFIG_CANOPEN_PDO_DYNAMIC_MAPPING=n) against dynamic mapping (the
 * default), on a simulation line. Every test asserts the behaviour of the configuration it
 * was built with, so both scenarios of testcase.yaml run the same tests.
 *
 * Dictionary (../objdict/pdo_test.eds): RPDO 0 valid on 200h+N mapping 2000h:01 (U8) and
 * 2001h (U16); TPDO 0 valid on 180h+N mapping 2000h:05 (U8) and 2002h (U32).
 */

#include <errno.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/sdo_abort.h>

#include "co_sim.h"
#include "pdo_test_od.h"

#define NODE_ID 0x21
#define INVALID 0x80000000U

static struct {
	struct co_node node;
	struct pdo_test_od_ram ram;
} t;

static const bool dynamic = IS_ENABLED(CONFIG_CANOPEN_PDO_DYNAMIC_MAPPING);

static uint8_t get_u8(uint16_t index, uint8_t sub)
{
	uint8_t v = 0xEE;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u8(co_node_od(&t.node), index, sub, &v));
	co_node_unlock(&t.node);
	return v;
}

static uint32_t get_u32(uint16_t index, uint8_t sub)
{
	uint32_t v = 0xEEEEEEEEU;

	co_node_lock(&t.node);
	zassert_ok(co_od_get_u32(co_node_od(&t.node), index, sub, &v));
	co_node_unlock(&t.node);
	return v;
}

static uint32_t set_u8(uint16_t index, uint8_t sub, uint8_t v, enum co_od_writer writer)
{
	co_node_lock(&t.node);
	uint32_t ab = co_od_set_u8(co_node_od(&t.node), index, sub, v, writer);

	co_node_unlock(&t.node);
	return ab;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &pdo_test_od_def, &t.ram, NODE_ID));
	zassert_ok(co_node_start(&t.node));
	sim.n_sent = 0; /* boot-up */
}

ZTEST_SUITE(co_pdo_static_map, NULL, NULL, before, NULL, NULL);

/* The master's procedure (PDO off, sub 0 = 0, entries, sub 0 = n): refused at the first map write.
 */
ZTEST(co_pdo_static_map, test_mapping_writes_refused_only_when_static)
{
	const uint32_t want = dynamic ? 0U : CO_SDO_AB_READONLY;

	/* The communication records stay writable either way. */
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, INVALID | (0x200 + NODE_ID), 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, INVALID | (0x180 + NODE_ID), 4), 0U);

	zassert_equal(co_sim_write(&t.node, 0x1600, 0, 0, 1), want);
	zassert_equal(get_u8(0x1600, 0), dynamic ? 0U : 2U);
	zassert_equal(co_sim_write(&t.node, 0x1600, 1, 0x20000308, 4), want);
	zassert_equal(get_u32(0x1600, 1), dynamic ? 0x20000308U : 0x20000108U);

	zassert_equal(co_sim_write(&t.node, 0x1A00, 0, 0, 1), want);
	zassert_equal(get_u8(0x1A00, 0), dynamic ? 0U : 2U);
	zassert_equal(co_sim_write(&t.node, 0x1A00, 2, 0, 4), want);

	/* The application is refused too; only the restore of saved parameters gets through. */
	zassert_equal(set_u8(0x1601, 0, 0, CO_OD_WRITER_APP), want);
	zassert_equal(set_u8(0x1A01, 0, 1, CO_OD_WRITER_STORAGE), 0U);
	zassert_equal(get_u8(0x1A01, 0), 1U);
}

/* A static mapping is the dictionary's: RPDO 0 writes 2000h:01 and 2001h. */
ZTEST(co_pdo_static_map, test_dictionary_mapping_in_effect)
{
	const uint8_t d[3] = {0x5A, 0x34, 0x12};
	uint16_t w = 0;

	if (CONFIG_CANOPEN_PDO_MAP_ENTRIES < 2) {
		ztest_test_skip(); /* test_mapping_longer_than_the_table_leaves_the_pdo_off */
	}

	co_sim_nmt(0x01, NODE_ID);
	co_sim_rx(0x200 + NODE_ID, 3, d);
	zassert_equal(get_u8(0x2000, 1), 0x5A);
	co_node_lock(&t.node);
	zassert_ok(co_od_get_u16(co_node_od(&t.node), 0x2001, 0, &w));
	co_node_unlock(&t.node);
	zassert_equal(w, 0x1234);
}

/*
 * The dictionary's mappings have two entries each: with a table of fewer
 * (CONFIG_CANOPEN_PDO_MAP_ENTRIES) the PDO stays off after the reset of communication, its
 * frames neither received nor sent.
 */
ZTEST(co_pdo_static_map, test_mapping_longer_than_the_table_leaves_the_pdo_off)
{
	const bool fits = CONFIG_CANOPEN_PDO_MAP_ENTRIES >= 2;
	const uint8_t d[3] = {0x6B, 0x34, 0x12};

	co_sim_nmt(0x01, NODE_ID);
	co_sim_rx(0x200 + NODE_ID, 3, d);
	zassert_equal(get_u8(0x2000, 1), fits ? 0x6B : 0x00, "RPDO 1 on only when it fits");
	sim.n_sent = 0;
	zassert_equal(co_tpdo_send_req(&t.node, 0), fits ? 0 : -EINVAL);
	zassert_equal(sim.n_sent, fits ? 1 : 0, "TPDO 1 on only when it fits");
}
