/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Expedited transfers (CiA 301 §7.2.4.3.3-4) and the dictionary's refusals forwarded by the
 * server (cia301.md §10 items 14-20).
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_expedited, NULL, NULL, before, NULL, NULL);

ZTEST(sdo_expedited, test_upload_u32_1000h)
{
	/* §10 item 14: 43 00 10 00 + 4 bytes. */
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
	h_expect_none();
}

ZTEST(sdo_expedited, test_upload_u8_1001h)
{
	/* §10 item 15: 4F 01 10 00 xx 00 00 00. */
	h_req(0x40, 0x1001, 0, 0);
	h_expect(0x4F, 0x1001, 0, 0);
}

ZTEST(sdo_expedited, test_upload_u16_and_sizes)
{
	uint8_t buf[8];
	uint32_t len;

	zassert_ok(cli_ul(0x2001, 0, buf, sizeof(buf), &len));
	zassert_equal(len, 2);
	zassert_equal(sys_get_le16(buf), 0x1234);
	zassert_ok(cli_ul(0x1018, 4, buf, sizeof(buf), &len));
	zassert_equal(len, 4);
	zassert_equal(sys_get_le32(buf), 0x12345678);
}

ZTEST(sdo_expedited, test_download_with_size_every_length)
{
	uint8_t v8 = 0x5a;
	uint8_t v16[2] = {0xcd, 0xab};
	uint8_t v32[4] = {0x00, 0x02, 0, 0};

	zassert_ok(cli_dl_exp(0x2009, 0, &v8, 1));
	zassert_equal(h.ram.manuf.x2009_u8, 0x5a);
	zassert_ok(cli_dl_exp(0x2001, 0, v16, 2));
	zassert_equal(h.ram.manuf.x2001_u16, 0xabcd);
	zassert_ok(cli_dl_exp(0x2000, 0, v32, 4));
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x200);
	/* A 3-byte expedited write into a 40-byte string (27h). */
	zassert_ok(cli_dl_exp(0x2003, 0, "abc", 3));
	zassert_str_equal(h.ram.manuf.x2003_string, "abc");
	zassert_equal(h_stats(0).completed, 4);
}

ZTEST(sdo_expedited, test_download_without_size_uses_type_size)
{
	/* 22h: e = 1, s = 0. The U16 takes its own 2 bytes; bytes 6-7 are not data. */
	h_req(0x22, 0x2001, 0, 0xffff4321);
	h_expect(0x60, 0x2001, 0, 0);
	zassert_equal(h.ram.manuf.x2001_u16, 0x4321);
	/* A string takes all 4 bytes. */
	h_req(0x22, 0x2003, 0, sys_get_le32((const uint8_t *)"wxyz"));
	h_expect(0x60, 0x2003, 0, 0);
	zassert_str_equal(h.ram.manuf.x2003_string, "wxyz");
}

ZTEST(sdo_expedited, test_abort_06020000_no_object)
{
	h_req(0x40, 0x5555, 0, 0);
	h_expect_abort(0x5555, 0, CO_SDO_AB_NO_OBJECT);
	h_req(0x23, 0x5555, 1, 0);
	h_expect_abort(0x5555, 1, CO_SDO_AB_NO_OBJECT);
	h_expect_none();
}

ZTEST(sdo_expedited, test_abort_06090011_no_sub)
{
	/* §10 item 17. */
	h_req(0x40, 0x1018, 7, 0);
	h_expect_abort(0x1018, 7, CO_SDO_AB_NO_SUB);
	h_req(0x2F, 0x1018, 9, 1);
	h_expect_abort(0x1018, 9, CO_SDO_AB_NO_SUB);
}

ZTEST(sdo_expedited, test_abort_06010002_read_only)
{
	/* §10 item 18: 1000h is ro; 1008h is const. */
	h_req(0x23, 0x1000, 0, 1);
	h_expect_abort(0x1000, 0, CO_SDO_AB_READONLY);
	h_req(0x21, 0x1008, 0, 5);
	h_expect_abort(0x1008, 0, CO_SDO_AB_READONLY);
	zassert_equal(h_get_u32(0x1000, 0), 0x00020192);
}

