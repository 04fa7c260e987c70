/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/storage.h>

#include "st_od.h"

#define MEDIUM_SIZE 2048

/* A medium wrapper that stops writing after `budget` bytes: power cut, kill, full disk. */
struct cut_be {
	struct co_storage_backend be;
	const struct co_storage_backend *inner;
	long budget; /* -1: unlimited */
	long written;
	int err; /* error returned once cut */
	int fail_sync;
};

static int cut_read(const struct co_storage_backend *be, uint32_t off, void *buf, size_t len)
{
	const struct cut_be *c = (const struct cut_be *)be;

	return c->inner->api->read(c->inner, off, buf, len);
}

static int cut_write(const struct co_storage_backend *be, uint32_t off, const void *buf, size_t len)
{
	struct cut_be *c = (struct cut_be *)be;

	if (c->budget >= 0 && c->written + (long)len > c->budget) {
		size_t part = (size_t)(c->budget - c->written);

		if (part > 0) {
			(void)c->inner->api->write(c->inner, off, buf, part);
		}
		c->written = c->budget;
		return c->err;
	}
	c->written += (long)len;
	return c->inner->api->write(c->inner, off, buf, len);
}

static int cut_sync(const struct co_storage_backend *be)
{
	const struct cut_be *c = (const struct cut_be *)be;

	return c->fail_sync ? -EIO : c->inner->api->sync(c->inner);
}

static uint32_t cut_size(const struct co_storage_backend *be)
{
	const struct cut_be *c = (const struct cut_be *)be;

	return c->inner->api->size(c->inner);
}

static const struct co_storage_backend_api cut_api = {cut_read, cut_write, cut_sync, cut_size};

static void cut_init(struct cut_be *c, const struct co_storage_backend *inner, long budget)
{
	c->be.api = &cut_api;
	c->inner = inner;
	c->budget = budget;
	c->written = 0;
	c->err = -EIO;
	c->fail_sync = 0;
}

/* One device: dictionary, RAM, storage on a medium. */
struct dev {
	struct co_od od;
	struct st_od_ram ram;
	struct co_storage st;
};

static uint8_t medium[MEDIUM_SIZE];
static struct co_storage_ram ram_be;
static struct dev d1;
static struct dev d2;

/* Power-on: fresh RAM, storage attached, Reset Node (application, then communication). */
static void boot(struct dev *d, const struct co_storage_backend *be, uint8_t node_id)
{
	memset(d, 0, sizeof(*d));
	zassert_ok(co_od_init(&d->od, &st_od_def, &d->ram, node_id));
	zassert_ok(co_storage_init(&d->st, &d->od, be));
	co_od_reset_app(&d->od);
	co_od_reset_comm(&d->od);
}

static uint32_t sdo_u32(struct dev *d, uint16_t index, uint8_t sub, uint32_t v)
{
	uint8_t b[4];

	co_od_le_put(b, 4, v);
	return co_od_write(&d->od, index, sub, b, 4, CO_OD_WRITER_SDO);
}

