/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Block download and block upload (CiA 301 §7.2.4.3.9-16; cia301.md §3.3-3.4, §10 items
 * 27-31), CRC on and off, block sizes, protocol switch, sequence errors, back-pressure.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>

#include "harness.h"

#include "sdo_internal.h"

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_block, NULL, NULL, before, NULL, NULL);

#if !defined(CONFIG_CANOPEN_SDO_BLOCK)

ZTEST(sdo_block, test_abort_05040001_block_transfer_disabled)
{
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 127, 0};

	h_req(0xC6, 0x2003, 0, 4);
	h_expect_abort(0x2003, 0, CO_SDO_AB_CMD);
	h_send(d);
	h_expect_abort(0x1008, 0, CO_SDO_AB_CMD);
}

#else

#define RAMDOM 0x2005U

static uint8_t data[1024];
static uint8_t old[256];
static uint8_t back[1024 + 8];

static void set_ramdom(uint32_t len, uint32_t seed)
{
	h_fill(data, len, seed);
	zassert_ok(h_set(RAMDOM, 0, data, len, CO_OD_WRITER_APP));
}

static void check_ramdom(uint32_t len)
{
	zassert_equal(h.ram.manuf.x2005_ram_domain_of_200.len, len, "domain holds %u bytes",
		      h.ram.manuf.x2005_ram_domain_of_200.len);
	zassert_mem_equal(h.ram.manuf.x2005_ram_domain_of_200.data, data, len);
}

/* Send segment @p seq of a block download, taken at @p off of data[]. */
static void seg(uint8_t seq, bool last, uint32_t off, uint32_t n)
{
	uint8_t d[8] = {(uint8_t)(seq | (last ? 0x80 : 0))};

	memcpy(&d[1], &data[off], n);
	h_send(d);
}

static void end_req(uint32_t total, uint32_t last_len, bool crc)
{
	uint8_t d[8] = {(uint8_t)(0xC1 | ((7U - last_len) << 2))};

	if (crc) {
		sys_put_le16(ref_crc16(data, total), &d[1]);
	}
	h_send(d);
}

ZTEST(sdo_block, test_crc16_reference_values)
{
	/* CRC-16-CCITT/XMODEM check value, and the server's table against the bitwise one. */
	uint8_t buf[300];

	zassert_equal(crc16_itu_t(0, (const uint8_t *)"123456789", 9), 0x31C3);
	zassert_equal(crc16_itu_t(0, NULL, 0), 0);
	h_fill(buf, sizeof(buf), 77);
	zassert_equal(crc16_itu_t(0, buf, sizeof(buf)), ref_crc16(buf, sizeof(buf)));
	zassert_equal(crc16_itu_t(crc16_itu_t(0, buf, 100), &buf[100], 200),
		      ref_crc16(buf, sizeof(buf)));
}

/* --- Block download ---------------------------------------------------------------------- */

ZTEST(sdo_block, test_block_download_sizes_crc_on_and_off)
{
	static const uint32_t sizes[] = {0, 1, 6, 7, 8, 13, 14, 15, 99, 199, 200};

	for (int crc = 0; crc < 2; crc++) {
		for (size_t i = 0; i < ARRAY_SIZE(sizes); i++) {
			h_fill(data, sizes[i], (uint32_t)(i + 10 * crc));
			zassert_ok(cli_blk_dl(RAMDOM, 0, data, sizes[i], crc != 0), "size %u",
				   sizes[i]);
			check_ramdom(sizes[i]);
		}
	}
	zassert_equal(h_stats(0).completed, 2 * ARRAY_SIZE(sizes));
}

ZTEST(sdo_block, test_block_download_string_and_u32)
{
	uint8_t v[4] = {0x22, 0x01, 0, 0};

	zassert_ok(cli_blk_dl(0x2003, 0, "block-written string", 20, true));
	zassert_str_equal(h.ram.manuf.x2003_string, "block-written string");
	zassert_ok(cli_blk_dl(0x2000, 0, v, 4, false));
	zassert_equal(h.ram.manuf.x2000_limited_u32, 0x122);
}

