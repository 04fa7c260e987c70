/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A flash in RAM with flash rules (erase to FFh, writes only clear bits) and a power cut
 * at a chosen byte, so tests can interrupt a download or a commit anywhere.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/util.h>

#include <canopen/pgm.h>

static struct co_pgm_flash_ram *ram_of(struct co_pgm_flash *f)
{
	return CONTAINER_OF(f, struct co_pgm_flash_ram, flash);
}

static uint8_t *slot_mem(struct co_pgm_flash_ram *r, uint8_t slot)
{
	return r->mem + (size_t)slot * r->flash.slot_size;
}

static int ram_erase(struct co_pgm_flash *f, uint8_t slot)
{
	struct co_pgm_flash_ram *r = ram_of(f);

	if (r->off) {
		return -EIO;
	}
	if (slot > 1U) {
		return -EINVAL;
	}
	if (r->budget == 0) {
		/* The power goes half way through the erase. */
		(void)memset(slot_mem(r, slot), 0xff, f->slot_size / 2U);
		r->off = true;
		return -EIO;
	}
	(void)memset(slot_mem(r, slot), 0xff, f->slot_size);
	r->erases++;
	return 0;
}

static int ram_write(struct co_pgm_flash *f, uint8_t slot, uint32_t off, const void *data,
		     size_t len)
{
	struct co_pgm_flash_ram *r = ram_of(f);
	const uint8_t *src = data;
	uint8_t *dst;
	size_t n = len;

	if (r->off) {
		return -EIO;
	}
	if (slot > 1U || (uint64_t)off + len > f->slot_size) {
		return -EINVAL;
	}
	dst = slot_mem(r, slot) + off;
	for (size_t i = 0; i < len; i++) {
		if ((dst[i] & src[i]) != src[i]) {
			/* Flash cannot set a bit that is clear: the byte was not erased. */
			return -EROFS;
		}
	}
	if (r->budget >= 0 && (int64_t)len > r->budget) {
		n = (size_t)r->budget;
	}
	for (size_t i = 0; i < n; i++) {
		dst[i] &= src[i];
	}
	r->bytes_written += (uint32_t)n;
	if (r->budget >= 0) {
		r->budget -= (int64_t)n;
		if (n < len) {
			r->off = true;
			return -EIO;
		}
	}
	return 0;
}

static int ram_read(struct co_pgm_flash *f, uint8_t slot, uint32_t off, void *buf, size_t len)
{
	struct co_pgm_flash_ram *r = ram_of(f);

	if (r->off) {
		return -EIO;
	}
	if (slot > 1U || (uint64_t)off + len > f->slot_size) {
		return -EINVAL;
	}
	(void)memcpy(buf, slot_mem(r, slot) + off, len);
	return 0;
}

static const struct co_pgm_flash_api ram_api = {
	.erase = ram_erase,
	.write = ram_write,
	.read = ram_read,
};

int co_pgm_flash_ram_init(struct co_pgm_flash_ram *r, void *mem, uint32_t slot_size)
{
	if (r == NULL || mem == NULL || slot_size < 16U + CO_PGM_HDR_SIZE) {
		return -EINVAL;
	}
	(void)memset(r, 0, sizeof(*r));
	r->flash.api = &ram_api;
	r->flash.slot_size = slot_size;
	r->mem = mem;
	r->budget = -1;
	(void)memset(mem, 0xff, (size_t)slot_size * 2U);
	return 0;
}

void co_pgm_flash_ram_cut_after(struct co_pgm_flash_ram *r, uint32_t bytes)
{
	r->budget = bytes;
}

void co_pgm_flash_ram_power_on(struct co_pgm_flash_ram *r)
{
	r->off = false;
	r->budget = -1;
}
