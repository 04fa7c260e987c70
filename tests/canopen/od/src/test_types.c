/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Every CiA 301 data type (§7.1): defaults, wire format, typed access, sizes. */

#include "common.h"

/* 6000h holds one sub-index per data type, with the EDS defaults below. */
struct wire_case {
	uint8_t sub;
	uint8_t dtype;
	uint8_t len;
	uint8_t bytes[8];
};

static const struct wire_case defaults[] = {
	{1, CO_DTYPE_BOOLEAN, 1, {0x01}},
	{2, CO_DTYPE_INTEGER8, 1, {0x9C}},                    /* -100 */
	{3, CO_DTYPE_INTEGER16, 2, {0xD0, 0x8A}},             /* -30000 */
	{4, CO_DTYPE_INTEGER32, 4, {0x00, 0x6C, 0xCA, 0x88}}, /* -2000000000 */
	{5, CO_DTYPE_UNSIGNED8, 1, {200}},
	{6, CO_DTYPE_UNSIGNED16, 2, {0xEF, 0xBE}},
	{7, CO_DTYPE_UNSIGNED32, 4, {0xEF, 0xBE, 0xAD, 0xDE}},
	{8, CO_DTYPE_REAL32, 4, {0x00, 0x00, 0xC0, 0x3F}}, /* 1.5f */
	{0xC, CO_DTYPE_TIME_OF_DAY, 6, {0xCD, 0xAB, 0x00, 0x20, 0x10, 0x00}},
	{0xD, CO_DTYPE_TIME_DIFFERENCE, 6, {0x10, 0x00, 0x00, 0x00, 0x01, 0x00}},
	{0xF, CO_DTYPE_INTEGER24, 3, {0x00, 0x00, 0x80}},
	{0x10, CO_DTYPE_REAL64, 8, {0x18, 0x2D, 0x44, 0x54, 0xFB, 0x21, 0x09, 0x40}},
	{0x11, CO_DTYPE_INTEGER40, 5, {0x00, 0x00, 0x00, 0x00, 0x80}},
	{0x12, CO_DTYPE_INTEGER48, 6, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F}},
	{0x13, CO_DTYPE_INTEGER56, 7, {0x0E, 0xD0, 0x31, 0x8C, 0xC5, 0xF4, 0xFF}},
	{0x14, CO_DTYPE_INTEGER64, 8, {0, 0, 0, 0, 0, 0, 0, 0x80}},
	{0x15, CO_DTYPE_UNSIGNED24, 3, {0xFF, 0xFF, 0xFF}},
	{0x16, CO_DTYPE_UNSIGNED40, 5, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF}},
	{0x17, CO_DTYPE_UNSIGNED48, 6, {0xBC, 0x9A, 0x78, 0x56, 0x34, 0x12}},
	{0x18, CO_DTYPE_UNSIGNED56, 7, {0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF, 0x00}},
	{0x19, CO_DTYPE_UNSIGNED64, 8, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}},
};

ZTEST(od_types, test_defaults_in_wire_format)
{
	for (size_t i = 0; i < ARRAY_SIZE(defaults); i++) {
		const struct wire_case *c = &defaults[i];
		struct co_od_info info;
		uint8_t buf[16];

		zassert_ok(co_od_find(&fx.od, 0x6000, c->sub, &info));
		zassert_equal(info.dtype, c->dtype, "sub %u", c->sub);
		zassert_equal(co_dtype_size(c->dtype), c->len, "sub %u", c->sub);
		zassert_equal(rd(&fx.od, 0x6000, c->sub, buf, sizeof(buf)), c->len, "sub %u",
			      c->sub);
		zassert_mem_equal(buf, c->bytes, c->len, "sub %u", c->sub);
	}
}

