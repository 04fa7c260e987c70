/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen node: one device (object dictionary + services) on one or two lines.
 *
 * A node has one recursive mutex, and one lock rule (doc/architecture.md, "Locks"):
 * - every public call of the node and its services (co_node_*, co_nmt_*, co_sdo_*, co_pdo_*,
 *   ...) takes the mutex inside, so an application thread just calls it;
 * - the dictionary accessors (co_od_*) never lock: the caller holds the mutex
 *   (co_node_lock()/co_node_unlock() around multi-step OD work). With
 *   CONFIG_CANOPEN_LOCK_CHECK an accessor called without it stops the program.
 * Line threads take the mutex around every dispatch to the node's services, so callbacks run
 * with it held; they may call the API (the mutex is recursive) and must not block.
 *
 * Life cycle: co_node_init() binds the node to its line, dictionary and node-ID;
 * co_node_start() runs the NMT Initialising state (reset application, reset communication),
 * sends the boot-up message and enters Pre-operational. Services are configured from the
 * dictionary at every reset and re-configured at once by any later write to their objects.
 *
 * @defgroup co_node Node
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_NODE_H_
#define SAFELINE_INCLUDE_CANOPEN_NODE_H_

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>

#include <zephyr/kernel.h>
#include <zephyr/sys/slist.h>
#include <zephyr/sys/util.h>

#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/od.h>
#include <canopen/services.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Node-ID of a node that has none yet (CiA 305: it waits for LSS to give it one). */
#define CO_NODE_ID_UNCONFIGURED 0xFFU

/** The lines a node can be attached to (CiA 302-6 names them default and redundant). */
enum co_node_line_id {
	/** The line given to co_node_init(); every node has it. */
	CO_LINE_DEFAULT = 0,
	/** A second line (co_node_attach_line()), for redundancy. */
	CO_LINE_REDUNDANT = 1,
};

/**
 * Number of lines a node can be attached to: two with CONFIG_CANOPEN_NODE_REDUNDANT_LINE, else
 * one (the default line; co_node_attach_line() returns -ENOTSUP).
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
#define CO_NODE_LINES 2U
#else
#define CO_NODE_LINES 1U
#endif

/**
 * @name Routes: which of its lines a node sends a frame on
 * @{
 */
/** A set of lines, CO_ROUTE_* or co_node_route_of(). */
typedef uint8_t co_route_t;
/** The default line. */
#define CO_ROUTE_DEFAULT   BIT(CO_LINE_DEFAULT)
/** The redundant line. */
#define CO_ROUTE_REDUNDANT BIT(CO_LINE_REDUNDANT)
/** Both lines (those the node is attached to). */
#define CO_ROUTE_BOTH      (CO_ROUTE_DEFAULT | CO_ROUTE_REDUNDANT)
/** The node's active line: the default line unless co_node_set_active_line() chose another. */
#define CO_ROUTE_ACTIVE    BIT(7)
/**
 * The lines a node's process data, emergencies, SYNC/TIME it produces and its heartbeat go
 * on: every line it has unless co_node_set_process_route() chose otherwise (CiA 302-6 sends
 * them on both lines; the ECSS profile of the redundancy service on the active line alone).
 */
#define CO_ROUTE_PROCESS   BIT(6)
/**
 * The lines the node's heartbeat and boot-up take: those of CO_ROUTE_PROCESS, including a
 * line left out of CO_ROUTE_PROCESS by co_node_set_tx_excluded() (so that the others see the
 * node on it again when it recovers).
 */
#define CO_ROUTE_EC        BIT(5)
/** @} */

/** @cond INTERNAL_HIDDEN */
/* The routes that include the default line on a node that has no other. */
#define CO_ROUTE_ON_DEFAULT (CO_ROUTE_DEFAULT | CO_ROUTE_ACTIVE | CO_ROUTE_PROCESS | CO_ROUTE_EC)
/** @endcond */

/** @cond INTERNAL_HIDDEN */
struct co_service;

/* One of the node's lines, with what the node registered on it. */
struct co_node_line {
	struct co_line *line;
	struct co_line_listener listener;
	struct co_line_member member;
};

