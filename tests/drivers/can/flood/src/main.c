/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Flood peer for tests/drivers/can/flood/pytest: can_socketcan0 sends a frame every 100 ms, as
 * a CANopen line sends its heartbeat, while cangen floods the bus.
 *
 * usage: zephyr.exe --can-if=0:<ifname> [--testargs <standard id in hex>...]
 *
 * - Receives the identifiers given on the command line (and counts their frames) and the
 *   control identifiers 0x7FE (report) and 0x7FF (quit); nothing else.
 * - Sends PERIODIC_ID every PERIOD_MS on a fixed schedule with can_send(K_NO_WAIT) and a
 *   callback. Its data is the attempt's 32-bit sequence number (little endian), so a send
 *   that failed is a gap in the sequence on the bus.
 * - Prints "READY" once started, one "STATS key=value..." line per report frame, and ends with
 *   status 0 on the quit frame (2 on a setup error).
 */

#include <errno.h>
#include <stdlib.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/atomic.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/printk.h>

#include <can_socketcan.h>

#include "cmdline.h"

#define PERIODIC_ID 0x701U
#define PERIOD_MS   100
#define REPORT_ID   0x7FEU
#define QUIT_ID     0x7FFU
#define MAX_USED    8

static K_SEM_DEFINE(control_sem, 0, 16);
static atomic_t report_requests;
static atomic_t quit_requested;

static atomic_t rx_used;    /* frames of the identifiers from the command line */
static atomic_t tx_ok;      /* TX callbacks with 0 */
static atomic_t tx_timeout; /* TX callbacks with -ETIMEDOUT */
static atomic_t tx_other;   /* TX callbacks with another error */

static void rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	if (frame->id == REPORT_ID) {
		(void)atomic_inc(&report_requests);
		k_sem_give(&control_sem);
	} else if (frame->id == QUIT_ID) {
		(void)atomic_set(&quit_requested, 1);
		k_sem_give(&control_sem);
	} else {
		(void)atomic_inc(&rx_used);
	}
}

static void tx_cb(const struct device *dev, int error, void *user_data)
{
	if (error == 0) {
		(void)atomic_inc(&tx_ok);
	} else if (error == -ETIMEDOUT) {
		(void)atomic_inc(&tx_timeout);
	} else {
		(void)atomic_inc(&tx_other);
	}
}

static struct {
	uint32_t attempts;
	uint32_t sent;
	uint32_t eagain;
	uint32_t failed;
} tx;

static void send_periodic(const struct device *dev)
{
	struct can_frame f = {.id = PERIODIC_ID, .dlc = 4};
	int rc;

	sys_put_le32(tx.attempts, f.data);
	tx.attempts++;
	rc = can_send(dev, &f, K_NO_WAIT, tx_cb, NULL);
	if (rc == 0) {
		tx.sent++;
	} else if (rc == -EAGAIN) {
		tx.eagain++;
	} else {
		tx.failed++;
	}
}

static void report(const struct device *dev)
{
	struct can_socketcan_stats s;

	(void)can_socketcan_get_stats(dev, &s);
	printk("STATS attempts=%u sent=%u eagain=%u failed=%u tx_ok=%ld tx_timeout=%ld "
	       "tx_other=%ld rx_used=%ld rx_frames=%u rx_overflows=%u tx_confirmed=%u "
	       "tx_echo_timeouts=%u tx_echoes_lost=%u tx_late_echoes=%u kernel_filters=%u\n",
	       tx.attempts, tx.sent, tx.eagain, tx.failed, atomic_get(&tx_ok),
	       atomic_get(&tx_timeout), atomic_get(&tx_other), atomic_get(&rx_used), s.rx_frames,
	       s.rx_overflows, s.tx_confirmed, s.tx_echo_timeouts, s.tx_echoes_lost,
	       s.tx_late_echoes, s.kernel_filters);
}

static int add_filter(const struct device *dev, uint32_t id)
{
	const struct can_filter f = {.id = id, .mask = CAN_STD_ID_MASK};
	int rc = can_add_rx_filter(dev, rx_cb, NULL, &f);

	if (rc < 0) {
		printk("ERROR can_add_rx_filter(0x%x): %d\n", id, rc);
	}
	return rc;
}

int main(void)
{
	const struct device *dev = device_get_binding("can_socketcan0");
	char **argv;
	int argc;
	int64_t next;

	if (dev == NULL) {
		printk("ERROR can_socketcan0 not ready\n");
		return 2;
	}
	native_get_test_cmd_line_args(&argc, &argv);
	if (argc > MAX_USED) {
		printk("ERROR at most %d identifiers\n", MAX_USED);
		return 2;
	}
	for (int i = 0; i < argc; i++) {
		char *end;
		unsigned long id = strtoul(argv[i], &end, 16);

		if (*end != '\0' || id > CAN_STD_ID_MASK || add_filter(dev, (uint32_t)id) < 0) {
			printk("ERROR bad identifier %s\n", argv[i]);
			return 2;
		}
	}
	if (add_filter(dev, REPORT_ID) < 0 || add_filter(dev, QUIT_ID) < 0) {
		return 2;
	}
	if (can_start(dev) != 0) {
		printk("ERROR can_start\n");
		return 2;
	}
	printk("READY\n");

	next = k_uptime_get();
	for (;;) {
		if (k_sem_take(&control_sem, K_TIMEOUT_ABS_MS(next)) != 0) {
			send_periodic(dev);
			next += PERIOD_MS;
			continue;
		}
		while (atomic_get(&report_requests) > 0) {
			(void)atomic_dec(&report_requests);
			report(dev);
		}
		if (atomic_get(&quit_requested) != 0) {
			break;
		}
	}
	report(dev);
	printk("QUIT\n");

	return 0;
}