ZTEST(sdo_block, test_block_download_without_size)
{
	h_fill(data, 50, 5);
	h_req(0xC4, RAMDOM, 0, 0);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	for (uint32_t off = 0, seq = 1; off < 50; off += 7, seq++) {
		bool last = off + 7 >= 50;

		seg((uint8_t)((seq - 1) % SRV_BLKSIZE + 1), last, off, MIN(7U, 50 - off));
		if (last || seq % SRV_BLKSIZE == 0) {
			h_expect(0xA2,
				 (uint16_t)(((seq - 1) % SRV_BLKSIZE + 1) | (SRV_BLKSIZE << 8)), 0,
				 0);
		}
	}
	end_req(50, 1, true);
	h_expect(0xA1, RAMDOM, 0, 0);
	check_ramdom(50);
}

/*
 * Download data[0..len) with the segments whose bit is set in @p drop (first sub-block only)
 * left out; the acknowledgement must name the last segment before the first gap and the
 * client then resends from there.
 */
static void blk_dl_with_gaps(uint32_t len, uint32_t drop)
{
	const struct can_frame *f;
	uint32_t off = 0;
	uint32_t last_len = 0;
	bool first = true;
	bool last = false;

	h_req(0xC6, RAMDOM, 0, len);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	while (!last) {
		uint32_t start = off;
		uint8_t expect_ack = 0;
		bool gap = false;
		uint8_t seq;

		for (seq = 1; seq <= SRV_BLKSIZE; seq++) {
			uint32_t n = MIN(7U, len - off);

			last = off + n >= len;
			if (first && (drop & (1U << seq))) {
				gap = true;
			} else {
				seg(seq, last, off, n);
				if (!gap) {
					expect_ack = seq;
				}
			}
			off += n;
			last_len = n;
			if (last) {
				break;
			}
		}
		f = h_next();
		zassert_equal(f->data[0], 0xA2);
		zassert_equal(f->data[1], expect_ack, "ackseq %u, expected %u", f->data[1],
			      expect_ack);
		zassert_equal(f->data[2], SRV_BLKSIZE);
		if (gap) {
			/* Resend from the segment after ackseq. */
			off = start + 7U * expect_ack;
			last = false;
		}
		first = false;
	}
	end_req(len, last_len, true);
	h_expect(0xA1, RAMDOM, 0, 0);
	h_expect_none();
}

ZTEST(sdo_block, test_block_download_gap_is_resent_from_ackseq)
{
	uint32_t len = MIN(200U, SRV_BLKSIZE * 7U + 10U);

	if (SRV_BLKSIZE < 2) {
		ztest_test_skip();
	}
	/* The first segment lost: ackseq 0, everything again. */
	h_fill(data, len, 1);
	blk_dl_with_gaps(len, 1U << 1);
	check_ramdom(len);
	if (SRV_BLKSIZE >= 4) {
		/* Segments 2 and 3 lost: ackseq 1; 4.. ignored. */
		h_fill(data, len, 2);
		blk_dl_with_gaps(len, (1U << 2) | (1U << 3));
		check_ramdom(len);
		zassert_true(h_stats(0).blk_seg_ignored > 0);
	}
}

ZTEST(sdo_block, test_block_download_gap_before_last_segment)
{
	/* The last segment (c = 1) arrives after a gap: it ends the sub-block, the ack names
	 * the last in-order segment, the client resends.
	 */
	if (SRV_BLKSIZE < 3) {
		ztest_test_skip();
	}
	h_fill(data, 20, 3);
	blk_dl_with_gaps(20, 1U << 2);
	check_ramdom(20);
}

ZTEST(sdo_block, test_block_download_duplicate_is_ignored)
{
	if (SRV_BLKSIZE < 3) {
		ztest_test_skip();
	}
	h_fill(data, 20, 4);
	h_req(0xC6, RAMDOM, 0, 20);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, false, 0, 7);
	seg(1, false, 0, 7);
	seg(2, false, 7, 7);
	seg(2, false, 7, 7);
	h_expect_none();
	seg(3, true, 14, 6);
	h_expect(0xA2, 3 | (SRV_BLKSIZE << 8), 0, 0);
	end_req(20, 6, true);
	h_expect(0xA1, RAMDOM, 0, 0);
	check_ramdom(20);
	zassert_equal(h_stats(0).blk_seg_ignored, 2);
}

