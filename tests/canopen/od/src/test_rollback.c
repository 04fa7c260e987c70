/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* A refused or aborted write of any size leaves every value as it was (validate, commit). */

#include "common.h"

static uint32_t refuse(struct co_od *od, struct co_od_req *req, void *user_data)
{
	(void)od;
	(void)req;
	return *(uint32_t *)user_data;
}

static void refuse_all(uint32_t *code)
{
	const struct co_od_hook h = {
		.index_first = 0x0000,
		.index_last = 0xFFFF,
		.sub_first = 0,
		.sub_last = 0xFF,
		.validate = refuse,
		.user_data = code,
	};

	zassert_ok(co_od_hook_register(&fx.od, &h));
}

ZTEST(od_rollback, test_refused_writes_of_every_object_change_nothing)
{
	static struct od_test_od_ram before;
	uint32_t code = CO_SDO_AB_INVALID_VALUE;
	uint8_t data[64];

	memset(data, 0x01, sizeof(data));
	refuse_all(&code);
	memcpy(&before, &fx.ram, sizeof(before));
	for (uint16_t i = 0; i < od_test_od_def.n_entries; i++) {
		const struct co_od_entry *e = &od_test_od_def.entries[i];

		for (uint16_t s = 0; s < e->n_subs; s++) {
			const struct co_od_sub *d = &od_test_od_def.subs[e->first + s];
			size_t len = d->size > sizeof(data) ? sizeof(data) : d->size;
			uint32_t ab = wr(&fx.od, e->index, d->sub, data, len, CO_OD_WRITER_APP);

			zassert_not_equal(ab, 0, "%04X:%u written", e->index, d->sub);
		}
	}
	zassert_mem_equal(&fx.ram, &before, sizeof(before));
}

/* Segmented download of the 32-byte string in 7-byte segments. */
static uint32_t segmented(struct co_od_xfer *x, const char *s, size_t len, size_t stop_after)
{
	uint32_t ab = co_od_write_begin(&fx.od, x, 0x6000, 9, (uint32_t)len, CO_OD_WRITER_SDO);

	for (size_t off = 0; ab == 0 && off < len && off < stop_after; off += 7) {
		size_t n = len - off < 7 ? len - off : 7;

		ab = co_od_write_chunk(&fx.od, x, (uint32_t)off, s + off, n, off + n == len);
	}
	return ab;
}

ZTEST(od_rollback, test_chunks_commit_only_at_the_end)
{
	static const char text[] = "a string of exactly thirty-two!!";
	struct co_od_xfer x;
	char buf[40];

	zassert_ok(segmented(&x, text, 32, 21));
	/* Three segments in: the object still holds its old value. */
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 5);
	zassert_mem_equal(buf, "hello", 5);
	co_od_write_abort(&fx.od, &x);
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 5);
	/* The whole transfer commits. */
	zassert_ok(segmented(&x, text, 32, SIZE_MAX));
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 32);
	zassert_mem_equal(buf, text, 32);
}

ZTEST(od_rollback, test_refused_chunked_write)
{
	uint32_t code = CO_SDO_AB_GENERAL;
	struct co_od_xfer x;
	char buf[40];

	refuse_all(&code);
	zassert_equal(segmented(&x, "0123456789012345678901234", 25, SIZE_MAX), CO_SDO_AB_GENERAL);
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 5);
	zassert_mem_equal(buf, "hello", 5);
	/* The scratch buffer was given back. */
	code = 0;
	zassert_ok(segmented(&x, "0123456789", 10, SIZE_MAX));
}

