/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What the simulated-time service tests share: one simulation line whose sent frames are kept
 * with their send time, a clock advanced deadline by deadline, and the frames and dictionary
 * writes a test feeds in. No threads: every handler runs inside co_sim_rx()/co_sim_run_until().
 */

#ifndef SAFELINE_TESTS_CANOPEN_LIB_CO_SIM_H_
#define SAFELINE_TESTS_CANOPEN_LIB_CO_SIM_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/node.h>

#define CO_SIM_MAX_TX 128

struct co_sim {
	struct co_line line;
	/* Simulated time [µs]. */
	uint64_t now;
	/* Every frame the line sent, and when. */
	struct can_frame sent[CO_SIM_MAX_TX];
	uint64_t sent_at[CO_SIM_MAX_TX];
	int n_sent;
	/* While set, the sink pushes back (-EAGAIN): frames wait in the line's TX queue. */
	bool tx_busy;
};

extern struct co_sim sim;

/* Clear everything and initialise sim.line (time 0, no frames). */
void co_sim_init(void);

/* Advance the time to @p at_us, running every deadline on the way at its own time. */
void co_sim_run_until(uint64_t at_us);

/* Receive a frame at the current time (@p data may be NULL). */
void co_sim_rx(uint32_t id, uint8_t dlc, const uint8_t *data);

/* Receive a frame with flags (RTR, IDE) at the current time. */
void co_sim_rx_flags(uint32_t id, uint8_t dlc, const uint8_t *data, uint8_t flags);

/* Receive an NMT command for @p node_id (0: all). */
void co_sim_nmt(uint8_t cs, uint8_t node_id);

/* Write @p len (1..8) little-endian bytes of @p value as the SDO server would. */
uint32_t co_sim_write(struct co_node *node, uint16_t index, uint8_t sub, uint64_t value,
		      size_t len);

#endif /* SAFELINE_TESTS_CANOPEN_LIB_CO_SIM_H_ */
