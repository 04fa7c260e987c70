/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* RAM storage backend: for tests, and for targets with battery-backed RAM. */

#include <errno.h>
#include <string.h>

#include <canopen/storage.h>

static const struct co_storage_ram *ram_of(const struct co_storage_backend *be)
{
	return (const struct co_storage_ram *)be;
}

static int ram_read(const struct co_storage_backend *be, uint32_t offset, void *buf, size_t len)
{
	const struct co_storage_ram *r = ram_of(be);

	if (offset > r->size || len > r->size - offset) {
		return -EINVAL;
	}
	(void)memcpy(buf, r->mem + offset, len);
	return 0;
}

static int ram_write(const struct co_storage_backend *be, uint32_t offset, const void *buf,
		     size_t len)
{
	const struct co_storage_ram *r = ram_of(be);

	if (offset > r->size || len > r->size - offset) {
		return -ENOSPC;
	}
	(void)memcpy(r->mem + offset, buf, len);
	return 0;
}

static int ram_sync(const struct co_storage_backend *be)
{
	(void)be;
	return 0;
}

static uint32_t ram_size(const struct co_storage_backend *be)
{
	return ram_of(be)->size;
}

static const struct co_storage_backend_api ram_api = {
	.read = ram_read,
	.write = ram_write,
	.sync = ram_sync,
	.size = ram_size,
};

int co_storage_ram_init(struct co_storage_ram *r, void *mem, uint32_t size)
{
	if (r == NULL || mem == NULL || size < 64U) {
		return -EINVAL;
	}
	r->be.api = &ram_api;
	r->mem = mem;
	r->size = size;
	return 0;
}