/* Parameters of each group changed to generation g (1, 2, 3 ...). */
static void set_generation(struct dev *d, uint32_t g)
{
	char text[32];

	zassert_ok(co_od_set_u16(&d->od, 0x1017, 0, (uint16_t)(100 * g), CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u32(&d->od, 0x1016, 1, 0x00050000U + g, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u32(&d->od, 0x1600, 2, 0x60000700U + g, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_i32(&d->od, 0x2003, 2, (int32_t)(-7 * (int32_t)g), CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u16(&d->od, 0x2001, 3, (uint16_t)(0x1000 + g), CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_u32(&d->od, 0x6000, 7, 0xA0000000U + g, CO_OD_WRITER_SDO));
	zassert_ok(co_od_set_f64(&d->od, 0x6000, 0x10, 0.5 * g, CO_OD_WRITER_SDO));
	snprintf(text, sizeof(text), "generation %u of the text", g);
	zassert_ok(co_od_write(&d->od, 0x6000, 9, text, strlen(text), CO_OD_WRITER_SDO));
}

/* Every stored value, concatenated in wire format. */
static size_t fingerprint(struct dev *d, uint8_t *out, size_t cap)
{
	size_t n = 0;

	for (uint16_t i = 0; i < st_od_def.n_entries; i++) {
		const struct co_od_entry *e = &st_od_def.entries[i];

		for (uint16_t s = 0; s < e->n_subs; s++) {
			const struct co_od_sub *sd = &st_od_def.subs[e->first + s];
			size_t len;

			if (!(sd->flags & CO_OD_F_STORE)) {
				continue;
			}
			zassert_true(n + 2 <= cap);
			out[n++] = (uint8_t)e->index;
			out[n++] = sd->sub;
			zassert_ok(co_od_read(&d->od, e->index, sd->sub, 0, out + n, cap - n, &len,
					      CO_OD_WRITER_APP));
			n += len;
		}
	}
	return n;
}

static void before(void *f)
{
	(void)f;
	memset(medium, 0xFF, sizeof(medium));
	zassert_ok(co_storage_ram_init(&ram_be, medium, sizeof(medium)));
}

ZTEST(storage, test_save_signature_and_restore)
{
	uint16_t hb;
	uint32_t v;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	zassert_equal(sdo_u32(&d1, 0x1010, 1, 0x12345678), CO_SDO_AB_DATA_XFER);
	zassert_equal(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_LOAD), CO_SDO_AB_DATA_XFER);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	/* 1010h keeps reading "save on command supported". */
	zassert_ok(co_od_get_u32(&d1.od, 0x1010, 1, &v));
	zassert_equal(v, 1);
	set_generation(&d1, 2);
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 100);

	static uint8_t a[1024];
	static uint8_t b[1024];
	size_t na;
	size_t nb;

	set_generation(&d1, 1);
	na = fingerprint(&d1, a, sizeof(a));
	nb = fingerprint(&d2, b, sizeof(b));
	zassert_equal(na, nb);
	zassert_mem_equal(a, b, na);
}

ZTEST(storage, test_groups_are_separate)
{
	uint16_t hb;
	int32_t i32;
	uint32_t u32;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 3);
	/* Save communication only. */
	zassert_ok(sdo_u32(&d1, 0x1010, 2, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 300);
	zassert_ok(co_od_get_i32(&d2.od, 0x2003, 2, &i32));
	zassert_equal(i32, 2, "manufacturer group was not saved");
	zassert_ok(co_od_get_u32(&d2.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xDEADBEEF, "application group was not saved");
	/* Now application only: communication stays as saved before. */
	set_generation(&d1, 4);
	zassert_ok(sdo_u32(&d1, 0x1010, 3, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 300);
	zassert_ok(co_od_get_u32(&d2.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xA0000004);
	zassert_ok(co_od_get_i32(&d2.od, 0x2003, 2, &i32));
	zassert_equal(i32, 2);
	/* Manufacturer (sub 4). */
	zassert_ok(sdo_u32(&d1, 0x1010, 4, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_i32(&d2.od, 0x2003, 2, &i32));
	zassert_equal(i32, -28);
}

ZTEST(storage, test_restore_defaults_at_next_reset)
{
	uint16_t hb;
	uint32_t u32;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	zassert_equal(sdo_u32(&d1, 0x1011, 1, CO_STORAGE_SIGNATURE_SAVE), CO_SDO_AB_DATA_XFER);
	/* Restore application defaults: nothing changes until a reset. */
	zassert_ok(sdo_u32(&d1, 0x1011, 3, CO_STORAGE_SIGNATURE_LOAD));
	zassert_ok(co_od_get_u32(&d1.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xA0000001);
	/* Reset Communication does not touch the application area. */
	co_od_reset_comm(&d1.od);
	zassert_ok(co_od_get_u32(&d1.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xA0000001);
	zassert_ok(co_od_get_u16(&d1.od, 0x1017, 0, &hb));
	zassert_equal(hb, 100);
	/* Reset Application brings the defaults. */
	co_od_reset_app(&d1.od);
	zassert_ok(co_od_get_u32(&d1.od, 0x6000, 7, &u32));
	zassert_equal(u32, 0xDEADBEEF);
	/* All groups. */
	zassert_ok(sdo_u32(&d1, 0x1011, 1, CO_STORAGE_SIGNATURE_LOAD));
	zassert_ok(co_od_get_u16(&d1.od, 0x1017, 0, &hb));
	zassert_equal(hb, 100);
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 0);
}

static void count_storage(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	(void)od;
	if (req->writer == CO_OD_WRITER_STORAGE) {
		(*(int *)user_data)++;
	}
}

ZTEST(storage, test_restore_goes_through_the_hooks)
{
	int restored = 0;
	const struct co_od_hook h = {
		.index_first = 0x1017,
		.index_last = 0x1017,
		.sub_first = 0,
		.sub_last = 0,
		.notify = count_storage,
		.user_data = &restored,
	};

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 2);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	zassert_ok(co_od_hook_register(&d1.od, &h));
	co_od_reset_comm(&d1.od);
	zassert_equal(restored, 1);
}

ZTEST(storage, test_nodeid_relative_values_follow_the_node_id)
{
	uint32_t v;

	boot(&d1, &ram_be.be, 5);
	/* 1400h:1 keeps its $NODEID default, 1800h:1 is set to an absolute value. */
	zassert_ok(co_od_set_u32(&d1.od, 0x1800, 1, 0x80000185, CO_OD_WRITER_SDO));
	zassert_ok(sdo_u32(&d1, 0x1010, 2, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d2, &ram_be.be, 9);
	zassert_ok(co_od_get_u32(&d2.od, 0x1400, 1, &v));
	zassert_equal(v, 0x209);
	zassert_ok(co_od_get_u32(&d2.od, 0x1800, 1, &v));
	zassert_equal(v, 0x80000185);
}

ZTEST(storage, test_backend_failure_is_a_hardware_abort)
{
	struct cut_be c;
	uint16_t hb;

	cut_init(&c, &ram_be.be, -1);
	boot(&d1, &c.be, 5);
	set_generation(&d1, 1);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	set_generation(&d1, 2);
	c.fail_sync = 1;
	zassert_equal(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE), CO_SDO_AB_HW);
	c.fail_sync = 0;
	c.budget = c.written + 10;
	zassert_equal(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE), CO_SDO_AB_HW);
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 100);
}

/* CiA 301 §7.5.2.13-14: anything but the signature is refused with 08000020h, on every
 * sub-index of both objects, and nothing is stored. */
ZTEST(storage, test_a_wrong_signature_is_refused_with_08000020h)
{
	uint16_t hb;
	uint32_t v;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	for (uint8_t sub = 1; sub <= 4; sub++) {
		zassert_equal(sdo_u32(&d1, 0x1010, sub, 5), CO_SDO_AB_DATA_XFER);
		zassert_equal(sdo_u32(&d1, 0x1010, sub, CO_STORAGE_SIGNATURE_LOAD),
			      CO_SDO_AB_DATA_XFER);
		zassert_equal(sdo_u32(&d1, 0x1011, sub, 5), CO_SDO_AB_DATA_XFER);
		zassert_equal(sdo_u32(&d1, 0x1011, sub, CO_STORAGE_SIGNATURE_SAVE),
			      CO_SDO_AB_DATA_XFER);
		zassert_ok(co_od_get_u32(&d1.od, 0x1010, sub, &v));
		zassert_equal(v, 1, "still 'saves on command'");
		zassert_ok(co_od_get_u32(&d1.od, 0x1011, sub, &v));
		zassert_equal(v, 1, "still 'restores defaults'");
	}
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 0, "nothing was stored");
}

/* A node without medium says so: 1010h/1011h read 0, at every reset too, and a save or a
 * restore is refused with 08000020h, with the right signature as well. */
ZTEST(storage, test_a_node_without_medium_says_so)
{
	uint32_t v;

	memset(&d1, 0, sizeof(d1));
	zassert_ok(co_od_init(&d1.od, &st_od_def, &d1.ram, 5));
	zassert_ok(co_storage_init_absent(&d1.st, &d1.od));
	for (int boot_no = 0; boot_no < 2; boot_no++) {
		co_od_reset_app(&d1.od);
		co_od_reset_comm(&d1.od);
		for (uint8_t sub = 1; sub <= 4; sub++) {
			zassert_ok(co_od_get_u32(&d1.od, 0x1010, sub, &v));
			zassert_equal(v, 0, "1010h:%u does not save", sub);
			zassert_ok(co_od_get_u32(&d1.od, 0x1011, sub, &v));
			zassert_equal(v, 0, "1011h:%u does not restore", sub);
			zassert_equal(sdo_u32(&d1, 0x1010, sub, CO_STORAGE_SIGNATURE_SAVE),
				      CO_SDO_AB_DATA_XFER);
			zassert_equal(sdo_u32(&d1, 0x1011, sub, CO_STORAGE_SIGNATURE_LOAD),
				      CO_SDO_AB_DATA_XFER);
			zassert_equal(sdo_u32(&d1, 0x1010, sub, 5), CO_SDO_AB_DATA_XFER);
			zassert_ok(co_od_get_u32(&d1.od, 0x1010, sub, &v));
			zassert_equal(v, 0, "a refused write changes nothing");
		}
	}
	zassert_equal(co_storage_save(&d1.st, CO_OD_GROUP_ALL), -ENODEV);
	zassert_equal(co_storage_clear(&d1.st, CO_OD_GROUP_ALL), -ENODEV);
	zassert_ok(co_storage_restore(&d1.st, CO_OD_GROUP_ALL));
	zassert_equal(co_storage_init_absent(NULL, &d1.od), -EINVAL);
}

/* Local control (the application) may forbid requests for a while: 08000021h, nothing
 * stored; a wrong signature stays 08000020h; the application itself may still save. */
ZTEST(storage, test_local_control_refuses_requests_with_08000021h)
{
	uint16_t hb;
	uint32_t v;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	co_storage_set_locked(&d1.st, true);
	zassert_equal(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE), CO_SDO_AB_DATA_LOC_CTRL);
	zassert_equal(sdo_u32(&d1, 0x1011, 1, CO_STORAGE_SIGNATURE_LOAD), CO_SDO_AB_DATA_LOC_CTRL);
	zassert_equal(sdo_u32(&d1, 0x1010, 1, 5), CO_SDO_AB_DATA_XFER);
	zassert_ok(co_od_get_u32(&d1.od, 0x1010, 1, &v));
	zassert_equal(v, 1, "the node still saves on command");
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 0, "nothing was stored");
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL), "the application's own save");
	co_storage_set_locked(&d1.st, false);
	set_generation(&d1, 2);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d2, &ram_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 200);
}

