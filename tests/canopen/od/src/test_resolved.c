/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Hooks resolved per object and the resolved access of PDOs and SRDOs: co_od_move_of() says
 * a copy only where a copy is what co_od_write_info()/co_od_read_info() would do, and says so
 * again after hooks changed; an object's hooks are its own, in registration order; the links
 * that make them so are counted against CONFIG_CANOPEN_OD_HOOK_LINKS.
 */

#include "common.h"

struct probe {
	int notified;
	int validated;
	uint32_t refuse;
	uint32_t refuse_read;
};

/* A multi-byte value is a plain copy only where its C storage has the wire's (little-endian)
 * byte order; on a big-endian target it goes through the accessor.
 */
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define MOVE_U32        CO_OD_MOVE_COPY
#define MOVE_U32_NOTIFY CO_OD_MOVE_COPY_NOTIFY
#else
#define MOVE_U32        CO_OD_MOVE_ACCESS
#define MOVE_U32_NOTIFY CO_OD_MOVE_ACCESS
#endif
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

/*
 * A PDO write through co_od_move_of()'s answer (a copy, then co_od_notify()) leaves what
 * co_od_write_info() leaves (fx.od resolved, fx.od2 generic).
 */
static void same_write(uint16_t index, uint8_t sub, const uint8_t *data, size_t len)
{
	struct co_od_info info;
	uint8_t a[16] = {0};
	uint8_t b[16] = {0};
	uint32_t ab_r = 0U;
	uint32_t ab_g;

	zassert_ok(co_od_find(&fx.od, index, sub, &info));
	switch (co_od_move_of(&fx.od, &info, CO_OD_WRITER_PDO, true)) {
	case CO_OD_MOVE_COPY:
		zassert_true(co_od_copy_word((void *)co_od_value_ptr(&fx.od, &info), data, len));
		break;
	case CO_OD_MOVE_COPY_NOTIFY:
		zassert_true(co_od_copy_word((void *)co_od_value_ptr(&fx.od, &info), data, len));
		co_od_notify(&fx.od, &info, data, len, CO_OD_WRITER_PDO);
		break;
	default:
		ab_r = co_od_write_info(&fx.od, &info, data, len, CO_OD_WRITER_PDO);
		break;
	}
	zassert_ok(co_od_find(&fx.od2, index, sub, &info));
	ab_g = co_od_write_info(&fx.od2, &info, data, len, CO_OD_WRITER_PDO);
	zassert_equal(ab_r, ab_g, "%04X:%u: resolved %08x, generic %08x", index, sub, ab_r, ab_g);
	zassert_equal(rd(&fx.od, index, sub, a, sizeof(a)), rd(&fx.od2, index, sub, b, sizeof(b)));
	zassert_mem_equal(a, b, sizeof(a), "%04X:%u stored differently", index, sub);
}

static enum co_od_move move_of(uint16_t index, uint8_t sub, bool write)
{
	struct co_od_info info;

	zassert_ok(co_od_find(&fx.od, index, sub, &info));
	return co_od_move_of(&fx.od, &info, CO_OD_WRITER_PDO, write);
}

ZTEST(od_resolved, test_a_copy_only_where_the_accessor_would_copy)
{
	static const struct {
		uint16_t index;
		uint8_t sub;
		uint8_t len;
		uint8_t data[8];
		enum co_od_move move;
	} cases[] = {
		{0x6000, 1, 1, {1}, CO_OD_MOVE_ACCESS},                   /* BOOLEAN: checked */
		{0x6000, 1, 1, {2}, CO_OD_MOVE_ACCESS},                   /* BOOLEAN 2 */
		{0x6000, 2, 1, {0x78}, CO_OD_MOVE_ACCESS},                /* INTEGER8, limits */
		{0x6000, 2, 1, {0x79}, CO_OD_MOVE_ACCESS},                /* above HighLimit */
		{0x6000, 5, 1, {9}, CO_OD_MOVE_ACCESS},                   /* LowLimit 10 */
		{0x6000, 7, 4, {1, 2, 3, 4}, MOVE_U32},                   /* U32 */
		{0x6000, 8, 4, {0, 0, 0x20, 0x41}, CO_OD_MOVE_ACCESS},    /* REAL32, limits */
		{0x6000, 0x0C, 6, {1, 2, 3, 4, 5, 6}, CO_OD_MOVE_ACCESS}, /* TIME_OF_DAY */
		{0x6000, 0x15, 3, {0xAA, 0xBB, 0xCC}, CO_OD_MOVE_ACCESS}, /* UNSIGNED24 */
		{0x6000, 0, 1, {3}, CO_OD_MOVE_ACCESS},                   /* const */
		{0x1018, 1, 4, {1, 0, 0, 0}, CO_OD_MOVE_ACCESS},          /* ro */
	};

	for (size_t i = 0; i < ARRAY_SIZE(cases); i++) {
		zassert_equal(move_of(cases[i].index, cases[i].sub, true), cases[i].move, "%04X:%u",
			      cases[i].index, cases[i].sub);
		same_write(cases[i].index, cases[i].sub, cases[i].data, cases[i].len);
	}
}

