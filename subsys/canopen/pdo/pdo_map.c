/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO mapping (CiA 301 §7.5.2.36/38): resolving and checking entries once, then moving bits
 * between frames and objects without lookups. Bits are numbered from bit 0 of byte 0 (the
 * CANopen little-endian order); an object's bits go to the frame least significant first.
 */

#include <string.h>

#include <zephyr/kernel.h>

/* The one copy of the frame paths in a size build (pdo_internal.h). */
#define CO_PDO_FRAME_DEFINE
#include "pdo_internal.h"

/* Length in bits of the dummy types 0001h-0007h (CiA 301 §7.4.7.1). */
static const uint8_t dummy_bits[8] = {0, 1, 8, 16, 32, 8, 16, 32};

static bool readable(uint8_t access)
{
	return access != CO_OD_ACCESS_WO;
}

static bool writable(uint8_t access)
{
	return access == CO_OD_ACCESS_WO || access == CO_OD_ACCESS_RW ||
	       access == CO_OD_ACCESS_RWR || access == CO_OD_ACCESS_RWW;
}

static bool mappable(const struct co_od_info *info, bool rx)
{
	if ((info->flags & CO_OD_F_MAP) == 0U) {
		return false;
	}
	if (rx) {
		return writable(info->access) && info->access != CO_OD_ACCESS_RWR &&
		       (info->flags & CO_OD_F_ROM) == 0U;
	}
	return readable(info->access) && info->access != CO_OD_ACCESS_RWW;
}

uint32_t co_pdo_map_check(const struct co_od *od, bool rx, uint32_t entry,
			  struct co_pdo_map_ent *ent)
{
	uint16_t index = CO_PDO_ENT_INDEX(entry);
	uint8_t sub = CO_PDO_ENT_SUB(entry);
	uint8_t bits = CO_PDO_ENT_BITS(entry);
	bool bitwise = IS_ENABLED(CONFIG_CANOPEN_PDO_BITWISE_MAPPING);

	memset(ent, 0, sizeof(*ent));
	ent->bits = bits;
	if (index >= 1U && index <= 7U) {
		/* Dummy entries only skip bits of received frames. */
		if (!rx || sub != 0U || bits != dummy_bits[index] ||
		    (!bitwise && bits % 8U != 0U)) {
			return CO_SDO_AB_NO_MAP;
		}
		ent->index = index;
		ent->entry = CO_OD_NO_ENTRY;
		ent->size = (uint8_t)(bits / 8U);
		ent->move = CO_PDO_MOVE_SKIP;
		return 0U;
	}
	struct co_od_info tmp;
	const struct co_od_info *info = &tmp;
	uint32_t ab = co_od_find(od, index, sub, &tmp);

	if (ab != 0U) {
		return ab;
	}
	co_pdo_ent_set(ent, info);
	ent->bits = bits;
	if (!mappable(info, rx) || bits == 0U) {
		return CO_SDO_AB_NO_MAP;
	}
	if (bits > CO_PDO_MAX_BITS) {
		return CO_SDO_AB_MAP_LEN;
	}
	uint32_t size_bits = info->size * 8U;

	if (bits > size_bits || (!bitwise && bits % 8U != 0U)) {
		return CO_SDO_AB_NO_MAP;
	}
	/* Part of an object: only the low-order bits of a fixed-size number (bit-wise mode). */
	if (bits < size_bits && (!bitwise || co_dtype_size(info->dtype) == 0U)) {
		return CO_SDO_AB_NO_MAP;
	}
	return 0U;
}

void co_pdo_bits_put(uint8_t *dst, unsigned int off, unsigned int n, const uint8_t *src)
{
	for (unsigned int i = 0; i < n; i++) {
		unsigned int d = off + i;
		uint8_t m = (uint8_t)(1U << (d % 8U));

		if ((src[i / 8U] >> (i % 8U)) & 1U) {
			dst[d / 8U] |= m;
		} else {
			dst[d / 8U] &= (uint8_t)~m;
		}
	}
}

