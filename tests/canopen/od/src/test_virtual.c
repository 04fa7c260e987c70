/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Object providers ("virtual objects"): same checks and hooks as dictionary objects. */

#include "common.h"

/* 3000h..30FFh: VAR UNSIGNED32 rw (limit 0..1000) kept in an array; 3100h: a string. */
struct vstore {
	uint32_t values[256];
	char text[48];
	uint32_t text_len;
	int writes;
	/* streaming DOMAIN (2002h in the EDS, no RAM) */
	uint8_t stream[200];
	uint32_t stream_len;
	int chunks;
	bool stream_done;
};

static const struct co_od_limit v_limit = {.lo = {.u = 0}, .hi = {.u = 1000}};

static uint32_t v_info(const struct co_od_provider *p, struct co_od_info *info)
{
	(void)p;
	if (info->index == 0x2002) {
		info->dtype = CO_DTYPE_DOMAIN;
		info->access = CO_OD_ACCESS_RW;
		info->flags = CO_OD_F_STREAM;
		info->size = 200;
		return info->sub == 0 ? 0 : CO_SDO_AB_NO_SUB;
	}
	if (info->sub != 0) {
		return CO_SDO_AB_NO_SUB;
	}
	if (info->index == 0x3100) {
		info->dtype = CO_DTYPE_VISIBLE_STRING;
		info->access = CO_OD_ACCESS_RW;
		info->size = 40;
		return 0;
	}
	if (info->index == 0x3101) {
		info->dtype = CO_DTYPE_UNSIGNED8;
		info->access = CO_OD_ACCESS_RO;
		info->size = 1;
		return 0;
	}
	if (info->index > 0x30FF) {
		return CO_SDO_AB_NO_OBJECT;
	}
	info->dtype = CO_DTYPE_UNSIGNED32;
	info->access = CO_OD_ACCESS_RW;
	info->flags = CO_OD_F_MAP;
	info->size = 4;
	info->limit = &v_limit;
	return 0;
}

static uint32_t v_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	struct vstore *v = p->user_data;

	if (info->index == 0x3100) {
		return v->text_len;
	}
	return info->index == 0x2002 ? v->stream_len : info->size;
}

static uint32_t v_read(const struct co_od_provider *p, const struct co_od_info *info,
		       uint32_t offset, void *buf, size_t cap, size_t *len)
{
	struct vstore *v = p->user_data;
	uint8_t tmp[4];
	const uint8_t *src;
	uint32_t total;

	if (info->index == 0x3100) {
		src = (const uint8_t *)v->text;
		total = v->text_len;
	} else if (info->index == 0x2002) {
		src = v->stream;
		total = v->stream_len;
	} else {
		co_od_le_put(tmp, 4, info->index == 0x3101 ? 7U : v->values[info->index & 0xFF]);
		src = tmp;
		total = info->size;
	}
	*len = offset < total ? total - offset : 0;
	*len = *len > cap ? cap : *len;
	memcpy(buf, src + offset, *len);
	return 0;
}

static uint32_t v_write(const struct co_od_provider *p, const struct co_od_info *info,
			uint32_t offset, const void *data, size_t len, bool last)
{
	struct vstore *v = p->user_data;

	if (info->index == 0x2002) {
		v->chunks++;
		if (offset + len > sizeof(v->stream)) {
			return CO_SDO_AB_DATA_LONG;
		}
		memcpy(v->stream + offset, data, len);
		v->stream_len = offset + (uint32_t)len;
		v->stream_done = last;
		return 0;
	}
	v->writes++;
	zassert_equal(offset, 0);
	zassert_true(last);
	if (info->index == 0x3100) {
		memcpy(v->text, data, len);
		v->text_len = (uint32_t)len;
		return 0;
	}
	v->values[info->index & 0xFF] = (uint32_t)co_od_le_get(data, 4);
	return 0;
}

