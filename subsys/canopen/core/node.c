/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* A node: its mutex, dictionary, line, and the list of services it drives. */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/node.h>

#include "node_internal.h"

LOG_MODULE_REGISTER(co_node, CONFIG_CANOPEN_LOG_LEVEL);

int co_node_init(struct co_node *node, const char *name, struct co_line *line,
		 const struct co_od_def *def, void *ram, uint8_t node_id)
{
	int err;

	if (node == NULL || line == NULL || def == NULL || ram == NULL || node_id < 1U ||
	    node_id > 127U) {
		return -EINVAL;
	}
	memset(node, 0, sizeof(*node));
	k_mutex_init(&node->lock);
	node->name = name;
	node->line = line;
	node->node_id = node_id;
	node->pending_node_id = node_id;
	node->nmt.state = CO_NMT_INITIALISING;
	co_line_attach(line);

	err = co_od_init(&node->od, def, ram, node_id);
	if (err != 0) {
		return err;
	}
	co_nmt_init(node);
	err = co_errctl_init(node);
	if (err != 0) {
		return err;
	}
#if defined(CONFIG_CANOPEN_EMCY)
	err = co_emcy_init(node);
	if (err != 0) {
		return err;
	}
#endif
#if defined(CONFIG_CANOPEN_SYNC)
	err = co_sync_init(node);
	if (err != 0) {
		return err;
	}
#endif
#if defined(CONFIG_CANOPEN_TIME)
	err = co_time_init(node);
	if (err != 0) {
		return err;
	}
#endif
#if defined(CONFIG_CANOPEN_PDO)
	err = co_pdo_init(node);
	if (err != 0) {
		return err;
	}
#endif
#if defined(CONFIG_CANOPEN_SDO_SERVER)
	for (uint8_t i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		err = co_sdo_srv_init(&node->sdo_srv[i], node, i);
		if (err != 0) {
			return err;
		}
	}
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
	for (uint8_t i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		err = co_sdo_cli_init(&node->sdo_cli[i], node, i);
		if (err != 0) {
			return err;
		}
	}
#endif
#if defined(CONFIG_CANOPEN_MGR)
	err = co_mgr_init(node);
	if (err != 0) {
		return err;
	}
#endif
	return 0;
}

int co_node_start(struct co_node *node)
{
	int err = 0;

	co_node_lock(node);
	if (node->started) {
		err = -EALREADY;
	} else {
		node->started = true;
		co_nmt_boot(node);
	}
	co_node_unlock(node);
	return err;
}

void co_node_services_reset_comm(struct co_node *node)
{
	co_errctl_reset_comm(node);
#if defined(CONFIG_CANOPEN_EMCY)
	co_emcy_reset_comm(node);
#endif
#if defined(CONFIG_CANOPEN_SYNC)
	co_sync_reset_comm(node);
#endif
#if defined(CONFIG_CANOPEN_TIME)
	co_time_reset_comm(node);
#endif
#if defined(CONFIG_CANOPEN_PDO)
	co_pdo_reset_comm(node);
#endif
#if defined(CONFIG_CANOPEN_SDO_SERVER)
	for (int i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		co_sdo_srv_reset_comm(&node->sdo_srv[i]);
	}
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
	for (int i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		co_sdo_cli_reset_comm(&node->sdo_cli[i]);
	}
#endif
#if defined(CONFIG_CANOPEN_MGR)
	co_mgr_reset_comm(node);
#endif
}

void co_node_services_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	co_errctl_set_state(node, from, to);
#if defined(CONFIG_CANOPEN_EMCY)
	co_emcy_set_state(node, to);
#endif
#if defined(CONFIG_CANOPEN_SYNC)
	co_sync_set_state(node, to);
#endif
#if defined(CONFIG_CANOPEN_TIME)
	co_time_set_state(node, to);
#endif
#if defined(CONFIG_CANOPEN_PDO)
	co_pdo_set_state(node, to);
#endif
#if defined(CONFIG_CANOPEN_SDO_SERVER)
	for (int i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		co_sdo_srv_set_state(&node->sdo_srv[i], to);
	}
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
	for (int i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		co_sdo_cli_set_state(&node->sdo_cli[i], to);
	}
#endif
#if defined(CONFIG_CANOPEN_MGR)
	co_mgr_set_state(node, to);
#endif
}

void co_node_lock(struct co_node *node)
{
	(void)k_mutex_lock(&node->lock, K_FOREVER);
}

void co_node_unlock(struct co_node *node)
{
	(void)k_mutex_unlock(&node->lock);
}

struct co_od *co_node_od(struct co_node *node)
{
	return &node->od;
}

uint8_t co_node_id(const struct co_node *node)
{
	return node->node_id;
}

struct co_line *co_node_line(struct co_node *node)
{
	return node->line;
}

int co_node_set_pending_id(struct co_node *node, uint8_t node_id)
{
	if (node_id < 1U || node_id > 127U) {
		return -EINVAL;
	}
	co_node_lock(node);
	node->pending_node_id = node_id;
	co_node_unlock(node);
	return 0;
}

int co_node_send(struct co_node *node, const struct can_frame *frame)
{
	return co_line_send_from(node->line, frame, &node->lock);
}
