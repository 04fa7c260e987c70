/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What a service is to the node: a const ops record. The node (core/node.c) walks the records
 * of include/canopen/services.h in order; it knows no service by name.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_

#include <zephyr/kernel.h>

#include <canopen/node.h>

#include "lock_check.h"

/* The service runs while the node has no node-ID (CO_NODE_ID_UNCONFIGURED), e.g. LSS. */
#define CO_SERVICE_F_UNCONFIGURED BIT(0)

/*
 * A service. Every operation is optional (NULL) and runs with the node's mutex held.
 *
 * init:       once, from co_node_init(): register hooks, receivers, listeners, timers. A
 *             negative errno fails the node's initialisation; the core then undoes what
 *             every service registered (it leaves the line with every receiver and timer of
 *             the node's mutex, and starts the dictionary afresh), so a service whose init
 *             uses only those needs no undo of its own.
 * reset_comm: NMT Reset Communication (and the first boot): configure from the dictionary.
 * set_state:  the node entered @p to from @p from.
 */
struct co_service {
	const char *name;
	uint32_t flags;
	int (*init)(struct co_node *node);
	void (*reset_comm)(struct co_node *node);
	void (*set_state)(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to);
};

/*
 * Set up the core of a node and initialise @p services (the composition root in
 * core/services.c passes the list of canopen/services.h).
 */
int co_node_setup(struct co_node *node, const char *name, struct co_line *line,
		  const struct co_od_def *def, void *ram, uint8_t node_id,
		  const struct co_service *const *services, size_t n_services);

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_ */
