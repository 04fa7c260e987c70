/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Byte order: swaps, CPU/bus conversions and unaligned loads and stores of little- and
 *        big-endian fields, as Zephyr's sys/byteorder.h.
 */

#ifndef ZEPHYR_INCLUDE_SYS_BYTEORDER_H_
#define ZEPHYR_INCLUDE_SYS_BYTEORDER_H_

#include <stddef.h>
#include <stdint.h>

#include <zephyr/sys/__assert.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @name Byte swaps of constant-width values */
/** @{ */
#define BSWAP_16(x) ((uint16_t)((((x) >> 8) & 0xffU) | (((x) & 0xffU) << 8)))
#define BSWAP_24(x) ((uint32_t)((((x) >> 16) & 0xffU) | ((x) & 0xff00U) | (((x) & 0xffU) << 16)))
#define BSWAP_32(x)                                                                                \
	((uint32_t)((((x) >> 24) & 0xffU) | (((x) >> 8) & 0xff00U) | (((x) & 0xff00U) << 8) |      \
		    (((x) & 0xffU) << 24)))
#define BSWAP_40(x)                                                                                \
	((uint64_t)((((x) >> 32) & 0xffULL) | (((x) >> 16) & 0xff00ULL) | ((x) & 0xff0000ULL) |    \
		    (((x) & 0xff00ULL) << 16) | (((x) & 0xffULL) << 32)))
#define BSWAP_48(x)                                                                                \
	((uint64_t)((((x) >> 40) & 0xffULL) | (((x) >> 24) & 0xff00ULL) |                          \
		    (((x) >> 8) & 0xff0000ULL) | (((x) & 0xff0000ULL) << 8) |                      \
		    (((x) & 0xff00ULL) << 24) | (((x) & 0xffULL) << 40)))
#define BSWAP_64(x)                                                                                \
	((uint64_t)((((x) >> 56) & 0xffULL) | (((x) >> 40) & 0xff00ULL) |                          \
		    (((x) >> 24) & 0xff0000ULL) | (((x) >> 8) & 0xff000000ULL) |                   \
		    (((x) & 0xff000000ULL) << 8) | (((x) & 0xff0000ULL) << 24) |                   \
		    (((x) & 0xff00ULL) << 40) | (((x) & 0xffULL) << 56)))
/** @} */

/** @name Conversions between CPU order and bus order */
/** @{ */
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define sys_le16_to_cpu(val) (val)
#define sys_cpu_to_le16(val) (val)
#define sys_le24_to_cpu(val) (val)
#define sys_cpu_to_le24(val) (val)
#define sys_le32_to_cpu(val) (val)
#define sys_cpu_to_le32(val) (val)
#define sys_le40_to_cpu(val) (val)
#define sys_cpu_to_le40(val) (val)
#define sys_le48_to_cpu(val) (val)
#define sys_cpu_to_le48(val) (val)
#define sys_le64_to_cpu(val) (val)
#define sys_cpu_to_le64(val) (val)
#define sys_be16_to_cpu(val) BSWAP_16(val)
#define sys_cpu_to_be16(val) BSWAP_16(val)
#define sys_be24_to_cpu(val) BSWAP_24(val)
#define sys_cpu_to_be24(val) BSWAP_24(val)
#define sys_be32_to_cpu(val) BSWAP_32(val)
#define sys_cpu_to_be32(val) BSWAP_32(val)
#define sys_be40_to_cpu(val) BSWAP_40(val)
#define sys_cpu_to_be40(val) BSWAP_40(val)
#define sys_be48_to_cpu(val) BSWAP_48(val)
#define sys_cpu_to_be48(val) BSWAP_48(val)
#define sys_be64_to_cpu(val) BSWAP_64(val)
#define sys_cpu_to_be64(val) BSWAP_64(val)
#elif __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
#define sys_le16_to_cpu(val) BSWAP_16(val)
#define sys_cpu_to_le16(val) BSWAP_16(val)
#define sys_le24_to_cpu(val) BSWAP_24(val)
#define sys_cpu_to_le24(val) BSWAP_24(val)
#define sys_le32_to_cpu(val) BSWAP_32(val)
#define sys_cpu_to_le32(val) BSWAP_32(val)
#define sys_le40_to_cpu(val) BSWAP_40(val)
#define sys_cpu_to_le40(val) BSWAP_40(val)
#define sys_le48_to_cpu(val) BSWAP_48(val)
#define sys_cpu_to_le48(val) BSWAP_48(val)
#define sys_le64_to_cpu(val) BSWAP_64(val)
#define sys_cpu_to_le64(val) BSWAP_64(val)
#define sys_be16_to_cpu(val) (val)
#define sys_cpu_to_be16(val) (val)
#define sys_be24_to_cpu(val) (val)
#define sys_cpu_to_be24(val) (val)
#define sys_be32_to_cpu(val) (val)
#define sys_cpu_to_be32(val) (val)
#define sys_be40_to_cpu(val) (val)
#define sys_cpu_to_be40(val) (val)
#define sys_be48_to_cpu(val) (val)
#define sys_cpu_to_be48(val) (val)
#define sys_be64_to_cpu(val) (val)
#define sys_cpu_to_be64(val) (val)
#else
#error "Unknown byte order"
#endif
/** @} */

