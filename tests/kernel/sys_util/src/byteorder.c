/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* sys/byteorder.h: loads, stores, swaps and CPU conversions, byte by byte. */

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

ZTEST_SUITE(byteorder, NULL, NULL, NULL, NULL, NULL);

static const uint8_t seq[8] = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08};

ZTEST(byteorder, test_get_le)
{
	zassert_equal(sys_get_le16(seq), 0x0201);
	zassert_equal(sys_get_le24(seq), 0x030201);
	zassert_equal(sys_get_le32(seq), 0x04030201);
	zassert_equal(sys_get_le40(seq), 0x0504030201ULL);
	zassert_equal(sys_get_le48(seq), 0x060504030201ULL);
	zassert_equal(sys_get_le64(seq), 0x0807060504030201ULL);
}

ZTEST(byteorder, test_get_be)
{
	zassert_equal(sys_get_be16(seq), 0x0102);
	zassert_equal(sys_get_be24(seq), 0x010203);
	zassert_equal(sys_get_be32(seq), 0x01020304);
	zassert_equal(sys_get_be40(seq), 0x0102030405ULL);
	zassert_equal(sys_get_be48(seq), 0x010203040506ULL);
	zassert_equal(sys_get_be64(seq), 0x0102030405060708ULL);
}

ZTEST(byteorder, test_put_le)
{
	uint8_t buf[9];

	/* Each store writes exactly its width: the canary after it survives. */
	memset(buf, 0xAA, sizeof(buf));
	sys_put_le16(0x0201, buf);
	zassert_mem_equal(buf, seq, 2);
	zassert_equal(buf[2], 0xAA);
	memset(buf, 0xAA, sizeof(buf));
	sys_put_le24(0xFF030201, buf);
	zassert_mem_equal(buf, seq, 3, "only the low 24 bits");
	zassert_equal(buf[3], 0xAA);
	sys_put_le32(0x04030201, buf);
	zassert_mem_equal(buf, seq, 4);
	memset(buf, 0xAA, sizeof(buf));
	sys_put_le40(0xFF0504030201ULL, buf);
	zassert_mem_equal(buf, seq, 5);
	zassert_equal(buf[5], 0xAA);
	sys_put_le48(0x060504030201ULL, buf);
	zassert_mem_equal(buf, seq, 6);
	memset(buf, 0xAA, sizeof(buf));
	sys_put_le64(0x0807060504030201ULL, buf);
	zassert_mem_equal(buf, seq, 8);
	zassert_equal(buf[8], 0xAA);
}

ZTEST(byteorder, test_put_be)
{
	uint8_t buf[9];

	memset(buf, 0xAA, sizeof(buf));
	sys_put_be16(0x0102, buf);
	zassert_mem_equal(buf, seq, 2);
	zassert_equal(buf[2], 0xAA);
	sys_put_be24(0x010203, buf);
	zassert_mem_equal(buf, seq, 3);
	sys_put_be32(0x01020304, buf);
	zassert_mem_equal(buf, seq, 4);
	sys_put_be40(0x0102030405ULL, buf);
	zassert_mem_equal(buf, seq, 5);
	sys_put_be48(0x010203040506ULL, buf);
	zassert_mem_equal(buf, seq, 6);
	memset(buf, 0xAA, sizeof(buf));
	sys_put_be64(0x0102030405060708ULL, buf);
	zassert_mem_equal(buf, seq, 8);
	zassert_equal(buf[8], 0xAA);
}

ZTEST(byteorder, test_unaligned)
{
	uint8_t buf[16] = {0};

	/* CAN payloads put fields at odd offsets. */
	sys_put_le32(0xDEADBEEF, &buf[3]);
	zassert_equal(sys_get_le32(&buf[3]), 0xDEADBEEF);
	sys_put_be16(0xCAFE, &buf[9]);
	zassert_equal(sys_get_be16(&buf[9]), 0xCAFE);
	zassert_equal(buf[9], 0xCA);
}

ZTEST(byteorder, test_swaps)
{
	uint8_t out[8];
	uint8_t buf[5] = {1, 2, 3, 4, 5};
	const uint8_t rev5[5] = {5, 4, 3, 2, 1};

	zassert_equal(BSWAP_16(0x1234), 0x3412);
	zassert_equal(BSWAP_24(0x123456), 0x563412);
	zassert_equal(BSWAP_32(0x12345678), 0x78563412);
	zassert_equal(BSWAP_48(0x123456789ABCULL), 0xBC9A78563412ULL);
	zassert_equal(BSWAP_64(0x0102030405060708ULL), 0x0807060504030201ULL);

	sys_memcpy_swap(out, seq, 8);
	zassert_equal(sys_get_le64(out), sys_get_be64(seq));
	sys_mem_swap(buf, sizeof(buf));
	zassert_mem_equal(buf, rev5, sizeof(rev5));
}

ZTEST(byteorder, test_cpu_conversions)
{
	uint16_t v16 = sys_cpu_to_le16(0x0201);
	uint32_t v32 = sys_cpu_to_be32(0x01020304);
	uint64_t v64 = sys_cpu_to_le64(0x0807060504030201ULL);

	/* In memory the values have the requested byte order, whatever the CPU's. */
	zassert_mem_equal(&v16, seq, 2);
	zassert_mem_equal(&v32, seq, 4);
	zassert_mem_equal(&v64, seq, 8);
	zassert_equal(sys_le16_to_cpu(v16), 0x0201);
	zassert_equal(sys_be32_to_cpu(v32), 0x01020304);
	zassert_equal(sys_be16_to_cpu(sys_cpu_to_be16(0xABCD)), 0xABCD);
}
