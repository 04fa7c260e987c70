/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief TIME object (CiA 301 §7.2.6): time stamp producer and consumer (1012h), and the
 *        TIME_OF_DAY conversions.
 *
 * The TIME frame carries a TIME_OF_DAY (CiA 301 §7.1.6.5), 6 bytes little endian:
 * bits 0..27 milliseconds after midnight, bits 28..31 reserved (0), then UNSIGNED16 days
 * since 1984-01-01. The value type is struct co_time (<canopen/types.h>), shared with the
 * object dictionary's TIME_OF_DAY objects.
 *
 * The stack has no wall clock: a producer sends the time the application hands to
 * co_time_req() or reads from its clock callback; a consumer hands every TIME received to
 * the application together with its reception time on the line clock, from which the
 * application corrects its own clock.
 *
 * @defgroup co_time TIME
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_TIME_H_
#define SAFELINE_INCLUDE_CANOPEN_TIME_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/types.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Default COB-ID of TIME. */
#define CO_TIME_COB_ID      0x100U
/** 1012h bit 31: the node consumes TIME. */
#define CO_TIME_COB_CONSUME 0x80000000U
/** 1012h bit 30: the node produces TIME. */
#define CO_TIME_COB_PRODUCE 0x40000000U

/** Length of a TIME frame / a TIME_OF_DAY on the wire [bytes]. */
#define CO_TIME_LEN          6U
/** Milliseconds in a day; a TIME_OF_DAY's ms field is below this. */
#define CO_TIME_MS_PER_DAY   86400000U
/** Mask of the millisecond field (28 bits) of a TIME_OF_DAY. */
#define CO_TIME_MS_MASK      0x0fffffffU
/** 1984-01-01 00:00 UTC, the TIME_OF_DAY epoch, in seconds since the Unix epoch. */
#define CO_TIME_EPOCH_UNIX_S 441763200LL

/** A calendar date and time of day (UTC, proleptic Gregorian calendar, no leap seconds). */
struct co_time_date {
	uint16_t year;   /**< 1984..2163 */
	uint8_t month;   /**< 1..12 */
	uint8_t day;     /**< 1..31 */
	uint8_t hour;    /**< 0..23 */
	uint8_t minute;  /**< 0..59 */
	uint8_t second;  /**< 0..59 */
	uint16_t millis; /**< 0..999 */
};

/**
 * @name TIME_OF_DAY conversions (pure functions, no node needed)
 * @{
 */

/**
 * @brief Encode a TIME_OF_DAY into its 6 wire bytes. The reserved bits 28..31 are sent as 0.
 */
void co_time_encode(const struct co_time *t, uint8_t out[CO_TIME_LEN]);

/**
 * @brief Decode 6 wire bytes into a TIME_OF_DAY. The reserved bits 28..31 are dropped.
 */
void co_time_decode(const uint8_t in[CO_TIME_LEN], struct co_time *t);

/**
 * @brief Convert microseconds since the Unix epoch (UTC) into a TIME_OF_DAY.
 *
 * Sub-millisecond parts are truncated.
 *
 * @retval 0 Converted.
 * @retval -ERANGE Before 1984-01-01 or after day 65535 (2163-06-06).
 */
int co_time_from_unix_us(int64_t unix_us, struct co_time *t);

/**
 * @brief Convert a TIME_OF_DAY into microseconds since the Unix epoch (UTC).
 *
 * @retval 0 Converted.
 * @retval -EINVAL The millisecond field is not below CO_TIME_MS_PER_DAY.
 */
int co_time_to_unix_us(const struct co_time *t, int64_t *unix_us);

/**
 * @brief Convert a calendar date into a TIME_OF_DAY.
 *
 * @retval 0 Converted.
 * @retval -EINVAL A field is out of its range (e.g. 30 February, hour 24).
 * @retval -ERANGE The date is before 1984-01-01 or after 2163-06-06.
 */
int co_time_from_date(const struct co_time_date *d, struct co_time *t);

/**
 * @brief Convert a TIME_OF_DAY into a calendar date.
 *
 * @retval 0 Converted.
 * @retval -EINVAL The millisecond field is not below CO_TIME_MS_PER_DAY.
 */
int co_time_to_date(const struct co_time *t, struct co_time_date *d);

/** @} */

/**
 * @brief Clock of a TIME producer: fill @p now with the current time of day.
 *
 * Called from co_time_req() (in the caller's thread) with the node's mutex held; must not
 * block.
 *
 * @retval 0 @p now is valid.
 * @retval <0 No time available (the error is returned by co_time_req()).
 */
typedef int (*co_time_clock_t)(struct co_node *node, struct co_time *now, void *user_data);

/**
 * @brief TIME indication: a TIME frame was received (consumer, 1012h bit 31).
 *
 * Runs in the line thread with the node's mutex held; must not block.
 *
 * @param node The consuming node.
 * @param t The time received (reserved bits cleared, ms below CO_TIME_MS_PER_DAY).
 * @param rx_us Reception time of the frame on the line clock [µs] (co_line_time()).
 * @param user_data As registered.
 */
typedef void (*co_time_ind_t)(struct co_node *node, const struct co_time *t, uint64_t rx_us,
			      void *user_data);

/**
 * @brief State of a node's TIME service (embedded in struct co_node as `time`).
 *
 * Named co_time_svc because struct co_time is the TIME_OF_DAY value type.
 */
struct co_time_svc {
	/** @cond INTERNAL_HIDDEN */
	struct co_rx rx;
	uint32_t cob_id;
	bool enabled;
	co_time_clock_t clock;
	void *clock_user_data;
	co_time_ind_t ind;
	void *ind_user_data;
	uint32_t ignored;
	/** @endcond */
};

/**
 * @brief Send a TIME frame (producer).
 *
 * Takes the node's mutex.
 *
 * @param node The node.
 * @param t The time to send, or NULL to read it from the clock set with co_time_set_clock().
 *
 * @retval 0 Sent or queued on the line.
 * @retval -EINVAL @p node is NULL, @p t is NULL and no clock is set, or the millisecond field
 *         is not below CO_TIME_MS_PER_DAY.
 * @retval -ENOTSUP The node is not a TIME producer (1012h absent or bit 30 clear).
 * @retval -ENETDOWN The node is not in Pre-operational or Operational.
 * @retval <0 The clock's error, or co_line_send()'s.
 */
int co_time_req(struct co_node *node, const struct co_time *t);

/** @brief Set the producer's clock (NULL removes it). */
void co_time_set_clock(struct co_node *node, co_time_clock_t cb, void *user_data);

/** @brief Set the TIME indication (NULL removes it). */
void co_time_set_ind(struct co_node *node, co_time_ind_t cb, void *user_data);

/**
 * @brief TIME frames the consumer ignored since the last reset communication: wrong length
 *        (not 6 bytes), RTR, or a millisecond field not below CO_TIME_MS_PER_DAY.
 */
uint32_t co_time_get_ignored(struct co_node *node);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_TIME_H_ */
