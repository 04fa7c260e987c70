/*
 * SPDX-License-Identifier: Apache-2.0
 *
 * Fixture of the runner's tests: one case fails on purpose.
 */
#include <zephyr/ztest.h>

ZTEST_SUITE(twister_fail, NULL, NULL, NULL, NULL, NULL);

ZTEST(twister_fail, test_good)
{
	zassert_true(true);
}

ZTEST(twister_fail, test_bad)
{
	int sum = 1 + 1;

	zassert_equal(sum, 3, "deliberately wrong");
}
