/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Compiler attributes and compile-time checks (GCC/Clang), as Zephyr's toolchain.h.
 */

#ifndef ZEPHYR_INCLUDE_TOOLCHAIN_H_
#define ZEPHYR_INCLUDE_TOOLCHAIN_H_

#include <stdbool.h>

#ifndef __ORDER_BIG_ENDIAN__
#define __ORDER_BIG_ENDIAN__ (1)
#endif

#define Z_STRINGIFY(x) #x
/** Turn a macro argument into a string literal after expanding it. */
#define STRINGIFY(s)   Z_STRINGIFY(s)

#define _DO_CONCAT(x, y) x##y
/** Paste two tokens after expanding them. */
#define _CONCAT(x, y)    _DO_CONCAT(x, y)

/**
 * @brief Fail the build when @p EXPR is false (C11 static assertion).
 *
 * May appear at file scope and in function bodies; the message is optional.
 */
#define BUILD_ASSERT(EXPR, MSG...) _Static_assert((EXPR), "" MSG)

#ifndef __weak
#define __weak __attribute__((__weak__))
#endif
#ifndef __packed
#define __packed __attribute__((__packed__))
#endif
#ifndef __aligned
#define __aligned(x) __attribute__((__aligned__(x)))
#endif
#ifndef __used
#define __used __attribute__((__used__))
#endif
#ifndef __unused
#define __unused __attribute__((__unused__))
#endif
#ifndef __maybe_unused
#define __maybe_unused __attribute__((__unused__))
#endif
#ifndef __deprecated
#define __deprecated __attribute__((__deprecated__))
#endif
#ifndef __printf_like
#define __printf_like(f, a) __attribute__((__format__(__printf__, f, a)))
#endif
/* On a host there is no .noinit section: the object is ordinary zero-initialised data. */
#ifndef __noinit
#define __noinit
#endif
#ifndef __fallthrough
#define __fallthrough __attribute__((__fallthrough__))
#endif
#ifndef __syscall
#define __syscall
#endif
#ifndef ALWAYS_INLINE
#define ALWAYS_INLINE inline __attribute__((__always_inline__))
#endif
#ifndef FUNC_NORETURN
#define FUNC_NORETURN __attribute__((__noreturn__))
#endif
#ifndef CODE_UNREACHABLE
#define CODE_UNREACHABLE __builtin_unreachable()
#endif

#define likely(x)   (__builtin_expect((bool)!!(x), true) != 0L)
#define unlikely(x) (__builtin_expect((bool)!!(x), false) != 0L)

#endif /* ZEPHYR_INCLUDE_TOOLCHAIN_H_ */
