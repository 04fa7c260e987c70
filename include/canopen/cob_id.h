/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief COB-ID rules shared by every service that lets its CAN-ID be configured.
 *
 * @ingroup canopen
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_COB_ID_H_
#define SAFELINE_INCLUDE_CANOPEN_COB_ID_H_

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Whether an 11-bit CAN-ID is restricted (CiA 301 §7.3.5, table 72).
 *
 * These identifiers belong to NMT (000h), SYNC/EMCY/TIME of the predefined connection set
 * (001h-07Fh, 101h-180h), the default SDO channels (581h-5FFh, 601h-67Fh), LSS and the
 * reserved range (6E0h-6FFh), and NMT error control (701h-77Fh, 780h-7FFh). No configurable
 * COB-ID (SYNC, TIME, EMCY, PDO, SDO) may use them.
 *
 * Out of line: every service that validates a COB-ID calls it, and an inline copy in each
 * costs about 50 bytes of code on a Cortex-M4.
 */
bool co_cob_id_restricted(uint32_t can_id);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_COB_ID_H_ */