ZTEST(od_resolved, test_moves_follow_the_hooks)
{
	struct probe p = {0};
	const struct co_od_hook notify_only = {0x6000, 0x6000, 7, 7, NULL, p_notify, &p};
	const uint8_t v[4] = {5, 0, 0, 0};

	zassert_equal(move_of(0x6000, 7, true), MOVE_U32);
	zassert_equal(move_of(0x6000, 7, false), MOVE_U32);
	zassert_ok(co_od_hook_register(&fx.od, &notify_only));
	zassert_equal(move_of(0x6000, 7, true), MOVE_U32_NOTIFY);
	zassert_equal(move_of(0x6000, 7, false), MOVE_U32, "no read check");
	same_write(0x6000, 7, v, 4);
	zassert_equal(p.notified, 1, "the copy's notify pass ran the hook");
	zassert_equal(p.validated, 0);
	zassert_equal(co_od_hook_unregister(&fx.od, &p), 1);

	/* The same hook on both dictionaries, which same_write() compares. */
	struct probe p2 = {.refuse = CO_SDO_AB_DATA_DEV_STATE};

	p.refuse = CO_SDO_AB_DATA_DEV_STATE;
	probe_hook(&fx.od, 0x6000, 7, &p);
	probe_hook(&fx.od2, 0x6000, 7, &p2);
	zassert_equal(move_of(0x6000, 7, true), CO_OD_MOVE_ACCESS, "a validate hook");
	zassert_equal(move_of(0x6000, 7, false), CO_OD_MOVE_ACCESS, "a read check");
	same_write(0x6000, 7, v, 4);
	zassert_equal(p.validated, 1, "the accessor asked the validate hook");
	zassert_equal(co_od_hook_unregister(&fx.od, &p), 1);
	zassert_equal(co_od_hook_unregister(&fx.od2, &p2), 1);
	zassert_equal(move_of(0x6000, 7, true), MOVE_U32, "and a copy again");
}

ZTEST(od_resolved, test_reads_through_the_accessor_see_a_later_read_check)
{
	struct co_od_info info;
	struct probe p = {.refuse_read = CO_SDO_AB_NO_DATA};
	uint8_t a[4];
	size_t la;

	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_read_info(&fx.od, &info, 0, a, 4, &la, CO_OD_WRITER_PDO));
	probe_hook(&fx.od, 0x6000, 7, &p);
	zassert_equal(co_od_read_info(&fx.od, &info, 0, a, 4, &la, CO_OD_WRITER_PDO),
		      CO_SDO_AB_NO_DATA, "a read check added later is seen");
	zassert_ok(co_od_read_info(&fx.od, &info, 0, a, 4, &la, CO_OD_WRITER_APP),
		   "the application is not checked");
}

/*
 * An object's hooks are its own: a write to an object without hooks calls none, however wide
 * the hooks on other objects are; a hook over a range of indexes links to each index of the
 * dictionary in it, and no other.
 */
static int wide_calls;

static uint32_t wide_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	wide_calls++;
	return 0U;
}

static void wide_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	wide_calls++;
}

static uint32_t wide_read_check(const struct co_od *od, const struct co_od_info *info,
				enum co_od_writer reader, void *user_data)
{
	wide_calls++;
	return 0U;
}

