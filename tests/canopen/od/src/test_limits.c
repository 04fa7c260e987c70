/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Limit checks of REAL values (LowLimit/HighLimit, CiA 306) decide as the C comparison of the
 * values would: zeros of both signs, subnormals, infinities and NaNs included. The accessors
 * compare integer keys, not floating-point values, so every case is checked against C here.
 */

#include "common.h"

/* The abort code the C comparison gives for @p v in lo..hi. */
static uint32_t c_verdict(double v, double lo, double hi)
{
	if (v < lo) {
		return CO_SDO_AB_VALUE_LOW;
	}
	if (hi < v) {
		return CO_SDO_AB_VALUE_HIGH;
	}
	return 0U;
}

/* Edge cases first, then a pseudo-random walk over the bit patterns. */
static uint64_t next_bits(uint64_t *state)
{
	*state ^= *state << 13;
	*state ^= *state >> 7;
	*state ^= *state << 17;
	return *state;
}

static const uint32_t real32_edges[] = {
	0x00000000U, 0x80000000U, /* +0, -0 */
	0x00000001U, 0x807FFFFFU, /* subnormals */
	0x00800000U, 0x80800000U, /* smallest normals */
	0x41200000U, 0x41200001U, /* 10 and the next float above it */
	0xC1200000U, 0xC1200001U, /* -10 and the next float below it */
	0x3F800000U, 0xBF800000U, /* 1, -1 */
	0x7F7FFFFFU, 0xFF7FFFFFU, /* largest finite */
	0x7F800000U, 0xFF800000U, /* infinities */
	0x7FC00000U, 0xFFC00001U, /* NaNs */
	0x7F800001U,              /* signalling NaN */
};

ZTEST(od_limits, test_real32_limit_as_c_compares)
{
	uint64_t state = 0x9E3779B97F4A7C15ULL;

	/* 6000h:8 REAL32, LowLimit -10, HighLimit 10 */
	for (size_t i = 0; i < ARRAY_SIZE(real32_edges) + 3000U; i++) {
		uint32_t bits = i < ARRAY_SIZE(real32_edges) ? real32_edges[i]
							     : (uint32_t)next_bits(&state);
		uint8_t wire[4] = {(uint8_t)bits, (uint8_t)(bits >> 8), (uint8_t)(bits >> 16),
				   (uint8_t)(bits >> 24)};
		float f;

		memcpy(&f, &bits, sizeof(f));
		zassert_equal(wr(&fx.od, 0x6000, 8, wire, sizeof(wire), CO_OD_WRITER_SDO),
			      c_verdict((double)f, -10.0, 10.0), "REAL32 %08x", bits);
	}
}

ZTEST(od_limits, test_real64_limit_as_c_compares)
{
	static const double bounds[][2] = {
		{-1.5, 2.5}, {0.0, 1e300}, {-0.0, 0.0}, {-1e-310, 1e-310}};
	static const uint64_t edges[] = {
		0x0000000000000000ULL, 0x8000000000000000ULL, 0x0000000000000001ULL,
		0x800FFFFFFFFFFFFFULL, 0x3FF8000000000000ULL, 0xBFF8000000000000ULL,
		0x4004000000000000ULL, 0x4004000000000001ULL, 0x7FEFFFFFFFFFFFFFULL,
		0x7FF0000000000000ULL, 0xFFF0000000000000ULL, 0x7FF8000000000000ULL,
		0xFFF0000000000001ULL,
	};
	uint64_t state = 0x2545F4914F6CDD1DULL;
	struct co_od_info info;

	/* 6000h:10 REAL64 has no limits in the EDS: give its descriptor some. */
	zassert_ok(co_od_find(&fx.od, 0x6000, 0x10, &info));
	for (size_t b = 0; b < ARRAY_SIZE(bounds); b++) {
		struct co_od_limit lim = {.lo = {.f = bounds[b][0]}, .hi = {.f = bounds[b][1]}};

		info.limit = &lim;
		for (size_t i = 0; i < ARRAY_SIZE(edges) + 1000U; i++) {
			uint64_t bits = i < ARRAY_SIZE(edges) ? edges[i] : next_bits(&state);
			uint8_t wire[8];
			double d;

			for (int k = 0; k < 8; k++) {
				wire[k] = (uint8_t)(bits >> (8 * k));
			}
			memcpy(&d, &bits, sizeof(d));
			zassert_equal(co_od_write_info(&fx.od, &info, wire, sizeof(wire),
						       CO_OD_WRITER_SDO),
				      c_verdict(d, bounds[b][0], bounds[b][1]),
				      "REAL64 %016llx in [%g, %g]", (unsigned long long)bits,
				      bounds[b][0], bounds[b][1]);
		}
	}
}

ZTEST(od_limits, test_signed_and_unsigned_extremes)
{
	/* 6000h:2 INTEGER8 -120..120, 1017h UNSIGNED16 0..60000 */
	int8_t i8 = INT8_MIN;
	uint8_t u16[2] = {0xFF, 0xFF};

	zassert_equal(wr(&fx.od, 0x6000, 2, &i8, 1, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_LOW);
	i8 = INT8_MAX;
	zassert_equal(wr(&fx.od, 0x6000, 2, &i8, 1, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_HIGH);
	i8 = -1;
	zassert_ok(wr(&fx.od, 0x6000, 2, &i8, 1, CO_OD_WRITER_SDO));
	zassert_equal(wr(&fx.od, 0x1017, 0, u16, 2, CO_OD_WRITER_SDO), CO_SDO_AB_VALUE_HIGH);
}

ZTEST_SUITE(od_limits, NULL, NULL, fx_before, NULL, NULL);
