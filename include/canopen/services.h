/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The services a node runs: the one list of the stack.
 *
 * Each service is a folder under subsys/canopen with a const ops record
 * (`const struct co_service co_service_NAME`, see subsys/canopen/core/node_internal.h) and,
 * when it keeps per-node state, a struct in its public header. This file names them once, in
 * the order the node initialises them, resets their communication and tells them of NMT state
 * changes; the node walks the list (reverse order to undo an initialisation).
 *
 * Adding a service: its folder (CMakeLists.txt, Kconfig, sources, header) and one entry
 * below: the header's include and one X() line. Nothing else in the stack changes.
 *
 * X(name, member): @p name gives the ops record co_service_<name>; @p member declares the
 * service's state inside struct co_node (or is empty for a service without state).
 *
 * @ingroup co_node
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SERVICES_H_
#define SAFELINE_INCLUDE_CANOPEN_SERVICES_H_

#include <zephyr/sys/util_macro.h>

#include <canopen/errctl.h>
#if defined(CONFIG_CANOPEN_REDUNDANCY) || defined(__DOXYGEN__)
#include <canopen/redundancy.h>
#endif
#if defined(CONFIG_CANOPEN_LSS) || defined(__DOXYGEN__)
#include <canopen/lss.h>
#endif
#if defined(CONFIG_CANOPEN_LSS_MASTER) || defined(__DOXYGEN__)
#include <canopen/lss_master.h>
#endif
#if defined(CONFIG_CANOPEN_EMCY) || defined(__DOXYGEN__)
#include <canopen/emcy.h>
#endif
#if defined(CONFIG_CANOPEN_SYNC) || defined(__DOXYGEN__)
#include <canopen/sync.h>
#endif
#if defined(CONFIG_CANOPEN_TIME) || defined(__DOXYGEN__)
#include <canopen/time.h>
#endif
#if defined(CONFIG_CANOPEN_PDO) || defined(__DOXYGEN__)
#include <canopen/pdo.h>
#endif
#if defined(CONFIG_CANOPEN_SRDO) || defined(__DOXYGEN__)
#include <canopen/srdo.h>
#endif
#if defined(CONFIG_CANOPEN_SDO_SERVER) || defined(__DOXYGEN__)
#include <canopen/sdo.h>
#endif
#if defined(CONFIG_CANOPEN_SDO_CLIENT) || defined(__DOXYGEN__)
#include <canopen/sdo_cli.h>
#endif
#if defined(CONFIG_CANOPEN_MGR) || defined(__DOXYGEN__)
#include <canopen/mgr.h>
#endif
#if defined(CONFIG_CANOPEN_PGM) || defined(__DOXYGEN__)
#include <canopen/pgm.h>
#endif
#if defined(CONFIG_CANOPEN_LEDS) || defined(__DOXYGEN__)
#include <canopen/leds.h>
#endif

/*
 * The order is what a node does on the bus at a reset or state change: LSS before all (it
 * runs while the node has no node-ID, and a reset returns it to waiting before anything else
 * is configured), the line choice of a node on two lines (set before anything is sent), error
 * control next (a state change is announced by a heartbeat at once),
 * then EMCY, SYNC, TIME, PDO, SRDO, SDO; program download after the SDO server that feeds it;
 * the manager after the SDO clients its boot-up uses;
 * the indicators, which only listen, last.
 */
/* clang-format off */
#define CO_NODE_SERVICES(X)                                                                        \
	IF_ENABLED(CONFIG_CANOPEN_LSS, (X(lss, struct co_lss lss)))                                \
	IF_ENABLED(CONFIG_CANOPEN_LSS_MASTER, (X(lss_master, struct co_lss_master lssm)))          \
	IF_ENABLED(CONFIG_CANOPEN_REDUNDANCY, (X(redundancy, struct co_redundancy rdn)))           \
	X(errctl, struct co_errctl ec)                                                             \
	IF_ENABLED(CONFIG_CANOPEN_EMCY, (X(emcy, struct co_emcy emcy)))                            \
	IF_ENABLED(CONFIG_CANOPEN_SYNC, (X(sync, struct co_sync sync)))                            \
	IF_ENABLED(CONFIG_CANOPEN_TIME, (X(time, struct co_time_svc time)))                        \
	IF_ENABLED(CONFIG_CANOPEN_PDO, (X(pdo, struct co_pdo pdo)))                                \
	IF_ENABLED(CONFIG_CANOPEN_SRDO, (X(srdo, struct co_srdo srdo)))                            \
	IF_ENABLED(CONFIG_CANOPEN_SDO_SERVER,                                                      \
		   (X(sdo_srv, struct co_sdo_srv sdo_srv[CONFIG_CANOPEN_SDO_SERVERS])))            \
	IF_ENABLED(CONFIG_CANOPEN_PGM, (X(pgm, struct co_pgm pgm)))                                \
	IF_ENABLED(CONFIG_CANOPEN_SDO_CLIENT,                                                      \
		   (X(sdo_cli, struct co_sdo_cli sdo_cli[CONFIG_CANOPEN_SDO_CLIENTS])))            \
	IF_ENABLED(CONFIG_CANOPEN_MGR, (X(mgr, struct co_mgr mgr)))                                \
	IF_ENABLED(CONFIG_CANOPEN_LEDS, (X(leds, struct co_leds leds)))
/* clang-format on */

#endif /* SAFELINE_INCLUDE_CANOPEN_SERVICES_H_ */
