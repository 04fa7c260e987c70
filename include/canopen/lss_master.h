/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief LSS master (CiA 305): configure and identify LSS slaves, find unconfigured ones.
 *
 * A node with CONFIG_CANOPEN_LSS_MASTER sends LSS requests on 7E5h and takes the slaves'
 * answers on 7E4h, on its default line. One request runs at a time per node. Every request
 * that has an answer has a timeout; answers of another kind, or with a DLC other than 8, are
 * ignored (counted).
 *
 * Two forms:
 * - asynchronous, co_lss_master_*_req(): start the request and return; the confirmation
 *   runs once, in the line thread with the node's mutex held (callable from any thread,
 *   also from a callback of the stack);
 * - blocking, the same names without _req: for application threads only. They refuse with
 *   -EDEADLK when called from a line thread or with the mutex of a node of the master's
 *   line held (as the blocking SDO client, doc/sdo-client.md).
 *
 * See doc/lss.md, "LSS master".
 *
 * @defgroup co_lss_master LSS master
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_LSS_MASTER_H_
#define SAFELINE_INCLUDE_CANOPEN_LSS_MASTER_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/lss.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** An LSS address: 1018h sub 1..4 of a device. */
struct co_lss_address {
	/** [0] vendor-ID, [1] product code, [2] revision number, [3] serial number. */
	uint32_t part[4];
};

/** What a request brought back. */
struct co_lss_master_result {
	/** Command specifier of the request (CO_LSS_CS_*). */
	uint8_t cs;
	/** 11h, 13h, 17h: the slave's error code (CO_LSS_ERR_*) and its byte 2. */
	uint8_t lss_err;
	uint8_t lss_spec;
	/** Inquire: the value (5Eh: the node-ID). */
	uint32_t value;
	/** Identify requests: answers counted during the timeout (merged frames count once). */
	uint16_t answers;
	/** Fastscan: the LSS address of the device it selected. */
	struct co_lss_address address;
	/** Frames this request sent (fastscan: every step, restarts included). */
	uint16_t frames;
	/** Fastscan: how many times the scan was restarted after a verify got no answer. */
	uint8_t restarts;
};

/**
 * @brief Confirmation of a request.
 *
 * Runs once per request that returned 0, in the line thread with the node's mutex held (or
 * in the thread of co_lss_master_cancel()); may start the next request.
 *
 * @param node The master's node.
 * @param err 0 on success; -ETIMEDOUT no answer within the timeout; -EREMOTEIO the slave
 *        answered with an error code (@p res lss_err, lss_spec); -ENODEV identify or fastscan:
 *        no slave answered; -EIO fastscan: every attempt lost its slave at a verify step;
 *        -ECANCELED cancelled (co_lss_master_cancel(), a reset of the node); or the send
 *        error of a later frame.
 * @param res What came back; valid during the call only.
 * @param user_data As given to the request.
 */
typedef void (*co_lss_master_con_t)(struct co_node *node, int err,
				    const struct co_lss_master_result *res, void *user_data);

/** Counters of the master. */
struct co_lss_master_stats {
	uint32_t requests;
	uint32_t frames_sent;
	uint32_t answers;
	/** Frames on 7E4h that were no answer to the running request (or came with none). */
	uint32_t ignored;
	uint32_t timeouts;
};

/** @cond INTERNAL_HIDDEN */
struct co_lss_master {
	struct co_rx rx;
	struct co_timer timer;
	/* The request running: its command specifier, 0 when idle. */
	uint8_t op;
	/* The answer it waits for (command specifier), 0 for none. */
	uint8_t expect;
	/* Fastscan: part under scan, bit under test (32: the probe, -1: the verify). */
	uint8_t fs_sub;
	int8_t fs_bit;
	uint8_t fs_known;
	bool answered;
	uint32_t timeout_ms;
	uint32_t fs_id;
	struct co_lss_address fs_known_addr;
	struct co_lss_master_result res;
	co_lss_master_con_t con;
	void *user_data;
	struct co_lss_master_stats stats;
};
/** @endcond */

/** @name Requests without an answer (any thread)
 * @{
 */

/**
 * @brief Switch state global (04h): every slave to waiting or configuration.
 *
 * @param node The master's node.
 * @param mode CO_LSS_MODE_WAITING or CO_LSS_MODE_CONFIGURATION.
 * @retval 0 Sent (queued on the line).
 * @retval -EINVAL Another mode.
 * @retval -EBUSY A request is running (its answers would be mixed up).
 * @retval other The send error of co_node_send().
 */
int co_lss_master_switch_global(struct co_node *node, uint8_t mode);

/**
 * @brief Activate bit timing (15h): the slaves in configuration switch to their configured
 *        bit timing, silent @p delay_ms before and after the switch.
 *
 * @retval 0 Sent. @retval -EBUSY A request is running. @retval other The send error.
 */
int co_lss_master_activate_bit_timing(struct co_node *node, uint16_t delay_ms);

/** @} */

/** @name Asynchronous requests
 *
 * @p timeout_ms 0 takes CONFIG_CANOPEN_LSS_MASTER_TIMEOUT (fastscan: its own
 * CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_TIMEOUT, per step). Each returns 0 (the confirmation
 * follows), -EBUSY (a request is running), -EINVAL (a bad argument) or the send error of the
 * first frame (nothing started).
 * @{
 */

/** Switch state selective (40h..43h) to the slave with @p addr; confirmed by its 44h. */
int co_lss_master_switch_selective_req(struct co_node *node, const struct co_lss_address *addr,
				       uint32_t timeout_ms, co_lss_master_con_t con,
				       void *user_data);

