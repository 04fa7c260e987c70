/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Object dictionary access to whole values: the access, size and limit checks, then the
 * object's hooks (od_hooks.c) around the commit; typed getters and setters on top.
 */

#include <string.h>

#include "od_internal.h"

/*
 * The limit checks compare numbers as 64-bit unsigned keys whose order is the numbers' order,
 * so that no class needs its own comparison and REAL values need no floating point (a
 * soft-float target would link the library's double routines for two comparisons).
 */

/* The IEEE 754 binary64 bits of a binary32 value (exact: every float is a double). */
static uint64_t real32_to_64(uint32_t b)
{
	uint64_t sign = (uint64_t)(b >> 31) << 63;
	uint32_t exp = (b >> 23) & 0xFFU;
	uint32_t man = b & 0x7FFFFFU;

	if (exp == 0xFFU) {
		exp = 0x7FFU; /* infinity, NaN */
	} else if (exp != 0U) {
		exp += 1023U - 127U;
	} else if (man != 0U) {
		/* A subnormal float is a normal double: shift the leading one out. */
		exp = 1023U - 126U;
		while ((man & 0x800000U) == 0U) {
			man <<= 1;
			exp--;
		}
		man &= 0x7FFFFFU;
	} else {
		/* zero */
	}
	return sign | ((uint64_t)exp << 52) | ((uint64_t)man << 29);
}

/* Whether binary64 bits are a NaN, which compares neither below nor above anything. */
static bool real_is_nan(uint64_t bits)
{
	return (bits << 1) > ((uint64_t)0x7FFU << 53);
}

/* The order key of a value of class @p cls. */
static uint64_t num_key(enum co_dtype_class cls, uint64_t v)
{
	const uint64_t top = (uint64_t)1 << 63;

	if (cls == CO_DTYPE_CLASS_INT) {
		return v ^ top;
	}
	if (cls == CO_DTYPE_CLASS_REAL) {
		if ((v << 1) == 0U) {
			return top; /* -0 and +0 are equal */
		}
		return (v & top) != 0U ? ~v : (v | top);
	}
	return v;
}

/* a < b for two values of class @p cls; false when either is a NaN, as in C. */
static bool num_lt(enum co_dtype_class cls, uint64_t a, uint64_t b)
{
	if (cls == CO_DTYPE_CLASS_REAL && (real_is_nan(a) || real_is_nan(b))) {
		return false;
	}
	return num_key(cls, a) < num_key(cls, b);
}

/* Wire bytes as the 64-bit pattern of their class (sign-extended, REAL32 widened). */
static uint64_t wire_num(uint8_t dtype, enum co_dtype_class cls, const uint8_t *in)
{
	uint32_t size = co_dtype_size(dtype);
	uint64_t raw = co_od_le_get(in, size);

	if (cls == CO_DTYPE_CLASS_INT) {
		raw = co_od_sign_extend(raw, size);
	} else if (cls == CO_DTYPE_CLASS_REAL && size == 4U) {
		raw = real32_to_64((uint32_t)raw);
	} else {
		/* UNSIGNED, BOOLEAN, REAL64: as they are */
	}
	return raw;
}

/* ---------------------------------------------------------------------------------------- */
/* Reading */

static bool readable(uint8_t access)
{
	return access != CO_OD_ACCESS_WO;
}

static bool writable(uint8_t access)
{
	return access == CO_OD_ACCESS_WO || access == CO_OD_ACCESS_RW ||
	       access == CO_OD_ACCESS_RWR || access == CO_OD_ACCESS_RWW;
}

static bool tpdo_mappable(const struct co_od_info *info)
{
	return (info->flags & CO_OD_F_MAP) && readable(info->access) &&
	       info->access != CO_OD_ACCESS_RWW;
}

static bool rpdo_mappable(const struct co_od_info *info)
{
	return (info->flags & CO_OD_F_MAP) && writable(info->access) &&
	       info->access != CO_OD_ACCESS_RWR;
}

static uint32_t check_read(const struct co_od_info *info, enum co_od_writer reader)
{
	switch (reader) {
	case CO_OD_WRITER_SDO:
		return readable(info->access) ? 0U : CO_SDO_AB_WRITEONLY;
	case CO_OD_WRITER_PDO:
	case CO_OD_WRITER_SRDO:
	case CO_OD_WRITER_MPDO:
		return tpdo_mappable(info) ? 0U : CO_SDO_AB_NO_MAP;
	default:
		return 0U;
	}
}

