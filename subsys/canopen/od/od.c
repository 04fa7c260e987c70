/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Object dictionary access layer: lookup, checks, hooks, staging and commit.
 *
 * Values are kept in their C storage types (types.h) in the node's RAM block or the ROM
 * block; every byte-stream access converts to and from the CiA wire format (little endian)
 * here, so the rest of the stack never casts raw OD memory.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/toolchain.h>

#include "od_internal.h"

#define OD_UNLIKELY(x) __builtin_expect(!!(x), 0)

/* Inlined on the hot paths when optimising for speed; one copy in a size build (-Os). */
#if defined(__OPTIMIZE_SIZE__)
#define OD_HOT_INLINE inline
#else
#define OD_HOT_INLINE inline __attribute__((always_inline))
#endif

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

static uint64_t load_native(const void *mem, size_t csize)
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
static uint64_t sign_extend(uint64_t v, uint32_t bytes)
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
	co_od_le_put(out, size, load_native(mem, co_od_csize(dtype)));
}

static void decode_fixed(uint8_t dtype, const uint8_t *in, void *mem)
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
		v = sign_extend(v, size);
	}
	store_native(mem, co_od_csize(dtype), v);
}

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
		raw = sign_extend(raw, size);
	} else if (cls == CO_DTYPE_CLASS_REAL && size == 4U) {
		raw = real32_to_64((uint32_t)raw);
	} else {
		/* UNSIGNED, BOOLEAN, REAL64: as they are */
	}
	return raw;
}

/* ---------------------------------------------------------------------------------------- */
/* Descriptors */

const struct co_od_entry *co_od_entry_find(const struct co_od_def *def, uint16_t index)
{
	size_t lo = 0;
	size_t hi = def->n_entries;

	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2U;
		uint16_t v = def->entries[mid].index;

		if (v == index) {
			return &def->entries[mid];
		}
		if (v < index) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return NULL;
}

static const struct co_od_sub *sub_find(const struct co_od_def *def, const struct co_od_entry *e,
					uint8_t sub)
{
	const struct co_od_sub *subs = &def->subs[e->first];

	/* Sub-indexes are usually dense: try the direct position first. */
	if (sub < e->n_subs && subs[sub].sub == sub) {
		return &subs[sub];
	}
	size_t lo = 0;
	size_t hi = e->n_subs;

	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2U;

		if (subs[mid].sub == sub) {
			return &subs[mid];
		}
		if (subs[mid].sub < sub) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return NULL;
}

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

static bool has_storage(const struct co_od_sub *desc)
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

		if (!has_storage(desc)) {
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

static void mem_commit(const struct co_od_sub *desc, uint8_t *mem, const uint8_t *data, size_t len)
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
		decode_fixed(desc->dtype, data, mem);
		break;
	}
}

/* ---------------------------------------------------------------------------------------- */
/* Instance */

