/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Layer setting services (LSS, CiA 305): the slave, and the frame format both sides use.
 *
 * LSS lets a master find a device by its LSS address (the four numbers of 1018h sub 1..4:
 * vendor-ID, product code, revision, serial number) and give it a node-ID and a bit rate,
 * before the device has a node-ID of its own. Every LSS frame is 8 bytes long: the master
 * sends on 7E5h, slaves answer on 7E4h; byte 0 is the command specifier (CO_LSS_CS_*), the
 * unused bytes are 0.
 *
 * The slave has two states, independent of NMT: waiting (after power-up and every reset) and
 * configuration. It runs while the node has no node-ID (CO_NODE_ID_UNCONFIGURED): it is the
 * service that gives the node one. A node-ID it configures takes effect at the next NMT Reset
 * Communication; a node that had none resets itself when the master switches it back to
 * waiting, and boots with its new ID.
 *
 * The constants and the inline frame helpers of this header serve a master as much as the
 * slave; they need no part of the slave built.
 *
 * See doc/lss.md for the behaviour, the decisions where CiA 305 was not available to us, and
 * the tests.
 *
 * @defgroup co_lss LSS
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_LSS_H_
#define SAFELINE_INCLUDE_CANOPEN_LSS_H_

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include <zephyr/drivers/can.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/line.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;
struct co_storage_backend;

/** @name Identifiers
 * @{
 */
/** Master to slaves. */
#define CO_LSS_MASTER_COB_ID 0x7E5U
/** Slaves to master. */
#define CO_LSS_SLAVE_COB_ID  0x7E4U
/** Length of every LSS frame. */
#define CO_LSS_DLC           8U
/** @} */

/** @name Command specifiers (byte 0)
 * @{
 */
/** Switch state global: byte 1 = CO_LSS_MODE_*. No answer. */
#define CO_LSS_CS_SWITCH_GLOBAL              0x04U
/** Switch state selective, vendor-ID in bytes 1..4. */
#define CO_LSS_CS_SWITCH_SEL_VENDOR          0x40U
/** Switch state selective, product code. */
#define CO_LSS_CS_SWITCH_SEL_PRODUCT         0x41U
/** Switch state selective, revision number. */
#define CO_LSS_CS_SWITCH_SEL_REVISION        0x42U
/** Switch state selective, serial number; the addressed slave answers 44h. */
#define CO_LSS_CS_SWITCH_SEL_SERIAL          0x43U
/** Answer of the slave that the selective switch put into configuration. */
#define CO_LSS_CS_SWITCH_SEL_RESULT          0x44U
/** Configure node-ID: byte 1 = node-ID; answer byte 1 = CO_LSS_ERR_*, byte 2 = detail. */
#define CO_LSS_CS_CONFIG_NODE_ID             0x11U
/** Configure bit timing: byte 1 = table selector, byte 2 = table index; answered as 11h. */
#define CO_LSS_CS_CONFIG_BIT_TIMING          0x13U
/** Activate bit timing: bytes 1..2 = switch delay [ms]. No answer. */
#define CO_LSS_CS_ACTIVATE_BIT_TIMING        0x15U
/** Store configuration; answered as 11h. */
#define CO_LSS_CS_STORE                      0x17U
/** Identify remote slave, vendor-ID (bytes 1..4). */
#define CO_LSS_CS_IDENT_VENDOR               0x46U
/** Identify remote slave, product code. */
#define CO_LSS_CS_IDENT_PRODUCT              0x47U
/** Identify remote slave, lowest revision number. */
#define CO_LSS_CS_IDENT_REVISION_LOW         0x48U
/** Identify remote slave, highest revision number. */
#define CO_LSS_CS_IDENT_REVISION_HIGH        0x49U
/** Identify remote slave, lowest serial number. */
#define CO_LSS_CS_IDENT_SERIAL_LOW           0x4AU
/** Identify remote slave, highest serial number; slaves in the ranges answer 4Fh. */
#define CO_LSS_CS_IDENT_SERIAL_HIGH          0x4BU
/** Identify non-configured remote slave; slaves without node-ID answer 50h. */
#define CO_LSS_CS_IDENT_NON_CONFIGURED       0x4CU
/** Answer to identify remote slave and to fastscan (no data: answers of slaves merge). */
#define CO_LSS_CS_IDENT_SLAVE                0x4FU
/** Answer to identify non-configured remote slave (no data). */
#define CO_LSS_CS_IDENT_NON_CONFIGURED_SLAVE 0x50U
/** Fastscan: IDNumber (bytes 1..4), BitCheck (5), LSSSub (6), LSSNext (7). */
#define CO_LSS_CS_FASTSCAN                   0x51U
/** Inquire vendor-ID; the answer carries 1018h sub 1 in bytes 1..4. */
#define CO_LSS_CS_INQUIRE_VENDOR             0x5AU
/** Inquire product code (1018h sub 2). */
#define CO_LSS_CS_INQUIRE_PRODUCT            0x5BU
/** Inquire revision number (1018h sub 3). */
#define CO_LSS_CS_INQUIRE_REVISION           0x5CU
/** Inquire serial number (1018h sub 4). */
#define CO_LSS_CS_INQUIRE_SERIAL             0x5DU
/** Inquire node-ID; the answer carries the node-ID in byte 1. */
#define CO_LSS_CS_INQUIRE_NODE_ID            0x5EU
/** @} */