uint32_t co_od_read_info(const struct co_od *od, const struct co_od_info *info, uint32_t offset,
			 void *buf, size_t cap, size_t *len, enum co_od_writer reader)
{
	uint32_t ab = check_read(info, reader);

	OD_ASSERT_LOCKED(od);
	*len = 0;
	if (ab == 0U) {
		ab = co_od_run_read_check(od, info, reader);
	}
	if (ab != 0U) {
		return ab;
	}
	if (INFO_PROV(info) != NULL) {
		return info->prov->api->read(info->prov, info, offset, buf, cap, len);
	}
	*len = co_od_mem_read(info->desc, co_od_mem(od->def, od->ram, info->desc), offset, buf,
			      cap);
	return 0;
}

uint32_t co_od_read(const struct co_od *od, uint16_t index, uint8_t sub, uint32_t offset, void *buf,
		    size_t cap, size_t *len, enum co_od_writer reader)
{
	struct co_od_info info;
	uint32_t ab = co_od_find(od, index, sub, &info);

	*len = 0;
	return ab != 0U ? ab : co_od_read_info(od, &info, offset, buf, cap, len, reader);
}

/* ---------------------------------------------------------------------------------------- */
/* Writing: checks, validate, commit, notify */

uint32_t co_od_check_access(const struct co_od_info *info, enum co_od_writer writer)
{
	if ((info->flags & CO_OD_F_ROM) || info->access == CO_OD_ACCESS_CONST) {
		return CO_SDO_AB_READONLY;
	}
	switch (writer) {
	case CO_OD_WRITER_SDO:
	case CO_OD_WRITER_MPDO:
		return writable(info->access) ? 0U : CO_SDO_AB_READONLY;
	case CO_OD_WRITER_PDO:
	case CO_OD_WRITER_SRDO:
		return rpdo_mappable(info) ? 0U : CO_SDO_AB_NO_MAP;
	case CO_OD_WRITER_APP:
	case CO_OD_WRITER_STORAGE:
		return 0U;
	default:
		return CO_SDO_AB_UNSUPP_ACCESS;
	}
}

/* Size check once the whole length is known. */
uint32_t co_od_check_size(const struct co_od_info *info, size_t len)
{
	if (len > info->size) {
		return CO_SDO_AB_DATA_LONG;
	}
	switch (co_dtype_class(info->dtype)) {
	case CO_DTYPE_CLASS_VSTR:
	case CO_DTYPE_CLASS_DOMAIN:
		return 0U;
	case CO_DTYPE_CLASS_USTR:
		return (len % 2U) ? CO_SDO_AB_TYPE_MISMATCH : 0U;
	default:
		return len < info->size ? CO_SDO_AB_DATA_SHORT : 0U;
	}
}

/* A limit as the 64-bit pattern of its class, $NODEID added when it is relative. */
static uint64_t lim_val(const struct co_od *od, enum co_dtype_class cls, union co_od_num v,
			bool rel)
{
	if (rel) {
		uint32_t nid = co_od_nid(od);

		if (cls == CO_DTYPE_CLASS_INT) {
			v.i += nid;
		} else {
			v.u += nid;
		}
	}
	return v.u;
}

