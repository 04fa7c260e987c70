/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Program download, slave side (CiA 302 §9, doc/pgm.md): 1F50h-1F57h served by an object
 * provider, images streamed from the SDO server into the inactive slot of a two-slot flash.
 *
 * Slot layout: [commit record, 16 bytes][image header, 32 bytes][body]. The commit record
 * (magic "SLCM", sequence, body CRC, record CRC) is written last, by the start that switches
 * to the image; the boot takes the verified slot with the highest sequence. Erasing a slot
 * erases its record first, so a cut anywhere in a download or a commit leaves the previous
 * committed image as the newest valid one.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/logging/log.h>

#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/pgm.h>
#include <canopen/sdo_abort.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_DATA    0x1F50U
#define IDX_CTRL    0x1F51U
#define IDX_VERIFY  0x1F52U
#define IDX_SW_ID   0x1F56U
#define IDX_STATUS  0x1F57U
#define REC_MAGIC   0x4D434C53U /* "SLCM" */
#define REC_SIZE    16U
#define IMG_OFF     REC_SIZE
#define BODY_OFF    (REC_SIZE + CO_PGM_HDR_SIZE)
#define VERIFY_STEP 64U

static void put_u32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
	p[2] = (uint8_t)(v >> 16);
	p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32(const uint8_t *p)
{
	return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
	       ((uint32_t)p[3] << 24);
}

/* --- Slots ------------------------------------------------------------------------------------ */

/* Header and body of @p slot as read back from the flash. */
static int image_verify(struct co_pgm_flash *f, uint8_t slot, struct co_pgm_image_info *info)
{
	uint8_t hdr[CO_PGM_HDR_SIZE];
	uint8_t buf[VERIFY_STEP];
	uint32_t crc = 0U;
	int err;

	err = f->api->read(f, slot, IMG_OFF, hdr, sizeof(hdr));
	if (err != 0) {
		return err;
	}
	if (co_pgm_image_parse(hdr, info) != 0 || info->length > f->slot_size - BODY_OFF) {
		return -EBADMSG;
	}
	for (uint32_t off = 0; off < info->length; off += VERIFY_STEP) {
		uint32_t n = MIN(VERIFY_STEP, info->length - off);

		err = f->api->read(f, slot, BODY_OFF + off, buf, n);
		if (err != 0) {
			return err;
		}
		crc = co_pgm_crc32(crc, buf, n);
	}
	return crc == info->crc ? 0 : -EBADMSG;
}

int co_pgm_slot_verify(struct co_pgm_flash *flash, uint8_t slot, struct co_pgm_image_info *info,
		       uint32_t *seq)
{
	uint8_t rec[REC_SIZE];
	struct co_pgm_image_info tmp;

	if (flash == NULL || flash->api == NULL || slot > 1U) {
		return -EINVAL;
	}
	if (flash->api->read(flash, slot, 0, rec, sizeof(rec)) != 0 ||
	    get_u32(&rec[0]) != REC_MAGIC || get_u32(&rec[12]) != co_pgm_crc32(0U, rec, 12)) {
		return -ENOENT;
	}
	if (image_verify(flash, slot, &tmp) != 0 || tmp.crc != get_u32(&rec[8])) {
		return -EBADMSG;
	}
	if (info != NULL) {
		*info = tmp;
	}
	if (seq != NULL) {
		*seq = get_u32(&rec[4]);
	}
	return 0;
}

static int commit_to(struct co_pgm_flash *f, uint8_t slot, uint32_t seq, uint32_t body_crc)
{
	uint8_t rec[REC_SIZE];

	put_u32(&rec[0], REC_MAGIC);
	put_u32(&rec[4], seq);
	put_u32(&rec[8], body_crc);
	put_u32(&rec[12], co_pgm_crc32(0U, rec, 12));
	return f->api->write(f, slot, 0, rec, sizeof(rec));
}

static int commit(struct co_pgm *pg, uint8_t slot, uint32_t seq, uint32_t body_crc)
{
	return commit_to(pg->flash, slot, seq, body_crc);
}

