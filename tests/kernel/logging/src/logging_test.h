/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#ifndef TESTS_KERNEL_LOGGING_LOGGING_TEST_H_
#define TESTS_KERNEL_LOGGING_LOGGING_TEST_H_

/* Each logs at every level and returns how many calls evaluated their arguments. */
int log_from_declared_module(void);
int log_from_log_level_module(void);
int log_from_default_module(void);

#endif /* TESTS_KERNEL_LOGGING_LOGGING_TEST_H_ */
