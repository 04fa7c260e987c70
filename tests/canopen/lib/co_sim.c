/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include "co_sim.h"

struct co_sim sim;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (sim.tx_busy) {
		return -EAGAIN;
	}
	zassert_true(sim.n_sent < CO_SIM_MAX_TX, "too many frames");
	sim.sent_at[sim.n_sent] = sim.now;
	sim.sent[sim.n_sent++] = *frame;
	return 0;
}

void co_sim_init(void)
{
	memset(&sim, 0, sizeof(sim));
	co_line_init_sim(&sim.line, "sim", sink, NULL);
}

void co_sim_run_until(uint64_t at_us)
{
	while (true) {
		uint64_t next = co_line_next_deadline(&sim.line);

		if (next == UINT64_MAX || next > at_us) {
			break;
		}
		sim.now = next;
		co_line_process(&sim.line, sim.now);
	}
	sim.now = at_us;
	co_line_process(&sim.line, sim.now);
}

void co_sim_rx_flags(uint32_t id, uint8_t dlc, const uint8_t *data, uint8_t flags)
{
	struct can_frame f = {.id = id, .dlc = dlc, .flags = flags};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}
	co_line_rx(&sim.line, &f, sim.now);
}

void co_sim_rx(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	co_sim_rx_flags(id, dlc, data, 0U);
}

void co_sim_nmt(uint8_t cs, uint8_t node_id)
{
	const uint8_t d[2] = {cs, node_id};

	co_sim_rx(0x000, 2, d);
}

uint32_t co_sim_write(struct co_node *node, uint16_t index, uint8_t sub, uint64_t value, size_t len)
{
	uint8_t buf[8];
	uint32_t ab;

	zassert_true(len >= 1U && len <= sizeof(buf));
	for (size_t i = 0; i < len; i++) {
		buf[i] = (uint8_t)(value >> (8 * i));
	}
	co_node_lock(node);
	ab = co_od_write(co_node_od(node), index, sub, buf, len, CO_OD_WRITER_SDO);
	co_node_unlock(node);
	return ab;
}
