/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Hooks that register and unregister hooks while the hooks of a write run (the PDO service
 * re-hooks its mapped objects from inside a notify hook). The table is sorted by index, so
 * a change below the running hook moves it; every hook present throughout must still run
 * exactly once, a hook removed before its turn not at all, a hook added during the write
 * from the next write on.
 */

#include "common.h"

enum {
	H0,   /* 1000h-1FFFh */
	H1,   /* 1010h-1017h: changes the table */
	H2,   /* 1015h-1017h */
	H3,   /* 1017h */
	NEW1, /* 1000h-1017h, added by H1 (below H1) */
	NEW2, /* 1016h-1017h, added by H1 (between H2 and H3) */
	N_HOOKS,
};

static struct {
	int notified[N_HOOKS];
	int validated[N_HOOKS];
	bool add;         /* H1 adds NEW1 and NEW2 (once) */
	bool remove;      /* H1 removes H0 (already run) and H3 (not yet run) */
	bool in_validate; /* H1 changes the table from its validate hook instead */
} re;

static int id_of(void *user_data)
{
	return (int)((int *)user_data - re.notified);
}

static void changes(struct co_od *od);

static uint32_t v_count(struct co_od *od, struct co_od_req *req, void *user_data)
{
	int id = id_of(user_data);

	re.validated[id]++;
	if (id == H1 && re.in_validate) {
		changes(od);
	}
	return 0U;
}

static void n_count(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	int id = id_of(user_data);

	re.notified[id]++;
	if (id == H1 && !re.in_validate) {
		changes(od);
	}
}

static void reg(struct co_od *od, int id, uint16_t first, uint16_t last)
{
	const struct co_od_hook h = {first, last, 0, 0xFF, v_count, n_count, &re.notified[id]};

	zassert_ok(co_od_hook_register(od, &h));
}

static void changes(struct co_od *od)
{
	if (re.add) {
		re.add = false;
		reg(od, NEW1, 0x1000, 0x1017);
		reg(od, NEW2, 0x1016, 0x1017);
	}
	if (re.remove) {
		re.remove = false;
		zassert_equal(co_od_hook_unregister(od, &re.notified[H0]), 1);
		zassert_equal(co_od_hook_unregister(od, &re.notified[H3]), 1);
	}
}

static void setup(void)
{
	memset(&re, 0, sizeof(re));
	reg(&fx.od, H0, 0x1000, 0x1FFF);
	reg(&fx.od, H1, 0x1010, 0x1017);
	reg(&fx.od, H2, 0x1015, 0x1017);
	reg(&fx.od, H3, 0x1017, 0x1017);
}

static void write_1017(void)
{
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 100, CO_OD_WRITER_SDO));
}

ZTEST(od_hook_reentry, test_hooks_added_below_while_notifying)
{
	setup();
	re.add = true;
	write_1017();
	for (int i = H0; i <= H3; i++) {
		zassert_equal(re.notified[i], 1, "hook %d notified %d times", i, re.notified[i]);
	}
	zassert_equal(re.notified[NEW1], 0, "added during the write: not called for it");
	zassert_equal(re.notified[NEW2], 0);

	memset(re.notified, 0, sizeof(re.notified));
	write_1017();
	for (int i = 0; i < N_HOOKS; i++) {
		zassert_equal(re.notified[i], 1, "next write: hook %d notified %d times", i,
			      re.notified[i]);
	}
}

ZTEST(od_hook_reentry, test_hooks_removed_while_notifying)
{
	setup();
	re.remove = true;
	write_1017();
	zassert_equal(re.notified[H0], 1);
	zassert_equal(re.notified[H1], 1);
	zassert_equal(re.notified[H2], 1, "the hook after the removed one still runs");
	zassert_equal(re.notified[H3], 0, "removed before its turn");
}

ZTEST(od_hook_reentry, test_add_and_remove_while_validating)
{
	setup();
	re.add = true;
	re.remove = true;
	re.in_validate = true;
	write_1017();
	zassert_equal(re.validated[H0], 1);
	zassert_equal(re.validated[H1], 1);
	zassert_equal(re.validated[H2], 1);
	zassert_equal(re.validated[H3], 0, "removed before its turn");
	zassert_equal(re.validated[NEW1] + re.validated[NEW2], 0);
	/* Notify runs over the table as it is after validation. */
	zassert_equal(re.notified[H0], 0);
	zassert_equal(re.notified[H3], 0);
	zassert_equal(re.notified[H1], 1);
	zassert_equal(re.notified[H2], 1);
	zassert_equal(re.notified[NEW1], 1);
	zassert_equal(re.notified[NEW2], 1);
}

ZTEST_SUITE(od_hook_reentry, NULL, NULL, fx_before, NULL, NULL);
