/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Helpers shared by the object dictionary sources. Each file keeps one concern and uses only
 * those below it: od.c (data types, values, instance) <- od_find.c (lookup) <- od_hooks.c
 * (hooks) <- od_access.c (whole values) <- od_xfer.c (chunked writes); od_eds.c reads the
 * descriptors.
 */

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

/*
 * The provider of an object, NULL for a dictionary object. Without
 * CONFIG_CANOPEN_OD_PROVIDERS no object has one, and the constant lets the compiler drop the
 * accessors' provider branches.
 */
#define INFO_PROV(info) (CO_OD_PROVIDERS ? (info)->prov : NULL)

#define OD_UNLIKELY(x) __builtin_expect(!!(x), 0)

/* od.c: values in their C storage. */
uint64_t co_od_load_native(const void *mem, size_t csize);
uint64_t co_od_sign_extend(uint64_t v, uint32_t bytes);
void co_od_decode_fixed(uint8_t dtype, const uint8_t *in, void *mem);
bool co_od_has_storage(const struct co_od_sub *desc);
void co_od_mem_commit(const struct co_od_sub *desc, uint8_t *mem, const uint8_t *data, size_t len);
/* The node-ID in $NODEID formulas: 1..127, else 0. */
uint32_t co_od_nid(const struct co_od *od);

/* od_find.c: the provider serving an index, or NULL. */
const struct co_od_provider *co_od_provider_of(const struct co_od *od, uint16_t index);

/* od_hooks.c: the hook passes of one object, in registration order. */
uint32_t co_od_run_validate(struct co_od *od, const struct co_od_req *req);
void co_od_run_notify(struct co_od *od, const struct co_od_req *req);
uint32_t co_od_run_read_check(const struct co_od *od, const struct co_od_info *info,
			      enum co_od_writer reader);
/* Which kinds of hook the object has (CO_OD_HAS_*). */
#define CO_OD_HAS_VALIDATE   0x1U
#define CO_OD_HAS_NOTIFY     0x2U
#define CO_OD_HAS_READ_CHECK 0x4U
unsigned int co_od_hooks_has(const struct co_od *od, const struct co_od_info *info);

/* od_access.c: the checks of a write, and its end once the whole value is known. */
uint32_t co_od_check_access(const struct co_od_info *info, enum co_od_writer writer);
uint32_t co_od_check_size(const struct co_od_info *info, size_t len);
uint32_t co_od_finish_write(struct co_od *od, const struct co_od_info *info, const uint8_t *data,
			    size_t len, enum co_od_writer writer);

#endif /* SAFELINE_SUBSYS_CANOPEN_OD_OD_INTERNAL_H_ */
