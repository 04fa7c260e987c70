/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Segmented transfers (CiA 301 §7.2.4.3.5-8; cia301.md §3.2, §10 items 23 and 26). */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_segmented, NULL, NULL, before, NULL, NULL);

ZTEST(sdo_segmented, test_upload_1008h_frame_by_frame)
{
	/* §10 item 26: "SafeLine SDO test device", 24 bytes: 41h + size, then segments with
	 * toggles 00h/10h/00h/10h, the last with c = 1 and n = 7 - 3.
	 */
	static const char name[] = "SafeLine SDO test device";

	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	for (int i = 0; i < 4; i++) {
		const struct can_frame *f;
		uint8_t t = (uint8_t)((i & 1) << 4);

		h_req(0x60 | t, 0, 0, 0);
		f = h_next();
		if (i < 3) {
			zassert_equal(f->data[0], t, "segment %d: %02x", i, f->data[0]);
			zassert_mem_equal(&f->data[1], &name[7 * i], 7);
		} else {
			zassert_equal(f->data[0], t | (4 << 1) | 1, "last: %02x", f->data[0]);
			zassert_mem_equal(&f->data[1], &name[21], 3);
			zassert_equal(f->data[4] | f->data[5] | f->data[6] | f->data[7], 0);
		}
	}
	h_expect_none();
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
	/* The transfer is over: one more request is unexpected. */
	h_req(0x70, 0, 0, 0);
	h_expect_abort(0, 0, CO_SDO_AB_CMD);
}

ZTEST(sdo_segmented, test_download_string_with_and_without_size)
{
	static const char *values[] = {"eight ch", "exactly fourteen",
				       "0123456789abcdef0123456789abc", "12345", "1234567"};

	for (size_t i = 0; i < ARRAY_SIZE(values); i++) {
		uint32_t len = (uint32_t)strlen(values[i]);
		char back[48];
		uint32_t n;

		zassert_ok(cli_dl_seg(0x2003, 0, values[i], len, (i & 1) == 0));
		zassert_str_equal(h.ram.manuf.x2003_string, values[i]);
		zassert_ok(cli_ul(0x2003, 0, back, sizeof(back), &n));
		zassert_equal(n, len);
		zassert_mem_equal(back, values[i], len);
	}
}

ZTEST(sdo_segmented, test_download_small_values_segmented)
{
	/* Segmented transfers of values that would fit an expedited one are fine. */
	uint8_t v[4] = {0x44, 0x03, 0, 0};

	zassert_ok(cli_dl_seg(0x2000, 0, v, 4, true));
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x344);
	zassert_ok(cli_dl_seg(0x2001, 0, v, 2, false));
	zassert_equal(h.ram.manuf.x2001_u16, 0x0344);
}

ZTEST(sdo_segmented, test_download_octet_string)
{
	uint8_t v[12];
	uint8_t back[12];
	uint32_t n;

	h_fill(v, sizeof(v), 3);
	zassert_ok(cli_dl_seg(0x2004, 0, v, sizeof(v), true));
	zassert_ok(cli_ul(0x2004, 0, back, sizeof(back), &n));
	zassert_equal(n, 12);
	zassert_mem_equal(back, v, 12);
	/* A fixed-length OCTET_STRING refuses fewer bytes, announced or not. */
	zassert_equal(cli_dl_seg(0x2004, 0, v, 11, true), CO_SDO_AB_DATA_SHORT);
	zassert_equal(cli_dl_seg(0x2004, 0, v, 11, false), CO_SDO_AB_DATA_SHORT);
	zassert_mem_equal(h.ram.manuf.x2004_octet_string_of_12, back, 12);
}

ZTEST(sdo_segmented, test_upload_empty_value)
{
	/* An empty string: size 0 and one empty last segment (n = 7, c = 1). */
	h_req(0x23, 0x2003, 0, 0);
	h_expect(0x60, 0x2003, 0, 0);
	zassert_equal(h.ram.manuf.x2003_string[0], 0);
	h_req(0x40, 0x2003, 0, 0);
	h_expect(0x41, 0x2003, 0, 0);
	h_req(0x60, 0, 0, 0);
	h_expect(0x0F, 0, 0, 0);
	h_expect_none();
}

ZTEST(sdo_segmented, test_download_empty_value)
{
	zassert_ok(cli_dl_seg(0x2003, 0, "", 0, true));
	zassert_equal(h.ram.manuf.x2003_string[0], 0);
}