ZTEST(sdo_block, test_block_download_duplicate_with_end_bit_is_ignored)
{
	/* A repeated segment is ignored whole: its c bit does not end the sub-block. */
	if (SRV_BLKSIZE < 3) {
		ztest_test_skip();
	}
	h_fill(data, 20, 5);
	h_req(0xC6, RAMDOM, 0, 20);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, false, 0, 7);
	seg(2, false, 7, 7);
	seg(1, true, 0, 7);
	h_expect_none();
	seg(3, true, 14, 6);
	h_expect(0xA2, 3 | (SRV_BLKSIZE << 8), 0, 0);
	end_req(20, 6, true);
	h_expect(0xA1, RAMDOM, 0, 0);
	check_ramdom(20);
}

ZTEST(sdo_block, test_block_download_last_segment_of_subblock_lost)
{
	/* The segment that would end the first sub-block never arrives (into 3000h). */
	uint32_t len = SRV_BLKSIZE * 7U + 7U;
	uint64_t t_last;

	if (SRV_BLKSIZE < 2) {
		ztest_test_skip();
	}
	h_fill(data, len, 6);
	h_req(0xC6, IDX_DOM, 0, len);
	h_expect(0xA4, IDX_DOM, 0, SRV_BLKSIZE);
	for (uint8_t s = 1; s < SRV_BLKSIZE; s++) {
		seg(s, false, (s - 1U) * 7U, 7);
	}
	h_expect_none();
	t_last = h.now;
	if (CONFIG_CANOPEN_SDO_BLOCK_SUBBLOCK_TIMEOUT == 0) {
		/* No sub-block timeout: the transfer times out. */
		h_run_until(t_last + TIMEOUT_US - 1);
		h_expect_none();
		h_run_until(t_last + TIMEOUT_US);
		h_expect_abort(IDX_DOM, 0, CO_SDO_AB_TIMEOUT);
		zassert_equal(h.commits, 0);
		return;
	}
	/* The server acknowledges what it has, and the client resends the rest. */
	h_run_until(t_last + CONFIG_CANOPEN_SDO_BLOCK_SUBBLOCK_TIMEOUT * MS - 1);
	h_expect_none();
	h_run_until(t_last + CONFIG_CANOPEN_SDO_BLOCK_SUBBLOCK_TIMEOUT * MS);
	h_expect(0xA2, (SRV_BLKSIZE - 1) | (SRV_BLKSIZE << 8), 0, 0);
	seg(1, false, (SRV_BLKSIZE - 1U) * 7U, 7);
	seg(2, true, SRV_BLKSIZE * 7U, 7);
	h_expect(0xA2, 2 | (SRV_BLKSIZE << 8), 0, 0);
	end_req(len, 7, true);
	h_expect(0xA1, IDX_DOM, 0, 0);
	zassert_equal(h.dom_len, len);
	zassert_mem_equal(h.dom, data, len);
}

ZTEST(sdo_block, test_abort_05040004_crc_mismatch)
{
	/* §10 item 28: the old value stays. */
	uint8_t d[8] = {0xC1 | (1 << 2)};

	set_ramdom(30, 8);
	memcpy(old, data, 30);
	h_fill(data, 20, 9);
	h_req(0xC6, RAMDOM, 0, 20);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	for (uint8_t s = 1; s <= 3; s++) {
		seg((uint8_t)((s - 1) % SRV_BLKSIZE + 1), s == 3, (s - 1U) * 7U, s == 3 ? 6 : 7);
		if (s == 3 || s % SRV_BLKSIZE == 0) {
			(void)h_next();
		}
	}
	sys_put_le16(ref_crc16(data, 20) ^ 0x0100, &d[1]);
	h_send(d);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_CRC);
	memcpy(data, old, 30);
	check_ramdom(30);
}

