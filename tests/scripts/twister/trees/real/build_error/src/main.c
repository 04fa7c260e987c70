/*
 * SPDX-License-Identifier: Apache-2.0
 *
 * Fixture of the runner's tests: a syntax error, on purpose.
 */
#include <zephyr/ztest.h>

ZTEST_SUITE(twister_broken, NULL, NULL, NULL, NULL, NULL);

ZTEST(twister_broken, test_never_built)
{
	int missing_semicolon = 1
}
