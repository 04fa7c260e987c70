/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Threads, wait queues and blocking on POSIX threads.
 *
 * Every k_thread is a detached pthread running thread_trampoline(). Blocking means waiting on
 * the thread's own condition variable with the kernel lock held; the thread that satisfies
 * the wait takes the waiter off the wait queue, stores the result in swap_retval and signals.
 * Wait queues are ordered by priority (FIFO among equals), so the highest-priority waiter is
 * served first, as in Zephyr.
 */

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

static pthread_mutex_t kernel_lock = PTHREAD_MUTEX_INITIALIZER;

/* The k_thread of the calling host thread (read inline by z_current(), kernel_internal.h). */
__thread struct k_thread *z_current_thread;
/* Thread object for host threads the kernel did not create (the boot thread, host I/O). */
static __thread struct k_thread dummy_thread;

void z_lock(void)
{
	(void)pthread_mutex_lock(&kernel_lock);
}

void z_unlock(void)
{
	(void)pthread_mutex_unlock(&kernel_lock);
}

void z_cond_init_monotonic(pthread_cond_t *cond)
{
	pthread_condattr_t attr;

	(void)pthread_condattr_init(&attr);
	(void)pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
	(void)pthread_cond_init(cond, &attr);
	(void)pthread_condattr_destroy(&attr);
}

int z_cond_wait_until(pthread_cond_t *cond, int64_t deadline_ns)
{
	struct timespec ts;

	if (deadline_ns == INT64_MAX) {
		return pthread_cond_wait(cond, &kernel_lock);
	}
	ts = z_ns_to_timespec(deadline_ns);

	return pthread_cond_timedwait(cond, &kernel_lock, &ts);
}

static void thread_base_init(struct k_thread *thread, int prio, uint8_t state)
{
	sys_dnode_init(&thread->base.qnode_dlist);
	thread->base.pended_on = NULL;
	thread->base.prio = prio;
	thread->base.thread_state = state;
	thread->base.user_options = 0;
	z_waitq_init(&thread->join_queue);
	thread->swap_retval = 0;
	thread->swap_data = NULL;
	thread->start_ns = 0;
	thread->name[0] = '\0';
#if defined(CONFIG_THREAD_CUSTOM_DATA)
	thread->custom_data = NULL;
#endif
	z_host(thread)->exit_jmp = NULL;
	z_cond_init_monotonic(&z_host(thread)->cond);
}

struct k_thread *z_current_adopt(void)
{
	/* Adopt the host thread; its dummy object lives as long as the thread. */
	thread_base_init(&dummy_thread, K_LOWEST_APPLICATION_THREAD_PRIO, Z_THREAD_DUMMY);
	z_host(&dummy_thread)->pthread = pthread_self();
	z_current_thread = &dummy_thread;
	return z_current_thread;
}

k_tid_t k_current_get(void)
{
	return z_current();
}

bool k_is_in_isr(void)
{
	return (z_current()->base.thread_state & Z_THREAD_ISR) != 0U;
}

/* ------------------------------------------------------------------------------------------ */
/* Wait queues */

void z_waitq_init(_wait_q_t *wq)
{
	sys_dlist_init(&wq->waitq);
}

struct k_thread *z_waitq_head(_wait_q_t *wq)
{
	return SYS_DLIST_PEEK_HEAD_CONTAINER(&wq->waitq, (struct k_thread *)NULL, base.qnode_dlist);
}

static void waitq_add(_wait_q_t *wq, struct k_thread *thread)
{
	struct k_thread *t;

	/* Before the first thread of lower priority: FIFO among equal priorities. */
	SYS_DLIST_FOR_EACH_CONTAINER(&wq->waitq, t, base.qnode_dlist) {
		if (z_is_prio_higher(thread->base.prio, t->base.prio)) {
			sys_dlist_insert(&t->base.qnode_dlist, &thread->base.qnode_dlist);
			thread->base.pended_on = wq;
			return;
		}
	}
	sys_dlist_append(&wq->waitq, &thread->base.qnode_dlist);
	thread->base.pended_on = wq;
}

static void unpend_thread(struct k_thread *thread)
{
	sys_dlist_remove(&thread->base.qnode_dlist);
	thread->base.pended_on = NULL;
	thread->base.thread_state &= ~Z_THREAD_PENDING;
}

struct k_thread *z_unpend_first_thread(_wait_q_t *wq)
{
	struct k_thread *thread = z_waitq_head(wq);

	if (thread != NULL) {
		unpend_thread(thread);
	}

	return thread;
}

void z_ready_thread(struct k_thread *thread, int retval)
{
	thread->swap_retval = retval;
	(void)pthread_cond_signal(&z_host(thread)->cond);
}

