#include <zephyr/ztest.h>

ZTEST_SUITE(hang, NULL, NULL, NULL, NULL, NULL);

ZTEST(hang, test_first)
{
}

ZTEST(hang, test_forever)
{
	k_sleep(K_FOREVER);
}

ZTEST(hang, test_never_reached)
{
}