ZTEST(sdo_block, test_abort_05040004_padding_is_not_in_the_crc)
{
	/* CANopenNode#624: a client that puts the padding of the last segment into its CRC
	 * gets 05040004h; the CRC covers the data only.
	 */
	uint8_t d[8] = {0xC1 | (4 << 2)};
	uint8_t padded[8];

	h_fill(data, 3, 10);
	memcpy(padded, data, 3);
	memset(&padded[3], 0, 4);
	h_req(0xC6, RAMDOM, 0, 3);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, true, 0, 3);
	h_expect(0xA2, 1 | (SRV_BLKSIZE << 8), 0, 0);
	sys_put_le16(ref_crc16(padded, 7), &d[1]);
	h_send(d);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_CRC);
}

ZTEST(sdo_block, test_block_download_crc_field_ignored_without_client_crc)
{
	/* cc = 0: the CRC field of the end request is not looked at. */
	uint8_t d[8] = {0xC1 | (2 << 2), 0xde, 0xad};

	h_fill(data, 12, 11);
	h_req(0xC2, RAMDOM, 0, 12);
	h_expect(0xA0, RAMDOM, 0, SRV_BLKSIZE);
	if (SRV_BLKSIZE == 1) {
		seg(1, false, 0, 7);
		h_expect(0xA2, 1 | (1 << 8), 0, 0);
		seg(1, true, 7, 5);
		h_expect(0xA2, 1 | (1 << 8), 0, 0);
	} else {
		seg(1, false, 0, 7);
		seg(2, true, 7, 5);
		h_expect(0xA2, 2 | (SRV_BLKSIZE << 8), 0, 0);
	}
	h_send(d);
	h_expect(0xA1, RAMDOM, 0, 0);
	check_ramdom(12);
}

ZTEST(sdo_block, test_abort_05040003_sequence_number_zero)
{
	/* §10 item 31: decided as an abort (doc/sdo.md). */
	h_req(0xC6, RAMDOM, 0, 20);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	h_fill(data, 20, 12);
	seg(0, false, 0, 7);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_SEQ_NUM);
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
}

ZTEST(sdo_block, test_abort_05040003_sequence_number_above_blksize)
{
	if (SRV_BLKSIZE == 127) {
		/* Every 7-bit sequence number is within a block size of 127. */
		ztest_test_skip();
	}
	h_req(0xC6, RAMDOM, 0, 200);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	h_fill(data, 200, 13);
	seg(SRV_BLKSIZE + 1, false, 0, 7);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_SEQ_NUM);
}

ZTEST(sdo_block, test_client_abort_during_subblock)
{
	/* 80h is the client's abort even where every frame is a segment. */
	set_ramdom(5, 14);
	memcpy(old, data, 5);
	h_req(0xC6, RAMDOM, 0, 100);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	h_fill(data, 100, 15);
	seg(1, false, 0, 7);
	if (SRV_BLKSIZE == 1) {
		h_expect(0xA2, 1 | (1 << 8), 0, 0);
	}
	h_req(0x80, RAMDOM, 0, CO_SDO_AB_GENERAL);
	h_expect_none();
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 0)));
	zassert_equal(h_stats(0).aborts_received, 1);
	memcpy(data, old, 5);
	check_ramdom(5);
}

ZTEST(sdo_block, test_frames_with_80h_to_9fh_are_segments_in_a_subblock)
{
	/* 81h = last segment, seqno 1: not an abort. */
	h_fill(data, 3, 16);
	h_req(0xC6, RAMDOM, 0, 3);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, true, 0, 3);
	h_expect(0xA2, 1 | (SRV_BLKSIZE << 8), 0, 0);
	end_req(3, 3, true);
	h_expect(0xA1, RAMDOM, 0, 0);
	check_ramdom(3);
}

