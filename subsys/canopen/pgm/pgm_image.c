/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* The program image format of pgm.h: CRC-32 and the 32-byte header. */

#include <errno.h>
#include <string.h>

#include <canopen/pgm.h>

/* Reflected IEEE polynomial, four bits at a time: a 64-byte table instead of 1 kB. */
static const uint32_t crc_nibble[16] = {
	0x00000000U, 0x1DB71064U, 0x3B6E20C8U, 0x26D930ACU, 0x76DC4190U, 0x6B6B51F4U,
	0x4DB26158U, 0x5005713CU, 0xEDB88320U, 0xF00F9344U, 0xD6D6A3E8U, 0xCB61B38CU,
	0x9B64C2B0U, 0x86D3D2D4U, 0xA00AE278U, 0xBDBDF21CU,
};

uint32_t co_pgm_crc32(uint32_t crc, const void *data, size_t len)
{
	const uint8_t *p = data;

	crc = ~crc;
	for (size_t i = 0; i < len; i++) {
		crc ^= p[i];
		crc = (crc >> 4) ^ crc_nibble[crc & 0xfU];
		crc = (crc >> 4) ^ crc_nibble[crc & 0xfU];
	}
	return ~crc;
}

static void put_u32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
	p[2] = (uint8_t)(v >> 16);
	p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32(const uint8_t *p)
{
	return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
	       ((uint32_t)p[3] << 24);
}

void co_pgm_image_header(uint8_t hdr[CO_PGM_HDR_SIZE], const void *body, uint32_t len,
			 uint32_t date, uint32_t time)
{
	(void)memset(hdr, 0, CO_PGM_HDR_SIZE);
	put_u32(&hdr[0], CO_PGM_MAGIC);
	hdr[4] = (uint8_t)CO_PGM_HDR_VERSION;
	hdr[6] = (uint8_t)CO_PGM_HDR_SIZE;
	put_u32(&hdr[8], len);
	put_u32(&hdr[12], co_pgm_crc32(0U, body, len));
	put_u32(&hdr[16], date);
	put_u32(&hdr[20], time);
	put_u32(&hdr[28], co_pgm_crc32(0U, hdr, 28));
}

int co_pgm_image_parse(const uint8_t hdr[CO_PGM_HDR_SIZE], struct co_pgm_image_info *info)
{
	if (get_u32(&hdr[0]) != CO_PGM_MAGIC || hdr[4] != CO_PGM_HDR_VERSION || hdr[5] != 0U ||
	    hdr[6] != CO_PGM_HDR_SIZE || hdr[7] != 0U) {
		return -ENOTSUP;
	}
	if (get_u32(&hdr[28]) != co_pgm_crc32(0U, hdr, 28)) {
		return -EBADMSG;
	}
	info->length = get_u32(&hdr[8]);
	info->crc = get_u32(&hdr[12]);
	info->date = get_u32(&hdr[16]);
	info->time = get_u32(&hdr[20]);
	return 0;
}