ZTEST(od_rollback, test_announced_size_must_match)
{
	struct co_od_xfer x;
	char buf[40];

	zassert_ok(co_od_write_begin(&fx.od, &x, 0x6000, 9, 20, CO_OD_WRITER_SDO));
	zassert_equal(co_od_write_chunk(&fx.od, &x, 0, "0123456789", 10, true),
		      CO_SDO_AB_DATA_SHORT);
	zassert_equal(rd(&fx.od, 0x6000, 9, buf, sizeof(buf)), 5);
	zassert_equal(co_od_write_begin(&fx.od, &x, 0x6000, 9, 33, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_LONG);
	zassert_equal(co_od_write_begin(&fx.od, &x, 0x6000, 7, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_SHORT);
}

ZTEST(od_rollback, test_overrun_and_wrong_offset)
{
	struct co_od_xfer x;
	char big[40];

	memset(big, 'z', sizeof(big));
	zassert_ok(co_od_write_begin(&fx.od, &x, 0x6000, 9, 0, CO_OD_WRITER_SDO));
	zassert_ok(co_od_write_chunk(&fx.od, &x, 0, big, 30, false));
	zassert_equal(co_od_write_chunk(&fx.od, &x, 30, big, 7, true), CO_SDO_AB_DATA_LONG);
	zassert_ok(co_od_write_begin(&fx.od, &x, 0x6000, 9, 0, CO_OD_WRITER_SDO));
	zassert_ok(co_od_write_chunk(&fx.od, &x, 0, big, 7, false));
	zassert_equal(co_od_write_chunk(&fx.od, &x, 8, big, 7, true), CO_SDO_AB_GENERAL);
	zassert_equal(co_od_write_chunk(&fx.od, &x, 7, big, 7, true), CO_SDO_AB_GENERAL,
		      "a finished transfer must not accept chunks");
	zassert_equal(OD_TEST_OD_VAL_X6000(&fx.ram).visible_string[0], 'h');
}

ZTEST(od_rollback, test_one_staging_buffer_per_node)
{
	struct co_od_xfer a;
	struct co_od_xfer b;
	struct co_od_xfer c;

	zassert_ok(co_od_write_begin(&fx.od, &a, 0x6000, 9, 0, CO_OD_WRITER_SDO));
	zassert_equal(co_od_write_begin(&fx.od, &b, 0x6000, 0xE, 0, CO_OD_WRITER_SDO),
		      CO_SDO_AB_OUT_OF_MEM);
	/* Values up to 8 bytes stage in the transfer itself, and the other node has its own. */
	zassert_ok(co_od_write_begin(&fx.od, &c, 0x6000, 0x19, 8, CO_OD_WRITER_SDO));
	zassert_ok(co_od_write_begin(&fx.od2, &b, 0x6000, 0xE, 0, CO_OD_WRITER_SDO));
	co_od_write_abort(&fx.od, &a);
	zassert_ok(co_od_write_begin(&fx.od, &a, 0x6000, 0xE, 0, CO_OD_WRITER_SDO));
	/* Restarting a transfer without an abort does not lose the buffer. */
	zassert_ok(co_od_write_begin(&fx.od, &a, 0x6000, 0xE, 0, CO_OD_WRITER_SDO));
	co_od_write_abort(&fx.od, &a);
	zassert_ok(co_od_write_begin(&fx.od, &b, 0x6000, 9, 0, CO_OD_WRITER_SDO));
	co_od_write_abort(&fx.od, &b);
	co_od_write_abort(&fx.od2, &b);
	co_od_write_abort(&fx.od, &c);
}

ZTEST(od_rollback, test_u64_in_two_segments)
{
	static const uint8_t v[8] = {1, 2, 3, 4, 5, 6, 7, 8};
	struct co_od_xfer x;
	uint64_t u;

	zassert_ok(co_od_write_begin(&fx.od, &x, 0x6000, 0x19, 8, CO_OD_WRITER_SDO));
	zassert_ok(co_od_write_chunk(&fx.od, &x, 0, v, 7, false));
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x19, &u));
	zassert_equal(u, UINT64_MAX);
	zassert_ok(co_od_write_chunk(&fx.od, &x, 7, v + 7, 1, true));
	zassert_ok(co_od_get_u64(&fx.od, 0x6000, 0x19, &u));
	zassert_equal(u, 0x0807060504030201ULL);
}

ZTEST(od_rollback, test_limits_checked_on_the_whole_value)
{
	static const uint8_t v[2] = {0x61, 0xEA}; /* 60001 */
	struct co_od_xfer x;
	uint16_t u;

	zassert_ok(co_od_write_begin(&fx.od, &x, 0x1017, 0, 2, CO_OD_WRITER_SDO));
	zassert_ok(co_od_write_chunk(&fx.od, &x, 0, v, 1, false));
	zassert_equal(co_od_write_chunk(&fx.od, &x, 1, v + 1, 1, true), CO_SDO_AB_VALUE_HIGH);
	zassert_ok(co_od_get_u16(&fx.od, 0x1017, 0, &u));
	zassert_equal(u, 0);
}

ZTEST_SUITE(od_rollback, NULL, NULL, fx_before, NULL, NULL);
