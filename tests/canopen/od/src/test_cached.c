/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Cached access (co_od_write_cached()/co_od_read_cached(), the PDO hot path): the same
 * result as co_od_write_info()/co_od_read_info() for every kind of value, and a cover made
 * before hooks changed must not hide them.
 */

#include "common.h"

struct probe {
	int notified;
	int validated;
	uint32_t refuse;
	uint32_t refuse_read;
};

static uint32_t p_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct probe *p = user_data;

	p->validated++;
	return p->refuse;
}

static void p_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	((struct probe *)user_data)->notified++;
}

static uint32_t p_read_check(const struct co_od *od, const struct co_od_info *info,
			     enum co_od_writer reader, void *user_data)
{
	return ((const struct probe *)user_data)->refuse_read;
}

static void probe_hook(struct co_od *od, uint16_t index, uint8_t sub, struct probe *p)
{
	const struct co_od_hook h = {
		index, index, sub, sub, p_validate, p_notify, p, p_read_check,
	};

	zassert_ok(co_od_hook_register(od, &h));
}

/* Write the same bytes through both paths (fx.od cached, fx.od2 generic); compare. */
static void same_write(uint16_t index, uint8_t sub, const uint8_t *data, size_t len,
		       enum co_od_writer w)
{
	struct co_od_info info;
	struct co_od_cover cover = {0};
	uint8_t a[16] = {0};
	uint8_t b[16] = {0};
	uint32_t ab_c;
	uint32_t ab_g;

	zassert_ok(co_od_find(&fx.od, index, sub, &info));
	ab_c = co_od_write_cached(&fx.od, &info, &cover, data, len, w);
	zassert_ok(co_od_find(&fx.od2, index, sub, &info));
	ab_g = co_od_write_info(&fx.od2, &info, data, len, w);
	zassert_equal(ab_c, ab_g, "%04X:%u: cached %08x, generic %08x", index, sub, ab_c, ab_g);
	zassert_equal(rd(&fx.od, index, sub, a, sizeof(a)), rd(&fx.od2, index, sub, b, sizeof(b)));
	zassert_mem_equal(a, b, sizeof(a), "%04X:%u stored differently", index, sub);
}

ZTEST(od_cached, test_write_same_as_generic)
{
	static const struct {
		uint16_t index;
		uint8_t sub;
		uint8_t len;
		uint8_t data[8];
	} cases[] = {
		{0x6000, 1, 1, {1}},                      /* BOOLEAN */
		{0x6000, 1, 1, {2}},                      /* BOOLEAN 2: 06090030h */
		{0x6000, 2, 1, {0x78}},                   /* INTEGER8 120 */
		{0x6000, 2, 1, {0x79}},                   /* 121: above HighLimit */
		{0x6000, 2, 1, {0x87}},                   /* -121: below LowLimit */
		{0x6000, 5, 1, {9}},                      /* U8 rww, LowLimit 10 */
		{0x6000, 5, 1, {200}},                    /* U8 rww */
		{0x6000, 7, 4, {1, 2, 3, 4}},             /* U32 */
		{0x6000, 7, 2, {1, 2}},                   /* short */
		{0x6000, 8, 4, {0, 0, 0x20, 0x41}},       /* REAL32 10.0 */
		{0x6000, 8, 4, {0, 0, 0x30, 0x41}},       /* 11.0: above HighLimit */
		{0x6000, 0x0C, 6, {1, 2, 3, 4, 5, 6}},    /* TIME_OF_DAY */
		{0x6000, 0x15, 3, {0xAA, 0xBB, 0xCC}},    /* UNSIGNED24 */
		{0x6000, 0x10, 8, {1, 2, 3, 4, 5, 6, 7}}, /* REAL64 */
		{0x6000, 0, 1, {3}},                      /* const */
		{0x1018, 1, 4, {1, 0, 0, 0}},             /* ro */
	};
	static const enum co_od_writer writers[] = {CO_OD_WRITER_PDO, CO_OD_WRITER_SDO,
						    CO_OD_WRITER_APP};

	for (size_t w = 0; w < ARRAY_SIZE(writers); w++) {
		for (size_t i = 0; i < ARRAY_SIZE(cases); i++) {
			same_write(cases[i].index, cases[i].sub, cases[i].data, cases[i].len,
				   writers[w]);
		}
	}
}

ZTEST(od_cached, test_hooks_registered_after_the_cover)
{
	struct co_od_info info;
	struct co_od_cover cover = {0};
	struct probe p = {.refuse = CO_SDO_AB_DATA_DEV_STATE};
	const uint8_t v1[4] = {1, 0, 0, 0};
	const uint8_t v2[4] = {2, 0, 0, 0};
	uint32_t u = 0;

	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_write_cached(&fx.od, &info, &cover, v1, 4, CO_OD_WRITER_PDO));
	probe_hook(&fx.od, 0x6000, 7, &p);
	zassert_equal(co_od_write_cached(&fx.od, &info, &cover, v2, 4, CO_OD_WRITER_PDO),
		      CO_SDO_AB_DATA_DEV_STATE, "a hook added later is seen");
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 7, &u));
	zassert_equal(u, 1);
	p.refuse = 0U;
	zassert_ok(co_od_write_cached(&fx.od, &info, &cover, v2, 4, CO_OD_WRITER_PDO));
	zassert_equal(p.validated, 2);
	zassert_equal(p.notified, 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &p), 1);
	zassert_ok(co_od_write_cached(&fx.od, &info, &cover, v1, 4, CO_OD_WRITER_PDO));
	zassert_equal(p.notified, 1, "a removed hook is not called");
}

ZTEST(od_cached, test_read_same_as_generic_and_read_check)
{
	struct co_od_info info;
	struct co_od_cover cover = {0};
	struct probe p = {0};
	uint8_t a[8];
	uint8_t b[8];
	size_t la;
	size_t lb;
	static const uint8_t subs[] = {1, 2, 7, 8, 0x0C, 0x15, 0x10, 0};

	zassert_ok(co_od_set_u32(&fx.od, 0x6000, 7, 0xA1B2C3D4, CO_OD_WRITER_APP));
	zassert_ok(co_od_set_i8(&fx.od, 0x6000, 2, -7, CO_OD_WRITER_APP));
	for (size_t i = 0; i < ARRAY_SIZE(subs); i++) {
		struct co_od_cover c = {0};

		memset(a, 0, sizeof(a));
		memset(b, 0, sizeof(b));
		zassert_ok(co_od_find(&fx.od, 0x6000, subs[i], &info));
		zassert_equal(
			co_od_read_cached(&fx.od, &info, &c, a, sizeof(a), &la, CO_OD_WRITER_PDO),
			co_od_read_info(&fx.od, &info, 0, b, sizeof(b), &lb, CO_OD_WRITER_PDO));
		zassert_equal(la, lb);
		zassert_mem_equal(a, b, sizeof(a), "6000h:%u", subs[i]);
	}
	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_read_cached(&fx.od, &info, &cover, a, 4, &la, CO_OD_WRITER_PDO));
	p.refuse_read = CO_SDO_AB_NO_DATA;
	probe_hook(&fx.od, 0x6000, 7, &p);
	zassert_equal(co_od_read_cached(&fx.od, &info, &cover, a, 4, &la, CO_OD_WRITER_PDO),
		      CO_SDO_AB_NO_DATA, "a read check added later is seen");
}

ZTEST_SUITE(od_cached, NULL, NULL, fx_before, NULL, NULL);
