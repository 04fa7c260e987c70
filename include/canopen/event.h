/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Node events and their listeners.
 *
 * A node publishes what happens to it (NMT state changes, error control, errors, SYNC, line
 * events, boot results) as events. Any number of listeners may follow a node: the
 * application, indicators, a bridge, another service. A listener is a struct the caller owns
 * (embedded in its own state, as Zephyr's callbacks are), so registering one allocates
 * nothing.
 *
 * One event kind is a question rather than news: CO_EV_NMT_VETO asks every listener that
 * subscribed to it whether the node may enter a state. Any refusal refuses the change, and
 * the node remembers who refused (co_nmt_get_refusal()).
 *
 * Listeners run in the thread that raised the event (a line thread, or an application thread
 * calling the API) with the node's mutex held. They may call the stack's API and must not
 * block. See doc/architecture.md for the event flow.
 *
 * @defgroup co_event Node events
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_EVENT_H_
#define SAFELINE_INCLUDE_CANOPEN_EVENT_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/sys/slist.h>
#include <zephyr/sys/util.h>

#include <canopen/errctl.h>
#include <canopen/line.h>
#include <canopen/nmt.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** What an event reports. */
enum co_event_type {
	/** The node changed NMT state (@ref co_event.nmt). */
	CO_EV_NMT_STATE,
	/**
	 * The node is about to enter @ref co_event.nmt "nmt.to" from "nmt.from". A listener
	 * refuses by returning non-zero. Offered for Pre-operational, Operational and Stopped;
	 * resets are unconditional (CiA 301 §7.3.2.1).
	 */
	CO_EV_NMT_VETO,
	/** A Reset Node or Reset Communication is about to run (@ref co_event.reset). */
	CO_EV_NMT_RESET,
	/**
	 * The node is about to leave "nmt.from" for "nmt.to" (@ref co_event.nmt), decided (no
	 * veto pending): the last moment to send in the old state, e.g. to abort an SDO transfer
	 * before Stopped forbids SDO. Raised for every change, the resets' Initialising included.
	 */
	CO_EV_NMT_LEAVE,
	/**
	 * The heartbeat consumer saw something of a remote node, or the manager lost or found a
	 * slave on one of two lines (@ref co_event.hb).
	 */
	CO_EV_HB,
	/** Life guarding of this node was lost or resumed (@ref co_event.life). */
	CO_EV_LIFE,
	/**
	 * A service detected or cleared a communication error (@ref co_event.error); the EMCY
	 * service turns it into an emergency, indicators into their error pattern.
	 */
	CO_EV_ERROR,
	/** An emergency was sent by this node or received from another (@ref co_event.emcy). */
	CO_EV_EMCY,
	/** A SYNC was received or produced (@ref co_event.sync). */
	CO_EV_SYNC,
	/** One of the node's lines reported an event (@ref co_event.line). */
	CO_EV_LINE,
	/** The manager finished the boot of a slave, well or not (@ref co_event.boot). */
	CO_EV_BOOT,
	/**
	 * An SRDO the node consumes or produces entered or left the safe state
	 * (@ref co_event.srdo, CiA 304).
	 */
	CO_EV_SRDO,
	/**
	 * The node's LSS slave changed state, waiting or configuration (@ref co_event.lss,
	 * CiA 305).
	 */
	CO_EV_LSS,
	/** A TPDO was handed to the node's lines, or could not be (@ref co_event.tpdo). */
	CO_EV_TPDO,
	/**
	 * The redundancy service saw something of the node's two lines: a heartbeat lost or
	 * found on one line, a line switch, a vetoed switch (@ref co_event.redundancy).
	 */
	CO_EV_REDUNDANCY,
	/**
	 * The flying master (CiA 302 §5.5) or the NMT master detection saw a change: this node
	 * became the active master, another did, the active master was lost
	 * (@ref co_event.fm).
	 */
	CO_EV_FM,
	/** Number of event types. */
	CO_EV_COUNT
};

/** Mask bit of one event type, for co_listener_init(). */
#define CO_EV_BIT(type) BIT(type)
/** Mask of every event type. */
#define CO_EV_ALL       (BIT(CO_EV_COUNT) - 1U)

/** @name Flags of a CO_EV_ERROR event
 * @{
 */
/** The error is present (clear = it went away). */
#define CO_ERROR_F_ACTIVE    BIT(0)
/** Apply the error behaviour 1029h sub 1 (communication error, CiA 301 §7.5.2.32). */
#define CO_ERROR_F_BEHAVIOUR BIT(1)
/** @} */

/** An event. Only the member that belongs to @ref type is valid. */
struct co_event {
	enum co_event_type type;
	union {
		/** CO_EV_NMT_STATE, CO_EV_NMT_VETO, CO_EV_NMT_LEAVE. */
		struct {
			enum co_nmt_state from;
			enum co_nmt_state to;
		} nmt;
		/** CO_EV_NMT_RESET. */
		struct {
			enum co_nmt_cs cs;
		} reset;
		/** CO_EV_HB. */
		struct {
			uint8_t node_id;
			enum co_hb_event event;
			enum co_nmt_state state;
			/**
			 * CO_HB_EV_LINE_LOST, CO_HB_EV_LINE_FOUND: the line concerned
			 * (enum co_node_line_id); 0 for the other events.
			 */
			uint8_t line;
		} hb;
		/** CO_EV_LIFE. */
		struct {
			bool lost;
		} life;
		/** CO_EV_ERROR. */
		struct {
			/** CiA 301 emergency error code (e.g. 8130h). */
			uint16_t code;
			/** Error register bits the error sets (CO_EMCY_REG_*). */
			uint8_t reg_bits;
			/** First manufacturer byte (e.g. the lost node's ID), 0 if none. */
			uint8_t info;
			/** Manufacturer bytes 1..4 as a little-endian number, 0 if none. */
			uint32_t detail;
			/** CO_ERROR_F_*. */
			uint8_t flags;
		} error;
		/** CO_EV_EMCY. */
		struct {
			/** CAN-ID the frame went out or came in on. */
			uint16_t cob_id;
			/** Producer's node-ID (this node's for own EMCY), 0 if unknown. */
			uint8_t node_id;
			/** The frame was produced by this node. */
			bool own;
			uint16_t code;
			uint8_t reg;
			uint8_t msef[5];
		} emcy;
		/** CO_EV_SYNC. */
		struct {
			/** SYNC counter, 0 without counter. */
			uint8_t counter;
			/** 1007h synchronous window [µs], 0 for none. */
			uint32_t window_us;
			/** Reception (or production) time [µs]. */
			uint64_t time_us;
		} sync;
		/** CO_EV_LINE. */
		struct {
			/** Which of the node's lines (enum co_node_line_id). */
			uint8_t idx;
			enum co_line_event event;
			int arg;
		} line;
		/** CO_EV_BOOT. */
		struct {
			uint8_t node_id;
			/** CiA 302-2 error status: 0 booted, else 'A'..'O'. */
			char status;
		} boot;
		/** CO_EV_TPDO. */
		struct {
			/** TPDO number (0 = 1800h). */
			uint16_t num;
			/** 0, or co_node_send()'s error: the frame did not reach every line. */
			int err;
		} tpdo;
		/** CO_EV_REDUNDANCY. */
		struct {
			/** What happened (enum co_rdn_event of canopen/redundancy.h). */
			uint8_t what;
			/** The line concerned, or the new active line (enum co_node_line_id). */
			uint8_t line;
			/** The remote node concerned, 0 if none. */
			uint8_t node_id;
			/** When [µs, node time]. */
			uint64_t time_us;
		} redundancy;
		/** CO_EV_FM. */
		struct {
			/** What happened (enum co_mgr_fm_event of canopen/mgr.h). */
			uint8_t what;
			/** The active master's node-ID (0 if none). */
			uint8_t master_id;
			/** Its priority (1F90h:03: 0 high, 1 medium, 2 low). */
			uint8_t priority;
			/** When [µs, node time]. */
			uint64_t time_us;
		} fm;
		/** CO_EV_SRDO. */
		struct {
			/** SRDO number, 1..64; 0 for a received GFC (reason CO_SRDO_R_GFC). */
			uint8_t srdo;
			/** The SRDO entered (true) or left (false) the safe state. */
			bool safe;
			/** Why (enum co_srdo_reason of canopen/srdo.h). */
			uint8_t reason;
			/** When the fault was detected (or the SRDO became valid) [µs]. */
			uint64_t time_us;
		} srdo;
		/** CO_EV_LSS. */
		struct {
			/** LSS state before (enum co_lss_state of canopen/lss.h). */
			uint8_t from;
			/** LSS state now. */
			uint8_t to;
			/**
			 * A fastscan is in progress for this node: it answered the fastscan
			 * probe and the scan has not ended for it, or this change ends it (the
			 * scan selected the node).
			 */
			bool fastscan;
		} lss;
	};
};

/**
 * @brief Receive an event.
 *
 * Runs in the thread that raised the event with the node's mutex held; must not block.
 *
 * @param node The node.
 * @param ev The event; valid during the call only.
 * @param user_data As given to co_listener_init().
 * @return For CO_EV_NMT_VETO: 0 to accept, non-zero (e.g. -EPERM) to refuse. Ignored for every
 *         other event.
 */
typedef int (*co_listener_cb_t)(struct co_node *node, const struct co_event *ev, void *user_data);

/** A listener. Embed it in the listener's own state; all fields are private. */
struct co_listener {
	/** @cond INTERNAL_HIDDEN */
	sys_snode_t snode;
	struct co_node *owner;
	co_listener_cb_t cb;
	void *user_data;
	const char *name;
	uint32_t mask;
	/** @endcond */
};

/**
 * @brief Fill a listener; register it with co_node_listener_add().
 *
 * @param l The listener.
 * @param name Who listens, for logs and for co_nmt_get_refusal(); must outlive the listener.
 * @param mask Events to receive: CO_EV_BIT() of each type, or CO_EV_ALL.
 * @param cb Handler.
 * @param user_data Passed to @p cb.
 */
static inline void co_listener_init(struct co_listener *l, const char *name, uint32_t mask,
				    co_listener_cb_t cb, void *user_data)
{
	*l = (struct co_listener){
		.cb = cb,
		.user_data = user_data,
		.name = name,
		.mask = mask,
	};
}

/**
 * @brief Follow a node's events. Listeners get each event in registration order.
 *
 * Takes the node's mutex; may be called from a listener.
 *
 * @retval 0 Registered.
 * @retval -EINVAL A NULL argument or a listener without handler.
 * @retval -EALREADY @p l is registered already (on this or another node).
 */
int co_node_listener_add(struct co_node *node, struct co_listener *l);

/**
 * @brief Stop following a node's events. Safe on a listener that is not registered.
 *
 * Takes the node's mutex. A listener may remove itself from its own handler; removing
 * another listener while an event is being delivered may still deliver that event to it.
 */
void co_node_listener_remove(struct co_node *node, struct co_listener *l);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_EVENT_H_ */