int co_pgm_slot_program(struct co_pgm_flash *flash, uint8_t slot, const void *image, size_t len,
			uint32_t seq)
{
	struct co_pgm_image_info info;
	int err;

	if (flash == NULL || flash->api == NULL || image == NULL || slot > 1U ||
	    len < CO_PGM_HDR_SIZE || len > flash->slot_size - REC_SIZE) {
		return -EINVAL;
	}
	err = flash->api->erase(flash, slot);
	if (err == 0) {
		err = flash->api->write(flash, slot, IMG_OFF, image, len);
	}
	if (err == 0) {
		err = image_verify(flash, slot, &info);
	}
	if (err == 0 && len != CO_PGM_HDR_SIZE + info.length) {
		err = -EBADMSG;
	}
	return err != 0 ? err : commit_to(flash, slot, seq, info.crc);
}

/* The boot: the newest committed slot that verifies. */
static int boot_select(struct co_pgm *pg)
{
	pg->run_slot = -1;
	pg->pend_slot = -1;
	pg->dl_slot = -1;
	pg->running = false;
	(void)memset(&pg->run, 0, sizeof(pg->run));
	for (uint8_t slot = 0; slot < 2U; slot++) {
		struct co_pgm_image_info info;
		uint32_t seq;

		if (co_pgm_slot_verify(pg->flash, slot, &info, &seq) != 0) {
			continue;
		}
		if (pg->run_slot < 0 || (int32_t)(seq - pg->run_seq) > 0) {
			pg->run_slot = (int8_t)slot;
			pg->run_seq = seq;
			pg->run = info;
		}
	}
	pg->running = pg->run_slot >= 0;
	pg->status = pg->running ? CO_PGM_FLASH_OK : CO_PGM_FLASH_NO_PROGRAM;
	return pg->running ? 0 : -ENOENT;
}

static void indicate(struct co_pgm *pg, enum co_pgm_event ev, const struct co_pgm_image_info *img)
{
	if (pg->ind != NULL) {
		pg->ind(pg->node, ev, img, pg->ind_user_data);
	}
}

/* --- 1F50h:01 download ------------------------------------------------------------------------ */

static uint32_t dl_fail(struct co_pgm *pg, uint32_t status)
{
	LOG_WRN("%s: program download refused (1F57h %08Xh)", pg->node->name, status);
	pg->status = status;
	pg->dl_slot = -1;
	indicate(pg, CO_PGM_EV_REFUSED, pg->run_slot >= 0 ? &pg->run : NULL);
	return CO_SDO_AB_HW;
}

static uint32_t flash_status_of(int err)
{
	return err == -EROFS ? CO_PGM_FLASH_NOT_CLEARED : CO_PGM_FLASH_WRITE;
}

static uint32_t dl_begin(struct co_pgm *pg)
{
	uint8_t slot;
	int err;

	if (pg->flash == NULL) {
		return CO_SDO_AB_HW;
	}
	if (pg->running) {
		/* CiA 302 §9: the program is stopped (1F51h:01 = 0) before a download. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	slot = pg->run_slot == 0 ? 1U : 0U;
	pg->pend_slot = -1;
	pg->status = CO_PGM_FLASH_BUSY;
	err = pg->flash->api->erase(pg->flash, slot);
	if (err != 0) {
		pg->dl_slot = (int8_t)slot;
		return dl_fail(pg, flash_status_of(err));
	}
	pg->dl_slot = (int8_t)slot;
	pg->dl_crc = 0U;
	pg->dl_hdr_ok = false;
	(void)memset(&pg->dl, 0, sizeof(pg->dl));
	return 0;
}

static uint32_t dl_chunk(struct co_pgm *pg, uint32_t offset, const uint8_t *data, size_t len)
{
	uint32_t end = offset + (uint32_t)len;
	int err;

	if (offset < CO_PGM_HDR_SIZE) {
		uint32_t n = MIN(end, CO_PGM_HDR_SIZE) - offset;

		(void)memcpy(&pg->hdr[offset], data, n);
		if (end >= CO_PGM_HDR_SIZE) {
			err = co_pgm_image_parse(pg->hdr, &pg->dl);
			if (err != 0) {
				return dl_fail(pg, err == -ENOTSUP ? CO_PGM_FLASH_FORMAT
								   : CO_PGM_FLASH_CRC);
			}
			if (pg->dl.length > pg->flash->slot_size - BODY_OFF) {
				return dl_fail(pg, CO_PGM_FLASH_ADDRESS);
			}
			pg->dl_hdr_ok = true;
		}
	}
	if (pg->dl_hdr_ok) {
		if (end > CO_PGM_HDR_SIZE + pg->dl.length) {
			/* More than the header announced. */
			return dl_fail(pg, CO_PGM_FLASH_FORMAT);
		}
		if (end > CO_PGM_HDR_SIZE) {
			uint32_t from = MAX(offset, CO_PGM_HDR_SIZE);

			pg->dl_crc = co_pgm_crc32(pg->dl_crc, data + (from - offset), end - from);
		}
	}
	err = pg->flash->api->write(pg->flash, (uint8_t)pg->dl_slot, IMG_OFF + offset, data, len);
	if (err != 0) {
		return dl_fail(pg, flash_status_of(err));
	}
	return 0;
}