/** @name Switch state global modes (byte 1 of 04h)
 * @{
 */
#define CO_LSS_MODE_WAITING       0x00U
#define CO_LSS_MODE_CONFIGURATION 0x01U
/** @} */

/** @name Error codes of the 11h, 13h and 17h answers (byte 1)
 * @{
 */
/** Success. */
#define CO_LSS_ERR_OK              0x00U
/** 11h: node-ID out of range (not 1..127 and not FFh). */
#define CO_LSS_ERR_NODE_ID_RANGE   0x01U
/** 13h: the bit timing is not supported. */
#define CO_LSS_ERR_BIT_TIMING      0x01U
/** 17h: storing is not supported. */
#define CO_LSS_ERR_STORE_SUPPORTED 0x01U
/** 17h: the storage medium could not be written. */
#define CO_LSS_ERR_STORE_MEDIUM    0x02U
/** Implementation specific; byte 2 then holds the manufacturer's code. */
#define CO_LSS_ERR_SPECIFIC        0xFFU
/** @} */

/** @name Fastscan fields
 * @{
 */
/** BitCheck of the probe that restarts every slave's scan. */
#define CO_LSS_FASTSCAN_CONFIRM  0x80U
/** LSSSub/LSSNext: the part of the LSS address a fastscan step checks. */
#define CO_LSS_FASTSCAN_VENDOR   0U
#define CO_LSS_FASTSCAN_PRODUCT  1U
#define CO_LSS_FASTSCAN_REVISION 2U
#define CO_LSS_FASTSCAN_SERIAL   3U
/** @} */

/** @name Bit timing table 0 (CiA 305)
 * @{
 */
/** Table selector of the standard table; 1..127 reserved, 128..255 manufacturer tables. */
#define CO_LSS_BIT_TIMING_TABLE_CIA  0U
/** Index 5: 100 kbit/s in older editions, reserved in the newer ones (see doc/lss.md). */
#define CO_LSS_BIT_TIMING_INDEX_100K 5U
/** Index 9: automatic bit rate detection. */
#define CO_LSS_BIT_TIMING_INDEX_AUTO 9U
/** Number of indices table 0 defines (0..9). */
#define CO_LSS_BIT_TIMING_INDICES    10U
/** @} */

/**
 * @brief The bit rate of an index of table 0.
 *
 * @param index Table index.
 * @param legacy_100k Whether index 5 means 100 kbit/s (older editions of CiA 305).
 * @return Bit rate [bit/s], or 0 for index 5 without @p legacy_100k, index 9 (automatic
 *         detection, no fixed rate) and indices the table does not define.
 */
