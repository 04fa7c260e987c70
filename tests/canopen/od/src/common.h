/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#ifndef TEST_CANOPEN_OD_COMMON_H_
#define TEST_CANOPEN_OD_COMMON_H_

#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/od.h>

#include "od_test_od.h"

/* Two nodes in one process, each with its own values. */
struct od_fixture {
	struct co_od od;
	struct od_test_od_ram ram;
	struct co_od od2;
	struct od_test_od_ram ram2;
};

extern struct od_fixture fx;

/* Fresh instances: node 5 and node 6. */
static inline void od_fixture_reset(void)
{
	memset(&fx, 0, sizeof(fx));
	zassert_ok(co_od_init(&fx.od, &od_test_od_def, &fx.ram, 5));
	zassert_ok(co_od_init(&fx.od2, &od_test_od_def, &fx.ram2, 6));
}

/* Write wire bytes; returns the abort code. */
static inline uint32_t wr(struct co_od *od, uint16_t index, uint8_t sub, const void *data,
			  size_t len, enum co_od_writer w)
{
	return co_od_write(od, index, sub, data, len, w);
}

/* Read all wire bytes into buf; returns the length, fails the test on an abort. */
static inline size_t rd(struct co_od *od, uint16_t index, uint8_t sub, void *buf, size_t cap)
{
	size_t len = 0;

	zassert_equal(co_od_read(od, index, sub, 0, buf, cap, &len, CO_OD_WRITER_APP), 0,
		      "read %04X:%u", index, sub);
	return len;
}

static inline void fx_before(void *f)
{
	(void)f;
	od_fixture_reset();
}

#endif /* TEST_CANOPEN_OD_COMMON_H_ */
