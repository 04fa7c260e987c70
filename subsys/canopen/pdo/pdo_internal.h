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

/* An entry's dictionary descriptor (NULL for a dummy and a provider's object). */
static inline const struct co_od_sub *co_pdo_ent_desc(const struct co_pdo_map_ent *ent)
{
	return ent->desc;
}

/* Whether an entry is an object of a provider (never without providers). */
static inline bool co_pdo_ent_is_prov(const struct co_pdo_map_ent *ent)
{
	return CO_OD_PROVIDERS && ent->desc == NULL && ent->index > 7U;
}

/* Whether an entry is a dummy (skips bits of an RPDO). */
static inline bool co_pdo_ent_is_dummy(const struct co_pdo_map_ent *ent)
{
	return ent->desc == NULL && ent->index <= 7U;
}

/* An entry's object index (a dummy's: its type 0001h-0007h). */
static inline uint16_t co_pdo_ent_index(const struct co_pdo_map_ent *ent)
{
	return ent->index;
}

/* An entry's sub-index (0 for a dummy). */
static inline uint8_t co_pdo_ent_sub(const struct co_pdo_map_ent *ent)
{
	return ent->sub;
}

/* An entry's object size on the wire in bytes (a dummy's: its type's whole bytes). */
static inline uint32_t co_pdo_ent_size(const struct co_pdo_map_ent *ent)
{
	return ent->size;
}

/* Mapped length of an entry in bits. */
static inline unsigned int co_pdo_ent_bits(const struct co_pdo_map_ent *ent)
{
	return ent->bits;
}

/* Whether an entry is its whole object in whole bytes (moved without masking). */
static inline bool co_pdo_ent_whole(const struct co_pdo_map_ent *ent)
{
	return !co_pdo_ent_is_dummy(ent) && ent->bits == ent->size * 8U;
}

/* Make @p ent the entry of the object @p info (from co_od_find(), mapped whole or in part). */
void co_pdo_ent_set(struct co_pdo_map_ent *ent, const struct co_od_info *info);

/*
 * The co_od_info of an entry that is not a dummy, for the accessors and hooks: rebuilt in
 * @p tmp from the descriptor, or described again by the provider (a provider's description
 * stays what it was while it is registered); NULL if the provider no longer describes it.
 */
const struct co_od_info *co_pdo_ent_info(const struct co_od *od, const struct co_pdo_map_ent *ent,
					 struct co_od_info *tmp);

/*
 * Read the mapped bits of an object as little-endian bytes into out[8] (zeroed above them).
 * Returns 0 or the reader's abort code (the bytes are then zero).
 */
uint32_t co_pdo_ent_read(const struct co_od *od, const struct co_pdo_map_ent *ent, uint8_t out[8],
			 enum co_od_writer reader);

/* Write the mapped bits (little-endian in val[8]) to the object; returns the abort code. */
uint32_t co_pdo_ent_write(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t val[8],
			  enum co_od_writer writer);

/* Copy n bits of src (from bit 0) into dst at bit offset off; and the reverse. */
void co_pdo_bits_put(uint8_t *dst, unsigned int off, unsigned int n, const uint8_t *src);
void co_pdo_bits_get(const uint8_t *src, unsigned int off, unsigned int n, uint8_t *dst);

/*
 * Frames and objects. Each entry of a mapping is resolved to how a frame moves it
 * (co_pdo_map_ent.move, co_od_move_of()): a copy, for an RPDO a copy and the object's notify
 * hooks, or the dictionary's accessors. The moves hold while the dictionary's hooks are what
 * they were when they were resolved (co_pdo_map.hook_gen, compared once per frame).
 */

/* Resolve every entry's move for the dictionary's hooks as they are now (pdo_map.c). */
void co_pdo_map_resolve(const struct co_od *od, struct co_pdo_map *map, bool rx);

/* A bit-wise mapping's frame (pdo_map.c). */
uint8_t co_pdo_map_pack_bits(const struct co_od *od, const struct co_pdo_map *map, uint8_t data[8]);
int co_pdo_map_unpack_bits(struct co_od *od, const struct co_pdo_map *map, const uint8_t *data);

/* An entry moved through the accessors, whole bytes at @p at (pdo_map.c). */
uint32_t co_pdo_ent_read_at(const struct co_od *od, const struct co_pdo_map_ent *ent, uint8_t *at);
uint32_t co_pdo_ent_write_at(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t *at);
/* An entry's notify hooks after its copy (pdo_map.c). */
void co_pdo_ent_notify(struct co_od *od, const struct co_pdo_map_ent *ent, const uint8_t *at);

