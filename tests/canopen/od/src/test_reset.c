/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Reset Communication / Reset Application and $NODEID values (CiA 301 §7.3.2.2). */

#include "common.h"

struct restore_log {
	int calls;
	uint32_t masks[4];
};

static void log_restore(struct co_od *od, uint32_t mask, void *user_data)
{
	struct restore_log *l = user_data;

	(void)od;
	l->masks[l->calls++ & 3] = mask;
}

ZTEST(od_reset, test_nodeid_values)
{
	struct co_od_info info;
	uint32_t v;

	zassert_ok(co_od_get_u32(&fx.od, 0x1400, 1, &v));
	zassert_equal(v, 0x205);
	zassert_ok(co_od_get_u32(&fx.od, 0x1800, 1, &v));
	zassert_equal(v, 0x185);
	zassert_ok(co_od_find(&fx.od, 0x1800, 1, &info));
	zassert_true(co_od_is_nodeid_default(&fx.od, &info));
	/* A new node-ID applies at the next Reset Communication. */
	zassert_ok(co_od_set_node_id(&fx.od, 0x7F));
	zassert_ok(co_od_get_u32(&fx.od, 0x1800, 1, &v));
	zassert_equal(v, 0x185);
	co_od_reset_comm(&fx.od);
	zassert_ok(co_od_get_u32(&fx.od, 0x1800, 1, &v));
	zassert_equal(v, 0x1FF);
	zassert_ok(co_od_set_u32(&fx.od, 0x1800, 1, 0x800001FF, CO_OD_WRITER_SDO));
	zassert_false(co_od_is_nodeid_default(&fx.od, &info));
	zassert_equal(co_od_set_node_id(&fx.od, 0), -EINVAL);
	zassert_equal(co_od_set_node_id(&fx.od, 128), -EINVAL);
	zassert_ok(co_od_set_node_id(&fx.od, 255)); /* unconfigured (LSS) */
}

ZTEST(od_reset, test_reset_comm_keeps_application_values)
{
	uint16_t u16;
	int32_t i32;

	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 1000, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_i32(&fx.od, 0x2003, 2, 77, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u16(&fx.od, 0x6000, 6, 1, CO_OD_WRITER_SDO));
	co_od_reset_comm(&fx.od);
	zassert_ok(co_od_get_u16(&fx.od, 0x1017, 0, &u16));
	zassert_equal(u16, 0);
	zassert_ok(co_od_get_i32(&fx.od, 0x2003, 2, &i32));
	zassert_equal(i32, 77);
	zassert_ok(co_od_get_u16(&fx.od, 0x6000, 6, &u16));
	zassert_equal(u16, 1);
}

ZTEST(od_reset, test_reset_app_keeps_communication_values)
{
	uint16_t u16;
	int32_t i32;

	zassert_ok(co_od_set_u16(&fx.od, 0x1017, 0, 1000, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_i32(&fx.od, 0x2003, 2, 77, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u16(&fx.od, 0x6000, 6, 1, CO_OD_WRITER_SDO));
	co_od_reset_app(&fx.od);
	zassert_ok(co_od_get_u16(&fx.od, 0x1017, 0, &u16));
	zassert_equal(u16, 1000);
	zassert_ok(co_od_get_i32(&fx.od, 0x2003, 2, &i32));
	zassert_equal(i32, 2);
	zassert_ok(co_od_get_u16(&fx.od, 0x6000, 6, &u16));
	zassert_equal(u16, 0xBEEF);
}

ZTEST(od_reset, test_restore_callback_groups)
{
	struct restore_log l = {0};

	zassert_ok(co_od_set_restore_cb(&fx.od, log_restore, &l));
	co_od_reset_app(&fx.od);
	co_od_reset_comm(&fx.od);
	zassert_equal(l.calls, 2);
	zassert_equal(l.masks[0],
		      CO_OD_GROUP_BIT(CO_OD_GROUP_APP) | CO_OD_GROUP_BIT(CO_OD_GROUP_MANUF));
	zassert_equal(l.masks[1], CO_OD_GROUP_BIT(CO_OD_GROUP_COMM));
}

ZTEST(od_reset, test_init_rejects_bad_arguments)
{
	struct co_od od;

	zassert_equal(co_od_init(&od, NULL, &fx.ram, 1), -EINVAL);
	zassert_equal(co_od_init(&od, &od_test_od_def, NULL, 1), -EINVAL);
	zassert_equal(co_od_init(NULL, &od_test_od_def, &fx.ram, 1), -EINVAL);
}

#ifdef CONFIG_CANOPEN_OD_EDS
struct sink_buf {
	char text[16384];
	size_t len;
};

static int to_buf(const char *s, size_t len, void *user)
{
	struct sink_buf *b = user;

	if (b->len + len >= sizeof(b->text)) {
		return -ENOSPC;
	}
	memcpy(b->text + b->len, s, len);
	b->len += len;
	return 0;
}

ZTEST(od_reset, test_eds_writer)
{
	static struct sink_buf b;

	b.len = 0;
	zassert_ok(co_od_eds_write(&fx.od, to_buf, &b));
	b.text[b.len] = '\0';
	zassert_not_null(strstr(b.text, "[1400sub1]\nParameterName=COB-ID used by RPDO\n"
					"ObjectType=0x7\nDataType=0x0007\nAccessType=rw\n"
					"DefaultValue=$NODEID+0x200\n"));
	zassert_not_null(strstr(b.text, "DefaultValue=-9223372036854775808\n"));
	zassert_not_null(strstr(b.text, "[ManufacturerObjects]\nSupportedObjects=6\n"));
}
#endif

ZTEST_SUITE(od_reset, NULL, NULL, fx_before, NULL, NULL);