ZTEST(storage, test_image_too_large)
{
	static uint8_t tiny[128];
	struct co_storage_ram small;

	zassert_ok(co_storage_ram_init(&small, tiny, sizeof(tiny)));
	boot(&d1, &small.be, 5);
	zassert_equal(co_storage_save(&d1.st, CO_OD_GROUP_ALL), -ENOSPC);
	zassert_equal(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE), CO_SDO_AB_HW);
}

ZTEST(storage, test_corrupted_medium_gives_defaults)
{
	uint16_t hb;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	/* One flipped bit anywhere in the only image: it must not be used. */
	medium[40] ^= 0x10;
	boot(&d2, &ram_be.be, 5);
	zassert_equal(d2.st.active, -1);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 0);
}

static uint32_t refuse_storage(struct co_od *od, struct co_od_req *req, void *user_data)
{
	(void)od;
	(void)user_data;
	return req->writer == CO_OD_WRITER_STORAGE ? CO_SDO_AB_INVALID_VALUE : 0U;
}

ZTEST(storage, test_refused_stored_values_are_skipped)
{
	const struct co_od_hook refuse = {
		.index_first = 0x1017,
		.index_last = 0x1017,
		.sub_first = 0,
		.sub_last = 0,
		.validate = refuse_storage,
	};
	uint16_t hb;
	uint32_t u32;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	memset(&d2, 0, sizeof(d2));
	zassert_ok(co_od_init(&d2.od, &st_od_def, &d2.ram, 5));
	zassert_ok(co_od_hook_register(&d2.od, &refuse));
	zassert_ok(co_storage_init(&d2.st, &d2.od, &ram_be.be));
	co_od_reset_comm(&d2.od);
	zassert_equal(d2.st.skipped, 1);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 0);
	zassert_ok(co_od_get_u32(&d2.od, 0x1016, 1, &u32));
	zassert_equal(u32, 0x00050001);
}

