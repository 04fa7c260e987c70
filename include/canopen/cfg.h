/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CiA 302 configuration manager (CMT, CiA 302 §6 / CiA 302-2 §3.5).
 *
 * The configuration manager stores the configuration of each slave of a CANopen manager and
 * downloads it to the slave over an SDO client:
 *  - 1F22h (concise DCF, ARRAY of DOMAIN, sub n = node-ID n): a binary stream of
 *    U32 count, then per entry U16 index, U8 sub-index, U32 size and size bytes of data,
 *    all little endian. It comes from const data the application registers
 *    (co_cfg_set_concise_dcf(), typically generated at build time by scripts/dcf2cdcf and
 *    canopen_concise_dcf() in CMake), or from SDO writes into a RAM pool of
 *    CONFIG_CANOPEN_CFG_POOL_SIZE bytes. Reading an empty sub-index returns `00 00 00 00`.
 *  - 1F20h (DCF, ARRAY of DOMAIN): stored and read back only; reading an empty sub-index is
 *    aborted with 08000024h.
 *  - 1F25h (configuration request): writing "conf" (666E6F63h) to sub n downloads the concise
 *    DCF of node n over the highest-numbered idle SDO client, rebound to node n's default
 *    SDO (with the NMT master only clients above CONFIG_CANOPEN_MGR_SLAVES, which its slave
 *    slots never use: 1F25h needs CONFIG_CANOPEN_SDO_CLIENTS >= CONFIG_CANOPEN_MGR_SLAVES + 1);
 *    sub 80h configures every node with a stored concise DCF, one after the other.
 *    The write succeeds at once; the result is reported through the indication
 *    (co_cfg_set_ind()). Refusals: another value 06090030h, no data for n 08000024h,
 *    malformed data 08000020h, busy or node down 08000022h, no idle client 060A0023h.
 *  - SDO writes of 1F20h/1F22h are refused with 08000022h while a download runs, with
 *    05040005h when the pool is full; a malformed concise DCF with 08000020h. The last
 *    complete write wins; an aborted one leaves the old value.
 *  - 1F26h/1F27h (expected configuration date/time per node, U32): served here when the
 *    dictionary lacks them. The comparison with the slave's 1020h is the NMT master's
 *    boot-up procedure (CiA 302-2 §3.5); it reads them with co_cfg_get_expected().
 *
 * Ownership: the application (or the manager) owns one `struct co_cfg` per manager node and
 * passes it to co_cfg_init(), which registers an object provider for 1F20h-1F27h and hooks
 * on the node's dictionary. There is no cfg member in struct co_node; code that has only the
 * node finds the instance with co_cfg_get().
 *
 * Locking: every call takes the node's mutex (recursive), so they may be made from
 * application threads and from the stack's callbacks alike. Confirmations and indications
 * run in the node's line thread with the node's mutex held and must not block.
 *
 * @defgroup co_cfg Configuration manager
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_CFG_H_
#define SAFELINE_INCLUDE_CANOPEN_CFG_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/od.h>
#include <canopen/sdo_abort.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;
struct co_sdo_cli;
struct co_cfg;

/** Store DCF (CiA 302 §6.1). */
#define CO_CFG_INDEX_DCF      0x1F20U
/** Concise DCF (CiA 302 §6.2). */
#define CO_CFG_INDEX_CDCF     0x1F22U
/** Configuration request (CiA 302 §6.4). */
#define CO_CFG_INDEX_REQ      0x1F25U
/** Expected configuration date (CiA 302 §6.3). */
#define CO_CFG_INDEX_DATE     0x1F26U
/** Expected configuration time (CiA 302 §6.3). */
#define CO_CFG_INDEX_TIME     0x1F27U
/** Signature "conf" written to 1F25h (bytes 63 6F 6E 66 on the wire). */
#define CO_CFG_SIGNATURE_CONF 0x666E6F63U
/** 1F25h sub-index and indication id meaning "all nodes". */
#define CO_CFG_ALL            0x80U
/** Size of the concise DCF header (entry count) [bytes]. */
#define CO_CFG_CDCF_HDR_SIZE  4U
/** Size of the header of one concise DCF entry (index, sub-index, size) [bytes]. */
#define CO_CFG_CDCF_ENTRY_HDR 7U

/**
 * @brief Confirmation of a configuration download, and indication of a 1F25h request.
 *
 * Runs in the manager node's line thread with its mutex held; must not block; may start the
 * next request (also on the same SDO client).
 *
 * @param node       The manager node.
 * @param id         Node-ID of the slave configured (CO_CFG_ALL for the final indication of
 *                   a 1F25h:80h request).
 * @param abort_code 0 if every entry was written; otherwise the CiA 301 abort code of the
 *                   first entry that failed (received from the slave, or the SDO client's
 *                   own, e.g. timeout 05040000h). Nothing after that entry was sent. For the
 *                   final CO_CFG_ALL indication: the first failure of any node, or 0.
 * @param index      Index of the failed entry (0 on success).
 * @param sub        Sub-index of the failed entry (0 on success).
 * @param user_data  As passed with the request / registered with co_cfg_set_ind().
 */
