/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CiA 301 SDO abort codes, shared by every service.
 *
 * Protocol refusals are reported as these uint32_t codes (CiA 301 §7.2.4.3.17), never as
 * errno values. The object dictionary returns them for every refused access, so the SDO
 * server forwards them unchanged and PDO/SRDO/MPDO code can map them to EMCY reactions.
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SDO_ABORT_H_
#define SAFELINE_INCLUDE_CANOPEN_SDO_ABORT_H_

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Every CiA 301 SDO abort code: X(name suffix, code, meaning).
 *
 * The CO_SDO_AB_* macros below are the names to use in code; this table exists so that
 * tools and tests can enumerate the codes and their texts.
 */
#define CO_SDO_ABORT_TABLE(X)                                                                      \
	X(TOGGLE, 0x05030000U, "Toggle bit not alternated")                                        \
	X(TIMEOUT, 0x05040000U, "SDO protocol timed out")                                          \
	X(CMD, 0x05040001U, "Client/server command specifier not valid or unknown")                \
	X(BLK_SIZE, 0x05040002U, "Invalid block size")                                             \
	X(SEQ_NUM, 0x05040003U, "Invalid sequence number")                                         \
	X(CRC, 0x05040004U, "CRC error")                                                           \
	X(OUT_OF_MEM, 0x05040005U, "Out of memory")                                                \
	X(UNSUPP_ACCESS, 0x06010000U, "Unsupported access to an object")                           \
	X(WRITEONLY, 0x06010001U, "Attempt to read a write only object")                           \
	X(READONLY, 0x06010002U, "Attempt to write a read only object")                            \
	X(NO_OBJECT, 0x06020000U, "Object does not exist in the object dictionary")                \
	X(NO_MAP, 0x06040041U, "Object cannot be mapped to the PDO")                               \
	X(MAP_LEN, 0x06040042U,                                                                    \
	  "Number and length of objects to be mapped would exceed PDO length")                     \
	X(PARAM_INCOMPAT, 0x06040043U, "General parameter incompatibility")                        \
	X(DEV_INCOMPAT, 0x06040047U, "General internal incompatibility in the device")             \
	X(HW, 0x06060000U, "Access failed due to a hardware error")                                \
	X(TYPE_MISMATCH, 0x06070010U,                                                              \
	  "Data type does not match, length of parameter does not match")                          \
	X(DATA_LONG, 0x06070012U, "Data type does not match, length of parameter too high")        \
	X(DATA_SHORT, 0x06070013U, "Data type does not match, length of parameter too low")        \
	X(NO_SUB, 0x06090011U, "Sub-index does not exist")                                         \
	X(INVALID_VALUE, 0x06090030U, "Invalid value for parameter")                               \
	X(VALUE_HIGH, 0x06090031U, "Value of parameter written too high")                          \
	X(VALUE_LOW, 0x06090032U, "Value of parameter written too low")                            \
	X(MAX_LESS_MIN, 0x06090036U, "Maximum value is less than minimum value")                   \
	X(NO_RESOURCE, 0x060A0023U, "Resource not available: SDO connection")                      \
	X(GENERAL, 0x08000000U, "General error")                                                   \
	X(DATA_XFER, 0x08000020U, "Data cannot be transferred or stored to the application")       \
	X(DATA_LOC_CTRL, 0x08000021U,                                                              \
	  "Data cannot be transferred or stored to the application because of local control")      \
	X(DATA_DEV_STATE, 0x08000022U,                                                             \
	  "Data cannot be transferred or stored to the application because of the device state")   \
	X(DATA_OD, 0x08000023U, "Object dictionary dynamic generation failed or no OD present")    \
	X(NO_DATA, 0x08000024U, "No data available")

