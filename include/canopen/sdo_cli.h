/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CiA 301 SDO client (§7.2.4): expedited, segmented and block transfers to a server.
 *
 * A node has CONFIG_CANOPEN_SDO_CLIENTS clients. Client n is configured by the SDO client
 * parameter object 1280h + n (COB-ID client to server in sub-index 1, server to client in
 * sub-index 2, server node-ID in sub-index 3, CiA 301 §7.5.2.34) when that object is in the
 * dictionary; otherwise (and in addition) co_sdo_cli_set_server() binds it to the default SDO
 * of a server node (600h + id / 580h + id), the way a manager talks to each of its slaves.
 *
 * One client runs one transfer at a time; transfers on different clients run concurrently.
 * The data of a download and the buffer of an upload belong to the caller until the
 * confirmation: the client keeps no copy.
 *
 * Requests (co_sdo_cli_*_req()) are asynchronous and may be called from any thread,
 * including from any callback of the stack in a line thread (they never block or wait for the
 * bus). The confirmation runs later in the line thread of the node, with the node's mutex
 * held, exactly once per accepted request; it may start the next transfer. The blocking calls
 * (co_sdo_cli_upload()/co_sdo_cli_download()) are for application threads only: they return
 * -EDEADLK in any line thread or with the mutex of a node of the client's line held. Their
 * result cannot be ignored (warn_unused_result): 0, a negative errno for the call, or
 * -ECONNABORTED with the CiA 301 abort code in a required out-parameter.
 *
 * @defgroup co_sdo_cli SDO client
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SDO_CLI_H_
#define SAFELINE_INCLUDE_CANOPEN_SDO_CLI_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/sdo_abort.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;
struct co_sdo_cli;

/** Index of the first SDO client parameter object. */
#define CO_SDO_CLI_PARAM_INDEX 0x1280U

/** How a transfer is carried out. */
enum co_sdo_cli_mode {
	/**
	 * Download: expedited up to 4 bytes, segmented above. Upload: whatever the server
	 * answers (expedited or segmented).
	 */
	CO_SDO_CLI_AUTO,
	/** Segmented even for 1..4 bytes (download); plain upload. */
	CO_SDO_CLI_SEGMENTED,
	/** Block transfer with CRC (the server may refuse CRC; then without). */
	CO_SDO_CLI_BLOCK,
};

/**
 * @brief Confirmation of a transfer.
 *
 * Runs in the node's line thread with the node's mutex held; must not block; may start the
 * next transfer on this or another client.
 *
 * @param cli The client.
 * @param abort_code 0 on success, otherwise the CiA 301 abort code (received from the server,
 *        or sent by the client: timeout 05040000h, buffer too small 05040005h, CRC 05040004h,
 *        ...), or CO_SDO_AB_GENERAL when the transfer was dropped by an NMT reset/stop.
 * @param size Bytes transferred (upload: bytes written into the caller's buffer).
 * @param user_data As passed with the request.
 */
typedef void (*co_sdo_cli_con_t)(struct co_sdo_cli *cli, uint32_t abort_code, size_t size,
				 void *user_data);

/* struct co_sdo_cli is defined by the implementation (sdo/sdo_cli.c) below this line. */

/** Counters of a client, for diagnostics and tests. */
struct co_sdo_cli_stats {
	uint32_t completed;       /**< Transfers confirmed with 0. */
	uint32_t aborts_sent;     /**< Aborts the client sent (its own or the application's). */
	uint32_t aborts_rcvd;     /**< Aborts received from the server. */
	uint32_t dropped;         /**< Transfers ended by NMT or reconfiguration (no frame). */
	uint32_t rx_malformed;    /**< Frames ignored: DLC != 8 or remote. */
	uint32_t rx_stray;        /**< Frames ignored: no transfer running, or a late answer. */
	uint32_t blk_seg_ignored; /**< Block upload segments ignored (gap, duplicate). */
	uint32_t tx_retries;      /**< Block download segments held back by a full TX queue. */
	uint32_t last_abort;      /**< Last abort code sent or received. */
};