bool z_sched_wake(_wait_q_t *wq, int retval)
{
	struct k_thread *thread = z_unpend_first_thread(wq);

	if (thread == NULL) {
		return false;
	}
	z_ready_thread(thread, retval);

	return true;
}

bool z_sched_wake_all(_wait_q_t *wq, int retval)
{
	bool woken = false;

	while (z_sched_wake(wq, retval)) {
		woken = true;
	}

	return woken;
}

int z_pend_curr(_wait_q_t *wq, k_timeout_t timeout)
{
	struct k_thread *cur = z_current();
	struct z_host_thread *host = z_host(cur);
	int64_t deadline = z_timeout_deadline_ns(timeout);

	z_check_abort_locked();

	cur->swap_retval = -EAGAIN;
	cur->base.thread_state |= Z_THREAD_PENDING;
	waitq_add(wq, cur);

	while ((cur->base.thread_state & Z_THREAD_PENDING) != 0U) {
		if ((cur->base.thread_state & Z_THREAD_ABORTING) != 0U) {
			unpend_thread(cur);
			z_thread_exit_self_locked();
		}
		if (z_cond_wait_until(&host->cond, deadline) == ETIMEDOUT &&
		    (cur->base.thread_state & Z_THREAD_PENDING) != 0U) {
			/* Timed out and nobody woke us in the meantime. */
			unpend_thread(cur);
			cur->swap_retval = -EAGAIN;
		}
	}
	z_check_abort_locked();

	return cur->swap_retval;
}

void z_thread_prio_set_locked(struct k_thread *thread, int prio)
{
	_wait_q_t *wq = thread->base.pended_on;

	/* Atomic: a thread reads its own priority without the kernel lock (k_mutex fast path). */
	__atomic_store_n(&thread->base.prio, prio, __ATOMIC_RELAXED);
	if (wq != NULL) {
		/* Re-sort: the thread's place in its wait queue depends on its priority. */
		sys_dlist_remove(&thread->base.qnode_dlist);
		waitq_add(wq, thread);
	}
}

/* ------------------------------------------------------------------------------------------ */
/* Thread life cycle */

/* Mark a thread ended and release its joiners (kernel lock held). */
static void thread_mark_dead_locked(struct k_thread *thread)
{
	thread->base.thread_state |= Z_THREAD_DEAD;
	thread->base.thread_state &= ~(Z_THREAD_ABORTING | Z_THREAD_PRESTART);
	(void)z_sched_wake_all(&thread->join_queue, 0);
}

void z_thread_exit_self_locked(void)
{
	struct k_thread *cur = z_current();
	jmp_buf *exit_jmp = z_host(cur)->exit_jmp;

	if (exit_jmp != NULL) {
		/* Back to the trampoline, which ends the thread. */
		z_unlock();
		longjmp(*exit_jmp, 1);
	}

	/* A host thread the kernel did not create. */
	thread_mark_dead_locked(cur);
	z_unlock();
	pthread_exit(NULL);
}

void z_check_abort_locked(void)
{
	if ((z_current()->base.thread_state & Z_THREAD_ABORTING) != 0U) {
		z_thread_exit_self_locked();
	}
}

static void set_host_name(const char *name)
{
	char host_name[16];
	size_t len = strnlen(name, sizeof(host_name) - 1U);

	/* Linux limits thread names to 15 characters; they help in debuggers and top. */
	(void)memcpy(host_name, name, len);
	host_name[len] = '\0';
	(void)pthread_setname_np(pthread_self(), host_name);
}

static void *thread_trampoline(void *arg)
{
	struct k_thread *thread = arg;
	struct z_host_thread *host = z_host(thread);
	jmp_buf exit_jmp;

	z_current_thread = thread;

	z_lock();
	/* Wait for the start time (INT64_MAX until k_thread_start()) unless aborted first. */
	while ((thread->base.thread_state & (Z_THREAD_ABORTING | Z_THREAD_DEAD)) == 0U) {
		if (thread->start_ns <= z_now_ns()) {
			break;
		}
		(void)z_cond_wait_until(&host->cond, thread->start_ns);
	}
	if ((thread->base.thread_state & (Z_THREAD_ABORTING | Z_THREAD_DEAD)) != 0U) {
		thread_mark_dead_locked(thread);
		z_unlock();
		return NULL;
	}
	thread->base.thread_state &= ~Z_THREAD_PRESTART;
	if (thread->name[0] != '\0') {
		set_host_name(thread->name);
	}
	z_unlock();

	host->exit_jmp = &exit_jmp;
	if (setjmp(exit_jmp) == 0) {
		thread->entry(thread->p1, thread->p2, thread->p3);
	}

	z_lock();
	host->exit_jmp = NULL;
	/* After this the object may be reused at once: do not touch it again. */
	thread_mark_dead_locked(thread);
	z_unlock();

	return NULL;
}

