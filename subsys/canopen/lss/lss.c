/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS slave (CiA 305): requests on 7E5h, answers on 7E4h, always 8 bytes.
 *
 * Decisions (doc/lss.md):
 * - Frames with a DLC other than 8, remote frames and unknown command specifiers are ignored.
 * - Switch state selective needs 40h, 41h, 42h, 43h in this order; a value that does not
 *   match, or a frame out of order, restarts the sequence. Identify remote slave (46h..4Bh)
 *   likewise. Any switch state global restarts both.
 * - "Unconfigured" for identify non-configured (4Ch) and fastscan: neither an active nor a
 *   pending node-ID. Fastscan answers only in waiting.
 * - Inquire node-ID answers the active node-ID (FFh while the node has none).
 * - A node that has no node-ID and got one resets its communication by itself when switched
 *   from configuration to waiting; a configured node takes a new node-ID at the next NMT
 *   Reset Communication (or Reset Node).
 * - NMT Reset Communication and Reset Node return the slave to waiting; the configured bit
 *   timing and a bit rate switch under way are kept (they belong to the controller).
 * - Bit timing: table 0 only, index 5 only with CONFIG_CANOPEN_LSS_BIT_TIMING_INDEX5_100K,
 *   index 9 (automatic detection) never; the line's controller decides the rest (the
 *   application's bit rate handler, else Zephyr's CAN API on the line's device).
 * - While a bit rate switch is under way the slave ignores every request: it must be silent.
 * - Store configuration writes the pending node-ID and the configured bit timing to the
 *   medium of co_lss_store_attach() (two copies, commit mark last).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/drivers/can.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>

#include <canopen/lss.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/storage.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_IDENTITY 0x1018U

/* No bit timing configured. */
#define BT_NONE 0xFFU

/* Activate bit timing: where the switch stands. */
enum {
	SWITCH_IDLE,
	SWITCH_BEFORE,
	SWITCH_AFTER,
};

/* Stored record: magic (written last), seq, node-ID, table, index, 0, CRC-16, 0, 0. */
#define REC_SIZE  16U
#define REC_MAGIC 0x3153534CU /* "LSS1" */

static bool legacy_100k(void)
{
	return IS_ENABLED(CONFIG_CANOPEN_LSS_BIT_TIMING_INDEX5_100K);
}

/* --- The node, as LSS sees it ------------------------------------------------------------- */

/* No node-ID now and none to come: what identify non-configured and fastscan look for. */
static bool unconfigured(const struct co_node *node)
{
	return !co_node_is_configured(node) && co_node_pending_id(node) == CO_NODE_ID_UNCONFIGURED;
}

/* One part of the LSS address: 0 vendor-ID, 1 product code, 2 revision, 3 serial number. */
static uint32_t address_part(struct co_node *node, uint8_t part)
{
	return co_od_uint(co_node_od(node), IDX_IDENTITY, (uint8_t)(part + 1U), 0U);
}

/* The default line's CAN device; NULL for a simulation line. */
static const struct device *line_device(struct co_node *node)
{
	return co_line_device(co_node_line(node));
}

static const char *state_str(uint8_t state)
{
	return state == CO_LSS_STATE_CONFIGURATION ? "configuration" : "waiting";
}

static void set_state(struct co_node *node, enum co_lss_state to)
{
	struct co_lss *l = &node->lss;
	enum co_lss_state from = (enum co_lss_state)l->state;
	struct co_event ev = {
		.type = CO_EV_LSS,
		.lss = {.from = (uint8_t)from, .to = (uint8_t)to, .fastscan = l->fs_active},
	};

	if (from == to) {
		return;
	}
	l->state = (uint8_t)to;
	LOG_INF("%s: LSS %s -> %s", node->name, state_str(from), state_str(to));
	if (l->ind != NULL) {
		l->ind(node, from, to, l->ind_user_data);
	}
	(void)co_node_publish(node, &ev, NULL);
}

/* --- Answers ------------------------------------------------------------------------------- */

