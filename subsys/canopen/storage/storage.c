/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * 1010h/1011h parameter storage with two image slots.
 *
 * Slot layout (little endian):
 *   0  magic  "SLS1", written last: the commit mark of the image
 *   4  seq    image sequence number; the valid slot with the newer one is current
 *   8  len    payload length
 *   12 crc    CRC-32 over seq, len and the payload
 *   16 payload: blocks of [group u8, 3 x 0, len u32] + records
 *      record: index u16, sub u8, flags u8 (bit 0: $NODEID default), len u16, data
 *
 * A save first clears the magic of the slot it writes (the one not in force), writes the
 * payload and header, syncs, then writes the magic and syncs again. Until the 4 magic bytes
 * are all on the medium that slot is invalid, so a cut at any byte leaves the other slot
 * (the previous image) in force.
 */

#include <errno.h>
#include <string.h>

#include <canopen/storage.h>

#define SLOT_MAGIC   0x31534C53U /* "SLS1" */
#define SLOT_HDR     16U
#define BLOCK_HDR    8U
#define REC_HDR      6U
#define REC_F_NODEID 0x01U

static uint32_t crc32_update(uint32_t crc, const uint8_t *p, size_t len)
{
	for (size_t i = 0; i < len; i++) {
		crc ^= p[i];
		for (int b = 0; b < 8; b++) {
			crc = (crc >> 1) ^ (0xEDB88320U & (0U - (crc & 1U)));
		}
	}
	return crc;
}

static uint32_t slot_base(const struct co_storage *st, int slot)
{
	return (uint32_t)slot * st->slot_size;
}

static int be_read(const struct co_storage *st, uint32_t off, void *buf, size_t len)
{
	return st->be->api->read(st->be, off, buf, len);
}

/* Check a slot: magic, length and CRC. */
static int slot_check(struct co_storage *st, int slot, uint32_t *seq, uint32_t *len)
{
	uint8_t hdr[SLOT_HDR];
	uint32_t base = slot_base(st, slot);
	int err = be_read(st, base, hdr, sizeof(hdr));

	if (err != 0) {
		return err;
	}
	if (co_od_le_get(hdr, 4) != SLOT_MAGIC) {
		return -ENOENT;
	}
	*seq = (uint32_t)co_od_le_get(hdr + 4, 4);
	*len = (uint32_t)co_od_le_get(hdr + 8, 4);
	if (*len > st->slot_size - SLOT_HDR) {
		return -EBADMSG;
	}
	uint32_t crc = crc32_update(0xFFFFFFFFU, hdr + 4, 8);

	uint32_t pos = 0U;

	while (pos < *len) {
		size_t n = *len - pos < sizeof(st->buf) ? *len - pos : sizeof(st->buf);

		err = be_read(st, base + SLOT_HDR + pos, st->buf, n);
		if (err != 0) {
			return err;
		}
		crc = crc32_update(crc, st->buf, n);
		pos += (uint32_t)n;
	}
	return (crc ^ 0xFFFFFFFFU) == (uint32_t)co_od_le_get(hdr + 12, 4) ? 0 : -EBADMSG;
}

