/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Pieces of the SDO protocol (CiA 301 §7.2.4.3) shared by the SDO server and client: the
 * layout of byte 0 of every SDO frame. The block-transfer CRC is Zephyr's crc16_itu_t().
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_SDO_SDO_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_SDO_SDO_INTERNAL_H_

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Every SDO frame has 8 data bytes (CiA 301 §7.2.4.3). */
#define CO_SDO_DLC 8U

/** Data bytes of a segment (segmented transfer and block sub-block). */
#define CO_SDO_SEG_SIZE 7U

/** Data bytes of an expedited transfer. */
#define CO_SDO_EXP_SIZE 4U

/** Largest block size (segments per sub-block), CiA 301 §7.2.4.3.9. */
#define CO_SDO_BLKSIZE_MAX 127U

/** Command specifier: bits 7..5 of byte 0. */
#define CO_SDO_CS(b)      ((uint8_t)((b) >> 5))
/** Byte 0 with command specifier @p cs and the low bits @p lo. */
#define CO_SDO_B0(cs, lo) ((uint8_t)(((cs) << 5) | (lo)))

/**
 * @name Client command specifiers (ccs), client to server
 * @{
 */
#define CO_SDO_CCS_DN_SEG  0U /**< download segment request */
#define CO_SDO_CCS_DN_INIT 1U /**< initiate download request */
#define CO_SDO_CCS_UP_INIT 2U /**< initiate upload request */
#define CO_SDO_CCS_UP_SEG  3U /**< upload segment request */
#define CO_SDO_CCS_BLK_UP  5U /**< every client frame of a block upload */
#define CO_SDO_CCS_BLK_DN  6U /**< every client frame of a block download */
/** @} */

/**
 * @name Server command specifiers (scs), server to client
 * @{
 */
#define CO_SDO_SCS_UP_SEG  0U /**< upload segment response */
#define CO_SDO_SCS_DN_SEG  1U /**< download segment response */
#define CO_SDO_SCS_UP_INIT 2U /**< initiate upload response */
#define CO_SDO_SCS_DN_INIT 3U /**< initiate download response */
#define CO_SDO_SCS_BLK_DN  5U /**< every server frame of a block download */
#define CO_SDO_SCS_BLK_UP  6U /**< every server frame of a block upload */
/** @} */

/** Abort transfer, both directions; byte 0 is 80h. */
#define CO_SDO_CS_ABORT    4U
/** Reserved command specifier (always answered with 05040001h). */
#define CO_SDO_CS_RESERVED 7U

/**
 * @name Initiate download/upload: byte 0 bits
 * @{
 */
#define CO_SDO_INIT_S        0x01U /**< size indicated */
#define CO_SDO_INIT_E        0x02U /**< expedited */
/** Bytes of 4..7 that hold no data (valid with e = 1 and s = 1). */
#define CO_SDO_INIT_N(b)     (((b) >> 2) & 0x3U)
#define CO_SDO_INIT_N_PUT(n) ((uint8_t)(((n) & 0x3U) << 2))
/** @} */

/**
 * @name Download/upload segment: byte 0 bits
 * @{
 */
#define CO_SDO_SEG_C        0x01U /**< last segment */
#define CO_SDO_SEG_T        0x10U /**< toggle */
/** Bytes of 1..7 that hold no data. */
#define CO_SDO_SEG_N(b)     (((b) >> 1) & 0x7U)
#define CO_SDO_SEG_N_PUT(n) ((uint8_t)(((n) & 0x7U) << 1))
/** @} */

/**
 * @name Block transfer: byte 0 bits
 * @{
 */
#define CO_SDO_BLK_CRC       0x04U /**< cc (client) / sc (server): CRC supported */
#define CO_SDO_BLK_S         0x02U /**< size indicated */
/** Bytes of the last segment that hold no data (end frames). */
#define CO_SDO_BLK_N(b)      (((b) >> 2) & 0x7U)
#define CO_SDO_BLK_N_PUT(n)  ((uint8_t)(((n) & 0x7U) << 2))
/** Block download subcommand of client frames (cs, bit 0). */
#define CO_SDO_BLK_DN_CS(b)  ((b) & 0x1U)
/** Block upload subcommand of client frames (cs, bits 1..0). */
#define CO_SDO_BLK_UP_CS(b)  ((b) & 0x3U)
/** Block download server subcommands (ss, bits 1..0) and block upload client ones (cs). */
#define CO_SDO_BLK_SUB_INIT  0U /**< initiate */
#define CO_SDO_BLK_SUB_END   1U /**< end */
#define CO_SDO_BLK_SUB_ACK   2U /**< block acknowledge */
#define CO_SDO_BLK_SUB_START 3U /**< start upload (block upload, client) */
/** Block upload server frames: ss, bit 0 (0 initiate response, 1 end request). */
#define CO_SDO_BLK_UP_SS_END 0x01U
/** Sub-block segment: last segment of the transfer. */
#define CO_SDO_BLK_SEG_C     0x80U
/** Sub-block segment: sequence number 1..127. */
#define CO_SDO_BLK_SEQNO(b)  ((b) & 0x7fU)
/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_SUBSYS_CANOPEN_SDO_SDO_INTERNAL_H_ */