/* Every answer goes back on the line its request came on. */
static void answer(struct co_node *node, uint8_t cs, uint8_t b1, uint8_t b2)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_SLAVE_COB_ID, cs);
	f.data[1] = b1;
	f.data[2] = b2;
	(void)co_node_send(node, co_node_route_of(node, &node->lss.rx), &f);
}

static void answer_u32(struct co_node *node, uint8_t cs, uint32_t value)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_SLAVE_COB_ID, cs);
	co_lss_frame_set_u32(&f, value);
	(void)co_node_send(node, co_node_route_of(node, &node->lss.rx), &f);
}

/* --- Bit rate ------------------------------------------------------------------------------ */

/*
 * The default steps on a line with a CAN device, through Zephyr's CAN API. The API has no
 * query for the rates a controller supports, so the check asks can_set_bitrate() of the
 * running controller: a driver that could take the rate once stopped refuses with -EBUSY,
 * one that cannot with -ENOSYS (no bit rate setting) or -ENOTSUP (out of its range).
 */
static int device_step(struct co_node *node, enum co_lss_bitrate_step step, uint32_t bitrate)
{
	const struct device *dev = line_device(node);
	enum can_state state;
	int err;

	if (dev == NULL) {
		return -ENOTSUP;
	}
	switch (step) {
	case CO_LSS_BITRATE_CHECK:
		err = can_get_state(dev, &state, NULL);
		if (err != 0) {
			return err;
		}
		/* Stopped, the call would set the rate at once instead of answering. */
		if (state == CAN_STATE_STOPPED) {
			return -ENETDOWN;
		}
		err = can_set_bitrate(dev, bitrate);
		return err == -EBUSY ? 0 : err;
	case CO_LSS_BITRATE_SILENCE:
		err = can_stop(dev);
		return err == -EALREADY ? 0 : err;
	case CO_LSS_BITRATE_SWITCH:
		return can_set_bitrate(dev, bitrate);
	case CO_LSS_BITRATE_RESUME:
		err = can_start(dev);
		return err == -EALREADY ? 0 : err;
	default:
		return -EINVAL;
	}
}

static int bitrate_step(struct co_node *node, enum co_lss_bitrate_step step, uint32_t bitrate)
{
	struct co_lss *l = &node->lss;

	if (l->br_handler != NULL) {
		return l->br_handler(node, step, bitrate, l->br_user_data);
	}
	return device_step(node, step, bitrate);
}

/* The two delays of activate bit timing: silent, switch, silent, resume. */
static void switch_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	struct co_lss *l = &node->lss;
	uint64_t next = timer->deadline + (uint64_t)l->switch_delay_ms * 1000U;
	int err;

	ARG_UNUSED(now_us);
	if (l->switching == SWITCH_BEFORE) {
		err = bitrate_step(node, CO_LSS_BITRATE_SWITCH, l->bt_bitrate);
		l->switch_failed = err != 0;
		if (err != 0) {
			LOG_ERR("%s: LSS: cannot switch to %u bit/s (%d), the old rate stays",
				node->name, l->bt_bitrate, err);
		} else {
			l->active_bitrate = l->bt_bitrate;
		}
		l->switching = SWITCH_AFTER;
		co_node_timer_start(node, timer, next);
	} else if (l->switching == SWITCH_AFTER) {
		l->switching = SWITCH_IDLE;
		err = bitrate_step(node, CO_LSS_BITRATE_RESUME, l->active_bitrate);
		if (err != 0) {
			LOG_ERR("%s: LSS: cannot resume after the bit rate switch (%d)", node->name,
				err);
		} else {
			LOG_INF("%s: LSS: %s at %u bit/s", node->name,
				l->switch_failed ? "resumed" : "switched", l->active_bitrate);
		}
	} else {
		/* SWITCH_IDLE: no switch is running. */
	}
}

