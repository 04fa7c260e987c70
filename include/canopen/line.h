/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen line: one CAN interface, one thread, one receive table, one timer heap.
 *
 * A line is the unit of concurrency of the stack (doc/architecture.md). Services register receivers
 * (by COB-ID) and timers (by absolute deadline) on the line. The line dispatches each received
 * frame to its receivers and each expired timer to its handler, taking the owner's mutex (the
 * node's) around every call. The thread sleeps until the next frame or the next deadline; it
 * never polls.
 *
 * The dispatch core is I/O-free: co_line_rx() and co_line_process() take the time as an
 * argument and co_line_send() hands frames to a sink in simulation mode, so protocol tests run
 * on simulated time without threads. co_line_start() binds the same core to a CAN device and a
 * thread.
 *
 * Time is a 64-bit monotonic count of microseconds.
 *
 * @defgroup co_line CANopen line
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_LINE_H_
#define SAFELINE_INCLUDE_CANOPEN_LINE_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/kernel.h>
#include <zephyr/drivers/can.h>
#include <zephyr/sys/slist.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_line;
struct co_rx;
struct co_timer;

/** @cond INTERNAL_HIDDEN */
/* Keys of the receive table beyond the 11-bit ids (struct co_line, rx_key). */
#define CO_LINE_KEY_MASKED 0x8000U
#define CO_LINE_KEY_FREE   0xffffU
/* In co_line.rx_masked_codes: a 29-bit receiver is registered. */
#define CO_LINE_MASKED_EXT (1U << 16)
/** @endcond */

/**
 * @brief Receive a frame.
 *
 * Runs in the line thread (or the caller of co_line_rx() in simulation), with the receiver's
 * lock held. Must not block.
 *
 * @param rx The receiver the frame matched.
 * @param frame The frame; valid during the call only.
 * @param now_us Reception time of the frame [µs].
 */
typedef void (*co_rx_handler_t)(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us);

/**
 * @brief Handle an expired deadline.
 *
 * Runs in the line thread with the timer's lock held; the timer is disarmed before the call
 * and may be re-armed from the handler. Must not block.
 *
 * @param timer The timer.
 * @param now_us Current time [µs] (at or after the deadline).
 */
typedef void (*co_timer_handler_t)(struct co_timer *timer, uint64_t now_us);

/**
 * @brief Send a frame in simulation mode (no CAN device).
 *
 * Runs in the sending thread (or the one draining the TX queue). As a CAN driver's
 * can_send(), it may be called by several threads at once when several threads send: a frame
 * goes to it without the line's TX lock while nothing waits in the TX queue.
 *
 * @retval 0 The frame was taken.
 * @retval -EAGAIN The sink is full; the line queues the frame and retries on co_line_process().
 */
typedef int (*co_line_sink_t)(struct co_line *line, const struct can_frame *frame, void *user_data);

/** Line events reported through co_line_event_cb_t. */
enum co_line_event {
	/** The RX queue overflowed; frames were lost (CiA 301 EMCY 8110h "CAN overrun"). */
	CO_LINE_EV_RX_OVERRUN,
	/** The TX queue overflowed; a frame was dropped (counted in co_line_stats). */
	CO_LINE_EV_TX_OVERFLOW,
	/** The CAN controller changed state; @p arg is the new enum can_state. */
	CO_LINE_EV_CAN_STATE,
	/** A send failed with a driver error other than back-pressure; @p arg is -errno. */
	CO_LINE_EV_TX_ERROR,
};

/**
 * @brief Learn about line events (overruns, controller state changes, TX errors).
 *
 * The application's callback (co_line_set_event_cb()). Runs in the line thread without any
 * node lock held, except CO_LINE_EV_TX_OVERFLOW and CO_LINE_EV_TX_ERROR raised by a send,
 * which run in the sender's thread. Must not block.
 */
typedef void (*co_line_event_cb_t)(struct co_line *line, enum co_line_event event, int arg,
				   void *user_data);

struct co_line_listener;

/**
 * @brief A line event for a listener (co_line_listener_add()).
 *
 * Always runs in the line thread (in simulation: the caller of co_line_process() or of the
 * test injection), with the listener's lock held and no other node lock. Events raised by a
 * send (TX overflow, TX error) are deferred to the line thread, so a listener never runs
 * inside another node's call. Must not block.
 *
 * @param l The listener.
 * @param event The event.
 * @param arg As for co_line_event_cb_t.
 */
