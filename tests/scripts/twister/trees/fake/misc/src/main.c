#include <zephyr/ztest.h>

ZTEST_SUITE(misc, NULL, NULL, NULL, NULL, NULL);

ZTEST(misc, test_one)
{
}
