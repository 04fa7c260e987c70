/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Conversions between milliseconds, microseconds, nanoseconds, ticks and hardware
 *        cycles, as Zephyr's sys/time_units.h.
 *
 * Every conversion exists as k_<from>_to_<to>_<rounding><width>():
 * - from/to: ms, us, ns, cyc, ticks (the combinations Zephyr provides: ms/us/ns to and from cyc
 *   and ticks, and cyc <-> ticks);
 * - rounding: floor (toward zero), near (to nearest), ceil (away from zero);
 * - width: 32 (uint32_t in and out, the result truncated) or 64 (uint64_t).
 *
 * Example: k_ms_to_ticks_ceil32(10) is the smallest tick count lasting at least 10 ms.
 */

#ifndef ZEPHYR_INCLUDE_SYS_TIME_UNITS_H_
#define ZEPHYR_INCLUDE_SYS_TIME_UNITS_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Rate of the hardware cycle counter (k_cycle_get_32()) in Hz. */
static inline int sys_clock_hw_cycles_per_sec(void)
{
	return CONFIG_SYS_CLOCK_HW_CYCLES_PER_SEC;
}

/*
 * The one conversion all others use: t * to_hz / from_hz with the requested rounding. Exact
 * ratios use a single multiply or divide; the general case splits t so that it cannot overflow
 * for any t that fits the result.
 */
static ALWAYS_INLINE uint64_t z_tmcvt(uint64_t t, uint32_t from_hz, uint32_t to_hz, bool round_up,
				      bool round_off)
{
	uint64_t off = 0;

	if (from_hz == to_hz) {
		return t;
	}
	if (to_hz > from_hz && (to_hz % from_hz) == 0U) {
		return t * (to_hz / from_hz);
	}
	if (from_hz > to_hz && (from_hz % to_hz) == 0U) {
		uint64_t div = from_hz / to_hz;

		if (round_up) {
			off = div - 1U;
		} else if (round_off) {
			off = div / 2U;
		}
		return t / div + ((t % div) + off) / div;
	}
	if (round_up) {
		off = from_hz - 1U;
	} else if (round_off) {
		off = from_hz / 2U;
	}

	return (t / from_hz) * to_hz + ((t % from_hz) * to_hz + off) / from_hz;
}

/* Defines the six conversions (floor/near/ceil x 32/64) from one unit to another. */
#define Z_TMCVT_DEFINE(from, to, from_hz, to_hz)                                                   \
	static ALWAYS_INLINE uint32_t k_##from##_to_##to##_floor32(uint32_t t)                     \
	{                                                                                          \
		return (uint32_t)z_tmcvt(t, (from_hz), (to_hz), false, false);                     \
	}                                                                                          \
	static ALWAYS_INLINE uint64_t k_##from##_to_##to##_floor64(uint64_t t)                     \
	{                                                                                          \
		return z_tmcvt(t, (from_hz), (to_hz), false, false);                               \
	}                                                                                          \
	static ALWAYS_INLINE uint32_t k_##from##_to_##to##_near32(uint32_t t)                      \
	{                                                                                          \
		return (uint32_t)z_tmcvt(t, (from_hz), (to_hz), false, true);                      \
	}                                                                                          \
	static ALWAYS_INLINE uint64_t k_##from##_to_##to##_near64(uint64_t t)                      \
	{                                                                                          \
		return z_tmcvt(t, (from_hz), (to_hz), false, true);                                \
	}                                                                                          \
	static ALWAYS_INLINE uint32_t k_##from##_to_##to##_ceil32(uint32_t t)                      \
	{                                                                                          \
		return (uint32_t)z_tmcvt(t, (from_hz), (to_hz), true, false);                      \
	}                                                                                          \
	static ALWAYS_INLINE uint64_t k_##from##_to_##to##_ceil64(uint64_t t)                      \
	{                                                                                          \
		return z_tmcvt(t, (from_hz), (to_hz), true, false);                                \
	}

#define Z_HZ_ms    1000U
#define Z_HZ_us    1000000U
#define Z_HZ_ns    1000000000U
#define Z_HZ_cyc   ((uint32_t)CONFIG_SYS_CLOCK_HW_CYCLES_PER_SEC)
#define Z_HZ_ticks ((uint32_t)CONFIG_SYS_CLOCK_TICKS_PER_SEC)

/* clang-format off */
Z_TMCVT_DEFINE(ms, cyc, Z_HZ_ms, Z_HZ_cyc)
Z_TMCVT_DEFINE(ms, ticks, Z_HZ_ms, Z_HZ_ticks)
Z_TMCVT_DEFINE(us, cyc, Z_HZ_us, Z_HZ_cyc)
Z_TMCVT_DEFINE(us, ticks, Z_HZ_us, Z_HZ_ticks)
Z_TMCVT_DEFINE(ns, cyc, Z_HZ_ns, Z_HZ_cyc)
Z_TMCVT_DEFINE(ns, ticks, Z_HZ_ns, Z_HZ_ticks)
Z_TMCVT_DEFINE(cyc, ms, Z_HZ_cyc, Z_HZ_ms)
Z_TMCVT_DEFINE(cyc, us, Z_HZ_cyc, Z_HZ_us)
Z_TMCVT_DEFINE(cyc, ns, Z_HZ_cyc, Z_HZ_ns)
Z_TMCVT_DEFINE(cyc, ticks, Z_HZ_cyc, Z_HZ_ticks)
Z_TMCVT_DEFINE(ticks, ms, Z_HZ_ticks, Z_HZ_ms)
Z_TMCVT_DEFINE(ticks, us, Z_HZ_ticks, Z_HZ_us)
Z_TMCVT_DEFINE(ticks, ns, Z_HZ_ticks, Z_HZ_ns)
Z_TMCVT_DEFINE(ticks, cyc, Z_HZ_ticks, Z_HZ_cyc)
/* clang-format on */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_TIME_UNITS_H_ */