/** An SDO client. Embedded in struct co_node; all fields are private. */
struct co_sdo_cli {
	/** @cond INTERNAL_HIDDEN */
	struct co_node *node;
	struct co_rx rx;
	struct co_timer timer;
	/* Client to server (sent) and server to client (received), as in 1280h sub 1/2. */
	uint32_t cob_tx;
	uint32_t cob_rx;
	uint8_t server_id;
	uint8_t num;
	uint8_t state;
	/* NMT Pre-operational or Operational. */
	bool active;
	/* Writing its own 1280h entries (co_sdo_cli_set_server()): exempt from the rule. */
	bool own_write;
	bool upload;
	bool exp;
	bool size_ind;
	bool crc_on;
	bool blk_last;
	uint8_t toggle;
	uint8_t blksize;
	uint8_t seq;
	uint8_t nseg;
	uint8_t pst;
	uint8_t tx_waits;
	uint16_t index;
	uint8_t sub;
	uint8_t last_seg[7];
	uint16_t crc;
	enum co_sdo_cli_mode mode;
	const uint8_t *dn_data;
	uint8_t *up_buf;
	/* Download: length of the data; upload: capacity of the buffer. */
	size_t len;
	/* Size indicated by the server (upload). */
	size_t size;
	/* Bytes confirmed by the server (download) or stored in order (upload). */
	size_t offset;
	/* Bytes of the segment in flight (segmented download). */
	size_t pending;
	uint64_t timeout_us;
	uint64_t deadline;
	uint64_t retry_at;
	uint32_t result;
	co_sdo_cli_con_t con;
	void *user_data;
	struct co_sdo_cli_stats stats;
	/** @endcond */
};

/**
 * @brief Client @p num of @p node.
 * @return The client, or NULL if @p num >= CONFIG_CANOPEN_SDO_CLIENTS.
 */
struct co_sdo_cli *co_sdo_cli_get(struct co_node *node, uint8_t num);

/**
 * @brief Bind a client to the default SDO of server node @p server_id.
 *
 * Uses 600h + id (client to server) and 580h + id (server to client). Writes 1280h + n
 * sub-indexes 1..3 when that object is in the dictionary.
 *
 * Without 1280h + n the binding survives Reset Communication; with it, the object's values
 * rule (Reset Communication restores them from the dictionary or storage).
 *
 * @retval 0 Bound.
 * @retval -EINVAL @p server_id outside 1..127.
 * @retval -EBUSY A transfer is running on the client.
 * @retval -EIO The dictionary refused the new COB-IDs (1280h + n).
 */
int co_sdo_cli_set_server(struct co_sdo_cli *cli, uint8_t server_id);

/**
 * @brief Start a download (write @p len bytes of @p data to index/sub of the server).
 *
 * @param timeout_ms Protocol timeout: longest wait for each answer of the server [ms]
 *        (0: CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT).
 * @retval 0 Started; @p con will be called once.
 * @retval -EBUSY A transfer is running on this client.
 * @retval -ENOTCONN The client has no valid COB-IDs.
 * @retval -ENETDOWN The node is not Pre-operational or Operational (Stopped or Initialising).
 * @retval -EINVAL NULL data with @p len > 0, @p len above 4 GiB - 1, or no @p con.
 * @retval -ENOBUFS, -ENETDOWN, -EIO The first frame could not be sent (co_node_send());
 *         nothing started, no confirmation follows.
 */
int co_sdo_cli_download_req(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, const void *data,
			    size_t len, enum co_sdo_cli_mode mode, uint32_t timeout_ms,
			    co_sdo_cli_con_t con, void *user_data);

/**
 * @brief Start an upload (read index/sub of the server into @p buf of @p cap bytes).
 *
 * A value longer than @p cap is aborted with 05040005h (out of memory) towards the server
 * and confirmed with that code.
 *
 * @return As co_sdo_cli_download_req().
 */
int co_sdo_cli_upload_req(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, void *buf,
			  size_t cap, enum co_sdo_cli_mode mode, uint32_t timeout_ms,
			  co_sdo_cli_con_t con, void *user_data);

/**
 * @brief Abort the running transfer with @p abort_code (sent to the server); the confirmation
 * follows with that code.
 *
 * Any thread. The abort frame goes out at once; the confirmation runs later in the line
 * thread, as always.
 *
 * @retval 0 Aborted.
 * @retval -EALREADY No transfer was running (or it has ended and its confirmation waits).
 * @retval -EINVAL @p abort_code is 0.
 */
int co_sdo_cli_abort_req(struct co_sdo_cli *cli, uint32_t abort_code);

/**
 * @brief Whether the client is busy: a transfer runs or its confirmation has not run yet.
 */
bool co_sdo_cli_busy(struct co_sdo_cli *cli);

/** @brief Copy the client's counters. */
void co_sdo_cli_get_stats(struct co_sdo_cli *cli, struct co_sdo_cli_stats *stats);