static inline uint32_t co_lss_bit_timing_bps(uint8_t index, bool legacy_100k)
{
	static const uint32_t bps[CO_LSS_BIT_TIMING_INDICES] = {
		1000000U, 800000U, 500000U, 250000U, 125000U, 0U, 50000U, 20000U, 10000U, 0U,
	};

	if (index == CO_LSS_BIT_TIMING_INDEX_100K && legacy_100k) {
		return 100000U;
	}
	return index < CO_LSS_BIT_TIMING_INDICES ? bps[index] : 0U;
}

/** @name Frame helpers (master and slave)
 * @{
 */

/** @brief Start an LSS frame: identifier @p id, 8 zero bytes, command specifier @p cs. */
static inline void co_lss_frame_init(struct can_frame *f, uint32_t id, uint8_t cs)
{
	(void)memset(f, 0, sizeof(*f));
	f->id = id;
	f->dlc = CO_LSS_DLC;
	f->data[0] = cs;
}

/** @brief Put a 32-bit value (an LSS address part, an IDNumber) into bytes 1..4. */
static inline void co_lss_frame_set_u32(struct can_frame *f, uint32_t value)
{
	sys_put_le32(value, &f->data[1]);
}

/** @brief The 32-bit value of bytes 1..4. */
static inline uint32_t co_lss_frame_get_u32(const struct can_frame *f)
{
	return sys_get_le32(&f->data[1]);
}

/** @brief Whether @p f has the form of an LSS frame (11-bit data frame of 8 bytes). */
static inline bool co_lss_frame_valid(const struct can_frame *f)
{
	return f->dlc == CO_LSS_DLC && (f->flags & (CAN_FRAME_RTR | CAN_FRAME_IDE)) == 0U;
}

/** @} */

/** The states of an LSS slave. */
enum co_lss_state {
	/** Answers only the switch, identify and fastscan commands. */
	CO_LSS_STATE_WAITING = 0,
	/** Configuration: takes configure, activate, store and inquire commands as well. */
	CO_LSS_STATE_CONFIGURATION = 1,
};

/**
 * @brief The steps of a bit rate change, as the slave asks them of the line's controller.
 *
 * See co_lss_set_bitrate_handler().
 */
enum co_lss_bitrate_step {
	/** Configure bit timing: can the line run at the rate? (nothing changes yet) */
	CO_LSS_BITRATE_CHECK,
	/** Activate bit timing: stop sending; the first switch delay starts. */
	CO_LSS_BITRATE_SILENCE,
	/** The first delay is over: change the rate (still silent). */
	CO_LSS_BITRATE_SWITCH,
	/** The second delay is over: send again. */
	CO_LSS_BITRATE_RESUME,
};

/**
 * @brief Carry out one step of a bit rate change for a node's default line.
 *
 * Runs in the line thread with the node's mutex held; must not block for long.
 *
 * @param node The node.
 * @param step What to do.
 * @param bitrate The new rate [bit/s] (for CO_LSS_BITRATE_RESUME: the rate now in force,
 *        the new one if the switch succeeded).
 * @param user_data As registered.
 * @return 0 on success. For CO_LSS_BITRATE_CHECK a negative errno makes the answer "bit
 *         timing not supported"; for CO_LSS_BITRATE_SWITCH it keeps the old rate (logged).
 */
typedef int (*co_lss_bitrate_handler_t)(struct co_node *node, enum co_lss_bitrate_step step,
					uint32_t bitrate, void *user_data);

/**
 * @brief LSS state indication.
 *
 * Runs in the line thread (or the thread calling the API) with the node's mutex held; must
 * not block. Listeners of CO_EV_LSS get the same news after it.
 */
typedef void (*co_lss_ind_t)(struct co_node *node, enum co_lss_state from, enum co_lss_state to,
			     void *user_data);

/** What a storage medium held for LSS (co_lss_store_attach()). */
struct co_lss_config {
	/** Stored node-ID: 1..127, or CO_NODE_ID_UNCONFIGURED. */
	uint8_t node_id;
	/** Stored bit timing index of table 0, or 0xFF when none was configured. */
	uint8_t bit_timing_index;
	/** Its bit rate [bit/s], 0 when none. */
	uint32_t bitrate;
};