static const struct co_od_provider_api v_api = {
	.info = v_info,
	.length = v_length,
	.read = v_read,
	.write = v_write,
};

static struct vstore store;
static struct co_od_provider prov = {
	.api = &v_api, .index_first = 0x3000, .index_last = 0x31FF, .user_data = &store};
static struct co_od_provider stream_prov = {
	.api = &v_api, .index_first = 0x2002, .index_last = 0x2002, .user_data = &store};

#if defined(CONFIG_CANOPEN_OD_PROVIDERS)

static void v_before(void *f)
{
	fx_before(f);
	memset(&store, 0, sizeof(store));
	zassert_ok(co_od_provider_register(&fx.od, &prov));
	zassert_ok(co_od_provider_register(&fx.od, &stream_prov));
}

ZTEST(od_virtual, test_read_write_through_the_provider)
{
	uint32_t v;

	zassert_ok(co_od_set_u32(&fx.od, 0x3005, 0, 42, CO_OD_WRITER_SDO));
	zassert_equal(store.values[5], 42);
	zassert_ok(co_od_get_u32(&fx.od, 0x3005, 0, &v));
	zassert_equal(v, 42);
	zassert_ok(co_od_set_u32(&fx.od, 0x3006, 0, 7, CO_OD_WRITER_PDO));
}

ZTEST(od_virtual, test_same_checks)
{
	uint8_t b[4] = {0};
	uint32_t v;

	zassert_equal(co_od_set_u32(&fx.od, 0x3005, 0, 1001, CO_OD_WRITER_SDO),
		      CO_SDO_AB_VALUE_HIGH);
	zassert_equal(wr(&fx.od, 0x3005, 0, b, 2, CO_OD_WRITER_SDO), CO_SDO_AB_DATA_SHORT);
	zassert_equal(wr(&fx.od, 0x3101, 0, b, 1, CO_OD_WRITER_SDO), CO_SDO_AB_READONLY);
	zassert_equal(wr(&fx.od, 0x3100, 0, b, 1, CO_OD_WRITER_PDO), CO_SDO_AB_NO_MAP);
	zassert_equal(co_od_get_u32(&fx.od, 0x3005, 1, &v), CO_SDO_AB_NO_SUB);
	zassert_equal(co_od_get_u32(&fx.od, 0x3200, 0, &v), CO_SDO_AB_NO_OBJECT);
	zassert_equal(store.writes, 0, "a refused write reached the provider");
}

static uint32_t odd_only(struct co_od *od, struct co_od_req *req, void *user_data)
{
	(void)od;
	(*(int *)user_data)++;
	return (co_od_req_uint(req) & 1U) ? 0U : CO_SDO_AB_INVALID_VALUE;
}

