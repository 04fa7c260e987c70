/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The kernel and driver functions the stack calls, as empty stand-ins, so that scripts/footprint
 * can link the stack for a Cortex-M4 without Zephyr. On a target Zephyr provides them; their
 * size is Zephyr's, not the stack's, so scripts/footprint does not count this file.
 */

#include <errno.h>
#include <stdarg.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/crc.h>

/* Stops the optimiser from folding a stub's result into its caller. */
static volatile int fp_sink;

void fp_reset(void);
extern int main(void);

__attribute__((section(".fp_vectors"), used)) static void (*const fp_vectors[2])(void) = {
	(void (*)(void))0x20040000, fp_reset};

void fp_reset(void)
{
	(void)main();
	for (;;) {
	}
}

/* --- Kernel ------------------------------------------------------------------------------- */

int k_mutex_init(struct k_mutex *mutex)
{
	return fp_sink;
}

int k_mutex_lock(struct k_mutex *mutex, k_timeout_t timeout)
{
	return fp_sink;
}

int k_mutex_unlock(struct k_mutex *mutex)
{
	return fp_sink;
}

void k_msgq_init(struct k_msgq *msgq, char *buffer, size_t msg_size, uint32_t max_msgs)
{
	fp_sink = (int)max_msgs;
}

int k_msgq_put(struct k_msgq *msgq, const void *data, k_timeout_t timeout)
{
	return fp_sink;
}

int k_msgq_get(struct k_msgq *msgq, void *data, k_timeout_t timeout)
{
	return fp_sink;
}

void k_msgq_purge(struct k_msgq *msgq)
{
}

uint32_t k_msgq_num_used_get(struct k_msgq *msgq)
{
	return (uint32_t)fp_sink;
}

k_tid_t k_thread_create(struct k_thread *new_thread, k_thread_stack_t *stack, size_t stack_size,
			k_thread_entry_t entry, void *p1, void *p2, void *p3, int prio,
			uint32_t options, k_timeout_t delay)
{
	return new_thread;
}

int k_thread_join(struct k_thread *thread, k_timeout_t timeout)
{
	return fp_sink;
}

k_tid_t k_current_get(void)
{
	return (k_tid_t)(uintptr_t)fp_sink;
}

int k_thread_name_set(k_tid_t thread, const char *str)
{
	return fp_sink;
}

static void *fp_custom;

void k_thread_custom_data_set(void *value)
{
	fp_custom = value;
}

void *k_thread_custom_data_get(void)
{
	return fp_custom;
}

int32_t k_sleep(k_timeout_t timeout)
{
	return fp_sink;
}

int64_t sys_clock_tick_get(void)
{
	return fp_sink;
}

void printk(const char *fmt, ...)
{
	fp_sink = fmt[0];
}

uint16_t crc16_itu_t(uint16_t seed, const uint8_t *src, size_t len)
{
	return (uint16_t)(seed + len);
}

/* --- Devices and CAN -------------------------------------------------------------------------- */

const struct device *device_get_binding(const char *name)
{
	return (const struct device *)(uintptr_t)fp_sink;
}

bool device_is_ready(const struct device *dev)
{
	return fp_sink != 0;
}

int can_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
	     can_tx_callback_t callback, void *user_data)
{
	return fp_sink;
}

int can_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
		      const struct can_filter *filter)
{
	return fp_sink;
}

/* --- Logging (CONFIG_LOG): Zephyr's logging core on a target -----------------------------------
 */

#if defined(CONFIG_LOG)
void z_log_printf(const struct log_source_const_data *source, uint8_t level, const char *func,
		  const char *fmt, ...)
{
	fp_sink = level;
}

void z_log_hexdump(const struct log_source_const_data *source, uint8_t level, const void *data,
		   size_t length, const char *str)
{
	fp_sink = level;
}
#endif