static void config_bit_timing(struct co_node *node, uint8_t table, uint8_t index)
{
	struct co_lss *l = &node->lss;
	uint32_t bitrate = table == CO_LSS_BIT_TIMING_TABLE_CIA
				   ? co_lss_bit_timing_bps(index, legacy_100k())
				   : 0U;

	if (bitrate == 0U || bitrate_step(node, CO_LSS_BITRATE_CHECK, bitrate) != 0) {
		answer(node, CO_LSS_CS_CONFIG_BIT_TIMING, CO_LSS_ERR_BIT_TIMING, 0U);
		return;
	}
	l->bt_index = index;
	l->bt_bitrate = bitrate;
	answer(node, CO_LSS_CS_CONFIG_BIT_TIMING, CO_LSS_ERR_OK, 0U);
}

static void activate_bit_timing(struct co_node *node, uint16_t delay_ms, uint64_t now_us)
{
	struct co_lss *l = &node->lss;
	int err;

	if (l->bt_index == BT_NONE) {
		LOG_WRN("%s: LSS: activate bit timing without a configured bit timing", node->name);
		return;
	}
	err = bitrate_step(node, CO_LSS_BITRATE_SILENCE, l->bt_bitrate);
	if (err != 0) {
		LOG_ERR("%s: LSS: cannot silence the line for the bit rate switch (%d)", node->name,
			err);
		return;
	}
	l->switching = SWITCH_BEFORE;
	l->switch_delay_ms = delay_ms;
	l->switch_failed = false;
	co_node_timer_start(node, &l->timer, now_us + (uint64_t)delay_ms * 1000U);
}

/* --- Storage ------------------------------------------------------------------------------- */

static int medium_read(const struct co_storage_backend *be, uint32_t off, void *buf, size_t len)
{
	return be->api->read(be, off, buf, len);
}

static int medium_write(const struct co_storage_backend *be, uint32_t off, const void *buf,
			size_t len)
{
	int err = be->api->write(be, off, buf, len);

	return err != 0 ? err : be->api->sync(be);
}

static uint16_t rec_crc(const uint8_t rec[REC_SIZE])
{
	return crc16_itu_t(0xFFFFU, &rec[4], 8U);
}

/* Whether a stored bit timing index is one this build accepts. */
static bool stored_bt_valid(uint8_t index)
{
	return index == BT_NONE || co_lss_bit_timing_bps(index, legacy_100k()) != 0U;
}

/* Read the record of one slot: 0 when valid, -ENOENT when not, -EIO when unreadable. */
static int rec_load(const struct co_storage_backend *be, uint8_t slot, uint8_t rec[REC_SIZE])
{
	uint8_t nid;

	if (medium_read(be, slot * REC_SIZE, rec, REC_SIZE) != 0) {
		return -EIO;
	}
	nid = rec[8];
	if (sys_get_le32(&rec[0]) != REC_MAGIC || sys_get_le16(&rec[12]) != rec_crc(rec) ||
	    !((nid >= 1U && nid <= 127U) || nid == CO_NODE_ID_UNCONFIGURED) ||
	    rec[9] != CO_LSS_BIT_TIMING_TABLE_CIA || !stored_bt_valid(rec[10])) {
		return -ENOENT;
	}
	return 0;
}

/*
 * Write the pending node-ID and the configured bit timing into the slot that does not hold
 * the record in force: its magic cleared first, then the body, then the magic. A write cut
 * anywhere leaves the other slot's record in force.
 */
static uint8_t store(struct co_node *node)
{
	struct co_lss *l = &node->lss;
	const struct co_storage_backend *be = l->store;
	static const uint8_t zero[4];
	uint8_t rec[REC_SIZE] = {0};
	uint8_t slot = l->store_slot == 0 ? 1U : 0U;
	uint32_t off = slot * REC_SIZE;

	if (be == NULL) {
		return CO_LSS_ERR_STORE_SUPPORTED;
	}
	sys_put_le32(REC_MAGIC, &rec[0]);
	sys_put_le32(l->store_seq + 1U, &rec[4]);
	rec[8] = co_node_pending_id(node);
	rec[9] = CO_LSS_BIT_TIMING_TABLE_CIA;
	rec[10] = l->bt_index;
	sys_put_le16(rec_crc(rec), &rec[12]);
	if (medium_write(be, off, zero, sizeof(zero)) != 0 ||
	    medium_write(be, off + 4U, &rec[4], REC_SIZE - 4U) != 0 ||
	    medium_write(be, off, rec, 4U) != 0) {
		LOG_ERR("%s: LSS: store configuration failed", node->name);
		return CO_LSS_ERR_STORE_MEDIUM;
	}
	l->store_slot = (int8_t)slot;
	l->store_seq++;
	return CO_LSS_ERR_OK;
}

