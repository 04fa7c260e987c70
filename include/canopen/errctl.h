/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief NMT error control (CiA 301 §7.2.8.3.2): heartbeat producer (1017h) and consumer
 *        (1016h), node guarding answers and life guarding (100Ch, 100Dh).
 *
 * @defgroup co_errctl Error control
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_ERRCTL_H_
#define SAFELINE_INCLUDE_CANOPEN_ERRCTL_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/nmt.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** What the heartbeat consumer saw of a remote node. */
enum co_hb_event {
	/** A boot-up message (state 00h) arrived: the node (re)started. */
	CO_HB_EV_BOOTUP,
	/** The first heartbeat arrived; monitoring runs from now on. */
	CO_HB_EV_STARTED,
	/** No heartbeat within the consumer time (heartbeat event; EMCY 8130h). */
	CO_HB_EV_LOST,
	/** A heartbeat arrived again after CO_HB_EV_LOST. */
	CO_HB_EV_RECOVERED,
	/** The state in the heartbeat changed. */
	CO_HB_EV_STATE,
	/**
	 * Manager on two lines: the slave's heartbeat stayed away on one line
	 * (@ref co_event.hb "hb.line") for its consumer time while the other line still brings
	 * it. Never given to the heartbeat consumer's indication.
	 */
	CO_HB_EV_LINE_LOST,
	/** Manager on two lines: the slave's heartbeat is back on a line after CO_HB_EV_LINE_LOST.
	 */
	CO_HB_EV_LINE_FOUND,
};

/**
 * @brief Heartbeat consumer indication.
 *
 * Runs in the line thread with the node's mutex held; must not block.
 *
 * @param node The consuming node.
 * @param remote_id Node-ID of the producer (1..127).
 * @param event What happened.
 * @param state The producer's last state (CO_NMT_INITIALISING for a boot-up).
 * @param user_data As registered.
 */
typedef void (*co_hb_ind_t)(struct co_node *node, uint8_t remote_id, enum co_hb_event event,
			    enum co_nmt_state state, void *user_data);

/**
 * @brief Life guarding indication (the node's master stopped guarding it, or resumed).
 *
 * @param node The guarded node.
 * @param lost true: no guarding request within the node life time (100Ch × 100Dh; EMCY
 *        8130h); false: a request arrived again.
 * @param user_data As registered.
 *
 * Runs in the line thread with the node's mutex held; must not block.
 */
typedef void (*co_life_ind_t)(struct co_node *node, bool lost, void *user_data);

/** @cond INTERNAL_HIDDEN */
struct co_hb_entry {
	struct co_rx rx;
	struct co_timer timer;
	struct co_node *node;
	uint16_t time_ms;
	/* The producer's node-ID is rx.id - 700h (0 while the entry is unused): a byte of its
	 * own would make the entry 88 instead of 80 bytes on a 32-bit target.
	 */
	uint8_t state;
	/* 0 unused/idle (waiting for a first heartbeat), 1 active, 2 lost */
	uint8_t mon;
};

struct co_errctl {
	/* Heartbeat producer. */
	struct co_timer hb_timer;
	uint16_t hb_period_ms;
	/* co_hb_hold(): the heartbeat producer is silent. */
	bool hb_held;
	/* Heartbeat consumer: one entry per 1016h sub-index we serve. */
	struct co_hb_entry hbc[CONFIG_CANOPEN_HB_CONSUMERS];
	co_hb_ind_t hb_ind;
	void *hb_user_data;
#if defined(CONFIG_CANOPEN_NODE_GUARDING)
	/* Node guarding answers and life guarding. */
	struct co_rx guard_rx;
	struct co_timer life_timer;
	uint16_t guard_time_ms;
	uint8_t life_factor;
	uint8_t toggle;
	bool guarded;
	bool life_lost;
	co_life_ind_t life_ind;
	void *life_user_data;
#endif
};
/** @endcond */

/**
 * @brief Hold the heartbeat producer silent, or let it send again.
 *
 * While held, 1017h's cadence runs on but no heartbeat goes out, so the node's consumers
 * see it lost. The redundancy service holds it when TPDO 1 fails too often (CiA 302-6), so
 * that the other nodes leave the line. A reset does not release it.
 */
void co_hb_hold(struct co_node *node, bool hold);

/** @brief Set the heartbeat consumer indication (NULL removes it). */
void co_hb_set_ind(struct co_node *node, co_hb_ind_t cb, void *user_data);

/** @brief Set the life guarding indication (NULL removes it; without
 * CONFIG_CANOPEN_NODE_GUARDING it is never called).
 */
void co_life_set_ind(struct co_node *node, co_life_ind_t cb, void *user_data);

/**
 * @brief Last known state of a remote node monitored through 1016h.
 *
 * @retval 0 @p state filled.
 * @retval -ENOENT @p remote_id is not monitored.
 * @retval -EAGAIN No heartbeat seen yet.
 */
int co_hb_get_remote_state(struct co_node *node, uint8_t remote_id, enum co_nmt_state *state);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_ERRCTL_H_ */