/* Indexes of the dictionary in [first, last]. */
static uint16_t entries_in(uint16_t first, uint16_t last)
{
	uint16_t n = 0U;

	for (uint16_t i = 0; i < od_test_od_def.n_entries; i++) {
		n += od_test_od_def.entries[i].index >= first &&
		     od_test_od_def.entries[i].index <= last;
	}
	return n;
}

ZTEST(od_resolved, test_a_write_calls_only_its_objects_hooks)
{
	const struct co_od_hook wide[] = {
		/* every index below 6000h, and 6000h's other sub-indexes */
		{0x0000, 0x5FFF, 0, 0xFF, wide_validate, wide_notify, &wide_calls, wide_read_check},
		{0x6000, 0x6000, 0, 6, wide_validate, wide_notify, &wide_calls, wide_read_check},
		{0x6001, 0xFFFF, 0, 0xFF, wide_validate, wide_notify, &wide_calls, wide_read_check},
	};
	uint8_t a[4];
	size_t la;

	wide_calls = 0;
	zassert_ok(co_od_hooks_register(&fx.od, wide, ARRAY_SIZE(wide)));
	zassert_equal(fx.od.n_links, entries_in(0x0000, 0xFFFF),
		      "a link per index of the dictionary each hook covers");
	zassert_ok(co_od_set_u32(&fx.od, 0x6000, 7, 9U, CO_OD_WRITER_SDO));
	zassert_ok(co_od_read(&fx.od, 0x6000, 7, 0, a, sizeof(a), &la, CO_OD_WRITER_SDO));
	zassert_equal(move_of(0x6000, 7, true), MOVE_U32);
	zassert_equal(wide_calls, 0, "no other object's hook ran");
	zassert_ok(co_od_set_u16(&fx.od, 0x6000, 6, 9U, CO_OD_WRITER_SDO));
	zassert_equal(wide_calls, 2, "6000h:06 has the hook: validate and notify");
	zassert_equal(co_od_hook_unregister(&fx.od, &wide_calls), 3);
	zassert_equal(fx.od.n_links, 0U, "the links went with the hooks");
}

/* More links than CONFIG_CANOPEN_OD_HOOK_LINKS: -ENOSPC, and nothing registered. */
ZTEST(od_resolved, test_links_exhausted_registers_nothing)
{
	struct probe p = {0};
	const struct co_od_hook all = {0x0000, 0xFFFF, 0, 0xFF, p_validate, p_notify, &p};
	uint16_t per_hook = entries_in(0x0000, 0xFFFF);
	int n = 0;
	int err;

	while ((err = co_od_hook_register(&fx.od, &all)) == 0) {
		n++;
	}
	zassert_equal(err, -ENOSPC);
	zassert_true(fx.od.n_links + per_hook > CONFIG_CANOPEN_OD_HOOK_LINKS ||
			     fx.od.n_hooks == CONFIG_CANOPEN_OD_HOOKS_MAX,
		     "refused for want of room only");
	zassert_equal(fx.od.n_links, n * per_hook, "the refused hook took no link");
	zassert_equal(co_od_hook_unregister(&fx.od, &p), n);

	/* A batch whose later hooks do not fit leaves out its first one too. */
	static struct co_od_hook batch[2 + CONFIG_CANOPEN_OD_HOOK_LINKS];
	size_t nb = 2U + CONFIG_CANOPEN_OD_HOOK_LINKS / per_hook;

	batch[0] = (struct co_od_hook){0x6000, 0x6000, 7, 7, NULL, p_notify, &p};
	for (size_t i = 1; i < nb; i++) {
		batch[i] = all;
	}
	zassert_equal(co_od_hooks_register(&fx.od, batch, nb), -ENOSPC);
	zassert_equal(fx.od.n_hooks, 0U);
	zassert_equal(fx.od.n_links, 0U);
	p.notified = 0;
	zassert_ok(co_od_set_u32(&fx.od, 0x6000, 7, 1U, CO_OD_WRITER_SDO));
	zassert_equal(p.notified + p.validated, 0, "nothing of the batch runs");
}

/*
 * The notify pass of an object: its hooks in registration order, whichever sub-indexes they
 * cover around it, the others never.
 */
static int order[8];
static int n_order;

static void o_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	order[n_order++] = (int)(intptr_t)user_data;
}

