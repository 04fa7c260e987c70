/*
 * SPDX-License-Identifier: Apache-2.0
 *
 * Fixture of the runner's tests: greets, then ticks forever.
 */
#include <zephyr/kernel.h>
#include <zephyr/sys/printk.h>

int main(void)
{
	printk("Hello from %s\n", CONFIG_BOARD);
	for (int tick = 1;; tick++) {
		k_msleep(50);
		printk("tick %d\n", tick);
	}
	return 0;
}
