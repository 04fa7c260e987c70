/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Sizes of the stack's state on the target, read by scripts/footprint from the symbol sizes
 * of this object (arm-none-eabi-nm -S): each fp_sizeof_X is an array of sizeof(X) bytes.
 * Not linked into the image.
 */

#include <zephyr/kernel.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/services.h>

#include "fp_od.h"

#define FP_SIZE(name, type) char fp_sizeof_##name[sizeof(type)]

FP_SIZE(line, struct co_line);
FP_SIZE(node, struct co_node);
FP_SIZE(od, struct co_od);
FP_SIZE(od_ram, struct fp_od_ram);
FP_SIZE(line_stack, char[CONFIG_CANOPEN_LINE_STACK_SIZE]);
FP_SIZE(rx, struct co_rx);
FP_SIZE(timer, struct co_timer);
#if defined(CONFIG_CANOPEN_PDO)
FP_SIZE(rpdo, struct co_rpdo);
FP_SIZE(tpdo, struct co_tpdo);
FP_SIZE(pdo_map_ent, struct co_pdo_map_ent);
FP_SIZE(pdo, struct co_pdo);
#endif
#if defined(CONFIG_CANOPEN_SDO_SERVER)
FP_SIZE(sdo_srv, struct co_sdo_srv);
#endif

/* Each service's state inside struct co_node, from the list of canopen/services.h. */
#define FP_SERVICE(name, member)                                                                   \
	struct fp_service_##name {                                                                 \
		member;                                                                            \
	};                                                                                         \
	FP_SIZE(service_##name, struct fp_service_##name);
CO_NODE_SERVICES(FP_SERVICE)