static int find_current(struct co_storage *st)
{
	uint32_t seq[2];
	uint32_t len;
	bool ok[2];

	for (int s = 0; s < 2; s++) {
		int err = slot_check(st, s, &seq[s], &len);

		if (err == -EIO) {
			return err;
		}
		ok[s] = err == 0;
	}
	st->active = -1;
	if (ok[0] && ok[1]) {
		/* Serial-number arithmetic: the newer image wins, also across wrap-around. */
		st->active = (int32_t)(seq[1] - seq[0]) > 0 ? 1 : 0;
	} else if (ok[0] || ok[1]) {
		st->active = ok[0] ? 0 : 1;
	} else {
		/* No valid image: active stays -1. */
	}
	st->seq = st->active >= 0 ? seq[st->active] : 0U;
	return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Image writer */

struct img {
	struct co_storage *st;
	uint32_t base;
	uint32_t pos; /* payload bytes written */
	uint32_t crc;
	int err;
};

static void img_put(struct img *w, const void *data, size_t len)
{
	if (w->err != 0 || len == 0U) {
		return;
	}
	w->err = w->st->be->api->write(w->st->be, w->base + SLOT_HDR + w->pos, data, len);
	w->crc = crc32_update(w->crc, data, len);
	w->pos += (uint32_t)len;
}

/* Walk the stored subs of one group: size them, or write them when w is not NULL. */
static uint32_t group_records(struct co_storage *st, uint8_t group, struct img *w)
{
	const struct co_od_def *def = st->od->def;
	uint32_t total = 0;

	for (uint16_t i = 0; i < def->n_entries; i++) {
		const struct co_od_entry *e = &def->entries[i];

		if (e->group != group) {
			continue;
		}
		for (uint16_t s = 0; s < e->n_subs; s++) {
			const struct co_od_sub *d = &def->subs[e->first + s];
			struct co_od_info info;

			if (!(d->flags & CO_OD_F_STORE) ||
			    co_od_find(st->od, e->index, d->sub, &info) != 0U || info.desc != d) {
				continue;
			}
			uint32_t len = co_od_length(st->od, &info);

			total += REC_HDR + len;
			if (w == NULL) {
				continue;
			}
			uint8_t hdr[REC_HDR];

			co_od_le_put(hdr, 2, e->index);
			hdr[2] = d->sub;
			hdr[3] = co_od_is_nodeid_default(st->od, &info) ? REC_F_NODEID : 0U;
			co_od_le_put(hdr + 4, 2, len);
			img_put(w, hdr, sizeof(hdr));
			uint32_t off = 0U;

			while (off < len) {
				size_t n;

				(void)co_od_read_info(st->od, &info, off, st->buf, sizeof(st->buf),
						      &n, CO_OD_WRITER_APP);
				if (n == 0U) {
					w->err = w->err != 0 ? w->err : -EIO;
					break;
				}
				img_put(w, st->buf, n);
				off += (uint32_t)n;
			}
		}
	}
	return total;
}

/* Find block `group` in the current image; returns its payload offset or -1. */
static int32_t old_block(struct co_storage *st, uint8_t group, uint32_t *blen)
{
	uint32_t seq;
	uint32_t len;

	if (st->active < 0 || slot_check(st, st->active, &seq, &len) != 0) {
		return -1;
	}
	uint32_t base = slot_base(st, st->active) + SLOT_HDR;

	for (uint32_t pos = 0; pos + BLOCK_HDR <= len;) {
		uint8_t hdr[BLOCK_HDR];

		if (be_read(st, base + pos, hdr, sizeof(hdr)) != 0) {
			return -1;
		}
		uint32_t l = (uint32_t)co_od_le_get(hdr + 4, 4);

		if (l > len - pos - BLOCK_HDR) {
			return -1;
		}
		if (hdr[0] == group) {
			*blen = l;
			return (int32_t)(pos + BLOCK_HDR);
		}
		pos += BLOCK_HDR + l;
	}
	return -1;
}

static int write_image(struct co_storage *st, uint32_t save_mask, uint32_t drop_mask)
{
	int slot = st->active == 0 ? 1 : 0;
	uint32_t seq = st->seq + 1U;
	uint32_t size[CO_OD_GROUP_COUNT] = {0};
	int32_t keep[CO_OD_GROUP_COUNT];
	uint32_t total = 0;
	uint8_t b4[4] = {0};
	int err;

	for (uint8_t g = 1; g < CO_OD_GROUP_COUNT; g++) {
		keep[g] = -1;
		if ((save_mask & CO_OD_GROUP_BIT(g)) != 0U) {
			size[g] = group_records(st, g, NULL);
			total += BLOCK_HDR + size[g];
		} else if ((drop_mask & CO_OD_GROUP_BIT(g)) == 0U) {
			keep[g] = old_block(st, g, &size[g]);
			if (keep[g] >= 0) {
				total += BLOCK_HDR + size[g];
			}
		} else {
			/* Dropped: keep[g] = -1 leaves the group out of the new image. */
		}
	}
	if (total > st->slot_size - SLOT_HDR) {
		return -ENOSPC;
	}
	struct img w = {.st = st, .base = slot_base(st, slot)};

	/* 1. The slot we overwrite stops being valid before any of it changes. */
	err = st->be->api->write(st->be, w.base, b4, sizeof(b4));
	if (err == 0) {
		err = st->be->api->sync(st->be);
	}
	if (err != 0) {
		return err;
	}
	/* 2. Payload. */
	uint8_t sl[8];

	co_od_le_put(sl, 4, seq);
	co_od_le_put(sl + 4, 4, total);
	w.crc = crc32_update(0xFFFFFFFFU, sl, sizeof(sl));
	for (uint8_t g = 1; g < CO_OD_GROUP_COUNT && w.err == 0; g++) {
		bool fresh = (save_mask & CO_OD_GROUP_BIT(g)) != 0U;

		if (!fresh && keep[g] < 0) {
			continue;
		}
		uint8_t bh[BLOCK_HDR] = {g, 0, 0, 0};

		co_od_le_put(bh + 4, 4, size[g]);
		img_put(&w, bh, sizeof(bh));
		if (fresh) {
			uint32_t start = w.pos;

			(void)group_records(st, g, &w);
			if (w.err == 0 && w.pos - start != size[g]) {
				w.err = -EIO; /* values changed while saving */
			}
			continue;
		}
		uint32_t from = slot_base(st, st->active) + SLOT_HDR + (uint32_t)keep[g];

		for (uint32_t off = 0; off < size[g] && w.err == 0;) {
			size_t n =
				size[g] - off < sizeof(st->buf) ? size[g] - off : sizeof(st->buf);

			w.err = be_read(st, from + off, st->buf, n);
			img_put(&w, st->buf, n);
			off += (uint32_t)n;
		}
	}
	if (w.err != 0) {
		return w.err;
	}
	/* 3. Header, sync, then the commit mark. */
	uint8_t hdr[12];

	(void)memcpy(hdr, sl, sizeof(sl));
	co_od_le_put(hdr + 8, 4, w.crc ^ 0xFFFFFFFFU);
	err = st->be->api->write(st->be, w.base + 4U, hdr, sizeof(hdr));
	if (err == 0) {
		err = st->be->api->sync(st->be);
	}
	if (err == 0) {
		co_od_le_put(b4, 4, SLOT_MAGIC);
		err = st->be->api->write(st->be, w.base, b4, sizeof(b4));
	}
	if (err == 0) {
		err = st->be->api->sync(st->be);
	}
	if (err != 0) {
		return err;
	}
	st->active = (int8_t)slot;
	st->seq = seq;
	return 0;
}

int co_storage_save(struct co_storage *st, uint32_t group_mask)
{
	if (st->absent) {
		return -ENODEV;
	}
	return write_image(st, group_mask & CO_OD_GROUP_ALL, 0);
}

int co_storage_clear(struct co_storage *st, uint32_t group_mask)
{
	if (st->absent) {
		return -ENODEV;
	}
	return write_image(st, 0, group_mask & CO_OD_GROUP_ALL);
}

/* ---------------------------------------------------------------------------------------- */
/* Restore */

static void restore_record(struct co_storage *st, uint32_t at, const uint8_t *hdr)
{
	uint16_t index = (uint16_t)co_od_le_get(hdr, 2);
	uint8_t sub = hdr[2];
	uint32_t len = (uint32_t)co_od_le_get(hdr + 4, 2);
	struct co_od_info info;

	if (co_od_find(st->od, index, sub, &info) != 0U || info.desc == NULL ||
	    !(info.flags & CO_OD_F_STORE) || len > info.size) {
		st->skipped++;
		return;
	}
	if ((hdr[3] & REC_F_NODEID) && (info.flags & CO_OD_F_NODEID)) {
		return; /* the reset computed it for the present node-ID */
	}
	if (len <= sizeof(st->buf)) {
		if (be_read(st, at, st->buf, len) != 0 ||
		    co_od_write_info(st->od, &info, st->buf, len, CO_OD_WRITER_STORAGE) != 0U) {
			st->skipped++;
		}
		return;
	}
	struct co_od_xfer x;

	if (co_od_write_begin(st->od, &x, index, sub, len, CO_OD_WRITER_STORAGE) != 0U) {
		st->skipped++;
		return;
	}
	uint32_t off = 0U;

	while (off < len) {
		size_t n = len - off < sizeof(st->buf) ? len - off : sizeof(st->buf);

		if (be_read(st, at + off, st->buf, n) != 0 ||
		    co_od_write_chunk(st->od, &x, off, st->buf, n, off + n == len) != 0U) {
			co_od_write_abort(st->od, &x);
			st->skipped++;
			return;
		}
		off += (uint32_t)n;
	}
}

int co_storage_restore(struct co_storage *st, uint32_t group_mask)
{
	uint32_t seq;
	uint32_t len;

	st->skipped = 0;
	if (st->active < 0) {
		return 0;
	}
	int err = slot_check(st, st->active, &seq, &len);

	if (err == -EIO) {
		return err;
	}
	if (err != 0) {
		/* The medium changed under us: nothing trustworthy to restore. */
		st->active = -1;
		return 0;
	}
	uint32_t base = slot_base(st, st->active) + SLOT_HDR;

	for (uint32_t pos = 0; pos + BLOCK_HDR <= len;) {
		uint8_t bh[BLOCK_HDR];

		if (be_read(st, base + pos, bh, sizeof(bh)) != 0) {
			return -EIO;
		}
		uint32_t blen = (uint32_t)co_od_le_get(bh + 4, 4);

		if (blen > len - pos - BLOCK_HDR) {
			return -EIO;
		}
		if (bh[0] < CO_OD_GROUP_COUNT && (group_mask & CO_OD_GROUP_BIT(bh[0]))) {
			uint32_t end = pos + BLOCK_HDR + blen;

			for (uint32_t r = pos + BLOCK_HDR; r + REC_HDR <= end;) {
				uint8_t rh[REC_HDR];

				if (be_read(st, base + r, rh, sizeof(rh)) != 0) {
					return -EIO;
				}
				uint32_t rlen = (uint32_t)co_od_le_get(rh + 4, 2);

				if (rlen > end - r - REC_HDR) {
					return -EIO;
				}
				restore_record(st, base + r + REC_HDR, rh);
				r += REC_HDR + rlen;
			}
		}
		pos += BLOCK_HDR + blen;
	}
	return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* 1010h / 1011h */

static uint32_t group_of_sub(uint8_t sub)
{
	switch (sub) {
	case 1:
		return CO_OD_GROUP_ALL;
	case 2:
		return CO_OD_GROUP_BIT(CO_OD_GROUP_COMM);
	case 3:
		return CO_OD_GROUP_BIT(CO_OD_GROUP_APP);
	case 4:
		return CO_OD_GROUP_BIT(CO_OD_GROUP_MANUF);
	default:
		return 0;
	}
}

static uint32_t storage_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_storage *st = user_data;

	(void)od;
	uint32_t mask = group_of_sub(req->info->sub);
	uint32_t v = (uint32_t)co_od_req_uint(req);
	bool save = req->info->index == 0x1010U;

	if (st->own_write) {
		return 0U;
	}
	/* CiA 301 §7.5.2.13-14: a wrong signature is refused with 0800002xh; 20h: cannot be
	 * stored, 21h: local control. Without medium nothing can be stored, signature or not. */
	if (mask == 0U || req->len != 4U || st->absent ||
	    v != (save ? CO_STORAGE_SIGNATURE_SAVE : CO_STORAGE_SIGNATURE_LOAD)) {
		return CO_SDO_AB_DATA_XFER;
	}
	if (st->locked) {
		return CO_SDO_AB_DATA_LOC_CTRL;
	}
	int err = save ? co_storage_save(st, mask) : co_storage_clear(st, mask);

	return err == 0 ? CO_OD_HANDLED : CO_SDO_AB_HW;
}

/* Without medium, 1010h/1011h sub 1.. read 0: "does not save", "does not restore". */
static int claim_nothing(struct co_storage *st)
{
	static const uint8_t zero[4];
	int err = 0;

	st->own_write = true;
	for (uint16_t index = 0x1010U; index <= 0x1011U; index++) {
		uint8_t highest = 0U;

		if (co_od_get_u8(st->od, index, 0, &highest) != 0U) {
			continue;
		}
		for (uint16_t sub = 1U; sub <= highest; sub++) {
			struct co_od_info info;

			if (co_od_find(st->od, index, (uint8_t)sub, &info) == 0U &&
			    co_od_write(st->od, index, (uint8_t)sub, zero,
					info.size < 4U ? info.size : 4U, CO_OD_WRITER_APP) != 0U) {
				err = -EROFS;
			}
		}
	}
	st->own_write = false;
	return err;
}

static void storage_restore_cb(struct co_od *od, uint32_t group_mask, void *user_data)
{
	struct co_storage *st = user_data;

	(void)od;
	if (st->absent) {
		/* The reset loaded the EDS values again. */
		if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
			(void)claim_nothing(st);
		}
		return;
	}
	(void)co_storage_restore(st, group_mask);
}

