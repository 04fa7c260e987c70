/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * PDO mapping: entry checks, compilation and the pack/unpack of frames. Shared by the PDO
 * service and meant for the MPDO (which maps one object per frame: it can check an object
 * with co_pdo_map_check() and move its bytes with co_pdo_ent_read()/co_pdo_ent_write()).
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_PDO_PDO_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_PDO_PDO_INTERNAL_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/toolchain.h>

#include <canopen/od.h>
#include <canopen/pdo.h>

/* Inlined on the hot paths when optimising for speed; one copy in a size build (-Os). */
#if defined(__OPTIMIZE_SIZE__)
#define CO_HOT_INLINE inline
#else
#define CO_HOT_INLINE ALWAYS_INLINE
#endif

/*
 * An entry's hook-coverage cache for the cached accessors of od.h; without
 * CONFIG_CANOPEN_OD_COVER the entry has none and they do not use it.
 */
#if CO_OD_COVER
#define CO_PDO_ENT_COVER(ent) (&(ent)->cover)
#else
#define CO_PDO_ENT_COVER(ent) ((struct co_od_cover *)NULL)
#endif

/* Whether the copy-only path holds for @p map at hook generation @p gen (never without the
 * cache: the mapping then has no mark).
 */
#if CO_OD_COVER
#define CO_PDO_MAP_FAST(map, gen) ((map)->fast_gen == (gen))
#else
#define CO_PDO_MAP_FAST(map, gen) false
#endif

/* Largest data field of a classic CAN frame, in bits. */
#define CO_PDO_MAX_BITS 64U

/* Fields of a mapping entry (CiA 301 §7.5.2.36): index 31..16, sub 15..8, length 7..0. */
#define CO_PDO_ENT_INDEX(e) ((uint16_t)((e) >> 16))
#define CO_PDO_ENT_SUB(e)   ((uint8_t)((e) >> 8))
#define CO_PDO_ENT_BITS(e)  ((uint8_t)(e))

/*
 * Resolve and check one mapping entry for a PDO of the given direction.
 * rx: true for an RPDO (object written), false for a TPDO (object read).
 * Returns 0 and fills *ent, or the abort code: 06020000h no such object, 06090011h no such
 * sub-index, 06040041h not mappable in that direction / bad length / dummy in a TPDO.
 */
uint32_t co_pdo_map_check(const struct co_od *od, bool rx, uint32_t entry,
			  struct co_pdo_map_ent *ent);

#if !CO_PDO_ENT_INFO
/*
 * co_pdo_map_ent.kind (pdo.h): bit 7 a provider's object, whose size in bytes is in bits
 * 0-3; otherwise the object code in bits 0-3 and the group in bits 4-5.
 */
static inline bool co_pdo_kind_prov(uint8_t kind)
{
	return (kind & 0x80U) != 0U;
}

static inline uint8_t co_pdo_kind_low(uint8_t kind)
{
	return kind & 0x0FU;
}

static inline uint8_t co_pdo_kind_group(uint8_t kind)
{
	return (uint8_t)(kind >> 4U) & 0x03U;
}

static inline uint8_t co_pdo_kind_of(const struct co_od_info *info)
{
	if (CO_OD_PROVIDERS && info->desc == NULL) {
		/* A mapped object is a number of at most 8 bytes (co_pdo_map_check()). */
		return (uint8_t)(0x80U | (info->size & 0x0FU));
	}
	return (uint8_t)((info->objcode & 0x0FU) | ((uint32_t)(info->group & 0x03U) << 4U));
}
#endif

/* An entry's dictionary descriptor (NULL for a dummy and a provider's object). */
static inline const struct co_od_sub *co_pdo_ent_desc(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return ent->info.desc;
#else
	return ent->desc;
#endif
}

/* Whether an entry is an object of a provider (never without providers). */
static inline bool co_pdo_ent_is_prov(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return CO_OD_PROVIDERS && ent->info.prov != NULL;
#else
	return CO_OD_PROVIDERS && co_pdo_kind_prov(ent->kind);
#endif
}

/* Whether an entry is a dummy (skips bits of an RPDO). */
static inline bool co_pdo_ent_is_dummy(const struct co_pdo_map_ent *ent)
{
	return co_pdo_ent_desc(ent) == NULL && !co_pdo_ent_is_prov(ent);
}

/* An entry's object index (a dummy's: its type 0001h-0007h). */
static inline uint16_t co_pdo_ent_index(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return ent->info.index;
#else
	return ent->index;
#endif
}

/* An entry's sub-index (0 for a dummy). */
static inline uint8_t co_pdo_ent_sub(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return ent->info.sub;
#else
	return ent->sub;
#endif
}

/* An entry's object size on the wire in bytes (a dummy's: its type's whole bytes). */
static inline uint32_t co_pdo_ent_size(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return ent->info.size;
#else
	if (ent->desc != NULL) {
		return ent->desc->size;
	}
	if (co_pdo_ent_is_prov(ent)) {
		return co_pdo_kind_low(ent->kind);
	}
	return co_dtype_size(ent->index);
#endif
}

