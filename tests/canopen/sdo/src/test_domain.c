/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Objects larger than any buffer: a 100 kB provider DOMAIN streamed through the dictionary
 * in chunks, in every protocol; provider failures; the dictionary's staging buffer shared by
 * two servers.
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

#define BIG 100000U

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_domain, NULL, NULL, before, NULL, NULL);

static uint8_t src[BIG + 1024];

static void check_streamed(uint32_t len)
{
	zassert_equal(h.commits, 1, "%u commits", h.commits);
	zassert_equal(h.dom_len, len);
	zassert_mem_equal(h.dom, src, len);
	/* Chunks of the server's buffer at most, so never the whole value at once. */
	zassert_true(h.chunk_max <= BUFSZ, "chunk of %u bytes", h.chunk_max);
	zassert_true(h.chunks >= len / BUFSZ, "%u chunks", h.chunks);
}

ZTEST(sdo_domain, test_domain_100k_segmented_download_and_upload)
{
	uint32_t len;

	h_fill(src, BIG, 100);
	zassert_ok(cli_dl_seg(IDX_DOM, 0, src, BIG, true));
	check_streamed(BIG);
	memset(h.rx, 0, sizeof(h.rx));
	zassert_ok(cli_ul(IDX_DOM, 0, h.rx, sizeof(h.rx), &len));
	zassert_equal(len, BIG);
	zassert_mem_equal(h.rx, src, BIG);
}

#if defined(CONFIG_CANOPEN_SDO_BLOCK)

ZTEST(sdo_domain, test_domain_100k_block_download_and_upload)
{
	uint32_t len;
	bool sw;

	h_fill(src, BIG, 101);
	zassert_ok(cli_blk_dl(IDX_DOM, 0, src, BIG, true));
	check_streamed(BIG);
	memset(h.rx, 0, sizeof(h.rx));
	zassert_ok(cli_blk_ul(IDX_DOM, 0, h.rx, sizeof(h.rx), &len, 127, true, 0, &sw));
	zassert_equal(len, BIG);
	zassert_mem_equal(h.rx, src, BIG);
	/* Small blocks, no CRC. */
	memset(h.rx, 0, sizeof(h.rx));
	zassert_ok(cli_blk_ul(IDX_DOM, 0, h.rx, sizeof(h.rx), &len, 3, false, 0, &sw));
	zassert_mem_equal(h.rx, src, BIG);
}

ZTEST(sdo_domain, test_domain_block_download_odd_size_without_crc)
{
	h_fill(src, 4321, 102);
	zassert_ok(cli_blk_dl(IDX_DOM, 0, src, 4321, false));
	check_streamed(4321);
}

ZTEST(sdo_domain, test_abort_05040004_streamed_crc_mismatch_is_not_committed)
{
	/* The provider got the chunks, but the transfer ends with an abort, not a commit. */
	uint8_t d[8];

	h_fill(src, 2000, 103);
	h_req(0xC6, IDX_DOM, 0, 14);
	h_expect(0xA4, IDX_DOM, 0, SRV_BLKSIZE);
	memcpy(d,
	       "\x01"
	       "abcdefg",
	       8);
	h_send(d);
	memcpy(d,
	       "\x82"
	       "hijklmn",
	       8);
	if (SRV_BLKSIZE == 1) {
		h_expect(0xA2, 1 | (1 << 8), 0, 0);
		d[0] = 0x81;
	}
	h_send(d);
	(void)h_next();
	memset(d, 0, sizeof(d));
	d[0] = 0xC1;
	sys_put_le16(0xbeef, &d[1]);
	h_send(d);
	h_expect_abort(IDX_DOM, 0, CO_SDO_AB_CRC);
	zassert_equal(h.commits, 0);
	zassert_equal(h.stream_aborts, 1);
	zassert_equal(h.dom_len, 0);
}

#endif /* CONFIG_CANOPEN_SDO_BLOCK */

ZTEST(sdo_domain, test_domain_empty_upload)
{
	uint32_t len = 1;

	zassert_ok(cli_ul(IDX_DOM, 0, h.rx, sizeof(h.rx), &len));
	zassert_equal(len, 0);
}

ZTEST(sdo_domain, test_abort_06070012_domain_beyond_capacity)
{
	/* The provider checks its capacity for streamed objects. */
	h_req(0x20, IDX_DOM, 0, 0);
	h_expect(0x60, IDX_DOM, 0, 0);
	h_fill(src, BIG + 100, 104);
	for (uint32_t off = 0, t = 0;; off += 7, t ^= 1) {
		uint8_t d[8] = {(uint8_t)(t << 4)};
		const struct can_frame *f;

		memcpy(&d[1], &src[off % BIG], 7);
		h_send(d);
		f = h_next();
		if (f->data[0] == 0x80) {
			zassert_equal(sys_get_le32(&f->data[4]), CO_SDO_AB_DATA_LONG);
			zassert_true(off + 7 > BIG && off <= BIG + BUFSZ, "aborted at %u", off);
			break;
		}
		zassert_true(off < BIG + BUFSZ, "no abort");
	}
	zassert_equal(h.commits, 0);
}

ZTEST(sdo_domain, test_abort_06060000_provider_fails_mid_upload)
{
	/* 3001h: 2000 bytes, reads fail from byte 1000. The failure is reported when the
	 * server needs those bytes, whichever protocol.
	 */
	uint32_t len;

	zassert_equal(cli_ul(IDX_BROKEN, 0, h.rx, sizeof(h.rx), &len), CO_SDO_AB_HW);
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	bool sw;

	zassert_equal(cli_blk_ul(IDX_BROKEN, 0, h.rx, sizeof(h.rx), &len, 127, true, 0, &sw),
		      CO_SDO_AB_HW);
#endif
}

ZTEST(sdo_domain, test_abort_08000000_value_shorter_than_announced)
{
	/* 3002h claims 100 bytes and delivers 10: the server cannot keep its word. */
	uint32_t len;

	zassert_equal(cli_ul(IDX_SHRINKS, 0, h.rx, sizeof(h.rx), &len), CO_SDO_AB_GENERAL);
}

ZTEST(sdo_domain, test_abort_05040005_staging_buffer_in_use)
{
	/* Server 0 holds the dictionary's staging buffer for a segmented write of 2003h;
	 * a second server's write of another staged value gets 05040005h.
	 */
	uint8_t v[4] = {0x40, 0x06, 0, 0};
	uint8_t on[4];

	sys_put_le32(SRV1_RX, on);
	zassert_ok(cli_dl_exp(0x1201, 1, on, 4));
	sys_put_le32(SRV1_TX, on);
	zassert_ok(cli_dl_exp(0x1201, 2, on, 4));
	h_req(0x21, 0x2003, 0, 20);
	h_expect(0x60, 0x2003, 0, 0);
	h.cli_tx = SRV1_RX;
	h.cli_rx = SRV1_TX;
	h_req(0x21, 0x2004, 0, 12);
	h_expect_abort(0x2004, 0, CO_SDO_AB_OUT_OF_MEM);
	/* Values of up to 8 bytes do not need it. */
	zassert_ok(cli_dl_seg(0x2000, 0, v, 4, true));
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x640);
	/* Server 0's transfer goes on. */
	h.cli_tx = 0x600 + NODE_ID;
	h.cli_rx = 0x580 + NODE_ID;
	h_req(0x00, 0x6261, 0x63, 0x67666564);
	h_expect(0x20, 0, 0, 0);
}
