/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Validate and notify hooks: per sub-index ranges, every writer, refusal before the write. */

#include "common.h"

struct rec {
	int validates;
	int notifies;
	uint32_t refuse; /* abort code to return from validate, 0 = accept */
	uint16_t last_index;
	uint8_t last_sub;
	enum co_od_writer last_writer;
	uint64_t seen_in_notify; /* value read back inside notify */
	uint64_t seen_in_validate;
	int order[8];
	int n_order;
	int id;
	struct rec *log; /* shared ordering log */
};

static uint32_t v_hook(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct rec *r = user_data;
	uint8_t buf[8] = {0};
	size_t len;

	r->validates++;
	/* The old value is still in place while validating. */
	(void)co_od_read(od, req->info->index, req->info->sub, 0, buf, sizeof(buf), &len,
			 CO_OD_WRITER_APP);
	r->seen_in_validate = co_od_le_get(buf, len > 8 ? 8 : len);
	if (r->log != NULL) {
		r->log->order[r->log->n_order++] = r->id;
	}
	return r->refuse;
}

static void n_hook(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct rec *r = user_data;
	uint8_t buf[8] = {0};
	size_t len;

	r->notifies++;
	r->last_index = req->info->index;
	r->last_sub = req->info->sub;
	r->last_writer = req->writer;
	(void)co_od_read(od, req->info->index, req->info->sub, 0, buf, sizeof(buf), &len,
			 CO_OD_WRITER_APP);
	r->seen_in_notify = co_od_le_get(buf, len > 8 ? 8 : len);
	if (r->log != NULL) {
		r->log->order[r->log->n_order++] = 10 + r->id;
	}
}

static int hook(struct co_od *od, uint16_t i0, uint16_t i1, uint8_t s0, uint8_t s1, struct rec *r)
{
	const struct co_od_hook h = {
		.index_first = i0,
		.index_last = i1,
		.sub_first = s0,
		.sub_last = s1,
		.validate = v_hook,
		.notify = n_hook,
		.user_data = r,
	};

	return co_od_hook_register(od, &h);
}

ZTEST(od_hooks, test_accept_then_notify_sees_new_value)
{
	struct rec r = {0};

	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 7, CO_OD_WRITER_APP));
	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &r));
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 500, CO_OD_WRITER_SDO));
	zassert_equal(r.validates, 1);
	zassert_equal(r.notifies, 1);
	zassert_equal(r.seen_in_validate, 7, "validate must run before the write");
	zassert_equal(r.seen_in_notify, 500, "notify must run after the write");
	zassert_equal(r.last_writer, CO_OD_WRITER_SDO);
}

ZTEST(od_hooks, test_refusal_keeps_value_and_skips_notify)
{
	struct rec r = {.refuse = CO_SDO_AB_DATA_DEV_STATE};
	uint16_t v;

	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &r));
	zassert_equal(co_od_set_u16(&fx.od, 0x1017, 0, 500, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
	zassert_ok(co_od_get_u16(&fx.od, 0x1017, 0, &v));
	zassert_equal(v, 0);
	zassert_equal(r.notifies, 0);
}

ZTEST(od_hooks, test_every_writer_is_named)
{
	static const enum co_od_writer writers[] = {
		CO_OD_WRITER_SDO,  CO_OD_WRITER_PDO, CO_OD_WRITER_SRDO,
		CO_OD_WRITER_MPDO, CO_OD_WRITER_APP, CO_OD_WRITER_STORAGE,
	};
	struct rec r = {0};

	/* 6000h:7 is rw and mappable both ways: every writer may write it. */
	zassert_ok(hook(&fx.od, 0x6000, 0x6000, 7, 7, &r));
	for (size_t i = 0; i < ARRAY_SIZE(writers); i++) {
		zassert_ok(co_od_set_u32(&fx.od, 0x6000, 7, (uint32_t)i, writers[i]));
		zassert_equal(r.last_writer, writers[i]);
		zassert_equal(r.seen_in_notify, i);
	}
	zassert_equal(r.notifies, ARRAY_SIZE(writers));
}

ZTEST(od_hooks, test_ranges)
{
	struct rec r = {0};
	uint32_t cob = 0x80000000U;

	/* Like the PDO service: all RPDO communication objects, sub-indexes 1..2. */
	zassert_ok(hook(&fx.od, 0x1400, 0x15FF, 1, 2, &r));
	zassert_ok(co_od_set_u32(&fx.od, 0x1400, 1, cob, CO_OD_WRITER_SDO));
	zassert_equal(r.notifies, 1);
	zassert_equal(r.last_index, 0x1400);
	zassert_equal(r.last_sub, 1);
	zassert_ok(co_od_set_u32(&fx.od, 0x1600, 1, 0, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u32(&fx.od, 0x1800, 1, cob, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 1, CO_OD_WRITER_SDO));
	zassert_equal(r.notifies, 1, "hook ran outside its range");
}

ZTEST(od_hooks, test_several_hooks_all_must_accept)
{
	struct rec log = {0};
	struct rec a = {.id = 1, .log = &log};
	struct rec b = {.id = 2, .log = &log, .refuse = CO_SDO_AB_PARAM_INCOMPAT};
	uint32_t v;

	zassert_ok(hook(&fx.od, 0x1005, 0x1005, 0, 0, &a));
	zassert_ok(hook(&fx.od, 0x1000, 0x1FFF, 0, 0xFF, &b));
	zassert_equal(co_od_set_u32(&fx.od, 0x1005, 0, 0x81, CO_OD_WRITER_SDO),
		      CO_SDO_AB_PARAM_INCOMPAT);
	zassert_ok(co_od_get_u32(&fx.od, 0x1005, 0, &v));
	zassert_equal(v, 0x80);
	zassert_equal(a.notifies + b.notifies, 0);
	b.refuse = 0;
	log.n_order = 0;
	zassert_ok(co_od_set_u32(&fx.od, 0x1005, 0, 0x81, CO_OD_WRITER_SDO));
	/* Hooks run in registration order (a, then the wider b): validates, then notifies. */
	zassert_equal(log.n_order, 4);
	zassert_equal(log.order[0], 1);
	zassert_equal(log.order[1], 2);
	zassert_equal(log.order[2], 11);
	zassert_equal(log.order[3], 12);
}

static uint32_t handled(struct co_od *od, struct co_od_req *req, void *user_data)
{
	(void)od;
	(void)req;
	(*(int *)user_data)++;
	return CO_OD_HANDLED;
}

ZTEST(od_hooks, test_handled_command_stores_nothing)
{
	int calls = 0;
	struct rec r = {0};
	const struct co_od_hook h = {
		.index_first = 0x1010,
		.index_last = 0x1010,
		.sub_first = 1,
		.sub_last = 4,
		.validate = handled,
		.user_data = &calls,
	};
	uint32_t v;

	zassert_ok(co_od_hook_register(&fx.od, &h));
	zassert_ok(hook(&fx.od, 0x1010, 0x1010, 1, 1, &r));
	zassert_ok(co_od_set_u32(&fx.od, 0x1010, 1, 0x65766173, CO_OD_WRITER_SDO));
	zassert_equal(calls, 1);
	zassert_ok(co_od_get_u32(&fx.od, 0x1010, 1, &v));
	zassert_equal(v, 1, "a handled command must not store its value");
	zassert_equal(r.notifies, 1, "notify still runs for commands");
}

ZTEST(od_hooks, test_registration_limits_and_unregister)
{
	struct rec r = {0};
	struct rec other = {0};
	const struct co_od_hook bad = {.index_first = 2, .index_last = 1, .notify = n_hook};
	const struct co_od_hook none = {.index_first = 1, .index_last = 1};

	zassert_equal(co_od_hook_register(&fx.od, &bad), -EINVAL);
	zassert_equal(co_od_hook_register(&fx.od, &none), -EINVAL);
	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &other));
	for (int i = 1; i < CONFIG_CANOPEN_OD_HOOKS_MAX; i++) {
		zassert_ok(hook(&fx.od, 0x2000 + i, 0x2000 + i, 0, 0, &r));
	}
	zassert_equal(hook(&fx.od, 0x1017, 0x1017, 0, 0, &r), -ENOSPC);
	zassert_equal(co_od_hook_unregister(&fx.od, &r), CONFIG_CANOPEN_OD_HOOKS_MAX - 1);
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 3, CO_OD_WRITER_SDO));
	zassert_equal(other.notifies, 1);
	zassert_equal(r.notifies, 0);
}

