/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen node: one device (object dictionary + services) attached to a line.
 *
 * A node has one recursive mutex. The line thread takes it around every dispatch to the
 * node's services; application threads take it through the API (every call locks inside;
 * co_node_lock()/co_node_unlock() group several calls, e.g. multi-step OD work). Callbacks run
 * in the line thread with it held, may call the API (the mutex is recursive) and must not
 * block.
 *
 * Life cycle: co_node_init() binds the node to its line, dictionary and node-ID;
 * co_node_start() runs the NMT Initialising state (reset application, reset communication),
 * sends the boot-up message and enters Pre-operational. Services are configured from the
 * dictionary at every reset and re-configured at once by any later write to their objects.
 *
 * @defgroup co_node Node
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_NODE_H_
#define SAFELINE_INCLUDE_CANOPEN_NODE_H_

#include <stdint.h>

#include <zephyr/kernel.h>

#include <canopen/errctl.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/od.h>

#if defined(CONFIG_CANOPEN_SDO_SERVER) || defined(__DOXYGEN__)
#include <canopen/sdo.h>
#endif
#if defined(CONFIG_CANOPEN_EMCY) || defined(__DOXYGEN__)
#include <canopen/emcy.h>
#endif
#if defined(CONFIG_CANOPEN_SYNC) || defined(__DOXYGEN__)
#include <canopen/sync.h>
#endif
#if defined(CONFIG_CANOPEN_TIME) || defined(__DOXYGEN__)
#include <canopen/time.h>
#endif
#if defined(CONFIG_CANOPEN_PDO) || defined(__DOXYGEN__)
#include <canopen/pdo.h>
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT) || defined(__DOXYGEN__)
#include <canopen/sdo_cli.h>
#endif
#if defined(CONFIG_CANOPEN_MGR) || defined(__DOXYGEN__)
#include <canopen/mgr.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** A CANopen node. Allocate statically; all fields are private. */
struct co_node {
	/** @cond INTERNAL_HIDDEN */
	struct k_mutex lock;
	const char *name;
	struct co_line *line;
	struct co_od od;
	uint8_t node_id;
	/* Node-ID to use from the next Reset Communication (LSS may change it). */
	uint8_t pending_node_id;
	bool started;
	struct co_nmt nmt;
	struct co_rx nmt_rx;
	struct co_errctl ec;
#if defined(CONFIG_CANOPEN_SDO_SERVER)
	struct co_sdo_srv sdo_srv[CONFIG_CANOPEN_SDO_SERVERS];
#endif
#if defined(CONFIG_CANOPEN_EMCY)
	struct co_emcy emcy;
#endif
#if defined(CONFIG_CANOPEN_SYNC)
	struct co_sync sync;
#endif
#if defined(CONFIG_CANOPEN_TIME)
	struct co_time_svc time;
#endif
#if defined(CONFIG_CANOPEN_PDO)
	struct co_pdo pdo;
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
	struct co_sdo_cli sdo_cli[CONFIG_CANOPEN_SDO_CLIENTS];
#endif
#if defined(CONFIG_CANOPEN_MGR)
	struct co_mgr mgr;
#endif
	/** @endcond */
};

/**
 * @brief Initialise a node.
 *
 * @param node Node to initialise (statically allocated).
 * @param name Name for logs; must outlive the node.
 * @param line Line the node is attached to (initialised, started or not).
 * @param def Generated dictionary description (NAME_od_def from scripts/eds2od).
 * @param ram The node's own RAM block for the dictionary (a struct NAME_od_ram).
 * @param node_id Node-ID 1..127.
 *
 * @retval 0 Initialised; the node is in Initialising until co_node_start().
 * @retval -EINVAL A NULL argument or a node-ID outside 1..127.
 */
int co_node_init(struct co_node *node, const char *name, struct co_line *line,
		 const struct co_od_def *def, void *ram, uint8_t node_id);

/**
 * @brief Start the node: reset application and communication, boot-up, Pre-operational.
 *
 * Call after the application has registered its hooks and indications. The boot-up
 * message goes out on the line.
 *
 * @retval 0 Started.
 * @retval -EALREADY The node was started before.
 */
int co_node_start(struct co_node *node);

/** @brief Take the node's mutex (recursive). Blocks. */
void co_node_lock(struct co_node *node);

/** @brief Release the node's mutex. */
void co_node_unlock(struct co_node *node);

/**
 * @brief The node's object dictionary, for the co_od_* accessors.
 *
 * Call the accessors with the node's mutex held (co_node_lock()).
 */
struct co_od *co_node_od(struct co_node *node);

/** @brief The node's current node-ID. */
uint8_t co_node_id(const struct co_node *node);

/** @brief The line the node is attached to. */
struct co_line *co_node_line(struct co_node *node);

/**
 * @brief Set the node-ID used from the next Reset Communication (e.g. after LSS).
 *
 * @retval 0 Done.
 * @retval -EINVAL Not 1..127.
 */
int co_node_set_pending_id(struct co_node *node, uint8_t node_id);

/**
 * @brief Send a frame from the node on its line (the services' path to the bus).
 *
 * @return As co_line_send().
 */
int co_node_send(struct co_node *node, const struct can_frame *frame);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_NODE_H_ */
