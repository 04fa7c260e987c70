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

#if defined(CONFIG_CANOPEN_EMCY)
/* Emergency object (emcy/emcy.c). */
int co_emcy_init(struct co_node *node);
void co_emcy_reset_comm(struct co_node *node);
void co_emcy_set_state(struct co_node *node, enum co_nmt_state to);
/*
 * A communication error of the stack itself (heartbeat or life guarding): @p event true when
 * one just occurred (raises @p code unless active, then applies 1029h sub1), @p active whether
 * any such error is still present (the code is cleared when none is).
 */
/* Another service's own error (e.g. SYNC length 8240h): raised once, cleared by the service. */
void co_emcy_raise_internal(struct co_node *node, uint16_t code, uint8_t reg_bits);
void co_emcy_clear_internal(struct co_node *node, uint16_t code);
void co_emcy_comm_error(struct co_node *node, uint16_t code, uint8_t info, bool event, bool active);
#endif

#if defined(CONFIG_CANOPEN_SYNC)
/* SYNC (sync/sync.c). */
int co_sync_init(struct co_node *node);
void co_sync_reset_comm(struct co_node *node);
void co_sync_set_state(struct co_node *node, enum co_nmt_state to);
#endif

#if defined(CONFIG_CANOPEN_TIME)
/* TIME (time/time.c). */
int co_time_init(struct co_node *node);
void co_time_reset_comm(struct co_node *node);
void co_time_set_state(struct co_node *node, enum co_nmt_state to);
#endif

#if defined(CONFIG_CANOPEN_PDO)
/* PDO and MPDO (pdo/). */
int co_pdo_init(struct co_node *node);
void co_pdo_reset_comm(struct co_node *node);
void co_pdo_set_state(struct co_node *node, enum co_nmt_state to);
/*
 * A SYNC was received or produced at @p now_us with @p counter (0 without counter):
 * synchronous TPDOs are sampled and sent, synchronous RPDOs committed. @p window_us is 1007h
 * (0 = no window): samples sent later and RPDOs received later are dropped.
 */
void co_pdo_sync(struct co_node *node, uint8_t counter, uint64_t now_us, uint32_t window_us);
#endif

#if defined(CONFIG_CANOPEN_SDO_CLIENT)
/* SDO clients (sdo/sdo_cli.c). */
int co_sdo_cli_init(struct co_sdo_cli *cli, struct co_node *node, uint8_t num);
void co_sdo_cli_reset_comm(struct co_sdo_cli *cli);
void co_sdo_cli_set_state(struct co_sdo_cli *cli, enum co_nmt_state to);
#endif

#if defined(CONFIG_CANOPEN_MGR)
/* Manager: NMT master, boot-up, configuration manager (mgr/). */
int co_mgr_init(struct co_node *node);
void co_mgr_reset_comm(struct co_node *node);
void co_mgr_set_state(struct co_node *node, enum co_nmt_state to);
#endif

/* Every service, in the order the node configures them. */
void co_node_services_reset_comm(struct co_node *node);
void co_node_services_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to);

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_NODE_INTERNAL_H_ */