static void order_hook(uint16_t first, uint16_t last, uint8_t sub_first, uint8_t sub_last, int tag)
{
	const struct co_od_hook h = {
		first, last, sub_first, sub_last, NULL, o_notify, (void *)(intptr_t)tag};

	zassert_ok(co_od_hook_register(&fx.od, &h));
}

ZTEST(od_resolved, test_notify_pass_in_registration_order)
{
	uint8_t data[4] = {1, 0, 0, 0};
	struct co_od_info info;

	n_order = 0;
	order_hook(0x6000, 0x6000, 7, 7, 1);
	order_hook(0x1000, 0x6000, 6, 8, 2); /* starts lower: still after the first */
	order_hook(0x6000, 0x6000, 1, 3, 3); /* another sub-index */
	order_hook(0x6000, 0xFFFF, 7, 7, 4);
	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_write_info(&fx.od, &info, data, 4, CO_OD_WRITER_PDO));
	zassert_equal(n_order, 3, "the hook on 6000h:01-03 is not called");
	zassert_equal(order[0], 1);
	zassert_equal(order[1], 2);
	zassert_equal(order[2], 4);
	n_order = 0;
	co_od_notify(&fx.od, &info, data, 4, CO_OD_WRITER_PDO);
	zassert_equal(n_order, 3, "co_od_notify() is the same pass");
	zassert_equal(order[2], 4);
	for (int tag = 1; tag <= 4; tag++) {
		zassert_equal(co_od_hook_unregister(&fx.od, (void *)(intptr_t)tag), 1);
	}
}

/* A single notify hook that registers a hook as it runs. */
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

static void write_u32(uint32_t v)
{
	struct co_od_info info;
	uint8_t data[4];

	co_od_le_put(data, 4, v);
	zassert_ok(co_od_find(&fx.od, 0x6000, 7, &info));
	zassert_ok(co_od_write_info(&fx.od, &info, data, 4, CO_OD_WRITER_PDO));
}

ZTEST(od_resolved, test_one_notify_hook_that_changes_the_hooks)
{
	const struct co_od_hook h = {0x6000, 0x6000, 7, 7, NULL, grow_notify, &grow_calls};
	uint32_t u = 0;

	memset(&late, 0, sizeof(late));
	grow_calls = 0;
	grow_add = false;
	zassert_ok(co_od_hook_register(&fx.od, &h));
	write_u32(1);
	zassert_equal(grow_calls, 1);

	grow_add = true;
	write_u32(2);
	zassert_equal(grow_calls, 2, "the hook ran once");
	zassert_equal(late.validated + late.notified, 0, "a hook added by the pass waits");
	zassert_ok(co_od_get_u32(&fx.od, 0x6000, 7, &u));
	zassert_equal(u, 2);

	write_u32(3);
	zassert_equal(grow_calls, 3);
	zassert_equal(late.validated, 1, "and joins at the next write");
	zassert_equal(late.notified, 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &late), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &grow_calls), 1);
}

static void filler_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
}

/* The last hook of a full table (past position 255 with 256 or more) is found and run. */
ZTEST(od_resolved, test_the_last_hook_of_a_full_table_runs)
{
	static int filler;
	struct probe p = {0};

	for (int i = 0; i < CONFIG_CANOPEN_OD_HOOKS_MAX - 1; i++) {
		const struct co_od_hook f = {0x1000, 0x1000, 0, 0, NULL, filler_notify, &filler};

		zassert_ok(co_od_hook_register(&fx.od, &f));
	}
	const struct co_od_hook h = {0x6000, 0x6000, 7, 7, p_validate, p_notify, &p};

	zassert_ok(co_od_hook_register(&fx.od, &h));
	zassert_equal(fx.od.n_hooks, CONFIG_CANOPEN_OD_HOOKS_MAX);
	write_u32(5);
	write_u32(6);
	zassert_equal(p.validated, 2);
	zassert_equal(p.notified, 2);
	zassert_equal(co_od_hook_unregister(&fx.od, &p), 1);
	zassert_equal(co_od_hook_unregister(&fx.od, &filler), CONFIG_CANOPEN_OD_HOOKS_MAX - 1);
}

ZTEST_SUITE(od_resolved, NULL, NULL, fx_before, NULL, NULL);
