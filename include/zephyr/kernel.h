/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The kernel API subset SafeLine uses, as Zephyr's kernel.h: threads, mutexes,
 *        semaphores, message queues, work queues, timers, time.
 *
 * Names, signatures, return codes and timeout semantics are Zephyr's. On native_posix the
 * implementation is kernel/posix (POSIX threads); see doc/kernel.md for its deviations.
 *
 * Timeouts: K_NO_WAIT never blocks; K_FOREVER blocks until the condition holds; K_MSEC() and
 * friends block at most that long; K_TIMEOUT_ABS_MS() and friends block until that uptime.
 */

#ifndef ZEPHYR_INCLUDE_KERNEL_H_
#define ZEPHYR_INCLUDE_KERNEL_H_

#include <errno.h>
#include <limits.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/fatal.h>
#include <zephyr/init.h>
#include <zephyr/kernel/thread.h>
#include <zephyr/kernel/thread_stack.h>
#include <zephyr/sys/__assert.h>
#include <zephyr/sys/atomic.h>
#include <zephyr/sys/dlist.h>
#include <zephyr/sys/printk.h>
#include <zephyr/sys/slist.h>
#include <zephyr/sys/util.h>
#include <zephyr/sys_clock.h>
#include <zephyr/toolchain.h>
#include <zephyr/types.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @defgroup kernel_apis Kernel APIs
 * @{
 */

/** @name Timeouts */
/** @{ */

/** Do not wait. */
#define K_NO_WAIT    Z_TIMEOUT_NO_WAIT
/** Wait @p t nanoseconds (rounded up to whole ticks). */
#define K_NSEC(t)    Z_TIMEOUT_NS(t)
/** Wait @p t microseconds (rounded up to whole ticks). */
#define K_USEC(t)    Z_TIMEOUT_US(t)
/** Wait @p t hardware cycles (rounded up to whole ticks). */
#define K_CYC(t)     Z_TIMEOUT_CYC(t)
/** Wait @p t ticks. */
#define K_TICKS(t)   Z_TIMEOUT_TICKS(t)
/** Wait @p ms milliseconds (rounded up to whole ticks). */
#define K_MSEC(ms)   Z_TIMEOUT_MS(ms)
/** Wait @p s seconds. */
#define K_SECONDS(s) K_MSEC((s) * MSEC_PER_SEC)
/** Wait @p m minutes. */
#define K_MINUTES(m) K_SECONDS((m) * 60)
/** Wait @p h hours. */
#define K_HOURS(h)   K_MINUTES((h) * 60)
/** Wait without limit. */
#define K_FOREVER    Z_FOREVER

/** Wait until uptime tick @p t (already passed: do not wait). */
#define K_TIMEOUT_ABS_TICKS(t) Z_TIMEOUT_TICKS(Z_TICK_ABS((k_ticks_t)MAX(t, 0)))
/** Wait until uptime @p t milliseconds. */
#define K_TIMEOUT_ABS_MS(t)    K_TIMEOUT_ABS_TICKS(k_ms_to_ticks_ceil64(t))
/** Wait until uptime @p t microseconds. */
#define K_TIMEOUT_ABS_US(t)    K_TIMEOUT_ABS_TICKS(k_us_to_ticks_ceil64(t))
/** Wait until uptime @p t nanoseconds. */
#define K_TIMEOUT_ABS_NS(t)    K_TIMEOUT_ABS_TICKS(k_ns_to_ticks_ceil64(t))
/** Wait until uptime @p t hardware cycles. */
#define K_TIMEOUT_ABS_CYC(t)   K_TIMEOUT_ABS_TICKS(k_cyc_to_ticks_ceil64(t))

/** @} */

/** @name Thread priorities */
/** @{ */

/*
 * As in Zephyr, a lower number is a higher priority; negative priorities are cooperative.
 * On native_posix priorities order every wait queue (the highest-priority waiter is served
 * first, FIFO among equals) and drive mutex priority inheritance; the host schedules the
 * threads themselves fairly (see doc/kernel.md).
 */
#define K_PRIO_COOP(x)    (-(CONFIG_NUM_COOP_PRIORITIES - (x)))
#define K_PRIO_PREEMPT(x) (x)

#define K_HIGHEST_THREAD_PRIO             (-CONFIG_NUM_COOP_PRIORITIES)
#define K_LOWEST_THREAD_PRIO              CONFIG_NUM_PREEMPT_PRIORITIES
#define K_IDLE_PRIO                       K_LOWEST_THREAD_PRIO
#define K_HIGHEST_APPLICATION_THREAD_PRIO (K_HIGHEST_THREAD_PRIO)
#define K_LOWEST_APPLICATION_THREAD_PRIO  (K_LOWEST_THREAD_PRIO - 1)

/** @} */

/** @name Thread options */
/** @{ */
/** The system halts if the thread ends (accepted, not enforced on native_posix). */
#define K_ESSENTIAL     (BIT(0))
/** The thread uses the FPU (no effect on native_posix). */
#define K_FP_REGS       (BIT(1))
/** The thread runs in user mode (no effect on native_posix). */
#define K_USER          (BIT(2))
/** The thread inherits its creator's permissions (no effect on native_posix). */
#define K_INHERIT_PERMS (BIT(3))
/** @} */

/**
 * @brief Create a thread.
 *
 * @param new_thread Thread object; must stay valid until the thread has ended and been joined.
 * @param stack Stack object from K_THREAD_STACK_DEFINE() (not used by native_posix, see
 *              kernel/thread_stack.h).
 * @param stack_size Usable stack size in bytes (K_THREAD_STACK_SIZEOF()).
 * @param entry Entry point; the thread ends when it returns.
 * @param p1 First entry point argument.
 * @param p2 Second entry point argument.
 * @param p3 Third entry point argument.
 * @param prio Priority (K_HIGHEST_THREAD_PRIO..K_LOWEST_APPLICATION_THREAD_PRIO).
 * @param options K_ESSENTIAL, K_FP_REGS, K_USER, K_INHERIT_PERMS.
 * @param delay K_NO_WAIT to start at once, K_FOREVER to wait for k_thread_start(), or a delay.
 *
 * @return ID of the new thread (@p new_thread).
 */
k_tid_t k_thread_create(struct k_thread *new_thread, k_thread_stack_t *stack, size_t stack_size,
			k_thread_entry_t entry, void *p1, void *p2, void *p3, int prio,
			uint32_t options, k_timeout_t delay);

/**
 * @brief Start a thread created with a K_FOREVER delay (no effect on a started thread).
 */
void k_thread_start(k_tid_t thread);

/**
 * @brief Wait for @p thread to end.
 *
 * @param thread Thread to wait for.
 * @param timeout How long to wait.
 *
 * @retval 0 The thread has ended (or had already).
 * @retval -EBUSY The thread is running and @p timeout is K_NO_WAIT.
 * @retval -EAGAIN The thread was still running when @p timeout expired.
 * @retval -EDEADLK @p thread is the caller, or @p thread is itself joining the caller.
 */
int k_thread_join(struct k_thread *thread, k_timeout_t timeout);

/**
 * @brief End a thread.
 *
 * Ending the calling thread does not return. Another thread ends at its next kernel call
 * (a blocking call, a sleep, k_yield()): on a host a thread cannot be stopped at an arbitrary
 * instruction without leaking the host's locks, so k_thread_abort() waits until then.
 * Aborting a thread that has not started, or has ended, takes effect at once.
 */
void k_thread_abort(k_tid_t thread);

/** @brief ID of the calling thread. */
k_tid_t k_current_get(void);

/**
 * @brief Name a thread.
 *
 * @param thread Thread to name, or NULL for the calling thread.
 * @param str Name; at most CONFIG_THREAD_MAX_NAME_LEN - 1 characters are kept.
 *
 * @retval 0 Success.
 */
int k_thread_name_set(k_tid_t thread, const char *str);

/**
 * @brief Name of @p thread ("" if it has none).
 */
const char *k_thread_name_get(k_tid_t thread);

/**
 * @brief Copy the name of @p thread into @p buf (@p size bytes, always terminated).
 *
 * @retval 0 Success.
 */
int k_thread_name_copy(k_tid_t thread, char *buf, size_t size);

#if defined(CONFIG_THREAD_CUSTOM_DATA) || defined(__DOXYGEN__)
/**
 * @brief Set the calling thread's custom data (one pointer per thread, as Zephyr's).
 *
 * @param value The value.
 */
void k_thread_custom_data_set(void *value);

/** @brief The calling thread's custom data (NULL until set). */
void *k_thread_custom_data_get(void);
#endif

/** @brief Current priority of @p thread (including a priority inherited from a mutex). */
int k_thread_priority_get(k_tid_t thread);

/** @brief Set the priority of @p thread; a waiting thread moves within its wait queue. */
void k_thread_priority_set(k_tid_t thread, int prio);

/**
 * @brief Sleep.
 *
 * @param timeout How long (or until when) to sleep; K_FOREVER sleeps until k_wakeup().
 *
 * @return 0 after a full sleep; if woken early by k_wakeup(), the milliseconds left (rounded
 *         up), or K_TICKS_FOREVER for a K_FOREVER sleep.
 */
int32_t k_sleep(k_timeout_t timeout);

/** @brief Sleep @p ms milliseconds; return as k_sleep(). */
static inline int32_t k_msleep(int32_t ms)
{
	return k_sleep(Z_TIMEOUT_MS(ms));
}

/**
 * @brief Sleep @p us microseconds (rounded up to whole ticks).
 *
 * @return 0, or the microseconds left if woken early by k_wakeup().
 */
int32_t k_usleep(int32_t us);

/** @brief Wake @p thread from k_sleep() early (no effect on a thread that is not asleep). */
void k_wakeup(k_tid_t thread);

/**
 * @brief Wait @p usec_to_wait microseconds without sleeping on a kernel object.
 *
 * On native_posix this does not spin: the host thread sleeps, so busy-waits in firmware do
 * not starve other threads of the host's few cores.
 */
void k_busy_wait(uint32_t usec_to_wait);

/** @brief Let other threads run. */
void k_yield(void);

/** @brief Whether the caller runs in interrupt context (timer expiry functions do). */
bool k_is_in_isr(void);

/**
 * @brief Define and start a thread at boot (after the APPLICATION init level, before main()).
 *
 * @param _name Thread ID variable (const k_tid_t); also the thread's name.
 * @param _stack_size Stack size in bytes.
 * @param _entry Entry point.
 * @param _p1 First entry point argument.
 * @param _p2 Second entry point argument.
 * @param _p3 Third entry point argument.
 * @param _prio Priority.
 * @param _options Thread options.
 * @param _delay Start delay in milliseconds (0: at once; SYS_FOREVER_MS: wait for
 *              k_thread_start()).
 */
#define K_THREAD_DEFINE(_name, _stack_size, _entry, _p1, _p2, _p3, _prio, _options, _delay)        \
	K_THREAD_STACK_DEFINE(_k_thread_stack_##_name, _stack_size);                               \
	static struct k_thread _k_thread_obj_##_name;                                              \
	static struct z_static_thread _k_thread_data_##_name = {                                   \
		.thread = &_k_thread_obj_##_name,                                                  \
		.stack = _k_thread_stack_##_name,                                                  \
		.stack_size = K_THREAD_STACK_SIZEOF(_k_thread_stack_##_name),                      \
		.entry = (_entry),                                                                 \
		.p1 = (void *)(_p1),                                                               \
		.p2 = (void *)(_p2),                                                               \
		.p3 = (void *)(_p3),                                                               \
		.prio = (_prio),                                                                   \
		.options = (_options),                                                             \
		.delay_ms = (_delay),                                                              \
		.name = #_name,                                                                    \
	};                                                                                         \
	static void __attribute__((constructor)) _k_thread_reg_##_name(void)                       \
	{                                                                                          \
		z_static_thread_register(&_k_thread_data_##_name);                                 \
	}                                                                                          \
	const k_tid_t _name = &_k_thread_obj_##_name

/** @cond INTERNAL_HIDDEN */
struct z_static_thread {
	struct k_thread *thread;
	k_thread_stack_t *stack;
	size_t stack_size;
	k_thread_entry_t entry;
	void *p1;
	void *p2;
	void *p3;
	int prio;
	uint32_t options;
	int32_t delay_ms;
	const char *name;
	struct z_static_thread *next;
};

void z_static_thread_register(struct z_static_thread *data);
/** @endcond */

/** @name Time */
/** @{ */

/** @brief Ticks elapsed since boot. */
static inline int64_t k_uptime_ticks(void)
{
	return sys_clock_tick_get();
}

/** @brief Milliseconds elapsed since boot. */
static inline int64_t k_uptime_get(void)
{
	return (int64_t)k_ticks_to_ms_floor64((uint64_t)k_uptime_ticks());
}

/** @brief Milliseconds elapsed since boot, truncated to 32 bits (wraps after ~49 days). */
static inline uint32_t k_uptime_get_32(void)
{
	return (uint32_t)k_uptime_get();
}

/** @brief Whole seconds elapsed since boot. */
static inline uint32_t k_uptime_seconds(void)
{
	return (uint32_t)k_ticks_to_ms_floor64((uint64_t)k_uptime_ticks()) / MSEC_PER_SEC;
}

/**
 * @brief Milliseconds elapsed since @p *reftime; stores the current uptime in @p *reftime.
 */
static inline int64_t k_uptime_delta(int64_t *reftime)
{
	int64_t uptime = k_uptime_get();
	int64_t delta = uptime - *reftime;

	*reftime = uptime;

	return delta;
}

/** @brief Hardware cycle counter (CONFIG_SYS_CLOCK_HW_CYCLES_PER_SEC), 32 bits. */
uint32_t k_cycle_get_32(void);

/** @brief Hardware cycle counter, 64 bits. */
uint64_t k_cycle_get_64(void);

/** @} */

/**
 * @brief Raise a moderate fatal error (reason K_ERR_KERNEL_OOPS).
 */
#define k_oops() z_except_reason(K_ERR_KERNEL_OOPS)

/**
 * @brief Raise a severe fatal error (reason K_ERR_KERNEL_PANIC).
 */
#define k_panic() z_except_reason(K_ERR_KERNEL_PANIC)

/* ---------------------------------------------------------------------------------------- */

/**
 * @brief A mutex: recursive, owned, with priority inheritance.
 */
struct k_mutex {
	/** @cond INTERNAL_HIDDEN */
	_wait_q_t wait_q;
	struct k_thread *owner;
	uint32_t lock_count;
	int owner_orig_prio;
	/* native_posix: 0 free, 1 locked, 2 locked and maybe waited for (the fast path's word). */
	int state;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
#define Z_MUTEX_INITIALIZER(obj)                                                                   \
	{                                                                                          \
		.wait_q = Z_WAIT_Q_INIT(&(obj).wait_q),                                            \
		.owner = NULL,                                                                     \
		.lock_count = 0,                                                                   \
		.owner_orig_prio = K_LOWEST_APPLICATION_THREAD_PRIO,                               \
		.state = 0,                                                                        \
	}
/** @endcond */

/** Define and initialize a mutex (no run-time init needed). */
#define K_MUTEX_DEFINE(name) struct k_mutex name = Z_MUTEX_INITIALIZER(name)

/**
 * @brief Initialize a mutex (unlocked).
 *
 * @retval 0 Success.
 */
int k_mutex_init(struct k_mutex *mutex);

/**
 * @brief Lock a mutex.
 *
 * The owner may lock it again (each lock needs one unlock). While a higher-priority thread
 * waits, the owner runs at that thread's priority (priority inheritance).
 *
 * @retval 0 Locked.
 * @retval -EBUSY Owned by another thread and @p timeout is K_NO_WAIT.
 * @retval -EAGAIN Still owned by another thread when @p timeout expired.
 */
int k_mutex_lock(struct k_mutex *mutex, k_timeout_t timeout);

/**
 * @brief Unlock a mutex; the last unlock hands it to the highest-priority waiter.
 *
 * @retval 0 Unlocked (or its lock count decreased).
 * @retval -EPERM The caller does not own the mutex.
 * @retval -EINVAL The mutex is not locked.
 */
int k_mutex_unlock(struct k_mutex *mutex);

/* ---------------------------------------------------------------------------------------- */

/**
 * @brief A counting semaphore.
 */
struct k_sem {
	/** @cond INTERNAL_HIDDEN */
	_wait_q_t wait_q;
	unsigned int count;
	unsigned int limit;
	/** @endcond */
};

/** Largest semaphore limit. */
#define K_SEM_MAX_LIMIT UINT_MAX

/** @cond INTERNAL_HIDDEN */
#define Z_SEM_INITIALIZER(obj, initial_count, count_limit)                                         \
	{                                                                                          \
		.wait_q = Z_WAIT_Q_INIT(&(obj).wait_q),                                            \
		.count = (initial_count),                                                          \
		.limit = (count_limit),                                                            \
	}
/** @endcond */

/** Define and initialize a semaphore (no run-time init needed). */
#define K_SEM_DEFINE(name, initial_count, count_limit)                                             \
	struct k_sem name = Z_SEM_INITIALIZER(name, initial_count, count_limit);                   \
	BUILD_ASSERT(((count_limit) != 0) && ((initial_count) <= (count_limit)) &&                 \
		     ((count_limit) <= K_SEM_MAX_LIMIT))

/**
 * @brief Initialize a semaphore.
 *
 * @retval 0 Success.
 * @retval -EINVAL @p limit is 0 or @p initial_count exceeds it.
 */
int k_sem_init(struct k_sem *sem, unsigned int initial_count, unsigned int limit);

/**
 * @brief Take a semaphore.
 *
 * @retval 0 Taken.
 * @retval -EBUSY Not available and @p timeout is K_NO_WAIT.
 * @retval -EAGAIN Not available before @p timeout expired, or reset while waiting.
 */
int k_sem_take(struct k_sem *sem, k_timeout_t timeout);

/**
 * @brief Give a semaphore: wake the highest-priority waiter, else count up (not beyond the
 *        limit).
 */
void k_sem_give(struct k_sem *sem);

/** @brief Set the count to 0; waiters return -EAGAIN. */
void k_sem_reset(struct k_sem *sem);

/** @brief Current count. */
unsigned int k_sem_count_get(struct k_sem *sem);

/* ---------------------------------------------------------------------------------------- */

/**
 * @brief A message queue of fixed-size messages in a caller-provided ring buffer.
 */
struct k_msgq {
	/** @cond INTERNAL_HIDDEN */
	_wait_q_t wait_q;
	size_t msg_size;
	uint32_t max_msgs;
	char *buffer_start;
	char *buffer_end;
	char *read_ptr;
	char *write_ptr;
	uint32_t used_msgs;
	uint8_t flags;
	/** @endcond */
};

/** Message queue attributes. */
struct k_msgq_attrs {
	/** Message size in bytes. */
	size_t msg_size;
	/** Capacity in messages. */
	uint32_t max_msgs;
	/** Messages in the queue. */
	uint32_t used_msgs;
};

/** @cond INTERNAL_HIDDEN */
#define Z_MSGQ_INITIALIZER(obj, q_buffer, q_msg_size, q_max_msgs)                                  \
	{                                                                                          \
		.wait_q = Z_WAIT_Q_INIT(&(obj).wait_q),                                            \
		.msg_size = (q_msg_size),                                                          \
		.max_msgs = (q_max_msgs),                                                          \
		.buffer_start = (q_buffer),                                                        \
		.buffer_end = (q_buffer) + ((q_max_msgs) * (q_msg_size)),                          \
		.read_ptr = (q_buffer),                                                            \
		.write_ptr = (q_buffer),                                                           \
		.used_msgs = 0,                                                                    \
		.flags = 0,                                                                        \
	}
/** @endcond */

/**
 * @brief Define a message queue and its buffer (no run-time init needed).
 *
 * @param q_name Queue name.
 * @param q_msg_size Message size in bytes.
 * @param q_max_msgs Capacity in messages.
 * @param q_align Alignment of the buffer (a power of two).
 */
#define K_MSGQ_DEFINE(q_name, q_msg_size, q_max_msgs, q_align)                                     \
	static char __aligned(q_align) _k_fifo_buf_##q_name[(q_max_msgs) * (q_msg_size)];          \
	struct k_msgq q_name =                                                                     \
		Z_MSGQ_INITIALIZER(q_name, _k_fifo_buf_##q_name, (q_msg_size), (q_max_msgs))

/**
 * @brief Initialize a message queue over @p buffer (@p max_msgs * @p msg_size bytes).
 */
void k_msgq_init(struct k_msgq *msgq, char *buffer, size_t msg_size, uint32_t max_msgs);

/**
 * @brief Release a message queue.
 *
 * @retval 0 Success.
 * @retval -EBUSY Threads are waiting on it.
 */
int k_msgq_cleanup(struct k_msgq *msgq);

/**
 * @brief Put a message at the back of the queue (copied; handed directly to a waiting reader).
 *
 * @retval 0 Queued.
 * @retval -ENOMSG Full and @p timeout is K_NO_WAIT, or purged while waiting.
 * @retval -EAGAIN Still full when @p timeout expired.
 */
int k_msgq_put(struct k_msgq *msgq, const void *data, k_timeout_t timeout);

/**
 * @brief Take the message at the front of the queue.
 *
 * @retval 0 @p data holds the message.
 * @retval -ENOMSG Empty and @p timeout is K_NO_WAIT.
 * @retval -EAGAIN Still empty when @p timeout expired.
 */
int k_msgq_get(struct k_msgq *msgq, void *data, k_timeout_t timeout);

/**
 * @brief Copy the message at the front without removing it.
 *
 * @retval 0 @p data holds the message.
 * @retval -ENOMSG The queue is empty.
 */
int k_msgq_peek(struct k_msgq *msgq, void *data);

/**
 * @brief Copy the message at position @p idx (0 = front) without removing it.
 *
 * @retval 0 @p data holds the message.
 * @retval -ENOMSG Fewer than @p idx + 1 messages are queued.
 */
int k_msgq_peek_at(struct k_msgq *msgq, void *data, uint32_t idx);

/** @brief Discard every message; waiting writers return -ENOMSG. */
void k_msgq_purge(struct k_msgq *msgq);

/** @brief Free slots. */
uint32_t k_msgq_num_free_get(struct k_msgq *msgq);

/** @brief Queued messages. */
uint32_t k_msgq_num_used_get(struct k_msgq *msgq);

/** @brief Read the queue's attributes. */
void k_msgq_get_attrs(struct k_msgq *msgq, struct k_msgq_attrs *attrs);

/* ---------------------------------------------------------------------------------------- */

/** @cond INTERNAL_HIDDEN */
struct _timeout;
typedef void (*_timeout_func_t)(struct _timeout *t);

/* A pending timeout: a node in the kernel's deadline list. */
struct _timeout {
	sys_dnode_t node;
	_timeout_func_t fn;
	/* Deadline in ns since boot. */
	int64_t deadline_ns;
};
/** @endcond */

struct k_timer;

/** Timer expiry function; runs in the timer (interrupt-like) context and must not block. */
typedef void (*k_timer_expiry_t)(struct k_timer *timer);
/** Timer stop function; runs in the thread that calls k_timer_stop(). */
typedef void (*k_timer_stop_t)(struct k_timer *timer);

/**
 * @brief A timer: one-shot or periodic, with optional expiry and stop functions.
 */
struct k_timer {
	/** @cond INTERNAL_HIDDEN */
	struct _timeout timeout;
	_wait_q_t wait_q;
	k_timer_expiry_t expiry_fn;
	k_timer_stop_t stop_fn;
	k_timeout_t period;
	uint32_t status;
	void *user_data;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
#define Z_TIMER_INITIALIZER(obj, expiry, stop)                                                     \
	{                                                                                          \
		.timeout = {.node = {{NULL}, {NULL}}, .fn = NULL, .deadline_ns = 0},               \
		.wait_q = Z_WAIT_Q_INIT(&(obj).wait_q),                                            \
		.expiry_fn = (expiry),                                                             \
		.stop_fn = (stop),                                                                 \
		.period = {0},                                                                     \
		.status = 0,                                                                       \
		.user_data = NULL,                                                                 \
	}
/** @endcond */

/** Define and initialize a timer (no run-time init needed). */
#define K_TIMER_DEFINE(name, expiry_fn, stop_fn)                                                   \
	struct k_timer name = Z_TIMER_INITIALIZER(name, expiry_fn, stop_fn)

/**
 * @brief Initialize a timer.
 *
 * @param timer Timer.
 * @param expiry_fn Called at each expiry (timer context), or NULL.
 * @param stop_fn Called when k_timer_stop() stops a running timer, or NULL.
 */
void k_timer_init(struct k_timer *timer, k_timer_expiry_t expiry_fn, k_timer_stop_t stop_fn);

/**
 * @brief Start (or restart) a timer; its status is reset to 0.
 *
 * @param timer Timer.
 * @param duration Time to the first expiry (K_NO_WAIT: at once; K_FOREVER: do nothing).
 * @param period Interval between later expiries, counted from the previous deadline so that
 *               the timer does not drift; K_NO_WAIT or K_FOREVER for a one-shot timer.
 */
void k_timer_start(struct k_timer *timer, k_timeout_t duration, k_timeout_t period);

/**
 * @brief Stop a timer. If it was running, call its stop function and wake a thread waiting
 *        in k_timer_status_sync().
 */
void k_timer_stop(struct k_timer *timer);

/** @brief Expiries since the last status read (reset to 0). */
uint32_t k_timer_status_get(struct k_timer *timer);

/**
 * @brief Wait for the next expiry (or a stop) of a running timer, then read and reset its
 *        status. Returns at once if the status is non-zero or the timer is stopped.
 */
uint32_t k_timer_status_sync(struct k_timer *timer);

/** @brief Uptime tick of the next expiry (meaningless if the timer is stopped). */
k_ticks_t k_timer_expires_ticks(const struct k_timer *timer);

/** @brief Ticks until the next expiry (0 if stopped). */
k_ticks_t k_timer_remaining_ticks(const struct k_timer *timer);

/** @brief Milliseconds until the next expiry, rounded down (0 if stopped). */
static inline uint32_t k_timer_remaining_get(struct k_timer *timer)
{
	return k_ticks_to_ms_floor32((uint32_t)k_timer_remaining_ticks(timer));
}

/** @brief Attach a user pointer to a timer. */
static inline void k_timer_user_data_set(struct k_timer *timer, void *user_data)
{
	timer->user_data = user_data;
}

/** @brief The user pointer attached to a timer. */
static inline void *k_timer_user_data_get(const struct k_timer *timer)
{
	return timer->user_data;
}

/* ---------------------------------------------------------------------------------------- */

struct k_work;
struct k_work_q;

/** Work handler; runs in the work queue's thread. */
typedef void (*k_work_handler_t)(struct k_work *work);

/** @name Work item state bits (k_work_busy_get()) */
/** @{ */
enum {
	/** @cond INTERNAL_HIDDEN */
	K_WORK_RUNNING_BIT = 0,
	K_WORK_CANCELING_BIT = 1,
	K_WORK_QUEUED_BIT = 2,
	K_WORK_DELAYED_BIT = 3,
	K_WORK_FLUSHING_BIT = 4,

	K_WORK_MASK = BIT(K_WORK_DELAYED_BIT) | BIT(K_WORK_QUEUED_BIT) | BIT(K_WORK_RUNNING_BIT) |
		      BIT(K_WORK_CANCELING_BIT) | BIT(K_WORK_FLUSHING_BIT),

	K_WORK_DELAYABLE_BIT = 8,
	K_WORK_DELAYABLE = BIT(K_WORK_DELAYABLE_BIT),

	K_WORK_QUEUE_STARTED_BIT = 0,
	K_WORK_QUEUE_STARTED = BIT(K_WORK_QUEUE_STARTED_BIT),
	K_WORK_QUEUE_BUSY_BIT = 1,
	K_WORK_QUEUE_BUSY = BIT(K_WORK_QUEUE_BUSY_BIT),
	K_WORK_QUEUE_DRAIN_BIT = 2,
	K_WORK_QUEUE_DRAIN = BIT(K_WORK_QUEUE_DRAIN_BIT),
	K_WORK_QUEUE_PLUGGED_BIT = 3,
	K_WORK_QUEUE_PLUGGED = BIT(K_WORK_QUEUE_PLUGGED_BIT),
	K_WORK_QUEUE_STOP_BIT = 4,
	K_WORK_QUEUE_STOP = BIT(K_WORK_QUEUE_STOP_BIT),
	K_WORK_QUEUE_NO_YIELD_BIT = 8,
	K_WORK_QUEUE_NO_YIELD = BIT(K_WORK_QUEUE_NO_YIELD_BIT),
	/** @endcond */

	/** The handler is running. */
	K_WORK_RUNNING = BIT(K_WORK_RUNNING_BIT),
	/** A cancellation is waiting for the handler to return. */
	K_WORK_CANCELING = BIT(K_WORK_CANCELING_BIT),
	/** The item is in a queue. */
	K_WORK_QUEUED = BIT(K_WORK_QUEUED_BIT),
	/** A delayable item's timer is running. */
	K_WORK_DELAYED = BIT(K_WORK_DELAYED_BIT),
	/** A flush is waiting for the item. */
	K_WORK_FLUSHING = BIT(K_WORK_FLUSHING_BIT),
};
/** @} */

/**
 * @brief A work item: a handler to run in a work queue's thread.
 */
struct k_work {
	/** @cond INTERNAL_HIDDEN */
	sys_snode_t node;
	k_work_handler_t handler;
	struct k_work_q *queue;
	uint32_t flags;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
#define Z_WORK_INITIALIZER(work_handler)                                                           \
	{                                                                                          \
		.handler = (work_handler),                                                         \
	}
/** @endcond */

/** Define and initialize a work item (no run-time init needed). */
#define K_WORK_DEFINE(work, work_handler) struct k_work work = Z_WORK_INITIALIZER(work_handler)

/**
 * @brief A delayable work item: a work item submitted by a timer.
 */
struct k_work_delayable {
	/** The work item (pass it to k_work_delayable_from_work() in the handler). */
	struct k_work work;
	/** @cond INTERNAL_HIDDEN */
	struct _timeout timeout;
	struct k_work_q *queue;
	/** @endcond */
};

/** @cond INTERNAL_HIDDEN */
#define Z_WORK_DELAYABLE_INITIALIZER(work_handler)                                                 \
	{                                                                                          \
		.work = {.handler = (work_handler), .flags = K_WORK_DELAYABLE},                    \
	}
/** @endcond */

/** Define and initialize a delayable work item (no run-time init needed). */
#define K_WORK_DELAYABLE_DEFINE(work, work_handler)                                                \
	struct k_work_delayable work = Z_WORK_DELAYABLE_INITIALIZER(work_handler)

/** @cond INTERNAL_HIDDEN */
struct z_work_flusher {
	struct k_work work;
	struct k_sem sem;
};

struct z_work_canceller {
	sys_snode_t node;
	struct k_work *work;
	struct k_sem sem;
};
/** @endcond */

/**
 * @brief Storage for the synchronous calls (flush, cancel_sync); the caller provides it, on
 *        its stack if it likes.
 */
struct k_work_sync {
	/** @cond INTERNAL_HIDDEN */
	union {
		struct z_work_flusher flusher;
		struct z_work_canceller canceller;
	};
	/** @endcond */
};

/** Work queue configuration for k_work_queue_start(). */
struct k_work_queue_config {
	/** Thread name, or NULL. */
	const char *name;
	/** Do not yield between work items. */
	bool no_yield;
	/** Mark the thread essential. */
	bool essential;
};

/**
 * @brief A work queue: a thread running work items one at a time, in submission order.
 */
struct k_work_q {
	/** @cond INTERNAL_HIDDEN */
	struct k_thread thread;
	sys_slist_t pending;
	_wait_q_t notifyq;
	_wait_q_t drainq;
	uint32_t flags;
	/** @endcond */
};

/** The system work queue, started at boot (POST_KERNEL). */
extern struct k_work_q k_sys_work_q;

/** @brief Initialize a work item. */
void k_work_init(struct k_work *work, k_work_handler_t handler);

/** @brief State of a work item: a combination of K_WORK_RUNNING, _CANCELING, _QUEUED, ... */
int k_work_busy_get(const struct k_work *work);

/** @brief Whether a work item is queued, running or being cancelled. */
static inline bool k_work_is_pending(const struct k_work *work)
{
	return k_work_busy_get(work) != 0;
}

/**
 * @brief Submit a work item to a queue.
 *
 * @param queue Queue, or NULL to resubmit to the queue it last ran on.
 * @param work Work item.
 *
 * @retval 0 Already queued (nothing changed).
 * @retval 1 Queued.
 * @retval 2 Queued to the queue that is running it (it runs again after it returns).
 * @retval -EBUSY Being cancelled, or the queue is draining or plugged.
 * @retval -EINVAL @p queue is NULL and the item never ran.
 * @retval -ENODEV The queue has not been started.
 */
int k_work_submit_to_queue(struct k_work_q *queue, struct k_work *work);

/** @brief Submit a work item to the system work queue; returns as k_work_submit_to_queue(). */
int k_work_submit(struct k_work *work);

/**
 * @brief Wait until a work item is neither queued nor running.
 *
 * @param work Work item (not a delayable one: use k_work_flush_delayable()).
 * @param sync Caller-provided storage for the wait.
 *
 * @return true if the call had to wait.
 */
bool k_work_flush(struct k_work *work, struct k_work_sync *sync);

/**
 * @brief Remove a work item from its queue if it has not started running.
 *
 * @return The item's state afterwards (k_work_busy_get()); K_WORK_RUNNING and
 *         K_WORK_CANCELING stay set while the handler runs.
 */
int k_work_cancel(struct k_work *work);

/**
 * @brief Cancel a work item and wait until its handler has returned.
 *
 * @return true if the item was pending (queued, running or cancelling) when called.
 */
bool k_work_cancel_sync(struct k_work *work, struct k_work_sync *sync);

/** @brief Initialize a work queue before k_work_queue_start(). */
void k_work_queue_init(struct k_work_q *queue);

/**
 * @brief Start a work queue's thread.
 *
 * @param queue Work queue.
 * @param stack Stack object.
 * @param stack_size Stack size in bytes.
 * @param prio Thread priority.
 * @param cfg Configuration, or NULL for the defaults.
 */
void k_work_queue_start(struct k_work_q *queue, k_thread_stack_t *stack, size_t stack_size,
			int prio, const struct k_work_queue_config *cfg);

/** @brief The thread of a work queue. */
static inline k_tid_t k_work_queue_thread_get(struct k_work_q *queue)
{
	return &queue->thread;
}

/**
 * @brief Wait until a work queue is empty and idle.
 *
 * While draining, only the queue's own handlers may submit to it. With @p plug the queue
 * then refuses submissions until k_work_queue_unplug().
 *
 * @retval 0 There was nothing to wait for.
 * @retval 1 The call waited.
 */
int k_work_queue_drain(struct k_work_q *queue, bool plug);

/**
 * @brief Accept submissions again after k_work_queue_drain(queue, true).
 *
 * @retval 0 Unplugged.
 * @retval -EALREADY The queue was not plugged.
 */
int k_work_queue_unplug(struct k_work_q *queue);

/**
 * @brief Stop a plugged, drained work queue's thread.
 *
 * @retval 0 Stopped; the queue may be started again.
 * @retval -EALREADY The queue is not running.
 * @retval -EBUSY The queue is not plugged (drain it with plug first).
 * @retval -ETIMEDOUT The thread did not stop within @p timeout.
 */
int k_work_queue_stop(struct k_work_q *queue, k_timeout_t timeout);

/** @brief Initialize a delayable work item. */
void k_work_init_delayable(struct k_work_delayable *dwork, k_work_handler_t handler);

/** @brief The delayable work item that contains @p work. */
static inline struct k_work_delayable *k_work_delayable_from_work(struct k_work *work)
{
	return CONTAINER_OF(work, struct k_work_delayable, work);
}

/** @brief State of a delayable work item (K_WORK_DELAYED while its timer runs). */
int k_work_delayable_busy_get(const struct k_work_delayable *dwork);

/** @brief Whether a delayable work item is scheduled, queued, running or being cancelled. */
static inline bool k_work_delayable_is_pending(const struct k_work_delayable *dwork)
{
	return k_work_delayable_busy_get(dwork) != 0;
}

/** @brief Uptime tick at which the item's timer expires (0 if not scheduled). */
k_ticks_t k_work_delayable_expires_get(const struct k_work_delayable *dwork);

/** @brief Ticks until the item's timer expires (0 if not scheduled). */
k_ticks_t k_work_delayable_remaining_get(const struct k_work_delayable *dwork);

/**
 * @brief Submit a delayable work item after @p delay, unless it is already scheduled or
 *        queued (the earlier schedule stands).
 *
 * @param queue Queue to submit to.
 * @param dwork Delayable work item.
 * @param delay Delay; K_NO_WAIT submits at once.
 *
 * @retval 0 Already scheduled or queued (nothing changed).
 * @retval 1 Scheduled, or (with K_NO_WAIT) queued.
 * @retval 2 K_NO_WAIT and the item was running: queued to its queue.
 * @retval -EBUSY K_NO_WAIT and the submission was refused (see k_work_submit_to_queue()).
 * @retval -EINVAL K_NO_WAIT and @p queue is NULL.
 * @retval -ENODEV K_NO_WAIT and the queue has not been started.
 */
int k_work_schedule_for_queue(struct k_work_q *queue, struct k_work_delayable *dwork,
			      k_timeout_t delay);

/** @brief k_work_schedule_for_queue() on the system work queue. */
int k_work_schedule(struct k_work_delayable *dwork, k_timeout_t delay);

/**
 * @brief Submit a delayable work item after @p delay, replacing any earlier schedule.
 *
 * An item that is already queued stays queued (it runs, and runs again after @p delay).
 *
 * @retval 0 K_NO_WAIT and the item was already queued.
 * @retval 1 Scheduled, or (with K_NO_WAIT) queued.
 * @retval 2 K_NO_WAIT and the item was running: queued to its queue.
 * @retval -EBUSY K_NO_WAIT and the submission was refused.
 * @retval -EINVAL K_NO_WAIT and @p queue is NULL.
 * @retval -ENODEV K_NO_WAIT and the queue has not been started.
 */
int k_work_reschedule_for_queue(struct k_work_q *queue, struct k_work_delayable *dwork,
				k_timeout_t delay);

/** @brief k_work_reschedule_for_queue() on the system work queue. */
int k_work_reschedule(struct k_work_delayable *dwork, k_timeout_t delay);

/**
 * @brief Submit a scheduled item at once and wait until it is neither queued nor running.
 *
 * @return true if the call had to wait.
 */
bool k_work_flush_delayable(struct k_work_delayable *dwork, struct k_work_sync *sync);

/**
 * @brief Stop a delayable item's timer and remove it from its queue.
 *
 * @return The item's state afterwards (k_work_delayable_busy_get()).
 */
int k_work_cancel_delayable(struct k_work_delayable *dwork);

/**
 * @brief Cancel a delayable work item and wait until its handler has returned.
 *
 * @return true if the item was pending when called.
 */
bool k_work_cancel_delayable_sync(struct k_work_delayable *dwork, struct k_work_sync *sync);

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_KERNEL_H_ */
