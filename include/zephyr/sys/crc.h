/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The CRC function of Zephyr's <zephyr/sys/crc.h> that the stack uses.
 */

#ifndef SAFELINE_INCLUDE_ZEPHYR_SYS_CRC_H_
#define SAFELINE_INCLUDE_ZEPHYR_SYS_CRC_H_

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief CRC-16-ITU-T (polynomial 1021h, MSB first, no final XOR), as in Zephyr.
 *
 * With @p seed 0 this is the CRC of CANopen's SDO block transfer and SRDO signature
 * ("123456789" gives 31C3h).
 *
 * @param seed Start value, or the CRC of the data before @p src.
 * @param src Bytes.
 * @param len Number of bytes.
 * @return The CRC.
 */
uint16_t crc16_itu_t(uint16_t seed, const uint8_t *src, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_ZEPHYR_SYS_CRC_H_ */
