/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Host side of the file storage backend. Plain C types only: the implementation sees the
 * host's headers (fcntl, unistd), the backend sees only the RTOS's, as with the SocketCAN
 * driver.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_STORAGE_FILE_HOST_H_
#define SAFELINE_SUBSYS_CANOPEN_STORAGE_FILE_HOST_H_

#include <stddef.h>
#include <stdint.h>

/* Open or create the file; returns a descriptor or a negative errno. */
int co_storage_host_open(const char *path);
/* Read len bytes at offset; bytes past the end of the file read as 0xFF (erased). */
int co_storage_host_pread(int fd, uint32_t offset, void *buf, size_t len);
/* Write len bytes at offset; 0 or a negative errno (-ENOSPC on a full disk). */
int co_storage_host_pwrite(int fd, uint32_t offset, const void *buf, size_t len);
/* fsync(); 0 or a negative errno. */
int co_storage_host_fsync(int fd);
/* close(). */
void co_storage_host_close(int fd);

#endif /* SAFELINE_SUBSYS_CANOPEN_STORAGE_FILE_HOST_H_ */
