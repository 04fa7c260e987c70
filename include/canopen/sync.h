/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief SYNC object (CiA 301 §7.2.5): producer and consumer (1005h, 1006h, 1007h, 1019h).
 *
 * @defgroup co_sync SYNC
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_SYNC_H_
#define SAFELINE_INCLUDE_CANOPEN_SYNC_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/line.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Default COB-ID of SYNC. */
#define CO_SYNC_COB_ID 0x080U

/**
 * @brief SYNC indication: a SYNC was received, or sent by this node as the producer.
 *
 * Two indications may be set: the one of co_sync_set_ind() runs before the synchronous PDOs
 * of this SYNC are processed (e.g. to refresh the inputs the TPDOs sample), the one of
 * co_sync_set_post_ind() after (the synchronous RPDOs have been committed).
 *
 * Runs in the line thread with the node's mutex held; must not block.
 *
 * @param node The node.
 * @param counter The SYNC counter (1..1019h), or 0 for a SYNC without counter.
 * @param user_data As registered.
 */
typedef void (*co_sync_ind_t)(struct co_node *node, uint8_t counter, void *user_data);

/** @cond INTERNAL_HIDDEN */
struct co_sync {
	struct co_rx rx;
	struct co_timer timer;
	uint32_t cob_id;
	uint32_t period_us;
	uint32_t window_us; /* 1007h */
	uint8_t overflow;
	uint8_t counter;
	bool enabled;
	/* 8240h (wrong SYNC length) is reported as present. */
	bool length_error;
	co_sync_ind_t ind;
	void *ind_user_data;
	co_sync_ind_t post_ind;
	void *post_ind_user_data;
};
/** @endcond */

/** @brief Set the SYNC indication called before the synchronous PDOs (NULL removes it). */
void co_sync_set_ind(struct co_node *node, co_sync_ind_t cb, void *user_data);

/** @brief Set the SYNC indication called after the synchronous PDOs (NULL removes it). */
void co_sync_set_post_ind(struct co_node *node, co_sync_ind_t cb, void *user_data);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_SYNC_H_ */