ZTEST(sdo_block, test_abort_05040001_block_download_end_expected)
{
	h_fill(data, 3, 17);
	h_req(0xC6, RAMDOM, 0, 3);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, true, 0, 3);
	h_expect(0xA2, 1 | (SRV_BLKSIZE << 8), 0, 0);
	/* A segment again instead of the end request. */
	seg(1, true, 0, 3);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_CMD);
	/* A block download initiate with the end bit clear is not an end request either. */
	h_req(0xC6, RAMDOM, 0, 3);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, true, 0, 3);
	h_expect(0xA2, 1 | (SRV_BLKSIZE << 8), 0, 0);
	h_req(0xC0, 0, 0, 0);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_CMD);
}

ZTEST(sdo_block, test_abort_06070012_block_download_longer_than_announced)
{
	h_fill(data, 30, 18);
	h_req(0xC6, RAMDOM, 0, 10);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	seg(1, false, 0, 7);
	if (SRV_BLKSIZE == 1) {
		h_expect(0xA2, 1 | (1 << 8), 0, 0);
		seg(1, false, 7, 7);
	} else {
		seg(2, false, 7, 7);
	}
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_DATA_LONG);
}

ZTEST(sdo_block, test_abort_06070012_and_06070013_end_disagrees_with_size)
{
	/* 10 announced; the end request says 8 (n = 6 in the second segment) or 14 (n = 0). */
	static const struct {
		uint8_t n;
		uint32_t code;
	} cases[] = {{6, CO_SDO_AB_DATA_SHORT}, {0, CO_SDO_AB_DATA_LONG}};

	h_fill(data, 14, 19);
	for (size_t i = 0; i < ARRAY_SIZE(cases); i++) {
		uint8_t d[8] = {(uint8_t)(0xC1 | (cases[i].n << 2))};

		h_req(0xC2, RAMDOM, 0, 10);
		h_expect(0xA0, RAMDOM, 0, SRV_BLKSIZE);
		seg(1, false, 0, 7);
		if (SRV_BLKSIZE == 1) {
			h_expect(0xA2, 1 | (1 << 8), 0, 0);
			seg(1, true, 7, 7);
			h_expect(0xA2, 1 | (1 << 8), 0, 0);
		} else {
			seg(2, true, 7, 7);
			h_expect(0xA2, 2 | (SRV_BLKSIZE << 8), 0, 0);
		}
		h_send(d);
		h_expect_abort(RAMDOM, 0, cases[i].code);
	}
}

ZTEST(sdo_block, test_abort_06070012_block_download_beyond_object)
{
	/* Announced too large: refused at the initiate. */
	h_req(0xC6, RAMDOM, 0, 201);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_DATA_LONG);
	h_req(0xC6, 0x2001, 0, 3);
	h_expect_abort(0x2001, 0, CO_SDO_AB_DATA_LONG);
}

ZTEST(sdo_block, test_abort_06010002_block_download_read_only)
{
	h_req(0xC6, 0x1000, 0, 4);
	h_expect_abort(0x1000, 0, CO_SDO_AB_READONLY);
}

ZTEST(sdo_block, test_abort_05040000_timeout_block_download)
{
	uint64_t t0;

	h_req(0xC6, RAMDOM, 0, 100);
	h_expect(0xA4, RAMDOM, 0, SRV_BLKSIZE);
	t0 = h.now;
	h_run_until(t0 + TIMEOUT_US - 1);
	h_expect_none();
	h_run_until(t0 + TIMEOUT_US);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_TIMEOUT);
}

/* --- Block upload ------------------------------------------------------------------------ */

ZTEST(sdo_block, test_block_upload_sizes_blksizes_crc)
{
	static const uint32_t sizes[] = {0, 1, 6, 7, 8, 13, 14, 15, 100, 200};
	static const uint8_t blksizes[] = {1, 2, 7, 13, 127};

	for (size_t b = 0; b < ARRAY_SIZE(blksizes); b++) {
		for (size_t i = 0; i < ARRAY_SIZE(sizes); i++) {
			for (int crc = 0; crc < 2; crc++) {
				uint32_t len = 0;
				bool sw;

				set_ramdom(sizes[i], (uint32_t)(i * 7 + b));
				zassert_ok(cli_blk_ul(RAMDOM, 0, back, sizeof(back), &len,
						      blksizes[b], crc != 0, 0, &sw),
					   "size %u blksize %u", sizes[i], blksizes[b]);
				zassert_false(sw);
				zassert_equal(len, sizes[i]);
				zassert_mem_equal(back, data, len);
			}
		}
	}
}