/* The size of an entry of a dictionary object (a marked mapping's: co_pdo_ent_desc() set). */
static inline uint32_t co_pdo_ent_desc_size(const struct co_pdo_map_ent *ent)
{
#if CO_PDO_ENT_INFO
	return ent->info.size;
#else
	return ent->desc->size;
#endif
}

/* Make @p ent a dummy entry of type @p index (0001h-0007h) of @p bytes whole bytes. */
static inline void co_pdo_ent_set_dummy(struct co_pdo_map_ent *ent, uint16_t index, uint32_t bytes)
{
#if CO_PDO_ENT_INFO
	ent->info.index = index;
	ent->info.dtype = (uint8_t)index;
	/* Its whole bytes: the length co_pdo_ent_bits() gives without bit-wise mapping. */
	ent->info.size = bytes;
#else
	/* Its whole bytes are its type's size (co_pdo_ent_size()). */
	(void)bytes;
	ent->index = index;
#endif
}

#if !CO_PDO_ENT_INFO
/*
 * A provider's object is described again by co_od_find(), as when it was mapped (a
 * provider's description stays what it was while it is registered): 0 or its abort code.
 */
uint32_t co_pdo_ent_prov_info(const struct co_od *od, const struct co_pdo_map_ent *ent,
			      struct co_od_info *tmp);
#endif

/*
 * The co_od_info of an entry that is not a dummy, for the accessors: its own, or rebuilt in
 * @p tmp from what a compact entry keeps; NULL if a provider no longer describes it.
 */
static inline const struct co_od_info *
co_pdo_ent_info(const struct co_od *od, const struct co_pdo_map_ent *ent, struct co_od_info *tmp)
{
#if CO_PDO_ENT_INFO
	(void)od;
	(void)tmp;
	return &ent->info;
#else
	if (co_pdo_ent_is_prov(ent)) {
		return co_pdo_ent_prov_info(od, ent, tmp) == 0U ? tmp : NULL;
	}
	co_od_info_fill(od, ent->desc, ent->index, co_pdo_kind_low(ent->kind),
			co_pdo_kind_group(ent->kind), tmp);
	return tmp;
#endif
}

/* As co_pdo_ent_info() for an entry with a descriptor, inline (the notify hooks of a frame). */
static inline const struct co_od_info *co_pdo_ent_desc_info(const struct co_od *od,
							    const struct co_pdo_map_ent *ent,
							    struct co_od_info *tmp)
{
#if CO_PDO_ENT_INFO
	(void)od;
	(void)tmp;
	return &ent->info;
#elif defined(__OPTIMIZE_SIZE__)
	co_od_info_fill(od, ent->desc, ent->index, co_pdo_kind_low(ent->kind),
			co_pdo_kind_group(ent->kind), tmp);
	return tmp;
#else
	co_od_info_fill_inline(od, ent->desc, ent->index, co_pdo_kind_low(ent->kind),
			       co_pdo_kind_group(ent->kind), tmp);
	return tmp;
#endif
}

/* Make @p ent the entry of the object @p info (from co_od_find(), mapped whole or in part). */
static inline void co_pdo_ent_set(struct co_pdo_map_ent *ent, const struct co_od_info *info)
{
#if CO_PDO_ENT_INFO
	ent->info = *info;
#else
	ent->desc = info->desc;
	ent->index = info->index;
	ent->sub = info->sub;
	ent->kind = co_pdo_kind_of(info);
#endif
}

/*
 * Mapped length of an entry in bits. Without bit-wise mapping co_pdo_map_check() lets only
 * whole objects in whole bytes through, and gives a dummy the size of its type, so the
 * length is the object's size and the entry does not store it.
 */
static inline unsigned int co_pdo_ent_bits(const struct co_pdo_map_ent *ent)
{
#if defined(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)
	return ent->bits;
#else
	return co_pdo_ent_size(ent) * 8U;
#endif
}

/* Whether an entry is its whole object in whole bytes (moved without masking). */
static inline bool co_pdo_ent_whole(const struct co_pdo_map_ent *ent)
{
#if defined(CONFIG_CANOPEN_PDO_BITWISE_MAPPING)
	return ent->whole;
#else
	return !co_pdo_ent_is_dummy(ent);
#endif
}

/*
 * The entry functions below keep ent->cover (which OD hooks cover the object) up to date,
 * hence the non-const entries.
 *
 * Read the mapped bits of an object as little-endian bytes into out[8] (zeroed above them).
 * Returns 0 or the reader's abort code (the bytes are then zero).
 */
uint32_t co_pdo_ent_read(const struct co_od *od, struct co_pdo_map_ent *ent, uint8_t out[8],
			 enum co_od_writer reader);

/* Write the mapped bits (little-endian in val[8]) to the object; returns the abort code. */
uint32_t co_pdo_ent_write(struct co_od *od, struct co_pdo_map_ent *ent, const uint8_t val[8],
			  enum co_od_writer writer);

/* Copy n bits of src (from bit 0) into dst at bit offset off; and the reverse. */
void co_pdo_bits_put(uint8_t *dst, unsigned int off, unsigned int n, const uint8_t *src);
void co_pdo_bits_get(const uint8_t *src, unsigned int off, unsigned int n, uint8_t *dst);

