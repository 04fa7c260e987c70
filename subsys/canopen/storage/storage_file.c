/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* File storage backend for native_posix; the host calls live in core/host_file.c. */

#include <errno.h>

#include <canopen/storage.h>

#include "host_file.h"

static const struct co_storage_file *file_of(const struct co_storage_backend *be)
{
	return (const struct co_storage_file *)be;
}

static int file_read(const struct co_storage_backend *be, uint32_t offset, void *buf, size_t len)
{
	const struct co_storage_file *f = file_of(be);

	if (offset > f->size || len > f->size - offset) {
		return -EINVAL;
	}
	return co_host_file_pread(f->fd, offset, buf, len);
}

static int file_write(const struct co_storage_backend *be, uint32_t offset, const void *buf,
		      size_t len)
{
	const struct co_storage_file *f = file_of(be);

	if (offset > f->size || len > f->size - offset) {
		return -ENOSPC;
	}
	return co_host_file_pwrite(f->fd, offset, buf, len);
}

static int file_sync(const struct co_storage_backend *be)
{
	return co_host_file_sync(file_of(be)->fd);
}

static uint32_t file_size(const struct co_storage_backend *be)
{
	return file_of(be)->size;
}

static const struct co_storage_backend_api file_api = {
	.read = file_read,
	.write = file_write,
	.sync = file_sync,
	.size = file_size,
};

int co_storage_file_open(struct co_storage_file *f, const char *path, uint32_t size)
{
	if (f == NULL || path == NULL || size < 64U) {
		return -EINVAL;
	}
	int fd = co_host_file_open(path);

	if (fd < 0) {
		return fd;
	}
	f->be.api = &file_api;
	f->fd = fd;
	f->size = size;
	return 0;
}

void co_storage_file_close(struct co_storage_file *f)
{
	if (f != NULL && f->fd >= 0) {
		co_host_file_close(f->fd);
		f->fd = -1;
	}
}