k_tid_t k_thread_create(struct k_thread *new_thread, k_thread_stack_t *stack, size_t stack_size,
			k_thread_entry_t entry, void *p1, void *p2, void *p3, int prio,
			uint32_t options, k_timeout_t delay)
{
	pthread_attr_t attr;
	int err;

	ARG_UNUSED(stack);
	ARG_UNUSED(stack_size);
	__ASSERT(prio >= K_HIGHEST_THREAD_PRIO && prio <= K_LOWEST_THREAD_PRIO,
		 "invalid priority %d", prio);

	/* Under the lock: threads that used the object's previous incarnation may still look. */
	z_lock();
	thread_base_init(new_thread, prio, Z_THREAD_PRESTART);
	new_thread->base.user_options = options;
	new_thread->entry = entry;
	new_thread->p1 = p1;
	new_thread->p2 = p2;
	new_thread->p3 = p3;
	if (K_TIMEOUT_EQ(delay, K_FOREVER)) {
		new_thread->start_ns = INT64_MAX;
	} else if (K_TIMEOUT_EQ(delay, K_NO_WAIT)) {
		new_thread->start_ns = 0;
	} else {
		new_thread->start_ns = z_timeout_deadline_ns(delay);
	}
	z_unlock();

	(void)pthread_attr_init(&attr);
	(void)pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
	err = pthread_create(&z_host(new_thread)->pthread, &attr, thread_trampoline, new_thread);
	(void)pthread_attr_destroy(&attr);
	if (err != 0) {
		printk("k_thread_create: cannot create a host thread: %s\n", strerror(err));
		k_panic();
	}

	return new_thread;
}

void z_thread_start_at_locked(struct k_thread *thread, int64_t deadline_ns)
{
	if ((thread->base.thread_state & Z_THREAD_PRESTART) == 0U) {
		return;
	}
	thread->start_ns = deadline_ns;
	(void)pthread_cond_signal(&z_host(thread)->cond);
}

void k_thread_start(k_tid_t thread)
{
	z_lock();
	z_thread_start_at_locked(thread, 0);
	z_unlock();
}

int k_thread_join(struct k_thread *thread, k_timeout_t timeout)
{
	struct k_thread *cur;
	int ret;

	z_lock();
	cur = z_current();
	/* A caller being aborted ends here, not with -EDEADLK from the thread that aborts it. */
	z_check_abort_locked();
	if ((thread->base.thread_state & Z_THREAD_DEAD) != 0U) {
		ret = 0;
	} else if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		ret = -EBUSY;
	} else if (thread == cur || thread->base.pended_on == &cur->join_queue) {
		ret = -EDEADLK;
	} else {
		ret = z_pend_curr(&thread->join_queue, timeout);
	}
	z_unlock();

	return ret;
}

void k_thread_abort(k_tid_t thread)
{
	struct k_thread *cur;

	z_lock();
	cur = z_current();
	if ((thread->base.thread_state & Z_THREAD_DEAD) != 0U) {
		z_unlock();
		return;
	}
	if (thread == cur) {
		z_thread_exit_self_locked();
	}
	thread->base.thread_state |= Z_THREAD_ABORTING;
	(void)pthread_cond_signal(&z_host(thread)->cond);
	/*
	 * The target ends at its next blocking call or sleep (a thread that has not started ends
	 * at once). The timeout thread must not wait (an interrupt cannot block); everyone else
	 * waits, as Zephyr's k_thread_abort() does, so the object may be reused on return.
	 */
	if (!k_is_in_isr() && (thread->base.thread_state & Z_THREAD_DEAD) == 0U) {
		/*
		 * Woken only by the thread's death. Do not look at the object again: by the time
		 * this thread runs, the object may already hold a new thread.
		 */
		(void)z_pend_curr(&thread->join_queue, K_FOREVER);
	}
	z_unlock();
}

int k_thread_name_set(k_tid_t thread, const char *str)
{
	k_tid_t t = (thread != NULL) ? thread : k_current_get();

	z_lock();
	(void)snprintf(t->name, sizeof(t->name), "%s", (str != NULL) ? str : "");
	z_unlock();
	if (t == k_current_get()) {
		set_host_name(t->name);
	}

	return 0;
}

#if defined(CONFIG_THREAD_CUSTOM_DATA)
void k_thread_custom_data_set(void *value)
{
	k_current_get()->custom_data = value;
}

