/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_timer on the kernel's timeout list. The expiry function runs in the timeout thread
 * (interrupt context: it must not block), without the kernel lock. A periodic timer's next
 * deadline is the previous deadline plus the period, so it does not drift with the host's
 * scheduling delays; an overrun catches up with back-to-back expiries, as in Zephyr.
 *
 * On a single-core target an expiry function has finished before any thread runs again. Here
 * a thread may run while it is still running, so k_timer_stop() (outside the timer context)
 * waits for it: after k_timer_stop() the timer object is no longer used and may be freed.
 */

#include <zephyr/kernel.h>

#include "kernel_internal.h"

/* The timer whose expiry is being handled, and who waits for that to end. */
static struct k_timer *expiring;
static _wait_q_t expiry_done = Z_WAIT_Q_INIT(&expiry_done);

static void timer_expired(struct _timeout *to)
{
	struct k_timer *timer = CONTAINER_OF(to, struct k_timer, timeout);
	k_timer_expiry_t expiry_fn = timer->expiry_fn;

	if (!K_TIMEOUT_EQ(timer->period, K_NO_WAIT) && !K_TIMEOUT_EQ(timer->period, K_FOREVER)) {
		z_add_timeout_at(&timer->timeout, timer_expired,
				 to->deadline_ns + z_ticks_to_ns(timer->period.ticks));
	}
	timer->status++;

	expiring = timer;
	if (expiry_fn != NULL) {
		z_unlock();
		expiry_fn(timer);
		z_lock();
	}

	(void)z_sched_wake(&timer->wait_q, 0);
	expiring = NULL;
	(void)z_sched_wake_all(&expiry_done, 0);
}

/* Wait until the timer's expiry handling, if running, has ended (kernel lock held). */
static void wait_expiry_done_locked(struct k_timer *timer)
{
	while (expiring == timer && !k_is_in_isr()) {
		(void)z_pend_curr(&expiry_done, K_FOREVER);
	}
}

void k_timer_init(struct k_timer *timer, k_timer_expiry_t expiry_fn, k_timer_stop_t stop_fn)
{
	sys_dnode_init(&timer->timeout.node);
	timer->timeout.fn = NULL;
	timer->timeout.deadline_ns = 0;
	z_waitq_init(&timer->wait_q);
	timer->expiry_fn = expiry_fn;
	timer->stop_fn = stop_fn;
	timer->period = K_NO_WAIT;
	timer->status = 0U;
	timer->user_data = NULL;
}

void k_timer_start(struct k_timer *timer, k_timeout_t duration, k_timeout_t period)
{
	if (K_TIMEOUT_EQ(duration, K_FOREVER)) {
		return;
	}

	z_lock();
	(void)z_abort_timeout(&timer->timeout);
	timer->period = period;
	timer->status = 0U;
	z_add_timeout(&timer->timeout, timer_expired, duration);
	z_unlock();
}

void k_timer_stop(struct k_timer *timer)
{
	bool was_running;

	z_lock();
	was_running = z_abort_timeout(&timer->timeout) == 0;
	wait_expiry_done_locked(timer);
	z_unlock();
	if (!was_running) {
		return;
	}

	if (timer->stop_fn != NULL) {
		timer->stop_fn(timer);
	}

	z_lock();
	(void)z_sched_wake(&timer->wait_q, 0);
	z_unlock();
}

uint32_t k_timer_status_get(struct k_timer *timer)
{
	uint32_t status;

	z_lock();
	status = timer->status;
	timer->status = 0U;
	z_unlock();

	return status;
}

uint32_t k_timer_status_sync(struct k_timer *timer)
{
	uint32_t status;

	z_lock();
	status = timer->status;
	if (status == 0U && !z_is_inactive_timeout(&timer->timeout)) {
		/* Wait for the next expiry or a stop. */
		(void)z_pend_curr(&timer->wait_q, K_FOREVER);
		status = timer->status;
	}
	timer->status = 0U;
	z_unlock();

	return status;
}

k_ticks_t k_timer_expires_ticks(const struct k_timer *timer)
{
	k_ticks_t ticks;

	z_lock();
	ticks = z_timeout_expires(&timer->timeout);
	z_unlock();

	return ticks;
}

k_ticks_t k_timer_remaining_ticks(const struct k_timer *timer)
{
	k_ticks_t ticks;

	z_lock();
	ticks = z_timeout_remaining(&timer->timeout);
	z_unlock();

	return ticks;
}
