/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Internals of the kernel subset on POSIX threads.
 *
 * One process-wide mutex (the kernel lock) protects every kernel object, wait queue and
 * thread state, as the scheduler lock does in Zephyr. A thread blocks on its own condition
 * variable, waiting on CLOCK_MONOTONIC until it is woken or its deadline passes; whoever
 * wakes it hands over the result (swap_retval) under the lock. A single timeout thread runs
 * the timer and delayable-work deadlines; it plays the part of the timer interrupt.
 */

#ifndef KERNEL_POSIX_KERNEL_INTERNAL_H_
#define KERNEL_POSIX_KERNEL_INTERNAL_H_

#include <pthread.h>
#include <setjmp.h>
#include <stdint.h>
#include <time.h>

#include <zephyr/kernel.h>

/* Thread state bits (struct _thread_base::thread_state). */
#define Z_THREAD_PRESTART BIT(0) /* created, not started */
#define Z_THREAD_PENDING  BIT(1) /* waiting in a wait queue */
#define Z_THREAD_SLEEPING BIT(2) /* in k_sleep() */
#define Z_THREAD_DEAD     BIT(3) /* ended */
#define Z_THREAD_ABORTING BIT(4) /* k_thread_abort() requested, not yet ended */
#define Z_THREAD_DUMMY    BIT(5) /* a host thread not created by k_thread_create() */
#define Z_THREAD_ISR      BIT(6) /* the timeout thread: "interrupt" context */

/* Host side of a thread, kept in the opaque struct k_thread::arch. */
struct z_host_thread {
	pthread_t pthread;
	pthread_cond_t cond;
	/* Where k_thread_abort() of the thread itself jumps to (NULL for dummy threads). */
	jmp_buf *exit_jmp;
};

BUILD_ASSERT(sizeof(struct z_host_thread) <= sizeof(((struct k_thread *)0)->arch),
	     "struct _thread_arch too small for the host thread");

static inline struct z_host_thread *z_host(struct k_thread *thread)
{
	return (struct z_host_thread *)(void *)thread->arch.host;
}

/* The kernel lock. */
void z_lock(void);
void z_unlock(void);

/* The calling thread (a dummy thread object for host threads the kernel did not create). */
/* The calling thread's k_thread: inline, since every k_mutex operation asks. */
extern __thread struct k_thread *z_current_thread;
struct k_thread *z_current_adopt(void);

static inline struct k_thread *z_current(void)
{
	struct k_thread *cur = z_current_thread;

	return cur != NULL ? cur : z_current_adopt();
}

/* Time since boot in ns on CLOCK_MONOTONIC. */
int64_t z_now_ns(void);
/* The CLOCK_MONOTONIC time of a point in ns since boot. */
struct timespec z_ns_to_timespec(int64_t ns_since_boot);
int64_t z_ticks_to_ns(int64_t ticks);

/* Deadline (ns since boot) of a timeout starting now; INT64_MAX for K_FOREVER. */
int64_t z_timeout_deadline_ns(k_timeout_t timeout);

/* Condition wait on the kernel lock until deadline_ns (INT64_MAX: no limit); ETIMEDOUT or 0. */
int z_cond_wait_until(pthread_cond_t *cond, int64_t deadline_ns);
void z_cond_init_monotonic(pthread_cond_t *cond);

/* Wait queues; all with the kernel lock held. */
void z_waitq_init(_wait_q_t *wq);
struct k_thread *z_waitq_head(_wait_q_t *wq);
/* Block the caller on wq until woken (returns the waker's value) or timeout (-EAGAIN). */
int z_pend_curr(_wait_q_t *wq, k_timeout_t timeout);
/* Remove the first waiter, or return NULL. */
struct k_thread *z_unpend_first_thread(_wait_q_t *wq);
/* Make a thread taken off a wait queue runnable with the given result. */
void z_ready_thread(struct k_thread *thread, int retval);
/* Wake one waiter with retval; true if there was one. */
bool z_sched_wake(_wait_q_t *wq, int retval);
/* Wake every waiter with retval; true if there was one. */
bool z_sched_wake_all(_wait_q_t *wq, int retval);
/* Change a thread's priority, keeping its wait queue ordered. */
void z_thread_prio_set_locked(struct k_thread *thread, int prio);
/* A lower number is a higher priority. */
static inline bool z_is_prio_higher(int prio, int test_prio)
{
	return prio < test_prio;
}

/* End the calling thread (kernel lock held; does not return). */
FUNC_NORETURN void z_thread_exit_self_locked(void);
/* If the caller has been asked to abort, end it now (kernel lock held). */
void z_check_abort_locked(void);

/* Start a created thread at deadline_ns (kernel lock held). */
void z_thread_start_at_locked(struct k_thread *thread, int64_t deadline_ns);

/* Timeouts (kernel lock held). The handler runs in the timeout thread with the lock held and
 * may release it temporarily.
 */
void z_add_timeout(struct _timeout *to, _timeout_func_t fn, k_timeout_t timeout);
void z_add_timeout_at(struct _timeout *to, _timeout_func_t fn, int64_t deadline_ns);
int z_abort_timeout(struct _timeout *to);
static inline bool z_is_inactive_timeout(const struct _timeout *to)
{
	return !sys_dnode_is_linked(&to->node);
}
k_ticks_t z_timeout_expires(const struct _timeout *to);
k_ticks_t z_timeout_remaining(const struct _timeout *to);
void z_timeout_thread_start(void);

/* Semaphore give with the kernel lock held (used by work queue synchronisation). */
void z_sem_give_locked(struct k_sem *sem);

/* Boot: run the init entries of one level. */
void z_sys_init_run_level(int level);
void z_init_static_threads(void);

/* Entry from the board: run the kernel, then app_main() in the "main" thread. */
void z_cstart(int (*app_main)(void));

/* Provided by the board: end the process (ON_EXIT hooks, then exit()). */
FUNC_NORETURN void posix_exit(int exit_code);

#endif /* KERNEL_POSIX_KERNEL_INTERNAL_H_ */
