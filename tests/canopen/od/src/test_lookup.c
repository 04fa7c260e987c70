/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Lookup by index and sub-index (CiA 301 §7.4.1), and per-node values. */

#include "common.h"

ZTEST(od_lookup, test_entries_sorted_and_all_found)
{
	const struct co_od_def *def = &od_test_od_def;

	zassert_equal(def->n_entries, OD_TEST_OD_CNT_ENTRIES);
	zassert_equal(def->n_subs, OD_TEST_OD_CNT_SUBS);
	for (uint16_t i = 0; i < def->n_entries; i++) {
		const struct co_od_entry *e = &def->entries[i];

		if (i > 0) {
			zassert_true(def->entries[i - 1].index < e->index, "not sorted at %u", i);
		}
		for (uint16_t s = 0; s < e->n_subs; s++) {
			struct co_od_info info;
			uint8_t sub = def->subs[e->first + s].sub;

			zassert_ok(co_od_find(&fx.od, e->index, sub, &info), "%04X:%u", e->index,
				   sub);
			zassert_equal(info.index, e->index);
			zassert_equal(info.sub, sub);
			zassert_equal(info.objcode, e->objcode);
		}
	}
}

ZTEST(od_lookup, test_missing_index_and_sub)
{
	struct co_od_info info;
	static const uint16_t absent[] = {0x0000, 0x0FFF, 0x1002, 0x1019, 0x1FFF,
					  0x2006, 0x5FFF, 0x6001, 0xFFFF};

	for (size_t i = 0; i < ARRAY_SIZE(absent); i++) {
		zassert_equal(co_od_find(&fx.od, absent[i], 0, &info), CO_SDO_AB_NO_OBJECT, "%04X",
			      absent[i]);
	}
	zassert_equal(co_od_find(&fx.od, 0x1018, 5, &info), CO_SDO_AB_NO_SUB);
	zassert_equal(co_od_find(&fx.od, 0x1000, 1, &info), CO_SDO_AB_NO_SUB);
	zassert_equal(co_od_find(&fx.od, 0x6000, 26, &info), CO_SDO_AB_NO_SUB);
	zassert_equal(co_od_find(&fx.od, 0x6000, 0xFF, &info), CO_SDO_AB_NO_SUB);
}

ZTEST(od_lookup, test_info_describes_the_object)
{
	struct co_od_info info;

	zassert_ok(co_od_find(&fx.od, 0x6000, 0x10, &info));
	zassert_equal(info.dtype, CO_DTYPE_REAL64);
	zassert_equal(info.size, 8);
	zassert_equal(info.access, CO_OD_ACCESS_RW);
	zassert_true(info.flags & CO_OD_F_MAP);
	zassert_equal(info.group, CO_OD_GROUP_APP);
	zassert_ok(co_od_find(&fx.od, 0x1008, 0, &info));
	zassert_true(info.flags & CO_OD_F_ROM);
	zassert_equal(info.access, CO_OD_ACCESS_CONST);
	zassert_ok(co_od_find(&fx.od, 0x1017, 0, &info));
	zassert_not_null(info.limit);
	zassert_equal(info.group, CO_OD_GROUP_COMM);
}

ZTEST(od_lookup, test_two_nodes_have_their_own_values)
{
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 100, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u16(&fx.od2, 0x1017, 0, 200, CO_OD_WRITER_SDO));

	uint16_t a;
	uint16_t b;

	zassert_ok(co_od_get_u16(&fx.od, 0x1017, 0, &a));
	zassert_ok(co_od_get_u16(&fx.od2, 0x1017, 0, &b));
	zassert_equal(a, 100);
	zassert_equal(b, 200);
	zassert_equal(OD_TEST_OD_VAL_X1017(&fx.ram), 100);
	zassert_equal(OD_TEST_OD_VAL_X1017(&fx.ram2), 200);
	/* $NODEID values follow each node's own node-ID. */
	zassert_equal(OD_TEST_OD_VAL_X1400(&fx.ram).cob_id_used_by_rpdo, 0x205);
	zassert_equal(OD_TEST_OD_VAL_X1400(&fx.ram2).cob_id_used_by_rpdo, 0x206);
}

ZTEST(od_lookup, test_generated_names_and_counts)
{
	zassert_equal(OD_TEST_OD_X6000, 0x6000);
	zassert_equal(OD_TEST_OD_X1018_S_VENDOR_ID, 1);
	zassert_equal(OD_TEST_OD_CNT_RPDO, 1);
	zassert_equal(OD_TEST_OD_CNT_TPDO, 1);
	zassert_equal(OD_TEST_OD_CNT_HB_CONS, 2);
	zassert_equal(OD_TEST_OD_CNT_NODEID, 2);
	zassert_true(OD_TEST_OD_MAX_STAGED <= CONFIG_CANOPEN_OD_SCRATCH_SIZE);
	zassert_equal(OD_TEST_OD_VAL_X6000(&fx.ram).unsigned16, 0xBEEF);
}

ZTEST_SUITE(od_lookup, NULL, NULL, fx_before, NULL, NULL);