ZTEST(od_virtual, test_same_hooks)
{
	int calls = 0;
	const struct co_od_hook h = {
		.index_first = 0x3000,
		.index_last = 0x30FF,
		.sub_first = 0,
		.sub_last = 0,
		.validate = odd_only,
		.user_data = &calls,
	};

	zassert_ok(co_od_hook_register(&fx.od, &h));
	zassert_equal(co_od_set_u32(&fx.od, 0x3010, 0, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE);
	zassert_equal(store.writes, 0);
	zassert_ok(co_od_set_u32(&fx.od, 0x3010, 0, 3, CO_OD_WRITER_SDO));
	zassert_equal(store.values[0x10], 3);
	zassert_equal(calls, 2);
}

ZTEST(od_virtual, test_large_value_staged_then_written_once)
{
	static const char text[] = "thirty-five characters of virtual!!";
	struct co_od_xfer x;
	char buf[48];

	zassert_ok(co_od_write_begin(&fx.od, &x, 0x3100, 0, 35, CO_OD_WRITER_SDO));
	for (uint32_t off = 0; off < 35; off += 7) {
		zassert_ok(co_od_write_chunk(&fx.od, &x, off, text + off, 7, off + 7 == 35));
		zassert_equal(store.writes, off + 7 == 35 ? 1 : 0);
	}
	zassert_equal(rd(&fx.od, 0x3100, 0, buf, sizeof(buf)), 35);
	zassert_mem_equal(buf, text, 35);
}

ZTEST(od_virtual, test_streamed_domain)
{
	struct co_od_xfer x;
	uint8_t chunk[7];
	uint8_t back[200];

	/* 2002h is a DOMAIN of the EDS without RAM: its provider streams it. */
	zassert_ok(co_od_write_begin(&fx.od, &x, 0x2002, 0, 0, CO_OD_WRITER_SDO));
	for (uint32_t off = 0; off < 140; off += 7) {
		for (int i = 0; i < 7; i++) {
			chunk[i] = (uint8_t)(off + i);
		}
		zassert_ok(co_od_write_chunk(&fx.od, &x, off, chunk, 7, off + 7 == 140));
	}
	zassert_equal(store.chunks, 20);
	zassert_true(store.stream_done);
	zassert_equal(rd(&fx.od, 0x2002, 0, back, sizeof(back)), 140);
	for (int i = 0; i < 140; i++) {
		zassert_equal(back[i], (uint8_t)i);
	}
}

ZTEST(od_virtual, test_registration)
{
	struct co_od_provider overlap = prov;
	struct co_od_provider bad = prov;

	overlap.index_first = 0x31FF;
	overlap.index_last = 0x3300;
	zassert_equal(co_od_provider_register(&fx.od, &overlap), -EEXIST);
	bad.api = NULL;
	zassert_equal(co_od_provider_register(&fx.od, &bad), -EINVAL);
	static struct co_od_provider third;
	static struct co_od_provider fourth;

	third = prov;
	third.index_first = third.index_last = 0x4000;
	zassert_ok(co_od_provider_register(&fx.od, &third));
	fourth = prov;
	fourth.index_first = fourth.index_last = 0x4001;
	zassert_equal(co_od_provider_register(&fx.od, &fourth), -ENOSPC);
	/* The dictionary's own objects win over a provider's range. */
	struct co_od_info info;

	zassert_ok(co_od_find(&fx.od, 0x2001, 1, &info));
	zassert_not_null(info.desc);
}

ZTEST_SUITE(od_virtual, NULL, NULL, v_before, NULL, NULL);

#else /* !CONFIG_CANOPEN_OD_PROVIDERS */

/* Built without providers: registering one says so, and their objects do not exist. */
ZTEST(od_no_providers, test_registration_refused)
{
	struct co_od_provider bad = prov;

	bad.api = NULL;
	zassert_equal(co_od_provider_register(&fx.od, &bad), -EINVAL);
	zassert_equal(co_od_provider_register(&fx.od, &prov), -ENOTSUP);
	zassert_equal(co_od_provider_register(&fx.od, &stream_prov), -ENOTSUP);
}

ZTEST(od_no_providers, test_no_provider_objects)
{
	struct co_od_info info;
	uint32_t v = 5;

	(void)co_od_provider_register(&fx.od, &prov);
	zassert_equal(co_od_find(&fx.od, 0x3000, 0, &info), CO_SDO_AB_NO_OBJECT);
	zassert_equal(co_od_write(&fx.od, 0x3000, 0, &v, sizeof(v), CO_OD_WRITER_SDO),
		      CO_SDO_AB_NO_OBJECT);
	/* 2002h, a DOMAIN of the EDS without RAM, is a dictionary object without data. */
	zassert_ok(co_od_find(&fx.od, 0x2002, 0, &info));
	zassert_is_null(info.prov);
	zassert_not_equal(co_od_write(&fx.od, 0x2002, 0, &v, 1, CO_OD_WRITER_SDO), 0U);
}

ZTEST_SUITE(od_no_providers, NULL, NULL, fx_before, NULL, NULL);

#endif /* CONFIG_CANOPEN_OD_PROVIDERS */
