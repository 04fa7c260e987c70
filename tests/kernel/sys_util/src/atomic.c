/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* sys/atomic.h: every operation returns the previous value; bitmaps span several words. */

#include <zephyr/sys/atomic.h>
#include <zephyr/ztest.h>

ZTEST_SUITE(atomic, NULL, NULL, NULL, NULL, NULL);

ZTEST(atomic, test_arithmetic)
{
	atomic_t v = ATOMIC_INIT(5);

	zassert_equal(atomic_get(&v), 5);
	zassert_equal(atomic_inc(&v), 5, "returns the old value");
	zassert_equal(atomic_dec(&v), 6);
	zassert_equal(atomic_add(&v, 10), 5);
	zassert_equal(atomic_sub(&v, 3), 15);
	zassert_equal(atomic_set(&v, 0xF0), 12);
	zassert_equal(atomic_or(&v, 0x0F), 0xF0);
	zassert_equal(atomic_and(&v, 0x3C), 0xFF);
	zassert_equal(atomic_xor(&v, 0xFF), 0x3C);
	zassert_equal(atomic_nand(&v, 0xFF), 0xC3);
	zassert_equal(atomic_get(&v), ~0xC3L);
	zassert_equal(atomic_clear(&v), ~0xC3L);
	zassert_equal(atomic_get(&v), 0);

	zassert_false(atomic_cas(&v, 1, 2), "no swap when the value differs");
	zassert_true(atomic_cas(&v, 0, 2));
	zassert_equal(atomic_get(&v), 2);
}

ZTEST(atomic, test_pointers)
{
	int a;
	int b;
	atomic_ptr_t p = ATOMIC_PTR_INIT(NULL);

	zassert_is_null(atomic_ptr_set(&p, &a));
	zassert_false(atomic_ptr_cas(&p, &b, NULL));
	zassert_true(atomic_ptr_cas(&p, &a, &b));
	zassert_equal_ptr(atomic_ptr_get(&p), &b);
	zassert_equal_ptr(atomic_ptr_clear(&p), &b);
	zassert_is_null(atomic_ptr_get(&p));
}

ZTEST(atomic, test_bitmap)
{
	ATOMIC_DEFINE(bits, 100);

	zassert_equal(ARRAY_SIZE(bits), DIV_ROUND_UP(100, ATOMIC_BITS));
	memset(bits, 0, sizeof(bits));
	atomic_set_bit(bits, 3);
	atomic_set_bit(bits, 70);
	zassert_true(atomic_test_bit(bits, 3));
	zassert_true(atomic_test_bit(bits, 70));
	zassert_false(atomic_test_bit(bits, 69));
	zassert_true(atomic_test_and_clear_bit(bits, 70));
	zassert_false(atomic_test_and_clear_bit(bits, 70));
	zassert_false(atomic_test_and_set_bit(bits, 99));
	zassert_true(atomic_test_and_set_bit(bits, 99));
	atomic_set_bit_to(bits, 3, false);
	zassert_false(atomic_test_bit(bits, 3));
	atomic_clear_bit(bits, 99);
	for (int i = 0; i < 100; i++) {
		zassert_false(atomic_test_bit(bits, i), "bit %d", i);
	}
}

#define COUNTING_THREADS 4
#define INCREMENTS       10000

static K_THREAD_STACK_ARRAY_DEFINE(stacks, COUNTING_THREADS, 2048);
static struct k_thread threads[COUNTING_THREADS];
static atomic_t shared;

static void inc_entry(void *p1, void *p2, void *p3)
{
	for (int i = 0; i < INCREMENTS; i++) {
		atomic_inc(&shared);
	}
}

ZTEST(atomic, test_concurrent_increments)
{
	atomic_clear(&shared);
	for (int i = 0; i < COUNTING_THREADS; i++) {
		k_thread_create(&threads[i], stacks[i], 2048, inc_entry, NULL, NULL, NULL, 5, 0,
				K_NO_WAIT);
	}
	for (int i = 0; i < COUNTING_THREADS; i++) {
		zassert_ok(k_thread_join(&threads[i], K_SECONDS(30)));
	}
	zassert_equal(atomic_get(&shared), COUNTING_THREADS * INCREMENTS, "lost an increment");
}
