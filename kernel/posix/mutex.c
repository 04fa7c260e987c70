/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_mutex: recursive, owned, with priority inheritance.
 *
 * While a thread of higher priority waits, the owner runs at the waiter's priority; when the
 * wait ends (lock handed over or timed out) the owner drops back to the priority it had when
 * it took the mutex, or to that of the remaining highest waiter. On unlock the mutex goes
 * straight to the highest-priority waiter. This follows Zephyr's single-level inheritance.
 */

#include <errno.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

int k_mutex_init(struct k_mutex *mutex)
{
	z_waitq_init(&mutex->wait_q);
	__atomic_store_n(&mutex->owner, NULL, __ATOMIC_RELAXED);
	mutex->lock_count = 0U;
	mutex->owner_orig_prio = K_LOWEST_APPLICATION_THREAD_PRIO;

	return 0;
}

static int new_prio_for_inheritance(int target, int limit)
{
	return z_is_prio_higher(target, limit) ? target : limit;
}

static void adjust_owner_prio(struct k_mutex *mutex, int new_prio)
{
	if (mutex->owner->base.prio != new_prio) {
		z_thread_prio_set_locked(mutex->owner, new_prio);
	}
}

int k_mutex_lock(struct k_mutex *mutex, k_timeout_t timeout)
{
	struct k_thread *cur;
	struct k_thread *waiter;
	int new_prio;
	int ret;

	z_lock();
	cur = z_current();
	if (mutex->lock_count == 0U || mutex->owner == cur) {
		mutex->owner_orig_prio =
			(mutex->lock_count == 0U) ? cur->base.prio : mutex->owner_orig_prio;
		mutex->lock_count++;
		/* Atomic: lock-rule checks read the owner without the kernel lock. */
		__atomic_store_n(&mutex->owner, cur, __ATOMIC_RELAXED);
		z_unlock();
		return 0;
	}

	if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		z_unlock();
		return -EBUSY;
	}

	new_prio = new_prio_for_inheritance(cur->base.prio, mutex->owner->base.prio);
	if (z_is_prio_higher(new_prio, mutex->owner->base.prio)) {
		adjust_owner_prio(mutex, new_prio);
	}

	ret = z_pend_curr(&mutex->wait_q, timeout);
	if (ret == 0) {
		/* k_mutex_unlock() made us the owner. */
		z_unlock();
		return 0;
	}

	/* Timed out: the owner keeps only the boost that remaining waiters justify. */
	if (mutex->owner != NULL) {
		waiter = z_waitq_head(&mutex->wait_q);
		new_prio = mutex->owner_orig_prio;
		if (waiter != NULL) {
			new_prio = new_prio_for_inheritance(waiter->base.prio, new_prio);
		}
		adjust_owner_prio(mutex, new_prio);
	}
	z_unlock();

	return -EAGAIN;
}

int k_mutex_unlock(struct k_mutex *mutex)
{
	struct k_thread *new_owner;

	z_lock();
	if (mutex->owner == NULL) {
		z_unlock();
		return -EINVAL;
	}
	if (mutex->owner != z_current()) {
		z_unlock();
		return -EPERM;
	}

	if (mutex->lock_count > 1U) {
		mutex->lock_count--;
		z_unlock();
		return 0;
	}

	adjust_owner_prio(mutex, mutex->owner_orig_prio);

	new_owner = z_unpend_first_thread(&mutex->wait_q);
	__atomic_store_n(&mutex->owner, new_owner, __ATOMIC_RELAXED);
	if (new_owner != NULL) {
		/* Hand over directly: the lock count stays 1 for the new owner. */
		mutex->owner_orig_prio = new_owner->base.prio;
		z_ready_thread(new_owner, 0);
	} else {
		mutex->lock_count = 0U;
	}
	z_unlock();

	return 0;
}
