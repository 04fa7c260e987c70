/*
 * SPDX-License-Identifier: Apache-2.0
 *
 * Fixture of the runner's tests: the second case never returns.
 */
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

ZTEST_SUITE(twister_hang, NULL, NULL, NULL, NULL, NULL);

ZTEST(twister_hang, test_first)
{
	zassert_true(true);
}

ZTEST(twister_hang, test_forever)
{
	k_sleep(K_FOREVER);
}