typedef void (*co_cfg_con_t)(struct co_node *node, uint8_t id, uint32_t abort_code, uint16_t index,
			     uint8_t sub, void *user_data);

/** @cond INTERNAL_HIDDEN */
#ifdef CONFIG_CANOPEN_CFG_POOL_SIZE
#define CO_CFG_POOL_SIZE CONFIG_CANOPEN_CFG_POOL_SIZE
#else
#define CO_CFG_POOL_SIZE 1024
#endif
#ifdef CONFIG_CANOPEN_CFG_JOBS
#define CO_CFG_JOBS CONFIG_CANOPEN_CFG_JOBS
#else
#define CO_CFG_JOBS 4
#endif
#ifdef CONFIG_CANOPEN_CFG_SDO_TIMEOUT
#define CO_CFG_SDO_TIMEOUT CONFIG_CANOPEN_CFG_SDO_TIMEOUT
#else
#define CO_CFG_SDO_TIMEOUT 0
#endif

#define CO_CFG_NODES 127U

/* Where the value of one 1F20h/1F22h sub-index lives. */
struct co_cfg_slot {
	const uint8_t *ext; /* application data (const), or NULL */
	uint32_t off;       /* pool offset when in_pool */
	uint32_t len;       /* length in bytes */
	bool in_pool;
};

/* One running download (one slave). */
struct co_cfg_job {
	struct co_cfg *cfg;
	struct co_sdo_cli *cli;
	co_cfg_con_t con;
	void *user_data;
	const uint8_t *data; /* the stream; stays put while the job runs */
	uint32_t len;
	uint32_t pos;       /* offset of the next entry header */
	uint32_t remaining; /* entries still to send */
	uint16_t index;     /* entry in flight */
	uint8_t sub;
	uint8_t id;
	bool active;
	bool all;              /* started by 1F25h:80h */
	struct co_timer defer; /* completes an empty stream outside the request */
};
/** @endcond */

/** A configuration manager instance. Allocate statically; all fields are private. */
struct co_cfg {
	/** @cond INTERNAL_HIDDEN */
	struct co_node *node;
	struct co_od_provider prov;
	co_cfg_con_t ind;
	void *ind_user_data;
	struct co_cfg_slot cdcf[CO_CFG_NODES];
	struct co_cfg_slot dcf[CO_CFG_NODES];
	uint32_t date[CO_CFG_NODES];
	uint32_t time[CO_CFG_NODES];
	/* RAM pool for SDO-written streams: committed values packed from 0 to pool_used. */
	uint8_t pool[CO_CFG_POOL_SIZE];
	uint32_t pool_used;
	/* The value being written (appended after pool_used until its last chunk). */
	struct co_cfg_slot *wr_slot;
	uint32_t wr_len;
	bool wr_overflow;
	struct co_cfg_job jobs[CO_CFG_JOBS];
	/* 1F25h:80h sweep: next node-ID to configure (0 = idle) and first failure. */
	uint8_t all_next;
	uint32_t all_abort;
	uint16_t all_index;
	uint8_t all_sub;
	/** @endcond */
};

/**
 * @brief Initialise a configuration manager and hook it into the node's dictionary.
 *
 * Registers an object provider for 1F20h-1F27h (it serves the objects the dictionary does
 * not have, and DOMAIN objects of the dictionary without RAM) and a validate hook on
 * 1F25h:01h-80h. Call before co_node_start(). All storage starts empty.
 *
 * @param cfg  Instance (statically allocated, outlives the node).
 * @param node Manager node (initialised with co_node_init()).
 * @retval 0 Initialised.
 * @retval -EINVAL A NULL argument.
 * @retval -EEXIST Another provider already serves part of 1F20h-1F27h.
 * @retval -ENOSPC No room for the provider or the hook (CONFIG_CANOPEN_OD_PROVIDERS_MAX,
 *         CONFIG_CANOPEN_OD_HOOKS_MAX).
 */
int co_cfg_init(struct co_cfg *cfg, struct co_node *node);

/**
 * @brief The configuration manager registered on @p node by co_cfg_init(), or NULL.
 *
 * Lets code that only has the node (the NMT master's boot-up procedure) reach the instance.
 */
struct co_cfg *co_cfg_get(struct co_node *node);

/**
 * @brief Register the indication of 1F25h requests (one call per node configured, then one
 * with id CO_CFG_ALL after a 1F25h:80h request).
 *
 * @retval 0 Registered (NULL removes it).
 * @retval -EINVAL @p cfg is NULL.
 */
