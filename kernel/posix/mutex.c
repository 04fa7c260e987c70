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
 *
 * An uncontended lock or unlock is one atomic operation on the mutex's state word and takes
 * no kernel lock, as a futex: 0 free, 1 locked, 2 locked with waiters possible. Only a thread
 * that has to wait, and the unlock that finds state 2 (or a raised priority to drop), take
 * the kernel lock. Fields only the owner touches (lock_count) need no atomics: ownership
 * passes through the state word (acquire/release) or through the kernel lock at a handover.
 */

#include <errno.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

#define M_FREE      0
#define M_LOCKED    1
#define M_CONTENDED 2

int k_mutex_init(struct k_mutex *mutex)
{
	z_waitq_init(&mutex->wait_q);
	__atomic_store_n(&mutex->owner, NULL, __ATOMIC_RELAXED);
	mutex->lock_count = 0U;
	__atomic_store_n(&mutex->owner_orig_prio, K_LOWEST_APPLICATION_THREAD_PRIO,
			 __ATOMIC_RELAXED);
	__atomic_store_n(&mutex->state, M_FREE, __ATOMIC_RELAXED);

	return 0;
}

static int prio_of(const struct k_thread *thread)
{
	return __atomic_load_n(&thread->base.prio, __ATOMIC_RELAXED);
}

static int new_prio_for_inheritance(int target, int limit)
{
	return z_is_prio_higher(target, limit) ? target : limit;
}

static void adjust_prio(struct k_thread *thread, int new_prio)
{
	if (prio_of(thread) != new_prio) {
		z_thread_prio_set_locked(thread, new_prio);
	}
}

/* The caller just won the state word: it is the owner now. */
static void take(struct k_mutex *mutex, struct k_thread *cur)
{
	mutex->lock_count = 1U;
	__atomic_store_n(&mutex->owner_orig_prio, prio_of(cur), __ATOMIC_RELAXED);
	/* Atomic: lock-rule checks and waiters read the owner without the kernel lock. */
	__atomic_store_n(&mutex->owner, cur, __ATOMIC_RELAXED);
}

static bool try_take(struct k_mutex *mutex, struct k_thread *cur)
{
	int expected = M_FREE;

	if (__atomic_compare_exchange_n(&mutex->state, &expected, M_LOCKED, false, __ATOMIC_ACQUIRE,
					__ATOMIC_RELAXED)) {
		take(mutex, cur);
		return true;
	}
	return false;
}

static __attribute__((noinline)) int lock_slow(struct k_mutex *mutex, struct k_thread *cur,
					       k_timeout_t timeout)
{
	struct k_thread *owner;
	struct k_thread *waiter;
	int new_prio;
	int ret;

	z_lock();
	for (;;) {
		int s = __atomic_load_n(&mutex->state, __ATOMIC_RELAXED);

		if (s == M_FREE) {
			if (try_take(mutex, cur)) {
				z_unlock();
				return 0;
			}
			continue;
		}
		if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
			z_unlock();
			return -EBUSY;
		}
		/* Mark it waited for, so that the owner's unlock comes here for the handover. */
		if (s == M_CONTENDED ||
		    __atomic_compare_exchange_n(&mutex->state, &s, M_CONTENDED, false,
						__ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
			break;
		}
	}

	/* An owner that has won the state word but not yet written its name is not boosted. */
	owner = __atomic_load_n(&mutex->owner, __ATOMIC_RELAXED);
	if (owner != NULL) {
		new_prio = new_prio_for_inheritance(prio_of(cur), prio_of(owner));
		adjust_prio(owner, new_prio);
	}

	ret = z_pend_curr(&mutex->wait_q, timeout);
	if (ret == 0) {
		/* The unlock handed the mutex over: we are its owner. */
		z_unlock();
		return 0;
	}

	/* Timed out: the owner keeps only the boost that remaining waiters justify. */
	owner = __atomic_load_n(&mutex->owner, __ATOMIC_RELAXED);
	if (owner != NULL) {
		waiter = z_waitq_head(&mutex->wait_q);
		new_prio = __atomic_load_n(&mutex->owner_orig_prio, __ATOMIC_RELAXED);
		if (waiter != NULL) {
			new_prio = new_prio_for_inheritance(prio_of(waiter), new_prio);
		}
		adjust_prio(owner, new_prio);
	}
	z_unlock();

	return -EAGAIN;
}

