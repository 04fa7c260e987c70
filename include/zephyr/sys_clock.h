/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Kernel time: ticks, timeouts and timepoints, as Zephyr's sys_clock.h.
 *
 * A k_timeout_t is a tick count: K_NO_WAIT (0), K_FOREVER (K_TICKS_FOREVER, -1), a relative
 * duration (> 0) or an absolute uptime (encoded below -1 by Z_TICK_ABS()). Tick rate:
 * CONFIG_SYS_CLOCK_TICKS_PER_SEC. Time counts from boot on the host's CLOCK_MONOTONIC.
 */

#ifndef ZEPHYR_INCLUDE_SYS_CLOCK_H_
#define ZEPHYR_INCLUDE_SYS_CLOCK_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/sys/time_units.h>
#include <zephyr/sys/util.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Tick count, signed so that it can hold the special timeout encodings. */
typedef int64_t k_ticks_t;

/** The tick count that means "forever". */
#define K_TICKS_FOREVER ((k_ticks_t) - 1)

/**
 * @brief Kernel timeout: how long (or until when) a blocking call may wait.
 *
 * Build it with K_NO_WAIT, K_FOREVER, K_MSEC(), K_TIMEOUT_ABS_MS() and friends; compare with
 * K_TIMEOUT_EQ().
 */
typedef struct {
	k_ticks_t ticks;
} k_timeout_t;

/** Whether two timeouts are equal. */
#define K_TIMEOUT_EQ(a, b) ((a).ticks == (b).ticks)

/** @cond INTERNAL_HIDDEN */
#define Z_TIMEOUT_NO_WAIT  ((k_timeout_t){0})
#define Z_TIMEOUT_TICKS(t) ((k_timeout_t){.ticks = (t)})
#define Z_FOREVER          Z_TIMEOUT_TICKS(K_TICKS_FOREVER)
#define Z_TIMEOUT_MS(t)    Z_TIMEOUT_TICKS((k_ticks_t)k_ms_to_ticks_ceil64((uint64_t)MAX((t), 0)))
#define Z_TIMEOUT_US(t)    Z_TIMEOUT_TICKS((k_ticks_t)k_us_to_ticks_ceil64((uint64_t)MAX((t), 0)))
#define Z_TIMEOUT_NS(t)    Z_TIMEOUT_TICKS((k_ticks_t)k_ns_to_ticks_ceil64((uint64_t)MAX((t), 0)))
#define Z_TIMEOUT_CYC(t)   Z_TIMEOUT_TICKS((k_ticks_t)k_cyc_to_ticks_ceil64((uint64_t)MAX((t), 0)))

/*
 * Absolute timeouts: uptime tick t is stored as -2 - t, below K_TICKS_FOREVER. The mapping is
 * its own inverse, so Z_TICK_ABS() both encodes and decodes; a negative result means the
 * timeout is relative.
 */
#define Z_TICK_ABS(t) (K_TICKS_FOREVER - 1 - (t))

#define Z_IS_TIMEOUT_RELATIVE(timeout) (Z_TICK_ABS((timeout).ticks) < 0)
/** @endcond */

/** @name Time unit constants */
/** @{ */
#define NSEC_PER_USEC 1000U
#define NSEC_PER_MSEC 1000000U
#define USEC_PER_MSEC 1000U
#define MSEC_PER_SEC  1000U
#define SEC_PER_MIN   60U
#define MIN_PER_HOUR  60U
#define HOUR_PER_DAY  24U
#define USEC_PER_SEC  ((USEC_PER_MSEC) * (MSEC_PER_SEC))
#define NSEC_PER_SEC  ((NSEC_PER_USEC) * (USEC_PER_MSEC) * (MSEC_PER_SEC))
/** @} */

/** "Forever" for APIs that take a duration in milliseconds. */
#define SYS_FOREVER_MS (-1)
/** "Forever" for APIs that take a duration in microseconds. */
#define SYS_FOREVER_US (-1)

/** Milliseconds (SYS_FOREVER_MS for forever) as a k_timeout_t. */
#define SYS_TIMEOUT_MS(ms) ((ms) == SYS_FOREVER_MS ? Z_FOREVER : Z_TIMEOUT_MS(ms))

/**
 * @brief Ticks elapsed since boot (64 bits).
 */
int64_t sys_clock_tick_get(void);

/**
 * @brief Ticks elapsed since boot, truncated to 32 bits.
 */
uint32_t sys_clock_tick_get_32(void);

/**
 * @brief A point in time, in ticks since boot, for deadlines that outlive one call.
 *
 * UINT64_MAX stands for "never" (from K_FOREVER), 0 for "already" (from K_NO_WAIT).
 */
typedef struct {
	uint64_t tick;
} k_timepoint_t;

/**
 * @brief The timepoint at which @p timeout ends, counted from now.
 */
k_timepoint_t sys_timepoint_calc(k_timeout_t timeout);

/**
 * @brief The relative timeout remaining until @p timepoint (K_NO_WAIT once it has passed,
 *        K_FOREVER for "never").
 */
k_timeout_t sys_timepoint_timeout(k_timepoint_t timepoint);

/**
 * @brief Compare two timepoints.
 *
 * @retval 0 they are equal.
 * @retval <0 @p a is earlier than @p b.
 * @retval >0 @p a is later than @p b.
 */
static inline int sys_timepoint_cmp(k_timepoint_t a, k_timepoint_t b)
{
	if (a.tick == b.tick) {
		return 0;
	}

	return (a.tick < b.tick) ? -1 : 1;
}

/**
 * @brief Whether @p timepoint has passed.
 */
static inline bool sys_timepoint_expired(k_timepoint_t timepoint)
{
	return K_TIMEOUT_EQ(sys_timepoint_timeout(timepoint), Z_TIMEOUT_NO_WAIT);
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_CLOCK_H_ */