#define CO_NODE_SERVICE_MEMBER(name, member) member;
/** @endcond */

/** A CANopen node. Allocate statically; all fields are private. */
struct co_node {
	/** @cond INTERNAL_HIDDEN */
	struct k_mutex lock;
	const char *name;
	struct co_node_line lines[CO_NODE_LINES];
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	uint8_t active_line;
	/* The line the frame being dispatched came on (co_node_rx_line()). */
	uint8_t rx_line;
	/* What CO_ROUTE_PROCESS means (co_node_set_process_route()). */
	co_route_t process_route;
	/* Lines left out of CO_ROUTE_PROCESS (co_node_set_tx_excluded()). */
	co_route_t tx_excluded;
#endif
	struct co_od od;
	uint8_t node_id;
	/* Node-ID to use from the next Reset Communication (LSS may change it). */
	uint8_t pending_node_id;
	bool started;
	/* The services, from the list of canopen/services.h (set by co_node_init()). */
	const struct co_service *const *services;
	uint8_t n_services;
	struct co_nmt nmt;
	struct co_rx nmt_rx;
	sys_slist_t listeners;
	/* Union of the listeners' masks: events nobody follows cost one test. */
	uint32_t listen_mask;
	/* Who refused the last refused NMT state change, and with what. */
	const char *refused_by;
	int refusal;
	CO_NODE_SERVICES(CO_NODE_SERVICE_MEMBER)
	/** @endcond */
};

/**
 * @brief Initialise a node on its default line.
 *
 * Binds the node to its line, dictionary and node-ID and initialises every service of
 * canopen/services.h in order (each registers its dictionary hooks, receivers and
 * listeners). On failure everything already done is undone: the node is left unregistered
 * from the line and may be initialised again. A node that is initialised already (attached to
 * a line) must not be initialised again.
 *
 * @param node Node to initialise (statically allocated).
 * @param name Name for logs; must outlive the node.
 * @param line Default line (initialised, started or not).
 * @param def Generated dictionary description (NAME_od_def from scripts/eds2od).
 * @param ram The node's own RAM block for the dictionary (a struct NAME_od_ram).
 * @param node_id Node-ID 1..127, or CO_NODE_ID_UNCONFIGURED for a node that waits for one.
 *
 * @retval 0 Initialised; the node is in Initialising until co_node_start().
 * @retval -EINVAL A NULL argument or a node-ID outside 1..127 and not CO_NODE_ID_UNCONFIGURED.
 * @retval -ENOSPC A receiver, hook or listener did not fit in its table (line receive slots,
 *         CONFIG_CANOPEN_OD_HOOKS, ...).
 * @retval other negative errno As returned by a service's initialisation (see its header).
 */
int co_node_init(struct co_node *node, const char *name, struct co_line *line,
		 const struct co_od_def *def, void *ram, uint8_t node_id);

/**
 * @brief Attach the node to a second line (redundancy).
 *
 * Call after co_node_init() and before co_node_start(). The node then hears the line's events
 * (CO_EV_LINE with its index), may send on it (CO_ROUTE_REDUNDANT, CO_ROUTE_BOTH) and register
 * receivers on it (co_node_rx_register()). Services register their receivers on the default
 * line; with the redundancy service (CONFIG_CANOPEN_REDUNDANCY) they hear the redundant line
 * too, through co_node_dispatch_from(). Without it they hear the default line only.
 *
 * @retval 0 Attached.
 * @retval -ENOTSUP The node can have one line only (built without
 *         CONFIG_CANOPEN_NODE_REDUNDANT_LINE, always on with CONFIG_CANOPEN_REDUNDANCY), whatever
 *         the arguments.
 * @retval -EINVAL A NULL argument, or @p idx is not CO_LINE_REDUNDANT.
 * @retval -EALREADY A line is attached there already, or it is the default line.
 * @retval -EBUSY The node has been started.
 */
int co_node_attach_line(struct co_node *node, enum co_node_line_id idx, struct co_line *line);

