/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Object dictionary: data types, values in their C storage and the instance life cycle.
 *
 * Values are kept in their C storage types (types.h) in the node's RAM block or the ROM
 * block; every byte-stream access converts to and from the CiA wire format (little endian)
 * with the helpers here, so the rest of the stack never casts raw OD memory. Lookup is in
 * od_find.c, hooks in od_hooks.c, whole-value access in od_access.c, chunked writes in
 * od_xfer.c (od_internal.h between them).
 */

#include <errno.h>
#include <string.h>

#include "od_internal.h"

/* ---------------------------------------------------------------------------------------- */
/* Data types */

uint32_t co_dtype_size(uint8_t dtype)
{
	switch (dtype) {
#define CO_OD_SIZE_CASE_(name, idx, size, cls, ctype)                                              \
	case idx:                                                                                  \
		return size;
		CO_DTYPE_TABLE(CO_OD_SIZE_CASE_)
#undef CO_OD_SIZE_CASE_
	default:
		return 0U;
	}
}

enum co_dtype_class co_dtype_class(uint8_t dtype)
{
	switch (dtype) {
#define CO_OD_CLASS_CASE_(name, idx, size, cls, ctype)                                             \
	case idx:                                                                                  \
		return CO_DTYPE_CLASS_##cls;
		CO_DTYPE_TABLE(CO_OD_CLASS_CASE_)
#undef CO_OD_CLASS_CASE_
	default:
		return CO_DTYPE_CLASS_NONE;
	}
}

const char *co_dtype_name(uint8_t dtype)
{
	switch (dtype) {
#define CO_OD_NAME_CASE_(name, idx, size, cls, ctype)                                              \
	case idx:                                                                                  \
		return #name;
		CO_DTYPE_TABLE(CO_OD_NAME_CASE_)
#undef CO_OD_NAME_CASE_
	default:
		return NULL;
	}
}

size_t co_od_csize(uint8_t dtype)
{
	switch (dtype) {
#define CO_OD_CSIZE_CASE_(name, idx, size, cls, ctype)                                             \
	case idx:                                                                                  \
		return (size) == 0 ? 0 : sizeof(ctype);
		CO_DTYPE_TABLE(CO_OD_CSIZE_CASE_)
#undef CO_OD_CSIZE_CASE_
	default:
		return 0;
	}
}

uint64_t co_od_load_native(const void *mem, size_t csize)
{
	switch (csize) {
	case 1: {
		uint8_t v;

		memcpy(&v, mem, 1);
		return v;
	}
	case 2: {
		uint16_t v;

		memcpy(&v, mem, 2);
		return v;
	}
	case 4: {
		uint32_t v;

		memcpy(&v, mem, 4);
		return v;
	}
	default: {
		uint64_t v;

		memcpy(&v, mem, 8);
		return v;
	}
	}
}

static void store_native(void *mem, size_t csize, uint64_t v)
{
	switch (csize) {
	case 1: {
		uint8_t x = (uint8_t)v;

		memcpy(mem, &x, 1);
		break;
	}
	case 2: {
		uint16_t x = (uint16_t)v;

		memcpy(mem, &x, 2);
		break;
	}
	case 4: {
		uint32_t x = (uint32_t)v;

		memcpy(mem, &x, 4);
		break;
	}
	default:
		memcpy(mem, &v, 8);
		break;
	}
}

/* Sign-extend the low `bytes` bytes of v. */
uint64_t co_od_sign_extend(uint64_t v, uint32_t bytes)
{
	if (bytes >= 8U) {
		return v;
	}
	uint64_t sign = (uint64_t)1 << (8U * bytes - 1U);
	uint64_t mask = ((uint64_t)1 << (8U * bytes)) - 1U;

	v &= mask;
	return (v ^ sign) - sign;
}

void co_od_encode_fixed(uint8_t dtype, const void *mem, uint8_t out[8])
{
	uint32_t size = co_dtype_size(dtype);

	memset(out, 0, 8);
	if (co_dtype_class(dtype) == CO_DTYPE_CLASS_TIME) {
		struct co_time t;

		memcpy(&t, mem, sizeof(t));
		co_od_le_put(out, 4, t.ms);
		co_od_le_put(out + 4, 2, t.days);
		return;
	}
	/* Integers, BOOLEAN and REAL: the C object's bits, little endian. */
	co_od_le_put(out, size, co_od_load_native(mem, co_od_csize(dtype)));
}

