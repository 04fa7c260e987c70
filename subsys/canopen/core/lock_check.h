/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The lock rule (doc/architecture.md, "Locks"): the stack's internals and the dictionary run
 * with the node's mutex held. CO_ASSERT_LOCKED() stops the program where that is not so
 * (CONFIG_CANOPEN_LOCK_CHECK); without the option it costs nothing.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_CORE_LOCK_CHECK_H_
#define SAFELINE_SUBSYS_CANOPEN_CORE_LOCK_CHECK_H_

#include <stdbool.h>

#if defined(CONFIG_CANOPEN_LOCK_CHECK)
#include <zephyr/kernel.h>

/* Log who broke the rule where, then k_panic(). */
void co_lock_violation(const struct k_mutex *lock, const char *file, int line);

static inline bool co_lock_held(const struct k_mutex *lock)
{
	/* Only this thread can make the owner equal to itself: an unlocked read is exact. */
	return __atomic_load_n(&lock->owner, __ATOMIC_RELAXED) == k_current_get();
}

#define CO_ASSERT_LOCKED(lock)                                                                     \
	do {                                                                                       \
		if (!co_lock_held(lock)) {                                                         \
			co_lock_violation((lock), __FILE__, __LINE__);                             \
		}                                                                                  \
	} while (false)
#else
#define CO_ASSERT_LOCKED(lock) ((void)(lock))
#endif

#endif /* SAFELINE_SUBSYS_CANOPEN_CORE_LOCK_CHECK_H_ */
