/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Driver-independent parts of the CAN API: argument checks shared by all drivers, the
 * blocking form of can_send() and message-queue filters.
 */

#include <errno.h>

#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>

#include "can_filter_table.h"

struct can_tx_sync_ctx {
	struct k_sem done;
	int status;
};

static void can_tx_sync_cb(const struct device *dev, int error, void *user_data)
{
	struct can_tx_sync_ctx *ctx = user_data;

	ctx->status = error;
	k_sem_give(&ctx->done);
}

int can_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
	     can_tx_callback_t callback, void *user_data)
{
	const struct can_driver_api *api;
	struct can_tx_sync_ctx ctx;
	int err;

	if (dev == NULL || frame == NULL) {
		return -EINVAL;
	}
	api = z_can_api(dev);
	if ((frame->flags & CAN_FRAME_IDE) != 0U) {
		if (frame->id > CAN_EXT_ID_MASK) {
			return -EINVAL;
		}
	} else if (frame->id > CAN_STD_ID_MASK) {
		return -EINVAL;
	} else {
		/* A standard identifier within 11 bits: valid. */
	}
	if ((frame->flags & CAN_FRAME_FDF) != 0U) {
		if (frame->dlc > CANFD_MAX_DLC) {
			return -EINVAL;
		}
	} else if (frame->dlc > CAN_MAX_DLC) {
		return -EINVAL;
	} else {
		/* A classic frame of at most 8 bytes: valid. */
	}

	if (callback != NULL) {
		return api->send(dev, frame, timeout, callback, user_data);
	}

	/* Blocking form: the timeout bounds the wait for queue space, not the transmission. */
	(void)k_sem_init(&ctx.done, 0, 1);
	ctx.status = -EIO;
	err = api->send(dev, frame, timeout, can_tx_sync_cb, &ctx);
	if (err != 0) {
		return err;
	}
	(void)k_sem_take(&ctx.done, K_FOREVER);

	return ctx.status;
}

int can_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
		      const struct can_filter *filter)
{
	uint32_t id_mask;

	if (dev == NULL || callback == NULL || filter == NULL) {
		return -EINVAL;
	}
	id_mask = ((filter->flags & CAN_FILTER_IDE) != 0U) ? CAN_EXT_ID_MASK : CAN_STD_ID_MASK;
	if ((filter->id & ~id_mask) != 0U || (filter->mask & ~id_mask) != 0U) {
		return -EINVAL;
	}
	if ((filter->flags & ~CAN_FILTER_IDE) != 0U) {
		return -ENOTSUP;
	}

	return z_can_api(dev)->add_rx_filter(dev, callback, user_data, filter);
}

static void can_msgq_put(const struct device *dev, struct can_frame *frame, void *user_data)
{
	struct k_msgq *msgq = user_data;

	/* Driver context: never wait; a full queue loses the frame, as in Zephyr. */
	(void)k_msgq_put(msgq, frame, K_NO_WAIT);
}

int can_add_rx_filter_msgq(const struct device *dev, struct k_msgq *msgq,
			   const struct can_filter *filter)
{
	if (msgq == NULL) {
		return -EINVAL;
	}

	return can_add_rx_filter(dev, can_msgq_put, msgq, filter);
}

int can_filter_table_add(struct can_filter_slot *slots, int n, struct k_mutex *lock,
			 can_rx_callback_t cb, void *user_data, const struct can_filter *filter)
{
	int id = -ENOSPC;

	(void)k_mutex_lock(lock, K_FOREVER);
	for (int i = 0; i < n; i++) {
		if (slots[i].cb == NULL) {
			slots[i].cb = cb;
			slots[i].user_data = user_data;
			slots[i].filter = *filter;
			id = i;
			break;
		}
	}
	(void)k_mutex_unlock(lock);
	return id;
}

void can_filter_table_remove(struct can_filter_slot *slots, int n, struct k_mutex *lock, int id)
{
	if (id < 0 || id >= n) {
		return;
	}
	(void)k_mutex_lock(lock, K_FOREVER);
	slots[id].cb = NULL;
	(void)k_mutex_unlock(lock);
}

void can_filter_table_deliver(const struct device *dev, struct can_filter_slot *slots, int n,
			      struct k_mutex *lock, const struct can_frame *frame)
{
	(void)k_mutex_lock(lock, K_FOREVER);
	for (int i = 0; i < n; i++) {
		struct can_filter_slot *s = &slots[i];

		if (s->cb != NULL && can_frame_matches_filter(frame, &s->filter)) {
			struct can_frame copy = *frame;

			s->cb(dev, &copy, s->user_data);
		}
	}
	(void)k_mutex_unlock(lock);
}
