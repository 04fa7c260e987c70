/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Access rights per writer and limit checks, with the CiA 301 abort code of each refusal. */

#include "common.h"

ZTEST(od_access, test_sdo_access_rights)
{
	uint8_t buf[8] = {0};
	size_t len;

	zassert_equal(wr(&fx.od, 0x1000, 0, buf, 4, CO_OD_WRITER_SDO), CO_SDO_AB_READONLY);
	zassert_equal(wr(&fx.od, 0x1008, 0, "x", 1, CO_OD_WRITER_SDO), CO_SDO_AB_READONLY);
	zassert_equal(co_od_read(&fx.od, 0x2000, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_SDO),
		      CO_SDO_AB_WRITEONLY);
	zassert_ok(wr(&fx.od, 0x2000, 0, buf, 2, CO_OD_WRITER_SDO));
	/* The application may read write-only and set read-only values ... */
	zassert_ok(co_od_read(&fx.od, 0x2000, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_APP));
	zassert_ok(co_od_set_u8(&fx.od, 0x1001, 0, 0x11, CO_OD_WRITER_APP));
	zassert_equal(OD_TEST_OD_VAL_X1001(&fx.ram), 0x11);
	/* ... but nobody writes constants, which live in flash. */
	zassert_equal(wr(&fx.od, 0x1008, 0, "x", 1, CO_OD_WRITER_APP), CO_SDO_AB_READONLY);
	zassert_equal(wr(&fx.od, 0x1018, 0, buf, 1, CO_OD_WRITER_STORAGE), CO_SDO_AB_READONLY);
	/* MPDO (DAM) writes need SDO write access. */
	zassert_equal(wr(&fx.od, 0x1000, 0, buf, 4, CO_OD_WRITER_MPDO), CO_SDO_AB_READONLY);
	zassert_ok(wr(&fx.od, 0x1017, 0, buf, 2, CO_OD_WRITER_MPDO));
}

ZTEST(od_access, test_pdo_mappability)
{
	uint8_t buf[8] = {0};
	size_t len;

	/* 1000h is not mappable. */
	zassert_equal(co_od_read(&fx.od, 0x1000, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_PDO),
		      CO_SDO_AB_NO_MAP);
	/* rwr: TPDO only; rww: RPDO only; rw + PDOMapping: both. */
	zassert_ok(co_od_read(&fx.od, 0x6000, 3, 0, buf, sizeof(buf), &len, CO_OD_WRITER_PDO));
	zassert_equal(wr(&fx.od, 0x6000, 3, buf, 2, CO_OD_WRITER_PDO), CO_SDO_AB_NO_MAP);
	zassert_equal(co_od_read(&fx.od, 0x6000, 5, 0, buf, sizeof(buf), &len, CO_OD_WRITER_SRDO),
		      CO_SDO_AB_NO_MAP);
	buf[0] = 100;
	zassert_ok(wr(&fx.od, 0x6000, 5, buf, 1, CO_OD_WRITER_SRDO));
	zassert_ok(wr(&fx.od, 0x6000, 7, buf, 4, CO_OD_WRITER_PDO));
	zassert_ok(co_od_read(&fx.od, 0x6000, 7, 0, buf, sizeof(buf), &len, CO_OD_WRITER_PDO));
	/* Read-only mappable (1001h) can be sent, not received. */
	zassert_ok(co_od_read(&fx.od, 0x1001, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_PDO));
	zassert_equal(wr(&fx.od, 0x1001, 0, buf, 1, CO_OD_WRITER_PDO), CO_SDO_AB_NO_MAP);
	/* A visible string without PDOMapping. */
	zassert_equal(wr(&fx.od, 0x6000, 9, "a", 1, CO_OD_WRITER_PDO), CO_SDO_AB_NO_MAP);
}

ZTEST(od_access, test_length_checks)
{
	uint8_t buf[8] = {0};

	zassert_equal(wr(&fx.od, 0x1005, 0, buf, 2, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_SHORT);
	zassert_equal(wr(&fx.od, 0x1005, 0, buf, 5, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_LONG);
	zassert_equal(wr(&fx.od, 0x1017, 0, buf, 4, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_LONG);
	zassert_equal(wr(&fx.od, 0x6000, 0x19, buf, 7, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_SHORT);
}

ZTEST(od_access, test_limits)
{
	uint8_t u8;
	int8_t i8;

	/* 6000h:5 UNSIGNED8 10..250 */
	zassert_equal(co_od_set_u8(&fx.od, 0x6000, 5, 9, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_LOW);
	zassert_equal(co_od_set_u8(&fx.od, 0x6000, 5, 251, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_HIGH);
	zassert_ok(co_od_get_u8(&fx.od, 0x6000, 5, &u8));
	zassert_equal(u8, 200);
	zassert_ok(co_od_set_u8(&fx.od, 0x6000, 5, 10, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u8(&fx.od, 0x6000, 5, 250, CO_OD_WRITER_SDO));
	/* 6000h:2 INTEGER8 -120..120: signed comparison */
	zassert_equal(co_od_set_i8(&fx.od, 0x6000, 2, -121, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_LOW);
	zassert_equal(co_od_set_i8(&fx.od, 0x6000, 2, 121, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_HIGH);
	zassert_ok(co_od_set_i8(&fx.od, 0x6000, 2, -120, CO_OD_WRITER_SDO));
	zassert_ok(co_od_get_i8(&fx.od, 0x6000, 2, &i8));
	zassert_equal(i8, -120);
	/* 6000h:8 REAL32 -10..10 */
	zassert_equal(co_od_set_f32(&fx.od, 0x6000, 8, 10.5f, CO_OD_WRITER_SDO),
		      CO_SDO_AB_VALUE_HIGH);
	zassert_equal(co_od_set_f32(&fx.od, 0x6000, 8, -10.5f, CO_OD_WRITER_SDO),
		      CO_SDO_AB_VALUE_LOW);
	zassert_ok(co_od_set_f32(&fx.od, 0x6000, 8, -9.75f, CO_OD_WRITER_SDO));
	/* 1017h UNSIGNED16 0..60000, 2003h:1 INTEGER32 -1000..1000, every writer */
	zassert_equal(co_od_set_u16(&fx.od, 0x1017, 0, 60001, CO_OD_WRITER_APP),
		      CO_SDO_AB_VALUE_HIGH);
	zassert_equal(co_od_set_i32(&fx.od, 0x2003, 1, -1001, CO_OD_WRITER_PDO),
		      CO_SDO_AB_VALUE_LOW);
	zassert_ok(co_od_set_i32(&fx.od, 0x2003, 1, 1000, CO_OD_WRITER_PDO));
}

ZTEST(od_access, test_value_pointer)
{
	struct co_od_info info;

	zassert_ok(co_od_find(&fx.od, 0x1017, 0, &info));
	zassert_equal_ptr(co_od_value_ptr(&fx.od, &info), &OD_TEST_OD_VAL_X1017(&fx.ram));
	zassert_ok(co_od_find(&fx.od, 0x2002, 0, &info)); /* DOMAIN without RAM */
	zassert_is_null(co_od_value_ptr(&fx.od, &info));
}

ZTEST_SUITE(od_access, NULL, NULL, fx_before, NULL, NULL);
