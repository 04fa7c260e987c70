/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Safety-relevant data objects (CiA 304 / EN 50325-5, objects 1300h-13FFh).
 *
 * An SRDO carries safety data as a pair of frames: the normal frame on COB-ID 1, then the
 * inverted frame on COB-ID 2, whose bytes are the bitwise complement of the normal ones. A
 * producer sends a pair every refresh time; a consumer checks every pair completely inside
 * the stack, on the frames' receive timestamps:
 * - SRVT: the inverted frame arrives at most SRVT after its normal frame;
 * - SCT: two complete, valid pairs are at most SCT apart;
 * - inversion: every byte of the inverted frame is the complement of the normal byte;
 * - length: both frames carry at least the mapped bytes.
 * A failed check writes nothing to the dictionary and latches the SRDO in the safe state
 * until the node leaves Operational and enters it again.
 *
 * SRDOs run in Operational only, and only with a valid configuration: 13FEh = A5h and each
 * active SRDO's parameters, mapping and 13FFh signature (CRC-16 of CiA 304) consistent. When
 * 13FEh = A5h and an SRDO fails that check, the node refuses Operational (EMCY 6300h, 13FEh
 * cleared) unless CONFIG_CANOPEN_SRDO_PERMISSIVE_START is set.
 *
 * SRDO numbers in this API count from 1, as the standard does: SRDO n is 1300h + n (the
 * communication record) and 1380h + n (the mapping record).
 *
 * @defgroup co_srdo SRDO
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SRDO_H_
#define SAFELINE_INCLUDE_CANOPEN_SRDO_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/od.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** @name Objects and values (CiA 304)
 * @{
 */
#define CO_SRDO_IDX_GFC       0x1300U /**< GFC parameter: 1 = GFC valid */
#define CO_SRDO_IDX_COMM      0x1300U /**< 1300h + n: communication record of SRDO n */
#define CO_SRDO_IDX_MAP       0x1380U /**< 1380h + n: mapping record of SRDO n */
#define CO_SRDO_IDX_VALID     0x13FEU /**< configuration valid */
#define CO_SRDO_IDX_SIGNATURE 0x13FFU /**< sub n: configuration signature of SRDO n */
#define CO_SRDO_VALID         0xA5U   /**< 13FEh value that declares the configuration valid */
#define CO_SRDO_DIR_NONE      0U      /**< 1301h+ sub 1: the SRDO does not exist */
#define CO_SRDO_DIR_TX        1U      /**< 1301h+ sub 1: producer */
#define CO_SRDO_DIR_RX        2U      /**< 1301h+ sub 1: consumer */
#define CO_SRDO_TT            254U    /**< the only transmission type of an SRDO */
#define CO_SRDO_GFC_COB_ID    0x001U  /**< global fail-safe command */
/** Bare default of SRDO 1's COB-ID 1: the stack adds 2 x node-ID (nodes 1..64). */
#define CO_SRDO_COB1_BASE     0x0FFU
/** Bare default of SRDO 1's COB-ID 2: the stack adds 2 x node-ID (nodes 1..64). */
#define CO_SRDO_COB2_BASE     0x100U
/** Highest SRDO number. */
#define CO_SRDO_MAX           64U
/** @} */

/** What an SRDO is doing (co_srdo_get_state()). */
enum co_srdo_state {
	/** Direction 0: the SRDO does not exist; it does not hold the node in the safe state. */
	CO_SRDO_STATE_DELETED,
	/** The SRDO holds its user in the safe state; the reason says why. */
	CO_SRDO_STATE_SAFE,
	/** Producing, or consuming valid pairs in time. */
	CO_SRDO_STATE_VALID,
};

/** Why an SRDO is in the safe state (also the reason of CO_EV_SRDO events). */
enum co_srdo_reason {
	/** Not in the safe state (CO_SRDO_STATE_VALID). */
	CO_SRDO_R_NONE,
	/** The node is not Operational. */
	CO_SRDO_R_NOT_OPERATIONAL,
	/** Operational, no valid pair received (consumer) or sent (producer) yet. */
	CO_SRDO_R_STARTING,
	/** The configuration is not valid: 13FEh is not A5h, or the check failed. */
	CO_SRDO_R_CONFIG,
	/** No valid pair within SCT of the previous one (consumer). */
	CO_SRDO_R_SCT,
	/** The inverted frame did not arrive within SRVT of the normal frame (consumer). */
	CO_SRDO_R_SRVT,
	/** The inverted frame is not the complement of the normal frame. */
	CO_SRDO_R_NOT_INVERTED,
	/** A frame shorter than the mapped data (consumer; EMCY 8210h). */
	CO_SRDO_R_SHORT,
	/** The pair could not be queued for sending (producer). */
	CO_SRDO_R_TX_FAIL,
	/** A global fail-safe command was received (events with SRDO number 0 only). */
	CO_SRDO_R_GFC,
};

/**
 * @name Emergency codes and details
 *
 * SCT, SRVT and inversion faults raise 8200h (protocol error) with manufacturer bytes
 * [SRDO number, CO_SRDO_R_*]; a short frame raises 8210h with [SRDO number]; a configuration
 * that fails its check raises 6300h with [SRDO number, then index << 16 | sub << 8 | cause
 * as little-endian UNSIGNED32]. They are cleared when the node leaves Operational.
 * @{
 */
#define CO_EMCY_SRDO_PROTOCOL 0x8200U /**< SCT, SRVT or inversion fault */
#define CO_EMCY_SRDO_CONFIG   0x6300U /**< data set: configuration check failed */
/** @} */

/** @name Causes in the detail of a configuration fault (low byte)
 * @{
 */
#define CO_SRDO_CFG_MISSING   1U  /**< an object of the configuration is missing */
#define CO_SRDO_CFG_VALUE     2U  /**< a parameter value is not allowed */
#define CO_SRDO_CFG_CRC       3U  /**< the signature 13FFh does not match */
#define CO_SRDO_CFG_TOO_LONG  4U  /**< the mapped data exceed 8 bytes */
#define CO_SRDO_CFG_NO_OBJECT 5U  /**< a mapped object does not exist */
#define CO_SRDO_CFG_MAPPING   6U  /**< a mapped object cannot be mapped (access, length) */
#define CO_SRDO_CFG_PAIR_LEN  7U  /**< a normal object and its inverted partner differ */
#define CO_SRDO_CFG_EMPTY     8U  /**< nothing mapped */
#define CO_SRDO_CFG_RX_SLOT   11U /**< no receive slot on the line */
/** @} */

/**
 * @brief SRDO indication: an SRDO entered or left the safe state, or a GFC arrived.
 *
 * Called at every change of an SRDO's state or reason, and with @p srdo 0 and reason
 * CO_SRDO_R_GFC for a received global fail-safe command. The same news reaches listeners as
 * CO_EV_SRDO events. Runs in the line thread (or the thread that changed the NMT state) with
 * the node's mutex held; must not block.
 *
 * @param node The node.
 * @param srdo SRDO number 1..64, or 0 for a GFC.
 * @param safe The SRDO is now in the safe state.
 * @param reason Why (enum co_srdo_reason).
 * @param time_us When [µs, node time]: for a faulty or valid frame its receive time; for a
 *        missing frame (SRVT, SCT) when the line thread ran the deadline, i.e. the deadline
 *        plus the thread's wake-up (and CONFIG_CANOPEN_SRDO_RX_ALLOWANCE_US).
 * @param user_data As registered.
 */
typedef void (*co_srdo_ind_t)(struct co_node *node, uint8_t srdo, bool safe,
			      enum co_srdo_reason reason, uint64_t time_us, void *user_data);

/** @cond INTERNAL_HIDDEN */
#if defined(CONFIG_CANOPEN_SRDO)
/*
 * One mapped object, resolved once per entry into Operational: its description, with which
 * the accessors reach its value and its hooks without a lookup.
 */
struct co_srdo_ent {
	struct co_od_info info;
	uint8_t offset; /* in its frame */
	uint8_t bytes;
};

struct co_srdo_inst {
	struct co_rx rx_normal;
	struct co_rx rx_inverted;
	struct co_timer timer;
	struct co_node *node;
	/* Timing [µs]: refresh (producer) or SCT (consumer), and SRVT. */
	uint32_t cycle_us;
	uint32_t srvt_us;
	/* Consumer: when it started, deadlines of the current pair and of the next valid pair. */
	uint64_t start_us;
	uint64_t srvt_deadline;
	uint64_t sct_deadline;
	uint16_t cob1;
	uint16_t cob2;
	/* In mapping order: even positions normal objects, odd positions their inverted partners.
	 */
	struct co_srdo_ent ent[16];
	uint8_t n_ent;
	uint8_t len; /* bytes per frame */
	uint8_t normal[8];
	uint8_t number;
	uint8_t dir;
	uint8_t reason; /* enum co_srdo_reason */
	bool expect_inverted;
};

struct co_srdo {
	struct co_srdo_inst inst[CONFIG_CANOPEN_SRDOS];
	struct co_listener listener;
	struct co_rx gfc_rx;
	uint8_t n_srdo;
	/* Emergencies raised since Operational was entered (srdo.c). */
	uint8_t raised;
	bool gfc_valid;
	co_srdo_ind_t ind;
	void *ind_user_data;
};
#endif
/** @endcond */

/**
 * @brief Whether the application may leave its safe state.
 *
 * True when the node is Operational, its SRDO configuration is declared valid (13FEh = A5h,
 * checked when written and on entering Operational) and every SRDO that exists (direction 1
 * or 2) is valid: every producer has sent and every consumer has received a valid pair in
 * time, and none has failed since the node entered Operational. SRDOs of direction 0 do not
 * count, but deleting one over SDO withdraws 13FEh and so makes this false until the
 * configuration is declared valid again. An application that needs a particular SRDO also
 * checks it with co_srdo_get_state().
 */
bool co_srdo_may_leave_safe_state(struct co_node *node);

/**
 * @brief State of one SRDO.
 *
 * @param node The node.
 * @param srdo SRDO number, 1..64.
 * @param reason If not NULL, gets why the SRDO is in the safe state (CO_SRDO_R_NONE when it
 *        is valid or deleted).
 * @retval >=0 An enum co_srdo_state.
 * @retval -EINVAL @p srdo is not an SRDO of the node's dictionary.
 */
int co_srdo_get_state(struct co_node *node, uint8_t srdo, enum co_srdo_reason *reason);

/**
 * @brief Send an extra pair of a producer now (CiA 304 on-demand transmission).
 *
 * The pair samples the mapped objects now; the refresh time restarts from it.
 *
 * @retval 0 Queued.
 * @retval -EINVAL @p srdo is not a producer of the node's dictionary.
 * @retval -ENETDOWN The producer does not run (not Operational, configuration not valid, or
 *         latched in the safe state).
 * @retval -ENOSPC The pair does not fit the TX queue; the producer is now in the safe state
 *         (CO_SRDO_R_TX_FAIL).
 */
int co_srdo_send_req(struct co_node *node, uint8_t srdo);

/**
 * @brief Send a global fail-safe command (COB-ID 001h, no data).
 *
 * @retval 0 Queued.
 * @retval -EPERM GFC is not valid (1300h = 0).
 * @retval -ENETDOWN The node is neither Pre-operational nor Operational.
 * @retval other As co_node_send().
 */
int co_srdo_gfc_req(struct co_node *node);

/** @brief Set the SRDO indication (NULL removes it). */
void co_srdo_set_ind(struct co_node *node, co_srdo_ind_t cb, void *user_data);

/**
 * @brief The configuration signature of an SRDO as CiA 304 computes it (13FFh sub n).
 *
 * CRC-16 (polynomial 1021h, start 0) over direction, refresh time/SCT, SRVT, the two
 * COB-IDs, the mapping count and each mapping entry preceded by its sub-index, multi-byte
 * values least significant byte first, from the dictionary's current values.
 *
 * @param node The node.
 * @param srdo SRDO number, 1..64.
 * @param crc Gets the signature.
 * @retval 0 Done.
 * @retval -EINVAL @p srdo is not an SRDO of the node's dictionary, or its objects are
 *         incomplete.
 */
int co_srdo_signature(struct co_node *node, uint8_t srdo, uint16_t *crc);

/**
 * @brief CRC-16 of CiA 304's configuration signature over @p len bytes.
 *
 * @param crc Start value (0 for a new signature).
 * @param data Bytes.
 * @param len Number of bytes.
 * @return The CRC so far.
 */
uint16_t co_srdo_crc(uint16_t crc, const uint8_t *data, size_t len);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_SRDO_H_ */