static uint32_t dl_end(struct co_pgm *pg, uint32_t size)
{
	struct co_pgm_image_info info;

	if (!pg->dl_hdr_ok || size != CO_PGM_HDR_SIZE + pg->dl.length || pg->dl_crc != pg->dl.crc) {
		return dl_fail(pg, CO_PGM_FLASH_CRC);
	}
	/* Read back: what counts is what the flash holds. */
	if (image_verify(pg->flash, (uint8_t)pg->dl_slot, &info) != 0) {
		return dl_fail(pg, CO_PGM_FLASH_WRITE);
	}
	pg->pend = info;
	pg->pend_slot = pg->dl_slot;
	pg->dl_slot = -1;
	pg->status = CO_PGM_FLASH_OK;
	LOG_INF("%s: program verified in slot %u (%u bytes, CRC %08Xh)", pg->node->name,
		(unsigned int)pg->pend_slot, info.length, info.crc);
	indicate(pg, CO_PGM_EV_VERIFIED, &pg->pend);
	return 0;
}

static uint32_t dl_write(struct co_pgm *pg, uint32_t offset, const void *data, size_t len,
			 bool last)
{
	uint32_t ab;

	if (data == NULL) {
		/* The SDO transfer was aborted: the image is incomplete. */
		return pg->dl_slot >= 0 ? dl_fail(pg, CO_PGM_FLASH_CRC) : 0U;
	}
	if (offset == 0U) {
		ab = dl_begin(pg);
		if (ab != 0U) {
			return ab;
		}
	} else if (pg->dl_slot < 0) {
		return CO_SDO_AB_HW;
	} else {
		/* The next chunk of the download under way. */
	}
	if (len > 0U) {
		ab = dl_chunk(pg, offset, data, len);
		if (ab != 0U) {
			return ab;
		}
	}
	return last ? dl_end(pg, offset + (uint32_t)len) : 0U;
}

/* --- 1F51h:01 control ------------------------------------------------------------------------- */

static void reset_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_pgm *pg = CONTAINER_OF(timer, struct co_pgm, reset_timer);

	ARG_UNUSED(now_us);
	/* The device restarts into the new image: Reset Node, boot-up message. */
	(void)co_nmt_req(pg->node, CO_NMT_CS_RESET_NODE);
}

