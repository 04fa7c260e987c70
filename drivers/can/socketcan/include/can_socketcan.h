/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Test helpers of the SocketCAN driver (not Zephyr API).
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
