/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT slave (CiA 301 §7.3.2): module control commands, the Initialising sequence with its
 * boot-up message, and the state changes that enable and disable the services.
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/nmt.h>
#include <canopen/node.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

const char *co_nmt_state_str(enum co_nmt_state state)
{
	switch (state) {
	case CO_NMT_INITIALISING:
		return "INITIALISING";
	case CO_NMT_STOPPED:
		return "STOPPED";
	case CO_NMT_OPERATIONAL:
		return "OPERATIONAL";
	case CO_NMT_PRE_OPERATIONAL:
		return "PRE-OPERATIONAL";
	default:
		return "?";
	}
}

static void nmt_enter(struct co_node *node, enum co_nmt_state to)
{
	enum co_nmt_state from = node->nmt.state;

	node->nmt.state = to;
	LOG_INF("%s: %s -> %s", node->name, co_nmt_state_str(from), co_nmt_state_str(to));
	co_node_services_set_state(node, from, to);
}

/* A change among Pre-operational, Operational and Stopped, offered to the application. */
static int nmt_change(struct co_node *node, enum co_nmt_state to)
{
	enum co_nmt_state from = node->nmt.state;

	if (from == to) {
		return 0;
	}
	if (node->nmt.state_ind != NULL) {
		int veto = node->nmt.state_ind(node, from, to, node->nmt.state_user_data);

		if (veto != 0) {
			LOG_INF("%s: change to %s refused by the application (%d)", node->name,
				co_nmt_state_str(to), veto);
			return -EPERM;
		}
	}
	nmt_enter(node, to);
	return 0;
}

static void send_bootup(struct co_node *node)
{
	struct can_frame f = {
		.id = CO_NMT_EC_COB_ID + node->node_id,
		.dlc = 1U,
		.data = {0U},
	};

	(void)co_node_send(node, &f);
}

/*
 * Reset Node or Reset Communication: Initialising, reload the dictionary areas, reconfigure
 * every service, boot-up, Pre-operational (and Operational when self-starting).
 */
static void nmt_reset(struct co_node *node, enum co_nmt_cs cs)
{
	if (node->nmt.reset_ind != NULL) {
		node->nmt.reset_ind(node, cs, node->nmt.reset_user_data);
	}
	if (node->nmt.state != CO_NMT_INITIALISING) {
		nmt_enter(node, CO_NMT_INITIALISING);
	}
	if (cs == CO_NMT_CS_RESET_NODE) {
		co_od_reset_app(&node->od);
	}
	/* A node-ID configured by LSS takes effect here (CiA 305 §8.3.2.1). */
	node->node_id = node->pending_node_id;
	(void)co_od_set_node_id(&node->od, node->node_id);
	co_od_reset_comm(&node->od);
	co_node_services_reset_comm(node);

	send_bootup(node);
	nmt_enter(node, CO_NMT_PRE_OPERATIONAL);
	if (node->nmt.autostart) {
		(void)nmt_change(node, CO_NMT_OPERATIONAL);
	}
}

void co_nmt_boot(struct co_node *node)
{
	nmt_reset(node, CO_NMT_CS_RESET_NODE);
}

static int nmt_command(struct co_node *node, uint8_t cs)
{
	if (node->nmt.state == CO_NMT_INITIALISING) {
		return -EBUSY;
	}
	switch (cs) {
	case CO_NMT_CS_START:
		return nmt_change(node, CO_NMT_OPERATIONAL);
	case CO_NMT_CS_STOP:
		return nmt_change(node, CO_NMT_STOPPED);
	case CO_NMT_CS_ENTER_PRE_OPERATIONAL:
		return nmt_change(node, CO_NMT_PRE_OPERATIONAL);
	case CO_NMT_CS_RESET_NODE:
	case CO_NMT_CS_RESET_COMMUNICATION:
		nmt_reset(node, (enum co_nmt_cs)cs);
		return 0;
	default:
		return -EINVAL;
	}
}

/*
 * 000h: [cs, node-ID]. CiA 301 defines only DLC 2; other lengths, RTR frames, commands for
 * other nodes and unknown command specifiers are ignored without any reaction.
 */
static void nmt_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	uint8_t target;

	if (frame->dlc != 2U || (frame->flags & CAN_FRAME_RTR) != 0U) {
		return;
	}
	target = frame->data[1];
	if (target != 0U && target != node->node_id) {
		return;
	}
	(void)nmt_command(node, frame->data[0]);
}

void co_nmt_init(struct co_node *node)
{
	co_rx_init(&node->nmt_rx, CO_NMT_COB_ID, nmt_rx, &node->lock, node);
	(void)co_rx_register(node->line, &node->nmt_rx);
}

enum co_nmt_state co_nmt_get_state(struct co_node *node)
{
	enum co_nmt_state state;

	co_node_lock(node);
	state = node->nmt.state;
	co_node_unlock(node);
	return state;
}

int co_nmt_req(struct co_node *node, enum co_nmt_cs cs)
{
	int err;

	co_node_lock(node);
	err = nmt_command(node, (uint8_t)cs);
	co_node_unlock(node);
	return err;
}

void co_nmt_set_state_ind(struct co_node *node, co_nmt_state_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->nmt.state_ind = cb;
	node->nmt.state_user_data = user_data;
	co_node_unlock(node);
}

void co_nmt_set_reset_ind(struct co_node *node, co_nmt_reset_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->nmt.reset_ind = cb;
	node->nmt.reset_user_data = user_data;
	co_node_unlock(node);
}

void co_nmt_set_autostart(struct co_node *node, bool autostart)
{
	co_node_lock(node);
	node->nmt.autostart = autostart;
	co_node_unlock(node);
}