/**
 * @brief Start the node: reset application and communication, boot-up, Pre-operational.
 *
 * Call after the application has registered its hooks, indications and listeners. The
 * boot-up message goes out on the default line. A node without node-ID
 * (CO_NODE_ID_UNCONFIGURED) stays in Initialising and silent, running only the services that
 * work unconfigured, until co_node_set_pending_id() and a reset give it one.
 *
 * @retval 0 Started.
 * @retval -EALREADY The node was started before.
 */
int co_node_start(struct co_node *node);

/** @brief Take the node's mutex (recursive). Blocks. */
void co_node_lock(struct co_node *node);

/** @brief Release the node's mutex. */
void co_node_unlock(struct co_node *node);

/**
 * @brief The node's object dictionary, for the co_od_* accessors.
 *
 * The accessors require the node's mutex (co_node_lock()); with CONFIG_CANOPEN_LOCK_CHECK a
 * call without it stops the program (doc/architecture.md, "Locks").
 */
struct co_od *co_node_od(struct co_node *node);

/** @brief The node's current node-ID (CO_NODE_ID_UNCONFIGURED while it has none). */
uint8_t co_node_id(const struct co_node *node);

/**
 * @brief The node-ID the next Reset Communication puts in force (co_node_set_pending_id()).
 *
 * Equal to co_node_id() unless a new one is pending. Requires the node's mutex.
 */
static inline uint8_t co_node_pending_id(const struct co_node *node)
{
	return node->pending_node_id;
}

/** @brief The node's default line. */
struct co_line *co_node_line(struct co_node *node);

/** @brief One of the node's lines, or NULL when none is attached there. */
struct co_line *co_node_get_line(struct co_node *node, enum co_node_line_id idx);

/**
 * @brief Set the node-ID used from the next Reset Communication (e.g. after LSS).
 *
 * @retval 0 Done.
 * @retval -EINVAL Not 1..127 and not CO_NODE_ID_UNCONFIGURED.
 */
int co_node_set_pending_id(struct co_node *node, uint8_t node_id);

/**
 * @brief Choose the node's active line (the route CO_ROUTE_ACTIVE), e.g. after a line switch.
 *
 * @retval 0 Done.
 * @retval -EINVAL No line is attached at @p idx.
 */
int co_node_set_active_line(struct co_node *node, enum co_node_line_id idx);

/**
 * @name For services: the node's path to its lines
 *
 * Services never hold a line pointer: they send through a route, register receivers on one
 * of the node's lines, and run their timers on the node's default line thread. Every call
 * here requires the node's mutex.
 * @{
 */

/** @cond INTERNAL_HIDDEN */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_send_routed(struct co_node *node, co_route_t route, const struct can_frame *frame);
#endif
#if defined(CONFIG_CANOPEN_LOCK_CHECK)
void co_node_assert_locked(const struct co_node *node);
#endif
/** @endcond */

/**
 * @brief Send a frame on every line of @p route the node is attached to.
 *
 * Inline for the common case of a node on one line (the PDO hot path); on a node that can
 * have one line only (no CONFIG_CANOPEN_NODE_REDUNDANT_LINE) every route but
 * CO_ROUTE_REDUNDANT is that line, and nothing else is left.
 *
 * @retval 0 Sent or queued on every line of the route.
 * @retval -ENODEV The node has no line on that route.
 * @retval other As co_line_send(), the first error of the lines of the route (the frame is
 *         still sent on the others).
 */
static inline int co_node_send(struct co_node *node, co_route_t route,
			       const struct can_frame *frame)
{
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	if (node->lines[CO_LINE_REDUNDANT].line != NULL || (route & CO_ROUTE_ON_DEFAULT) == 0U) {
		return co_node_send_routed(node, route, frame);
	}
#else
	if ((route & CO_ROUTE_ON_DEFAULT) == 0U) {
		return -ENODEV;
	}
#endif
#if defined(CONFIG_CANOPEN_LOCK_CHECK)
	co_node_assert_locked(node);
#endif
	return co_line_send_from(node->lines[CO_LINE_DEFAULT].line, frame, &node->lock);
}