int co_cfg_set_ind(struct co_cfg *cfg, co_cfg_con_t ind, void *user_data);

/**
 * @brief Make @p data the concise DCF of node @p id (1F22h:id), replacing any stored one.
 *
 * The data is not copied and must stay valid and unchanged while registered (e.g. the
 * const array generated by canopen_concise_dcf()). It is checked when applied, not here.
 * NULL with @p len 0 empties the sub-index. A later SDO write of 1F22h:id replaces it.
 *
 * @retval 0 Registered.
 * @retval -EINVAL @p id outside 1..127, NULL data with len > 0, or len >= 4 GiB.
 * @retval -EBUSY A download of @p id is running, or the old value is in the pool and a
 *         download is running (replacing it would move the stream being sent).
 */
int co_cfg_set_concise_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t *data, size_t len);

/**
 * @brief The concise DCF stored for node @p id (registered or written over SDO).
 *
 * The pointer stays valid until the next write of 1F20h/1F22h.
 *
 * @retval 0 Stored; *data and *len set.
 * @retval -ENOENT Nothing stored for @p id (reads of 1F22h:id return `00 00 00 00`).
 * @retval -EINVAL @p id outside 1..127 or a NULL argument.
 */
int co_cfg_get_concise_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t **data, size_t *len);

/**
 * @brief Make @p text the DCF file of node @p id (1F20h:id); stored and read back only.
 *
 * @return As co_cfg_set_concise_dcf().
 */
int co_cfg_set_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t *text, size_t len);

/**
 * @brief Expected configuration date and time of node @p id (1F26h:id, 1F27h:id).
 *
 * Read through the dictionary, so the values come from the dictionary's own 1F26h/1F27h when
 * it has them, else from this instance. Both 0 means "do not verify, download" (CiA 302-2
 * §3.5); comparing them with the slave's 1020h is the boot-up procedure's job.
 *
 * @retval 0 Read.
 * @retval -EINVAL @p id outside 1..127 or a NULL argument.
 */
int co_cfg_get_expected(struct co_cfg *cfg, uint8_t id, uint32_t *date, uint32_t *time);

/**
 * @brief Check the framing of a concise DCF stream.
 *
 * The stream must be at least 4 bytes, every entry header 7 bytes, every size within the
 * remaining bytes, and no byte may follow the last entry.
 *
 * @param data    Stream.
 * @param len     Its length in bytes.
 * @param entries Number of entries (may be NULL).
 * @retval 0 Well formed.
 * @retval -EBADMSG Truncated stream or entry, count mismatch or trailing bytes.
 * @retval -EINVAL NULL data with len > 0.
 */
int co_cfg_cdcf_check(const uint8_t *data, size_t len, uint32_t *entries);

/**
 * @brief Download the concise DCF of node @p id over @p cli, entry by entry in stream order.
 *
 * This is the "update configuration" step of the boot-up procedure (CiA 302-2 §3.5) and of
 * 1F25h. The whole stream is checked first (co_cfg_cdcf_check()), so a malformed stream
 * sends nothing. Each entry is one SDO download (expedited up to 4 bytes, segmented above)
 * of the data straight from storage; the first abort or timeout ends the download and is
 * confirmed with the entry's index/sub-index. An empty stream (count 0) is confirmed with
 * success from the line thread, never before this function returns.
 *
 * The NMT master's boot-up procedure calls this with the instance from co_cfg_get(node); it
 * is the `struct co_cfg *` form (not a `struct co_node *`) because the node has no cfg
 * member.
 *
 * @param cfg       Instance.
 * @param cli       SDO client already bound to the slave (co_sdo_cli_set_server() or 1280h);
 *                  the configuration manager does not rebind it. It must stay idle for other
 *                  users until @p con.
 * @param id        Node-ID 1..127 whose concise DCF is sent.
 * @param con       Confirmation, called exactly once when 0 is returned.
 * @param user_data Passed to @p con.
 * @retval 0 Started.
 * @retval -EINVAL NULL cfg/cli/con or @p id outside 1..127.
 * @retval -ENOENT No concise DCF stored for @p id.
 * @retval -EBADMSG The stored concise DCF is malformed; nothing was sent.
 * @retval -EBUSY A download of @p id is running, all CONFIG_CANOPEN_CFG_JOBS downloads are
 *         running, or @p cli is busy: retry later (the NMT master's boot-up waits for a job
 *         to end; it never fails a boot for this).
 * @retval -ENOTCONN, -ENETDOWN From co_sdo_cli_download_req() for the first entry.
 */
int co_cfg_download_req(struct co_cfg *cfg, struct co_sdo_cli *cli, uint8_t id, co_cfg_con_t con,
			void *user_data);

/** @brief Whether a download of node @p id (or of any node, for CO_CFG_ALL) is running. */
bool co_cfg_busy(struct co_cfg *cfg, uint8_t id);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_CFG_H_ */
