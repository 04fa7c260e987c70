#include <zephyr/ztest.h>

ZTEST_SUITE(broken, NULL, NULL, NULL, NULL, NULL);

ZTEST(broken, test_one)
{
}
