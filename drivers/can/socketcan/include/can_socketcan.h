/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Statistics and test helpers of the SocketCAN driver (not Zephyr API).
 */

#ifndef SAFELINE_DRIVERS_CAN_SOCKETCAN_H_
#define SAFELINE_DRIVERS_CAN_SOCKETCAN_H_

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief The Linux interface a SocketCAN controller uses.
 *
 * @return Interface name, or NULL if @p dev is not a SocketCAN controller.
 */
const char *can_socketcan_ifname(const struct device *dev);

/** @brief What a SocketCAN controller's socket has seen since it was opened. */
struct can_socketcan_stats {
	/** Data and remote frames read from the socket, own echoes not counted: what the
	 *  kernel filter let through. */
	uint32_t rx_frames;
	/** Frames the kernel dropped because the socket's receive buffer was full
	 *  (SO_RXQ_OVFL), as of the last frame read. */
	uint32_t rx_overflows;
	/** Frames confirmed by their echo (TX callback 0). */
	uint32_t tx_confirmed;
	/** Frames released because no echo came for CONFIG_CAN_SOCKETCAN_TX_ECHO_TIMEOUT_MS
	 *  (TX callback -ETIMEDOUT). */
	uint32_t tx_echo_timeouts;
	/** Frames released because a later frame's echo came first, so theirs was lost
	 *  (TX callback -ETIMEDOUT). */
	uint32_t tx_echoes_lost;
	/** Echoes that matched no frame in flight (of frames released before). */
	uint32_t tx_late_echoes;
	/** Entries in the socket's kernel filter now: receive filters plus sent identifiers. */
	uint16_t kernel_filters;
};

/**
 * @brief Read a SocketCAN controller's socket statistics.
 *
 * @retval 0 Copied into @p stats.
 * @retval -EINVAL @p dev is not a SocketCAN controller or @p stats is NULL.
 */
int can_socketcan_get_stats(const struct device *dev, struct can_socketcan_stats *stats);

/**
 * @brief Write the Linux error frame that announces @p state onto the controller's interface,
 *        as `cansend <if> 20000040#0000000000000000` does for bus-off. On vcan it loops back
 *        to every socket with an error filter, including the controller's own, which then
 *        changes state exactly as it would for a real controller's report.
 *
 * Error frames: active CAN_ERR_RESTARTED; warning and passive CAN_ERR_CRTL with the TX
 * warning/passive bit; bus-off CAN_ERR_BUSOFF.
 *
 * @retval 0 Written.
 * @retval -EINVAL @p dev is not a SocketCAN controller or @p state is CAN_STATE_STOPPED.
 * @retval -EIO The controller has no socket.
 * @retval <0 The negative errno of the write.
 */
int can_socketcan_inject_state(const struct device *dev, enum can_state state);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_DRIVERS_CAN_SOCKETCAN_H_ */
