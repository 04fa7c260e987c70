/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief NMT slave (CiA 301 §7.3.2): states, commands, boot-up, state-change indication.
 *
 * @defgroup co_nmt NMT slave
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_NMT_H_
#define SAFELINE_INCLUDE_CANOPEN_NMT_H_

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** NMT states, with their heartbeat and node-guarding codes (CiA 301 §7.2.8.3.2). */
enum co_nmt_state {
	/** Initialising; its code is the boot-up message. */
	CO_NMT_INITIALISING = 0x00,
	CO_NMT_STOPPED = 0x04,
	CO_NMT_OPERATIONAL = 0x05,
	CO_NMT_PRE_OPERATIONAL = 0x7f,
};

/** NMT command specifiers (CiA 301 §7.2.8.3.1). */
enum co_nmt_cs {
	CO_NMT_CS_START = 0x01,
	CO_NMT_CS_STOP = 0x02,
	CO_NMT_CS_ENTER_PRE_OPERATIONAL = 0x80,
	CO_NMT_CS_RESET_NODE = 0x81,
	CO_NMT_CS_RESET_COMMUNICATION = 0x82,
};

/** COB-ID of NMT module control. */
#define CO_NMT_COB_ID    0x000U
/** Base COB-ID of NMT error control (boot-up, heartbeat, node guarding): 700h + node-ID. */
#define CO_NMT_EC_COB_ID 0x700U

/**
 * @brief Decide on a state change between Pre-operational, Operational and Stopped.
 *
 * Called before the change, for NMT commands from the bus and for local requests alike. The
 * resets (Reset Node, Reset Communication) are not offered for a veto: CiA 301 makes them
 * unconditional.
 *
 * Runs in the line thread (or the requesting thread for co_nmt_req()) with the node's mutex
 * held; must not block.
 *
 * @param node The node.
 * @param from Current state.
 * @param to Requested state.
 * @param user_data As registered.
 * @retval 0 Accept the change.
 * @retval negative errno Refuse it; the node stays in @p from.
 */
typedef int (*co_nmt_state_ind_t)(struct co_node *node, enum co_nmt_state from,
				  enum co_nmt_state to, void *user_data);

/**
 * @brief Learn that a reset is about to run (application hook for its own objects).
 *
 * @param node The node.
 * @param cs CO_NMT_CS_RESET_NODE or CO_NMT_CS_RESET_COMMUNICATION.
 * @param user_data As registered.
 *
 * Runs with the node's mutex held; must not block.
 */
typedef void (*co_nmt_reset_ind_t)(struct co_node *node, enum co_nmt_cs cs, void *user_data);

/** @cond INTERNAL_HIDDEN */
struct co_nmt {
	enum co_nmt_state state;
	co_nmt_state_ind_t state_ind;
	void *state_user_data;
	co_nmt_reset_ind_t reset_ind;
	void *reset_user_data;
	/* Go to Operational by itself after boot-up (CiA 302 self-starting device). */
	bool autostart;
};
/** @endcond */

/** @brief Current NMT state of a node. */
enum co_nmt_state co_nmt_get_state(struct co_node *node);

/**
 * @brief Request a state change or reset of the node itself (local NMT service).
 *
 * Takes the node's mutex. Offers the change to the state indication, as for a command
 * received from the bus.
 *
 * @retval 0 Done (or already in that state).
 * @retval -EINVAL Unknown command specifier.
 * @retval -EPERM The state indication refused the change.
 * @retval -EBUSY The node has not been started (still Initialising).
 */
int co_nmt_req(struct co_node *node, enum co_nmt_cs cs);

/** @brief Set the state-change indication (NULL removes it). */
void co_nmt_set_state_ind(struct co_node *node, co_nmt_state_ind_t cb, void *user_data);

/** @brief Set the reset indication (NULL removes it). */
void co_nmt_set_reset_ind(struct co_node *node, co_nmt_reset_ind_t cb, void *user_data);

/**
 * @brief Enter Operational by itself after boot-up (no NMT master needed).
 *
 * The state indication is still asked. Takes effect at the next boot-up.
 */
void co_nmt_set_autostart(struct co_node *node, bool autostart);

/** @brief Name of a state ("PRE-OPERATIONAL"...). */
const char *co_nmt_state_str(enum co_nmt_state state);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_NMT_H_ */
