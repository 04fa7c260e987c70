/* Scanned only: the fake toolchain runs image.py instead. */
#include <zephyr/ztest.h>

ZTEST_SUITE(demo, NULL, NULL, NULL, NULL, NULL);

ZTEST(demo, test_adds)
{
}

ZTEST(demo, test_skips)
{
	ztest_test_skip();
}

/* ZTEST(demo, test_commented_out) */
