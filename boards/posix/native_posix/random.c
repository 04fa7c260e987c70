/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Zephyr's random API on native_posix: a deterministic generator seeded by --seed
 * (splitmix64), so that a run can be repeated. Not cryptographically secure, like Zephyr's
 * native entropy driver; sys_csrand_get() says so by being the same generator.
 */

#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include <zephyr/random/random.h>

#include "posix_board_if.h"
#include "posix_native_task.h"

static atomic_uint_fast64_t state;

/* After the command line is parsed, before any thread exists. */
static void seed_random(void)
{
	atomic_store(&state, native_get_seed());
}
NATIVE_TASK(seed_random, PRE_BOOT_2, 0);

static uint64_t next(void)
{
	uint64_t z = atomic_fetch_add(&state, 0x9e3779b97f4a7c15ULL) + 0x9e3779b97f4a7c15ULL;

	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;

	return z ^ (z >> 31);
}

uint32_t sys_rand32_get(void)
{
	return (uint32_t)(next() >> 32);
}

void sys_rand_get(void *dst, size_t len)
{
	uint8_t *p = dst;

	while (len > 0U) {
		uint64_t r = next();
		size_t n = (len < sizeof(r)) ? len : sizeof(r);

		(void)memcpy(p, &r, n);
		p += n;
		len -= n;
	}
}

int sys_csrand_get(void *dst, size_t len)
{
	sys_rand_get(dst, len);

	return 0;
}