static int rc_calls;

static uint32_t rc_refuse(const struct co_od *od, const struct co_od_info *info,
			  enum co_od_writer reader, void *user_data)
{
	rc_calls++;
	return CO_SDO_AB_NO_DATA;
}

/*
 * A hook with a read check is one hook like any other: it takes one table entry, runs in
 * registration order with the others, and is removed whole.
 */
ZTEST(od_hooks, test_a_hook_with_a_read_check_is_one_hook)
{
	struct rec log = {0};
	struct rec a = {.id = 1, .log = &log};
	struct rec b = {.id = 2, .log = &log};
	struct rec c = {.id = 3, .log = &log};
	struct rec fill = {0};
	struct rec rc = {0};
	const struct co_od_hook with_check = {
		.index_first = 0x1017,
		.index_last = 0x1017,
		.validate = v_hook,
		.notify = n_hook,
		.user_data = &b,
		.read_check = rc_refuse,
	};
	uint8_t buf[2];
	size_t len;

	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &a));
	for (int i = 1; i < CONFIG_CANOPEN_OD_HOOKS_MAX - 2; i++) {
		zassert_ok(hook(&fx.od, 0x2000 + i, 0x2000 + i, 0, 0, &fill));
	}
	/* Two entries free: the hook with its check, then one more. */
	rc_calls = 0;
	zassert_ok(co_od_hook_register(&fx.od, &with_check));
	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &c));
	zassert_equal(hook(&fx.od, 0x1017, 0x1017, 0, 0, &rc), -ENOSPC, "the table is full");
	zassert_equal(co_od_hook_unregister(&fx.od, &fill), CONFIG_CANOPEN_OD_HOOKS_MAX - 3);

	zassert_equal(co_od_read(&fx.od, 0x1017, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_DATA, "the read check runs");
	zassert_equal(rc_calls, 1);
	zassert_ok(co_od_read(&fx.od, 0x1017, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_APP));
	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 5, CO_OD_WRITER_SDO));
	zassert_equal(log.n_order, 6);
	static const int expected[] = {1, 2, 3, 11, 12, 13};

	zassert_mem_equal(log.order, expected, sizeof(expected), "registration order");

	zassert_equal(co_od_hook_unregister(&fx.od, &b), 1, "one hook");
	zassert_ok(co_od_read(&fx.od, 0x1017, 0, 0, buf, sizeof(buf), &len, CO_OD_WRITER_SDO));
	zassert_equal(rc_calls, 1, "a removed read check does not run");
}

ZTEST(od_hooks, test_hooks_are_per_node)
{
	struct rec r = {0};

	zassert_ok(hook(&fx.od, 0x1017, 0x1017, 0, 0, &r));
	zassert_ok(co_od_set_u16(&fx.od2, 0x1017, 0, 9, CO_OD_WRITER_SDO));
	zassert_equal(r.notifies, 0);
}

ZTEST_SUITE(od_hooks, NULL, NULL, fx_before, NULL, NULL);
