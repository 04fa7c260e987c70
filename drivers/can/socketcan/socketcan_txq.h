/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The SocketCAN driver's frames in flight: written to the socket, waiting for their echo.
 * Plain data and arithmetic, no locking and no system calls, so that the rules are unit-tested
 * on any host (tests/drivers/can/socketcan_txq); the driver holds its lock around every call
 * and runs the callbacks of what comes out afterwards.
 *
 * An entry leaves the queue in one of three ways:
 * - its echo: the first entry, from the oldest, whose frame equals the echoed one;
 * - a lost echo: the kernel echoes a socket's frames in the order they were written, so when a
 *   later frame's echo comes, the echoes of the entries before it were dropped (the socket's
 *   receive buffer overflowed) and will never come;
 * - no echo at all for the timeout: the oldest entry leaves once both its own write and the
 *   last echo of any of our frames are at least the timeout in the past. An echo resets the
 *   clock because on a slow or busy bus a queue of frames legitimately takes long to drain;
 *   while echoes keep coming the bus is moving our frames.
 *
 * Times are nanoseconds on one monotonic clock, chosen by the caller.
 */

#ifndef SAFELINE_DRIVERS_CAN_SOCKETCAN_TXQ_H_
#define SAFELINE_DRIVERS_CAN_SOCKETCAN_TXQ_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/drivers/can.h>

#include "socketcan_host.h"

struct sc_txq_entry {
	can_tx_callback_t cb;
	void *user_data;
	struct socketcan_host_frame frame;
	uint64_t written_ns;
};

struct sc_txq {
	struct sc_txq_entry *entries; /* ring of @ref size, oldest at @ref head */
	uint16_t size;
	uint16_t head;
	uint16_t count;
	uint64_t timeout_ns;
	uint64_t last_echo_ns; /* 0: no echo yet */
};

/* What sc_txq_echo() found. */
enum sc_txq_echo_result {
	SC_TXQ_ECHO_MATCHED, /* @p done is the entry; @p lost[] the older ones */
	SC_TXQ_ECHO_LATE,    /* no entry has that frame: the echo of one that already left */
};

void sc_txq_init(struct sc_txq *q, struct sc_txq_entry *entries, uint16_t size,
		 uint64_t timeout_ns);

/* Appends an entry; false (nothing changed) if the queue is full. */
bool sc_txq_push(struct sc_txq *q, const struct socketcan_host_frame *frame, can_tx_callback_t cb,
		 void *user_data, uint64_t written_ns);

/* Removes the newest entry (its write failed). */
void sc_txq_drop_newest(struct sc_txq *q);

/*
 * The echo of one of our frames, received at @p at_ns. On SC_TXQ_ECHO_MATCHED, @p done gets
 * the matching entry and @p lost (room for the queue's size) the @p n_lost entries written
 * before it, oldest first.
 */
enum sc_txq_echo_result sc_txq_echo(struct sc_txq *q, const struct socketcan_host_frame *frame,
				    uint64_t at_ns, struct sc_txq_entry *done,
				    struct sc_txq_entry *lost, int *n_lost);

/*
 * Removes, oldest first, the entries with no echo for the timeout as of @p now_ns into
 * @p out (room for the queue's size); returns how many.
 */
int sc_txq_expire(struct sc_txq *q, uint64_t now_ns, struct sc_txq_entry *out);

/* Removes every entry into @p out, oldest first; returns how many. */
int sc_txq_take_all(struct sc_txq *q, struct sc_txq_entry *out);

static inline uint16_t sc_txq_count(const struct sc_txq *q)
{
	return q->count;
}

#endif /* SAFELINE_DRIVERS_CAN_SOCKETCAN_TXQ_H_ */