/*
 * The frame paths: inline in the RPDO and SYNC paths when optimising for speed; in a size
 * build (-Os) one copy each, in pdo_map.c (CO_PDO_FRAME_DEFINE).
 */
#if defined(__OPTIMIZE_SIZE__) && !defined(CO_PDO_FRAME_DEFINE)
uint8_t co_pdo_map_pack(const struct co_od *od, struct co_pdo_map *map, uint8_t data[8]);
int co_pdo_map_unpack(struct co_od *od, struct co_pdo_map *map, const uint8_t *data);
#else
#if defined(__OPTIMIZE_SIZE__)
#define CO_PDO_FRAME_FN
#else
#define CO_PDO_FRAME_FN static ALWAYS_INLINE
#endif

/* Sample every mapped object into data[8] (zero above the mapped bits); returns the frame
 * length in bytes. A refused read leaves zeros.
 */
CO_PDO_FRAME_FN uint8_t co_pdo_map_pack(const struct co_od *od, struct co_pdo_map *map,
					uint8_t data[8])
{
	if (unlikely(map->hook_gen != od->hook_gen)) {
		co_pdo_map_resolve(od, map, false);
	}
	if (unlikely(!map->bytewise)) {
		return co_pdo_map_pack_bits(od, map, data);
	}
	uint8_t frame[8] = {0};
	unsigned int off = 0;

	for (const struct co_pdo_map_ent *ent = map->ent; ent < map->ent + map->n; ent++) {
		if (likely(ent->move == CO_PDO_MOVE_COPY)) {
			(void)co_od_copy_word(&frame[off], od->ram + ent->desc->offset, ent->size);
		} else {
			(void)co_pdo_ent_read_at(od, ent, &frame[off]);
		}
		off += ent->bits / 8U;
	}
	memcpy(data, frame, sizeof(frame));
	return (uint8_t)off;
}

/*
 * Write every mapped object from data (at least the mapped bytes long); dummies are skipped.
 * Returns the number of objects whose write was refused.
 */
CO_PDO_FRAME_FN int co_pdo_map_unpack(struct co_od *od, struct co_pdo_map *map, const uint8_t *data)
{
	if (unlikely(map->hook_gen != od->hook_gen)) {
		co_pdo_map_resolve(od, map, true);
	}
	if (unlikely(!map->bytewise)) {
		return co_pdo_map_unpack_bits(od, map, data);
	}
	unsigned int off = 0;
	int refused = 0;

	for (const struct co_pdo_map_ent *ent = map->ent; ent < map->ent + map->n; ent++) {
		switch (ent->move) {
		case CO_PDO_MOVE_COPY:
			(void)co_od_copy_word(od->ram + ent->desc->offset, &data[off], ent->size);
			break;
		case CO_PDO_MOVE_COPY_HOOK: {
			(void)co_od_copy_word(od->ram + ent->desc->offset, &data[off], ent->size);
			/*
			 * The pass of the object's one hook: one call (od.h, co_od_notify_only()).
			 * It sees the object as co_od_find() describes it; a copied object has no
			 * limits and no provider.
			 */
			const struct co_od_entry *e = &od->def->entries[ent->entry];
			const struct co_od_info info = {
				.desc = ent->desc,
				.size = ent->size,
				.index = ent->index,
				.sub = ent->sub,
				.dtype = ent->desc->dtype,
				.access = ent->desc->access,
				.flags = ent->desc->flags,
				.objcode = e->objcode,
				.group = e->group,
				.entry = ent->entry,
			};
			const struct co_od_req req = {.info = &info,
						      .writer = CO_OD_WRITER_PDO,
						      .data = &data[off],
						      .len = ent->size};
			const struct co_od_hook *h = &od->hooks[ent->hook].hook;

			h->notify(od, &req, h->user_data);
			if (unlikely(map->hook_gen != od->hook_gen)) {
				co_pdo_map_resolve(od, map, true);
			}
			break;
		}
		case CO_PDO_MOVE_COPY_NOTIFY:
			(void)co_od_copy_word(od->ram + ent->desc->offset, &data[off], ent->size);
			co_pdo_ent_notify(od, ent, &data[off]);
			/* A hook that changed the hooks: the next entries' moves are resolved
			 * again. */
			if (unlikely(map->hook_gen != od->hook_gen)) {
				co_pdo_map_resolve(od, map, true);
			}
			break;
		case CO_PDO_MOVE_ACCESS:
			refused += co_pdo_ent_write_at(od, ent, &data[off]) != 0U;
			if (unlikely(map->hook_gen != od->hook_gen)) {
				co_pdo_map_resolve(od, map, true);
			}
			break;
		default:
			break;
		}
		off += ent->bits / 8U;
	}
	return refused;
}
#endif /* the frame paths */

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