/** No abort: the access succeeded. */
#define CO_SDO_AB_NONE           0x00000000U
/** Toggle bit not alternated. */
#define CO_SDO_AB_TOGGLE         0x05030000U
/** SDO protocol timed out. */
#define CO_SDO_AB_TIMEOUT        0x05040000U
/** Client/server command specifier not valid or unknown. */
#define CO_SDO_AB_CMD            0x05040001U
/** Invalid block size (block mode only). */
#define CO_SDO_AB_BLK_SIZE       0x05040002U
/** Invalid sequence number (block mode only). */
#define CO_SDO_AB_SEQ_NUM        0x05040003U
/** CRC error (block mode only). */
#define CO_SDO_AB_CRC            0x05040004U
/** Out of memory. */
#define CO_SDO_AB_OUT_OF_MEM     0x05040005U
/** Unsupported access to an object. */
#define CO_SDO_AB_UNSUPP_ACCESS  0x06010000U
/** Attempt to read a write only object. */
#define CO_SDO_AB_WRITEONLY      0x06010001U
/** Attempt to write a read only object. */
#define CO_SDO_AB_READONLY       0x06010002U
/** Object does not exist in the object dictionary. */
#define CO_SDO_AB_NO_OBJECT      0x06020000U
/** Object cannot be mapped to the PDO. */
#define CO_SDO_AB_NO_MAP         0x06040041U
/** Number and length of the objects to be mapped would exceed the PDO length. */
#define CO_SDO_AB_MAP_LEN        0x06040042U
/** General parameter incompatibility. */
#define CO_SDO_AB_PARAM_INCOMPAT 0x06040043U
/** General internal incompatibility in the device. */
#define CO_SDO_AB_DEV_INCOMPAT   0x06040047U
/** Access failed due to a hardware error. */
#define CO_SDO_AB_HW             0x06060000U
/** Data type does not match; length of service parameter does not match. */
#define CO_SDO_AB_TYPE_MISMATCH  0x06070010U
/** Data type does not match; length of service parameter too high. */
#define CO_SDO_AB_DATA_LONG      0x06070012U
/** Data type does not match; length of service parameter too low. */
#define CO_SDO_AB_DATA_SHORT     0x06070013U
/** Sub-index does not exist. */
#define CO_SDO_AB_NO_SUB         0x06090011U
/** Invalid value for parameter (download only). */
#define CO_SDO_AB_INVALID_VALUE  0x06090030U
/** Value of parameter written too high (download only). */
#define CO_SDO_AB_VALUE_HIGH     0x06090031U
/** Value of parameter written too low (download only). */
#define CO_SDO_AB_VALUE_LOW      0x06090032U
/** Maximum value is less than minimum value. */
#define CO_SDO_AB_MAX_LESS_MIN   0x06090036U
/** Resource not available: SDO connection. */
#define CO_SDO_AB_NO_RESOURCE    0x060A0023U
/** General error. */
#define CO_SDO_AB_GENERAL        0x08000000U
/** Data cannot be transferred or stored to the application. */
#define CO_SDO_AB_DATA_XFER      0x08000020U
/** Data cannot be transferred or stored to the application because of local control. */
#define CO_SDO_AB_DATA_LOC_CTRL  0x08000021U
/** Data cannot be transferred or stored to the application because of the device state. */
#define CO_SDO_AB_DATA_DEV_STATE 0x08000022U
/** Object dictionary dynamic generation failed or no object dictionary is present. */
#define CO_SDO_AB_DATA_OD        0x08000023U
/** No data available. */
#define CO_SDO_AB_NO_DATA        0x08000024U

/**
 * @brief Text of an SDO abort code, for logs and tools.
 *
 * @param code abort code
 * @return the CiA 301 meaning, or "Unknown abort code"
 */
static inline const char *co_sdo_abort_str(uint32_t code)
{
	switch (code) {
	case CO_SDO_AB_NONE:
		return "No abort";
#define CO_SDO_ABORT_CASE_(name, val, text)                                                        \
	case val:                                                                                  \
		return text;
		CO_SDO_ABORT_TABLE(CO_SDO_ABORT_CASE_)
#undef CO_SDO_ABORT_CASE_
	default:
		return "Unknown abort code";
	}
}

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_SDO_ABORT_H_ */
