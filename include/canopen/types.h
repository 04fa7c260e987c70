/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CiA 301 basic data types.
 *
 * One X-macro table (CO_DTYPE_TABLE) lists every CiA 301 static data type with its
 * data-type index, its size on the wire and its class. The enum, the size and class
 * look-ups in the object dictionary and the EDS generator (scripts/pylib/eds2od) all follow
 * it; a test checks that the generator's table matches this one.
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_TYPES_H_
#define SAFELINE_INCLUDE_CANOPEN_TYPES_H_

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Every CiA 301 static data type (CiA 301 §7.4.7, data-type indexes 0001h-001Bh).
 *
 * X(name, index, wire size in bytes (0 = variable length), class, C storage type)
 */
#define CO_DTYPE_TABLE(X)                                                                          \
	X(BOOLEAN, 0x0001, 1, BOOL, uint8_t)                                                       \
	X(INTEGER8, 0x0002, 1, INT, int8_t)                                                        \
	X(INTEGER16, 0x0003, 2, INT, int16_t)                                                      \
	X(INTEGER32, 0x0004, 4, INT, int32_t)                                                      \
	X(UNSIGNED8, 0x0005, 1, UINT, uint8_t)                                                     \
	X(UNSIGNED16, 0x0006, 2, UINT, uint16_t)                                                   \
	X(UNSIGNED32, 0x0007, 4, UINT, uint32_t)                                                   \
	X(REAL32, 0x0008, 4, REAL, float)                                                          \
	X(VISIBLE_STRING, 0x0009, 0, VSTR, char)                                                   \
	X(OCTET_STRING, 0x000A, 0, OSTR, uint8_t)                                                  \
	X(UNICODE_STRING, 0x000B, 0, USTR, uint16_t)                                               \
	X(TIME_OF_DAY, 0x000C, 6, TIME, struct co_time)                                            \
	X(TIME_DIFFERENCE, 0x000D, 6, TIME, struct co_time)                                        \
	X(DOMAIN, 0x000F, 0, DOMAIN, uint8_t)                                                      \
	X(INTEGER24, 0x0010, 3, INT, int32_t)                                                      \
	X(REAL64, 0x0011, 8, REAL, double)                                                         \
	X(INTEGER40, 0x0012, 5, INT, int64_t)                                                      \
	X(INTEGER48, 0x0013, 6, INT, int64_t)                                                      \
	X(INTEGER56, 0x0014, 7, INT, int64_t)                                                      \
	X(INTEGER64, 0x0015, 8, INT, int64_t)                                                      \
	X(UNSIGNED24, 0x0016, 3, UINT, uint32_t)                                                   \
	X(UNSIGNED40, 0x0018, 5, UINT, uint64_t)                                                   \
	X(UNSIGNED48, 0x0019, 6, UINT, uint64_t)                                                   \
	X(UNSIGNED56, 0x001A, 7, UINT, uint64_t)                                                   \
	X(UNSIGNED64, 0x001B, 8, UINT, uint64_t)

/** @brief Data-type index of a CiA 301 basic type. */
enum co_dtype {
#define CO_DTYPE_ENUM_(name, idx, size, cls, ctype) CO_DTYPE_##name = idx,
	CO_DTYPE_TABLE(CO_DTYPE_ENUM_)
#undef CO_DTYPE_ENUM_
};

/** @brief How a data type is encoded; decides conversions and checks. */
enum co_dtype_class {
	CO_DTYPE_CLASS_NONE = 0, /**< not a known type */
	CO_DTYPE_CLASS_BOOL,     /**< BOOLEAN: one byte, 0 or 1 */
	CO_DTYPE_CLASS_INT,      /**< two's complement, little endian */
	CO_DTYPE_CLASS_UINT,     /**< unsigned, little endian */
	CO_DTYPE_CLASS_REAL,     /**< IEEE 754, little endian */
	CO_DTYPE_CLASS_VSTR,     /**< VISIBLE_STRING: shorter writes allowed, NUL padded */
	CO_DTYPE_CLASS_OSTR,     /**< OCTET_STRING: fixed length */
	CO_DTYPE_CLASS_USTR,     /**< UNICODE_STRING: 16-bit units, shorter writes allowed */
	CO_DTYPE_CLASS_TIME,     /**< TIME_OF_DAY / TIME_DIFFERENCE: 28-bit ms + U16 days */
	CO_DTYPE_CLASS_DOMAIN,   /**< DOMAIN: any length up to the object's capacity */
};

/**
 * @brief TIME_OF_DAY and TIME_DIFFERENCE as the application sees them.
 *
 * On the wire: 6 bytes, bits 0..27 milliseconds after midnight, bits 28..31 reserved
 * (kept as written), then UNSIGNED16 days since 1984-01-01 (CiA 301 §7.1.6.5).
 */
struct co_time {
	uint32_t ms;   /**< milliseconds; bits 28..31 are the reserved bits */
	uint16_t days; /**< days since 1 January 1984 */
};

/**
 * @brief DOMAIN value held in RAM: the used length and the bytes.
 *
 * The generator declares one per RAM-backed DOMAIN with the capacity given in the EDS.
 */
#define CO_DOMAIN_STRUCT(cap)                                                                      \
	struct {                                                                                   \
		uint32_t len;                                                                      \
		uint8_t data[cap];                                                                 \
	}

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_TYPES_H_ */