static uint32_t ctrl_start(struct co_pgm *pg)
{
	struct co_pgm_image_info info;
	uint32_t seq;
	int err;

	if (pg->pend_slot < 0) {
		if (pg->run_slot < 0) {
			return CO_SDO_AB_NO_DATA;
		}
		pg->running = true;
		indicate(pg, CO_PGM_EV_STARTED, &pg->run);
		return 0;
	}
	/* Switch: the commit record makes the new image the one that boots. */
	err = commit(pg, (uint8_t)pg->pend_slot, pg->run_slot >= 0 ? pg->run_seq + 1U : 1U,
		     pg->pend.crc);
	if (err == 0) {
		err = co_pgm_slot_verify(pg->flash, (uint8_t)pg->pend_slot, &info, &seq);
	}
	if (err != 0) {
		pg->status = CO_PGM_FLASH_WRITE;
		pg->pend_slot = -1;
		return CO_SDO_AB_HW;
	}
	pg->run = info;
	pg->run_seq = seq;
	pg->run_slot = pg->pend_slot;
	pg->pend_slot = -1;
	pg->running = true;
	LOG_INF("%s: program switched to slot %u, restarting", pg->node->name,
		(unsigned int)pg->run_slot);
	indicate(pg, CO_PGM_EV_SWITCHED, &pg->run);
	/* After the SDO answer has gone out. */
	co_node_timer_start(pg->node, &pg->reset_timer, co_node_time(pg->node));
	return 0;
}

static uint32_t ctrl_write(struct co_pgm *pg, uint8_t v)
{
	switch (v) {
	case CO_PGM_STOP:
		pg->running = false;
		indicate(pg, CO_PGM_EV_STOPPED, pg->run_slot >= 0 ? &pg->run : NULL);
		return 0;
	case CO_PGM_START:
		if (pg->dl_slot >= 0) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
		return ctrl_start(pg);
	case CO_PGM_RESET:
		if (pg->run_slot < 0) {
			return CO_SDO_AB_NO_DATA;
		}
		pg->running = false;
		indicate(pg, CO_PGM_EV_RESET, &pg->run);
		return 0;
	case CO_PGM_CLEAR:
		if (pg->running || pg->dl_slot >= 0) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
		if (pg->pend_slot >= 0) {
			/* Only an image not yet started: the committed one always stays. */
			if (pg->flash->api->erase(pg->flash, (uint8_t)pg->pend_slot) != 0) {
				pg->status = CO_PGM_FLASH_WRITE;
				return CO_SDO_AB_HW;
			}
			pg->pend_slot = -1;
			indicate(pg, CO_PGM_EV_CLEARED, pg->run_slot >= 0 ? &pg->run : NULL);
		}
		return 0;
	default:
		return CO_SDO_AB_VALUE_HIGH;
	}
}

/* --- Provider --------------------------------------------------------------------------------- */

static struct co_pgm *prov_pgm(const struct co_od_provider *p)
{
	return p->user_data;
}

static uint32_t prov_info(const struct co_od_provider *p, struct co_od_info *info)
{
	uint8_t last;

	switch (info->index) {
	case IDX_DATA:
	case IDX_CTRL:
	case IDX_SW_ID:
	case IDX_STATUS:
		last = 1U;
		break;
	case IDX_VERIFY:
		last = 2U;
		break;
	default:
		return CO_SDO_AB_NO_OBJECT;
	}
	if (info->sub > last) {
		return CO_SDO_AB_NO_SUB;
	}
	info->objcode = CO_OD_OBJ_ARRAY;
	if (info->sub == 0U) {
		info->dtype = CO_DTYPE_UNSIGNED8;
		info->access = CO_OD_ACCESS_CONST;
		info->size = 1U;
		return 0;
	}
	switch (info->index) {
	case IDX_DATA:
		info->dtype = CO_DTYPE_DOMAIN;
		info->access = CO_OD_ACCESS_WO;
		info->flags = CO_OD_F_STREAM;
		info->size = UINT32_MAX;
		break;
	case IDX_CTRL:
		info->dtype = CO_DTYPE_UNSIGNED8;
		info->access = CO_OD_ACCESS_RW;
		info->size = 1U;
		break;
	default:
		info->dtype = CO_DTYPE_UNSIGNED32;
		info->access = CO_OD_ACCESS_RO;
		info->size = 4U;
		break;
	}
	return 0;
}

static uint32_t prov_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	return info->dtype == CO_DTYPE_DOMAIN ? 0U : info->size;
}

