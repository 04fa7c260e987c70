/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include "co_bus.h"

struct co_bus bus;

static bool live(int i)
{
	return bus.port[i].used && bus.port[i].alive;
}

static void bus_put(const struct can_frame *f, int from)
{
	const struct co_bus_frame e = {.f = *f, .at = bus.now, .from = from};

	if (!bus.no_log) {
		zassert_true(bus.n_log < CO_BUS_MAX_LOG, "log full");
		bus.log[bus.n_log++] = e;
	}
	zassert_true(bus.n_pend < CO_BUS_MAX_PEND, "too many frames in flight");
	bus.pend[bus.n_pend++] = e;
	if (bus.tap != NULL) {
		bus.tap(f, from);
	}
}

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	int i = (int)(intptr_t)user_data;

	ARG_UNUSED(line);
	if (bus.port[i].busy) {
		return -EAGAIN;
	}
	if (bus.port[i].alive) {
		bus_put(frame, i);
	}
	return 0;
}

void co_bus_init(void)
{
	memset(&bus, 0, sizeof(bus));
}

void co_bus_attach(int i, struct co_line *line, const char *name)
{
	zassert_true(i >= 0 && i < CO_BUS_MAX_PORTS, "port %d", i);
	bus.port[i] = (struct co_bus_port){.line = line, .used = true, .alive = true};
	co_line_init_sim(line, name, sink, (void *)(intptr_t)i);
}

void co_bus_settle(void)
{
	for (int guard = 0; guard < 100000; guard++) {
		bool did = false;

		if (bus.n_pend > 0) {
			struct co_bus_frame e = bus.pend[0];

			memmove(&bus.pend[0], &bus.pend[1], (size_t)(bus.n_pend - 1) * sizeof(e));
			bus.n_pend--;
			for (int j = 0; j < CO_BUS_MAX_PORTS; j++) {
				if (j != e.from && live(j) &&
				    (e.from == CO_BUS_INJECTED ||
				     bus.port[j].side == bus.port[e.from].side)) {
					(void)co_line_rx(bus.port[j].line, &e.f, bus.now);
				}
			}
			did = true;
		}
		for (int j = 0; j < CO_BUS_MAX_PORTS; j++) {
			if (live(j) && k_msgq_num_used_get(&bus.port[j].line->rxq) > 0U) {
				co_line_process(bus.port[j].line, bus.now);
				did = true;
			}
		}
		if (!did) {
			return;
		}
	}
	zassert_unreachable("the bus does not settle");
}

static void process_all(void)
{
	for (int j = 0; j < CO_BUS_MAX_PORTS; j++) {
		if (live(j)) {
			co_line_process(bus.port[j].line, bus.now);
		}
	}
	co_bus_settle();
}

void co_bus_run_until(uint64_t at_us)
{
	co_bus_settle();
	for (int guard = 0; guard < 1000000; guard++) {
		uint64_t next = UINT64_MAX;

		for (int j = 0; j < CO_BUS_MAX_PORTS; j++) {
			if (live(j)) {
				next = MIN(next, co_line_next_deadline(bus.port[j].line));
			}
		}
		if (next > at_us) {
			break;
		}
		/* A deadline already passed runs now: the time never goes back. */
		bus.now = MAX(bus.now, next);
		process_all();
	}
	bus.now = at_us;
	process_all();
}

void co_bus_run_ms(uint64_t ms)
{
	co_bus_run_until(bus.now + ms * 1000ULL);
}

void co_bus_inject(const struct can_frame *f)
{
	bus_put(f, CO_BUS_INJECTED);
	co_bus_settle();
}
