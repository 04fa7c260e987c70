/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CiA 301 SDO (service data objects): the SDO server.
 *
 * A node has CONFIG_CANOPEN_SDO_SERVERS servers; server n is configured by the SDO server
 * parameter object 1200h + n (COB-ID client to server in sub-index 1, server to client in
 * sub-index 2, CiA 301 §7.5.2.33). Each server runs expedited, segmented and block transfers
 * (download and upload, CRC on or off, protocol switch) against the node's object dictionary,
 * through the dictionary's accessors: every write is checked, validated by the hooks and only
 * committed when complete, every read respects the access rights. Values larger than the
 * server's buffer stream through the dictionary in chunks.
 *
 * The node runs the servers: co_node_init() calls co_sdo_srv_init(), every Reset
 * Communication calls co_sdo_srv_reset_comm(), every NMT state change calls
 * co_sdo_srv_set_state(). Frames arrive through a line receiver and timeouts are line timers,
 * both handled in the line thread with the node's mutex held. The protocol and its decisions
 * (which abort code for which frame) are described in doc/sdo.md.
 *
 * @defgroup co_sdo SDO
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SDO_H_
#define SAFELINE_INCLUDE_CANOPEN_SDO_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/od.h>
#include <canopen/sdo_abort.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Index of the first SDO server parameter object (the default SDO). */
#define CO_SDO_SRV_PARAM_INDEX 0x1200U
/** Default COB-ID client to server of the default SDO: 600h + node-ID. */
#define CO_SDO_SRV_DEFAULT_RX  0x600U
/** Default COB-ID server to client of the default SDO: 580h + node-ID. */
#define CO_SDO_SRV_DEFAULT_TX  0x580U

/**
 * @name SDO COB-ID bits (1200h-12FFh sub-index 1 and 2)
 * @{
 */
/** Bit 31: 1 = the channel does not exist / is not valid. */
#define CO_SDO_COBID_INVALID 0x80000000U
/** Bit 30: dynamically assigned (CiA 302-5); kept, no effect on the server. */
#define CO_SDO_COBID_DYN     0x40000000U
/** Bit 29: 29-bit CAN identifier. */
#define CO_SDO_COBID_FRAME   0x20000000U
/** Bits 28..0: the CAN identifier (bits 10..0 when bit 29 is 0). */
#define CO_SDO_COBID_ID_MASK 0x1fffffffU
/** @} */

/** Counters of one SDO server, for diagnostics and tests. */
struct co_sdo_srv_stats {
	/** Frames ignored because their DLC was not 8, or because they were remote frames. */
	uint32_t rx_malformed;
	/** Frames ignored because the node was not Pre-operational or Operational. */
	uint32_t rx_inactive;
	/** Block download segments ignored as duplicates or after a sequence gap. */
	uint32_t blk_seg_ignored;
	/** Block upload segments sent again after a partial acknowledgement. */
	uint32_t blk_seg_resent;
	/** Block upload segments offered again because the line's TX queue was full. */
	uint32_t tx_retries;
	/** Block upload sub-blocks cut short by a send error other than a full queue. */
	uint32_t tx_errors;
	/** Transfers completed. */
	uint32_t completed;
	/** Aborts sent by the server. */
	uint32_t aborts_sent;
	/** Aborts received from the client. */
	uint32_t aborts_received;
	/** Transfers dropped without a frame (NMT Stopped, reset, COB-ID made invalid). */
	uint32_t dropped;
	/** Code of the last abort sent or received (0 = none yet). */
	uint32_t last_abort;
};

/** @cond INTERNAL_HIDDEN */
#if defined(CONFIG_CANOPEN_SDO_SERVER_BUFFER_SIZE)
#define CO_SDO_SRV_BUF_SIZE CONFIG_CANOPEN_SDO_SERVER_BUFFER_SIZE
#else
#define CO_SDO_SRV_BUF_SIZE 889
#endif