typedef void (*co_line_listener_cb_t)(struct co_line_listener *l, enum co_line_event event,
				      int arg);

/** A listener for line events; embedded in a service (e.g. a node's EMCY). */
struct co_line_listener {
	/** Handler; called with @ref lock held. */
	co_line_listener_cb_t cb;
	/** Owner's mutex (a node's), or NULL. */
	struct k_mutex *lock;
	/** Opaque pointer for the handler. */
	void *user_data;

	/** @cond INTERNAL_HIDDEN */
	struct co_line_listener *next;
	struct co_line *line;
	/** @endcond */
};

/** A receiver: a COB-ID (optionally masked) bound to a handler. Embedded in a service. */
struct co_rx {
	/** CAN identifier to match (11 or 29 bits). */
	uint32_t id;
	/** Bits of @ref id that must match; all ones for an exact match. */
	uint32_t mask;
	/** Match 29-bit (extended) identifiers. */
	bool ext;
	/** Handler; called with @ref lock held. */
	co_rx_handler_t handler;
	/** Owner's mutex (a node's), or NULL. */
	struct k_mutex *lock;
	/** Opaque pointer for the handler. */
	void *user_data;

	/** @cond INTERNAL_HIDDEN */
	struct co_line *line;
	/*
	 * The line's copy of the frame key (id, with bit 31 for a 29-bit id) and of the mask, for
	 * masked and 29-bit receivers: written under the table lock when the receiver joins a
	 * line and read by lookups that take no lock (line.c), while the owner may rewrite id,
	 * mask and ext of a receiver it has just unregistered. Exact 11-bit receivers are
	 * matched by the table's key array and never read them.
	 */
	uint32_t key_id;
	uint32_t key_mask;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
/*
 * A 64-bit time aligned to 4 bytes: a 32-bit target (Cortex-M's LDRD needs no more) then
 * keeps struct co_timer at 28 instead of 32 bytes. On a typedef, GCC's aligned attribute may
 * lower the alignment.
 */
typedef uint64_t co_time4_t __attribute__((aligned(4)));
/** @endcond */

/** @cond INTERNAL_HIDDEN */
#define CO_TIMER_UNARMED 0xffffU
/** @endcond */

/** A deadline bound to a handler. Embedded in a service. */
struct co_timer {
	/** Handler; called with @ref lock held. */
	co_timer_handler_t handler;
	/** Owner's mutex (a node's), or NULL. */
	struct k_mutex *lock;
	/** Opaque pointer for the handler. */
	void *user_data;

