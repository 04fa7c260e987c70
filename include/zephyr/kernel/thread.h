/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief The thread object, as Zephyr's kernel/thread.h.
 *
 * Callers allocate struct k_thread (statically or in their own structs) and never touch its
 * fields; everything is accessed through the k_thread_*() API.
 */

#ifndef ZEPHYR_INCLUDE_KERNEL_THREAD_H_
#define ZEPHYR_INCLUDE_KERNEL_THREAD_H_

#include <stdint.h>

#include <zephyr/sys/dlist.h>
#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @cond INTERNAL_HIDDEN */

/* A queue of threads waiting on a kernel object, highest priority first. */
typedef struct {
	sys_dlist_t waitq;
} _wait_q_t;

#define Z_WAIT_Q_INIT(wait_q) {SYS_DLIST_STATIC_INIT(&(wait_q)->waitq)}

/* Scheduling state shared by every thread. */
struct _thread_base {
	/* Node in the wait queue the thread is pended on. */
	sys_dnode_t qnode_dlist;
	/* The wait queue the thread is pended on, or NULL. */
	_wait_q_t *pended_on;
	/* Current priority (may be raised by priority inheritance). */
	int prio;
	/* Z_THREAD_* state bits. */
	uint8_t thread_state;
	/* K_ESSENTIAL and friends. */
	uint32_t user_options;
};

/*
 * Storage for the host thread (pthread_t, a condition variable, ...). Opaque here so that no
 * host header leaks into the Zephyr API; kernel/posix checks at build time that it fits.
 */
struct _thread_arch {
	uint64_t host[16] __aligned(16);
};

/** @endcond */

/** Thread entry point. */
typedef void (*k_thread_entry_t)(void *p1, void *p2, void *p3);

/**
 * @brief A thread.
 */
struct k_thread {
	/** @cond INTERNAL_HIDDEN */
	struct _thread_base base;
	/* Threads waiting in k_thread_join() for this one. */
	_wait_q_t join_queue;
	k_thread_entry_t entry;
	void *p1;
	void *p2;
	void *p3;
	/* Result and payload handed over by the thread that wakes this one. */
	int swap_retval;
	void *swap_data;
	/* Absolute start time in ns since boot; INT64_MAX until k_thread_start(). */
	int64_t start_ns;
	char name[CONFIG_THREAD_MAX_NAME_LEN];
#if defined(CONFIG_THREAD_CUSTOM_DATA)
	void *custom_data;
#endif
	struct _thread_arch arch;
	/** @endcond */
};

/** Thread ID: a pointer to the thread object. */
typedef struct k_thread *k_tid_t;

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_KERNEL_THREAD_H_ */
