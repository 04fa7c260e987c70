/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Multiplexed PDOs (CiA 301 §7.2.3): one object per 8-byte frame.
 *
 *   byte 0   bit 7 address mode (0 SAM, 1 DAM), bits 6..0 node-ID
 *            (DAM: destination, 0 = every node; SAM: the producer)
 *   byte 1-2 index, byte 3 sub-index (DAM: in the destination's dictionary; SAM: in the
 *            producer's), bytes 4-7 the value (1..4 bytes, zero padded)
 *
 * A PDO is an MPDO when its mapping sub 0 is FEh (SAM) or FFh (DAM); its communication
 * record (COB-ID, type 254/255, inhibit time) is used as for any PDO (pdo.c). This file has
 * the object side: the DAM write, the dispatcher list (1FD0h-1FFFh) of a SAM consumer, the
 * scanner list (1FA0h-1FCFh) of a SAM producer and the checks of writes to both lists.
 *
 * Decisions (doc/pdo.md):
 * - MPDO objects are 1..4-byte fixed-size values (the frame holds four bytes); DAM and SAM
 *   consumers write with CO_OD_WRITER_MPDO (SDO write access), a SAM producer reads with it
 *   (TPDO mappability).
 * - Dispatcher entries (CiA 301 1FD0h): bits 63..56 block size, 55..40 local index, 39..32
 *   local sub-index, 31..16 sender index, 15..8 sender sub-index, 7..0 sender node-ID.
 *   Scanner entries (1FA0h): bits 31..24 block size, 23..8 index, 7..0 sub-index. A block
 *   size of 0 counts as 1 (as lely reads it).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>

#include <canopen/node.h>
#include <canopen/pdo.h>

#include "node_internal.h"
#include "pdo_internal.h"

#define IDX_SCAN_FIRST 0x1FA0U
#define IDX_SCAN_LAST  0x1FCFU
#define IDX_DISP_FIRST 0x1FD0U
#define IDX_DISP_LAST  0x1FFFU

#define ADDR_DAM     0x80U
#define ADDR_NODE_ID 0x7FU

#define MPDO_MAX_BYTES 4U

/* --- Helpers ------------------------------------------------------------------------------ */

static uint32_t block_of(uint32_t raw)
{
	return raw == 0U ? 1U : raw;
}

/* Objects an MPDO can carry: fixed-size values of 1..4 bytes. */
static bool mpdo_sized(const struct co_od_info *info)
{
	uint32_t size = co_dtype_size(info->dtype);

	return size != 0U && size <= MPDO_MAX_BYTES && info->size == size;
}

/* What an SDO may write (the MPDO writer's rule, od.c check_access()). */
static bool mpdo_writable(const struct co_od_info *info)
{
	if ((info->flags & CO_OD_F_ROM) != 0U) {
		return false;
	}
	return info->access == CO_OD_ACCESS_WO || info->access == CO_OD_ACCESS_RW ||
	       info->access == CO_OD_ACCESS_RWR || info->access == CO_OD_ACCESS_RWW;
}

static uint64_t od_entry(const struct co_od *od, uint16_t index, uint8_t sub)
{
	uint8_t buf[8] = {0};
	size_t len = 0;

	if (co_od_read(od, index, sub, 0, buf, sizeof(buf), &len, CO_OD_WRITER_APP) != 0U) {
		return 0U;
	}
	return co_od_le_get(buf, len);
}

/* Resolve a local object for a SAM producer: listed, readable as a TPDO would read it. */
static uint32_t scan_object(const struct co_od *od, uint16_t index, uint8_t sub,
			    struct co_pdo_map_ent *ent)
{
	struct co_od_info info;
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (!mpdo_sized(&info)) {
		return CO_SDO_AB_NO_MAP;
	}
	return co_pdo_map_check(
		od, false, ((uint32_t)index << 16) | ((uint32_t)sub << 8) | (info.size * 8U), ent);
}

/* --- Receive ------------------------------------------------------------------------------ */

static enum co_mpdo_rx_result write_object(struct co_node *node, uint16_t index, uint8_t sub,
					   const uint8_t data[4], bool dam)
{
	struct co_pdo_map_ent ent = {0};
	struct co_od_info tmp;
	const struct co_od_info *info = &tmp;
	uint8_t val[8] = {0};

	if (co_od_find(&node->od, index, sub, &tmp) != 0U) {
		return dam ? CO_MPDO_RX_MISSING : CO_MPDO_RX_REFUSED;
	}
	if (!mpdo_sized(info)) {
		return CO_MPDO_RX_REFUSED;
	}
	co_pdo_ent_set(&ent, info);
	memcpy(val, data, MPDO_MAX_BYTES);
	return co_pdo_ent_write(&node->od, &ent, val, CO_OD_WRITER_MPDO) == 0U ? CO_MPDO_RX_WRITTEN
									       : CO_MPDO_RX_REFUSED;
}

/* SAM: find the sender's object in the dispatcher list and write the local object. */
static enum co_mpdo_rx_result dispatch(struct co_node *node, uint8_t sender, uint16_t index,
				       uint8_t sub, const uint8_t data[4])
{
	uint64_t present = node->pdo.mpdo_disp;

	for (unsigned int i = 0; present != 0U; i++, present >>= 1) {
		uint16_t list = (uint16_t)(IDX_DISP_FIRST + i);

		if ((present & 1U) == 0U) {
			continue;
		}
		uint8_t n = (uint8_t)od_entry(&node->od, list, 0);

		for (unsigned int j = 1; j <= n && j < 0xFFU; j++) {
			uint64_t e = od_entry(&node->od, list, (uint8_t)j);
			uint32_t block = block_of((uint32_t)(e >> 56));
			uint8_t s_sub = (uint8_t)(e >> 8);

			if (e == 0U || (uint8_t)e != sender || (uint16_t)(e >> 16) != index ||
			    sub < s_sub || (uint32_t)(sub - s_sub) >= block) {
				continue;
			}
			return write_object(node, (uint16_t)(e >> 40),
					    (uint8_t)((uint8_t)(e >> 32) + (sub - s_sub)), data,
					    false);
		}
	}
	return CO_MPDO_RX_IGNORED;
}

enum co_mpdo_rx_result co_mpdo_rx(struct co_node *node, uint8_t mode, const uint8_t data[8])
{
	struct co_mpdo_stats *st = &node->pdo.mpdo_stats;
	bool dam = (data[0] & ADDR_DAM) != 0U;
	uint8_t id = data[0] & ADDR_NODE_ID;
	uint16_t index = (uint16_t)(data[1] | (data[2] << 8));
	enum co_mpdo_rx_result res;

	if (dam != (mode == CO_MPDO_DAM)) {
		/* A DAM consumer does not dispatch SAM frames, nor the reverse. */
		res = CO_MPDO_RX_IGNORED;
	} else if (dam) {
		res = (id == 0U || id == co_node_id(node))
			      ? write_object(node, index, data[3], &data[4], true)
			      : CO_MPDO_RX_IGNORED;
	} else {
		res = dispatch(node, id, index, data[3], &data[4]);
	}
	switch (res) {
	case CO_MPDO_RX_WRITTEN:
		st->written++;
		break;
	case CO_MPDO_RX_REFUSED:
		st->refused++;
		break;
	case CO_MPDO_RX_MISSING:
		st->missing++;
		break;
	default:
		st->ignored++;
		break;
	}
	return res;
}

/* --- Transmit ----------------------------------------------------------------------------- */

static int tpdo_check(struct co_node *node, uint16_t num, uint8_t mode, struct co_tpdo **out)
{
	struct co_tpdo *t;

	if (num >= CO_TPDOS) {
		return -EINVAL;
	}
	t = &node->pdo.tpdo[num];
	if (!t->present || (t->cob_id & CO_PDO_COB_INVALID) != 0U || t->mpdo != mode) {
		return -EINVAL;
	}
	if (!node->pdo.operational) {
		return -ENETDOWN;
	}
	*out = t;
	return 0;
}

int co_mpdo_dam_req(struct co_node *node, uint16_t num, uint8_t dest_id, uint16_t index,
		    uint8_t sub, const void *data, size_t len)
{
	uint8_t f[8] = {0};
	struct co_tpdo *t;
	int err;

	if (node == NULL || dest_id > ADDR_NODE_ID || data == NULL || len == 0U ||
	    len > MPDO_MAX_BYTES) {
		return -EINVAL;
	}
	f[0] = ADDR_DAM | dest_id;
	f[1] = (uint8_t)index;
	f[2] = (uint8_t)(index >> 8);
	f[3] = sub;
	memcpy(&f[4], data, len);
	co_node_lock(node);
	err = tpdo_check(node, num, CO_MPDO_DAM, &t);
	if (err == 0) {
		err = co_tpdo_mpdo_send(t, f);
	}
	co_node_unlock(node);
	return err;
}

/* Whether (index, sub) is covered by an entry of the scanner list. */
static bool scanned(const struct co_node *node, uint16_t index, uint8_t sub)
{
	uint64_t present = node->pdo.mpdo_scan;

	for (unsigned int i = 0; present != 0U; i++, present >>= 1) {
		uint16_t list = (uint16_t)(IDX_SCAN_FIRST + i);

		if ((present & 1U) == 0U) {
			continue;
		}
		uint8_t n = (uint8_t)od_entry(&node->od, list, 0);

		for (unsigned int j = 1; j <= n && j < 0xFFU; j++) {
			uint32_t e = (uint32_t)od_entry(&node->od, list, (uint8_t)j);
			uint8_t first = (uint8_t)e;

			if (e != 0U && (uint16_t)(e >> 8) == index && sub >= first &&
			    (uint32_t)(sub - first) < block_of(e >> 24)) {
				return true;
			}
		}
	}
	return false;
}

int co_mpdo_sam_req(struct co_node *node, uint16_t num, uint16_t index, uint8_t sub)
{
	struct co_pdo_map_ent ent;
	uint8_t val[8];
	uint8_t f[8] = {0};
	struct co_tpdo *t;
	int err;

	if (node == NULL) {
		return -EINVAL;
	}
	co_node_lock(node);
	err = tpdo_check(node, num, CO_MPDO_SAM, &t);
	if (err == 0 && !scanned(node, index, sub)) {
		err = -ENOENT;
	}
	if (err == 0 && (scan_object(&node->od, index, sub, &ent) != 0U ||
			 co_pdo_ent_read(&node->od, &ent, val, CO_OD_WRITER_MPDO) != 0U)) {
		err = -EIO;
	}
	if (err == 0) {
		f[0] = co_node_id(node) & ADDR_NODE_ID;
		f[1] = (uint8_t)index;
		f[2] = (uint8_t)(index >> 8);
		f[3] = sub;
		memcpy(&f[4], val, MPDO_MAX_BYTES);
		err = co_tpdo_mpdo_send(t, f);
	}
	co_node_unlock(node);
	return err;
}

void co_mpdo_get_stats(struct co_node *node, struct co_mpdo_stats *stats)
{
	co_node_lock(node);
	*stats = node->pdo.mpdo_stats;
	co_node_unlock(node);
}

/* --- Scanner and dispatcher lists --------------------------------------------------------- */

static uint32_t scan_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint32_t v = (uint32_t)co_od_req_uint(req);
	uint32_t block = block_of(v >> 24);
	uint16_t index = (uint16_t)(v >> 8);
	uint8_t first = (uint8_t)v;

	if (req->writer == CO_OD_WRITER_STORAGE || v == 0U) {
		return 0U;
	}
	if (first + block - 1U > 0xFFU) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* Every object of the block must be one a SAM producer can send. */
	for (uint32_t k = 0; k < block; k++) {
		struct co_pdo_map_ent ent;
		uint32_t ab = scan_object(od, index, (uint8_t)(first + k), &ent);

		if (ab != 0U) {
			return ab;
		}
	}
	return 0U;
}