	/** @cond INTERNAL_HIDDEN */
	co_time4_t deadline;
	struct co_line *line;
	/* Arming number on its line: equal deadlines run in arming order. */
	uint32_t seq;
	/* Place in the line's heap of armed timers, CO_TIMER_UNARMED when not armed. */
	uint16_t slot;
	/** @endcond */
};

/**
 * A node's membership of a line (embedded in the node): the line knows its nodes' locks, to
 * deliver frames between them and to tell whether a thread holds one (co_line_owner_held()).
 */
struct co_line_member {
	/** @cond INTERNAL_HIDDEN */
	struct co_line_member *next;
	const struct k_mutex *lock;
	/** @endcond */
};

/** Counters of a line, for diagnostics and tests. */
struct co_line_stats {
	uint32_t rx_frames;    /**< Frames dispatched. */
	uint32_t rx_unhandled; /**< Frames no receiver wanted. */
	uint32_t rx_overruns;  /**< Frames lost because the RX queue was full. */
	uint32_t tx_frames;    /**< Frames handed to the driver or the sink. */
	uint32_t tx_queued;    /**< Frames that had to wait for back-pressure to clear. */
	uint32_t tx_dropped;   /**< Frames dropped because the TX queue was full. */
	uint32_t tx_errors;    /**< Sends refused by the driver with an error. */
	uint16_t tx_queue_max; /**< Highest TX queue occupancy seen. */
	/** Queued frames a node withdrew (co_line_tx_purge(), e.g. on entering Stopped). */
	uint32_t tx_purged;
	/** Receivers a frame did not reach: more matched than CONFIG_CANOPEN_LINE_RX_FANOUT. */
	uint32_t rx_fanout_drops;
	/** Timers not armed: CONFIG_CANOPEN_LINE_TIMERS were armed already (logged once). */
	uint32_t timer_overflows;
};

/** @cond INTERNAL_HIDDEN */
/*
 * The kind of a queued message, in the two high bits of its frame's dlc, which a frame never
 * sets (a DLC is 4 bits on the bus; a driver refuses a larger one to send): a field of its own
 * would make the message 4 bytes longer. A frame from the bus has neither.
 */
#define CO_LINE_MSG_FRAME 0x00U
#define CO_LINE_MSG_WAKE  0x80U
/* A frame sent by a node of this line, for the line's other nodes. */
#define CO_LINE_MSG_LOCAL 0x40U
#define CO_LINE_MSG_KINDS (CO_LINE_MSG_WAKE | CO_LINE_MSG_LOCAL)

struct co_line_rx_msg {
#if defined(CONFIG_CANOPEN_LINE_SHARED)
	/* CO_LINE_MSG_LOCAL: lock of the sending node, whose receivers skip the frame. First:
	 * a 64-bit host then packs the rest behind it (32 bytes, not 40).
	 */
	const struct k_mutex *origin;
#endif
	/* Its dlc carries the kind (CO_LINE_MSG_KINDS). */
	struct can_frame frame;
	/*
	 * Low 32 bits of the reception time [µs]: a message waits far less than the 35 minutes
	 * that half of them span, and the reader extends them from its own time. A message is 20
	 * bytes on a 32-bit target (24 on a shared line); a 64-bit time would make it 24 (32).
	 */
	uint32_t time_lo;
};

struct co_line {
	const char *name;
	/*
	 * Receive table (line.c, "Receive table"): rx_key[i] is the key of receiver rx_tab[i].
	 * The rx_exact exact 11-bit receivers come first, sorted by id (key: the id; receivers of
	 * one id in registration order), then the masked and 29-bit ones (CO_LINE_KEY_MASKED, in
	 * registration order), then free entries (CO_LINE_KEY_FREE, NULL). rx_used entries in all.
	 * One more key, always free, ends every run of equal keys inside the array.
	 */
	struct co_rx *rx_tab[CONFIG_CANOPEN_LINE_RX_SLOTS];
	uint16_t rx_key[CONFIG_CANOPEN_LINE_RX_SLOTS + 1];
	uint8_t rx_exact;
	uint8_t rx_used;
	/* Nodes attached; from two on, frames a node sends reach the others (local delivery). */
	uint8_t n_nodes;
	/*
	 * Which frames the masked part can match: bit g (0..15) when a masked 11-bit receiver
	 * matches some id of function code g (id >> 7), CO_LINE_MASKED_EXT when a 29-bit
	 * receiver is registered. A frame walks the masked part only when its bit is set.
	 */
	uint32_t rx_masked_codes;
	/*
	 * Sequence count of the receive table: odd while a writer (holding lock) changes it.
	 * Lookups read the table without the lock and keep their result only when the count
	 * was even and unchanged around the read (line.c, "Receive table").
	 */
	uint32_t rx_seq;
	/*
	 * Armed timers, a binary min-heap by (deadline, seq): timers[0] runs first, a timer's
	 * children are at 2 * slot + 1 and 2 * slot + 2 (line.c, "Timers").
	 */
	struct co_timer *timers[CONFIG_CANOPEN_LINE_TIMERS];
	uint16_t n_timers;
	/* Arming number of the next co_timer_start(). */
	uint32_t timer_seq;
	/*
	 * The timer co_line_process() took off the heap and is about to run; a start or stop
	 * of it meanwhile (by its owner, in another thread) clears this, and it does not run.
	 */
	struct co_timer *popped;
	/* Serialises changes of the receive table, protects the timer heap. Leaf lock: never
	 * held while a node lock is taken.
	 */
	struct k_mutex lock;

	/* TX ring; frames wait here while the driver pushes back. */
	struct k_mutex tx_lock;
	struct can_frame txq[CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE];
	/* The sending node's mutex of each queued frame (NULL: sent with co_line_send()). */
	const struct k_mutex *txq_origin[CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE];
	uint16_t tx_head;
	uint16_t tx_count;
	/* Frames handed to the driver whose TX completion has not run yet (co_line_stop()). */
	atomic_t tx_inflight;

#if defined(CONFIG_CANOPEN_LINE_SIM)
	co_line_sink_t sink;
	void *sink_user_data;
#endif
	co_line_event_cb_t event_cb;
	void *event_user_data;
	/* Listeners of the nodes on the line, in registration order. */
	struct co_line_listener *listeners;
	/* A send-side TX error waiting for the line thread's listeners (an overflow: a flag). */
	atomic_t tx_error_pending;
	/* rx_overruns is counted with atomic operations (driver callbacks), the rest as noted. */
	struct co_line_stats stats;
#if defined(CONFIG_CANOPEN_LINE_SIM)
	/* Simulation mode: the time of the last co_line_rx()/co_line_process(). */
	uint64_t sim_now;
#endif
	struct co_line_member *members;