ZTEST(sdo_segmented, test_segment_with_fewer_bytes_before_the_last)
{
	/* n applies to every segment: 3 + 7 + 1 bytes. */
	uint8_t d[8];

	h_req(0x21, 0x2003, 0, 11);
	h_expect(0x60, 0x2003, 0, 0);
	memcpy(d,
	       "\x08"
	       "abc\0\0\0\0",
	       8);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	memcpy(d,
	       "\x10"
	       "defghij",
	       8);
	h_send(d);
	h_expect(0x30, 0, 0, 0);
	memcpy(d,
	       "\x0d"
	       "k\0\0\0\0\0\0",
	       8);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	zassert_str_equal(h.ram.manuf.x2003_string, "abcdefghijk");
}

ZTEST(sdo_segmented, test_abort_05030000_toggle_download)
{
	/* §10 item 23: the second segment with t = 0 again. */
	uint8_t d[8] = {0x00, '1', '2', '3', '4', '5', '6', '7'};

	h_req(0x21, 0x2003, 0, 20);
	h_expect(0x60, 0x2003, 0, 0);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	h_send(d);
	h_expect_abort(0x2003, 0, CO_SDO_AB_TOGGLE);
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
	/* The first segment must have t = 0. */
	h_req(0x21, 0x2003, 0, 20);
	h_expect(0x60, 0x2003, 0, 0);
	d[0] = 0x10;
	h_send(d);
	h_expect_abort(0x2003, 0, CO_SDO_AB_TOGGLE);
}

ZTEST(sdo_segmented, test_abort_05030000_toggle_upload)
{
	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	h_req(0x70, 0, 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_TOGGLE);
	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	h_req(0x60, 0, 0, 0);
	(void)h_next();
	h_req(0x60, 0, 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_TOGGLE);
}

ZTEST(sdo_segmented, test_abort_06070012_more_than_announced)
{
	uint8_t d[8] = {0x00, '1', '2', '3', '4', '5', '6', '7'};

	h_req(0x21, 0x2003, 0, 10);
	h_expect(0x60, 0x2003, 0, 0);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	/* 7 more bytes, 3 were left. */
	d[0] = 0x11;
	h_send(d);
	h_expect_abort(0x2003, 0, CO_SDO_AB_DATA_LONG);
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_segmented, test_abort_06070013_less_than_announced)
{
	uint8_t d[8] = {0x00, '1', '2', '3', '4', '5', '6', '7'};

	h_req(0x21, 0x2003, 0, 20);
	h_expect(0x60, 0x2003, 0, 0);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	d[0] = 0x11;
	h_send(d);
	h_expect_abort(0x2003, 0, CO_SDO_AB_DATA_SHORT);
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_segmented, test_abort_06070012_more_than_the_object_holds)
{
	static uint8_t v[60];

	h_fill(v, sizeof(v), 1);
	/* Announced: refused at the initiate. */
	h_req(0x21, 0x2003, 0, 41);
	h_expect_abort(0x2003, 0, CO_SDO_AB_DATA_LONG);
	/* Not announced: refused when the data gets too long. */
	zassert_equal(cli_dl_seg(0x2003, 0, v, sizeof(v), false), CO_SDO_AB_DATA_LONG);
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_segmented, test_abort_06090031_value_checked_at_the_end)
{
	uint8_t v[4];

	sys_put_le32(0x2000, v);
	zassert_equal(cli_dl_seg(0x2000, 0, v, 4, true), CO_SDO_AB_VALUE_HIGH);
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x100);
}

/*
 * An upload keeps its object where a download keeps its chunked write (one transfer state per
 * server): a download the client aborted halfway leaves nothing behind for the upload that
 * follows, nor for the next download of the same object.
 */
ZTEST(sdo_segmented, test_upload_and_download_after_an_aborted_download)
{
	static const char name[] = "SafeLine SDO test device";
	uint8_t v[12];
	uint8_t back[24];
	uint32_t n;

	h_fill(v, sizeof(v), 5);
	h_req(0x21, 0x2004, 0, 12);
	h_expect(0x60, 0x2004, 0, 0);
	h_req(0x00, 0, 0, 0);
	h_expect(0x20, 0, 0, 0);
	h_req(0x80, 0x2004, 0, CO_SDO_AB_GENERAL);
	h_expect_none();
	zassert_ok(cli_ul(0x1008, 0, back, sizeof(back), &n));
	zassert_equal(n, 24);
	zassert_mem_equal(back, name, 24);
	zassert_ok(cli_dl_seg(0x2004, 0, v, sizeof(v), true));
	zassert_ok(cli_ul(0x2004, 0, back, sizeof(back), &n));
	zassert_equal(n, 12);
	zassert_mem_equal(back, v, 12);
}
