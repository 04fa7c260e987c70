#include <zephyr/ztest.h>

ZTEST_SUITE(crash, NULL, NULL, NULL, NULL, NULL);

ZTEST(crash, test_oops)
{
	k_oops();
}

ZTEST(crash, test_after)
{
}
