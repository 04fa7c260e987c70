/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Kernel time and the timeout list.
 *
 * Uptime is CLOCK_MONOTONIC minus the time of boot, kept internally in nanoseconds and
 * reported in ticks of CONFIG_SYS_CLOCK_TICKS_PER_SEC. Timers and delayable work put a
 * struct _timeout in one list sorted by deadline; the timeout thread sleeps until the first
 * deadline and runs the handlers, as a tickless timer interrupt would. Threads that block
 * with a timeout do not use this list: each waits on its own condition variable.
 */

#include <errno.h>
#include <stdio.h>
#include <time.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

static int64_t boot_mono_ns;
static sys_dlist_t timeout_list = SYS_DLIST_STATIC_INIT(&timeout_list);
static pthread_cond_t timeout_cond;

static int64_t mono_ns(void)
{
	struct timespec ts;

	(void)clock_gettime(CLOCK_MONOTONIC, &ts);

	return (int64_t)ts.tv_sec * NSEC_PER_SEC + ts.tv_nsec;
}

/* Uptime starts before any constructor of the application runs. */
static void __attribute__((constructor(101))) clock_init(void)
{
	boot_mono_ns = mono_ns();
	z_cond_init_monotonic(&timeout_cond);
}

int64_t z_now_ns(void)
{
	return mono_ns() - boot_mono_ns;
}

struct timespec z_ns_to_timespec(int64_t ns_since_boot)
{
	int64_t abs_ns = boot_mono_ns + ns_since_boot;
	struct timespec ts = {
		.tv_sec = (time_t)(abs_ns / NSEC_PER_SEC),
		.tv_nsec = (long)(abs_ns % NSEC_PER_SEC),
	};

	return ts;
}

int64_t z_ticks_to_ns(int64_t ticks)
{
	return (int64_t)k_ticks_to_ns_ceil64((uint64_t)ticks);
}

int64_t sys_clock_tick_get(void)
{
	return (int64_t)k_ns_to_ticks_floor64((uint64_t)z_now_ns());
}

uint32_t sys_clock_tick_get_32(void)
{
	return (uint32_t)sys_clock_tick_get();
}

uint32_t k_cycle_get_32(void)
{
	return (uint32_t)k_cycle_get_64();
}

uint64_t k_cycle_get_64(void)
{
	return k_ns_to_cyc_floor64((uint64_t)z_now_ns());
}

int64_t z_timeout_deadline_ns(k_timeout_t timeout)
{
	k_ticks_t abs_ticks;

	if (K_TIMEOUT_EQ(timeout, K_FOREVER)) {
		return INT64_MAX;
	}
	abs_ticks = Z_TICK_ABS(timeout.ticks);
	if (abs_ticks >= 0) {
		return z_ticks_to_ns(abs_ticks);
	}

	/* Relative: at least the requested time from now, never less. */
	return z_now_ns() + z_ticks_to_ns(MAX(timeout.ticks, 0));
}

/* Ordering for the timeout list: true once past every timeout due at or before *data. */
static int due_later(sys_dnode_t *node, void *data)
{
	return CONTAINER_OF(node, struct _timeout, node)->deadline_ns > *(int64_t *)data;
}

void z_add_timeout_at(struct _timeout *to, _timeout_func_t fn, int64_t deadline_ns)
{
	to->fn = fn;
	to->deadline_ns = deadline_ns;
	/* Behind timeouts with the same deadline: they expire in the order they were set. */
	sys_dlist_insert_at(&timeout_list, &to->node, due_later, &deadline_ns);
	if (sys_dlist_peek_head(&timeout_list) == &to->node) {
		/* New earliest deadline: the timeout thread must sleep less. */
		(void)pthread_cond_signal(&timeout_cond);
	}
}

void z_add_timeout(struct _timeout *to, _timeout_func_t fn, k_timeout_t timeout)
{
	if (K_TIMEOUT_EQ(timeout, K_FOREVER)) {
		return;
	}
	z_add_timeout_at(to, fn, z_timeout_deadline_ns(timeout));
}

int z_abort_timeout(struct _timeout *to)
{
	if (z_is_inactive_timeout(to)) {
		return -EINVAL;
	}
	sys_dlist_remove(&to->node);

	return 0;
}

k_ticks_t z_timeout_expires(const struct _timeout *to)
{
	if (z_is_inactive_timeout(to)) {
		return 0;
	}

	return (k_ticks_t)k_ns_to_ticks_ceil64((uint64_t)MAX(to->deadline_ns, 0));
}

k_ticks_t z_timeout_remaining(const struct _timeout *to)
{
	int64_t left;

	if (z_is_inactive_timeout(to)) {
		return 0;
	}
	left = to->deadline_ns - z_now_ns();

	return (left > 0) ? (k_ticks_t)k_ns_to_ticks_ceil64((uint64_t)left) : 0;
}

static void *timeout_thread(void *arg)
{
	struct k_thread *self = z_current();

	ARG_UNUSED(arg);

	z_lock();
	/* Handlers run here as they would in the timer interrupt. */
	self->base.thread_state |= Z_THREAD_ISR;
	self->base.prio = K_HIGHEST_THREAD_PRIO;
	(void)snprintf(self->name, sizeof(self->name), "timer");
	(void)pthread_setname_np(pthread_self(), "timer");

	for (;;) {
		sys_dnode_t *node = sys_dlist_peek_head(&timeout_list);
		struct _timeout *to;

		if (node == NULL) {
			(void)z_cond_wait_until(&timeout_cond, INT64_MAX);
			continue;
		}
		to = CONTAINER_OF(node, struct _timeout, node);
		if (to->deadline_ns > z_now_ns()) {
			(void)z_cond_wait_until(&timeout_cond, to->deadline_ns);
			continue;
		}
		sys_dlist_remove(&to->node);
		to->fn(to);
	}

	return NULL;
}

void z_timeout_thread_start(void)
{
	pthread_attr_t attr;
	pthread_t thread;

	(void)pthread_attr_init(&attr);
	(void)pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
	if (pthread_create(&thread, &attr, timeout_thread, NULL) != 0) {
		printk("cannot create the timeout thread\n");
		k_panic();
	}
	(void)pthread_attr_destroy(&attr);
}

k_timepoint_t sys_timepoint_calc(k_timeout_t timeout)
{
	k_timepoint_t timepoint;

	if (K_TIMEOUT_EQ(timeout, K_FOREVER)) {
		timepoint.tick = UINT64_MAX;
	} else if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		timepoint.tick = 0;
	} else {
		k_ticks_t dt = timeout.ticks;

		if (Z_IS_TIMEOUT_RELATIVE(timeout)) {
			timepoint.tick = (uint64_t)sys_clock_tick_get() + (uint64_t)MAX(1, dt);
		} else {
			timepoint.tick = (uint64_t)Z_TICK_ABS(dt);
		}
	}

	return timepoint;
}

k_timeout_t sys_timepoint_timeout(k_timepoint_t timepoint)
{
	uint64_t now;
	uint64_t remaining;

	if (timepoint.tick == UINT64_MAX) {
		return K_FOREVER;
	}
	if (timepoint.tick == 0U) {
		return K_NO_WAIT;
	}
	now = (uint64_t)sys_clock_tick_get();
	remaining = (timepoint.tick > now) ? (timepoint.tick - now) : 0U;

	return K_TICKS((k_ticks_t)remaining);
}
