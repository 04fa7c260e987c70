/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief SDO requesting device (SRD) of CiA 302 §7: register with the SDO manager, ask for a
 * connection to a slave, release it.
 *
 * The SRD's dictionary holds 1F10h (U32, rw) and client entries 1280h+ (COB-IDs invalid until
 * the manager writes them). co_sdom_srd_register() sets 1F10h and sends 6E0h; the manager
 * answers by writing 1F10h, which co_sdom_srd_status() decodes. The requests go to the
 * manager's 1F00h/1F01h over the client entry set up at registration. Every call requires
 * the node's mutex (co_node_lock()); the SDO confirmations run in the line thread. The
 * struct co_sdom_srd belongs to the application (it holds the data of the running write).
 *
 * @defgroup co_sdom SDO requesting device
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SDOM_H_
#define SAFELINE_INCLUDE_CANOPEN_SDOM_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/sdo_cli.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Connection states of 1F10h bits 2..1. */
enum co_sdom_state {
	CO_SDOM_FAILED = 0,       /**< the last request failed: see error */
	CO_SDOM_REGISTERED = 1,   /**< the channel SRD -> manager is set up */
	CO_SDOM_ALL_DEFAULTS = 2, /**< the SRD owns every default SDO */
	CO_SDOM_CONNECTED = 3,    /**< the requested connection to the slave is set up */
};

/** 1F10h decoded. */
struct co_sdom_status {
	uint16_t index; /**< client entry (1280h+) the manager set up */
	uint8_t error;  /**< 01h-04h when state is CO_SDOM_FAILED (CiA 302 §7.2.3) */
	uint8_t state;  /**< enum co_sdom_state */
	bool pending;   /**< Rq indication: the manager has not answered yet */
};

/** An SRD: its node and the client entry of its channel to the manager. */
struct co_sdom_srd {
	struct co_node *node;
	uint16_t reg_index; /**< 1280h..12FFh, or 0 for "all default SDOs" */
	uint8_t buf[4];     /**< the 1F00h/1F01h value being written */
};

/**
 * @brief Ask the SDO manager to register this node (1F10h, then 6E0h with DLC 0).
 *
 * @param srd Filled in here.
 * @param node The SRD's node.
 * @param reg_index Free client entry 1280h..12FFh for the channel to the manager, or 0 to ask
 *        for every default SDO (1F10h = 00000003h).
 * @retval 0 Sent; poll co_sdom_srd_status() for the answer.
 * @retval -EINVAL @p reg_index outside 1280h..12FFh and not 0.
 * @retval -EIO The dictionary has no writable 1F10h.
 * @retval other co_node_send()'s error.
 */
int co_sdom_srd_register(struct co_sdom_srd *srd, struct co_node *node, uint16_t reg_index);

/**
 * @brief Decode 1F10h.
 *
 * @retval 0 Done.
 * @retval -EIO The dictionary has no 1F10h.
 */
int co_sdom_srd_status(const struct co_sdom_srd *srd, struct co_sdom_status *st);

/**
 * @brief Ask for a connection to @p slave on client entry @p cli_index (writes 1F00h on the
 * manager through the registration channel).
 *
 * @p con runs with the write's abort code: 0 means the manager started (the result comes in
 * 1F10h), 060A0023h that it refused (1F10h carries the error code).
 *
 * @retval 0 Started; -EINVAL for indexes outside 1280h..12FFh or @p slave outside 1..127,
 *         -ENOTCONN without a registration channel; otherwise co_sdo_cli_download_req()'s
 *         error.
 */
int co_sdom_srd_request(struct co_sdom_srd *srd, uint16_t cli_index, uint8_t slave,
			co_sdo_cli_con_t con, void *user_data);

/**
 * @brief Release connections (1F01h): @p slave 0 releases everything and de-registers,
 * @p cli_index 0 every connection to @p slave.
 *
 * @retval As co_sdom_srd_request() (@p slave may be 0, @p cli_index may be 0).
 */
int co_sdom_srd_release(struct co_sdom_srd *srd, uint16_t cli_index, uint8_t slave,
			co_sdo_cli_con_t con, void *user_data);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_SDOM_H_ */
