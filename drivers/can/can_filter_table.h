/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Software receive filters shared by the native_posix CAN drivers: a fixed table of
 * (callback, filter) slots under the driver's RX lock. Not Zephyr API; drivers only.
 */

#ifndef SAFELINE_DRIVERS_CAN_FILTER_TABLE_H_
#define SAFELINE_DRIVERS_CAN_FILTER_TABLE_H_

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>

struct can_filter_slot {
	can_rx_callback_t cb; /* NULL: free */
	void *user_data;
	struct can_filter filter;
};

/* Take a free slot: its index, or -ENOSPC. */
int can_filter_table_add(struct can_filter_slot *slots, int n, struct k_mutex *lock,
			 can_rx_callback_t cb, void *user_data, const struct can_filter *filter);

/* Free a slot; out-of-range ids are ignored. Once it returns the callback is never called. */
void can_filter_table_remove(struct can_filter_slot *slots, int n, struct k_mutex *lock, int id);

/* Call every matching callback, each with its own copy of the frame (callbacks may modify it). */
void can_filter_table_deliver(const struct device *dev, struct can_filter_slot *slots, int n,
			      struct k_mutex *lock, const struct can_frame *frame);

#endif /* SAFELINE_DRIVERS_CAN_FILTER_TABLE_H_ */
