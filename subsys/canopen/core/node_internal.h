/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * How the node drives its services. Every function here is called with the node's mutex held.
 * The NMT state machine (nmt/nmt.c) runs the resets and state changes and calls each
 * service's reset_comm and set_state in turn.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_

#include <canopen/node.h>

/* NMT slave (nmt/nmt.c). */
void co_nmt_init(struct co_node *node);
/* Initialising: reset application, reset communication, boot-up, Pre-operational. */
void co_nmt_boot(struct co_node *node);

/* Error control (nmt/errctl.c). */
int co_errctl_init(struct co_node *node);
void co_errctl_reset_comm(struct co_node *node);
void co_errctl_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to);

/* Every service, in the order the node configures them. */
void co_node_services_reset_comm(struct co_node *node);
void co_node_services_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to);

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_ */
