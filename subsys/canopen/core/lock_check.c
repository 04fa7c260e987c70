/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* The lock rule's alarm (lock_check.h). */

#include <zephyr/kernel.h>
#include <zephyr/sys/printk.h>

#include "lock_check.h"

void co_lock_violation(const struct k_mutex *lock, const char *file, int line)
{
	/* printk, not the log: the message must show even in an image built without logging. */
	printk("lock rule broken at %s:%d: the caller does not hold the node's mutex %p "
	       "(co_node_lock() first; doc/architecture.md, \"Locks\")\n",
	       file, line, (const void *)lock);
	k_panic();
}
