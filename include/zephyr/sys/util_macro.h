/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Preprocessor helpers: bits, Kconfig tests and conditional code, as Zephyr's.
 */

#ifndef ZEPHYR_INCLUDE_SYS_UTIL_MACRO_H_
#define ZEPHYR_INCLUDE_SYS_UTIL_MACRO_H_

#include <zephyr/toolchain.h>

/** Unsigned integer with bit @p n set. */
#define BIT(n)   (1UL << (n))
/** 64-bit unsigned integer with bit @p n set. */
#define BIT64(n) (1ULL << (n))

/** Set or clear bit @p bit of @p var depending on @p set. */
#define WRITE_BIT(var, bit, set) ((var) = (set) ? ((var) | BIT(bit)) : ((var) & ~BIT(bit)))

/** Mask of the @p n least significant bits. */
#define BIT_MASK(n)   (BIT(n) - 1UL)
/** 64-bit mask of the @p n least significant bits. */
#define BIT64_MASK(n) (BIT64(n) - 1ULL)

/** Contiguous mask from bit @p l up to and including bit @p h. */
#define GENMASK(h, l)   (((~0UL) - (1UL << (l)) + 1) & (~0UL >> (sizeof(long) * 8 - 1 - (h))))
/** 64-bit contiguous mask from bit @p l up to and including bit @p h. */
#define GENMASK64(h, l) (((~0ULL) - (1ULL << (l)) + 1) & (~0ULL >> (64 - 1 - (h))))

/** Concatenate two tokens after expanding them. */
#define UTIL_CAT(a, ...)           UTIL_PRIMITIVE_CAT(a, __VA_ARGS__)
#define UTIL_PRIMITIVE_CAT(a, ...) a##__VA_ARGS__

/*
 * Kconfig tests. A Kconfig bool that is set is defined to 1; pasting it onto Z_XXXX yields a
 * macro with a trailing comma, which shifts the argument list by one. Anything else (undefined,
 * 0, another value) leaves the list unshifted.
 */
#define Z_XXXX1 Z_YYYY,

#define Z_IS_ENABLED1(config_macro)          Z_IS_ENABLED2(Z_XXXX##config_macro)
#define Z_IS_ENABLED2(one_or_two_args)       Z_IS_ENABLED3(one_or_two_args 1, 0)
#define Z_IS_ENABLED3(ignore_this, val, ...) val

/**
 * @brief 1 if @p config_macro is defined to 1, else 0; usable in C and in `#if`.
 */
#define IS_ENABLED(config_macro) Z_IS_ENABLED1(config_macro)

#define Z_DEBRACKET(...)                            __VA_ARGS__
#define Z_GET_ARG2_DEBRACKET(ignore_this, val, ...) Z_DEBRACKET val
#define Z_COND_CODE(one_or_two_args, _if_code, _else_code)                                         \
	Z_GET_ARG2_DEBRACKET(one_or_two_args _if_code, _else_code)
#define Z_COND_CODE_1(_flag, _if_1_code, _else_code)                                               \
	Z_COND_CODE(Z_XXXX##_flag, _if_1_code, _else_code)
#define Z_COND_CODE_0(_flag, _if_0_code, _else_code)                                               \
	Z_COND_CODE(Z_ZZZZ##_flag, _if_0_code, _else_code)
#define Z_ZZZZ0 Z_YYYY,

/**
 * @brief Insert @p _if_1_code if @p _flag is defined to 1, else @p _else_code.
 *
 * Both code arguments must be wrapped in parentheses, which are removed.
 */
#define COND_CODE_1(_flag, _if_1_code, _else_code) Z_COND_CODE_1(_flag, _if_1_code, _else_code)

/** Like COND_CODE_1() but tests for a flag defined to 0. */
#define COND_CODE_0(_flag, _if_0_code, _else_code) Z_COND_CODE_0(_flag, _if_0_code, _else_code)

/** Insert the code (in parentheses) only if @p _flag is defined to 1. */
#define IF_ENABLED(_flag, _code) COND_CODE_1(_flag, _code, ())

/** Insert the code (in parentheses) only if @p _flag is not defined to 1. */
#define IF_DISABLED(_flag, _code) COND_CODE_1(_flag, (), _code)

#endif /* ZEPHYR_INCLUDE_SYS_UTIL_MACRO_H_ */
