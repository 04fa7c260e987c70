/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Host side of the file flash (native board only). Plain C types only: the implementation
 * sees the host's headers (fcntl, unistd), the flash only the RTOS's.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_PGM_FLASH_FILE_HOST_H_
#define SAFELINE_SUBSYS_CANOPEN_PGM_FLASH_FILE_HOST_H_

#include <stddef.h>
#include <stdint.h>

/* Open or create the file; a descriptor or a negative errno. */
int co_pgm_host_open(const char *path);
/* The file's size in bytes, or a negative errno. */
int64_t co_pgm_host_size(int fd);
/* Read len bytes at offset; bytes past the end of the file read as FFh (erased). */
int co_pgm_host_pread(int fd, uint32_t offset, void *buf, size_t len);
/* Write len bytes at offset; 0 or a negative errno. */
int co_pgm_host_pwrite(int fd, uint32_t offset, const void *buf, size_t len);
/* close(). */
void co_pgm_host_close(int fd);

#endif /* SAFELINE_SUBSYS_CANOPEN_PGM_FLASH_FILE_HOST_H_ */