ZTEST(od_types, test_wire_round_trip_of_every_fixed_type)
{
	for (size_t i = 0; i < ARRAY_SIZE(defaults); i++) {
		const struct wire_case *c = &defaults[i];
		uint8_t v[8];
		uint8_t back[8];

		/* A different valid pattern: flip the low bit of the lowest byte. */
		memcpy(v, c->bytes, c->len);
		v[0] ^= (c->dtype == CO_DTYPE_BOOLEAN) ? 1U : 0x02U;
		zassert_ok(wr(&fx.od, 0x6000, c->sub, v, c->len, CO_OD_WRITER_SDO), "sub %u",
			   c->sub);
		zassert_equal(rd(&fx.od, 0x6000, c->sub, back, sizeof(back)), c->len);
		zassert_mem_equal(back, v, c->len, "sub %u", c->sub);
	}
}

ZTEST(od_types, test_typed_getters)
{
	bool b;
	int8_t i8;
	int16_t i16;
	int32_t i32;
	int64_t i64;
	uint8_t u8;
	uint16_t u16;
	uint32_t u32;
	uint64_t u64;
	float f32;
	double f64;
	struct co_time t;

	zassert_ok(co_od_get_bool(&fx.od, 0x6000, 1, &b));
	zassert_true(b);
	zassert_ok(co_od_get_i8(&fx.od, 0x6000, 2, &i8));
	zassert_equal(i8, -100);
	zassert_ok(co_od_get_i16(&fx.od, 0x6000, 3, &i16));
	zassert_equal(i16, -30000);
	zassert_ok(co_od_get_i32(&fx.od, 0x6000, 4, &i32));
	zassert_equal(i32, -2000000000);
	zassert_ok(co_od_get_u8(&fx.od, 0x6000, 5, &u8));
	zassert_equal(u8, 200);
	zassert_ok(co_od_get_u16(&fx.od, 0x6000, 6, &u16));
	zassert_equal(u16, 0xBEEF);
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xDEADBEEF);
	zassert_ok(co_od_get_f32(&fx.od, 0x6000, 8, &f32));
	zassert_equal(f32, 1.5f);
	zassert_ok(co_od_get_time(&fx.od, 0x6000, 0xC, &t));
	zassert_equal(t.ms, 0x2000ABCD);
	zassert_equal(t.days, 0x10);
	zassert_ok(co_od_get_i32(&fx.od, 0x6000, 0xF, &i32)); /* INTEGER24 */
	zassert_equal(i32, -8388608);
	zassert_ok(co_od_get_f64(&fx.od, 0x6000, 0x10, &f64));
	zassert_equal(f64, 3.141592653589793);
	zassert_ok(co_od_get_i64(&fx.od, 0x6000, 0x11, &i64)); /* INTEGER40 */
	zassert_equal(i64, -549755813888LL);
	zassert_ok(co_od_get_i64(&fx.od, 0x6000, 0x12, &i64)); /* INTEGER48 */
	zassert_equal(i64, 140737488355327LL);
	zassert_ok(co_od_get_i64(&fx.od, 0x6000, 0x13, &i64)); /* INTEGER56 */
	zassert_equal(i64, -12345678901234LL);
	zassert_ok(co_od_get_i64(&fx.od, 0x6000, 0x14, &i64));
	zassert_equal(i64, INT64_MIN);
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 0x15, &u32)); /* UNSIGNED24 */
	zassert_equal(u32, 0xFFFFFF);
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x16, &u64)); /* UNSIGNED40 */
	zassert_equal(u64, 0xFFFFFFFFFFULL);
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x17, &u64));
	zassert_equal(u64, 0x123456789ABCULL);
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x18, &u64));
	zassert_equal(u64, 0x00FFEEDDCCBBAAULL);
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x19, &u64));
	zassert_equal(u64, UINT64_MAX);
}

