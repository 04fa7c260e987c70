/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Between the line core (line.c) and its threaded binding (line_thread.c). */

#ifndef SAFELINE_SUBSYS_CANOPEN_CORE_LINE_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_CORE_LINE_INTERNAL_H_

#include <canopen/line.h>

/* Flags in co_line.flags. */
#define CO_LINE_F_RUNNING      0
#define CO_LINE_F_STOP         1
/* Frames wait in the TX queue: a TX completion must wake the thread to drain it. */
#define CO_LINE_F_TX_WAITING   2
/* The RX queue overflowed since the thread last reported it. */
#define CO_LINE_F_RX_OVERRUN   3
/* The controller state changed since the thread last reported it. */
#define CO_LINE_F_STATE        4
/* A wake message is in the RX queue. */
#define CO_LINE_F_WAKE_PENDING 5
/* The controller went bus-off since the thread last reported a state (recovery may have
 * followed before the thread ran; bus-off must still be reported).
 */
#define CO_LINE_F_BUS_OFF      6
/* The TX queue overflowed since the line thread last told the listeners (several are one). */
#define CO_LINE_F_TX_OVERFLOW  7

/* A frame lost to a full RX queue: counted, and reported by the line thread. */
static inline void co_line_rx_overrun(struct co_line *line)
{
	(void)__atomic_fetch_add(&line->stats.rx_overruns, 1U, __ATOMIC_RELAXED);
	atomic_set_bit(&line->flags, CO_LINE_F_RX_OVERRUN);
}

/*
 * A simulated line (co_line_init_sim()): no CAN device, time driven by the caller. Without
 * CONFIG_CANOPEN_LINE_SIM every line has a device and the simulation branches are left out.
 */
static inline bool co_line_is_sim(const struct co_line *line)
{
	return IS_ENABLED(CONFIG_CANOPEN_LINE_SIM) && line->dev == NULL;
}

/*
 * The reception time of a queued message: its low 32 bits extended from @p ref, a time of the
 * same line within 2^31 µs of it (the reader's current time).
 */
static inline uint64_t co_line_msg_time(const struct co_line_rx_msg *msg, uint64_t ref)
{
	uint32_t diff = msg->time_lo - (uint32_t)ref;
	int32_t ahead = (int32_t)diff;

	return ref + (uint64_t)(int64_t)ahead;
}

/* Wake the line thread so it re-reads its deadline (no-op in simulation). */
void co_line_wake(struct co_line *line);

/* Send through the CAN device: 0, -EAGAIN/-ENOBUFS on back-pressure, or a driver error. */
int co_line_dev_send(struct co_line *line, const struct can_frame *frame);

/* Retry frames that wait in the TX queue. */
void co_line_tx_drain(struct co_line *line);

/* Dispatch a frame; receivers whose lock is @p origin (the sending node's) are skipped. */
int co_line_dispatch(struct co_line *line, const struct can_frame *frame, uint64_t now_us,
		     const struct k_mutex *origin);

/*
 * Dispatch @p frame to the receivers of @p lock only (@p only true), or to all but them (false,
 * as co_line_dispatch() with @p lock as origin). A node on two lines hands the frames of its
 * redundant line to its own receivers this way (co_node_dispatch_from()); it is not counted
 * as a received frame of @p line.
 */
int co_line_dispatch_sel(struct co_line *line, const struct can_frame *frame, uint64_t now_us,
			 const struct k_mutex *lock, bool only);

/* Simulation: dispatch the frames waiting for local delivery. */
void co_line_local_drain(struct co_line *line);

/*
 * Report an event to the application's callback and to the listeners. Line thread (or the
 * simulation's driver) only, with no node lock held.
 */
void co_line_report(struct co_line *line, enum co_line_event event, int arg);

/*
 * Report an event raised by a send, in any thread and possibly under a node lock: the
 * application's callback runs now, the listeners later in the line thread
 * (co_line_report_deferred()).
 */
void co_line_report_from_send(struct co_line *line, enum co_line_event event, int arg);

/* Line thread: give the listeners the events co_line_report_from_send() held back. */
void co_line_report_deferred(struct co_line *line);

/*
 * Tests: emit a line event as the line thread would (application callback, then listeners).
 * Call from the thread that drives the line (a simulation test's thread), without node locks.
 */
static inline void co_line_inject_event(struct co_line *line, enum co_line_event event, int arg)
{
	co_line_report(line, event, arg);
}

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_LINE_INTERNAL_H_ */