void *k_thread_custom_data_get(void)
{
	return k_current_get()->custom_data;
}
#endif

const char *k_thread_name_get(k_tid_t thread)
{
	return thread->name;
}

int k_thread_name_copy(k_tid_t thread, char *buf, size_t size)
{
	if (size == 0U) {
		return -ENOSPC;
	}
	z_lock();
	(void)snprintf(buf, size, "%s", thread->name);
	z_unlock();

	return 0;
}

int k_thread_priority_get(k_tid_t thread)
{
	int prio;

	z_lock();
	prio = thread->base.prio;
	z_unlock();

	return prio;
}

void k_thread_priority_set(k_tid_t thread, int prio)
{
	__ASSERT(prio >= K_HIGHEST_THREAD_PRIO && prio <= K_LOWEST_THREAD_PRIO,
		 "invalid priority %d", prio);
	z_lock();
	z_thread_prio_set_locked(thread, prio);
	z_unlock();
}

/* ------------------------------------------------------------------------------------------ */
/* Sleeping and yielding */

int32_t k_sleep(k_timeout_t timeout)
{
	struct k_thread *cur;
	int64_t deadline;
	int64_t left_ns = 0;
	bool woken;

	if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		k_yield();
		return 0;
	}

	z_lock();
	cur = z_current();
	z_check_abort_locked();
	deadline = z_timeout_deadline_ns(timeout);
	cur->base.thread_state |= Z_THREAD_SLEEPING;
	while ((cur->base.thread_state & Z_THREAD_SLEEPING) != 0U) {
		if (z_cond_wait_until(&z_host(cur)->cond, deadline) == ETIMEDOUT) {
			break;
		}
		z_check_abort_locked();
	}
	/* k_wakeup() clears the flag; a full sleep leaves it set. */
	woken = (cur->base.thread_state & Z_THREAD_SLEEPING) == 0U;
	cur->base.thread_state &= ~Z_THREAD_SLEEPING;
	if (woken && deadline != INT64_MAX) {
		left_ns = MAX(deadline - z_now_ns(), 0);
	}
	z_check_abort_locked();
	z_unlock();

	if (!woken) {
		return 0;
	}
	if (deadline == INT64_MAX) {
		return (int32_t)K_TICKS_FOREVER;
	}

	return (int32_t)DIV_ROUND_UP(left_ns, (int64_t)NSEC_PER_MSEC);
}

int32_t k_usleep(int32_t us)
{
	int64_t start = z_now_ns();
	int32_t left_ms = k_sleep(Z_TIMEOUT_US(us));

	if (left_ms == 0) {
		return 0;
	}

	/* Woken early: report the microseconds left. */
	return (int32_t)MAX((int64_t)us - (z_now_ns() - start) / NSEC_PER_USEC, 0);
}

void k_wakeup(k_tid_t thread)
{
	z_lock();
	if ((thread->base.thread_state & Z_THREAD_SLEEPING) != 0U) {
		thread->base.thread_state &= ~Z_THREAD_SLEEPING;
		(void)pthread_cond_signal(&z_host(thread)->cond);
	}
	z_unlock();
}

void k_yield(void)
{
	z_lock();
	z_check_abort_locked();
	z_unlock();
	(void)sched_yield();
}

void k_busy_wait(uint32_t usec_to_wait)
{
	struct timespec ts = z_ns_to_timespec(z_now_ns() + (int64_t)usec_to_wait * NSEC_PER_USEC);

	/* Sleeping instead of spinning keeps the host's cores for the other threads. */
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
	}
}

/* ------------------------------------------------------------------------------------------ */
/* Threads defined with K_THREAD_DEFINE() */

static struct z_static_thread *static_threads;

void z_static_thread_register(struct z_static_thread *data)
{
	/* Runs from constructors, before main() and before any thread exists. */
	data->next = static_threads;
	static_threads = data;
}

void z_init_static_threads(void)
{
	struct z_static_thread *data;

	for (data = static_threads; data != NULL; data = data->next) {
		(void)k_thread_create(data->thread, data->stack, data->stack_size, data->entry,
				      data->p1, data->p2, data->p3, data->prio, data->options,
				      K_FOREVER);
		(void)k_thread_name_set(data->thread, data->name);
	}

	z_lock();
	for (data = static_threads; data != NULL; data = data->next) {
		if (data->delay_ms != SYS_FOREVER_MS) {
			z_thread_start_at_locked(
				data->thread, z_now_ns() + (int64_t)data->delay_ms * NSEC_PER_MSEC);
		}
	}
	z_unlock();
}
