/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Several simulation lines on one simulated bus, on simulated time: what the multi-node tests
 * (flying master, SDO manager, LSS master, manager LSS) share. Every frame a line sends is
 * logged with its send time and delivered, in send order and at that time, to the other
 * lines on the same side of the bus. No threads: every handler runs inside co_bus_settle()
 * and co_bus_run_until().
 */

#ifndef SAFELINE_TESTS_CANOPEN_LIB_CO_BUS_H_
#define SAFELINE_TESTS_CANOPEN_LIB_CO_BUS_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>

#define CO_BUS_MAX_PORTS 8
#define CO_BUS_MAX_LOG   4096
#define CO_BUS_MAX_PEND  256
/* The sender of a frame fed in by the test (co_bus_inject()): it reaches every side. */
#define CO_BUS_INJECTED  (-1)

struct co_bus_port {
	struct co_line *line;
	bool used;
	/* Off: the line neither sends nor receives nor runs its timers (a node switched off). */
	bool alive;
	/* The controller pushes back (-EAGAIN): frames wait in the line's TX queue. */
	bool busy;
	/* Bus split: frames reach lines of the same side only. */
	int side;
};

struct co_bus_frame {
	struct can_frame f;
	uint64_t at;
	int from; /* port index, CO_BUS_INJECTED */
};

/* Called for every frame a line puts on the bus (counting by the LSS tests). */
typedef void (*co_bus_tap_t)(const struct can_frame *f, int from);

struct co_bus {
	/* Simulated time [µs]. */
	uint64_t now;
	struct co_bus_port port[CO_BUS_MAX_PORTS];
	struct co_bus_frame log[CO_BUS_MAX_LOG];
	int n_log;
	/* Set by a test that reads no log (long scans): frames are only delivered and tapped. */
	bool no_log;
	struct co_bus_frame pend[CO_BUS_MAX_PEND];
	int n_pend;
	co_bus_tap_t tap;
};

extern struct co_bus bus;

/* Clear everything: time 0, no port, no frame. */
void co_bus_init(void);

/* Initialise @p line as a simulation line on port @p i (alive, side 0). */
void co_bus_attach(int i, struct co_line *line, const char *name);

/* Deliver what was sent, at the time it was sent, until nobody sends any more. */
void co_bus_settle(void);

/* Advance the time to @p at_us, running every deadline of every live line at its own time. */
void co_bus_run_until(uint64_t at_us);

/* Advance the time by @p ms milliseconds. */
void co_bus_run_ms(uint64_t ms);

/* Put @p f on the bus as if another device sent it now, and deliver it. */
void co_bus_inject(const struct can_frame *f);

#endif /* SAFELINE_TESTS_CANOPEN_LIB_CO_BUS_H_ */