/*
 * Loads and stores go byte by byte: the fields of a CAN frame are unaligned and the result does
 * not depend on the CPU's byte order.
 */

/** Store @p val big-endian into @p dst (2 bytes, any alignment). */
static inline void sys_put_be16(uint16_t val, uint8_t dst[2])
{
	dst[0] = (uint8_t)(val >> 8);
	dst[1] = (uint8_t)val;
}

/** Store the low 24 bits of @p val big-endian into @p dst (3 bytes). */
static inline void sys_put_be24(uint32_t val, uint8_t dst[3])
{
	dst[0] = (uint8_t)(val >> 16);
	sys_put_be16((uint16_t)val, &dst[1]);
}

/** Store @p val big-endian into @p dst (4 bytes). */
static inline void sys_put_be32(uint32_t val, uint8_t dst[4])
{
	sys_put_be16((uint16_t)(val >> 16), dst);
	sys_put_be16((uint16_t)val, &dst[2]);
}

/** Store the low 40 bits of @p val big-endian into @p dst (5 bytes). */
static inline void sys_put_be40(uint64_t val, uint8_t dst[5])
{
	dst[0] = (uint8_t)(val >> 32);
	sys_put_be32((uint32_t)val, &dst[1]);
}

/** Store the low 48 bits of @p val big-endian into @p dst (6 bytes). */
static inline void sys_put_be48(uint64_t val, uint8_t dst[6])
{
	sys_put_be16((uint16_t)(val >> 32), dst);
	sys_put_be32((uint32_t)val, &dst[2]);
}

/** Store @p val big-endian into @p dst (8 bytes). */
static inline void sys_put_be64(uint64_t val, uint8_t dst[8])
{
	sys_put_be32((uint32_t)(val >> 32), dst);
	sys_put_be32((uint32_t)val, &dst[4]);
}

/** Store @p val little-endian into @p dst (2 bytes, any alignment). */
static inline void sys_put_le16(uint16_t val, uint8_t dst[2])
{
	dst[0] = (uint8_t)val;
	dst[1] = (uint8_t)(val >> 8);
}

/** Store the low 24 bits of @p val little-endian into @p dst (3 bytes). */
static inline void sys_put_le24(uint32_t val, uint8_t dst[3])
{
	sys_put_le16((uint16_t)val, dst);
	dst[2] = (uint8_t)(val >> 16);
}

/** Store @p val little-endian into @p dst (4 bytes). */
static inline void sys_put_le32(uint32_t val, uint8_t dst[4])
{
	sys_put_le16((uint16_t)val, dst);
	sys_put_le16((uint16_t)(val >> 16), &dst[2]);
}

/** Store the low 40 bits of @p val little-endian into @p dst (5 bytes). */
static inline void sys_put_le40(uint64_t val, uint8_t dst[5])
{
	sys_put_le32((uint32_t)val, dst);
	dst[4] = (uint8_t)(val >> 32);
}

/** Store the low 48 bits of @p val little-endian into @p dst (6 bytes). */
static inline void sys_put_le48(uint64_t val, uint8_t dst[6])
{
	sys_put_le32((uint32_t)val, dst);
	sys_put_le16((uint16_t)(val >> 32), &dst[4]);
}