void co_od_decode_fixed(uint8_t dtype, const uint8_t *in, void *mem)
{
	uint32_t size = co_dtype_size(dtype);
	enum co_dtype_class cls = co_dtype_class(dtype);

	if (cls == CO_DTYPE_CLASS_TIME) {
		struct co_time t = {
			.ms = (uint32_t)co_od_le_get(in, 4),
			.days = (uint16_t)co_od_le_get(in + 4, 2),
		};

		memcpy(mem, &t, sizeof(t));
		return;
	}
	uint64_t v = co_od_le_get(in, size);

	if (cls == CO_DTYPE_CLASS_INT) {
		v = co_od_sign_extend(v, size);
	}
	store_native(mem, co_od_csize(dtype), v);
}

/* ---------------------------------------------------------------------------------------- */
/* Descriptors */

const struct co_od_nodeid *co_od_nodeid_of(const struct co_od_def *def, uint32_t pos)
{
	for (uint16_t i = 0; i < def->n_nodeid; i++) {
		if (def->nodeid[i].sub == pos) {
			return &def->nodeid[i];
		}
	}
	return NULL;
}

const uint8_t *co_od_mem(const struct co_od_def *def, const uint8_t *ram,
			 const struct co_od_sub *desc)
{
	const uint8_t *base = (desc->flags & CO_OD_F_ROM) ? (const uint8_t *)def->rom : ram;

	return base + desc->offset;
}

bool co_od_has_storage(const struct co_od_sub *desc)
{
	return !(co_dtype_class(desc->dtype) == CO_DTYPE_CLASS_DOMAIN && desc->size == 0U);
}

uint32_t co_od_mem_length(const struct co_od_sub *desc, const uint8_t *mem)
{
	switch (co_dtype_class(desc->dtype)) {
	case CO_DTYPE_CLASS_VSTR: {
		uint32_t n = 0;

		while (n < desc->size && mem[n] != 0U) {
			n++;
		}
		return n;
	}
	case CO_DTYPE_CLASS_USTR: {
		uint32_t n = 0;

		while (n < desc->size / 2U) {
			uint16_t u;

			memcpy(&u, mem + 2U * n, 2);
			if (u == 0U) {
				break;
			}
			n++;
		}
		return 2U * n;
	}
	case CO_DTYPE_CLASS_DOMAIN: {
		uint32_t len;

		if (!co_od_has_storage(desc)) {
			return 0;
		}
		memcpy(&len, mem, sizeof(len));
		return len <= desc->size ? len : desc->size;
	}
	default:
		return desc->size;
	}
}

size_t co_od_mem_read(const struct co_od_sub *desc, const uint8_t *mem, uint32_t offset,
		      uint8_t *buf, size_t cap)
{
	uint32_t total = co_od_mem_length(desc, mem);

	if (offset >= total) {
		return 0;
	}
	size_t n = total - offset;

	if (n > cap) {
		n = cap;
	}
	switch (co_dtype_class(desc->dtype)) {
	case CO_DTYPE_CLASS_VSTR:
	case CO_DTYPE_CLASS_OSTR:
		memcpy(buf, mem + offset, n);
		break;
	case CO_DTYPE_CLASS_DOMAIN:
		memcpy(buf, mem + sizeof(uint32_t) + offset, n);
		break;
	case CO_DTYPE_CLASS_USTR:
		for (size_t i = 0; i < n; i++) {
			uint32_t b = offset + (uint32_t)i;
			uint16_t u;

			memcpy(&u, mem + 2U * (b / 2U), 2);
			buf[i] = (uint8_t)(u >> (8U * (b % 2U)));
		}
		break;
	default: {
		uint8_t tmp[8];

		co_od_encode_fixed(desc->dtype, mem, tmp);
		memcpy(buf, tmp + offset, n);
		break;
	}
	}
	return n;
}