/* --- Requests ------------------------------------------------------------------------------ */

static void switch_global(struct co_node *node, uint8_t mode)
{
	struct co_lss *l = &node->lss;
	bool boot;

	if (mode != CO_LSS_MODE_WAITING && mode != CO_LSS_MODE_CONFIGURATION) {
		return;
	}
	l->sel_step = 0U;
	l->ident_step = 0U;
	l->fs_active = false;
	if (mode == CO_LSS_MODE_CONFIGURATION) {
		set_state(node, CO_LSS_STATE_CONFIGURATION);
		return;
	}
	/* A node without node-ID that got one boots with it at once (as CANopenNode does); a
	 * configured node waits for an NMT reset.
	 */
	boot = l->state == CO_LSS_STATE_CONFIGURATION && !co_node_is_configured(node) &&
	       co_node_pending_id(node) != CO_NODE_ID_UNCONFIGURED;
	set_state(node, CO_LSS_STATE_WAITING);
	if (boot) {
		LOG_INF("%s: LSS: node-ID %u, resetting communication", node->name,
			co_node_pending_id(node));
		(void)co_nmt_req(node, CO_NMT_CS_RESET_COMMUNICATION);
	}
}

static void switch_selective(struct co_node *node, uint8_t part, uint32_t value)
{
	struct co_lss *l = &node->lss;

	if (l->state != CO_LSS_STATE_WAITING) {
		return;
	}
	/* 40h always starts afresh; 41h..43h continue a sequence that matched so far. */
	if ((part != 0U && part != l->sel_step) || value != address_part(node, part)) {
		l->sel_step = 0U;
		return;
	}
	l->sel_step = (uint8_t)(part + 1U);
	if (l->sel_step == 4U) {
		l->sel_step = 0U;
		answer(node, CO_LSS_CS_SWITCH_SEL_RESULT, 0U, 0U);
		set_state(node, CO_LSS_STATE_CONFIGURATION);
	}
}

static void identify_remote(struct co_node *node, uint8_t step, uint32_t value)
{
	struct co_lss *l = &node->lss;
	bool match;

	if (step != 0U && step != l->ident_step) {
		l->ident_step = 0U;
		return;
	}
	switch (step) {
	case 0U: /* vendor-ID */
	case 1U: /* product code */
		match = value == address_part(node, step);
		break;
	case 2U: /* revision low */
	case 4U: /* serial low */
		l->ident_low = value;
		match = true;
		break;
	default: { /* revision high, serial high */
		uint32_t own = address_part(node, step == 3U ? 2U : 3U);

		match = l->ident_low <= own && own <= value;
		break;
	}
	}
	l->ident_step = match ? (uint8_t)(step + 1U) : 0U;
	if (l->ident_step == 6U) {
		l->ident_step = 0U;
		answer(node, CO_LSS_CS_IDENT_SLAVE, 0U, 0U);
	}
}