ZTEST(od_types, test_typed_setters_and_ranges)
{
	int32_t i32;
	int64_t i64;
	uint32_t u32;

	zassert_ok(co_od_set_i32(&fx.od, 0x6000, 0xF, 8388607, CO_OD_WRITER_APP));
	zassert_ok(co_od_get_i32(&fx.od, 0x6000, 0xF, &i32));
	zassert_equal(i32, 8388607);
	zassert_equal(co_od_set_i32(&fx.od, 0x6000, 0xF, 8388608, CO_OD_WRITER_APP),
		      CO_SDO_AB_VALUE_HIGH);
	zassert_equal(co_od_set_i32(&fx.od, 0x6000, 0xF, -8388609, CO_OD_WRITER_APP),
		      CO_SDO_AB_VALUE_LOW);
	zassert_equal(co_od_set_u32(&fx.od, 0x6000, 0x15, 0x1000000, CO_OD_WRITER_APP),
		      CO_SDO_AB_VALUE_HIGH);
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 0x15, &u32));
	zassert_equal(u32, 0xFFFFFF, "refused set changed the value");
	zassert_ok(co_od_set_i64(&fx.od, 0x6000, 0x13, -36028797018963968LL, CO_OD_WRITER_APP));
	zassert_ok(co_od_get_i64(&fx.od, 0x6000, 0x13, &i64));
	zassert_equal(i64, -36028797018963968LL);
	zassert_ok(co_od_set_f64(&fx.od, 0x6000, 0x10, -2.25, CO_OD_WRITER_PDO));
	zassert_ok(co_od_set_bool(&fx.od, 0x6000, 1, false, CO_OD_WRITER_APP));
	zassert_equal(OD_TEST_OD_VAL_X6000(&fx.ram).boolean, 0);

	struct co_time t = {.ms = 1234, .days = 15000};
	struct co_time back;

	zassert_ok(co_od_set_time(&fx.od, 0x6000, 0xD, &t, CO_OD_WRITER_SDO));
	zassert_ok(co_od_get_time(&fx.od, 0x6000, 0xD, &back));
	zassert_equal(back.ms, 1234);
	zassert_equal(back.days, 15000);
}

ZTEST(od_types, test_type_mismatch)
{
	uint16_t u16;
	int32_t i32;
	float f;

	zassert_equal(co_od_get_u16(&fx.od, 0x6000, 7, &u16), CO_SDO_AB_TYPE_MISMATCH);
	zassert_equal(co_od_get_i32(&fx.od, 0x6000, 7, &i32), CO_SDO_AB_TYPE_MISMATCH);
	zassert_equal(co_od_get_f32(&fx.od, 0x6000, 0x10, &f), CO_SDO_AB_TYPE_MISMATCH);
	zassert_equal(co_od_set_u16(&fx.od, 0x6000, 9, 1, CO_OD_WRITER_APP),
		      CO_SDO_AB_TYPE_MISMATCH);
	zassert_equal(co_od_get_u32(&fx.od, 0x7000, 0, (uint32_t *)&i32), CO_SDO_AB_NO_OBJECT);
}