/**
 * @brief Download @p len bytes of @p data to index/sub of the server and wait for the result.
 *
 * For application threads: runs co_sdo_cli_download_req() and waits for its confirmation.
 * The result must be used (warn_unused_result): a failed transfer is reported only there.
 *
 * Timeouts. Each answer of the server is awaited at most CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT,
 * the protocol timeout of a request with @c timeout_ms 0: a server that stops answering is
 * aborted with 05040000h and the call returns -ECONNABORTED. @p timeout bounds the whole
 * call (all frames of the transfer): when it expires first, the client sends abort 05040000h
 * to the server and the call returns -EAGAIN at once, without waiting for a line thread; the
 * client is then idle (ready for the next transfer) and no longer uses @p data.
 *
 * Deadlocks. The confirmation comes from the line thread of the client's node, which takes
 * the mutex of every node attached to that line. The call refuses with -EDEADLK, before
 * starting anything, when it is made from any line thread (a callback of the stack) or while
 * the calling thread holds the mutex of any node attached to the client's line, the client's
 * own node included (co_node_lock()). Use co_sdo_cli_download_req() there.
 *
 * @param cli The client.
 * @param index Index of the object on the server.
 * @param sub Sub-index of the object on the server.
 * @param data The value; used in place until the call returns. NULL only with @p len 0.
 * @param len Bytes of the value (up to 4 GiB - 1).
 * @param mode How to transfer (enum co_sdo_cli_mode).
 * @param timeout Longest duration of the whole call: K_MSEC() and friends, an absolute
 *        K_TIMEOUT_ABS_MS() and friends, or K_FOREVER (bounded by the protocol timeout
 *        only). K_NO_WAIT is refused: a transfer cannot complete without waiting.
 * @param[out] abort_code Required. The CiA 301 abort code when the call returns
 *        -ECONNABORTED; 0 on every other return (written whenever it is not NULL).
 *
 * @retval 0 Done: the server confirmed the whole value.
 * @retval -ECONNABORTED The transfer was aborted; *abort_code says why: the server's code,
 *         the code the client sent (05040000h protocol timeout, 05040001h unexpected answer,
 *         ...), or 08000000h when an NMT state change or a reconfiguration of the client
 *         dropped it.
 * @retval -EAGAIN @p timeout expired before the transfer ended; the client aborted it
 *         towards the server with 05040000h.
 * @retval -EDEADLK Called from a line thread, or with the mutex of a node of the client's
 *         line held; nothing was started.
 * @retval -EINVAL NULL @p cli or @p abort_code, @p timeout K_NO_WAIT, or an argument
 *         co_sdo_cli_download_req() refuses (NULL data with @p len > 0, @p len too large).
 * @retval -EBUSY A transfer is running on this client; nothing was started.
 * @retval -ENOTCONN The client has no valid COB-IDs; nothing was started.
 * @retval -ENETDOWN The node is not Pre-operational or Operational (or its line refused the
 *         first frame); nothing was started.
 * @retval -ENOBUFS, -EIO The first frame could not be sent (other errors of co_node_send()
 *         pass through too); nothing was started.
 */
__attribute__((__warn_unused_result__)) int
co_sdo_cli_download(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, const void *data,
		    size_t len, enum co_sdo_cli_mode mode, k_timeout_t timeout,
		    uint32_t *abort_code);

/**
 * @brief Upload index/sub of the server into @p buf of @p cap bytes and wait for the result.
 *
 * As co_sdo_cli_download(): same timeouts, same deadlock rule, same return contract. A value
 * longer than @p cap is aborted with 05040005h (-ECONNABORTED); nothing is written past
 * @p cap. @p buf is used in place until the call returns.
 *
 * @param cli The client.
 * @param index Index of the object on the server.
 * @param sub Sub-index of the object on the server.
 * @param buf Buffer for the value; NULL only with @p cap 0.
 * @param cap Bytes @p buf holds.
 * @param[out] len Bytes written into @p buf (on -ECONNABORTED or -EAGAIN, how far the transfer
 *        got; 0 when nothing was started); may be NULL.
 * @param mode How to transfer (enum co_sdo_cli_mode).
 * @param timeout Longest duration of the whole call, as co_sdo_cli_download().
 * @param[out] abort_code Required; as co_sdo_cli_download().
 *
 * @retval 0 Done: *len bytes of the value are in @p buf.
 * @retval -ECONNABORTED The transfer was aborted; *abort_code says why.
 * @retval -EAGAIN @p timeout expired before the transfer ended (abort 05040000h sent).
 * @retval -EDEADLK Called from a line thread, or with the mutex of a node of the client's
 *         line held; nothing was started.
 * @retval -EINVAL NULL @p cli or @p abort_code, @p timeout K_NO_WAIT, or NULL @p buf with
 *         @p cap > 0.
 * @retval -EBUSY, -ENOTCONN, -ENETDOWN, -ENOBUFS, -EIO As co_sdo_cli_download(); nothing was
 *         started.
 */
__attribute__((__warn_unused_result__)) int
co_sdo_cli_upload(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, void *buf, size_t cap,
		  size_t *len, enum co_sdo_cli_mode mode, k_timeout_t timeout,
		  uint32_t *abort_code);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_SDO_CLI_H_ */
