/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @brief Redundant CAN lines (CiA 302-6): a node on a default and a redundant line.
 *
 * A node attached to two lines (co_node_attach_line()) with this service hears both: its
 * services receive every frame of either line, and co_node_rx_line() tells them where it came
 * from. What goes where:
 *
 * | service | lines |
 * |---|---|
 * | NMT, heartbeat, boot-up | heard on both; heartbeat and boot-up sent on both; guarding answered
 * where asked | | PDO, EMCY, SRDO | sent on both; a PDO's copy from the other line is dropped
 * (co_pdo_rx_duplicates()) | | SYNC, TIME | sent on both; acted on from the active line only | |
 * SDO server | answers on the line the request came on | | SDO client, the manager's NMT and
 * guarding | the active line |
 *
 * The service supervises the heartbeat of every node of 1016h on each line separately and
 * chooses the active line with a state machine (doc/redundancy.md):
 * - after a reset, the evaluation timer runs; three heartbeats of every supervised node on the
 *   default line make it active, the timer's end the redundant line;
 * - with the default line active, a heartbeat lost there switches to the redundant line;
 * - with the redundant line active, three good heartbeat cycles of every supervised node on the
 *   default line switch back.
 * The application may veto those two automatic switches; co_redundancy_switch_req() switches
 * without asking. TPDO 1 is supervised: each failed send adds 4 to a counter, each good one
 * takes 1 away; at the limit in 1F60h sub 5 the node's heartbeat stops (so the other nodes
 * leave the line), at 0 it resumes.
 *
 * With CONFIG_CANOPEN_REDUNDANCY_ECSS the node follows ECSS-E-ST-50-15C instead: it talks on
 * the active bus only and toggles buses when the master's heartbeat (the first 1016h entry)
 * stays away for Ttoggle heartbeat periods, at most Ntoggle times.
 *
 * @defgroup co_redundancy Redundancy
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_REDUNDANCY_H_
#define SAFELINE_INCLUDE_CANOPEN_REDUNDANCY_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/event.h>
#include <canopen/line.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** @name Object 1F60h (our layout; doc/redundancy.md)
 * @{
 */
#define CO_RDN_IDX          0x1F60U
#define CO_RDN_SUB_BDEFAULT 1U /**< U8: the line that starts active (ECSS: the default bus) */
#define CO_RDN_SUB_TTOGGLE  2U /**< U8: master heartbeat periods before a toggle (ECSS) */
#define CO_RDN_SUB_NTOGGLE  3U /**< U8: toggles before "no master" (ECSS) */
#define CO_RDN_SUB_CTOGGLE  4U /**< U8: toggles so far (ECSS, status) */
#define CO_RDN_SUB_TPDO_MAX 5U /**< U8: TPDO 1 error-counter limit, 0 = not supervised */
/** @} */

/** States of the line choice. */
enum co_rdn_state {
	/** After a reset: waiting for the default line's heartbeats or the evaluation timer. */
	CO_RDN_NEGOTIATING,
	/** The default line is active. */
	CO_RDN_DEFAULT_ACTIVE,
	/** The redundant line is active. */
	CO_RDN_REDUNDANT_ACTIVE,
	/** ECSS: Ntoggle toggles found no master; the current bus became Bdefault. */
	CO_RDN_NO_MASTER,
};

/** What a CO_EV_REDUNDANCY event reports (its "what"). */
enum co_rdn_event {
	/** The evaluation timer ended without the default line's heartbeats. */
	CO_RDN_EV_EVAL_TIMEOUT,
	/** Every supervised node sent three heartbeats on the default line. */
	CO_RDN_EV_DEFAULT_LINE_OK,
	/** A supervised node's heartbeat was lost on a line (line, node_id). */
	CO_RDN_EV_HB_ERROR,
	/** A supervised node's heartbeat came back on a line (line, node_id). */
	CO_RDN_EV_HB_OK,
	/** The active line changed (line: the new one). */
	CO_RDN_EV_SWITCH,
	/** The application vetoed a switch to @p line. */
	CO_RDN_EV_VETOED,
	/** TPDO 1 failed too often: the heartbeat stopped. */
	CO_RDN_EV_TPDO_FAILED,
	/** TPDO 1's error counter is back at 0: the heartbeat resumed. */
	CO_RDN_EV_TPDO_OK,
	/** ECSS: Ntoggle toggles without the master's heartbeat. */
	CO_RDN_EV_NO_MASTER,
};

/**
 * @brief May the service switch to @p to? Return false to veto.
 *
 * Asked before the automatic switches (heartbeat lost on the default line, default line OK
 * again). Runs in a line thread with the node's mutex held; must not block.
 */
typedef bool (*co_rdn_veto_t)(struct co_node *node, enum co_rdn_event why, uint8_t to,
			      void *user_data);

/** @cond INTERNAL_HIDDEN */
#if defined(CONFIG_CANOPEN_REDUNDANCY)
/*
 * A frame taken from one line, waiting for its copy from the other (the duplicate filter of
 * RPDOs and EMCY consumers, co_rdn_is_copy()). All-zero is an empty entry.
 */
struct co_rdn_taken {
	uint64_t at;
	uint16_t id;
	uint8_t data[8];
	uint8_t len;
	uint8_t line;
	bool used;
	bool copied; /* its copy from the other line came already */
};

/*
 * Whether @p frame, received on @p line at @p now_us, is the other line's copy of a frame in
 * @p ring (@p n entries, the oldest at *@p next). If not, it is taken: it replaces the oldest
 * entry. Each taken frame has one copy: same CAN-ID, length and data, from the other line,
 * within CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US.
 */
bool co_rdn_is_copy(struct co_rdn_taken *ring, uint8_t n, uint8_t *next, uint8_t line,
		    const struct can_frame *frame, uint64_t now_us);

/* One supervised node's heartbeat on one line. */
struct co_rdn_hb {
	uint64_t deadline;
	uint64_t counted_at; /* the last heartbeat counted as a good cycle */
	uint8_t count;       /* heartbeats since the last loss, up to 3 */
	bool seen;
	bool lost;
};

struct co_redundancy {
	struct co_rx fwd;     /* every frame of the redundant line, handed to the node */
	struct co_rx fwd_ext; /* the same for 29-bit frames */
	struct co_rx hb_rx;   /* heartbeats of supervised nodes, on either line */
	struct co_timer timer;
	struct co_listener listener;
	uint64_t eval_end;
	uint64_t toggle_at; /* ECSS */
	uint32_t hb_us[CONFIG_CANOPEN_REDUNDANCY_NODES];
	uint8_t hb_id[CONFIG_CANOPEN_REDUNDANCY_NODES];
	struct co_rdn_hb hb[2][CONFIG_CANOPEN_REDUNDANCY_NODES];
	uint8_t n_hb;
	uint8_t state; /* enum co_rdn_state */
	uint16_t tpdo_errors;
	uint8_t tpdo_max;
	/* Lines whose controller cannot send (error passive, bus-off): no process data there. */
	uint8_t tx_excluded;
	/* Lines whose sends fail with -ENETDOWN/-ENETUNREACH until a frame comes in there. */
	uint8_t link_down;
	uint8_t excluded_now; /* tx_excluded | link_down as last applied */
	bool tpdo_failed;
	uint32_t switches;
	co_rdn_veto_t veto;
	void *veto_user_data;
};
#endif
/** @endcond */

/**
 * @brief Set the veto callback (NULL: every automatic switch happens).
 */
void co_redundancy_set_veto(struct co_node *node, co_rdn_veto_t cb, void *user_data);

/**
 * @brief Make line @p idx (enum co_node_line_id) active now, without asking the veto.
 *
 * @retval 0 Done (also when it was active already).
 * @retval -EINVAL No line is attached there.
 * @retval -ENODEV The node has no redundant line.
 */
int co_redundancy_switch_req(struct co_node *node, uint8_t idx);

/**
 * @brief The state of the line choice and the active line.
 *
 * @param node The node.
 * @param state If not NULL, gets an enum co_rdn_state.
 * @param switches If not NULL, gets the number of switches since start-up.
 * @return The active line (enum co_node_line_id).
 */
uint8_t co_redundancy_get(struct co_node *node, enum co_rdn_state *state, uint32_t *switches);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_REDUNDANCY_H_ */