static int attach(struct co_storage *st)
{
	const struct co_od_hook hook = {
		.index_first = 0x1010,
		.index_last = 0x1011,
		.sub_first = 1,
		.sub_last = 0xFF,
		.validate = storage_validate,
		.user_data = st,
	};
	int err;

	(void)co_od_hook_unregister(st->od, st);
	err = co_od_hook_register(st->od, &hook);
	if (err != 0) {
		return err;
	}
	return co_od_set_restore_cb(st->od, storage_restore_cb, st);
}

int co_storage_init_absent(struct co_storage *st, struct co_od *od)
{
	int err;

	if (st == NULL || od == NULL) {
		return -EINVAL;
	}
	(void)memset(st, 0, sizeof(*st));
	st->od = od;
	st->active = -1;
	st->absent = true;
	err = attach(st);
	return err != 0 ? err : claim_nothing(st);
}

void co_storage_set_locked(struct co_storage *st, bool locked)
{
	st->locked = locked;
}

int co_storage_init(struct co_storage *st, struct co_od *od, const struct co_storage_backend *be)
{
	if (st == NULL || od == NULL || be == NULL || be->api == NULL) {
		return -EINVAL;
	}
	(void)memset(st, 0, sizeof(*st));
	st->od = od;
	st->be = be;
	st->slot_size = be->api->size(be) / 2U;
	if (st->slot_size < 32U) {
		return -EINVAL;
	}
	int err = find_current(st);

	if (err != 0) {
		return err;
	}
	return attach(st);
}
