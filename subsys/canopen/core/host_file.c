/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Host files of the native board's file-backed media: POSIX file calls (host_file.h). */

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host_file.h"

int co_host_file_open(const char *path)
{
	int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, S_IRUSR | S_IWUSR);

	return fd >= 0 ? fd : -errno;
}

int64_t co_host_file_size(int fd)
{
	struct stat st;

	return fstat(fd, &st) == 0 ? (int64_t)st.st_size : -errno;
}

int co_host_file_pread(int fd, uint32_t offset, void *buf, size_t len)
{
	size_t done = 0;

	while (done < len) {
		ssize_t n = pread(fd, (char *)buf + done, len - done, (off_t)offset + (off_t)done);

		if (n < 0) {
			if (errno == EINTR) {
				continue;
			}
			return -errno;
		}
		if (n == 0) {
			/* Never written: erased. */
			(void)memset((char *)buf + done, 0xFF, len - done);
			break;
		}
		done += (size_t)n;
	}
	return 0;
}

int co_host_file_pwrite(int fd, uint32_t offset, const void *buf, size_t len)
{
	size_t done = 0;

	while (done < len) {
		ssize_t n = pwrite(fd, (const char *)buf + done, len - done,
				   (off_t)offset + (off_t)done);

		if (n < 0) {
			if (errno == EINTR) {
				continue;
			}
			return -errno;
		}
		if (n == 0) {
			/* Nothing written and no error: it would only loop. */
			return -ENOSPC;
		}
		done += (size_t)n;
	}
	return 0;
}

int co_host_file_sync(int fd)
{
	return fsync(fd) == 0 ? 0 : -errno;
}

void co_host_file_close(int fd)
{
	(void)close(fd);
}
