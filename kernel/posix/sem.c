/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_sem: counting semaphore. A give goes straight to the highest-priority waiter, so a
 * thread arriving later cannot take the count first.
 */

#include <errno.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

int k_sem_init(struct k_sem *sem, unsigned int initial_count, unsigned int limit)
{
	if (limit == 0U || initial_count > limit) {
		return -EINVAL;
	}
	z_waitq_init(&sem->wait_q);
	sem->count = initial_count;
	sem->limit = limit;

	return 0;
}

void z_sem_give_locked(struct k_sem *sem)
{
	if (!z_sched_wake(&sem->wait_q, 0)) {
		sem->count += (sem->count != sem->limit) ? 1U : 0U;
	}
}

void k_sem_give(struct k_sem *sem)
{
	z_lock();
	z_sem_give_locked(sem);
	z_unlock();
}

int k_sem_take(struct k_sem *sem, k_timeout_t timeout)
{
	int ret;

	z_lock();
	if (sem->count > 0U) {
		sem->count--;
		ret = 0;
	} else if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		ret = -EBUSY;
	} else {
		ret = z_pend_curr(&sem->wait_q, timeout);
	}
	z_unlock();

	return ret;
}

void k_sem_reset(struct k_sem *sem)
{
	z_lock();
	(void)z_sched_wake_all(&sem->wait_q, -EAGAIN);
	sem->count = 0U;
	z_unlock();
}

unsigned int k_sem_count_get(struct k_sem *sem)
{
	unsigned int count;

	z_lock();
	count = sem->count;
	z_unlock();

	return count;
}