void co_pdo_bits_get(const uint8_t *src, unsigned int off, unsigned int n, uint8_t *dst)
{
	for (unsigned int i = 0; i < n; i++) {
		unsigned int s = off + i;
		uint8_t m = (uint8_t)(1U << (i % 8U));

		if ((src[s / 8U] >> (s % 8U)) & 1U) {
			dst[i / 8U] |= m;
		} else {
			dst[i / 8U] &= (uint8_t)~m;
		}
	}
}

void co_pdo_ent_set(struct co_pdo_map_ent *ent, const struct co_od_info *info)
{
	ent->desc = CO_OD_PROVIDERS && info->prov != NULL ? NULL : info->desc;
	ent->index = info->index;
	ent->entry = info->entry;
	ent->sub = info->sub;
	/* A mapped object is a number of at most 8 bytes (co_pdo_map_check()). */
	ent->size = (uint8_t)(info->size <= 8U ? info->size : 8U);
	ent->bits = (uint8_t)(ent->size * 8U);
	ent->move = CO_PDO_MOVE_ACCESS;
}

const struct co_od_info *co_pdo_ent_info(const struct co_od *od, const struct co_pdo_map_ent *ent,
					 struct co_od_info *tmp)
{
	if (ent->desc == NULL) {
		return co_od_find(od, ent->index, ent->sub, tmp) == 0U ? tmp : NULL;
	}
	co_od_info_fill(od, ent->entry, ent->desc, tmp);
	return tmp;
}

uint32_t co_pdo_ent_read(const struct co_od *od, const struct co_pdo_map_ent *ent, uint8_t out[8],
			 enum co_od_writer reader)
{
	size_t len = 0;
	struct co_od_info tmp;
	const struct co_od_info *info = co_pdo_ent_info(od, ent, &tmp);
	unsigned int whole = co_pdo_ent_bits(ent) / 8U;
	uint32_t ab;

	memset(out, 0, 8);
	if (info == NULL) {
		return CO_SDO_AB_NO_OBJECT;
	}
	size_t cap = info->size < 8U ? info->size : 8U;

	ab = co_od_read_info(od, info, 0U, out, cap, &len, reader);
	if (ab != 0U) {
		memset(out, 0, 8);
		return ab;
	}
	/* Keep only the mapped bits (bit-wise mapping of part of a number). */
	if (co_pdo_ent_bits(ent) % 8U != 0U) {
		out[whole] &= (uint8_t)((1U << (co_pdo_ent_bits(ent) % 8U)) - 1U);
		whole++;
	}
	if (whole < 8U) {
		memset(&out[whole], 0, 8U - whole);
	}
	return 0U;
}

uint32_t co_pdo_ent_write(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t val[8],
			  enum co_od_writer writer)
{
	uint8_t buf[8];
	struct co_od_info tmp;
	const struct co_od_info *info = co_pdo_ent_info(od, ent, &tmp);

	if (info == NULL) {
		return CO_SDO_AB_NO_OBJECT;
	}
	uint32_t size = info->size;

	memcpy(buf, val, sizeof(buf));
	/* A signed number mapped in part keeps its sign. */
	if (co_pdo_ent_bits(ent) < size * 8U && co_dtype_class(info->dtype) == CO_DTYPE_CLASS_INT &&
	    ((buf[(co_pdo_ent_bits(ent) - 1U) / 8U] >> ((co_pdo_ent_bits(ent) - 1U) % 8U)) & 1U)) {
		for (unsigned int b = co_pdo_ent_bits(ent); b < size * 8U; b++) {
			buf[b / 8U] |= (uint8_t)(1U << (b % 8U));
		}
	}
	return co_od_write_info(od, info, buf, size, writer);
}

uint32_t co_pdo_ent_read_at(const struct co_od *od, const struct co_pdo_map_ent *ent, uint8_t *at)
{
	uint8_t val[8];
	uint32_t ab = co_pdo_ent_read(od, ent, val, CO_OD_WRITER_PDO);

	/* A refused read leaves zeros (val is zeroed then). */
	memcpy(at, val, co_pdo_ent_bits(ent) / 8U);
	return ab;
}

