/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Random numbers, as Zephyr's random/random.h.
 *
 * On native_posix the generator is deterministic, seeded by the --seed command-line option,
 * and not cryptographically secure.
 */

#ifndef ZEPHYR_INCLUDE_RANDOM_RANDOM_H_
#define ZEPHYR_INCLUDE_RANDOM_RANDOM_H_

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @brief A 32-bit random number. */
uint32_t sys_rand32_get(void);

/** @brief Fill @p dst with @p len random bytes. */
void sys_rand_get(void *dst, size_t len);

/**
 * @brief Fill @p dst with @p len cryptographically secure random bytes.
 *
 * @retval 0 Success.
 */
int sys_csrand_get(void *dst, size_t len);

/** @brief An 8-bit random number. */
static inline uint8_t sys_rand8_get(void)
{
	uint8_t ret;

	sys_rand_get(&ret, sizeof(ret));

	return ret;
}

/** @brief A 16-bit random number. */
static inline uint16_t sys_rand16_get(void)
{
	uint16_t ret;

	sys_rand_get(&ret, sizeof(ret));

	return ret;
}

/** @brief A 64-bit random number. */
static inline uint64_t sys_rand64_get(void)
{
	uint64_t ret;

	sys_rand_get(&ret, sizeof(ret));

	return ret;
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_RANDOM_RANDOM_H_ */