static uint32_t check_value(const struct co_od *od, const struct co_od_info *info,
			    const uint8_t *data)
{
	enum co_dtype_class cls = co_dtype_class(info->dtype);

	if (cls == CO_DTYPE_CLASS_BOOL && data[0] > 1U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (info->limit == NULL || cls == CO_DTYPE_CLASS_NONE || co_dtype_size(info->dtype) == 0U) {
		return 0U;
	}
	const struct co_od_limit *l = info->limit;
	uint64_t v = wire_num(info->dtype, cls, data);
	uint64_t lo = lim_val(od, cls, l->lo, (l->rel & CO_OD_LIM_LO_REL) != 0U);
	uint64_t hi = lim_val(od, cls, l->hi, (l->rel & CO_OD_LIM_HI_REL) != 0U);

	if (num_lt(cls, v, lo)) {
		return CO_SDO_AB_VALUE_LOW;
	}
	if (num_lt(cls, hi, v)) {
		return CO_SDO_AB_VALUE_HIGH;
	}
	return 0U;
}

/* The checks that need the whole value, then validate, commit and notify. */
uint32_t co_od_finish_write(struct co_od *od, const struct co_od_info *info, const uint8_t *data,
			    size_t len, enum co_od_writer writer)
{
	uint32_t ab = co_od_check_size(info, len);

	if (ab == 0U) {
		ab = check_value(od, info, data);
	}
	if (ab != 0U) {
		return ab;
	}
	struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

	ab = co_od_run_validate(od, &req);
	if (ab != 0U && ab != CO_OD_HANDLED) {
		return ab;
	}
	if (ab == 0U) {
		if (INFO_PROV(info) != NULL) {
			ab = info->prov->api->write(info->prov, info, 0, data, len, true);
			if (ab != 0U) {
				return ab;
			}
		} else if (co_od_has_storage(info->desc)) {
			co_od_mem_commit(info->desc, od->ram + info->desc->offset, data, len);
		} else {
			return CO_SDO_AB_NO_DATA;
		}
	}
	co_od_run_notify(od, &req);
	return 0U;
}

uint32_t co_od_write_info(struct co_od *od, const struct co_od_info *info, const void *data,
			  size_t len, enum co_od_writer writer)
{
	uint32_t ab = co_od_check_access(info, writer);

	OD_ASSERT_LOCKED(od);
	if (ab != 0U) {
		return ab;
	}
	if (INFO_PROV(info) != NULL && (info->flags & CO_OD_F_STREAM)) {
		struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

		ab = co_od_run_validate(od, &req);
		if (ab == 0U) {
			ab = info->prov->api->write(info->prov, info, 0, data, len, true);
		}
		if (ab != 0U && ab != CO_OD_HANDLED) {
			return ab;
		}
		co_od_run_notify(od, &req);
		return 0U;
	}
	return co_od_finish_write(od, info, data, len, writer);
}

uint32_t co_od_write(struct co_od *od, uint16_t index, uint8_t sub, const void *data, size_t len,
		     enum co_od_writer writer)
{
	struct co_od_info info;
	uint32_t ab = co_od_find(od, index, sub, &info);

	return ab != 0U ? ab : co_od_write_info(od, &info, data, len, writer);
}

/* ---------------------------------------------------------------------------------------- */
/* Resolved access (PDO, SRDO) */

/* Whether the C storage of a fixed-size type holds its wire bytes as they are. */
static bool wire_is_storage(uint8_t dtype)
{
	enum co_dtype_class cls = co_dtype_class(dtype);

	if (__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__ ||
	    co_dtype_size(dtype) != co_od_csize(dtype)) {
		return false;
	}
	return cls == CO_DTYPE_CLASS_UINT || cls == CO_DTYPE_CLASS_INT ||
	       cls == CO_DTYPE_CLASS_REAL || cls == CO_DTYPE_CLASS_BOOL;
}

enum co_od_move co_od_move_of(const struct co_od *od, const struct co_od_info *info,
			      enum co_od_writer who, bool write)
{
	uint32_t size = co_dtype_size(info->dtype);

	/* A RAM value of a fixed-size type whose wire bytes are its C storage. */
	if (INFO_PROV(info) != NULL || (info->flags & CO_OD_F_ROM) != 0U || size == 0U ||
	    info->size != size || !co_od_has_storage(info->desc) || !wire_is_storage(info->dtype)) {
		return CO_OD_MOVE_ACCESS;
	}
	unsigned int has = co_od_hooks_has(od, info);

	if (!write) {
		return check_read(info, who) == 0U && (has & CO_OD_HAS_READ_CHECK) == 0U
			       ? CO_OD_MOVE_COPY
			       : CO_OD_MOVE_ACCESS;
	}
	/* Limits and BOOLEAN values are checked, validate hooks asked: the accessor does it. */
	if (co_od_check_access(info, who) != 0U || info->limit != NULL ||
	    co_dtype_class(info->dtype) == CO_DTYPE_CLASS_BOOL ||
	    (has & CO_OD_HAS_VALIDATE) != 0U) {
		return CO_OD_MOVE_ACCESS;
	}
	return (has & CO_OD_HAS_NOTIFY) != 0U ? CO_OD_MOVE_COPY_NOTIFY : CO_OD_MOVE_COPY;
}

/* ---------------------------------------------------------------------------------------- */
/* Typed access */

/* k: 'u' unsigned, 'i' signed, 'f' real, 'b' boolean */
static bool typed_ok(uint8_t dtype, char k, size_t csize)
{
	enum co_dtype_class cls = co_dtype_class(dtype);

	switch (k) {
	case 'u':
		return (cls == CO_DTYPE_CLASS_UINT ||
			(cls == CO_DTYPE_CLASS_BOOL && csize == 1U)) &&
		       co_od_csize(dtype) == csize;
	case 'i':
		return cls == CO_DTYPE_CLASS_INT && co_od_csize(dtype) == csize;
	case 'f':
		return cls == CO_DTYPE_CLASS_REAL && co_od_csize(dtype) == csize;
	default:
		return cls == CO_DTYPE_CLASS_BOOL;
	}
}

static uint32_t typed_get(const struct co_od *od, uint16_t index, uint8_t sub, char k, void *value,
			  size_t csize)
{
	struct co_od_info info;
	uint8_t wire[8] = {0};
	size_t len;
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (!typed_ok(info.dtype, k, csize)) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	ab = co_od_read_info(od, &info, 0, wire, sizeof(wire), &len, CO_OD_WRITER_APP);
	if (ab != 0U) {
		return ab;
	}
	if (k == 'b') {
		*(bool *)value = wire[0] != 0U;
		return 0;
	}
	co_od_decode_fixed(info.dtype, wire, value);
	return 0;
}

static uint32_t typed_set(struct co_od *od, uint16_t index, uint8_t sub, char k, const void *value,
			  size_t csize, enum co_od_writer writer)
{
	struct co_od_info info;
	uint8_t wire[8];
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (!typed_ok(info.dtype, k, csize)) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	if (k == 'b') {
		wire[0] = *(const bool *)value ? 1U : 0U;
	} else {
		co_od_encode_fixed(info.dtype, value, wire);
		/* A value that does not fit the wire size (UNSIGNED24 in a uint32_t) is refused. */
		uint8_t back[8];

		co_od_decode_fixed(info.dtype, wire, back);
		if (memcmp(back, value, csize) != 0) {
			bool neg = k == 'i' &&
				   (int64_t)co_od_sign_extend(co_od_load_native(value, csize),
							      (uint32_t)csize) < 0;

			return neg ? CO_SDO_AB_VALUE_LOW : CO_SDO_AB_VALUE_HIGH;
		}
	}
	return co_od_write_info(od, &info, wire, co_dtype_size(info.dtype), writer);
}

#define CO_OD_KIND_u8   'u'
#define CO_OD_KIND_u16  'u'
#define CO_OD_KIND_u32  'u'
#define CO_OD_KIND_u64  'u'
#define CO_OD_KIND_i8   'i'
#define CO_OD_KIND_i16  'i'
#define CO_OD_KIND_i32  'i'
#define CO_OD_KIND_i64  'i'
#define CO_OD_KIND_f32  'f'
#define CO_OD_KIND_f64  'f'
#define CO_OD_KIND_bool 'b'

#define CO_OD_TYPED_DEF_(sfx, ctype)                                                               \
	uint32_t co_od_get_##sfx(const struct co_od *od, uint16_t index, uint8_t sub,              \
				 ctype *value)                                                     \
	{                                                                                          \
		return typed_get(od, index, sub, CO_OD_KIND_##sfx, value, sizeof(ctype));          \
	}                                                                                          \
	uint32_t co_od_set_##sfx(struct co_od *od, uint16_t index, uint8_t sub, ctype value,       \
				 enum co_od_writer writer)                                         \
	{                                                                                          \
		return typed_set(od, index, sub, CO_OD_KIND_##sfx, &value, sizeof(ctype), writer); \
	}
CO_OD_TYPED_TABLE(CO_OD_TYPED_DEF_)
#undef CO_OD_TYPED_DEF_

uint32_t co_od_get_time(const struct co_od *od, uint16_t index, uint8_t sub, struct co_time *t)
{
	struct co_od_info info;
	uint8_t wire[8] = {0};
	size_t len;
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (co_dtype_class(info.dtype) != CO_DTYPE_CLASS_TIME) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	ab = co_od_read_info(od, &info, 0, wire, sizeof(wire), &len, CO_OD_WRITER_APP);
	if (ab == 0U) {
		co_od_decode_fixed(info.dtype, wire, t);
	}
	return ab;
}

uint32_t co_od_set_time(struct co_od *od, uint16_t index, uint8_t sub, const struct co_time *t,
			enum co_od_writer writer)
{
	struct co_od_info info;
	uint8_t wire[8];
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (co_dtype_class(info.dtype) != CO_DTYPE_CLASS_TIME) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	co_od_encode_fixed(info.dtype, t, wire);
	return co_od_write_info(od, &info, wire, 6, writer);
}

uint64_t co_od_req_uint(const struct co_od_req *req)
{
	return co_od_le_get(req->data, req->len > 8 ? 8 : req->len);
}

uint32_t co_od_uint(const struct co_od *od, uint16_t index, uint8_t sub, uint32_t dflt)
{
	uint8_t wire[8] = {0};
	size_t len;

	if (co_od_read(od, index, sub, 0, wire, sizeof(wire), &len, CO_OD_WRITER_APP) != 0U ||
	    len == 0U) {
		return dflt;
	}
	return (uint32_t)co_od_le_get(wire, len);
}
