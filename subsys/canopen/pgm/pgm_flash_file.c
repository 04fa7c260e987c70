/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A flash kept in a host file (native board): the same flash rules as the RAM flash (erase to
 * FFh, writes only clear bits) and the same power cut at a chosen byte, but the image outlives
 * the process, so a test can cut the power, end the process and boot a new one from the file.
 * Slot s occupies bytes [s * slot_size, (s + 1) * slot_size) of the file; bytes never written
 * read as erased, so a new file is an erased flash.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/util.h>

#include <canopen/pgm.h>

#include "host_file.h"

#define CHUNK 256U

static struct co_pgm_flash_file *file_of(struct co_pgm_flash *f)
{
	return CONTAINER_OF(f, struct co_pgm_flash_file, flash);
}

static uint32_t slot_base(const struct co_pgm_flash *f, uint8_t slot)
{
	return (uint32_t)slot * f->slot_size;
}

static int file_erase(struct co_pgm_flash *f, uint8_t slot)
{
	struct co_pgm_flash_file *ff = file_of(f);
	uint8_t ones[CHUNK];
	uint32_t end = f->slot_size;
	int err = 0;

	if (ff->off || ff->fd < 0) {
		return -EIO;
	}
	if (slot > 1U) {
		return -EINVAL;
	}
	if (ff->budget == 0) {
		/* The power goes half way through the erase. */
		end = f->slot_size / 2U;
	}
	(void)memset(ones, 0xff, sizeof(ones));
	for (uint32_t off = 0; off < end && err == 0; off += CHUNK) {
		err = co_host_file_pwrite(ff->fd, slot_base(f, slot) + off, ones,
					  MIN(CHUNK, end - off));
	}
	if (err != 0) {
		return err;
	}
	if (end < f->slot_size) {
		ff->off = true;
		return -EIO;
	}
	ff->erases++;
	return 0;
}

/* Flash cannot set a bit that is clear: -EROFS when a byte was not erased. */
static int check_erased(struct co_pgm_flash_file *ff, uint32_t pos, const uint8_t *src, size_t len)
{
	uint8_t cur[CHUNK];

	for (size_t done = 0; done < len; done += CHUNK) {
		size_t n = MIN(CHUNK, len - done);
		int err = co_host_file_pread(ff->fd, pos + (uint32_t)done, cur, n);

		if (err != 0) {
			return err;
		}
		for (size_t i = 0; i < n; i++) {
			if ((cur[i] & src[done + i]) != src[done + i]) {
				return -EROFS;
			}
		}
	}
	return 0;
}

static int file_write(struct co_pgm_flash *f, uint8_t slot, uint32_t off, const void *data,
		      size_t len)
{
	struct co_pgm_flash_file *ff = file_of(f);
	const uint32_t pos = slot_base(f, slot) + off;
	size_t n = len;
	int err;

	if (ff->off || ff->fd < 0) {
		return -EIO;
	}
	if (slot > 1U || (uint64_t)off + len > f->slot_size) {
		return -EINVAL;
	}
	err = check_erased(ff, pos, data, len);
	if (err != 0) {
		return err;
	}
	if (ff->budget >= 0 && (int64_t)len > ff->budget) {
		n = (size_t)ff->budget;
	}
	/* Every bit of the data is set in the erased bytes: writing it clears only bits. */
	err = n > 0U ? co_host_file_pwrite(ff->fd, pos, data, n) : 0;
	if (err != 0) {
		return err;
	}
	ff->bytes_written += (uint32_t)n;
	if (ff->budget >= 0) {
		ff->budget -= (int64_t)n;
		if (n < len) {
			ff->off = true;
			return -EIO;
		}
	}
	return 0;
}

static int file_read(struct co_pgm_flash *f, uint8_t slot, uint32_t off, void *buf, size_t len)
{
	struct co_pgm_flash_file *ff = file_of(f);

	if (ff->off || ff->fd < 0) {
		return -EIO;
	}
	if (slot > 1U || (uint64_t)off + len > f->slot_size) {
		return -EINVAL;
	}
	return co_host_file_pread(ff->fd, slot_base(f, slot) + off, buf, len);
}

static const struct co_pgm_flash_api file_api = {
	.erase = file_erase,
	.write = file_write,
	.read = file_read,
};

int co_pgm_flash_file_open(struct co_pgm_flash_file *ff, const char *path, uint32_t slot_size)
{
	int64_t size;
	int fd;

	if (ff == NULL || path == NULL || path[0] == '\0' || slot_size < 16U + CO_PGM_HDR_SIZE ||
	    slot_size > UINT32_MAX / 2U) {
		return -EINVAL;
	}
	fd = co_host_file_open(path);
	if (fd < 0) {
		return fd;
	}
	size = co_host_file_size(fd);
	if (size < 0 || size > 2 * (int64_t)slot_size) {
		/* Not a flash of this geometry: refuse rather than misread its slots. */
		co_host_file_close(fd);
		return size < 0 ? (int)size : -EFBIG;
	}
	(void)memset(ff, 0, sizeof(*ff));
	ff->flash.api = &file_api;
	ff->flash.slot_size = slot_size;
	ff->fd = fd;
	ff->budget = -1;
	return 0;
}

void co_pgm_flash_file_close(struct co_pgm_flash_file *ff)
{
	if (ff->fd >= 0) {
		co_host_file_close(ff->fd);
		ff->fd = -1;
	}
}

void co_pgm_flash_file_cut_after(struct co_pgm_flash_file *ff, uint32_t bytes)
{
	ff->budget = bytes;
}
