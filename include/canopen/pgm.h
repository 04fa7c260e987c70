/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Program download (CiA 302 §9, objects 1F50h-1F57h): slave side, image format and
 *        the manager's image source.
 *
 * Slave side (CONFIG_CANOPEN_PGM): 1F50h:01 (DOMAIN, write only) receives a program image,
 * streamed chunk by chunk from the SDO server into the inactive slot of a flash-like backend
 * (struct co_pgm_flash, two slots A/B); the image is verified by reading it back after the
 * last byte. 1F51h:01 controls the program (0 stop, 1 start, 2 reset, 3 clear), 1F52h:01/02
 * report the running image's date and time, 1F56h:01 its CRC-32, 1F57h:01 the flash status.
 * A new image runs only after a start that writes its commit record; until then, and after
 * any failure or power cut, the previous verified image stays the one that boots.
 *
 * The objects are served by an object provider: the device's EDS must not describe
 * 1F50h-1F57h (objects of the EDS take precedence over a provider).
 *
 * Manager side (CONFIG_CANOPEN_MGR_PGM): the application registers an image source; the
 * boot's "check and update software version" step then stops the slave's program,
 * downloads the image by block SDO, starts it, waits for the slave's boot-up and reads
 * 1F52h again (mgr.h, co_mgr_set_pgm_source()).
 *
 * @defgroup co_pgm Program download
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_PGM_H_
#define SAFELINE_INCLUDE_CANOPEN_PGM_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/od.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** @name Image format (little-endian)
 *
 * A 32-byte header, then the program body:
 *
 * | offset | size | field |
 * |---|---|---|
 * | 0 | 4 | magic "SLPG" |
 * | 4 | 2 | header version (1) |
 * | 6 | 2 | header size (32) |
 * | 8 | 4 | body length in bytes |
 * | 12 | 4 | CRC-32 of the body (1F56h) |
 * | 16 | 4 | date: days since 1984-01-01 (1F52h:01) |
 * | 20 | 4 | time: ms after midnight (1F52h:02) |
 * | 24 | 4 | reserved, 0 |
 * | 28 | 4 | CRC-32 of bytes 0..27 |
 *
 * CRC-32 is the IEEE 802.3 polynomial (reflected, init and final XOR FFFFFFFFh), the one of
 * zlib's crc32().
 * @{
 */
#define CO_PGM_MAGIC       0x47504C53U /* "SLPG" */
#define CO_PGM_HDR_VERSION 1U
#define CO_PGM_HDR_SIZE    32U
/** @} */

/** What an image header says. */
struct co_pgm_image_info {
	uint32_t length; /**< body length */
	uint32_t crc;    /**< CRC-32 of the body (1F56h:01) */
	uint32_t date;   /**< days since 1984-01-01 (1F52h:01) */
	uint32_t time;   /**< ms after midnight (1F52h:02) */
};

/** @brief CRC-32 (IEEE) of @p len bytes, continuing @p crc (0 to start). */
uint32_t co_pgm_crc32(uint32_t crc, const void *data, size_t len);

/**
 * @brief Write the 32-byte header of an image whose body is @p body into @p hdr.
 *
 * The image on the wire is the header followed by the body.
 */
void co_pgm_image_header(uint8_t hdr[CO_PGM_HDR_SIZE], const void *body, uint32_t len,
			 uint32_t date, uint32_t time);

/**
 * @brief Parse and check a header (magic, version, size, header CRC).
 *
 * @retval 0 valid, @p info filled
 * @retval -ENOTSUP not our format (magic, version or size)
 * @retval -EBADMSG header CRC wrong
 */
int co_pgm_image_parse(const uint8_t hdr[CO_PGM_HDR_SIZE], struct co_pgm_image_info *info);

/** @name 1F57h:01 flash status (bit 0: in progress; bits 1..7: error code)
 * @{
 */
#define CO_PGM_FLASH_BUSY        0x01U
#define CO_PGM_FLASH_OK          0x00U
#define CO_PGM_FLASH_NO_PROGRAM  (1U << 1)
#define CO_PGM_FLASH_FORMAT      (2U << 1)
#define CO_PGM_FLASH_CRC         (3U << 1)
#define CO_PGM_FLASH_NOT_CLEARED (4U << 1)
#define CO_PGM_FLASH_WRITE       (5U << 1)
#define CO_PGM_FLASH_ADDRESS     (6U << 1)
#define CO_PGM_FLASH_UNSPECIFIED (63U << 1)
/** @} */

/** 1F51h:01 commands (written) and states (read: 0 stopped, 1 running). */
enum co_pgm_ctrl {
	CO_PGM_STOP = 0,
	CO_PGM_START = 1,
	CO_PGM_RESET = 2,
	CO_PGM_CLEAR = 3,
};

/* --- Flash-like backend ----------------------------------------------------------------------- */

struct co_pgm_flash;

/**
 * @brief Operations of a flash with two slots of flash->slot_size bytes each.
 *
 * Flash rules: erase sets a whole slot to FFh; write may only clear bits of erased bytes.
 * Each returns 0 or a negative errno. Called with the node's mutex held.
 */
struct co_pgm_flash_api {
	int (*erase)(struct co_pgm_flash *f, uint8_t slot);
	int (*write)(struct co_pgm_flash *f, uint8_t slot, uint32_t off, const void *data,
		     size_t len);
	int (*read)(struct co_pgm_flash *f, uint8_t slot, uint32_t off, void *buf, size_t len);
};

/** A flash backend: its operations and its slot size. */
struct co_pgm_flash {
	const struct co_pgm_flash_api *api;
	/** Bytes per slot: 16 (commit record) + 32 (header) + the largest body. */
	uint32_t slot_size;
};

/**
 * @brief A RAM-backed flash (any board) that can lose power at a chosen byte.
 *
 * The memory outlives a simulated restart: the test keeps it and attaches it to the restarted
 * node. co_pgm_flash_ram_cut_after() arms a power cut: the write that reaches the byte stops
 * there (the bytes before it are written), an erase that starts at or after it stops half
 * way, and every access fails with -EIO until co_pgm_flash_ram_power_on().
 */
struct co_pgm_flash_ram {
	struct co_pgm_flash flash;
	uint8_t *mem; /**< 2 x slot_size bytes */
	/** Bytes that may still be written before the cut; negative: no cut armed. */
	int64_t budget;
	bool off; /**< the power is cut */
	uint32_t bytes_written;
	uint32_t erases;
};

/**
 * @brief Set up a RAM flash over @p mem (2 x @p slot_size bytes), erased.
 * @retval -EINVAL @p mem NULL or @p slot_size below 48
 */
int co_pgm_flash_ram_init(struct co_pgm_flash_ram *r, void *mem, uint32_t slot_size);

/** @brief Cut the power after @p bytes more written bytes (see struct co_pgm_flash_ram). */
void co_pgm_flash_ram_cut_after(struct co_pgm_flash_ram *r, uint32_t bytes);

/** @brief Power back: accesses work again, no cut armed. */
void co_pgm_flash_ram_power_on(struct co_pgm_flash_ram *r);

/**
 * @brief A flash kept in a host file, native board only (CONFIG_CANOPEN_PGM_FLASH_FILE).
 *
 * The same flash rules and power cut as struct co_pgm_flash_ram, but the slots live in a
 * file (slot s at byte s x slot_size; bytes never written read as erased), so an image
 * outlives the process: a device restarted as a new process boots what the file holds.
 * After a cut every access fails with -EIO until the file is opened again (the next power-on).
 */
struct co_pgm_flash_file {
	struct co_pgm_flash flash;
	int fd; /**< host file descriptor, -1 when closed */
	/** Bytes that may still be written before the cut; negative: no cut armed. */
	int64_t budget;
	bool off; /**< the power is cut */
	uint32_t bytes_written;
	uint32_t erases;
};

/**
 * @brief Open (or create, erased) the file flash at @p path with slots of @p slot_size bytes.
 *
 * @retval 0 open
 * @retval -EINVAL @p path NULL or empty, or @p slot_size below 48 or too large
 * @retval -EFBIG the file is larger than two slots: a flash of another geometry
 * @retval other the host's errno, negative (cannot open or create the file)
 */
int co_pgm_flash_file_open(struct co_pgm_flash_file *f, const char *path, uint32_t slot_size);

/** @brief Close the file; the flash then fails every access with -EIO. */
void co_pgm_flash_file_close(struct co_pgm_flash_file *f);

/** @brief Cut the power after @p bytes more written bytes (as co_pgm_flash_ram_cut_after()). */
void co_pgm_flash_file_cut_after(struct co_pgm_flash_file *f, uint32_t bytes);

/* --- Slave side --------------------------------------------------------------------------------
 */

/** What happened to the program (co_pgm_ind_t). */
enum co_pgm_event {
	/** Stopped (1F51h:01 = 0). */
	CO_PGM_EV_STOPPED,
	/** Running: started again (1F51h:01 = 1, same image). */
	CO_PGM_EV_STARTED,
	/**
	 * A new image was committed and runs (1F51h:01 = 1 after a verified download): the
	 * device restarts with it (the service requests Reset Node right after the answer).
	 */
	CO_PGM_EV_SWITCHED,
	/** Reset (1F51h:01 = 2): the program is stopped and starts from scratch. */
	CO_PGM_EV_RESET,
	/** A downloaded image was verified (not running yet). */
	CO_PGM_EV_VERIFIED,
	/** A download failed (1F57h:01 says why); the running image is unchanged. */
	CO_PGM_EV_REFUSED,
	/** A verified image not yet started was erased (1F51h:01 = 3). */
	CO_PGM_EV_CLEARED,
};

/**
 * @brief The program changed; @p img is the running image (NULL if none), for
 *        CO_PGM_EV_VERIFIED the downloaded one.
 *
 * Runs with the node's mutex held; must not block.
 */
typedef void (*co_pgm_ind_t)(struct co_node *node, enum co_pgm_event ev,
			     const struct co_pgm_image_info *img, void *user_data);

/** @cond INTERNAL_HIDDEN */
struct co_pgm {
	struct co_node *node;
	struct co_pgm_flash *flash;
	struct co_od_provider prov;  /* 1F50h-1F57h */
	struct co_timer reset_timer; /* the restart after a switch, once the answer is out */
	co_pgm_ind_t ind;
	void *ind_user_data;
	struct co_pgm_image_info run;  /* running image (valid when run_slot >= 0) */
	struct co_pgm_image_info pend; /* verified download (valid when pend_slot >= 0) */
	struct co_pgm_image_info dl;   /* header of the download in progress */
	uint32_t run_seq;
	uint32_t dl_crc;  /* CRC of the body received so far */
	uint32_t status;  /* 1F57h:01 */
	int8_t run_slot;  /* -1: no valid image */
	int8_t pend_slot; /* -1: none */
	int8_t dl_slot;   /* -1: no download in progress */
	uint8_t hdr[CO_PGM_HDR_SIZE];
	bool running; /* 1F51h:01 read value */
	bool dl_hdr_ok;
};
/** @endcond */

/**
 * @brief Give the service its flash and boot from it: the slot with a valid commit record
 *        and a verified image, the newest commit if both qualify, becomes the running image.
 *
 * Call after co_node_init(), before co_node_start() (a restarted device calls it again with
 * the same flash). Without a valid image 1F52h reads 0/0 and 1F57h:01 reads 02h (no valid
 * program).
 *
 * @retval 0 a valid image runs
 * @retval -ENOENT no valid image (the service works: a download can bring one)
 * @retval -EINVAL @p flash or its api NULL, or a slot too small for a header
 */
int co_pgm_attach(struct co_node *node, struct co_pgm_flash *flash);

/** @brief Set the program indication (NULL removes it). */
void co_pgm_set_ind(struct co_node *node, co_pgm_ind_t cb, void *user_data);

/**
 * @brief The running image, or -ENOENT when there is none.
 * @param[out] slot the slot it runs from (may be NULL)
 */
int co_pgm_get_running(struct co_node *node, struct co_pgm_image_info *info, int *slot);

/** @brief 1F57h:01. */
uint32_t co_pgm_flash_status(struct co_node *node);

/** @brief 1F51h:01 read value: true when the program runs. */
bool co_pgm_is_running(struct co_node *node);

/**
 * @brief Verify slot @p slot of @p flash as the boot does (commit record, header, body CRC),
 *        independently of any node (tests, boot loaders).
 *
 * @retval 0 valid; @p info (may be NULL) and @p seq (may be NULL) filled
 * @retval -ENOENT no valid commit record
 * @retval -EBADMSG committed but the image does not verify
 */
int co_pgm_slot_verify(struct co_pgm_flash *flash, uint8_t slot, struct co_pgm_image_info *info,
		       uint32_t *seq);

/* --- Manager side (CONFIG_CANOPEN_MGR_PGM) -----------------------------------------------------
 */

/**
 * @brief Image source of the manager: the program image for slave @p id.
 *
 * Called in the boot's software step when the slave's 1F52h differs from 1F53h/1F54h and
 * 1F81h bit 6 allows an update. The image (header and body, as co_pgm_image_header() makes
 * it) must stay valid and unchanged until that slave's boot attempt ends.
 *
 * @retval 0 @p image and @p len set: the manager downloads it
 * @retval other no image for @p id: the software indication (co_mgr_set_sw_ind()) decides,
 *         as without this source
 */
typedef int (*co_mgr_pgm_source_t)(struct co_node *node, uint8_t id, const void **image,
				   size_t *len, void *user_data);

/** @brief Set the manager's image source (NULL removes it). */
void co_mgr_set_pgm_source(struct co_node *node, co_mgr_pgm_source_t cb, void *user_data);

/**
 * @brief Program slot @p slot of @p flash with @p image and commit it with sequence @p seq,
 *        as a factory tool or a boot loader would (no node needed).
 *
 * The slot is erased, the image written and verified, then the commit record written. The
 * boot takes the committed slot with the highest sequence.
 *
 * @retval 0 done
 * @retval -EINVAL bad arguments, or the image does not fit the slot
 * @retval -EBADMSG the image does not verify (header or body CRC)
 * @retval other the flash's error
 */
int co_pgm_slot_program(struct co_pgm_flash *flash, uint8_t slot, const void *image, size_t len,
			uint32_t seq);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_PGM_H_ */