	/* Received frames for the thread; in simulation, frames for local delivery only. */
	struct k_msgq rxq;
	/* Threaded mode. */
	const struct device *dev;
	char rxq_buf[CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE * sizeof(struct co_line_rx_msg)];
	k_tid_t tid;
	int filter_std;
	/*
	 * After the two words above: in the 32-bit footprint build, on its 16-byte alignment, and
	 * the four words after it end the line there too (no padding before or after it).
	 */
	struct k_thread thread;
	int filter_ext;
	atomic_t flags;
	atomic_t can_state;
	atomic_t tx_async_err;
};
/** @endcond */

/**
 * @name Setting up a line
 * @{
 */

#if defined(CONFIG_CANOPEN_LINE_SIM)
/**
 * @brief Initialise a line in simulation mode: frames sent go to @p sink.
 *
 * Nothing runs by itself: the caller feeds frames with co_line_rx() and time with
 * co_line_process(). Used by protocol unit tests on simulated time. Only with
 * CONFIG_CANOPEN_LINE_SIM.
 *
 * @param line Line to initialise (statically allocated by the caller).
 * @param name Name for logs; must outlive the line.
 * @param sink Receives every frame the line sends.
 * @param user_data Passed to @p sink.
 */
void co_line_init_sim(struct co_line *line, const char *name, co_line_sink_t sink, void *user_data);
#endif

/**
 * @brief Initialise a line bound to a CAN device.
 *
 * Receivers and timers may be registered before co_line_start().
 *
 * @param line Line to initialise (statically allocated by the caller).
 * @param name Name for logs and the thread; must outlive the line.
 * @param dev CAN controller; must be ready.
 *
 * @retval 0 Initialised.
 * @retval -ENODEV The device is not ready.
 */
int co_line_init(struct co_line *line, const char *name, const struct device *dev);

/**
 * @brief Start the line: install the CAN filters, start the controller and the line thread.
 *
 * @param line Initialised line.
 * @param stack Stack for the line thread (K_THREAD_STACK_DEFINE), owned by the line until
 *              co_line_stop() returns.
 * @param stack_size Size of @p stack (K_THREAD_STACK_SIZEOF).
 * @param prio Thread priority.
 *
 * @retval 0 Running.
 * @retval -EALREADY The line is already running.
 * @retval -ENOSPC The driver has no free filter.
 * @retval -EIO The controller could not be started.
 */
int co_line_start(struct co_line *line, k_thread_stack_t *stack, size_t stack_size, int prio);

/**
 * @brief Stop the line thread and remove the CAN filters. Waits for the thread to end.
 *
 * Returns 0 only when no callback of the line (receive, state change, TX completion) can run
 * any more: the line may then be re-initialised or freed. Waits for the TX completions of the
 * frames the driver holds; after 100 ms it stops the controller (can_stop()) to abort them.
 * Frames sent meanwhile wait in the line's TX queue. Must not be called from the line thread.
 *
 * @retval 0 Stopped.
 * @retval -EBUSY Stopped, but the driver still holds frames it could not abort: their
 *         completions will still reach the line; keep it untouched and call again until 0.
 * @retval -EALREADY The line was not running.
 */
int co_line_stop(struct co_line *line);

/**
 * @brief Set the application's callback for line events (NULL to remove).
 *
 * One per line; independent of the listeners (co_line_listener_add()), which the nodes use.
 */
void co_line_set_event_cb(struct co_line *line, co_line_event_cb_t cb, void *user_data);

/** @brief Fill a listener; register it with co_line_listener_add(). */
static inline void co_line_listener_init(struct co_line_listener *l, co_line_listener_cb_t cb,
					 struct k_mutex *lock, void *user_data)
{
	*l = (struct co_line_listener){
		.cb = cb,
		.lock = lock,
		.user_data = user_data,
	};
}

/**
 * @brief Register a listener for the line's events (co_node_init() registers the node's).
 *
 * Every listener gets every event, in registration order, after the application's
 * callback. A listener registered on another line is moved.
 *
 * @retval 0 Registered (or already registered on @p line).
 */
int co_line_listener_add(struct co_line *line, struct co_line_listener *l);

/**
 * @brief Remove a listener. Safe on a listener that is not registered. A listener removed
 * while its line reports an event may still get that event, not later ones.
 */
void co_line_listener_remove(struct co_line_listener *l);

/** @} */

/**
 * @name Receivers and timers
 * @{
 */

/**
 * @brief Fill a receiver for one exact 11-bit COB-ID; register it with co_rx_register() or
 * co_rx_set_id().
 */
static inline void co_rx_init(struct co_rx *rx, uint32_t id, co_rx_handler_t handler,
			      struct k_mutex *lock, void *user_data)
{
	*rx = (struct co_rx){
		.id = id,
		.mask = 0x7ffU,
		.handler = handler,
		.lock = lock,
		.user_data = user_data,
	};
}

/**
 * @brief Register a receiver on a line.
 *
 * Fill @p rx (id, mask, ext, handler, lock, user_data) first. Several receivers may share one
 * COB-ID; each gets every matching frame, exact 11-bit receivers (mask 7FFh) first, each kind
 * in registration order. Each receiver, of any kind, takes one of the line's
 * CONFIG_CANOPEN_LINE_RX_SLOTS entries. A frame's exact receivers are found by a binary search
 * over the whole table (the same number of steps however many are registered); masked and
 * 29-bit receivers are compared only with frames they can match (by function code).
 *
 * @retval 0 Registered.
 * @retval -EALREADY @p rx is already registered on a line.
 * @retval -EINVAL The id does not fit 11 (or 29) bits.
 * @retval -ENOSPC All CONFIG_CANOPEN_LINE_RX_SLOTS entries are in use.
 */
int co_rx_register(struct co_line *line, struct co_rx *rx);

/**
 * @brief Remove a receiver. Safe on a receiver that is not registered.
 */
void co_rx_unregister(struct co_rx *rx);

/**
 * @brief Move a registered receiver to a new COB-ID (e.g. after a COB-ID object write).
 *
 * @retval 0 Moved (or registered, if it was not).
 * @retval -EINVAL The id does not fit.
 * @retval -ENOSPC No free entry (for a receiver that was not registered on @p line); it is
 *         then unregistered.
 */
int co_rx_set_id(struct co_line *line, struct co_rx *rx, uint32_t id);

/**
 * @brief Initialise a timer. Call once before co_timer_start().
 */
void co_timer_init(struct co_timer *timer, co_timer_handler_t handler, struct k_mutex *lock,
		   void *user_data);

/**
 * @brief Arm a timer for an absolute deadline, replacing any earlier deadline.
 *
 * May be called from any thread; the line thread wakes if the new deadline comes first.
 * Costs O(log n) in the armed timers of the line. When CONFIG_CANOPEN_LINE_TIMERS timers are
 * armed on the line already, the timer stays disarmed: the line counts it
 * (co_line_stats.timer_overflows) and logs an error the first time. The services call it
 * through co_node_timer_start(), which returns nothing, from handlers that cannot undo what
 * they did: a size that fits the services a node runs is the remedy, not a return value.
 *
 * @param line Line whose thread runs the handler.
 * @param timer Initialised timer.
 * @param deadline_us Absolute time [µs] (same clock as co_line_now()).
 */
void co_timer_start(struct co_line *line, struct co_timer *timer, uint64_t deadline_us);

/** @brief Disarm a timer. Safe on a timer that is not armed. */
void co_timer_stop(struct co_timer *timer);

/** @brief Whether a timer is armed. */
bool co_timer_is_armed(const struct co_timer *timer);

/** @} */

/**
 * @name Sending and dispatch
 * @{
 */

/**
 * @brief Send a frame on the line, in order with every frame sent before.
 *
 * When the driver reports back-pressure the frame waits in the line's TX queue and goes out as
 * soon as the driver takes frames again; the caller never retries. While the queue is empty
 * the frame goes straight to the driver without the line's TX lock. "Before" is the order of
 * the calls: a send that returned before another began goes out first; sends that overlap in
 * time, from different threads, may go out in either order.
 *
 * @retval 0 Sent or queued.
 * @retval -ENOBUFS The TX queue is full; the frame is dropped, counted and reported
 *         (CO_LINE_EV_TX_OVERFLOW).
 * @retval -ENETDOWN The controller is stopped or bus-off.
 * @retval -EIO Another driver error (reported as CO_LINE_EV_TX_ERROR).
 */
int co_line_send(struct co_line *line, const struct can_frame *frame);

/**
 * @brief Free places in the line's TX queue.
 *
 * A producer of a long burst (an SDO block upload sub-block) checks this to pause before the
 * queue overflows, instead of losing a frame to co_line_send()'s -ENOBUFS.
 *
 * @return Frames that can be sent now without an overflow (at least).
 */
int co_line_tx_space(struct co_line *line);

/**
 * @brief Send a frame on behalf of a node attached to the line.
 *
 * Like co_line_send(); in addition, when several nodes share the line, the frame is delivered
 * to the receivers of the other nodes (the controller does not receive its own frames, but
 * the other nodes are on the bus as much as any remote one). Receivers whose lock is
 * @p origin do not get it. Local delivery happens in the line thread (in simulation: in the
 * next co_line_process()), with the send time as reception time.
 *
 * @return As co_line_send().
 */
int co_line_send_from(struct co_line *line, const struct can_frame *frame,
		      const struct k_mutex *origin);

/**
 * @brief Withdraw frames a node queued on the line (waiting for back-pressure to clear).
 *
 * The node core calls it when a node enters Stopped: what the node queued before (an SDO
 * answer, a PDO) must not go out in a state where only NMT and error control may speak.
 *
 * @param line The line.
 * @param origin The node's mutex, as given to co_line_send_from().
 * @param keep Frames to keep (NULL: none); called with the line's TX lock held, must not block.
 * @param arg Passed to @p keep.
 * @return Number of frames withdrawn (counted in co_line_stats.tx_purged).
 */
int co_line_tx_purge(struct co_line *line, const struct k_mutex *origin,
		     bool (*keep)(const struct can_frame *frame, void *arg), void *arg);

/**
 * @brief Attach a node to the line (co_node_init() does it).
 *
 * @param line The line.
 * @param m The node's membership record; @p lock is the node's mutex.
 * @param lock The node's mutex.
 * @retval 0 attached
 * @retval -EBUSY another node is attached and CONFIG_CANOPEN_LINE_SHARED is off
 */
int co_line_attach(struct co_line *line, struct co_line_member *m, const struct k_mutex *lock);

/**
 * @brief Detach a node from the line, with every receiver and timer of its mutex.
 *
 * Safe on a record that is not attached.
 */
void co_line_detach(struct co_line *line, struct co_line_member *m);

/**
 * @brief Whether the calling thread holds the mutex of a node attached to @p line.
 *
 * A thread holding one must not wait for the line's thread (it may need that mutex).
 */
bool co_line_owner_held(struct co_line *line);

/** @brief The line whose thread is calling, or NULL when called from any other thread. */
struct co_line *co_line_current(void);

/**
 * @brief Dispatch one received frame to its receivers.
 *
 * The line thread calls this for each frame; simulation tests call it directly, from one
 * thread at a time. The receivers are looked up without a lock (receivers may be registered
 * and moved meanwhile by any thread); each is called with its own lock held.
 *
 * @param line Line.
 * @param frame Received frame.
 * @param now_us Reception time [µs].
 * @return Number of receivers that got the frame.
 */
int co_line_rx(struct co_line *line, const struct can_frame *frame, uint64_t now_us);

/**
 * @brief Run every timer whose deadline is at or before @p now_us, and retry queued frames.
 *
 * @return The earliest remaining deadline [µs], or UINT64_MAX if no timer is armed.
 */
uint64_t co_line_process(struct co_line *line, uint64_t now_us);

/** @brief Earliest armed deadline [µs], or UINT64_MAX. */
uint64_t co_line_next_deadline(struct co_line *line);

/** @brief Copy the line's counters. */
void co_line_get_stats(struct co_line *line, struct co_line_stats *stats);

/** @brief Current time of the line clock [µs] (monotonic, from k_uptime_ticks()). */
uint64_t co_line_now(void);

/**
 * @brief Time as the line sees it [µs]: the clock for a threaded line, the time last passed to
 * co_line_rx()/co_line_process() for a simulation line.
 *
 * Services use it where no time is handed to them (OD hooks, application requests), so that
 * simulation tests stay deterministic.
 */
uint64_t co_line_time(const struct co_line *line);

/** @brief The line's CAN device, or NULL for a simulation line. */
const struct device *co_line_device(const struct co_line *line);

/** @} */

/**
 * @brief Whether two times are ordered a <= b, wrap-safe for any difference below 2^63 µs.
 */
static inline bool co_time_before_eq(uint64_t a, uint64_t b)
{
	return (int64_t)(a - b) <= 0;
}

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_LINE_H_ */
