/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The composition root: the one place that names every service (through the list of
 * canopen/services.h) and hands the list to the node core. The core (node.c) and the
 * services depend on each other only through this table, so no service is reachable from
 * node.c by a call, and node.c stays out of every dependency circle.
 */

#include <canopen/node.h>

#include "node_internal.h"

#define CO_SERVICE_EXTERN(name, member) extern const struct co_service co_service_##name;
#define CO_SERVICE_ENTRY(name, member)  &co_service_##name,

CO_NODE_SERVICES(CO_SERVICE_EXTERN)

static const struct co_service *const co_services[] = {CO_NODE_SERVICES(CO_SERVICE_ENTRY)};

int co_node_init(struct co_node *node, const char *name, struct co_line *line,
		 const struct co_od_def *def, void *ram, uint8_t node_id)
{
	return co_node_setup(node, name, line, def, ram, node_id, co_services,
			     ARRAY_SIZE(co_services));
}