/* A host thread the kernel has not met yet takes its thread object first (rare). */
static __attribute__((noinline)) int lock_adopt(struct k_mutex *mutex, k_timeout_t timeout)
{
	struct k_thread *cur = z_current_adopt();

	if (try_take(mutex, cur)) {
		return 0;
	}
	return lock_slow(mutex, cur, timeout);
}

/*
 * The fast paths below are leaf code (the waits are out of line), so a free mutex costs one
 * compare-and-swap and a handful of loads and stores, as a futex does.
 */
int k_mutex_lock(struct k_mutex *mutex, k_timeout_t timeout)
{
	struct k_thread *cur = z_current_thread;

	if (unlikely(cur == NULL)) {
		return lock_adopt(mutex, timeout);
	}
	if (likely(try_take(mutex, cur))) {
		return 0;
	}
	/* Held: by this thread (a recursive lock), or a wait. */
	if (__atomic_load_n(&mutex->owner, __ATOMIC_RELAXED) == cur) {
		mutex->lock_count++;
		return 0;
	}
	return lock_slow(mutex, cur, timeout);
}

/* Hand the mutex to the first waiter, or free it; drop a boost. Kernel lock held. */
static __attribute__((noinline)) void unlock_slow(struct k_mutex *mutex, struct k_thread *cur,
						  int orig_prio)
{
	struct k_thread *new_owner;

	z_lock();
	adjust_prio(cur, orig_prio);
	new_owner = z_unpend_first_thread(&mutex->wait_q);
	if (new_owner != NULL) {
		/* Hand over directly: the lock count is 1 for the new owner. */
		mutex->lock_count = 1U;
		__atomic_store_n(&mutex->owner_orig_prio, prio_of(new_owner), __ATOMIC_RELAXED);
		__atomic_store_n(&mutex->owner, new_owner, __ATOMIC_RELAXED);
		__atomic_store_n(&mutex->state,
				 z_waitq_head(&mutex->wait_q) != NULL ? M_CONTENDED : M_LOCKED,
				 __ATOMIC_RELEASE);
		z_ready_thread(new_owner, 0);
	} else {
		__atomic_store_n(&mutex->state, M_FREE, __ATOMIC_RELEASE);
	}
	z_unlock();
}

int k_mutex_unlock(struct k_mutex *mutex)
{
	/* A thread without a thread object (NULL) owns no mutex: -EINVAL or -EPERM below. */
	struct k_thread *cur = z_current_thread;
	struct k_thread *owner = __atomic_load_n(&mutex->owner, __ATOMIC_RELAXED);
	int orig_prio;
	int expected = M_LOCKED;

	if (unlikely(owner != cur || owner == NULL)) {
		return owner == NULL ? -EINVAL : -EPERM;
	}
	if (mutex->lock_count > 1U) {
		mutex->lock_count--;
		return 0;
	}

	/* Give up the name before the state word: the next owner writes its own at once. */
	orig_prio = __atomic_load_n(&mutex->owner_orig_prio, __ATOMIC_RELAXED);
	mutex->lock_count = 0U;
	__atomic_store_n(&mutex->owner, NULL, __ATOMIC_RELAXED);
	if (likely(prio_of(cur) == orig_prio &&
		   __atomic_compare_exchange_n(&mutex->state, &expected, M_FREE, false,
					       __ATOMIC_RELEASE, __ATOMIC_RELAXED))) {
		return 0;
	}
	unlock_slow(mutex, cur, orig_prio);

	return 0;
}
