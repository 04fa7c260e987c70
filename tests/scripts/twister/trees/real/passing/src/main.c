/*
 * SPDX-License-Identifier: Apache-2.0
 *
 * Fixture of the runner's tests: one case passes, one skips.
 */
#include <zephyr/ztest.h>

ZTEST_SUITE(twister_pass, NULL, NULL, NULL, NULL, NULL);

ZTEST(twister_pass, test_adds)
{
	zassert_equal(2 + 2, 4, "arithmetic works");
}

ZTEST(twister_pass, test_skips)
{
	ztest_test_skip();
}