ZTEST(sdo_block, test_block_upload_1008h)
{
	uint32_t len;
	bool sw;

	zassert_ok(cli_blk_ul(0x1008, 0, back, sizeof(back), &len, 127, true, 0, &sw));
	zassert_equal(len, 24);
	zassert_mem_equal(back, "SafeLine SDO test device", 24);
}

ZTEST(sdo_block, test_block_upload_partial_ack_resends_from_ackseq)
{
	/* 100 bytes = 15 segments, block size 10. The client acknowledges 4 of the first 10:
	 * the server sends bytes 28.. again, numbered from 1, and the CRC covers each byte once.
	 */
	const struct can_frame *f;
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 10, 0};
	uint32_t off;

	set_ramdom(100, 21);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 100);
	h_req(0xA3, 0, 0, 0);
	for (uint8_t s = 1; s <= 10; s++) {
		f = h_next();
		zassert_equal(f->data[0], s);
		zassert_mem_equal(&f->data[1], &data[(s - 1) * 7], 7);
	}
	h_expect_none();
	h_req(0xA2, 4 | (10 << 8), 0, 0);
	/* The 11 remaining segments (bytes 28..99) in a block of 10, then 1. */
	off = 28;
	for (uint8_t s = 1; s <= 10; s++, off += 7) {
		f = h_next();
		zassert_equal(f->data[0], s);
		zassert_mem_equal(&f->data[1], &data[off], 7);
	}
	h_expect_none();
	zassert_equal(h_stats(0).blk_seg_resent, 6);
	h_req(0xA2, 10 | (10 << 8), 0, 0);
	f = h_next();
	zassert_equal(f->data[0], 0x81);
	zassert_mem_equal(&f->data[1], &data[98], 2);
	h_req(0xA2, 1 | (10 << 8), 0, 0);
	/* n = 5, CRC over the 100 bytes. */
	h_expect(0xC1 | (5 << 2), ref_crc16(data, 100), 0, 0);
	h_req(0xA1, 0, 0, 0);
	h_expect_none();
	zassert_equal(h_stats(0).completed, 1);
}

ZTEST(sdo_block, test_block_upload_ack_zero_resends_whole_block)
{
	const struct can_frame *f;
	uint8_t d[8] = {0xA0, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 3, 0};

	set_ramdom(30, 22);
	h_send(d);
	h_expect(0xC2, RAMDOM, 0, 30);
	h_req(0xA3, 0, 0, 0);
	h.rd += 3;
	h_req(0xA2, 0 | (3 << 8), 0, 0);
	for (uint8_t s = 1; s <= 3; s++) {
		f = h_next();
		zassert_equal(f->data[0], s);
		zassert_mem_equal(&f->data[1], &data[(s - 1) * 7], 7);
	}
	h_expect_none();
}

ZTEST(sdo_block, test_block_upload_ack_changes_blksize)
{
	const struct can_frame *f;
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 2, 0};

	set_ramdom(60, 23);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 60);
	h_req(0xA3, 0, 0, 0);
	h.rd += 2;
	h_expect_none();
	/* All 2 received; 5 per block from now on. */
	h_req(0xA2, 2 | (5 << 8), 0, 0);
	for (uint8_t s = 1; s <= 5; s++) {
		f = h_next();
		zassert_equal(f->data[0], s);
		zassert_mem_equal(&f->data[1], &data[14 + (s - 1) * 7], 7);
	}
	h_expect_none();
}

ZTEST(sdo_block, test_abort_05040002_initiate_blksize_0_and_128)
{
	/* §10 item 29. */
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 0, 0};

	h_send(d);
	h_expect_abort(0x1008, 0, CO_SDO_AB_BLK_SIZE);
	d[4] = 128;
	h_send(d);
	h_expect_abort(0x1008, 0, CO_SDO_AB_BLK_SIZE);
	d[4] = 255;
	h_send(d);
	h_expect_abort(0x1008, 0, CO_SDO_AB_BLK_SIZE);
}