/** @cond INTERNAL_HIDDEN */
struct co_lss {
	struct co_rx rx;
	/* The two delays of an activate bit timing. */
	struct co_timer timer;
	uint8_t state;
	/* Switch state selective: how many of 40h..43h matched, in order. */
	uint8_t sel_step;
	/* Identify remote slave: how many of 46h..4Bh matched, in order. */
	uint8_t ident_step;
	/* Fastscan: the LSS address part the next step checks (LSSPos). */
	uint8_t fs_pos;
	/* The node answered a fastscan probe and the scan has not ended for it. */
	bool fs_active;
	/* Activate bit timing: 0 idle, 1 silent before the switch, 2 silent after it. */
	uint8_t switching;
	uint16_t switch_delay_ms;
	/* Identify remote slave: the lower bound of the range being checked. */
	uint32_t ident_low;
	/* Configured bit timing (table 0 index, 0xFF none) and its rate. */
	uint8_t bt_index;
	uint32_t bt_bitrate;
	/* The rate LSS last put in force, 0 while it is the line's own. */
	uint32_t active_bitrate;
	/* The switch of the activation under way failed: the old rate stays. */
	bool switch_failed;
	/* Storage of the LSS configuration. */
	const struct co_storage_backend *store;
	uint32_t store_seq;
	int8_t store_slot;
	co_lss_ind_t ind;
	void *ind_user_data;
	co_lss_bitrate_handler_t br_handler;
	void *br_user_data;
};
/** @endcond */

/** @brief The node's LSS state. */
enum co_lss_state co_lss_get_state(struct co_node *node);

/** @brief Set the LSS state indication (NULL removes it). */
void co_lss_set_ind(struct co_node *node, co_lss_ind_t cb, void *user_data);

/**
 * @brief Take over the bit rate changes of the node's default line.
 *
 * Without a handler the slave uses the line's CAN device through Zephyr's CAN API: the
 * check asks can_set_bitrate() of the running controller (-EBUSY means the driver can set
 * that rate once stopped; -ENOSYS or -ENOTSUP that it cannot), silence is can_stop(), the
 * switch can_set_bitrate(), resume can_start(). A line without a CAN device (a simulation
 * line) supports no bit rate change unless a handler is set. Stopping the controller
 * silences every node on that line: the rate belongs to the controller.
 *
 * @param node The node.
 * @param handler The handler, or NULL for the default behaviour.
 * @param user_data Passed to @p handler.
 */
void co_lss_set_bitrate_handler(struct co_node *node, co_lss_bitrate_handler_t handler,
				void *user_data);

/**
 * @brief Keep the LSS configuration (store configuration, 17h) on a storage medium.
 *
 * The medium holds only the LSS record (node-ID and bit timing, two copies so that a write
 * cut at any byte leaves the previous one in force); at least 32 bytes. Any backend of
 * canopen/storage.h serves (RAM, file, or the application's own). Without a medium, store
 * configuration answers "storing not supported".
 *
 * A valid record found on the medium is applied: its node-ID becomes the node's pending
 * node-ID (in force from the next reset: call before co_node_start() to boot with it) and
 * its bit timing the configured one. The bit rate itself is set on the line's controller only
 * if that controller is stopped (the line not started yet); otherwise the application sets it
 * from @p loaded before starting the line.
 *
 * @param node The node.
 * @param be The medium, or NULL to detach.
 * @param loaded If not NULL, gets the stored configuration (on 0 only).
 *
 * @retval 0 Attached; a stored configuration was found and applied.
 * @retval -ENOENT Attached; the medium holds no valid record (nothing applied).
 * @retval -EINVAL The medium is smaller than 32 bytes.
 * @retval -EIO The medium could not be read (not attached).
 */
int co_lss_store_attach(struct co_node *node, const struct co_storage_backend *be,
			struct co_lss_config *loaded);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_LSS_H_ */