static void fastscan(struct co_node *node, const struct can_frame *f)
{
	struct co_lss *l = &node->lss;
	uint32_t id = co_lss_frame_get_u32(f);
	uint8_t bit = f->data[5];
	uint8_t sub = f->data[6];
	uint8_t next = f->data[7];
	uint32_t mask;

	if (l->state != CO_LSS_STATE_WAITING || !unconfigured(node)) {
		return;
	}
	if ((bit > 31U && bit != CO_LSS_FASTSCAN_CONFIRM) || sub > CO_LSS_FASTSCAN_SERIAL ||
	    next > CO_LSS_FASTSCAN_SERIAL) {
		return;
	}
	if (bit == CO_LSS_FASTSCAN_CONFIRM) {
		l->fs_pos = CO_LSS_FASTSCAN_VENDOR;
		l->fs_active = true;
		answer(node, CO_LSS_CS_IDENT_SLAVE, 0U, 0U);
		return;
	}
	if (l->fs_pos != sub) {
		return;
	}
	/* Bits 31..BitCheck must match; the ones below are still unknown to the master. */
	mask = UINT32_MAX << bit;
	if (((address_part(node, sub) ^ id) & mask) != 0U) {
		return;
	}
	l->fs_active = true;
	answer(node, CO_LSS_CS_IDENT_SLAVE, 0U, 0U);
	l->fs_pos = next;
	if (bit == 0U && next < sub) {
		/* The last part verified: the scan selected this node. */
		set_state(node, CO_LSS_STATE_CONFIGURATION);
		l->fs_active = false;
	}
}

/* Requests of the configuration state. */
static void configure(struct co_node *node, const struct can_frame *f, uint64_t now_us)
{
	uint8_t cs = f->data[0];

	switch (cs) {
	case CO_LSS_CS_CONFIG_NODE_ID: {
		uint8_t nid = f->data[1];

		if (co_node_set_pending_id(node, nid) != 0) {
			answer(node, cs, CO_LSS_ERR_NODE_ID_RANGE, 0U);
		} else {
			answer(node, cs, CO_LSS_ERR_OK, 0U);
		}
		break;
	}
	case CO_LSS_CS_CONFIG_BIT_TIMING:
		config_bit_timing(node, f->data[1], f->data[2]);
		break;
	case CO_LSS_CS_ACTIVATE_BIT_TIMING:
		activate_bit_timing(node, sys_get_le16(&f->data[1]), now_us);
		break;
	case CO_LSS_CS_STORE:
		answer(node, cs, store(node), 0U);
		break;
	case CO_LSS_CS_INQUIRE_VENDOR:
	case CO_LSS_CS_INQUIRE_PRODUCT:
	case CO_LSS_CS_INQUIRE_REVISION:
	case CO_LSS_CS_INQUIRE_SERIAL:
		answer_u32(node, cs, address_part(node, (uint8_t)(cs - CO_LSS_CS_INQUIRE_VENDOR)));
		break;
	case CO_LSS_CS_INQUIRE_NODE_ID:
		answer(node, cs, co_node_id(node), 0U);
		break;
	default:
		break;
	}
}

static void lss_rx(struct co_rx *rx, const struct can_frame *f, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_lss *l = &node->lss;
	uint8_t cs = f->data[0];

	if (!co_lss_frame_valid(f) || l->switching != SWITCH_IDLE) {
		return;
	}
	if (cs == CO_LSS_CS_SWITCH_GLOBAL) {
		switch_global(node, f->data[1]);
	} else if (cs >= CO_LSS_CS_SWITCH_SEL_VENDOR && cs <= CO_LSS_CS_SWITCH_SEL_SERIAL) {
		switch_selective(node, (uint8_t)(cs - CO_LSS_CS_SWITCH_SEL_VENDOR),
				 co_lss_frame_get_u32(f));
	} else if (cs >= CO_LSS_CS_IDENT_VENDOR && cs <= CO_LSS_CS_IDENT_SERIAL_HIGH) {
		identify_remote(node, (uint8_t)(cs - CO_LSS_CS_IDENT_VENDOR),
				co_lss_frame_get_u32(f));
	} else if (cs == CO_LSS_CS_IDENT_NON_CONFIGURED) {
		if (unconfigured(node)) {
			answer(node, CO_LSS_CS_IDENT_NON_CONFIGURED_SLAVE, 0U, 0U);
		}
	} else if (cs == CO_LSS_CS_FASTSCAN) {
		fastscan(node, f);
	} else if (l->state == CO_LSS_STATE_CONFIGURATION) {
		configure(node, f, now_us);
	} else {
		/* Configuration commands outside the configuration state are ignored (CiA 305). */
	}
}

/* --- Node interface ------------------------------------------------------------------------ */