/**
 * @brief The route that answers a frame received by @p rx: the line it came on.
 *
 * Call from the receiver's handler. A frame of the redundant line handed over by
 * co_node_dispatch_from() is answered there. Always CO_ROUTE_DEFAULT on a node that can have
 * one line only (inline then).
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
co_route_t co_node_route_of(const struct co_node *node, const struct co_rx *rx);
#else
static inline co_route_t co_node_route_of(const struct co_node *node, const struct co_rx *rx)
{
	ARG_UNUSED(node);
	ARG_UNUSED(rx);
	return CO_ROUTE_DEFAULT;
}
#endif

/**
 * @brief The line the frame being handled came on (enum co_node_line_id).
 *
 * Call from a receiver's handler (CO_LINE_DEFAULT outside one, and always on a node with one
 * line). A service that acts on a frame from the active line only (SYNC, TIME) compares it
 * with co_node_active_line().
 */
static inline uint8_t co_node_rx_line(const struct co_node *node)
{
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	return node->rx_line;
#else
	ARG_UNUSED(node);
	return (uint8_t)CO_LINE_DEFAULT;
#endif
}

/** @brief The node's active line (enum co_node_line_id; always the default on a one-line node). */
static inline uint8_t co_node_active_line(const struct co_node *node)
{
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	return node->active_line;
#else
	ARG_UNUSED(node);
	return (uint8_t)CO_LINE_DEFAULT;
#endif
}

#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
/**
 * @brief Hand a frame that came on line @p idx to the node's receivers of the default line.
 *
 * For the redundancy service: one catch-all receiver on the redundant line brings its frames
 * to the node's services, which then hear both lines through the receivers they registered on
 * the default line; co_node_rx_line() tells them where a frame came from. Requires the node's
 * mutex (a receiver's handler holds it). Only on a node that can have two lines
 * (CONFIG_CANOPEN_NODE_REDUNDANT_LINE).
 *
 * @return Number of receivers called.
 */
int co_node_dispatch_from(struct co_node *node, enum co_node_line_id idx,
			  const struct can_frame *frame, uint64_t now_us);
#endif

/**
 * @brief Choose what CO_ROUTE_PROCESS means (CO_ROUTE_BOTH, or CO_ROUTE_ACTIVE).
 *
 * On a node that can have one line only both mean the default line: nothing is kept.
 *
 * @retval 0 Done.
 * @retval -EINVAL Another route.
 */
int co_node_set_process_route(struct co_node *node, co_route_t route);

/**
 * @brief Leave lines out of CO_ROUTE_PROCESS (their controller cannot send, e.g. error
 * passive after a cut, or bus-off), so that process data do not pile up behind them and go
 * out stale later. CO_ROUTE_EC still reaches them. A route that would be left without any
 * line keeps all of its lines, so on a node that can have one line only this does nothing.
 *
 * @param node The node.
 * @param lines CO_ROUTE_DEFAULT and/or CO_ROUTE_REDUNDANT, or 0.
 */
void co_node_set_tx_excluded(struct co_node *node, co_route_t lines);