ZTEST(od_types, test_boolean_values)
{
	uint8_t v = 2;

	zassert_equal(wr(&fx.od, 0x6000, 1, &v, 1, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	v = 0;
	zassert_ok(wr(&fx.od, 0x6000, 1, &v, 1, CO_OD_WRITER_SDO));
}

ZTEST(od_types, test_visible_string)
{
	char buf[40];
	struct co_od_info info;

	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 5);
	zassert_mem_equal(buf, "hello", 5);
	zassert_ok(co_od_find(&fx.od, 0x6000, 9, &info));
	zassert_equal(info.size, 32);
	zassert_equal(co_od_length(&fx.od, &info), 5);
	zassert_ok(wr(&fx.od, 0x6000, 9, "hi", 2, CO_OD_WRITER_SDO));
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 2);
	zassert_mem_equal(buf, "hi", 2);
	/* The RAM copy stays a C string for the application. */
	zassert_equal(strcmp(OD_TEST_OD_VAL_X6000(&fx.ram).visible_string, "hi"), 0);
	memset(buf, 'x', sizeof(buf));
	zassert_ok(wr(&fx.od, 0x6000, 9, buf, 32, CO_OD_WRITER_SDO));
	zassert_equal(wr(&fx.od, 0x6000, 9, buf, 33, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_LONG);
	/* Offset reads, as segmented uploads do. */
	size_t len;

	zassert_ok(co_od_read(&fx.od, 0x6000, 9, 30, buf, sizeof(buf), &len, CO_OD_WRITER_SDO));
	zassert_equal(len, 2);
	zassert_ok(co_od_read(&fx.od, 0x6000, 9, 32, buf, sizeof(buf), &len, CO_OD_WRITER_SDO));
	zassert_equal(len, 0);
}

ZTEST(od_types, test_octet_string_is_fixed_length)
{
	static const uint8_t four[] = {1, 2, 3, 4};
	uint8_t buf[8];

	zassert_equal(rd(&fx.od, 0x6000, 0xA, buf, sizeof(buf)), 4);
	zassert_mem_equal(buf, ((uint8_t[]){0x01, 0x02, 0xA0, 0xFF}), 4);
	zassert_equal(wr(&fx.od, 0x6000, 0xA, four, 3, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_SHORT);
	zassert_equal(wr(&fx.od, 0x6000, 0xA, buf, 5, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_LONG);
	zassert_ok(wr(&fx.od, 0x6000, 0xA, four, 4, CO_OD_WRITER_SDO));
	zassert_equal(rd(&fx.od, 0x6000, 0xA, buf, sizeof(buf)), 4);
	zassert_mem_equal(buf, four, 4);
}

ZTEST(od_types, test_unicode_string)
{
	/* "Grüße" in UTF-16LE */
	static const uint8_t gruesse[] = {'G', 0, 'r', 0, 0xFC, 0, 0xDF, 0, 'e', 0};
	uint8_t buf[24];

	zassert_equal(rd(&fx.od, 0x6000, 0xB, buf, sizeof(buf)), sizeof(gruesse));
	zassert_mem_equal(buf, gruesse, sizeof(gruesse));
	zassert_equal(wr(&fx.od, 0x6000, 0xB, gruesse, 3, CO_OD_WRITER_SDO),
		      CO_SDO_AB_TYPE_MISMATCH);
	zassert_ok(wr(&fx.od, 0x6000, 0xB, gruesse, 4, CO_OD_WRITER_SDO));
	zassert_equal(rd(&fx.od, 0x6000, 0xB, buf, sizeof(buf)), 4);
	zassert_equal(OD_TEST_OD_VAL_X6000(&fx.ram).unicode_string[1], 'r');
	zassert_equal(OD_TEST_OD_VAL_X6000(&fx.ram).unicode_string[2], 0);
}

ZTEST(od_types, test_domain_in_ram)
{
	uint8_t data[64];
	uint8_t buf[80];

	zassert_equal(rd(&fx.od, 0x6000, 0xE, buf, sizeof(buf)), 4);
	zassert_mem_equal(buf, ((uint8_t[]){0x00, 0x11, 0x22, 0x33}), 4);
	for (size_t i = 0; i < sizeof(data); i++) {
		data[i] = (uint8_t)(i * 7U);
	}
	zassert_ok(wr(&fx.od, 0x6000, 0xE, data, 64, CO_OD_WRITER_SDO));
	zassert_equal(rd(&fx.od, 0x6000, 0xE, buf, sizeof(buf)), 64);
	zassert_mem_equal(buf, data, 64);
	zassert_equal(wr(&fx.od, 0x6000, 0xE, buf, 65, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_LONG);
	zassert_ok(wr(&fx.od, 0x6000, 0xE, data, 0, CO_OD_WRITER_SDO));
	zassert_equal(rd(&fx.od, 0x6000, 0xE, buf, sizeof(buf)), 0);
}

ZTEST(od_types, test_dtype_table)
{
	zassert_equal(co_dtype_size(CO_DTYPE_UNSIGNED56), 7);
	zassert_equal(co_dtype_size(CO_DTYPE_DOMAIN), 0);
	zassert_equal(co_dtype_size(0x17), 0); /* reserved */
	zassert_equal(co_dtype_class(CO_DTYPE_TIME_OF_DAY), CO_DTYPE_CLASS_TIME);
	zassert_equal(co_dtype_class(0x0E), CO_DTYPE_CLASS_NONE);
	zassert_equal(strcmp(co_dtype_name(CO_DTYPE_INTEGER40), "INTEGER40"), 0);
	zassert_is_null(co_dtype_name(0x30));
}

ZTEST_SUITE(od_types, NULL, NULL, fx_before, NULL, NULL);
