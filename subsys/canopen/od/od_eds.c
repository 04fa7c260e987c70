/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * EDS writer: prints the dictionary the firmware has, in the same form scripts/eds2od
 * writes NAME.eds (see gen.write_eds), so tools read exactly what the device holds.
 */

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "od_internal.h"

struct eds_out {
	int (*sink)(const char *s, size_t len, void *user);
	void *user;
	int err;
};

static void put(struct eds_out *o, const char *s, size_t len)
{
	if (o->err == 0 && len > 0U) {
		int r = o->sink(s, len, o->user);

		if (r < 0) {
			o->err = r;
		}
	}
}

static void puts_(struct eds_out *o, const char *s)
{
	put(o, s, strlen(s));
}

static void __attribute__((format(printf, 2, 3))) putf(struct eds_out *o, const char *fmt, ...)
{
	char buf[96];
	va_list ap;

	va_start(ap, fmt);
	int n = vsnprintf(buf, sizeof(buf), fmt, ap);

	va_end(ap);
	if (n > 0) {
		put(o, buf, (size_t)n < sizeof(buf) ? (size_t)n : sizeof(buf) - 1U);
	}
}

static void put_hex(struct eds_out *o, const uint8_t *p, size_t n)
{
	static const char digits[] = "0123456789ABCDEF";

	for (size_t i = 0; i < n; i++) {
		char b[2] = {digits[p[i] >> 4], digits[p[i] & 0xFU]};

		put(o, b, 2);
	}
}

/* One byte of a UTF-8 sequence; v is masked to its 8 bits by the caller's lead or 0x3F. */
static char utf8_byte(uint32_t v)
{
	return (char)(uint8_t)v;
}

/* UTF-16 units to UTF-8, stopping at the first NUL unit. */
static void put_utf16(struct eds_out *o, const uint8_t *mem, size_t units)
{
	for (size_t i = 0; i < units; i++) {
		uint16_t u;
		uint32_t cp;
		char b[4];
		size_t n;

		memcpy(&u, mem + 2U * i, 2);
		if (u == 0U) {
			break;
		}
		cp = u;
		if (u >= 0xD800U && u <= 0xDBFFU && i + 1U < units) {
			uint16_t lo;

			memcpy(&lo, mem + 2U * (i + 1U), 2);
			if (lo >= 0xDC00U && lo <= 0xDFFFU) {
				cp = 0x10000U + (((uint32_t)u - 0xD800U) << 10) + (lo - 0xDC00U);
				i++;
			}
		}
		if (cp < 0x80U) {
			b[0] = (char)cp;
			n = 1;
		} else if (cp < 0x800U) {
			b[0] = utf8_byte(0xC0U | (cp >> 6));
			b[1] = utf8_byte(0x80U | (cp & 0x3FU));
			n = 2;
		} else if (cp < 0x10000U) {
			b[0] = utf8_byte(0xE0U | (cp >> 12));
			b[1] = utf8_byte(0x80U | ((cp >> 6) & 0x3FU));
			b[2] = utf8_byte(0x80U | (cp & 0x3FU));
			n = 3;
		} else {
			b[0] = utf8_byte(0xF0U | (cp >> 18));
			b[1] = utf8_byte(0x80U | ((cp >> 12) & 0x3FU));
			b[2] = utf8_byte(0x80U | ((cp >> 6) & 0x3FU));
			b[3] = utf8_byte(0x80U | (cp & 0x3FU));
			n = 4;
		}
		put(o, b, n);
	}
}

static void put_num(struct eds_out *o, uint8_t dtype, union co_od_num v)
{
	switch (co_dtype_class(dtype)) {
	case CO_DTYPE_CLASS_INT:
		putf(o, "%" PRId64, v.i);
		break;
	case CO_DTYPE_CLASS_REAL:
		putf(o, co_dtype_size(dtype) == 4U ? "%.9g" : "%.17g", v.f);
		break;
	default:
		putf(o, "0x%" PRIX64, v.u);
		break;
	}
}

/* The default value held in memory, formatted like gen.eds_value(). */
static void put_value(struct eds_out *o, const struct co_od_sub *d, const uint8_t *mem)
{
	uint32_t size = co_dtype_size(d->dtype);

	switch (co_dtype_class(d->dtype)) {
	case CO_DTYPE_CLASS_VSTR:
		put(o, (const char *)mem, co_od_mem_length(d, mem));
		return;
	case CO_DTYPE_CLASS_OSTR:
		put_hex(o, mem, d->size);
		return;
	case CO_DTYPE_CLASS_DOMAIN:
		put_hex(o, mem + sizeof(uint32_t), co_od_mem_length(d, mem));
		return;
	case CO_DTYPE_CLASS_USTR:
		put_utf16(o, mem, d->size / 2U);
		return;
	default:
		break;
	}
	uint8_t wire[8];
	uint64_t raw;
	union co_od_num v;

	co_od_encode_fixed(d->dtype, mem, wire);
	raw = co_od_le_get(wire, size);
	if (co_dtype_class(d->dtype) == CO_DTYPE_CLASS_INT) {
		uint64_t sign = (uint64_t)1 << (8U * size - 1U);

		v.i = size >= 8U ? (int64_t)raw : (int64_t)((raw ^ sign) - sign);
	} else if (co_dtype_class(d->dtype) == CO_DTYPE_CLASS_REAL) {
		if (size == 4U) {
			uint32_t bits = (uint32_t)raw;
			float f;

			memcpy(&f, &bits, sizeof(f));
			v.f = f;
		} else {
			memcpy(&v.f, &raw, sizeof(v.f));
		}
	} else {
		v.u = raw;
	}
	put_num(o, d->dtype, v);
}