/** One SDO server. Embedded in struct co_node; all fields are private. */
struct co_sdo_srv {
	struct co_node *node;
	struct co_rx rx;
	/* COB-IDs in use (sub-index 1 and 2 as last configured). */
	uint32_t cob_rx;
	struct co_timer timer;
	/*
	 * Chunked write into the dictionary (segmented and block download). An upload keeps
	 * its object in xfer.info: the two never run at once, and xfer.active stays false.
	 */
	struct co_od_xfer xfer;
	struct co_sdo_srv_stats stats;
	uint32_t cob_tx;
	/* Protocol timeout: last client frame + CONFIG_CANOPEN_SDO_SERVER_TIMEOUT. */
	uint64_t deadline;
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	/* Block download sub-block timeout (0 = not armed). */
	uint64_t sub_deadline;
	/* Retry of a sub-block the TX queue could not take (0 = none pending). */
	uint64_t retry_at;
#endif
	/* Size of the value: announced (download, if size_ind) or current (upload). */
	uint32_t size;
	/* Download: data bytes received (in order, excluding a held-back last segment).
	 * Upload (segmented): bytes sent. Block upload: offset of the current sub-block.
	 */
	uint32_t offset;
	/* Download: bytes already handed to the dictionary. Block upload: bytes in the CRC. */
	uint32_t done;
	/* Upload: value offset of buf[0]; download: unused. */
	uint32_t buf_off;
	/* Bytes valid in buf. */
	uint32_t buf_len;
	uint16_t index;
	uint8_t sub;
	uint8_t num;
	uint8_t state;
	uint8_t toggle;
	/* The line of the last request: answers go there. */
	uint8_t route;
	/* Timeouts put off because our own frames had not left the line yet. */
	uint8_t tx_waits;
	bool size_ind;
	/* NMT state is Pre-operational or Operational. */
	bool active;
	/* Inside the receive handler; a COB-ID change is applied when it returns. */
	bool in_rx;
	bool reconf;
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	uint16_t crc;
	/* Block size of the current sub-block. */
	uint8_t blksize;
	/* Block download: last in-order sequence number of the sub-block.
	 * Block upload: segments of the sub-block sent so far.
	 */
	uint8_t seq;
	/* Block upload: segments in the current sub-block. */
	uint8_t blk_nseg;
	bool crc_on;
	/* Block download: a segment arrived in this sub-block. Block upload: the current
	 * sub-block holds the last segment.
	 */
	bool blk_flag;
	/* Block download: the last segment, held until the end frame tells its length. */
	uint8_t tail[7];
#endif
	uint8_t buf[CO_SDO_SRV_BUF_SIZE] __attribute__((aligned(4)));
};
/** @endcond */

/**
 * @name Called by the node (subsys/canopen/core/node.c)
 * @{
 */

/**
 * @brief Initialise SDO server @p num of @p node. Once, from co_node_init().
 *
 * Binds the server to the node's line and dictionary; server 0 also registers the dictionary
 * hook that validates and applies writes to the COB-IDs of every server (1200h + n, sub-index
 * 1 and 2). The server stays silent until co_sdo_srv_reset_comm() and co_sdo_srv_set_state().
 *
 * @param srv  server (node->sdo_srv[num])
 * @param node node it belongs to
 * @param num  0 .. CONFIG_CANOPEN_SDO_SERVERS - 1; the server uses object 1200h + num
 * @retval 0 initialised
 * @retval -EINVAL NULL argument or @p num out of range
 * @retval -ENOSPC no room for the dictionary hook (CONFIG_CANOPEN_OD_HOOKS_MAX)
 */
int co_sdo_srv_init(struct co_sdo_srv *srv, struct co_node *node, uint8_t num);

/**
 * @brief Configure the server after a Reset Communication.
 *
 * Drops a running transfer without a frame, reads the COB-IDs from 1200h + num (server 0
 * uses 600h + node-ID and 580h + node-ID when 1200h is not in the dictionary) and registers
 * the receiver if both are valid.
 */
void co_sdo_srv_reset_comm(struct co_sdo_srv *srv);

/**
 * @brief Tell the server the node's NMT state.
 *
 * The server answers in Pre-operational and Operational only. In the other states frames are
 * ignored (counted in rx_inactive) and a running transfer is dropped without a frame.
 */
void co_sdo_srv_set_state(struct co_sdo_srv *srv, enum co_nmt_state state);

/** @} */

/**
 * @brief SDO server @p num of @p node.
 *
 * @return the server, or NULL if @p num >= CONFIG_CANOPEN_SDO_SERVERS
 */
struct co_sdo_srv *co_sdo_srv_get(struct co_node *node, uint8_t num);

/**
 * @brief Copy the counters of a server. Takes the node's mutex.
 */
void co_sdo_srv_get_stats(struct co_sdo_srv *srv, struct co_sdo_srv_stats *stats);

/**
 * @brief Whether the server is in a transfer. Takes the node's mutex.
 */
bool co_sdo_srv_busy(struct co_sdo_srv *srv);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_SDO_H_ */