ZTEST(sdo_expedited, test_abort_06010001_write_only)
{
	/* §10 item 19. */
	h_req(0x40, 0x2002, 0, 0);
	h_expect_abort(0x2002, 0, CO_SDO_AB_WRITEONLY);
	/* It is writable. */
	h_req(0x2F, 0x2002, 0, 7);
	h_expect(0x60, 0x2002, 0, 0);
}

ZTEST(sdo_expedited, test_abort_06070013_too_short_and_06070012_too_long)
{
	/* §10 item 20: 2 bytes to a U32, 4 bytes to a U16. */
	h_req(0x2B, 0x2000, 0, 0x20);
	h_expect_abort(0x2000, 0, CO_SDO_AB_DATA_SHORT);
	h_req(0x23, 0x2001, 0, 0x11112222);
	h_expect_abort(0x2001, 0, CO_SDO_AB_DATA_LONG);
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x100);
	zassert_equal(h.ram.manuf.x2001_u16, 0x1234);
}

ZTEST(sdo_expedited, test_abort_06090031_high_and_06090032_low)
{
	h_req(0x23, 0x2000, 0, 0x1001);
	h_expect_abort(0x2000, 0, CO_SDO_AB_VALUE_HIGH);
	h_req(0x23, 0x2000, 0, 0x0f);
	h_expect_abort(0x2000, 0, CO_SDO_AB_VALUE_LOW);
	h_req(0x23, 0x2000, 0, 0x1000);
	h_expect(0x60, 0x2000, 0, 0);
}

ZTEST(sdo_expedited, test_abort_06090030_invalid_boolean)
{
	h_req(0x2F, 0x2008, 0, 2);
	h_expect_abort(0x2008, 0, CO_SDO_AB_INVALID_VALUE);
	h_req(0x2F, 0x2008, 0, 1);
	h_expect(0x60, 0x2008, 0, 0);
}

ZTEST(sdo_expedited, test_abort_08000022_and_06040043_from_a_hook)
{
	/* Whatever a validate hook answers reaches the client unchanged. */
	h.hook_code = CO_SDO_AB_DATA_DEV_STATE;
	h_req(0x23, 0x2007, 0, 42);
	h_expect_abort(0x2007, 0, CO_SDO_AB_DATA_DEV_STATE);
	h.hook_code = CO_SDO_AB_PARAM_INCOMPAT;
	h_req(0x23, 0x2007, 0, 42);
	h_expect_abort(0x2007, 0, CO_SDO_AB_PARAM_INCOMPAT);
	zassert_equal(h.ram.manuf.x2007_u32_guarded_by_a_hook, 0);
	h.hook_code = 0;
	h_req(0x23, 0x2007, 0, 42);
	h_expect(0x60, 0x2007, 0, 0);
	zassert_equal(h.ram.manuf.x2007_u32_guarded_by_a_hook, 42);
}

ZTEST(sdo_expedited, test_abort_08000024_domain_without_data)
{
	/* 2006h is a DOMAIN with no storage and no provider: it holds 0 bytes, and even those
	 * cannot be stored.
	 */
	h_req(0x23, 0x2006, 0, 1);
	h_expect_abort(0x2006, 0, CO_SDO_AB_DATA_LONG);
	zassert_equal(cli_dl_seg(0x2006, 0, "", 0, true), CO_SDO_AB_NO_DATA);
}

ZTEST(sdo_expedited, test_aborts_are_counted)
{
	h_req(0x40, 0x5555, 0, 0);
	h_expect_abort(0x5555, 0, CO_SDO_AB_NO_OBJECT);
	zassert_equal(h_stats(0).aborts_sent, 1);
	zassert_equal(h_stats(0).last_abort, CO_SDO_AB_NO_OBJECT);
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
}
