/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Fatal errors, as Zephyr's fatal.h.
 *
 * On native_posix a fatal error prints ">>> SAFELINE FATAL ERROR <reason>: <text>" (the test
 * runner's fault marker), the current thread, and ends the process with exit code 1.
 */

#ifndef ZEPHYR_INCLUDE_FATAL_H_
#define ZEPHYR_INCLUDE_FATAL_H_

#include <zephyr/toolchain.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Why the system hit a fatal error. */
enum k_fatal_error_reason {
	/** Generic CPU exception, not covered by other codes. */
	K_ERR_CPU_EXCEPTION,
	/** Unhandled hardware interrupt. */
	K_ERR_SPURIOUS_IRQ,
	/** Faulting context overflowed its stack buffer. */
	K_ERR_STACK_CHK_FAIL,
	/** Moderate severity software error (k_oops()). */
	K_ERR_KERNEL_OOPS,
	/** High severity software error (k_panic(), failed __ASSERT()). */
	K_ERR_KERNEL_PANIC,
	/** Arch-specific codes start here. */
	K_ERR_ARCH_START = 16
};

/** Exception stack frame; on a host there is none, the pointer is always NULL. */
struct arch_esf;
/** Older name of struct arch_esf. */
typedef struct arch_esf z_arch_esf_t;

/**
 * @brief Halt the system after a fatal error: end the process with exit code 1.
 *
 * @param reason One of enum k_fatal_error_reason.
 */
FUNC_NORETURN void k_fatal_halt(unsigned int reason);

/**
 * @brief Decide what a fatal error does; called after the error has been reported.
 *
 * Weak: an application or test may replace it. The default calls k_fatal_halt(). A
 * replacement that returns lets the faulting thread be aborted instead (the rest of the
 * system keeps running).
 *
 * @param reason One of enum k_fatal_error_reason.
 * @param esf Exception stack frame (NULL on a host).
 */
void k_sys_fatal_error_handler(unsigned int reason, const struct arch_esf *esf);

/** @cond INTERNAL_HIDDEN */
/* Report a fatal error and run the handler; returns only if the handler did not halt. */
void z_fatal_error(unsigned int reason, const struct arch_esf *esf);
FUNC_NORETURN void z_except_reason(unsigned int reason);
/** @endcond */

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_FATAL_H_ */
