/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Thread stack objects, as Zephyr's kernel/thread_stack.h.
 *
 * On native_posix every thread runs on a host stack that the host allocates (its size is the
 * host default, far larger than firmware stacks). The stack objects still exist, with the
 * declared size, so that firmware code that defines and measures them compiles unchanged.
 */

#ifndef ZEPHYR_INCLUDE_KERNEL_THREAD_STACK_H_
#define ZEPHYR_INCLUDE_KERNEL_THREAD_STACK_H_

#include <stddef.h>

#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @cond INTERNAL_HIDDEN */
struct z_thread_stack_element {
	char data;
};

#define Z_THREAD_STACK_OBJ_ALIGN 16
/** @endcond */

/** A thread stack object (declare with K_THREAD_STACK_DEFINE()). */
typedef struct z_thread_stack_element k_thread_stack_t;

/** Bytes of a stack object reserved by the kernel (none on native_posix). */
#define K_THREAD_STACK_RESERVED 0
/** Bytes of a kernel stack object reserved by the kernel (none on native_posix). */
#define K_KERNEL_STACK_RESERVED 0

/** Size in bytes of a stack object for a stack of @p size bytes. */
#define K_THREAD_STACK_LEN(size) ((size) + K_THREAD_STACK_RESERVED)
/** Size in bytes of a kernel stack object for a stack of @p size bytes. */
#define K_KERNEL_STACK_LEN(size) ((size) + K_KERNEL_STACK_RESERVED)

/** Usable size of the stack object @p sym. */
#define K_THREAD_STACK_SIZEOF(sym) (sizeof(sym) - K_THREAD_STACK_RESERVED)
/** Usable size of the kernel stack object @p sym. */
#define K_KERNEL_STACK_SIZEOF(sym) (sizeof(sym) - K_KERNEL_STACK_RESERVED)

/** Define a thread stack @p sym of @p size bytes (prefix with static for file scope). */
#define K_THREAD_STACK_DEFINE(sym, size)                                                           \
	struct z_thread_stack_element                                                              \
		__aligned(Z_THREAD_STACK_OBJ_ALIGN) sym[K_THREAD_STACK_LEN(size)]

/** Define an array of @p nmemb thread stacks of @p size bytes each. */
#define K_THREAD_STACK_ARRAY_DEFINE(sym, nmemb, size)                                              \
	struct z_thread_stack_element                                                              \
		__aligned(Z_THREAD_STACK_OBJ_ALIGN) sym[nmemb][K_THREAD_STACK_LEN(size)]

/** Declare a thread stack defined in another file. */
#define K_THREAD_STACK_EXTERN(sym) extern k_thread_stack_t sym[]

/** Define a stack for a thread that never enters user mode (same as a thread stack here). */
#define K_KERNEL_STACK_DEFINE(sym, size)                                                           \
	struct z_thread_stack_element                                                              \
		__aligned(Z_THREAD_STACK_OBJ_ALIGN) sym[K_KERNEL_STACK_LEN(size)]

/** Define an array of kernel stacks. */
#define K_KERNEL_STACK_ARRAY_DEFINE(sym, nmemb, size)                                              \
	struct z_thread_stack_element                                                              \
		__aligned(Z_THREAD_STACK_OBJ_ALIGN) sym[nmemb][K_KERNEL_STACK_LEN(size)]

/** Declare a kernel stack defined in another file. */
#define K_KERNEL_STACK_EXTERN(sym) extern k_thread_stack_t sym[]

/** Define a kernel stack as a struct member. */
#define K_KERNEL_STACK_MEMBER(sym, size)                                                           \
	struct z_thread_stack_element                                                              \
		__aligned(Z_THREAD_STACK_OBJ_ALIGN) sym[K_KERNEL_STACK_LEN(size)]

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_KERNEL_THREAD_STACK_H_ */