/*
 * Frames and objects. A mapping whose entries are all whole objects in whole bytes, each a
 * plain value for the PDO (co_od_cover_plain_write()/_read(): a copy, and for an RPDO at most
 * one notify hook), is marked with the hook generation at which it was found so
 * (map->fast_gen); while the dictionary's hook table stays as it was, a frame is a copy per
 * object and no per-object test. Anything else, and the first frame after a change, goes
 * through the cached accessors entry by entry (pdo_map.c), which then mark the mapping again.
 */

/* The general path of co_pdo_map_pack() (pdo_map.c). */
uint8_t co_pdo_map_pack_gen(const struct co_od *od, struct co_pdo_map *map, uint8_t data[8]);

/* The general path of co_pdo_map_unpack(), from entry @p from on at byte/bit offset @p off. */
int co_pdo_map_unpack_gen(struct co_od *od, struct co_pdo_map *map, const uint8_t *data,
			  uint8_t from, unsigned int off);

/* Sample every mapped object into data[8] (zero above the mapped bits); returns the frame
 * length in bytes. A refused read leaves zeros.
 */
static CO_HOT_INLINE uint8_t co_pdo_map_pack(const struct co_od *od, struct co_pdo_map *map,
					     uint8_t data[8])
{
#if CO_OD_COVER
	if (likely(CO_PDO_MAP_FAST(map, od->hook_gen))) {
		uint8_t frame[8] = {0};
		unsigned int off = 0;

		for (const struct co_pdo_map_ent *ent = map->ent; ent < map->ent + map->n; ent++) {
			/* A marked mapping holds whole dictionary objects only. */
			unsigned int bytes = co_pdo_ent_desc_size(ent);

			(void)co_od_copy_word(&frame[off], od->ram + co_pdo_ent_desc(ent)->offset,
					      bytes);
			off += bytes;
		}
		memcpy(data, frame, sizeof(frame));
		return (uint8_t)(off);
	}
#endif
	return co_pdo_map_pack_gen(od, map, data);
}

/*
 * Write every mapped object from data (at least the mapped bytes long); dummies are skipped.
 * Returns the number of objects whose write was refused.
 */
static CO_HOT_INLINE int co_pdo_map_unpack(struct co_od *od, struct co_pdo_map *map,
					   const uint8_t *data)
{
#if CO_OD_COVER
	uint32_t gen = od->hook_gen;

	if (likely(CO_PDO_MAP_FAST(map, gen))) {
		unsigned int off = 0;

		for (uint8_t i = 0; i < map->n; i++) {
			struct co_pdo_map_ent *ent = &map->ent[i];
			unsigned int bytes = co_pdo_ent_desc_size(ent);

			(void)co_od_copy_word(od->ram + co_pdo_ent_desc(ent)->offset, &data[off],
					      bytes);
#if CO_PDO_ENT_INFO
			co_od_cover_notify(od, &ent->info, &ent->cover, &data[off], bytes,
					   CO_OD_WRITER_PDO);
#else
			if ((ent->cover.flags & CO_OD_COVER_NOTIFY1) != 0U) {
				/* The hook sees the object as co_od_find() describes it. */
				struct co_od_info tmp;

				co_od_cover_notify(od, co_pdo_ent_desc_info(od, ent, &tmp),
						   &ent->cover, &data[off], bytes,
						   CO_OD_WRITER_PDO);
			}
#endif
			off += bytes;
			/* A hook that changed the hook table: the rest entry by entry. */
			if (unlikely(od->hook_gen != gen)) {
				return co_pdo_map_unpack_gen(od, map, data, i + 1U, off);
			}
		}
		return 0;
	}
#endif
	return co_pdo_map_unpack_gen(od, map, data, 0U, 0U);
}

struct co_node;
struct can_frame;

/* What became of a received MPDO (co_mpdo_rx()). */
enum co_mpdo_rx_result {
	CO_MPDO_RX_WRITTEN, /* the object was written */
	CO_MPDO_RX_IGNORED, /* not for us / not dispatched */
	CO_MPDO_RX_REFUSED, /* the dictionary refused the write */
	CO_MPDO_RX_MISSING, /* DAM: no such object (EMCY 8230h) */
};

/*
 * Send an MPDO frame (8 bytes) on an MPDO TPDO, now or at the end of its inhibit time
 * (pdo.c). Returns 0 or -EBUSY when a frame already waits for the inhibit time.
 */
int co_tpdo_mpdo_send(struct co_tpdo *t, const uint8_t data[8]);

#if defined(CONFIG_CANOPEN_MPDO)
/* Note the scanner/dispatcher objects of the dictionary and hook their writes (mpdo.c). */
int co_mpdo_init(struct co_node *node);

/* Process an MPDO of DLC 8 received by an RPDO whose mapping sub 0 is @p mode (mpdo.c). */
enum co_mpdo_rx_result co_mpdo_rx(struct co_node *node, uint8_t mode, const uint8_t data[8]);
#endif

#endif /* SAFELINE_SUBSYS_CANOPEN_PDO_PDO_INTERNAL_H_ */