ZTEST(sdo_block, test_abort_05040002_ack_blksize_0)
{
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 1, 0};

	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	(void)h_next();
	h_req(0xA2, 1 | (0 << 8), 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_BLK_SIZE);
	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	(void)h_next();
	h_req(0xA2, 1 | (128 << 8), 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_BLK_SIZE);
}

ZTEST(sdo_block, test_abort_05040003_ackseq_beyond_sent)
{
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 2, 0};

	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	h.rd += 2;
	h_req(0xA2, 3 | (2 << 8), 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_SEQ_NUM);
}

ZTEST(sdo_block, test_block_upload_protocol_switch)
{
	/* §10 item 30: pst >= size answers with the normal upload protocol. */
	uint32_t len;
	bool sw;

	zassert_ok(cli_blk_ul(0x2001, 0, back, sizeof(back), &len, 127, true, 2, &sw));
	zassert_equal(sw, IS_ENABLED(CONFIG_CANOPEN_SDO_BLOCK_PST));
	zassert_equal(len, 2);
	zassert_equal(sys_get_le16(back), 0x1234);
	/* 24 bytes, pst 24: segmented. */
	zassert_ok(cli_blk_ul(0x1008, 0, back, sizeof(back), &len, 127, true, 24, &sw));
	zassert_equal(sw, IS_ENABLED(CONFIG_CANOPEN_SDO_BLOCK_PST));
	zassert_mem_equal(back, "SafeLine SDO test device", 24);
	/* pst below the size, or 0: block. */
	zassert_ok(cli_blk_ul(0x1008, 0, back, sizeof(back), &len, 127, true, 23, &sw));
	zassert_false(sw);
	zassert_ok(cli_blk_ul(0x2001, 0, back, sizeof(back), &len, 127, false, 0, &sw));
	zassert_false(sw);
	zassert_equal(len, 2);
}

ZTEST(sdo_block, test_abort_05040001_block_upload_out_of_order)
{
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 4, 0};

	/* Acknowledge before the start. */
	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA2, 0 | (4 << 8), 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_CMD);
	/* Start twice. */
	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	h.rd += 4;
	h_req(0xA3, 0, 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_CMD);
	/* Something else than the end response after the end request. */
	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	h.rd += 4;
	h_req(0xA2, 4 | (4 << 8), 0, 0);
	(void)h_next();
	h_req(0xA2, 4 | (4 << 8), 0, 0);
	h_expect_abort(0x1008, 0, CO_SDO_AB_CMD);
}

ZTEST(sdo_block, test_abort_06010001_block_upload_write_only)
{
	uint8_t d[8] = {0xA4, 0x02, 0x20, 0x00, 10, 0};

	h_send(d);
	h_expect_abort(0x2002, 0, CO_SDO_AB_WRITEONLY);
}

ZTEST(sdo_block, test_abort_05040000_timeout_block_upload)
{
	uint8_t d[8] = {0xA4, 0x08, 0x10, 0x00, 127, 0};
	uint64_t t0;

	h_send(d);
	h_expect(0xC6, 0x1008, 0, 24);
	h_req(0xA3, 0, 0, 0);
	t0 = h.now;
	h.rd += 4;
	h_run_until(t0 + TIMEOUT_US - 1);
	h_expect_none();
	h_run_until(t0 + TIMEOUT_US);
	h_expect_abort(0x1008, 0, CO_SDO_AB_TIMEOUT);
}

