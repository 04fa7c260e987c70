/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Host side of the file flash (native board only): POSIX file calls. */

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pgm_flash_file_host.h"

int co_pgm_host_open(const char *path)
{
	int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, S_IRUSR | S_IWUSR);

	return fd >= 0 ? fd : -errno;
}

int64_t co_pgm_host_size(int fd)
{
	struct stat st;

	return fstat(fd, &st) == 0 ? (int64_t)st.st_size : -errno;
}

int co_pgm_host_pread(int fd, uint32_t offset, void *buf, size_t len)
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
			memset((char *)buf + done, 0xFF, len - done);
			break;
		}
		done += (size_t)n;
	}
	return 0;
}

int co_pgm_host_pwrite(int fd, uint32_t offset, const void *buf, size_t len)
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
		done += (size_t)n;
	}
	return 0;
}

void co_pgm_host_close(int fd)
{
	(void)close(fd);
}
