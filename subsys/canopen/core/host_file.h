/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Host files for the native board's file-backed media (the storage service's file backend,
 * program download's file flash). Plain C types only: the implementation sees the host's
 * headers (fcntl, unistd), its callers only the RTOS's, as with the SocketCAN driver. A file
 * reads as an erased medium where it was never written.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_CORE_HOST_FILE_H_
#define SAFELINE_SUBSYS_CANOPEN_CORE_HOST_FILE_H_

#include <stddef.h>
#include <stdint.h>

/* Open or create the file (read/write, owner only); a descriptor or a negative errno. */
int co_host_file_open(const char *path);
/* The file's size in bytes, or a negative errno. */
int64_t co_host_file_size(int fd);
/* Read len bytes at offset; bytes past the end of the file read as FFh (erased). */
int co_host_file_pread(int fd, uint32_t offset, void *buf, size_t len);
/* Write len bytes at offset; 0 or a negative errno (-ENOSPC when nothing more fits). */
int co_host_file_pwrite(int fd, uint32_t offset, const void *buf, size_t len);
/* fsync(); 0 or a negative errno. */
int co_host_file_sync(int fd);
/* close(). */
void co_host_file_close(int fd);

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_HOST_FILE_H_ */
