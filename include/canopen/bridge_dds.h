/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Cyclone DDS bridge for supervisory PCs (native_posix only).
 *
 * The bridge follows any number of lines and nodes of the process through the node core's
 * listeners and publishes what it learns as DDS topics: canopen/bridge_state,
 * canopen/line_state, canopen/node_state, canopen/emcy (with a history for late joiners),
 * canopen/srdo_state and canopen/od_value (objects chosen in the configuration file). It
 * serves SDO read/write and NMT requests (canopen/sdo/request -> reply,
 * canopen/nmt/request -> reply), refused unless the allow-list permits them. Types:
 * subsys/canopen/bridge/dds/idl/safeline_canopen.idl; everything else: doc/dds-bridge.md.
 *
 * Threads. Listeners run in line threads and never wait: they copy the event into a bounded
 * queue (an event that finds it full is counted and published as lost). One bridge thread
 * turns events into samples; one request thread serves requests with the blocking SDO
 * client calls (never on a line thread, never with a node lock held) and polls the selected
 * objects. No DDS call runs with a node or line lock held.
 *
 * One bridge per process: co_bridge_dds_init() once, then add lines and nodes (before or
 * after they start; the bridge reads their current state when they are added), and
 * co_bridge_dds_stop() at the end (also safe at process exit).
 *
 * @defgroup co_bridge_dds DDS bridge
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_BRIDGE_DDS_H_
#define SAFELINE_INCLUDE_CANOPEN_BRIDGE_DDS_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Domain id meaning CONFIG_CANOPEN_BRIDGE_DDS_DOMAIN. */
#define CO_BRIDGE_DDS_DOMAIN_DEFAULT UINT32_MAX

/** A bridged node without SDO client for requests. */
#define CO_BRIDGE_DDS_NO_SDO_CLIENT 0xFFU

/** How the bridge starts. */
struct co_bridge_dds_config {
	/** Name, the key of canopen/bridge_state (at most 32 characters); NULL: "safeline". */
	const char *name;
	/** DDS domain id, or CO_BRIDGE_DDS_DOMAIN_DEFAULT. */
	uint32_t domain_id;
	/**
	 * Cyclone DDS configuration: a file name, a file:// URI or XML text. NULL: the
	 * built-in loopback configuration (co_bridge_dds_loopback_config()), pinned to lo with
	 * multicast off. CYCLONEDDS_URI in the environment is never used: another configuration
	 * is a deliberate choice of the application.
	 */
	const char *dds_config;
	/**
	 * Bridge configuration file: the nodes' EDS files and the objects to publish
	 * (doc/dds-bridge.md, "Configuration file"); NULL: none.
	 */
	const char *config_file;
	/**
	 * Allow-list: which clients may write which objects of which nodes and send which NMT
	 * commands (doc/dds-bridge.md, "Allow-list"); NULL: read-only, every write and NMT
	 * request is refused.
	 */
	const char *allow_file;
};

/** What the bridge does with one node of the process. */
struct co_bridge_dds_node_config {
	/** Name in canopen/node_state (at most 32 characters); NULL: from its EDS, if any. */
	const char *name;
	/**
	 * SDO client of the node that serves SDO requests to other nodes of its line, or
	 * CO_BRIDGE_DDS_NO_SDO_CLIENT. The bridge rebinds it to each request's server
	 * (co_sdo_cli_set_server()): give it a client nobody else uses.
	 */
	uint8_t sdo_client;
};

/** Counters of the bridge (also published in canopen/bridge_state). */
struct co_bridge_dds_stats {
	uint32_t events;           /**< Events taken into the queue. */
	uint32_t events_lost;      /**< Events lost: the queue was full. */
	uint32_t queue_max;        /**< Highest queue occupancy seen. */
	uint32_t samples;          /**< Samples written. */
	uint32_t requests;         /**< SDO and NMT requests received. */
	uint32_t refused;          /**< Requests refused by the allow-list. */
	uint32_t malformed;        /**< Malformed requests, unknown lines and nodes. */
	uint32_t replies_deferred; /**< Replies held until the requester was discovered. */
	uint32_t replies_lost;     /**< Replies whose requester never appeared. */
};

/**
 * @brief Start the bridge: read the configuration files, create the DDS participant and its
 * topics, start the bridge and request threads.
 *
 * @retval 0 Running.
 * @retval -EALREADY The bridge was started before (one per process).
 * @retval -EINVAL A configuration file has an error (logged as FILE:LINE: reason), or a name
 *         is too long.
 * @retval -ENOENT A configuration file or an EDS it names cannot be read.
 * @retval -EIO Cyclone DDS refused the configuration or the participant (logged).
 */
int co_bridge_dds_init(const struct co_bridge_dds_config *cfg);

/**
 * @brief Follow a line: its controller state and counters (canopen/line_state) and the
 * heartbeats on it (the age of each node's last heartbeat).
 *
 * @param line An initialised line.
 * @param line_no The line's number in every topic (the key "line"), 0..254.
 * @param name Name in canopen/line_state (at most 32 characters; NULL: none).
 * @retval 0 Followed.
 * @retval -EINVAL NULL line, line_no 255 or a name too long.
 * @retval -EALREADY The line, or another line with that number, is followed already.
 * @retval -ENOSPC CONFIG_CANOPEN_BRIDGE_DDS_LINES lines are followed already.
 * @retval -ESRCH The bridge is not running.
 * @retval other As co_rx_register().
 */
int co_bridge_dds_add_line(struct co_line *line, uint8_t line_no, const char *name);

/**
 * @brief Follow a node: its own state and events, and what it learns of others (heartbeat
 * consumer, manager, EMCY consumer). Its default line must be followed already.
 *
 * @param node An initialised node.
 * @param cfg Options; NULL: no name, no SDO client.
 * @retval 0 Followed.
 * @retval -EINVAL NULL node, or a name too long.
 * @retval -ENOENT The node's default line is not followed.
 * @retval -EALREADY The node is followed already.
 * @retval -ENOSPC CONFIG_CANOPEN_BRIDGE_DDS_NODES nodes are followed already.
 * @retval -ESRCH The bridge is not running.
 * @retval other As co_node_listener_add().
 */
int co_bridge_dds_add_node(struct co_node *node, const struct co_bridge_dds_node_config *cfg);

/**
 * @brief Stop the bridge: end its threads and delete the DDS participant, so that clients
 * see the bridge's instances lose their writer at once.
 *
 * Safe from any thread, at process exit too; listeners and receivers stay registered and do
 * nothing from then on. Safe when the bridge is not running.
 */
void co_bridge_dds_stop(void);

/** @brief Whether the bridge is running. */
bool co_bridge_dds_running(void);

/** @brief Copy the bridge's counters. */
void co_bridge_dds_get_stats(struct co_bridge_dds_stats *stats);

/** @brief The built-in loopback configuration (XML). */
const char *co_bridge_dds_loopback_config(void);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_BRIDGE_DDS_H_ */