static int lss_init(struct co_node *node)
{
	struct co_lss *l = &node->lss;

	l->state = CO_LSS_STATE_WAITING;
	l->bt_index = BT_NONE;
	l->store_slot = -1;
	co_timer_init(&l->timer, switch_timer, &node->lock, node);
	co_rx_init(&l->rx, CO_LSS_MASTER_COB_ID, lss_rx, &node->lock, node);
	return co_node_rx_register(node, CO_LINE_DEFAULT, &l->rx);
}

static void lss_reset_comm(struct co_node *node)
{
	struct co_lss *l = &node->lss;

	l->sel_step = 0U;
	l->ident_step = 0U;
	l->fs_pos = CO_LSS_FASTSCAN_VENDOR;
	l->fs_active = false;
	set_state(node, CO_LSS_STATE_WAITING);
}

const struct co_service co_service_lss = {
	.name = "lss",
	.flags = CO_SERVICE_F_UNCONFIGURED,
	.init = lss_init,
	.reset_comm = lss_reset_comm,
};

/* --- API ----------------------------------------------------------------------------------- */

enum co_lss_state co_lss_get_state(struct co_node *node)
{
	enum co_lss_state state;

	co_node_lock(node);
	state = (enum co_lss_state)node->lss.state;
	co_node_unlock(node);
	return state;
}

void co_lss_set_ind(struct co_node *node, co_lss_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->lss.ind = cb;
	node->lss.ind_user_data = user_data;
	co_node_unlock(node);
}

void co_lss_set_bitrate_handler(struct co_node *node, co_lss_bitrate_handler_t handler,
				void *user_data)
{
	co_node_lock(node);
	node->lss.br_handler = handler;
	node->lss.br_user_data = user_data;
	co_node_unlock(node);
}

/* Apply a stored bit rate to the line's controller, if it is stopped (not started yet). */
static void apply_stored_bitrate(struct co_node *node, uint32_t bitrate)
{
	const struct device *dev = line_device(node);
	enum can_state state;

	if (dev == NULL || can_get_state(dev, &state, NULL) != 0 || state != CAN_STATE_STOPPED) {
		return;
	}
	if (can_set_bitrate(dev, bitrate) == 0) {
		node->lss.active_bitrate = bitrate;
	} else {
		LOG_WRN("%s: LSS: the stored %u bit/s cannot be set", node->name, bitrate);
	}
}

int co_lss_store_attach(struct co_node *node, const struct co_storage_backend *be,
			struct co_lss_config *loaded)
{
	struct co_lss *l = &node->lss;
	uint8_t rec[2][REC_SIZE];
	int best = -1;
	uint32_t best_seq = 0U;
	int err = 0;

	co_node_lock(node);
	if (be == NULL) {
		l->store = NULL;
		goto out;
	}
	if (be->api->size(be) < 2U * REC_SIZE) {
		err = -EINVAL;
		goto out;
	}
	for (uint8_t slot = 0U; slot < 2U; slot++) {
		int r = rec_load(be, slot, rec[slot]);

		if (r == -EIO) {
			err = -EIO;
			goto out;
		}
		if (r == 0) {
			uint32_t seq = sys_get_le32(&rec[slot][4]);

			if (best < 0 || (int32_t)(seq - best_seq) > 0) {
				best = slot;
				best_seq = seq;
			}
		}
	}
	l->store = be;
	l->store_slot = (int8_t)best;
	l->store_seq = best_seq;
	if (best < 0) {
		err = -ENOENT;
		goto out;
	}
	(void)co_node_set_pending_id(node, rec[best][8]);
	if (rec[best][10] != BT_NONE) {
		l->bt_index = rec[best][10];
		l->bt_bitrate = co_lss_bit_timing_bps(l->bt_index, legacy_100k());
		apply_stored_bitrate(node, l->bt_bitrate);
	}
	if (loaded != NULL) {
		*loaded = (struct co_lss_config){
			.node_id = rec[best][8],
			.bit_timing_index = rec[best][10],
			.bitrate = rec[best][10] != BT_NONE ? l->bt_bitrate : 0U,
		};
	}
out:
	co_node_unlock(node);
	return err;
}
