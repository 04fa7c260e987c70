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

/*
 * The pass of the covering notify hooks through a cover, whatever its shape: one hook (the
 * inline path), hooks next to each other, and hooks with one between them that covers
 * another sub-index. Each covering hook runs once, in registration order, the other never.
 */
static int order[8];
static int n_order;

static void o_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	order[n_order++] = (int)(intptr_t)user_data;
}

static void order_hook(uint8_t sub_first, uint8_t sub_last, int tag)
{
	const struct co_od_hook h = {
		0x6000, 0x6000, sub_first, sub_last, NULL, o_notify, (void *)(intptr_t)tag};

	zassert_ok(co_od_hook_register(&fx.od, &h));
}

static void write_u32_cached(struct co_od_cover *cover, uint32_t v)
{
	struct co_od_info info;
	uint8_t data[4];

	co_od_le_put(data, 4, v);
	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_write_cached(&fx.od, &info, cover, data, 4, CO_OD_WRITER_PDO));
}

ZTEST(od_cached, test_notify_pass_of_every_cover_shape)
{
	struct co_od_cover cover = {0};

	n_order = 0;
	order_hook(7, 7, 1);
	write_u32_cached(&cover, 1);
	zassert_equal(n_order, 1, "one hook: one call");
	zassert_equal(order[0], 1);

	order_hook(6, 8, 2);
	n_order = 0;
	write_u32_cached(&cover, 2);
	zassert_equal(n_order, 2, "two hooks next to each other");
	zassert_equal(order[0], 1);
	zassert_equal(order[1], 2);

	order_hook(1, 3, 3); /* same index_first: between them and the next one, not covering */
	order_hook(7, 7, 4);
	n_order = 0;
	write_u32_cached(&cover, 3);
	zassert_equal(n_order, 3, "the hook on 6000h:01-03 is not called");
	zassert_equal(order[0], 1);
	zassert_equal(order[1], 2);
	zassert_equal(order[2], 4);
	zassert_equal(co_od_hook_unregister(&fx.od, (void *)(intptr_t)1), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, (void *)(intptr_t)2), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, (void *)(intptr_t)3), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, (void *)(intptr_t)4), 1);
}

/* A single notify hook (the one-call pass) that registers and removes hooks as it runs. */
static struct probe late;
static int grow_calls;
static bool grow_add;

static void grow_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	grow_calls++;
	if (grow_add) {
		grow_add = false;
		probe_hook(od, 0x6000, 7, &late);
	}
}

ZTEST(od_cached, test_one_notify_hook_that_changes_the_table)
{
	const struct co_od_hook h = {0x6000, 0x6000, 7, 7, NULL, grow_notify, &grow_calls};
	struct co_od_cover cover = {0};
	uint32_t u = 0;

	memset(&late, 0, sizeof(late));
	grow_calls = 0;
	grow_add = false;
	zassert_ok(co_od_hook_register(&fx.od, &h));
	write_u32_cached(&cover, 1);
	zassert_equal(grow_calls, 1);

	grow_add = true;
	write_u32_cached(&cover, 2);
	zassert_equal(grow_calls, 2, "the hook ran once");
	zassert_equal(late.validated + late.notified, 0, "a hook added by the pass waits");
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 7, &u));
	zassert_equal(u, 2);

	write_u32_cached(&cover, 3);
	zassert_equal(grow_calls, 3);
	zassert_equal(late.validated, 1, "and joins at the next write");
	zassert_equal(late.notified, 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &late), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &grow_calls), 1);
}

/* The cover is 8 bytes while hook positions fit a byte, the generation a full word. */
ZTEST(od_cached, test_cover_layout)
{
	zassert_equal(sizeof(((struct co_od_cover *)NULL)->gen), sizeof(uint32_t));
	if (CONFIG_CANOPEN_OD_HOOKS_MAX < 256) {
		zassert_equal(sizeof(struct co_od_cover), 8U);
	} else {
		zassert_equal(sizeof(((struct co_od_cover *)NULL)->first), sizeof(uint16_t));
	}
}

static void filler_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
}

/*
 * A hook behind every other entry of a full table (past position 255 when the table holds
 * 256 or more) is found by the cover: its validate and notify hooks run on cached writes.
 */
ZTEST(od_cached, test_cover_finds_the_last_hook_of_a_full_table)
{
	static int filler;
	struct probe p = {0};
	struct co_od_cover cover = {0};

	for (int i = 0; i < CONFIG_CANOPEN_OD_HOOKS_MAX - 1; i++) {
		const struct co_od_hook f = {0x1000, 0x1000, 0, 0, NULL, filler_notify, &filler};

		zassert_ok(co_od_hook_register(&fx.od, &f));
	}
	const struct co_od_hook h = {0x6000, 0x6000, 7, 7, p_validate, p_notify, &p};

	zassert_ok(co_od_hook_register(&fx.od, &h));
	zassert_equal(fx.od.n_hooks, CONFIG_CANOPEN_OD_HOOKS_MAX);
	write_u32_cached(&cover, 5);
	write_u32_cached(&cover, 6);
	if (IS_ENABLED(CONFIG_CANOPEN_OD_COVER)) {
		zassert_equal(cover.first, CONFIG_CANOPEN_OD_HOOKS_MAX - 1);
	}
	zassert_equal(p.validated, 2);
	zassert_equal(p.notified, 2);
	zassert_equal(co_od_hook_unregister(&fx.od, &p), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &filler), CONFIG_CANOPEN_OD_HOOKS_MAX - 1);
}

ZTEST_SUITE(od_cached, NULL, NULL, fx_before, NULL, NULL);
