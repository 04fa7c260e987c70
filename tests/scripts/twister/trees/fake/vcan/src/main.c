#include <zephyr/ztest.h>

ZTEST_SUITE(vcan, NULL, NULL, NULL, NULL, NULL);

ZTEST(vcan, test_args)
{
}