/**
 * @brief Withdraw frames the node queued on the lines of @p route (still waiting for the
 * driver's back-pressure to clear), e.g. a heartbeat that a newer one replaces.
 *
 * @param node The node.
 * @param route The lines to look at.
 * @param keep Frames to keep (NULL: none); called with a line's TX lock held, must not block.
 * @param arg Passed to @p keep.
 * @return Frames withdrawn (counted in each line's co_line_stats.tx_purged).
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_tx_withdraw(struct co_node *node, co_route_t route,
			bool (*keep)(const struct can_frame *frame, void *arg), void *arg);
#else
static inline int co_node_tx_withdraw(struct co_node *node, co_route_t route,
				      bool (*keep)(const struct can_frame *frame, void *arg),
				      void *arg)
{
	return (route & CO_ROUTE_ON_DEFAULT) != 0U
		       ? co_line_tx_purge(node->lines[CO_LINE_DEFAULT].line, &node->lock, keep, arg)
		       : 0;
}
#endif

/**
 * @brief Free places in the TX queues of a route (the smallest of its lines).
 *
 * @return Frames that can be sent on every line of the route without an overflow; 0 when the
 *         node has no line on the route.
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_tx_space(struct co_node *node, co_route_t route);
#else
static inline int co_node_tx_space(struct co_node *node, co_route_t route)
{
	return (route & CO_ROUTE_ON_DEFAULT) != 0U
		       ? co_line_tx_space(node->lines[CO_LINE_DEFAULT].line)
		       : 0;
}
#endif

/**
 * @brief Register a receiver of the node on one of its lines.
 *
 * @retval 0 Registered.
 * @retval -ENODEV No line attached at @p idx.
 * @retval other As co_rx_register().
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_rx_register(struct co_node *node, enum co_node_line_id idx, struct co_rx *rx);
#else
static inline int co_node_rx_register(struct co_node *node, enum co_node_line_id idx,
				      struct co_rx *rx)
{
	return idx == CO_LINE_DEFAULT ? co_rx_register(node->lines[CO_LINE_DEFAULT].line, rx)
				      : -ENODEV;
}
#endif

/**
 * @brief Move a receiver of the node to a new COB-ID on one of its lines.
 *
 * @retval 0 Moved (or registered).
 * @retval -ENODEV No line attached at @p idx.
 * @retval other As co_rx_set_id().
 */
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_rx_set_id(struct co_node *node, enum co_node_line_id idx, struct co_rx *rx,
		      uint32_t id);
#else
static inline int co_node_rx_set_id(struct co_node *node, enum co_node_line_id idx,
				    struct co_rx *rx, uint32_t id)
{
	return idx == CO_LINE_DEFAULT ? co_rx_set_id(node->lines[CO_LINE_DEFAULT].line, rx, id)
				      : -ENODEV;
}
#endif

/** @brief Arm one of the node's timers (it runs in the default line's thread). */
void co_node_timer_start(struct co_node *node, struct co_timer *timer, uint64_t deadline_us);

/** @brief The node's time [µs] (co_line_time() of its default line). */
uint64_t co_node_time(const struct co_node *node);

/**
 * @brief Give an event to the node's listeners, in registration order.
 *
 * For CO_EV_NMT_VETO the first refusal stops the round and is returned; every other event
 * reaches every listener that follows it.
 *
 * @retval 0 Delivered (or, for a veto, accepted by all).
 * @retval non-zero The refusal of a veto listener; @p who (if not NULL) gets its name.
 */
int co_node_publish(struct co_node *node, const struct co_event *ev, const char **who);

/**
 * @brief Report a communication error or its end (a CO_EV_ERROR event).
 *
 * The EMCY service (when built) raises or clears the emergency; other listeners (indicators,
 * a bridge) see it too.
 *
 * @param node The node.
 * @param code CiA 301 emergency error code.
 * @param reg_bits Error register bits (CO_EMCY_REG_*).
 * @param info First manufacturer byte, 0 if none.
 * @param flags CO_ERROR_F_ACTIVE to raise (none to clear), CO_ERROR_F_BEHAVIOUR to apply 1029h.
 */
void co_node_error(struct co_node *node, uint16_t code, uint8_t reg_bits, uint8_t info,
		   uint8_t flags);

/** @brief The node's NMT state, for services (the node's mutex is held). */
static inline enum co_nmt_state co_node_nmt_state(const struct co_node *node)
{
	return node->nmt.state;
}

/** @brief Whether the node has a node-ID (not CO_NODE_ID_UNCONFIGURED). */
static inline bool co_node_is_configured(const struct co_node *node)
{
	return node->node_id != CO_NODE_ID_UNCONFIGURED;
}

/** @} */

/**
 * @brief Who refused the node's last refused NMT state change.
 *
 * @param node The node.
 * @param err If not NULL, gets the refusal (the veto's return value).
 * @return The refusing listener's name ("application" for the state indication), or NULL
 *         when no change has been refused since the last reset.
 */
const char *co_nmt_get_refusal(struct co_node *node, int *err);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_NODE_H_ */