uint32_t co_pdo_ent_write_at(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t *at)
{
	uint8_t val[8] = {0};

	memcpy(val, at, co_pdo_ent_bits(ent) / 8U);
	return co_pdo_ent_write(od, ent, val, CO_OD_WRITER_PDO);
}

void co_pdo_ent_notify(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t *at)
{
	struct co_od_info info;

	/* The hooks see the object as co_od_find() describes it. */
	co_od_info_fill(od, ent->entry, ent->desc, &info);
	co_od_notify(od, &info, at, ent->size, CO_OD_WRITER_PDO);
}

void co_pdo_map_resolve(const struct co_od *od, struct co_pdo_map *map, bool rx)
{
	for (uint8_t i = 0; i < map->n; i++) {
		struct co_pdo_map_ent *ent = &map->ent[i];
		struct co_od_info info;
		enum co_od_move move;

		if (co_pdo_ent_is_dummy(ent)) {
			ent->move = CO_PDO_MOVE_SKIP;
			continue;
		}
		ent->move = CO_PDO_MOVE_ACCESS;
		/* A copy moves whole values of 1, 2, 4 or 8 bytes of the dictionary. */
		if (ent->desc == NULL || !co_pdo_ent_whole(ent) ||
		    (ent->size != 1U && ent->size != 2U && ent->size != 4U && ent->size != 8U)) {
			continue;
		}
		co_od_info_fill(od, ent->entry, ent->desc, &info);
		move = co_od_move_of(od, &info, CO_OD_WRITER_PDO, rx);
		if (move == CO_OD_MOVE_COPY) {
			ent->move = CO_PDO_MOVE_COPY;
		} else if (move == CO_OD_MOVE_COPY_NOTIFY) {
			int hook = co_od_notify_only(od, &info);

			ent->move = hook >= 0 ? CO_PDO_MOVE_COPY_HOOK : CO_PDO_MOVE_COPY_NOTIFY;
			ent->hook = hook >= 0 ? (uint16_t)hook : 0U;
		} else {
			/* through the accessors */
		}
	}
	map->hook_gen = od->hook_gen;
}

/*
 * Without bit-wise mapping co_pdo_map_check() lets through whole objects in whole bytes and
 * (RPDOs) dummies only, so every mapping is byte-wise and the per-bit paths below are not
 * taken; leaving them out of such a build saves their code.
 */
#define BITWISE IS_ENABLED(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)

uint8_t co_pdo_map_pack_bits(const struct co_od *od, const struct co_pdo_map *map, uint8_t data[8])
{
	uint8_t val[8];
	unsigned int off = 0;

	memset(data, 0, 8);
	if (!BITWISE) {
		return 0U;
	}
	for (uint8_t i = 0; i < map->n; i++) {
		const struct co_pdo_map_ent *ent = &map->ent[i];

		(void)co_pdo_ent_read(od, ent, val, CO_OD_WRITER_PDO);
		co_pdo_bits_put(data, off, co_pdo_ent_bits(ent), val);
		off += co_pdo_ent_bits(ent);
	}
	return (uint8_t)((map->bits + 7U) / 8U);
}

int co_pdo_map_unpack_bits(struct co_od *od, const struct co_pdo_map *map, const uint8_t *data)
{
	uint8_t val[8];
	unsigned int off = 0;
	int refused = 0;

	if (!BITWISE) {
		return 0;
	}
	for (uint8_t i = 0; i < map->n; i++) {
		const struct co_pdo_map_ent *ent = &map->ent[i];

		if (!co_pdo_ent_is_dummy(ent)) {
			memset(val, 0, sizeof(val));
			co_pdo_bits_get(data, off, co_pdo_ent_bits(ent), val);
			refused += co_pdo_ent_write(od, ent, val, CO_OD_WRITER_PDO) != 0U;
		}
		off += co_pdo_ent_bits(ent);
	}
	return refused;
}