static uint32_t nid_or_zero(uint8_t nid)
{
	return (nid >= 1U && nid <= 127U) ? nid : 0U;
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
		co_od_le_put(wire, 8, (uint64_t)(n->base + (int64_t)nid_or_zero(od->node_id)));
		decode_fixed(desc->dtype, wire, od->ram + desc->offset);
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

/*
 * The provider of an object, NULL for a dictionary object. Without
 * CONFIG_CANOPEN_OD_PROVIDERS no object has one, and the constant lets the compiler drop the
 * accessors' provider branches.
 */
#define INFO_PROV(info) (CO_OD_PROVIDERS ? (info)->prov : NULL)

/* ---------------------------------------------------------------------------------------- */
/* Hooks and providers */

/*
 * Every change of the hook table makes the caches of "which hooks cover this object"
 * (struct co_od_cover) stale. The generation is never 0, so a zeroed cover is stale too.
 */
static void hook_gen_bump(struct co_od *od)
{
	od->hook_gen++;
	if (od->hook_gen == 0U) {
		od->hook_gen = 1U;
	}
}

/*
 * Remove the hooks of a failed batch (registration number @p first_seq on) or those
 * registered with @p user_data: one compaction loop for both, which also recomputes the
 * widest span. Returns how many were removed.
 */
static int hooks_remove(struct co_od *od, bool batch, uint32_t first_seq, const void *user_data)
{
	uint16_t w = 0;
	int removed = 0;

	od->hook_span = 0;
	for (uint16_t r = 0; r < od->n_hooks; r++) {
		if (batch ? (od->hook_seq[r] >= first_seq)
			  : (od->hooks[r].user_data == user_data)) {
			/* A hook's read check is an entry of its own: count the hook once. */
			if (od->hooks[r].kind == CO_OD_HOOK_ENT_PLAIN) {
				removed++;
			}
			continue;
		}
		od->hooks[w] = od->hooks[r];
		od->hook_seq[w] = od->hook_seq[r];
		uint16_t span = od->hooks[w].index_last - od->hooks[w].index_first;

		if (span > od->hook_span) {
			od->hook_span = span;
		}
		w++;
	}
	od->n_hooks = w;
	if (removed > 0) {
		hook_gen_bump(od);
	}
	return removed;
}

int co_od_hooks_register(struct co_od *od, const struct co_od_hook *hooks, size_t n)
{
	uint32_t first;

	if (od == NULL) {
		return -EINVAL;
	}
	OD_ASSERT_LOCKED(od);
	first = od->hook_next_seq;
	for (size_t i = 0; i < n; i++) {
		int err = co_od_hook_register(od, &hooks[i]);

		if (err != 0) {
			/* All or nothing: a service never runs with half of its hooks. */
			(void)hooks_remove(od, true, first, NULL);
			return err;
		}
	}
	return 0;
}

int co_od_hook_register(struct co_od *od, const struct co_od_hook *hook)
{
	if (od == NULL || hook == NULL || hook->index_last < hook->index_first ||
	    hook->sub_last < hook->sub_first || (hook->validate == NULL && hook->notify == NULL)) {
		return -EINVAL;
	}
	OD_ASSERT_LOCKED(od);
	uint16_t n = (hook->read_check != NULL) ? 2U : 1U;

	if (od->n_hooks + n > CO_OD_HOOKS_MAX) {
		return -ENOSPC;
	}
	/* Keep the table sorted by first index; equal keys keep registration order. */
	uint16_t pos = od->n_hooks;

	while (pos > 0U && od->hooks[pos - 1U].index_first > hook->index_first) {
		od->hooks[pos + n - 1U] = od->hooks[pos - 1U];
		od->hook_seq[pos + n - 1U] = od->hook_seq[pos - 1U];
		pos--;
	}
	struct co_od_hook_ent e = {
		.index_first = hook->index_first,
		.index_last = hook->index_last,
		.sub_first = hook->sub_first,
		.sub_last = hook->sub_last,
		.kind = CO_OD_HOOK_ENT_PLAIN,
		.fn.validate = hook->validate,
		.notify = hook->notify,
		.user_data = hook->user_data,
	};

	for (uint16_t k = 0U; k < n; k++) {
		od->hooks[pos + k] = e;
		od->hook_seq[pos + k] = od->hook_next_seq++;
		/* The read check next: the same range, a later registration number. */
		e.kind = CO_OD_HOOK_ENT_READ_CHECK;
		e.fn.read_check = hook->read_check;
		e.notify = NULL;
	}
	od->n_hooks += n;
	hook_gen_bump(od);
	uint16_t span = hook->index_last - hook->index_first;

	if (span > od->hook_span) {
		od->hook_span = span;
	}
	return 0;
}

int co_od_hook_unregister(struct co_od *od, const void *user_data)
{
	OD_ASSERT_LOCKED(od);
	return hooks_remove(od, false, 0U, user_data);
}

/* First hook that may cover index: hooks start at most hook_span below it. */
static uint16_t hooks_start(const struct co_od *od, uint16_t index)
{
	uint32_t from = (index > od->hook_span) ? (uint32_t)index - od->hook_span : 0U;
	uint16_t lo = 0;
	uint16_t hi = od->n_hooks;

	while (lo < hi) {
		uint16_t mid = lo + (hi - lo) / 2U;

		if (od->hooks[mid].index_first < from) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return lo;
}

static bool hook_covers(const struct co_od_hook_ent *h, uint16_t index, uint8_t sub)
{
	return index >= h->index_first && index <= h->index_last && sub >= h->sub_first &&
	       sub <= h->sub_last;
}

/*
 * Position of the first hook after the one that was at (first, seq), whether that one is
 * still registered or not: the table is ordered by (index_first, registration number).
 */
static uint16_t hooks_after(const struct co_od *od, uint16_t first, uint32_t seq)
{
	uint16_t lo = 0;
	uint16_t hi = od->n_hooks;

	while (lo < hi) {
		uint16_t mid = lo + (hi - lo) / 2U;

		if (od->hooks[mid].index_first < first) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	while (lo < od->n_hooks && od->hooks[lo].index_first == first && od->hook_seq[lo] <= seq) {
		lo++;
	}
	return lo;
}

/*
 * A hook may register or unregister hooks (the PDO service re-hooks its mapped objects when
 * a mapping is written), which moves the table under the loop. The loops below therefore
 * re-find their place when the generation changed, and only call hooks registered before
 * the loop started: every hook present throughout runs exactly once, a removed one no more.
 */
/*
 * The loops start at @p i; @p end bounds them while the table is unchanged (a cached
 * coverage, struct co_od_cover), UINT16_MAX otherwise.
 */
static uint32_t run_validate_at(struct co_od *od, const struct co_od_req *req, uint16_t i,
				uint16_t end)
{
	uint16_t index = req->info->index;
	uint32_t result = 0;
	uint32_t gen = od->hook_gen;
	uint32_t limit = od->hook_next_seq;

	while (i < od->n_hooks && i < end && od->hooks[i].index_first <= index) {
		const struct co_od_hook_ent *h = &od->hooks[i];

		if (h->kind != CO_OD_HOOK_ENT_PLAIN || h->fn.validate == NULL ||
		    od->hook_seq[i] >= limit || !hook_covers(h, index, req->info->sub)) {
			i++;
			continue;
		}
		struct co_od_req copy = *req;
		uint16_t first = h->index_first;
		uint32_t seq = od->hook_seq[i];
		uint32_t r = h->fn.validate(od, &copy, h->user_data);

		if (r == CO_OD_HANDLED) {
			result = CO_OD_HANDLED;
		} else if (r != 0U) {
			return r;
		}
		if (od->hook_gen != gen) {
			gen = od->hook_gen;
			i = hooks_after(od, first, seq);
			end = UINT16_MAX;
		} else {
			i++;
		}
	}
	return result;
}

static uint32_t run_validate(struct co_od *od, const struct co_od_req *req)
{
	return run_validate_at(od, req, hooks_start(od, req->info->index), UINT16_MAX);
}

/* The notify pass from position @p i; @p limit: hooks registered from then on do not run. */
static void notify_from(struct co_od *od, const struct co_od_req *req, uint16_t i, uint16_t end,
			uint32_t limit)
{
	uint16_t index = req->info->index;
	uint32_t gen = od->hook_gen;

	while (i < od->n_hooks && i < end && od->hooks[i].index_first <= index) {
		const struct co_od_hook_ent *h = &od->hooks[i];

		if (h->notify == NULL || od->hook_seq[i] >= limit ||
		    !hook_covers(h, index, req->info->sub)) {
			i++;
			continue;
		}
		uint16_t first = h->index_first;
		uint32_t seq = od->hook_seq[i];

		h->notify(od, req, h->user_data);
		if (od->hook_gen != gen) {
			gen = od->hook_gen;
			i = hooks_after(od, first, seq);
			end = UINT16_MAX;
		} else {
			i++;
		}
	}
}

static void run_notify_at(struct co_od *od, const struct co_od_req *req, uint16_t i, uint16_t end)
{
	notify_from(od, req, i, end, od->hook_next_seq);
}

static void run_notify(struct co_od *od, const struct co_od_req *req)
{
	run_notify_at(od, req, hooks_start(od, req->info->index), UINT16_MAX);
}

int co_od_provider_register(struct co_od *od, const struct co_od_provider *p)
{
	if (od == NULL || p == NULL || p->api == NULL || p->api->info == NULL ||
	    p->api->read == NULL || p->api->write == NULL || p->index_last < p->index_first) {
		return -EINVAL;
	}
#if CO_OD_PROVIDERS
	for (uint8_t i = 0; i < od->n_prov; i++) {
		if (p->index_first <= od->prov[i]->index_last &&
		    od->prov[i]->index_first <= p->index_last) {
			return -EEXIST;
		}
	}
	if (od->n_prov >= CO_OD_PROVIDERS_MAX) {
		return -ENOSPC;
	}
	od->prov[od->n_prov++] = p;
	return 0;
#else
	return -ENOTSUP;
#endif
}

static const struct co_od_provider *provider_of(const struct co_od *od, uint16_t index)
{
#if CO_OD_PROVIDERS
	for (uint8_t i = 0; i < od->n_prov; i++) {
		if (index >= od->prov[i]->index_first && index <= od->prov[i]->index_last) {
			return od->prov[i];
		}
	}
#endif
	return NULL;
}

/* ---------------------------------------------------------------------------------------- */
/* Lookup */

static uint32_t provider_info(const struct co_od_provider *p, uint16_t index, uint8_t sub,
			      struct co_od_info *info)
{
	memset(info, 0, sizeof(*info));
	info->prov = p;
	info->index = index;
	info->sub = sub;
	info->objcode = CO_OD_OBJ_VAR;
	return p->api->info(p, info);
}

uint32_t co_od_find(const struct co_od *od, uint16_t index, uint8_t sub, struct co_od_info *info)
{
	const struct co_od_def *def = od->def;
	const struct co_od_entry *e = co_od_entry_find(def, index);

	if (e == NULL) {
		const struct co_od_provider *p = provider_of(od, index);

		return p != NULL ? provider_info(p, index, sub, info) : CO_SDO_AB_NO_OBJECT;
	}
	const struct co_od_sub *desc = sub_find(def, e, sub);

	if (desc == NULL) {
		return CO_SDO_AB_NO_SUB;
	}
	if (!has_storage(desc)) {
		/* A DOMAIN without RAM is served by the provider of its index, if any. */
		const struct co_od_provider *p = provider_of(od, index);

		if (p != NULL && provider_info(p, index, sub, info) == 0U) {
			info->objcode = e->objcode;
			return 0;
		}
	}
#if defined(__OPTIMIZE_SIZE__)
	/* One copy, shared with the PDO mapping entries, which rebuild their objects' info. */
	co_od_info_fill(od, desc, index, e->objcode, e->group, info);
#else
	co_od_info_fill_inline(od, desc, index, e->objcode, e->group, info);
#endif
	return 0;
}

void co_od_info_fill(const struct co_od *od, const struct co_od_sub *desc, uint16_t index,
		     uint8_t objcode, uint8_t group, struct co_od_info *info)
{
	co_od_info_fill_inline(od, desc, index, objcode, group, info);
}

const void *co_od_value_ptr(const struct co_od *od, const struct co_od_info *info)
{
	if (info->desc == NULL || !has_storage(info->desc)) {
		return NULL;
	}
	return co_od_mem(od->def, od->ram, info->desc);
}

uint32_t co_od_length(const struct co_od *od, const struct co_od_info *info)
{
	if (INFO_PROV(info) != NULL) {
		return info->prov->api->length != NULL ? info->prov->api->length(info->prov, info)
						       : info->size;
	}
	return co_od_mem_length(info->desc, co_od_mem(od->def, od->ram, info->desc));
}

bool co_od_is_nodeid_default(const struct co_od *od, const struct co_od_info *info)
{
	if (info->desc == NULL || !(info->desc->flags & CO_OD_F_NODEID)) {
		return false;
	}
	const struct co_od_nodeid *n =
		co_od_nodeid_of(od->def, (uint32_t)(info->desc - od->def->subs));
	uint8_t wire[8];

	if (n == NULL) {
		return false;
	}
	co_od_encode_fixed(info->dtype, co_od_mem(od->def, od->ram, info->desc), wire);
	uint32_t size = co_dtype_size(info->dtype);
	uint64_t mask = size >= 8U ? UINT64_MAX : (((uint64_t)1 << (8U * size)) - 1U);
	uint64_t want = (uint64_t)(n->base + (int64_t)nid_or_zero(od->node_id)) & mask;

	return co_od_le_get(wire, size) == want;
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

static uint32_t run_read_check_at(const struct co_od *od, const struct co_od_info *info,
				  enum co_od_writer reader, uint16_t i, uint16_t end)
{
	uint16_t index = info->index;

	if (reader == CO_OD_WRITER_APP || reader == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	for (; i < od->n_hooks && i < end && od->hooks[i].index_first <= index; i++) {
		const struct co_od_hook_ent *h = &od->hooks[i];

		if (h->kind != CO_OD_HOOK_ENT_READ_CHECK || !hook_covers(h, index, info->sub)) {
			continue;
		}
		uint32_t r = h->fn.read_check(od, info, reader, h->user_data);

		if (r != 0U) {
			return r;
		}
	}
	return 0U;
}

static uint32_t run_read_check(const struct co_od *od, const struct co_od_info *info,
			       enum co_od_writer reader)
{
	return run_read_check_at(od, info, reader, hooks_start(od, info->index), UINT16_MAX);
}

uint32_t co_od_read_info(const struct co_od *od, const struct co_od_info *info, uint32_t offset,
			 void *buf, size_t cap, size_t *len, enum co_od_writer reader)
{
	uint32_t ab = check_read(info, reader);

	OD_ASSERT_LOCKED(od);
	*len = 0;
	if (ab == 0U) {
		ab = run_read_check(od, info, reader);
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

static uint32_t check_access(const struct co_od_info *info, enum co_od_writer writer)
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
static uint32_t check_size(const struct co_od_info *info, size_t len)
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
		uint32_t nid = nid_or_zero(od->node_id);

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
static uint32_t finish_write(struct co_od *od, const struct co_od_info *info, const uint8_t *data,
			     size_t len, enum co_od_writer writer)
{
	uint32_t ab = check_size(info, len);

	if (ab == 0U) {
		ab = check_value(od, info, data);
	}
	if (ab != 0U) {
		return ab;
	}
	struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

	ab = run_validate(od, &req);
	if (ab != 0U && ab != CO_OD_HANDLED) {
		return ab;
	}
	if (ab == 0U) {
		if (INFO_PROV(info) != NULL) {
			ab = info->prov->api->write(info->prov, info, 0, data, len, true);
			if (ab != 0U) {
				return ab;
			}
		} else if (has_storage(info->desc)) {
			mem_commit(info->desc, od->ram + info->desc->offset, data, len);
		} else {
			return CO_SDO_AB_NO_DATA;
		}
	}
	run_notify(od, &req);
	return 0U;
}

uint32_t co_od_write_info(struct co_od *od, const struct co_od_info *info, const void *data,
			  size_t len, enum co_od_writer writer)
{
	uint32_t ab = check_access(info, writer);

	OD_ASSERT_LOCKED(od);
	if (ab != 0U) {
		return ab;
	}
	if (INFO_PROV(info) != NULL && (info->flags & CO_OD_F_STREAM)) {
		struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

		ab = run_validate(od, &req);
		if (ab == 0U) {
			ab = info->prov->api->write(info->prov, info, 0, data, len, true);
		}
		if (ab != 0U && ab != CO_OD_HANDLED) {
			return ab;
		}
		run_notify(od, &req);
		return 0U;
	}
	return finish_write(od, info, data, len, writer);
}

/* ---------------------------------------------------------------------------------------- */
/* Cached access (hot paths) */

/* Whether the C storage of a fixed-size type holds its wire bytes as they are. */
#if defined(CONFIG_CANOPEN_LOCK_CHECK)
void co_od_assert_locked(const struct co_od *od)
{
	OD_ASSERT_LOCKED(od);
}
#endif

/*
 * The cached accessors (CONFIG_CANOPEN_OD_COVER): which hooks cover an object, found once per
 * change of the hook table, and the copy-only paths of PDO and SRDO writes and reads.
 */
#if CO_OD_COVER

static bool wire_is_storage(uint8_t dtype)
{
	uint32_t size = co_dtype_size(dtype);
	enum co_dtype_class cls = co_dtype_class(dtype);

	if (__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__ || size != co_od_csize(dtype)) {
		return false;
	}
	return cls == CO_DTYPE_CLASS_UINT || cls == CO_DTYPE_CLASS_INT ||
	       cls == CO_DTYPE_CLASS_REAL || cls == CO_DTYPE_CLASS_BOOL;
}

/* memcpy() of a fixed-size value with constant lengths, which compilers inline. */
static inline void copy_fixed(void *dst, const void *src, uint32_t size)
{
	switch (size) {
	case 1:
		memcpy(dst, src, 1);
		break;
	case 2:
		memcpy(dst, src, 2);
		break;
	case 4:
		memcpy(dst, src, 4);
		break;
	case 8:
		memcpy(dst, src, 8);
		break;
	default:
		/* Not a size of a copied type (1, 2, 4, 8); a loop keeps callers leaf code. */
		for (uint32_t i = 0; i < size; i++) {
			((uint8_t *)dst)[i] = ((const uint8_t *)src)[i];
		}
		break;
	}
}

/*
 * A PDO/SRDO write that needs no check and no hook but what the cover made: a RAM value such
 * writers may write, whose C storage is its wire format, without limits or validate hooks.
 */
#define COVER_W_MASK                                                                               \
	(CO_OD_COVER_DIRECT | CO_OD_COVER_COPY | CO_OD_COVER_MAP_W | CO_OD_COVER_CHECK |           \
	 CO_OD_COVER_VALIDATE)
#define COVER_W_COPY (CO_OD_COVER_DIRECT | CO_OD_COVER_COPY | CO_OD_COVER_MAP_W)

/* Likewise for a read: such readers may read it, no read-check hook. */
#define COVER_R_MASK                                                                               \
	(CO_OD_COVER_DIRECT | CO_OD_COVER_COPY | CO_OD_COVER_MAP_R | CO_OD_COVER_READ_CHECK)
#define COVER_R_COPY (CO_OD_COVER_DIRECT | CO_OD_COVER_COPY | CO_OD_COVER_MAP_R)

static __attribute__((noinline)) void
cover_make(const struct co_od *od, const struct co_od_info *info, struct co_od_cover *cover)
{
	uint16_t index = info->index;
	uint16_t flags = CO_OD_COVER_MADE | CO_OD_COVER_EXACT;
	uint16_t first = UINT16_MAX;
	uint16_t end = 0U;

	for (uint16_t i = hooks_start(od, index);
	     i < od->n_hooks && od->hooks[i].index_first <= index; i++) {
		const struct co_od_hook_ent *h = &od->hooks[i];

		if (!hook_covers(h, index, info->sub)) {
			/* A hook between two covering ones: the range is not exact. */
			if (first != UINT16_MAX) {
				flags &= (uint16_t)~CO_OD_COVER_EXACT;
			}
			continue;
		}
		if (first == UINT16_MAX) {
			first = i;
		} else if (end != i) {
			flags &= (uint16_t)~CO_OD_COVER_EXACT;
		}
		end = i + 1U;
		if (h->kind == CO_OD_HOOK_ENT_READ_CHECK) {
			flags |= CO_OD_COVER_READ_CHECK;
		} else {
			flags |= (h->fn.validate != NULL ? CO_OD_COVER_VALIDATE : 0U) |
				 (h->notify != NULL ? CO_OD_COVER_NOTIFY : 0U);
		}
	}
	if (INFO_PROV(info) == NULL && (info->flags & CO_OD_F_ROM) == 0U &&
	    co_dtype_size(info->dtype) != 0U && info->size == co_dtype_size(info->dtype) &&
	    has_storage(info->desc)) {
		flags |= CO_OD_COVER_DIRECT;
		if (info->limit != NULL || co_dtype_class(info->dtype) == CO_DTYPE_CLASS_BOOL) {
			flags |= CO_OD_COVER_CHECK;
		}
		if (wire_is_storage(info->dtype)) {
			flags |= CO_OD_COVER_COPY;
		}
	}
	/* The access checks of the PDO and SRDO writers and readers, made once. */
	if (check_access(info, CO_OD_WRITER_PDO) == 0U) {
		flags |= CO_OD_COVER_MAP_W;
	}
	if (check_read(info, CO_OD_WRITER_PDO) == 0U) {
		flags |= CO_OD_COVER_MAP_R;
	}
	/* One hook, a notify one: the pass is one call, nothing can follow it. */
	if ((flags & (CO_OD_COVER_EXACT | CO_OD_COVER_NOTIFY)) ==
		    (CO_OD_COVER_EXACT | CO_OD_COVER_NOTIFY) &&
	    end == first + 1U) {
		flags |= CO_OD_COVER_NOTIFY1;
	}
	/* No covering hook: an empty range (the positions fit co_od_hook_pos_t). */
	if (first == UINT16_MAX) {
		first = 0U;
	}
	cover->first = (co_od_hook_pos_t)first;
	cover->end = (co_od_hook_pos_t)end;
	/* What the inline accessors of od.h do alone: copy, then at most one notify call. */
	if ((flags & COVER_W_MASK) == COVER_W_COPY &&
	    ((flags & CO_OD_COVER_NOTIFY) == 0U || (flags & CO_OD_COVER_NOTIFY1) != 0U)) {
		flags |= CO_OD_COVER_W_FAST;
	}
	if ((flags & COVER_R_MASK) == COVER_R_COPY) {
		flags |= CO_OD_COVER_R_FAST;
	}
	cover->flags = flags;
	cover->gen = od->hook_gen;
}

static inline void cover_refresh(const struct co_od *od, const struct co_od_info *info,
				 struct co_od_cover *cover)
{
	/* hook_gen is never 0: a zeroed cover is made at first use. */
	if (OD_UNLIKELY(cover->gen != od->hook_gen)) {
		cover_make(od, info, cover);
	}
}

static inline bool pdo_or_srdo(enum co_od_writer w)
{
	return w == CO_OD_WRITER_PDO || w == CO_OD_WRITER_SRDO;
}

/*
 * The notify pass of a fresh cover whose hooks are exactly [first, end): no search, no
 * coverage test. A hook that changes the table hands the rest of the pass to notify_from(),
 * which goes on exactly as run_notify_at() would have.
 */
static OD_HOT_INLINE void run_notify_cover(struct co_od *od, const struct co_od_req *req,
					   const struct co_od_cover *cover)
{
	uint32_t gen = od->hook_gen;
	uint32_t limit = od->hook_next_seq;
	uint16_t i = cover->first;

	do {
		const struct co_od_hook_ent *h = &od->hooks[i];

		if (h->notify != NULL) {
			uint16_t first = h->index_first;
			uint32_t seq = od->hook_seq[i];

			h->notify(od, req, h->user_data);
			if (OD_UNLIKELY(od->hook_gen != gen)) {
				notify_from(od, req, hooks_after(od, first, seq), UINT16_MAX,
					    limit);
				return;
			}
		}
	} while (++i < cover->end);
}

/* finish_write() of a fixed-size RAM value, the hook scans limited to a fresh cover. */
static __attribute__((noinline)) uint32_t write_covered(struct co_od *od,
							const struct co_od_info *info,
							struct co_od_cover *cover, const void *data,
							size_t len, enum co_od_writer writer)
{
	uint16_t flags = cover->flags;
	uint32_t ab = 0U;

	if ((flags & CO_OD_COVER_MAP_W) == 0U || !pdo_or_srdo(writer)) {
		ab = check_access(info, writer);
	}
	if (ab == 0U && (flags & CO_OD_COVER_CHECK) != 0U) {
		ab = check_value(od, info, data);
	}
	if (ab != 0U) {
		return ab;
	}
	struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};
	uint32_t gen = od->hook_gen;

	if ((flags & CO_OD_COVER_VALIDATE) != 0U) {
		ab = run_validate_at(od, &req, cover->first, cover->end);
		if (ab != 0U && ab != CO_OD_HANDLED) {
			return ab;
		}
	}
	if (ab == 0U) {
		uint8_t *mem = od->ram + info->desc->offset;

		if ((flags & CO_OD_COVER_COPY) != 0U) {
			copy_fixed(mem, data, info->size);
		} else {
			decode_fixed(info->dtype, data, mem);
		}
	}
	if (OD_UNLIKELY(od->hook_gen != gen)) {
		/* A validate hook changed the table: the cover is stale. */
		run_notify(od, &req);
	} else if ((flags & CO_OD_COVER_NOTIFY) != 0U) {
		if ((flags & CO_OD_COVER_EXACT) != 0U) {
			run_notify_cover(od, &req, cover);
		} else {
			run_notify_at(od, &req, cover->first, cover->end);
		}
	}
	return 0U;
}

/* The value is written (a copy by a PDO/SRDO writer): the notify hooks of a fresh cover. */
static __attribute__((noinline)) uint32_t write_notify(struct co_od *od,
						       const struct co_od_info *info,
						       const struct co_od_cover *cover,
						       const void *data, size_t len,
						       enum co_od_writer writer)
{
	const struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

	if (OD_UNLIKELY((cover->flags & CO_OD_COVER_EXACT) == 0U)) {
		run_notify_at(od, &req, cover->first, cover->end);
	} else {
		run_notify_cover(od, &req, cover);
	}
	return 0U;
}

/* A stale cover: make it, then write through it. */
static __attribute__((noinline)) uint32_t write_remade(struct co_od *od,
						       const struct co_od_info *info,
						       struct co_od_cover *cover, const void *data,
						       size_t len, enum co_od_writer writer)
{
	cover_make(od, info, cover);
	return co_od_write_cover(od, info, cover, data, len, writer);
}

/*
 * The common PDO case is leaf code: every check was made with the cover, so a fresh cover
 * of a plain value costs a comparison of generations and a copy; anything else goes out of
 * line (tail calls).
 */
uint32_t co_od_write_cover(struct co_od *od, const struct co_od_info *info,
			   struct co_od_cover *cover, const void *data, size_t len,
			   enum co_od_writer writer)
{
	OD_ASSERT_LOCKED(od);
	if (OD_UNLIKELY(cover->gen != od->hook_gen)) {
		/* hook_gen is never 0: a zeroed cover is made here at first use. */
		return write_remade(od, info, cover, data, len, writer);
	}

	uint16_t flags = cover->flags;

	if (OD_UNLIKELY((flags & CO_OD_COVER_DIRECT) == 0U || len != info->size)) {
		return co_od_write_info(od, info, data, len, writer);
	}
	if ((flags & COVER_W_MASK) != COVER_W_COPY || !pdo_or_srdo(writer)) {
		return write_covered(od, info, cover, data, len, writer);
	}
	copy_fixed(od->ram + info->desc->offset, data, len);
	if ((flags & CO_OD_COVER_NOTIFY1) != 0U) {
		/*
		 * The notify pass of one hook: it ran when the pass began and was the only one;
		 * hooks it adds join from the next write on, so nothing follows it.
		 */
		const struct co_od_req req = {
			.info = info, .writer = writer, .data = data, .len = len};
		const struct co_od_hook_ent *h = &od->hooks[cover->first];

		h->notify(od, &req, h->user_data);
		return 0U;
	}
	if ((flags & CO_OD_COVER_NOTIFY) != 0U) {
		return write_notify(od, info, cover, data, len, writer);
	}
	return 0U;
}

/* co_od_read_info() of a fixed-size RAM value, the read-check scan limited to a fresh cover. */
static __attribute__((noinline)) uint32_t read_covered(const struct co_od *od,
						       const struct co_od_info *info,
						       const struct co_od_cover *cover, void *buf,
						       size_t *len, enum co_od_writer reader)
{
	uint16_t flags = cover->flags;
	uint32_t ab = check_read(info, reader);

	*len = 0;
	if (ab == 0U && (flags & CO_OD_COVER_READ_CHECK) != 0U) {
		ab = run_read_check_at(od, info, reader, cover->first, cover->end);
	}
	if (ab != 0U) {
		return ab;
	}
	const uint8_t *mem = od->ram + info->desc->offset;

	if ((flags & CO_OD_COVER_COPY) != 0U) {
		copy_fixed(buf, mem, info->size);
	} else {
		uint8_t tmp[8];

		co_od_encode_fixed(info->dtype, mem, tmp);
		memcpy(buf, tmp, info->size);
	}
	*len = info->size;
	return 0U;
}

/* A stale cover: make it, then read through it. */
static __attribute__((noinline)) uint32_t read_remade(const struct co_od *od,
						      const struct co_od_info *info,
						      struct co_od_cover *cover, void *buf,
						      size_t cap, size_t *len,
						      enum co_od_writer reader)
{
	cover_make(od, info, cover);
	return co_od_read_cover(od, info, cover, buf, cap, len, reader);
}

/* As co_od_write_cached(): the common TPDO case is leaf code, the rest out of line. */
uint32_t co_od_read_cover(const struct co_od *od, const struct co_od_info *info,
			  struct co_od_cover *cover, void *buf, size_t cap, size_t *len,
			  enum co_od_writer reader)
{
	OD_ASSERT_LOCKED(od);
	if (OD_UNLIKELY(cover->gen != od->hook_gen)) {
		return read_remade(od, info, cover, buf, cap, len, reader);
	}

	uint16_t flags = cover->flags;

	if (OD_UNLIKELY((flags & CO_OD_COVER_DIRECT) == 0U || cap < info->size)) {
		return co_od_read_info(od, info, 0, buf, cap, len, reader);
	}
	if ((flags & COVER_R_MASK) != COVER_R_COPY || !pdo_or_srdo(reader)) {
		return read_covered(od, info, cover, buf, len, reader);
	}
	copy_fixed(buf, od->ram + info->desc->offset, info->size);
	*len = info->size;
	return 0U;
}

#else /* !CO_OD_COVER */

/* Without the cache the cached accessors are the generic ones; the cover is not used. */
uint32_t co_od_write_cover(struct co_od *od, const struct co_od_info *info,
			   struct co_od_cover *cover, const void *data, size_t len,
			   enum co_od_writer writer)
{
	(void)cover;
	return co_od_write_info(od, info, data, len, writer);
}

uint32_t co_od_read_cover(const struct co_od *od, const struct co_od_info *info,
			  struct co_od_cover *cover, void *buf, size_t cap, size_t *len,
			  enum co_od_writer reader)
{
	(void)cover;
	return co_od_read_info(od, info, 0, buf, cap, len, reader);
}

#endif /* CO_OD_COVER */

uint32_t co_od_write(struct co_od *od, uint16_t index, uint8_t sub, const void *data, size_t len,
		     enum co_od_writer writer)
{
	struct co_od_info info;
	uint32_t ab = co_od_find(od, index, sub, &info);

	return ab != 0U ? ab : co_od_write_info(od, &info, data, len, writer);
}

/* ---------------------------------------------------------------------------------------- */
/* Chunked writes */

static bool streaming(const struct co_od_xfer *x)
{
	return INFO_PROV(&x->info) != NULL && (x->info.flags & CO_OD_F_STREAM);
}

static void xfer_end(struct co_od *od, struct co_od_xfer *x)
{
	if (od->scratch_owner == x) {
		od->scratch_owner = NULL;
	}
	x->scratch = false;
	x->active = false;
}

uint32_t co_od_write_begin(struct co_od *od, struct co_od_xfer *x, uint16_t index, uint8_t sub,
			   uint32_t total, enum co_od_writer writer)
{
	uint32_t ab;

	OD_ASSERT_LOCKED(od);
	/* A transfer restarted without an abort gives its staging buffer back first. */
	xfer_end(od, x);
	memset(x, 0, sizeof(*x));
	ab = co_od_find(od, index, sub, &x->info);
	if (ab == 0U) {
		ab = check_access(&x->info, writer);
	}
	if (ab != 0U) {
		return ab;
	}
	x->writer = writer;
	x->total = total;
	if (!streaming(x)) {
		if (total > x->info.size) {
			return CO_SDO_AB_DATA_LONG;
		}
		if (total != 0U && check_size(&x->info, total) != 0U) {
			return check_size(&x->info, total);
		}
		if (x->info.size > sizeof(x->small)) {
			if (x->info.size > CO_OD_SCRATCH_SIZE) {
				return CO_SDO_AB_OUT_OF_MEM;
			}
			if (od->scratch_owner != NULL) {
				return CO_SDO_AB_OUT_OF_MEM;
			}
			od->scratch_owner = x;
			x->scratch = true;
		}
	}
	x->active = true;
	return 0;
}

uint32_t co_od_write_chunk(struct co_od *od, struct co_od_xfer *x, uint32_t offset,
			   const void *data, size_t len, bool last)
{
	uint32_t ab = 0;

	OD_ASSERT_LOCKED(od);
	if (!x->active || offset != x->offset) {
		xfer_end(od, x);
		return CO_SDO_AB_GENERAL;
	}
	if (streaming(x)) {
		ab = x->info.prov->api->write(x->info.prov, &x->info, offset, data, len, last);
		x->offset += (uint32_t)len;
		if (ab == 0U && last) {
			struct co_od_req req = {
				.info = &x->info, .writer = x->writer, .data = data, .len = len};

			ab = run_validate(od, &req);
			if (ab == 0U || ab == CO_OD_HANDLED) {
				ab = 0U;
				run_notify(od, &req);
			}
		}
		if (ab != 0U || last) {
			xfer_end(od, x);
		}
		return ab;
	}
	if ((uint64_t)offset + len > x->info.size) {
		xfer_end(od, x);
		return CO_SDO_AB_DATA_LONG;
	}
	uint8_t *stage = x->scratch ? od->scratch : x->small;

	memcpy(stage + offset, data, len);
	x->offset += (uint32_t)len;
	if (last) {
		if (x->total != 0U && x->offset != x->total) {
			ab = x->offset < x->total ? CO_SDO_AB_DATA_SHORT : CO_SDO_AB_DATA_LONG;
		} else {
			ab = finish_write(od, &x->info, stage, x->offset, x->writer);
		}
		xfer_end(od, x);
	}
	return ab;
}

void co_od_write_abort(struct co_od *od, struct co_od_xfer *x)
{
	if (x->active && streaming(x)) {
		/* Tell a streaming provider the transfer is over (zero-length last chunk). */
		(void)x->info.prov->api->write(x->info.prov, &x->info, x->offset, NULL, 0, true);
	}
	xfer_end(od, x);
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
	decode_fixed(info.dtype, wire, value);
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

		decode_fixed(info.dtype, wire, back);
		if (memcmp(back, value, csize) != 0) {
			bool neg = k == 'i' && (int64_t)sign_extend(load_native(value, csize),
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
		decode_fixed(info.dtype, wire, t);
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