ZTEST(sdo_block, test_block_upload_survives_tx_back_pressure)
{
	/* anchors.md §4 #2: the controller refuses frames while a 29-segment sub-block goes
	 * out and the line's TX queue (16 frames here) fills up. The server pauses and goes
	 * on; the client sees every segment, in order.
	 */
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 127, 0};
	const struct can_frame *f;

	BUILD_ASSERT(CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE < 29, "the test needs a short TX queue");
	set_ramdom(200, 24);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 200);
	h.sink_result = -EAGAIN;
	h_req(0xA3, 0, 0, 0);
	h_expect_none();
	h_advance(5 * MS);
	h_expect_none();
	h.sink_result = 0;
	h_advance(5 * MS);
	for (uint8_t s = 1; s <= 29; s++) {
		f = h_next();
		zassert_equal(f->data[0], s == 29 ? 0x80 | s : s, "segment %u: %02x", s,
			      f->data[0]);
		zassert_mem_equal(&f->data[1], &data[(s - 1) * 7], s == 29 ? 4 : 7);
	}
	h_expect_none();
	zassert_true(h_stats(0).tx_retries > 0);
	{
		struct co_line_stats ls;

		co_line_get_stats(&h.line, &ls);
		zassert_equal(ls.tx_dropped, 0U, "the server paused before the queue overflowed");
	}
	h_req(0xA2, 29 | (127 << 8), 0, 0);
	h_expect(0xC1 | (3 << 2), ref_crc16(data, 200), 0, 0);
	h_req(0xA1, 0, 0, 0);
	h_expect_none();
}

ZTEST(sdo_block, test_block_upload_send_error_ends_in_timeout)
{
	/* A driver error (not back-pressure): the server stops sending the sub-block instead of
	 * hammering a failing controller, and the transfer times out.
	 */
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 127, 0};
	uint64_t t0;

	set_ramdom(200, 25);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 200);
	h.sink_result = -EIO;
	h_req(0xA3, 0, 0, 0);
	t0 = h.now;
	zassert_equal(h_stats(0).tx_errors, 1);
	h.sink_result = 0;
	h_run_until(t0 + TIMEOUT_US - 1);
	h_expect_none();
	zassert_equal(h_stats(0).tx_errors, 1);
	h_run_until(t0 + TIMEOUT_US);
	h_expect_abort(RAMDOM, 0, CO_SDO_AB_TIMEOUT);
}

ZTEST(sdo_block, test_timeout_waits_while_own_frames_are_queued)
{
	/* A controller that takes longer than the SDO timeout to send the sub-block: the client
	 * cannot answer before it got the segments, so the server does not time out meanwhile.
	 */
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 127, 0};
	const uint64_t timeout = CONFIG_CANOPEN_SDO_SERVER_TIMEOUT * MS;

	set_ramdom(200, 26);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 200);
	h.sink_result = -EAGAIN;
	h_req(0xA3, 0, 0, 0);
	h_advance(3 * timeout);
	zassert_equal(h_stats(0).aborts_sent, 0U, "no timeout while segments wait in the queue");
	h.sink_result = 0;
	h_advance(5 * MS);
	for (uint8_t s = 1; s <= 29; s++) {
		zassert_equal(h_next()->data[0], s == 29 ? 0x80 | s : s);
	}
	h_req(0xA2, 29 | (127 << 8), 0, 0);
	h_expect(0xC1 | (3 << 2), ref_crc16(data, 200), 0, 0);
	h_req(0xA1, 0, 0, 0);
	zassert_equal(h_stats(0).completed, 1U);
}

ZTEST(sdo_block, test_timeout_comes_when_the_queue_never_drains)
{
	uint8_t d[8] = {0xA4, (uint8_t)RAMDOM, (uint8_t)(RAMDOM >> 8), 0, 127, 0};
	const uint64_t timeout = CONFIG_CANOPEN_SDO_SERVER_TIMEOUT * MS;

	set_ramdom(200, 27);
	h_send(d);
	h_expect(0xC6, RAMDOM, 0, 200);
	h.sink_result = -EAGAIN;
	h_req(0xA3, 0, 0, 0);
	h_advance(20 * timeout);
	zassert_equal(h_stats(0).aborts_sent, 1U, "the wait is bounded");
	zassert_equal(h_stats(0).last_abort, CO_SDO_AB_TIMEOUT);
	h.sink_result = 0;
}

#endif /* CONFIG_CANOPEN_SDO_BLOCK */
