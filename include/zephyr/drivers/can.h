/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CAN controller API: the subset of Zephyr's `<zephyr/drivers/can.h>` that SafeLine uses.
 *
 * Names, types, flags, return codes and timeout semantics are Zephyr's (classic CAN; the CAN FD
 * flags exist but no SafeLine driver supports them). Code written against this header compiles
 * unchanged in a Zephyr tree.
 *
 * Calling contexts: RX, TX-completion and state-change callbacks run in the driver's context
 * (an ISR on a target, the driver's dispatch thread on native_posix). They must not block.
 */

#ifndef ZEPHYR_INCLUDE_DRIVERS_CAN_H_
#define ZEPHYR_INCLUDE_DRIVERS_CAN_H_

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/util.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief CAN controller interface
 * @defgroup can_interface CAN controller interface
 * @{
 */

/** @name CAN identifier and frame size limits */
/** @{ */
/** Bit mask of a standard (11-bit) CAN identifier. */
#define CAN_STD_ID_MASK 0x7FFU
/** Bit mask of an extended (29-bit) CAN identifier. */
#define CAN_EXT_ID_MASK 0x1FFFFFFFU
/** Maximum data length code of a classic CAN frame. */
#define CAN_MAX_DLC     8U
/** Maximum data length code of a CAN FD frame. */
#define CANFD_MAX_DLC   15U
/** Maximum payload of a frame in bytes (classic CAN: SafeLine builds without CAN FD). */
#define CAN_MAX_DLEN    8U
/** @} */

/** @name CAN controller mode flags (can_mode_t) */
/** @{ */
/** Normal mode. */
#define CAN_MODE_NORMAL          0
/** The controller receives the frames it sends (internal loopback; nothing reaches the bus). */
#define CAN_MODE_LOOPBACK        BIT(0)
/** The controller only listens: no ACK, no error frames, no transmission. */
#define CAN_MODE_LISTENONLY      BIT(1)
/** CAN FD frames may be sent and received. */
#define CAN_MODE_FD              BIT(2)
/** A frame is transmitted once, without automatic retransmission. */
#define CAN_MODE_ONE_SHOT        BIT(3)
/** Each bit is sampled three times. */
#define CAN_MODE_3_SAMPLES       BIT(4)
/** Bus-off recovery only on can_recover(); otherwise it is automatic. */
#define CAN_MODE_MANUAL_RECOVERY BIT(5)
/** @} */

/** Controller operation mode: a combination of CAN_MODE_* flags. */
typedef uint32_t can_mode_t;

/** State of a CAN controller. */
enum can_state {
	/** Error-active (both error counters below 96). */
	CAN_STATE_ERROR_ACTIVE,
	/** Error-warning (an error counter at 96 or more, both below 128). */
	CAN_STATE_ERROR_WARNING,
	/** Error-passive (an error counter at 128 or more, TX counter at most 255). */
	CAN_STATE_ERROR_PASSIVE,
	/** Bus-off (TX error counter above 255): the controller takes no part in bus traffic. */
	CAN_STATE_BUS_OFF,
	/** The controller is stopped (can_stop() or never started). */
	CAN_STATE_STOPPED,
};

/** @name CAN frame flags */
/** @{ */
/** Extended (29-bit) identifier. */
#define CAN_FRAME_IDE BIT(0)
/** Remote transmission request: no data, @ref can_frame.dlc says how much is requested. */
#define CAN_FRAME_RTR BIT(1)
/** CAN FD frame format. */
#define CAN_FRAME_FDF BIT(2)
/** CAN FD bit rate switch. */
#define CAN_FRAME_BRS BIT(3)
/** CAN FD error state indicator (received frames only). */
#define CAN_FRAME_ESI BIT(4)
/** @} */

/** A CAN frame. */
struct can_frame {
	/** Standard (11-bit) or extended (29-bit) identifier, right-aligned. */
	uint32_t id;
	/** Data length code (0..8 for classic CAN). */
	uint8_t dlc;
	/** CAN_FRAME_* flags. */
	uint8_t flags;
#if defined(CONFIG_CAN_RX_TIMESTAMP) || defined(__DOXYGEN__)
	/**
	 * Receive time from the controller's free-running timer (received frames only).
	 *
	 * The unit is controller specific. SafeLine's native_posix drivers count microseconds on
	 * the kernel's uptime clock (low 16 bits, so the value wraps every 65.536 ms): the virtual
	 * bus stamps the end of the frame on the bus, SocketCAN the kernel's receive time.
	 */
	uint16_t timestamp;
#else
	/** @cond INTERNAL_HIDDEN */
	uint16_t reserved;
	/** @endcond */
#endif
	/** Payload. */
	union {
		/** Payload as bytes. */
		uint8_t data[CAN_MAX_DLEN];
		/** Payload as 32-bit words, for drivers that copy word by word. */
		uint32_t data_32[DIV_ROUND_UP(CAN_MAX_DLEN, sizeof(uint32_t))];
	};
};

/** @name CAN filter flags */
/** @{ */
/** The filter matches extended (29-bit) identifiers; without it, standard ones. */
#define CAN_FILTER_IDE BIT(0)
/** @} */

/**
 * @brief A receive filter: a frame matches when `(frame.id ^ id) & mask` is zero and its
 *        identifier type equals the filter's. Data and remote frames both match.
 */
struct can_filter {
	/** Identifier to match. */
	uint32_t id;
	/** Identifier bits that must equal @ref id (1 = compare). */
	uint32_t mask;
	/** CAN_FILTER_* flags. */
	uint8_t flags;
};

/** CAN controller error counters. */
struct can_bus_err_cnt {
	/** Transmit error counter. */
	uint8_t tx_err_cnt;
	/** Receive error counter. */
	uint8_t rx_err_cnt;
};

/**
 * @brief Transmission done (or aborted).
 *
 * Runs in the driver's context; must not block.
 *
 * @param dev The controller.
 * @param error 0 when the frame was sent; -ENETDOWN if the controller was stopped first;
 *        -ENETUNREACH if it went bus-off first; -ETIMEDOUT if the driver got no
 *        confirmation in time (SocketCAN: no echo); -EIO on another transmit error.
 * @param user_data As passed to can_send().
 */
typedef void (*can_tx_callback_t)(const struct device *dev, int error, void *user_data);

/**
 * @brief A frame matched a receive filter.
 *
 * Runs in the driver's context; must not block. @p frame is a copy owned by the driver, valid
 * until the callback returns; the callback may modify it.
 *
 * @param dev The controller.
 * @param frame The received frame.
 * @param user_data As passed to can_add_rx_filter().
 */
typedef void (*can_rx_callback_t)(const struct device *dev, struct can_frame *frame,
				  void *user_data);

/**
 * @brief The controller changed state.
 *
 * Runs in the driver's context; must not block.
 *
 * @param dev The controller.
 * @param state The new state.
 * @param err_cnt The error counters at the change.
 * @param user_data As passed to can_set_state_change_callback().
 */
typedef void (*can_state_change_callback_t)(const struct device *dev, enum can_state state,
					    struct can_bus_err_cnt err_cnt, void *user_data);

/** @cond INTERNAL_HIDDEN */

/*
 * Driver side. Each driver places these first in its config and data structs, so generic code
 * reads the mode and the state callback without knowing the driver.
 */
struct can_driver_config {
	/* Lowest and highest bit rate the controller supports, in bit/s. */
	uint32_t min_bitrate;
	uint32_t max_bitrate;
	/* Bit rate after init, in bit/s. */
	uint32_t bitrate;
};

struct can_driver_data {
	can_mode_t mode;
	bool started;
	can_state_change_callback_t state_change_cb;
	void *state_change_cb_user_data;
};

/*
 * Operations of a CAN driver. Mandatory: get_capabilities, start, stop, set_mode, send,
 * add_rx_filter, remove_rx_filter, get_state, set_state_change_callback. Optional (NULL makes
 * the API call return -ENOSYS): set_bitrate, recover, get_max_filters.
 */
struct can_driver_api {
	int (*get_capabilities)(const struct device *dev, can_mode_t *cap);
	int (*start)(const struct device *dev);
	int (*stop)(const struct device *dev);
	int (*set_mode)(const struct device *dev, can_mode_t mode);
	int (*set_bitrate)(const struct device *dev, uint32_t bitrate);
	int (*send)(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
		    can_tx_callback_t callback, void *user_data);
	int (*add_rx_filter)(const struct device *dev, can_rx_callback_t callback, void *user_data,
			     const struct can_filter *filter);
	void (*remove_rx_filter)(const struct device *dev, int filter_id);
	int (*recover)(const struct device *dev, k_timeout_t timeout);
	int (*get_state)(const struct device *dev, enum can_state *state,
			 struct can_bus_err_cnt *err_cnt);
	void (*set_state_change_callback)(const struct device *dev,
					  can_state_change_callback_t callback, void *user_data);
	int (*get_max_filters)(const struct device *dev, bool ide);
};

static inline const struct can_driver_api *z_can_api(const struct device *dev)
{
	return (const struct can_driver_api *)dev->api;
}

/** @endcond */

/**
 * @brief Convert a data length code to a number of bytes.
 *
 * @param dlc Data length code (0..15).
 * @return Payload size in bytes (DLC 9..15 are CAN FD sizes 12..64).
 */
static inline uint8_t can_dlc_to_bytes(uint8_t dlc)
{
	static const uint8_t dlc_table[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

	return dlc_table[MIN(dlc, ARRAY_SIZE(dlc_table) - 1U)];
}

/**
 * @brief Convert a number of bytes to the smallest data length code that holds them.
 *
 * @param num_bytes Payload size (0..64).
 * @return Data length code.
 */
static inline uint8_t can_bytes_to_dlc(uint8_t num_bytes)
{
	return num_bytes <= 8U    ? num_bytes
	       : num_bytes <= 12U ? 9U
	       : num_bytes <= 16U ? 10U
	       : num_bytes <= 20U ? 11U
	       : num_bytes <= 24U ? 12U
	       : num_bytes <= 32U ? 13U
	       : num_bytes <= 48U ? 14U
				  : 15U;
}

/**
 * @brief Whether @p frame matches @p filter.
 *
 * @param frame A CAN frame.
 * @param filter A receive filter.
 * @retval true The identifier type is the same and the masked identifier bits are equal.
 * @retval false Otherwise.
 */
static inline bool can_frame_matches_filter(const struct can_frame *frame,
					    const struct can_filter *filter)
{
	if (((frame->flags & CAN_FRAME_IDE) != 0U) != ((filter->flags & CAN_FILTER_IDE) != 0U)) {
		return false;
	}

	return ((frame->id ^ filter->id) & filter->mask) == 0U;
}

/**
 * @brief Get the modes the controller supports.
 *
 * @param dev The controller.
 * @param[out] cap Supported CAN_MODE_* flags.
 * @retval 0 Success.
 * @retval -EIO General input/output error.
 */
static inline int can_get_capabilities(const struct device *dev, can_mode_t *cap)
{
	return z_can_api(dev)->get_capabilities(dev, cap);
}

/**
 * @brief Start the controller: it takes part in bus traffic from now on.
 *
 * @param dev The controller.
 * @retval 0 Success.
 * @retval -EALREADY The controller is already started.
 * @retval -EIO General input/output error (for SocketCAN: the interface could not be used).
 */
static inline int can_start(const struct device *dev)
{
	return z_can_api(dev)->start(dev);
}

/**
 * @brief Stop the controller. Pending transmissions are aborted: their callbacks get
 *        -ENETDOWN. Configuration calls need a stopped controller.
 *
 * @param dev The controller.
 * @retval 0 Success.
 * @retval -EALREADY The controller is already stopped.
 * @retval -EIO General input/output error.
 */
static inline int can_stop(const struct device *dev)
{
	return z_can_api(dev)->stop(dev);
}

/**
 * @brief Set the operation mode (only while stopped).
 *
 * @param dev The controller.
 * @param mode CAN_MODE_* flags.
 * @retval 0 Success.
 * @retval -EBUSY The controller is started.
 * @retval -ENOTSUP A requested mode is not supported.
 * @retval -EIO General input/output error.
 */
static inline int can_set_mode(const struct device *dev, can_mode_t mode)
{
	return z_can_api(dev)->set_mode(dev, mode);
}

/**
 * @brief Get the operation mode.
 *
 * @param dev The controller.
 * @return The current CAN_MODE_* flags.
 */
static inline can_mode_t can_get_mode(const struct device *dev)
{
	return ((const struct can_driver_data *)dev->data)->mode;
}

/**
 * @brief Set the bit rate (only while stopped).
 *
 * @param dev The controller.
 * @param bitrate Bit rate in bit/s.
 * @retval 0 Success.
 * @retval -ENOTSUP The bit rate is outside the controller's range.
 * @retval -EBUSY The controller is started.
 * @retval -ENOSYS The driver cannot set the bit rate.
 * @retval -EIO General input/output error.
 */
static inline int can_set_bitrate(const struct device *dev, uint32_t bitrate)
{
	const struct can_driver_config *common = (const struct can_driver_config *)dev->config;

	if (z_can_api(dev)->set_bitrate == NULL) {
		return -ENOSYS;
	}
	if (bitrate < common->min_bitrate || bitrate > common->max_bitrate) {
		return -ENOTSUP;
	}

	return z_can_api(dev)->set_bitrate(dev, bitrate);
}

/**
 * @brief Queue a frame for transmission.
 *
 * With a @p callback, returns once the frame is queued; the callback reports the outcome.
 * Without one, blocks until the frame is sent (or aborted) and returns the outcome.
 *
 * @param dev The controller.
 * @param frame The frame (copied before return).
 * @param timeout How long to wait for room in the transmit queue.
 * @param callback Completion callback, or NULL to block until done.
 * @param user_data Passed to @p callback.
 * @retval 0 Queued (with a callback) or sent (without).
 * @retval -EINVAL Invalid identifier, DLC or other argument.
 * @retval -ENOTSUP Unsupported frame flags (e.g. CAN FD on a classic controller).
 * @retval -ENETDOWN The controller is stopped.
 * @retval -ENETUNREACH The controller is bus-off.
 * @retval -EBUSY Arbitration lost (one-shot mode only).
 * @retval -EIO Another transmit error.
 * @retval -EAGAIN The transmit queue stayed full for @p timeout.
 */
int can_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
	     can_tx_callback_t callback, void *user_data);

/**
 * @brief Add a receive filter; matching frames are passed to @p callback.
 *
 * @param dev The controller.
 * @param callback Receive callback.
 * @param user_data Passed to @p callback.
 * @param filter The filter (copied).
 * @retval >=0 Filter id, for can_remove_rx_filter().
 * @retval -ENOSPC All filters are in use.
 * @retval -EINVAL Invalid argument (NULL, or id/mask bits outside the identifier type).
 * @retval -ENOTSUP Unsupported filter flags.
 */
int can_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
		      const struct can_filter *filter);

/**
 * @brief Remove a receive filter. Once this returns, its callback is not called again.
 *
 * @param dev The controller.
 * @param filter_id A value returned by can_add_rx_filter().
 */
static inline void can_remove_rx_filter(const struct device *dev, int filter_id)
{
	z_can_api(dev)->remove_rx_filter(dev, filter_id);
}

/**
 * @brief Number of receive filters the controller offers.
 *
 * @param dev The controller.
 * @param ide true for extended-identifier filters, false for standard ones.
 * @retval >=0 Number of filters.
 * @retval -ENOSYS Not reported by the driver.
 */
static inline int can_get_max_filters(const struct device *dev, bool ide)
{
	if (z_can_api(dev)->get_max_filters == NULL) {
		return -ENOSYS;
	}

	return z_can_api(dev)->get_max_filters(dev, ide);
}

/**
 * @brief Define a message queue of @p max_frames CAN frames for can_add_rx_filter_msgq().
 */
#define CAN_MSGQ_DEFINE(name, max_frames)                                                          \
	K_MSGQ_DEFINE(name, sizeof(struct can_frame), max_frames, 4)

/**
 * @brief Add a receive filter whose matching frames are put into @p msgq (without waiting;
 *        a frame that finds the queue full is dropped).
 *
 * @param dev The controller.
 * @param msgq A queue of struct can_frame (CAN_MSGQ_DEFINE()).
 * @param filter The filter (copied).
 * @retval >=0 Filter id.
 * @retval -ENOSPC All filters are in use.
 * @retval -EINVAL Invalid argument.
 * @retval -ENOTSUP Unsupported filter flags.
 */
int can_add_rx_filter_msgq(const struct device *dev, struct k_msgq *msgq,
			   const struct can_filter *filter);

/**
 * @brief Get the controller state and error counters.
 *
 * @param dev The controller.
 * @param[out] state The state, or NULL.
 * @param[out] err_cnt The error counters, or NULL.
 * @retval 0 Success.
 * @retval -EIO General input/output error.
 */
static inline int can_get_state(const struct device *dev, enum can_state *state,
				struct can_bus_err_cnt *err_cnt)
{
	return z_can_api(dev)->get_state(dev, state, err_cnt);
}

/**
 * @brief Recover from bus-off (manual recovery mode only): wait until the controller has seen
 *        the 128 x 11 recessive bits that end bus-off.
 *
 * @param dev The controller.
 * @param timeout How long to wait for the recovery.
 * @retval 0 Recovered (or was not bus-off).
 * @retval -ENOTSUP The controller is not in CAN_MODE_MANUAL_RECOVERY.
 * @retval -ENETDOWN The controller is stopped.
 * @retval -EAGAIN Not recovered within @p timeout.
 * @retval -ENOSYS The driver cannot recover manually.
 */
static inline int can_recover(const struct device *dev, k_timeout_t timeout)
{
	if (z_can_api(dev)->recover == NULL) {
		return -ENOSYS;
	}

	return z_can_api(dev)->recover(dev, timeout);
}

/**
 * @brief Register the state change callback (one per controller; NULL removes it).
 *
 * @param dev The controller.
 * @param callback Called on every state change, in the driver's context.
 * @param user_data Passed to @p callback.
 */
static inline void can_set_state_change_callback(const struct device *dev,
						 can_state_change_callback_t callback,
						 void *user_data)
{
	z_can_api(dev)->set_state_change_callback(dev, callback, user_data);
}

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_DRIVERS_CAN_H_ */
