/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Emergency object (CiA 301 §7.2.7): producer (1001h, 1003h, 1014h, 1015h), consumer
 *        (1028h) and error behaviour (1029h).
 *
 * The application reports each error condition with co_emcy_raise() when it appears and
 * co_emcy_clear() when it goes away. The node keeps a table of active errors, derives the
 * error register 1001h from it, records every raise in the pre-defined error field 1003h and
 * sends one EMCY frame per raise and per clear, spaced by the inhibit time 1015h.
 *
 * @defgroup co_emcy Emergency
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_EMCY_H_
#define SAFELINE_INCLUDE_CANOPEN_EMCY_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/redundancy.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** @name Error register 1001h bits (CiA 301 §7.5.2.2)
 * @{
 */
#define CO_EMCY_REG_GENERIC       0x01U
#define CO_EMCY_REG_CURRENT       0x02U
#define CO_EMCY_REG_VOLTAGE       0x04U
#define CO_EMCY_REG_TEMPERATURE   0x08U
#define CO_EMCY_REG_COMMUNICATION 0x10U
#define CO_EMCY_REG_PROFILE       0x20U
#define CO_EMCY_REG_MANUFACTURER  0x80U
/** @} */

/** @name Some emergency error codes (CiA 301 Table 21)
 * @{
 */
#define CO_EMCY_NO_ERROR       0x0000U
#define CO_EMCY_GENERIC        0x1000U
#define CO_EMCY_CAN_OVERRUN    0x8110U
#define CO_EMCY_CAN_PASSIVE    0x8120U
#define CO_EMCY_HEARTBEAT      0x8130U
#define CO_EMCY_BUS_OFF_RECOV  0x8140U
#define CO_EMCY_PDO_LENGTH     0x8210U
#define CO_EMCY_PDO_LENGTH_EXC 0x8220U
#define CO_EMCY_SYNC_LENGTH    0x8240U
#define CO_EMCY_RPDO_TIMEOUT   0x8250U
/** @} */

/** @name Manufacturer field byte 0 of the stack's 8110h (which queue lost frames)
 * @{
 */
#define CO_EMCY_OVERRUN_RX 0x01U
#define CO_EMCY_OVERRUN_TX 0x02U
/** @} */

/** Base COB-ID of EMCY in the predefined connection set: 80h + node-ID. */
#define CO_EMCY_COB_ID 0x080U

/**
 * @brief EMCY consumer indication (a frame from a COB-ID listed in 1028h).
 *
 * Runs in the line thread with the node's mutex held; must not block.
 *
 * @param node The consuming node.
 * @param cob_id CAN-ID the frame came on.
 * @param remote_id Producer's node-ID when @p cob_id is 80h + 1..127, else 0.
 * @param code Emergency error code (0000h: error reset).
 * @param reg The producer's error register.
 * @param msef Manufacturer-specific error field (5 bytes).
 * @param user_data As registered.
 */
typedef void (*co_emcy_ind_t)(struct co_node *node, uint16_t cob_id, uint8_t remote_id,
			      uint16_t code, uint8_t reg, const uint8_t msef[5], void *user_data);

/** Counters and flags of a node's EMCY producer. */
struct co_emcy_status {
	/** Active errors. */
	uint8_t active;
	/** Frames waiting for the inhibit time to pass. */
	uint8_t queued;
	/** Frames lost because the queue was full (since the last reset communication). */
	uint32_t overflows;
};

/* The service state exists when the service is built; the codes above always do. */
#if defined(CONFIG_CANOPEN_EMCY)
/** @cond INTERNAL_HIDDEN */
struct co_emcy_active {
	uint16_t code;
	uint8_t reg;
	/* Raised by the stack itself (communication errors), dropped at reset communication. */
	bool internal;
};

struct co_emcy {
	/* Producer. */
	struct co_emcy_active active[CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS];
	uint8_t n_active;
	/* 1001h as derived, and the bits of errors that found the table full. */
	uint8_t reg;
	uint8_t lost_reg;
	uint8_t queue[CONFIG_CANOPEN_EMCY_QUEUE][8];
	uint8_t q_head;
	uint8_t q_count;
	uint32_t overflows;
	struct co_timer inhibit_timer;
	uint64_t last_tx_us;
	/* Not before this time: the active line's TX queue was full at the last attempt. */
	uint64_t retry_us;
	bool sent_any;
	uint32_t cob_id;
	uint16_t inhibit_100us;
	uint8_t hist_max;
	bool enabled;
	/* Our own writes to 1001h/1003h pass the refusing validate hooks. */
	bool self_write;
	/* Other services' errors and the lines' events reach EMCY as node events. */
	struct co_listener listener;
#if defined(CONFIG_CANOPEN_EMCY_LINE_EVENTS)
	/* Line events: the controller state last reported, and the timers that end the
	 * event-type errors 8110h and 8140h.
	 */
	struct co_timer overrun_timer;
	struct co_timer recovered_timer;
	uint8_t can_state;
#endif
	/* Consumer. */
#if CONFIG_CANOPEN_EMCY_CONSUMERS > 0
	struct co_rx cons_rx[CONFIG_CANOPEN_EMCY_CONSUMERS];
#endif
	co_emcy_ind_t ind;
	void *ind_user_data;
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/* Two lines: the last EMCY frames taken, each matched once by its copy from the other. */
	struct co_rdn_taken taken[4];
	uint8_t taken_next;
#endif
};
/** @endcond */
#endif

/**
 * @brief Report that an error condition appeared.
 *
 * Adds @p code to the active errors, updates 1001h (bit 0 and @p reg_bits), stores
 * (code | (msef[0] | msef[1] << 8) << 16) at 1003h sub1 and sends the EMCY frame
 * [code LE16, 1001h, msef[0..4]]. Within the inhibit time (1015h) the frame is queued and sent
 * when it expires; the caller never retries. In Stopped (and Initialising) the error is
 * recorded but no frame is sent. Raising an active code again sends and records it again
 * (with the new manufacturer field) and adds @p reg_bits.
 *
 * Takes the node's mutex.
 *
 * @param node The node.
 * @param code Emergency error code, not 0000h.
 * @param reg_bits Error register bits (CO_EMCY_REG_*); bit 0 is always set.
 * @param msef Manufacturer-specific error field (5 bytes), or NULL for zeros.
 * @retval 0 Done (frame sent, queued, or not due in this state).
 * @retval -EINVAL @p code is 0000h or @p node is NULL.
 * @retval -ENOSPC CONFIG_CANOPEN_EMCY_ACTIVE_ERRORS errors already active: the frame and
 *         1003h entry are still produced, 1001h gets the bits, but the code cannot be
 *         cleared individually (it goes with the last clear).
 */
int co_emcy_raise(struct co_node *node, uint16_t code, uint8_t reg_bits, const uint8_t msef[5]);

/**
 * @brief Report that an error condition went away.
 *
 * Removes @p code from the active errors, updates 1001h and sends an error reset EMCY
 * (code 0000h, the new 1001h, zero manufacturer field). When it was the last active error,
 * 1001h reads 0 in that frame.
 *
 * Takes the node's mutex.
 *
 * @retval 0 Cleared.
 * @retval -ENOENT @p code is not active.
 * @retval -EINVAL @p node is NULL.
 */
int co_emcy_clear(struct co_node *node, uint16_t code);

/** @brief Whether @p code is active. */
bool co_emcy_is_active(struct co_node *node, uint16_t code);

/** @brief Current error register 1001h as derived from the active errors. */
uint8_t co_emcy_get_reg(struct co_node *node);

/** @brief Counters of the EMCY producer. */
void co_emcy_get_status(struct co_node *node, struct co_emcy_status *status);

/** @brief Set the EMCY consumer indication (NULL removes it; never called when
 * CONFIG_CANOPEN_EMCY_CONSUMERS is 0).
 */
void co_emcy_set_ind(struct co_node *node, co_emcy_ind_t cb, void *user_data);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_EMCY_H_ */