void co_od_mem_commit(const struct co_od_sub *desc, uint8_t *mem, const uint8_t *data, size_t len)
{
	switch (co_dtype_class(desc->dtype)) {
	case CO_DTYPE_CLASS_VSTR:
		/* One byte more than the capacity keeps the value a C string. */
		memcpy(mem, data, len);
		memset(mem + len, 0, desc->size + 1U - len);
		break;
	case CO_DTYPE_CLASS_OSTR:
		memcpy(mem, data, len);
		break;
	case CO_DTYPE_CLASS_USTR: {
		size_t units = desc->size / 2U + 1U;

		for (size_t i = 0; i < units; i++) {
			uint16_t u = 0;

			if (2U * i + 1U < len) {
				u = (uint16_t)co_od_le_get(data + 2U * i, 2);
			}
			memcpy(mem + 2U * i, &u, 2);
		}
		break;
	}
	case CO_DTYPE_CLASS_DOMAIN: {
		uint32_t l = (uint32_t)len;

		memcpy(mem + sizeof(uint32_t), data, len);
		memcpy(mem, &l, sizeof(l));
		break;
	}
	default:
		co_od_decode_fixed(desc->dtype, data, mem);
		break;
	}
}

/* ---------------------------------------------------------------------------------------- */
/* Instance */

uint32_t co_od_nid(const struct co_od *od)
{
	return (od->node_id >= 1U && od->node_id <= 127U) ? od->node_id : 0U;
}

static void apply_nodeid(struct co_od *od, uint16_t first, uint16_t last)
{
	const struct co_od_def *def = od->def;

	for (uint16_t i = 0; i < def->n_nodeid; i++) {
		const struct co_od_nodeid *n = &def->nodeid[i];
		const struct co_od_sub *desc = &def->subs[n->sub];
		uint8_t wire[8];

		if (n->index < first || n->index > last || (desc->flags & CO_OD_F_ROM)) {
			continue;
		}
		co_od_le_put(wire, 8, (uint64_t)(n->base + (int64_t)co_od_nid(od)));
		co_od_decode_fixed(desc->dtype, wire, od->ram + desc->offset);
	}
}

int co_od_init(struct co_od *od, const struct co_od_def *def, void *ram, uint8_t node_id)
{
	if (od == NULL || def == NULL || ram == NULL || def->max_staged > CO_OD_SCRATCH_SIZE) {
		return -EINVAL;
	}
	memset(od, 0, sizeof(*od));
	od->def = def;
	od->ram = ram;
	od->node_id = node_id;
	od->hook_gen = 1U;
	od->hook_next_seq = 1U;
	/* Every entry starts without hooks (link 0: none). */
	od->hook_heads = (uint16_t *)(void *)(od->ram + def->hook_heads);
	memset(od->hook_heads, 0, (size_t)def->n_entries * sizeof(uint16_t));
	memcpy(od->ram, def->ram_defaults, def->ram_size);
	apply_nodeid(od, 0x0000, 0xFFFF);
	return 0;
}

int co_od_set_node_id(struct co_od *od, uint8_t node_id)
{
	if (od == NULL || !((node_id >= 1U && node_id <= 127U) || node_id == 255U)) {
		return -EINVAL;
	}
	od->node_id = node_id;
	return 0;
}

int co_od_set_restore_cb(struct co_od *od, co_od_restore_cb cb, void *user_data)
{
	if (od == NULL) {
		return -EINVAL;
	}
	od->restore = cb;
	od->restore_user_data = user_data;
	return 0;
}

void co_od_reset_comm(struct co_od *od)
{
	const struct co_od_def *def = od->def;

	OD_ASSERT_LOCKED(od);
	memcpy(od->ram, def->ram_defaults, def->comm_end);
	apply_nodeid(od, 0x0000, 0x1FFF);
	if (od->restore != NULL) {
		od->restore(od, CO_OD_GROUP_BIT(CO_OD_GROUP_COMM), od->restore_user_data);
	}
}

void co_od_reset_app(struct co_od *od)
{
	const struct co_od_def *def = od->def;

	OD_ASSERT_LOCKED(od);
	memcpy(od->ram + def->comm_end, (const uint8_t *)def->ram_defaults + def->comm_end,
	       def->ram_size - def->comm_end);
	apply_nodeid(od, 0x2000, 0xFFFF);
	if (od->restore != NULL) {
		od->restore(od,
			    CO_OD_GROUP_BIT(CO_OD_GROUP_MANUF) | CO_OD_GROUP_BIT(CO_OD_GROUP_APP),
			    od->restore_user_data);
	}
}