/** Configure node-ID (11h): 1..127 or CO_NODE_ID_UNCONFIGURED (FFh); else -EINVAL. */
int co_lss_master_config_node_id_req(struct co_node *node, uint8_t node_id, uint32_t timeout_ms,
				     co_lss_master_con_t con, void *user_data);

/** Configure bit timing (13h): table selector and index. */
int co_lss_master_config_bit_timing_req(struct co_node *node, uint8_t table, uint8_t index,
					uint32_t timeout_ms, co_lss_master_con_t con,
					void *user_data);

/** Store configuration (17h). */
int co_lss_master_store_req(struct co_node *node, uint32_t timeout_ms, co_lss_master_con_t con,
			    void *user_data);

/**
 * Inquire (5Ah..5Eh: vendor-ID, product code, revision, serial number, node-ID); the value
 * comes in the result. Another @p cs: -EINVAL.
 */
int co_lss_master_inquire_req(struct co_node *node, uint8_t cs, uint32_t timeout_ms,
			      co_lss_master_con_t con, void *user_data);

/**
 * Identify remote slave (46h..4Bh): is there a slave with this vendor-ID and product code,
 * its revision in @p rev_low..rev_high and its serial number in @p serial_low..serial_high
 * (bounds included)? Waits the whole timeout (any number may answer): 0 and the count of
 * answers, or -ENODEV.
 */
int co_lss_master_identify_remote_req(struct co_node *node, uint32_t vendor, uint32_t product,
				      uint32_t rev_low, uint32_t rev_high, uint32_t serial_low,
				      uint32_t serial_high, uint32_t timeout_ms,
				      co_lss_master_con_t con, void *user_data);

/** Identify non-configured remote slave (4Ch): 0 when any slave without node-ID answered. */
int co_lss_master_identify_non_configured_req(struct co_node *node, uint32_t timeout_ms,
					      co_lss_master_con_t con, void *user_data);

/**
 * @brief Fastscan: select one slave without node-ID (the lowest LSS address among those
 *        whose known parts match).
 *
 * Probe, then for each part of the LSS address 32 bit steps and a verify, each step waiting
 * the whole @p timeout_ms: at most 1 + 4 x 33 frames. A part whose bit in @p known_mask
 * (BIT(0) vendor-ID .. BIT(3) serial number) is set is taken from @p known and only
 * verified (one frame). A verify without answer (a slave lost on the way) restarts the scan,
 * at most CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_RESTARTS times (then -EIO).
 *
 * On success the selected slave is in LSS configuration and its address is in the result;
 * configure its node-ID next, then switch global to waiting. Call again for the next one
 * until -ENODEV (no slave without node-ID answered the probe).
 */
int co_lss_master_fastscan_req(struct co_node *node, const struct co_lss_address *known,
			       uint8_t known_mask, uint32_t timeout_ms, co_lss_master_con_t con,
			       void *user_data);

/**
 * @brief Cancel the running request: confirmed with -ECANCELED, here and now.
 * @retval 0 Cancelled. @retval -EALREADY No request was running.
 */
int co_lss_master_cancel(struct co_node *node);

/** @brief Whether a request is running. */
bool co_lss_master_busy(struct co_node *node);

/** @brief The master's counters. */
void co_lss_master_get_stats(struct co_node *node, struct co_lss_master_stats *stats);

/** @} */

/** @name Blocking requests (application threads only)
 *
 * Each starts the request of the same name with the default protocol timeout and waits for
 * its confirmation. @p timeout bounds the whole call (K_FOREVER: the protocol timeouts
 * only; K_NO_WAIT is refused, -EINVAL). @p res may be NULL. Returns what the confirmation
 * got (0, -ETIMEDOUT, -EREMOTEIO, -ENODEV, -EIO), or:
 * - -EAGAIN: @p timeout expired first; the request was cancelled, the master is idle;
 * - -EDEADLK: called from a line thread, or holding the mutex of a node on the master's
 *   line; nothing started;
 * - -EBUSY, -EINVAL or a send error: nothing started.
 * @{
 */
int co_lss_master_switch_selective(struct co_node *node, const struct co_lss_address *addr,
				   k_timeout_t timeout, struct co_lss_master_result *res);
int co_lss_master_config_node_id(struct co_node *node, uint8_t node_id, k_timeout_t timeout,
				 struct co_lss_master_result *res);
int co_lss_master_config_bit_timing(struct co_node *node, uint8_t table, uint8_t index,
				    k_timeout_t timeout, struct co_lss_master_result *res);
int co_lss_master_store(struct co_node *node, k_timeout_t timeout,
			struct co_lss_master_result *res);
int co_lss_master_inquire(struct co_node *node, uint8_t cs, k_timeout_t timeout,
			  struct co_lss_master_result *res);
int co_lss_master_identify_remote(struct co_node *node, uint32_t vendor, uint32_t product,
				  uint32_t rev_low, uint32_t rev_high, uint32_t serial_low,
				  uint32_t serial_high, k_timeout_t timeout,
				  struct co_lss_master_result *res);
int co_lss_master_identify_non_configured(struct co_node *node, k_timeout_t timeout,
					  struct co_lss_master_result *res);
int co_lss_master_fastscan(struct co_node *node, const struct co_lss_address *known,
			   uint8_t known_mask, k_timeout_t timeout,
			   struct co_lss_master_result *res);
/** @} */

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_LSS_MASTER_H_ */
