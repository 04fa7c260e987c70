/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Helpers shared by the object dictionary sources (access layer and EDS writer). */

#ifndef SAFELINE_SUBSYS_CANOPEN_OD_OD_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_OD_OD_INTERNAL_H_

#include <canopen/od.h>

#include "lock_check.h"

/* The lock rule: a node's dictionary is used with the node's mutex held (lock_check.h). */
#define OD_ASSERT_LOCKED(od)                                                                       \
	do {                                                                                       \
		if ((od)->lock != NULL) {                                                          \
			CO_ASSERT_LOCKED((od)->lock);                                              \
		}                                                                                  \
	} while (false)

/* Bits of struct co_od_limit.rel. */
#define CO_OD_LIM_LO_REL   0x01U
#define CO_OD_LIM_HI_REL   0x02U
#define CO_OD_LIM_LO_GIVEN 0x04U
#define CO_OD_LIM_HI_GIVEN 0x08U

/* Size of the C storage type of a fixed-size data type (0 for variable-size types). */
size_t co_od_csize(uint8_t dtype);

/* Value memory of a sub-index inside the given RAM block or the ROM block. */
const uint8_t *co_od_mem(const struct co_od_def *def, const uint8_t *ram,
			 const struct co_od_sub *desc);

/* Current length in bytes of a dictionary value in memory. */
uint32_t co_od_mem_length(const struct co_od_sub *desc, const uint8_t *mem);

/* Copy up to cap wire bytes of a dictionary value starting at offset; returns the count. */
size_t co_od_mem_read(const struct co_od_sub *desc, const uint8_t *mem, uint32_t offset,
		      uint8_t *buf, size_t cap);

/* Encode a fixed-size value from its C storage into 8 wire bytes. */
void co_od_encode_fixed(uint8_t dtype, const void *mem, uint8_t out[8]);

/* The $NODEID table entry of a sub-index position, or NULL. */
const struct co_od_nodeid *co_od_nodeid_of(const struct co_od_def *def, uint32_t pos);

/* The entry of an index (binary search), or NULL. */
const struct co_od_entry *co_od_entry_find(const struct co_od_def *def, uint16_t index);

#endif /* SAFELINE_SUBSYS_CANOPEN_OD_OD_INTERNAL_H_ */
