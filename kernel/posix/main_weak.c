/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * main() for images that have none, e.g. firmware made only of K_THREAD_DEFINE threads and
 * work items. Returning from main() ends a native_posix image, so this one sleeps: such an
 * image runs until --stop-at, a signal or a fatal error, as it would on a target.
 */

#include <zephyr/kernel.h>

__weak int main(void)
{
	for (;;) {
		(void)k_sleep(K_FOREVER);
	}

	return 0;
}
