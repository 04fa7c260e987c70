#include <zephyr/ztest.h>

ZTEST_SUITE(arith, NULL, NULL, NULL, NULL, NULL);

ZTEST(arith, test_good)
{
}

ZTEST(arith, test_bad)
{
	zassert_equal(1 + 1, 3, "wrong sum");
}
