/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Misc utilities (sizes, arithmetic, pointers, bit fields), as Zephyr's sys/util.h.
 */

#ifndef ZEPHYR_INCLUDE_SYS_UTIL_H_
#define ZEPHYR_INCLUDE_SYS_UTIL_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/sys/util_macro.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Number of bits in a long. */
#define BITS_PER_LONG      (__CHAR_BIT__ * __SIZEOF_LONG__)
/** Number of bits in a long long. */
#define BITS_PER_LONG_LONG (__CHAR_BIT__ * __SIZEOF_LONG_LONG__)
/** Number of bits in a byte. */
#define BITS_PER_BYTE      (__CHAR_BIT__)
/** Number of bits in a nibble. */
#define BITS_PER_NIBBLE    (__CHAR_BIT__ / 2)

/** Cast @p x, a pointer, to an unsigned integer. */
#define POINTER_TO_UINT(x) ((uintptr_t)(x))
/** Cast @p x, an unsigned integer, to a void pointer. */
#define UINT_TO_POINTER(x) ((void *)(uintptr_t)(x))
/** Cast @p x, a pointer, to a signed integer. */
#define POINTER_TO_INT(x)  ((intptr_t)(x))
/** Cast @p x, a signed integer, to a void pointer. */
#define INT_TO_POINTER(x)  ((void *)(intptr_t)(x))

/** 0 if @p cond is true-ish, else a compile error (negative array size). */
#define ZERO_OR_COMPILE_ERROR(cond) ((int)sizeof(char[1 - (2 * !(cond))]) - 1)

/** 0 if @p array is an array, a compile error if it is a pointer. */
#define IS_ARRAY(array)                                                                            \
	ZERO_OR_COMPILE_ERROR(                                                                     \
		!__builtin_types_compatible_p(__typeof__(array), __typeof__(&(array)[0])))

/** Number of elements of @p array; a compile error when given a pointer. */
#define ARRAY_SIZE(array) ((size_t)(IS_ARRAY(array) + (sizeof(array) / sizeof((array)[0]))))

/** Whether @p ptr points into @p array (an element boundary is not required). */
#define PART_OF_ARRAY(array, ptr)                                                                  \
	((ptr) && ((ptr) >= &(array)[0] && (ptr) < &(array)[ARRAY_SIZE(array)]))

/**
 * @brief The struct of type @p type that contains @p ptr as its member @p field.
 */
#define CONTAINER_OF(ptr, type, field) ((type *)(((char *)(ptr)) - offsetof(type, field)))

/** Size of member @p member of struct type @p type. */
#define SIZEOF_FIELD(type, member) sizeof((((type *)0)->member))

/** Round @p x up to a multiple of @p align. */
#define ROUND_UP(x, align)                                                                         \
	((((unsigned long)(x) + ((unsigned long)(align) - 1)) / (unsigned long)(align)) *          \
	 (unsigned long)(align))

/** Round @p x down to a multiple of @p align. */
#define ROUND_DOWN(x, align)                                                                       \
	(((unsigned long)(x) / (unsigned long)(align)) * (unsigned long)(align))

/** Round @p x up to a multiple of the word size. */
#define WB_UP(x) ROUND_UP(x, sizeof(void *))
/** Round @p x down to a multiple of the word size. */
#define WB_DN(x) ROUND_DOWN(x, sizeof(void *))

/** @p n divided by @p d, rounded up (integer arguments, @p d > 0). */
#define DIV_ROUND_UP(n, d) (((n) + (d) - 1) / (d))

/** @p n divided by @p d, rounded to the nearest integer (halves away from zero). */
#define DIV_ROUND_CLOSEST(n, d)                                                                    \
	((((n) < 0) ^ ((d) < 0)) ? ((n) - ((d) / 2)) / (d) : ((n) + ((d) / 2)) / (d))

#ifndef MAX
/** The larger of @p a and @p b; arguments may be evaluated twice. */
#define MAX(a, b) (((a) > (b)) ? (a) : (b))
#endif

#ifndef MIN
/** The smaller of @p a and @p b; arguments may be evaluated twice. */
#define MIN(a, b) (((a) < (b)) ? (a) : (b))
#endif

#ifndef CLAMP
/** @p val limited to [@p low, @p high]; arguments may be evaluated twice. */
#define CLAMP(val, low, high) (((val) <= (low)) ? (low) : MIN(val, high))
#endif

/** Whether @p val is within [@p min, @p max]. */
#define IN_RANGE(val, min, max) ((val) >= (min) && (val) <= (max))

/** Whether @p x is a power of two (0 is not). */
#define IS_POWER_OF_TWO(x) (((x) != 0U) && (((x) & ((x) - 1U)) == 0U))

/** Whether @p ptr is aligned to @p align bytes. */
#define IS_PTR_ALIGNED_BYTES(ptr, bytes) ((((uintptr_t)ptr) % bytes) == 0)

/** The lowest set bit of @p value (0 if none), used by FIELD_GET/FIELD_PREP. */
#define LSB_GET(value) ((value) & -(value))

/** Extract the field of @p value selected by the contiguous @p mask. */
#define FIELD_GET(mask, value)  (((value) & (mask)) / LSB_GET(mask))
/** Shift @p value into the field selected by the contiguous @p mask. */
#define FIELD_PREP(mask, value) (((value) * LSB_GET(mask)) & (mask))

/** Tell the compiler that @p x is intentionally unused. */
#define ARG_UNUSED(x) (void)(x)

/** Number of bytes in @p x kibibytes. */
#define KB(x) (((size_t)(x)) << 10)
/** Number of bytes in @p x mebibytes. */
#define MB(x) (KB(x) << 10)
/** Number of bytes in @p x gibibytes. */
#define GB(x) (MB(x) << 10)

/** Number of Hz in @p x kHz. */
#define KHZ(x) ((x) * 1000)
/** Number of Hz in @p x MHz. */
#define MHZ(x) (KHZ(x) * 1000)

/**
 * @brief Whether @p x is a power of two.
 */
static inline bool is_power_of_two(unsigned int x)
{
	return IS_POWER_OF_TWO(x);
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_UTIL_H_ */
