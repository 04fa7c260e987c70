/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include "common.h"

/* Test instances live in the test, not in the stack (which keeps no file-scope state). */
struct od_fixture fx;