ZTEST(storage, test_two_nodes_two_media)
{
	static uint8_t other[MEDIUM_SIZE];
	static struct co_storage_ram other_be;
	uint16_t hb;

	zassert_ok(co_storage_ram_init(&other_be, other, sizeof(other)));
	memset(other, 0xFF, sizeof(other));
	boot(&d1, &ram_be.be, 5);
	boot(&d2, &other_be.be, 6);
	set_generation(&d1, 1);
	set_generation(&d2, 2);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	zassert_ok(sdo_u32(&d2, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	boot(&d1, &ram_be.be, 5);
	boot(&d2, &other_be.be, 6);
	zassert_ok(co_od_get_u16(&d1.od, 0x1017, 0, &hb));
	zassert_equal(hb, 100);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 200);
}

ZTEST_SUITE(storage, NULL, NULL, before, NULL, NULL);

/* ---------------------------------------------------------------------------------------- */
/* Saves cut off at every byte */

static uint8_t snap[MEDIUM_SIZE];
static uint8_t fp_old[1024];
static uint8_t fp_new[1024];
static uint8_t fp[1024];

static void medium_copy(const struct co_storage_backend *be, uint8_t *to, bool save)
{
	if (save) {
		zassert_ok(be->api->read(be, 0, to, MEDIUM_SIZE));
	} else {
		zassert_ok(be->api->write(be, 0, to, MEDIUM_SIZE));
	}
}

/*
 * Three generations: 1 and 2 saved (both slots hold an image), then the save of generation 3
 * (all groups, or only `mask`) is cut after every possible number of bytes, followed by a
 * power-on. The restored parameters must be exactly generation 2's, or, once every byte is
 * written, exactly generation 3's: never generation 1, never a mix.
 */
static void cut_everywhere(const struct co_storage_backend *inner, uint32_t mask, int err)
{
	struct cut_be c;
	size_t n_old;
	size_t n_new;
	long total;
	long cuts = 0;

	boot(&d1, inner, 5);
	set_generation(&d1, 1);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	set_generation(&d1, 2);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	boot(&d2, inner, 5);
	n_old = fingerprint(&d2, fp_old, sizeof(fp_old));
	medium_copy(inner, snap, true);

	/* The complete save, to learn its size and its result. */
	set_generation(&d1, 3);
	cut_init(&c, inner, -1);
	zassert_ok(co_storage_init(&d1.st, &d1.od, &c.be));
	zassert_ok(co_storage_save(&d1.st, mask));
	total = c.written;
	boot(&d2, inner, 5);
	n_new = fingerprint(&d2, fp_new, sizeof(fp_new));
	zassert_true(n_new != n_old || memcmp(fp_old, fp_new, n_old) != 0);

	for (long cut = 0; cut <= total; cut++) {
		medium_copy(inner, snap, false);
		cut_init(&c, inner, cut);
		c.err = err;
		zassert_ok(co_storage_init(&d1.st, &d1.od, &c.be));
		int r = co_storage_save(&d1.st, mask);

		zassert_equal(r == 0, cut == total, "cut %ld of %ld: result %d", cut, total, r);
		boot(&d2, inner, 5);
		zassert_equal(d2.st.skipped, 0);
		size_t n = fingerprint(&d2, fp, sizeof(fp));

		if (cut < total) {
			zassert_true(n == n_old && memcmp(fp, fp_old, n) == 0,
				     "cut at byte %ld of %ld: not the old parameters", cut, total);
		} else {
			zassert_true(n == n_new && memcmp(fp, fp_new, n) == 0,
				     "complete save: not the new parameters");
		}
		cuts++;
	}
	zassert_equal(cuts, total + 1);
	zassert_true(total > 100, "the image should be a few hundred bytes, is %ld", total);
}

ZTEST(storage_cut, test_ram_medium_all_groups)
{
	cut_everywhere(&ram_be.be, CO_OD_GROUP_ALL, -EIO);
}

ZTEST(storage_cut, test_ram_medium_one_group_kept_others_copied)
{
	cut_everywhere(&ram_be.be, CO_OD_GROUP_BIT(CO_OD_GROUP_COMM), -EIO);
}

ZTEST(storage_cut, test_ram_medium_restore_defaults)
{
	/* 1011h "load" also rewrites the image: a cut must not lose the other groups. */
	struct cut_be c;
	long total;

	boot(&d1, &ram_be.be, 5);
	set_generation(&d1, 1);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	set_generation(&d1, 2);
	zassert_ok(co_storage_save(&d1.st, CO_OD_GROUP_ALL));
	boot(&d2, &ram_be.be, 5);
	size_t n_old = fingerprint(&d2, fp_old, sizeof(fp_old));

	medium_copy(&ram_be.be, snap, true);
	cut_init(&c, &ram_be.be, -1);
	zassert_ok(co_storage_init(&d1.st, &d1.od, &c.be));
	zassert_ok(co_storage_clear(&d1.st, CO_OD_GROUP_BIT(CO_OD_GROUP_APP)));
	total = c.written;
	for (long cut = 0; cut < total; cut++) {
		medium_copy(&ram_be.be, snap, false);
		cut_init(&c, &ram_be.be, cut);
		zassert_ok(co_storage_init(&d1.st, &d1.od, &c.be));
		zassert_not_equal(co_storage_clear(&d1.st, CO_OD_GROUP_BIT(CO_OD_GROUP_APP)), 0);
		boot(&d2, &ram_be.be, 5);
		size_t n = fingerprint(&d2, fp, sizeof(fp));

		zassert_true(n == n_old && memcmp(fp, fp_old, n) == 0, "cut at %ld", cut);
	}
}

#ifdef CONFIG_CANOPEN_STORAGE_FILE
static struct co_storage_file file_be;

static void file_before(void *f)
{
	static uint8_t erased[MEDIUM_SIZE];

	before(f);
	/* The file lives in the working directory (the build folder under the runner). */
	zassert_ok(co_storage_file_open(&file_be, "canopen_storage_test.bin", MEDIUM_SIZE));
	memset(erased, 0xFF, sizeof(erased));
	zassert_ok(file_be.be.api->write(&file_be.be, 0, erased, sizeof(erased)));
}

static void file_after(void *f)
{
	(void)f;
	co_storage_file_close(&file_be);
}

ZTEST(storage_file, test_file_medium_power_cut)
{
	cut_everywhere(&file_be.be, CO_OD_GROUP_ALL, -EIO);
}

ZTEST(storage_file, test_file_medium_disk_full)
{
	cut_everywhere(&file_be.be, CO_OD_GROUP_BIT(CO_OD_GROUP_APP), -ENOSPC);
}

ZTEST(storage_file, test_file_survives_reopen)
{
	uint16_t hb;

	boot(&d1, &file_be.be, 5);
	set_generation(&d1, 7);
	zassert_ok(sdo_u32(&d1, 0x1010, 1, CO_STORAGE_SIGNATURE_SAVE));
	co_storage_file_close(&file_be);
	zassert_ok(co_storage_file_open(&file_be, "canopen_storage_test.bin", MEDIUM_SIZE));
	boot(&d2, &file_be.be, 5);
	zassert_ok(co_od_get_u16(&d2.od, 0x1017, 0, &hb));
	zassert_equal(hb, 700);
}

ZTEST_SUITE(storage_file, NULL, NULL, file_before, file_after, NULL);
#endif

ZTEST_SUITE(storage_cut, NULL, NULL, before, NULL, NULL);
