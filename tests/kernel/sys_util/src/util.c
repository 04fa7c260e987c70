/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* sys/util.h, sys/util_macro.h and toolchain.h: bit helpers, arithmetic, Kconfig tests. */

#include <zephyr/sys/util.h>
#include <zephyr/ztest.h>

ZTEST_SUITE(util, NULL, NULL, NULL, NULL, NULL);

/* Compile-time checks: a failure stops the build. */
BUILD_ASSERT(BIT(3) == 8);
BUILD_ASSERT(ARRAY_SIZE(((int[7]){0})) == 7, "with a message");

#define TEST_ONE   1
#define TEST_ZERO  0
#define TEST_OTHER 2

ZTEST(util, test_bits)
{
	zassert_equal(BIT(0), 1UL);
	zassert_equal(BIT(31), 0x80000000UL);
	zassert_equal(BIT64(40), 0x10000000000ULL);
	zassert_equal(BIT_MASK(5), 0x1FUL);
	zassert_equal(GENMASK(7, 4), 0xF0UL);
	zassert_equal(GENMASK(31, 0), 0xFFFFFFFFUL);
	zassert_equal(GENMASK64(63, 60), 0xF000000000000000ULL);
	zassert_equal(FIELD_GET(GENMASK(7, 4), 0xA5), 0xA);
	zassert_equal(FIELD_PREP(GENMASK(7, 4), 0x3), 0x30);

	uint32_t v = 0;

	WRITE_BIT(v, 2, true);
	zassert_equal(v, 4);
	WRITE_BIT(v, 2, false);
	zassert_equal(v, 0);
}

ZTEST(util, test_arithmetic)
{
	zassert_equal(MIN(3, -2), -2);
	zassert_equal(MAX(3, -2), 3);
	zassert_equal(CLAMP(15, 0, 10), 10);
	zassert_equal(CLAMP(-5, 0, 10), 0);
	zassert_equal(CLAMP(5, 0, 10), 5);
	zassert_equal(ROUND_UP(13, 8), 16);
	zassert_equal(ROUND_UP(16, 8), 16);
	zassert_equal(ROUND_DOWN(13, 8), 8);
	zassert_equal(DIV_ROUND_UP(13, 8), 2);
	zassert_equal(DIV_ROUND_UP(16, 8), 2);
	zassert_equal(DIV_ROUND_CLOSEST(13, 8), 2);
	zassert_equal(DIV_ROUND_CLOSEST(11, 8), 1);
	zassert_equal(DIV_ROUND_CLOSEST(-13, 8), -2);
	zassert_true(IN_RANGE(5, 5, 6));
	zassert_false(IN_RANGE(7, 5, 6));
	zassert_true(IS_POWER_OF_TWO(64U));
	zassert_false(IS_POWER_OF_TWO(0U));
	zassert_false(is_power_of_two(12));
	zassert_equal(KB(2), 2048);
	zassert_equal(MB(1), 1048576);
}

struct outer {
	int a;
	char b;
	long member;
};

ZTEST(util, test_containers_and_arrays)
{
	struct outer o;
	long *p = &o.member;
	int arr[5];

	zassert_equal_ptr(CONTAINER_OF(p, struct outer, member), &o);
	zassert_equal(ARRAY_SIZE(arr), 5);
	zassert_true(PART_OF_ARRAY(arr, &arr[4]));
	zassert_false(PART_OF_ARRAY(arr, &arr[0] + 5));
	zassert_equal(SIZEOF_FIELD(struct outer, member), sizeof(long));
	zassert_equal(POINTER_TO_UINT(UINT_TO_POINTER(1234U)), 1234U);
	zassert_equal(POINTER_TO_INT(INT_TO_POINTER(-7)), -7);
}

ZTEST(util, test_config_macros)
{
	zassert_equal(IS_ENABLED(TEST_ONE), 1);
	zassert_equal(IS_ENABLED(TEST_ZERO), 0, "defined to 0 is not enabled");
	zassert_equal(IS_ENABLED(TEST_OTHER), 0, "only 1 counts");
	zassert_equal(IS_ENABLED(TEST_UNDEFINED), 0);
	zassert_equal(IS_ENABLED(CONFIG_ZTEST), 1, "Kconfig symbols are visible everywhere");

	int x = COND_CODE_1(TEST_ONE, (10), (20));
	int y = COND_CODE_1(TEST_UNDEFINED, (10), (20));
	int z = COND_CODE_0(TEST_ZERO, (30), (40));
	int w = 0 IF_ENABLED(TEST_ONE, (+5)) IF_DISABLED(TEST_ONE, (+7));

	zassert_equal(x, 10);
	zassert_equal(y, 20);
	zassert_equal(z, 30);
	zassert_equal(w, 5);

#if IS_ENABLED(TEST_ONE)
	zassert_true(true, "IS_ENABLED works in #if");
#else
	ztest_test_fail();
#endif
	zassert_str_equal(STRINGIFY(TEST_ONE), "1", "STRINGIFY expands its argument");
	zassert_equal(UTIL_CAT(TEST_, ONE), 1);
	ARG_UNUSED(x);
}