static void put_rel(struct eds_out *o, uint8_t dtype, int64_t base)
{
	if (co_dtype_class(dtype) == CO_DTYPE_CLASS_UINT) {
		putf(o, "$NODEID+0x%" PRIX64, (uint64_t)base);
	} else {
		putf(o, "$NODEID+%" PRId64, base);
	}
}

static uint32_t default_len(const struct co_od_sub *d, const uint8_t *mem)
{
	if (!(d->flags & CO_OD_F_DEFAULT)) {
		return 0;
	}
	return co_od_mem_length(d, mem);
}

static const char *const access_names[] = {"ro", "wo", "rw", "rwr", "rww", "const"};

static void put_sub(struct eds_out *o, const struct co_od_def *def, const struct co_od_entry *e,
		    uint32_t pos, bool top)
{
	const struct co_od_sub *d = &def->subs[pos];
	const uint8_t *mem = co_od_mem(def, def->ram_defaults, d);
	bool storage = !(co_dtype_class(d->dtype) == CO_DTYPE_CLASS_DOMAIN && d->size == 0U);

	if (top) {
		putf(o, "[%04X]\n", e->index);
	} else {
		putf(o, "[%04Xsub%X]\n", e->index, d->sub);
	}
	puts_(o, "ParameterName=");
	puts_(o, def->names + d->name);
	putf(o, "\nObjectType=0x%X\n", top ? e->objcode : 0x7U);
	putf(o, "DataType=0x%04X\nAccessType=%s\n", d->dtype,
	     d->access < 6U ? access_names[d->access] : "ro");
	if ((d->flags & CO_OD_F_DEFAULT) != 0U) {
		const struct co_od_nodeid *n = co_od_nodeid_of(def, pos);

		puts_(o, "DefaultValue=");
		if (n != NULL) {
			put_rel(o, d->dtype, n->base);
		} else if (storage) {
			put_value(o, d, mem);
		} else {
			/* A DOMAIN without storage has no default: the key stays empty. */
		}
		puts_(o, "\n");
	}
	putf(o, "PDOMapping=%u\n", (d->flags & CO_OD_F_MAP) ? 1U : 0U);
	if ((d->flags & CO_OD_F_LIMITS) != 0U) {
		const struct co_od_limit *l = &def->limits[d->limit];

		if ((l->rel & CO_OD_LIM_LO_GIVEN) != 0U) {
			puts_(o, "LowLimit=");
			if ((l->rel & CO_OD_LIM_LO_REL) != 0U) {
				put_rel(o, d->dtype, l->lo.i);
			} else {
				put_num(o, d->dtype, l->lo);
			}
			puts_(o, "\n");
		}
		if ((l->rel & CO_OD_LIM_HI_GIVEN) != 0U) {
			puts_(o, "HighLimit=");
			if ((l->rel & CO_OD_LIM_HI_REL) != 0U) {
				put_rel(o, d->dtype, l->hi.i);
			} else {
				put_num(o, d->dtype, l->hi);
			}
			puts_(o, "\n");
		}
	}
	if (co_dtype_size(d->dtype) == 0U && d->size != (storage ? default_len(d, mem) : 0U)) {
		putf(o, "SafeLineSize=%" PRIu32 "\n", d->size);
	}
	puts_(o, "\n");
}

static int list_of(uint16_t index)
{
	if (index == 0x1000U || index == 0x1001U || index == 0x1018U) {
		return 0;
	}
	if (index >= 0x2000U && index <= 0x5FFFU) {
		return 2;
	}
	return 1;
}

int co_od_eds_write(const struct co_od *od, int (*sink)(const char *s, size_t len, void *user),
		    void *user_data)
{
	static const char *const lists[] = {"MandatoryObjects", "OptionalObjects",
					    "ManufacturerObjects"};
	const struct co_od_def *def = od->def;
	struct eds_out o = {.sink = sink, .user = user_data};

	if (def->names == NULL || def->eds_header == NULL) {
		return -ENOTSUP;
	}
	puts_(&o, def->eds_header);
	for (int li = 0; li < 3; li++) {
		unsigned int n = 0;

		for (uint16_t i = 0; i < def->n_entries; i++) {
			n += list_of(def->entries[i].index) == li ? 1U : 0U;
		}
		putf(&o, "[%s]\nSupportedObjects=%u\n", lists[li], n);
		n = 0;
		for (uint16_t i = 0; i < def->n_entries; i++) {
			if (list_of(def->entries[i].index) == li) {
				putf(&o, "%u=0x%04X\n", ++n, def->entries[i].index);
			}
		}
		puts_(&o, "\n");
		for (uint16_t i = 0; i < def->n_entries; i++) {
			const struct co_od_entry *e = &def->entries[i];

			if (list_of(e->index) != li) {
				continue;
			}
			if (e->objcode == CO_OD_OBJ_VAR || e->objcode == CO_OD_OBJ_DOMAIN ||
			    e->objcode == CO_OD_OBJ_DEFTYPE) {
				put_sub(&o, def, e, e->first, true);
				continue;
			}
			putf(&o, "[%04X]\nParameterName=", e->index);
			puts_(&o, def->names + e->name);
			putf(&o, "\nObjectType=0x%X\nSubNumber=0x%X\n\n", e->objcode, e->n_subs);
			for (uint16_t s = 0; s < e->n_subs; s++) {
				put_sub(&o, def, e, (uint32_t)e->first + s, false);
			}
		}
	}
	return o.err;
}
