/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Atomic operations and atomic bitmaps, as Zephyr's sys/atomic.h.
 *
 * Built on the compiler's __atomic builtins with sequentially consistent ordering, which
 * ThreadSanitizer understands. Every read-modify-write returns the previous value.
 */

#ifndef ZEPHYR_INCLUDE_SYS_ATOMIC_H_
#define ZEPHYR_INCLUDE_SYS_ATOMIC_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/sys/util.h>

#ifdef __cplusplus
extern "C" {
#endif

/** An atomic variable (the size of a long). */
typedef long atomic_t;
/** The value type of an atomic variable. */
typedef atomic_t atomic_val_t;
/** An atomic pointer. */
typedef void *atomic_ptr_t;
/** The value type of an atomic pointer. */
typedef atomic_ptr_t atomic_ptr_val_t;

/** Initializer of an atomic variable. */
#define ATOMIC_INIT(i)     (i)
/** Initializer of an atomic pointer. */
#define ATOMIC_PTR_INIT(p) (p)

/** Bits in one atomic_t. */
#define ATOMIC_BITS                   (sizeof(atomic_val_t) * 8)
/** Number of atomic_t needed for a bitmap of @p num_bits bits. */
#define ATOMIC_BITMAP_SIZE(num_bits)  (ROUND_UP(num_bits, ATOMIC_BITS) / ATOMIC_BITS)
/** Define an atomic bitmap @p name of @p num_bits bits, all clear. */
#define ATOMIC_DEFINE(name, num_bits) atomic_t name[ATOMIC_BITMAP_SIZE(num_bits)]

#define Z_ATOMIC_ORDER __ATOMIC_SEQ_CST

/**
 * @brief Compare-and-set: store @p new_value if @p *target equals @p old_value.
 *
 * @return true if the value was stored.
 */
static inline bool atomic_cas(atomic_t *target, atomic_val_t old_value, atomic_val_t new_value)
{
	return __atomic_compare_exchange_n(target, &old_value, new_value, false, Z_ATOMIC_ORDER,
					   Z_ATOMIC_ORDER);
}

/** Pointer compare-and-set; true if @p new_value was stored. */
static inline bool atomic_ptr_cas(atomic_ptr_t *target, atomic_ptr_val_t old_value,
				  atomic_ptr_val_t new_value)
{
	return __atomic_compare_exchange_n(target, &old_value, new_value, false, Z_ATOMIC_ORDER,
					   Z_ATOMIC_ORDER);
}

/** Add @p value; return the previous value. */
static inline atomic_val_t atomic_add(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_add(target, value, Z_ATOMIC_ORDER);
}

/** Subtract @p value; return the previous value. */
static inline atomic_val_t atomic_sub(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_sub(target, value, Z_ATOMIC_ORDER);
}

/** Increment; return the previous value. */
static inline atomic_val_t atomic_inc(atomic_t *target)
{
	return atomic_add(target, 1);
}

/** Decrement; return the previous value. */
static inline atomic_val_t atomic_dec(atomic_t *target)
{
	return atomic_sub(target, 1);
}

/** Read the value. */
static inline atomic_val_t atomic_get(const atomic_t *target)
{
	return __atomic_load_n(target, Z_ATOMIC_ORDER);
}

/** Read a pointer. */
static inline atomic_ptr_val_t atomic_ptr_get(const atomic_ptr_t *target)
{
	return __atomic_load_n(target, Z_ATOMIC_ORDER);
}

/** Store @p value; return the previous value. */
static inline atomic_val_t atomic_set(atomic_t *target, atomic_val_t value)
{
	return __atomic_exchange_n(target, value, Z_ATOMIC_ORDER);
}

/** Store a pointer; return the previous one. */
static inline atomic_ptr_val_t atomic_ptr_set(atomic_ptr_t *target, atomic_ptr_val_t value)
{
	return __atomic_exchange_n(target, value, Z_ATOMIC_ORDER);
}

/** Store 0; return the previous value. */
static inline atomic_val_t atomic_clear(atomic_t *target)
{
	return atomic_set(target, 0);
}

/** Store NULL; return the previous pointer. */
static inline atomic_ptr_val_t atomic_ptr_clear(atomic_ptr_t *target)
{
	return atomic_ptr_set(target, NULL);
}

/** Bitwise OR with @p value; return the previous value. */
static inline atomic_val_t atomic_or(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_or(target, value, Z_ATOMIC_ORDER);
}

/** Bitwise XOR with @p value; return the previous value. */
static inline atomic_val_t atomic_xor(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_xor(target, value, Z_ATOMIC_ORDER);
}

/** Bitwise AND with @p value; return the previous value. */
static inline atomic_val_t atomic_and(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_and(target, value, Z_ATOMIC_ORDER);
}

/** Bitwise NAND with @p value; return the previous value. */
static inline atomic_val_t atomic_nand(atomic_t *target, atomic_val_t value)
{
	return __atomic_fetch_nand(target, value, Z_ATOMIC_ORDER);
}

/** Mask of bit @p bit within its atomic_t. */
#define ATOMIC_MASK(bit)       BIT((unsigned long)(bit) & (ATOMIC_BITS - 1U))
/** The atomic_t of a bitmap that holds bit @p bit. */
#define ATOMIC_ELEM(addr, bit) ((addr) + ((bit) / ATOMIC_BITS))

/** Whether bit @p bit of the bitmap @p target is set. */
static inline bool atomic_test_bit(const atomic_t *target, int bit)
{
	atomic_val_t val = atomic_get(ATOMIC_ELEM(target, bit));

	return (1 & (val >> (bit & (ATOMIC_BITS - 1)))) != 0;
}

/** Clear bit @p bit; return whether it was set. */
static inline bool atomic_test_and_clear_bit(atomic_t *target, int bit)
{
	atomic_val_t mask = (atomic_val_t)ATOMIC_MASK(bit);

	return (atomic_and(ATOMIC_ELEM(target, bit), ~mask) & mask) != 0;
}

/** Set bit @p bit; return whether it was set. */
static inline bool atomic_test_and_set_bit(atomic_t *target, int bit)
{
	atomic_val_t mask = (atomic_val_t)ATOMIC_MASK(bit);

	return (atomic_or(ATOMIC_ELEM(target, bit), mask) & mask) != 0;
}

/** Clear bit @p bit. */
static inline void atomic_clear_bit(atomic_t *target, int bit)
{
	(void)atomic_and(ATOMIC_ELEM(target, bit), ~(atomic_val_t)ATOMIC_MASK(bit));
}

/** Set bit @p bit. */
static inline void atomic_set_bit(atomic_t *target, int bit)
{
	(void)atomic_or(ATOMIC_ELEM(target, bit), (atomic_val_t)ATOMIC_MASK(bit));
}

/** Set bit @p bit to @p val. */
static inline void atomic_set_bit_to(atomic_t *target, int bit, bool val)
{
	if (val) {
		atomic_set_bit(target, bit);
	} else {
		atomic_clear_bit(target, bit);
	}
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_ATOMIC_H_ */
