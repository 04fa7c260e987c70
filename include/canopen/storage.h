/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Parameter storage: 1010h store parameters, 1011h restore default parameters.
 *
 * The storage module keeps the stored groups (communication, application, manufacturer)
 * of one node on a backend (a file on native_posix, RAM, later a flash area). The medium is
 * split into two slots; a save writes a complete new image into the slot that does not hold
 * the current one and makes it valid with a final 4-byte commit mark, so a save cut off at
 * any byte (power loss, killed process, full disk) leaves the previous image in force.
 *
 * Writing "save" (65766173h) to 1010h sub n saves: sub 1 all groups, 2 communication
 * (1000h-1FFFh), 3 application (6000h-9FFFh), 4 manufacturer (2000h-5FFFh). Writing "load"
 * (64616F6Ch) to 1011h sub n drops the stored group, so the defaults apply from the next
 * Reset Node / Reset Communication (CiA 301 §7.5.2.13, §7.5.2.14). Other values are refused
 * with 08000020h; a backend failure with 06060000h; a request while the application forbids
 * it (co_storage_set_locked()) with 08000021h. A node without medium says so
 * (co_storage_init_absent()): 1010h/1011h read 0 and every request is refused with 08000020h.
 *
 * Like the object dictionary, calls must be made with the node's mutex held.
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_STORAGE_H_
#define SAFELINE_INCLUDE_CANOPEN_STORAGE_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/od.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @defgroup co_storage Parameter storage
 * @{
 */

/** @brief "save" read as a little-endian UNSIGNED32 (CiA 301 §7.5.2.13). */
#define CO_STORAGE_SIGNATURE_SAVE 0x65766173U
/** @brief "load" read as a little-endian UNSIGNED32 (CiA 301 §7.5.2.14). */
#define CO_STORAGE_SIGNATURE_LOAD 0x64616F6CU

/** @cond INTERNAL_HIDDEN */
#ifdef CONFIG_CANOPEN_STORAGE_CHUNK_SIZE
#define CO_STORAGE_CHUNK CONFIG_CANOPEN_STORAGE_CHUNK_SIZE
#else
#define CO_STORAGE_CHUNK 64
#endif
/** @endcond */

struct co_storage_backend;

/**
 * @brief Operations of a storage medium: byte-addressed reads and writes.
 *
 * Writes may be cut off at any byte (the storage module never relies on a write being
 * atomic). Every function returns 0 or a negative errno (-EIO, -ENOSPC).
 */
struct co_storage_backend_api {
	/** @brief Read @p len bytes at @p offset; never-written bytes read as anything. */
	int (*read)(const struct co_storage_backend *be, uint32_t offset, void *buf, size_t len);
	/** @brief Write @p len bytes at @p offset. */
	int (*write)(const struct co_storage_backend *be, uint32_t offset, const void *buf,
		     size_t len);
	/** @brief Make every completed write durable (fsync, flash buffer flush). */
	int (*sync)(const struct co_storage_backend *be);
	/** @brief Capacity of the medium in bytes. */
	uint32_t (*size)(const struct co_storage_backend *be);
};

/** @brief A storage medium; embed it first in the backend's own struct. */
struct co_storage_backend {
	const struct co_storage_backend_api *api;
};

/** @brief RAM backend (tests; battery-backed RAM). */
struct co_storage_ram {
	struct co_storage_backend be;
	uint8_t *mem;
	uint32_t size;
};

/**
 * @brief Set up a RAM backend over @p mem.
 *
 * @retval 0 success
 * @retval -EINVAL NULL memory or size under 64 bytes
 */
int co_storage_ram_init(struct co_storage_ram *r, void *mem, uint32_t size);

/** @brief File backend (native_posix): the medium is a host file. */
struct co_storage_file {
	struct co_storage_backend be;
	int fd;
	uint32_t size;
};

/**
 * @brief Open (create if needed) the file at @p path as a medium of @p size bytes.
 *
 * @retval 0 success
 * @retval -EINVAL bad arguments
 * @retval negative errno from the host (-EACCES, -ENOENT, ...)
 */
int co_storage_file_open(struct co_storage_file *f, const char *path, uint32_t size);

/** @brief Close the file. */
void co_storage_file_close(struct co_storage_file *f);

/** @brief Storage of one node. */
struct co_storage {
	struct co_od *od;
	const struct co_storage_backend *be;
	uint32_t slot_size; /**< bytes per slot */
	uint32_t seq;       /**< sequence number of the current image */
	int8_t active;      /**< slot holding the current image, -1 if none */
	uint32_t skipped;   /**< stored values refused or unknown at the last restore */
	bool absent;        /**< no medium: 1010h/1011h read 0, requests refused */
	bool locked;        /**< local control forbids requests (08000021h) */
	bool own_write;     /**< the module writes 1010h/1011h itself (not a request) */
	uint8_t buf[CO_STORAGE_CHUNK];
};

/**
 * @brief Attach storage to a node's dictionary.
 *
 * Finds the current image on the medium, registers the 1010h/1011h hooks and the restore
 * callback that co_od_reset_comm()/co_od_reset_app() call. Nothing is restored here.
 *
 * @retval 0 success
 * @retval -EINVAL bad arguments or a medium under 64 bytes
 * @retval -ENOSPC no hook slot left in the dictionary
 * @retval -EIO the medium cannot be read
 */
int co_storage_init(struct co_storage *st, struct co_od *od, const struct co_storage_backend *be);

/**
 * @brief Declare that the node has no storage medium (none attached, or it cannot be used).
 *
 * 1010h and 1011h sub-indexes 1.. then read 0 ("does not save on command", "does not restore
 * defaults", CiA 301 §7.5.2.13-14), after every reset too, and a save or restore request is
 * refused with 08000020h (a wrong signature as well). co_storage_save() and
 * co_storage_clear() return -ENODEV.
 *
 * @retval 0 success
 * @retval -EINVAL bad arguments
 * @retval -ENOSPC no hook slot left in the dictionary
 * @retval -EROFS a sub-index could not be set to 0 (it keeps its value; requests are refused)
 */
int co_storage_init_absent(struct co_storage *st, struct co_od *od);

/**
 * @brief Let local control forbid save and restore requests, or allow them again.
 *
 * While locked, a 1010h/1011h write with the right signature is refused with 08000021h
 * ("because of local control"); the sub-indexes keep reading what the node supports. The
 * application's own co_storage_save()/co_storage_clear() calls are not affected.
 */
void co_storage_set_locked(struct co_storage *st, bool locked);

/**
 * @brief Save the current values of the groups in @p group_mask (CO_OD_GROUP_BIT()).
 *
 * Groups not in the mask keep their stored values.
 *
 * @retval 0 saved
 * @retval -ENOSPC the image does not fit in a slot
 * @retval -ENODEV no medium (co_storage_init_absent())
 * @retval -EIO / other negative errno from the backend; the previous image stays current
 */
int co_storage_save(struct co_storage *st, uint32_t group_mask);

/**
 * @brief Drop the stored groups in @p group_mask: defaults apply from the next reset.
 *
 * @retval 0 done
 * @retval negative errno as co_storage_save()
 */
int co_storage_clear(struct co_storage *st, uint32_t group_mask);

/**
 * @brief Write the stored values of the groups in @p group_mask into the dictionary.
 *
 * Each value goes through the accessors with writer CO_OD_WRITER_STORAGE, so limits and
 * validate hooks apply and notify hooks run. Values the dictionary refuses, or objects it
 * no longer has, are skipped and counted in st->skipped. Values stored as "$NODEID + base"
 * are not written: the reset already computed them for the current node-ID.
 *
 * @retval 0 restored (or nothing stored)
 * @retval -EIO the medium cannot be read
 */
int co_storage_restore(struct co_storage *st, uint32_t group_mask);

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_STORAGE_H_ */
