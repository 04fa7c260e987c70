/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The manager gives node-IDs to missing slaves by LSS (CONFIG_CANOPEN_MGR_LSS_ASSIGN).
 *
 * A slave assigned in 1F81h with its vendor-ID in 1F85h whose boot ends with status B (no
 * answer) is searched by fastscan among the devices without node-ID: vendor-ID, product code
 * (1F86h) and serial number (1F88h) are known parts when not 0, the revision is scanned and
 * checked against 1F87h as the boot checks it. The device found gets the slave's node-ID,
 * stores it and is switched back to waiting, so it boots with it (boot-up) and the manager's
 * boot retry picks it up. See doc/mgr.md, "Node-IDs by LSS".
 *
 * @ingroup co_mgr
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_MGR_LSS_H_
#define SAFELINE_INCLUDE_CANOPEN_MGR_LSS_H_

#include <stdint.h>

#include <canopen/event.h>
#include <canopen/lss_master.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/**
 * @brief Result of the LSS search for one slave.
 *
 * Runs in the line thread with the node's mutex held; must not block.
 *
 * @param node The manager's node.
 * @param id The slave's node-ID.
 * @param err 0 the device was found, has the node-ID and was switched to waiting (it
 *        boots); -ENODEV no device without node-ID matched; -EILSEQ one matched 1F85h,
 *        1F86h and 1F88h but not the revision 1F87h (left without node-ID); -EREMOTEIO the
 *        device refused the node-ID; -ETIMEDOUT it did not answer the node-ID; a store that
 *        failed is logged only (the device boots, but forgets its node-ID at power-off).
 * @param addr The LSS address found (err 0 or -EILSEQ), else NULL.
 * @param user_data As registered.
 */
typedef void (*co_mgr_lss_ind_t)(struct co_node *node, uint8_t id, int err,
				 const struct co_lss_address *addr, void *user_data);

/** @cond INTERNAL_HIDDEN */
struct co_mgr_lss {
	struct co_listener listener;
	/* Slaves waiting for a search, and slaves searched since the master's last reset. */
	uint32_t pending[4];
	uint32_t searched[4];
	/* The slave searched now (0: none) and where its assignment stands. */
	uint8_t id;
	uint8_t step;
	struct co_lss_address found;
	co_mgr_lss_ind_t ind;
	void *ind_user_data;
};
/** @endcond */

/** @brief Set the indication of the LSS searches (NULL removes it). */
void co_mgr_set_lss_ind(struct co_node *node, co_mgr_lss_ind_t cb, void *user_data);

/**
 * @brief Search slave @p id by LSS now (as a boot ending with B would).
 *
 * @retval 0 Queued (the result comes through the indication).
 * @retval -EINVAL @p id outside 1..127, not assigned in 1F81h, or 1F85h is 0.
 */
int co_mgr_lss_search(struct co_node *node, uint8_t id);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_MGR_LSS_H_ */