static uint32_t prov_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	struct co_pgm *pg = prov_pgm(p);
	bool have = pg->run_slot >= 0;
	uint8_t tmp[4];
	uint32_t v;

	if (info->sub == 0U) {
		v = info->index == IDX_VERIFY ? 2U : 1U;
	} else {
		switch (info->index) {
		case IDX_CTRL:
			v = pg->running ? 1U : 0U;
			break;
		case IDX_VERIFY:
			/* No valid program: 0/0, which never matches a manager's expectation. */
			v = !have ? 0U : info->sub == 1U ? pg->run.date : pg->run.time;
			break;
		case IDX_SW_ID:
			v = have ? pg->run.crc : 0U;
			break;
		case IDX_STATUS:
			v = pg->status;
			break;
		default:
			return CO_SDO_AB_WRITEONLY;
		}
	}
	put_u32(tmp, v);
	if (offset >= info->size) {
		*len = 0;
		return 0;
	}
	*len = MIN(cap, info->size - offset);
	(void)memcpy(buf, tmp + offset, *len);
	return 0;
}

static uint32_t prov_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	struct co_pgm *pg = prov_pgm(p);

	if (info->index == IDX_DATA) {
		return dl_write(pg, offset, data, len, last);
	}
	if (info->index == IDX_CTRL && len == 1U) {
		return ctrl_write(pg, *(const uint8_t *)data);
	}
	return CO_SDO_AB_READONLY;
}

static const struct co_od_provider_api prov_api = {
	.info = prov_info,
	.length = prov_length,
	.read = prov_read,
	.write = prov_write,
};

/* --- Node interface --------------------------------------------------------------------------- */

static int pgm_init(struct co_node *node)
{
	struct co_pgm *pg = &node->pgm;

	(void)memset(pg, 0, sizeof(*pg));
	pg->node = node;
	pg->run_slot = -1;
	pg->pend_slot = -1;
	pg->dl_slot = -1;
	pg->status = CO_PGM_FLASH_NO_PROGRAM;
	pg->prov = (struct co_od_provider){
		.api = &prov_api,
		.index_first = IDX_DATA,
		.index_last = IDX_STATUS,
		.user_data = pg,
	};
	co_timer_init(&pg->reset_timer, reset_timer_handler, &node->lock, pg);
	return co_od_provider_register(&node->od, &pg->prov);
}

const struct co_service co_service_pgm = {
	.name = "pgm",
	.init = pgm_init,
};

/* --- API -------------------------------------------------------------------------------------- */

int co_pgm_attach(struct co_node *node, struct co_pgm_flash *flash)
{
	int ret;

	if (flash == NULL || flash->api == NULL || flash->slot_size < BODY_OFF) {
		return -EINVAL;
	}
	co_node_lock(node);
	node->pgm.flash = flash;
	ret = boot_select(&node->pgm);
	co_node_unlock(node);
	if (ret == 0) {
		LOG_INF("%s: program in slot %d runs (date %u, time %u)", node->name,
			node->pgm.run_slot, node->pgm.run.date, node->pgm.run.time);
	} else {
		LOG_WRN("%s: no valid program in the flash", node->name);
	}
	return ret;
}

void co_pgm_set_ind(struct co_node *node, co_pgm_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->pgm.ind = cb;
	node->pgm.ind_user_data = user_data;
	co_node_unlock(node);
}

int co_pgm_get_running(struct co_node *node, struct co_pgm_image_info *info, int *slot)
{
	int ret = -ENOENT;

	co_node_lock(node);
	if (node->pgm.run_slot >= 0) {
		if (info != NULL) {
			*info = node->pgm.run;
		}
		if (slot != NULL) {
			*slot = node->pgm.run_slot;
		}
		ret = 0;
	}
	co_node_unlock(node);
	return ret;
}

uint32_t co_pgm_flash_status(struct co_node *node)
{
	uint32_t v;

	co_node_lock(node);
	v = node->pgm.status;
	co_node_unlock(node);
	return v;
}

bool co_pgm_is_running(struct co_node *node)
{
	bool v;

	co_node_lock(node);
	v = node->pgm.running;
	co_node_unlock(node);
	return v;
}