/** Store @p val little-endian into @p dst (8 bytes). */
static inline void sys_put_le64(uint64_t val, uint8_t dst[8])
{
	sys_put_le32((uint32_t)val, dst);
	sys_put_le32((uint32_t)(val >> 32), &dst[4]);
}

/** Load a big-endian 16-bit value from @p src (any alignment). */
static inline uint16_t sys_get_be16(const uint8_t src[2])
{
	return (uint16_t)(((uint16_t)src[0] << 8) | src[1]);
}

/** Load a big-endian 24-bit value from @p src. */
static inline uint32_t sys_get_be24(const uint8_t src[3])
{
	return ((uint32_t)src[0] << 16) | sys_get_be16(&src[1]);
}

/** Load a big-endian 32-bit value from @p src. */
static inline uint32_t sys_get_be32(const uint8_t src[4])
{
	return ((uint32_t)sys_get_be16(&src[0]) << 16) | sys_get_be16(&src[2]);
}

/** Load a big-endian 40-bit value from @p src. */
static inline uint64_t sys_get_be40(const uint8_t src[5])
{
	return ((uint64_t)src[0] << 32) | sys_get_be32(&src[1]);
}

/** Load a big-endian 48-bit value from @p src. */
static inline uint64_t sys_get_be48(const uint8_t src[6])
{
	return ((uint64_t)sys_get_be16(&src[0]) << 32) | sys_get_be32(&src[2]);
}

/** Load a big-endian 64-bit value from @p src. */
static inline uint64_t sys_get_be64(const uint8_t src[8])
{
	return ((uint64_t)sys_get_be32(&src[0]) << 32) | sys_get_be32(&src[4]);
}

/** Load a little-endian 16-bit value from @p src (any alignment). */
static inline uint16_t sys_get_le16(const uint8_t src[2])
{
	return (uint16_t)(((uint16_t)src[1] << 8) | src[0]);
}

/** Load a little-endian 24-bit value from @p src. */
static inline uint32_t sys_get_le24(const uint8_t src[3])
{
	return ((uint32_t)src[2] << 16) | sys_get_le16(&src[0]);
}

/** Load a little-endian 32-bit value from @p src. */
static inline uint32_t sys_get_le32(const uint8_t src[4])
{
	return ((uint32_t)sys_get_le16(&src[2]) << 16) | sys_get_le16(&src[0]);
}

/** Load a little-endian 40-bit value from @p src. */
static inline uint64_t sys_get_le40(const uint8_t src[5])
{
	return ((uint64_t)src[4] << 32) | sys_get_le32(&src[0]);
}

/** Load a little-endian 48-bit value from @p src. */
static inline uint64_t sys_get_le48(const uint8_t src[6])
{
	return ((uint64_t)sys_get_le16(&src[4]) << 32) | sys_get_le32(&src[0]);
}

/** Load a little-endian 64-bit value from @p src. */
static inline uint64_t sys_get_le64(const uint8_t src[8])
{
	return ((uint64_t)sys_get_le32(&src[4]) << 32) | sys_get_le32(&src[0]);
}

/**
 * @brief Copy @p length bytes from @p src to @p dst in reverse order.
 *
 * The buffers must not overlap.
 */
static inline void sys_memcpy_swap(void *dst, const void *src, size_t length)
{
	uint8_t *pdst = (uint8_t *)dst;
	const uint8_t *psrc = (const uint8_t *)src;

	__ASSERT(((psrc < pdst && (psrc + length) <= pdst) ||
		  (psrc > pdst && (pdst + length) <= psrc)),
		 "Source and destination buffers must not overlap");

	if (length == 0U) {
		return;
	}

	psrc += length - 1;

	for (; length > 0; length--) {
		*pdst++ = *psrc--;
	}
}

/**
 * @brief Reverse the order of the @p length bytes of @p buf in place.
 */
static inline void sys_mem_swap(void *buf, size_t length)
{
	uint8_t *p = (uint8_t *)buf;

	for (size_t i = 0; i < (length / 2U); i++) {
		uint8_t tmp = p[i];

		p[i] = p[length - 1U - i];
		p[length - 1U - i] = tmp;
	}
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_BYTEORDER_H_ */