static uint32_t disp_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint64_t v = co_od_req_uint(req);
	uint32_t block = block_of((uint32_t)(v >> 56));
	uint16_t local = (uint16_t)(v >> 40);
	uint8_t local_sub = (uint8_t)(v >> 32);
	uint8_t sender_sub = (uint8_t)(v >> 8);
	uint8_t sender = (uint8_t)v;

	if (req->writer == CO_OD_WRITER_STORAGE || v == 0U) {
		return 0U;
	}
	if (sender < 1U || sender > ADDR_NODE_ID || local_sub + block - 1U > 0xFFU ||
	    sender_sub + block - 1U > 0xFFU) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* Every local object of the block must take an MPDO value. */
	for (uint32_t k = 0; k < block; k++) {
		struct co_od_info info;
		uint32_t ab = co_od_find(od, local, (uint8_t)(local_sub + k), &info);

		if (ab != 0U) {
			return ab;
		}
		if (!mpdo_sized(&info) || !mpdo_writable(&info)) {
			return CO_SDO_AB_NO_MAP;
		}
	}
	return 0U;
}

int co_mpdo_init(struct co_node *node)
{
	struct co_pdo *pdo = &node->pdo;
	struct co_od_info info;
	int err = 0;

	pdo->mpdo_scan = 0U;
	pdo->mpdo_disp = 0U;
	memset(&pdo->mpdo_stats, 0, sizeof(pdo->mpdo_stats));
	for (unsigned int i = 0; i <= IDX_SCAN_LAST - IDX_SCAN_FIRST; i++) {
		if (co_od_find(&node->od, (uint16_t)(IDX_SCAN_FIRST + i), 0, &info) == 0U) {
			pdo->mpdo_scan |= (uint64_t)1 << i;
		}
		if (co_od_find(&node->od, (uint16_t)(IDX_DISP_FIRST + i), 0, &info) == 0U) {
			pdo->mpdo_disp |= (uint64_t)1 << i;
		}
	}
	if (pdo->mpdo_scan != 0U) {
		const struct co_od_hook h = {IDX_SCAN_FIRST, IDX_SCAN_LAST, 1,   0xFE,
					     scan_validate,  NULL,          node};

		err = co_od_hook_register(&node->od, &h);
	}
	if (err == 0 && pdo->mpdo_disp != 0U) {
		const struct co_od_hook h = {IDX_DISP_FIRST, IDX_DISP_LAST, 1,   0xFE,
					     disp_validate,  NULL,          node};

		err = co_od_hook_register(&node->od, &h);
	}
	return err;
}
