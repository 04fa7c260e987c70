/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Interop peer for tests/drivers/can/interop/pytest: can_socketcan0 against can-utils.
 *
 * usage: zephyr.exe --can-if=0:<ifname> --testargs <frame>...
 * Frames are in cansend syntax (123#11223344, 1ABCDEF0#, 456#R, 456#R3).
 *
 * 1. Receives through three filters and prints every frame as "RX <cansend syntax>" and
 *    every state change as "STATE <n> <tx_err_cnt> <rx_err_cnt>":
 *    standard 0x100..0x1FF (id 0x100, mask 0x700), extended 0x18DAxxxx (mask 0x1FFF0000),
 *    and the control ids 0x7FD (go) and 0x7FF (quit).
 * 2. Prints "READY", waits for the go frame, sends the frames of the command line (blocking,
 *    so each is confirmed by its echo) and prints "SENT <n>".
 * 3. Ends with status 0 on the quit frame, 1 after 120 s without it, 2 on a setup error.
 */

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/printk.h>

#include "cmdline.h"

#define GO_ID   0x7FDU
#define QUIT_ID 0x7FFU

K_SEM_DEFINE(go_sem, 0, 1);
K_SEM_DEFINE(quit_sem, 0, 1);

static void print_frame(const char *tag, const struct can_frame *f)
{
	if ((f->flags & CAN_FRAME_IDE) != 0U) {
		printk("%s %08X#", tag, f->id);
	} else {
		printk("%s %03X#", tag, f->id);
	}
	if ((f->flags & CAN_FRAME_RTR) != 0U) {
		printk("R%u\n", f->dlc);
		return;
	}
	for (int i = 0; i < f->dlc; i++) {
		printk("%02X", f->data[i]);
	}
	printk("\n");
}

static void rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	if ((frame->flags & CAN_FRAME_IDE) == 0U && frame->id == GO_ID) {
		k_sem_give(&go_sem);
	} else if ((frame->flags & CAN_FRAME_IDE) == 0U && frame->id == QUIT_ID) {
		k_sem_give(&quit_sem);
	} else {
		print_frame("RX", frame);
	}
}

static void state_cb(const struct device *dev, enum can_state state, struct can_bus_err_cnt cnt,
		     void *user_data)
{
	printk("STATE %d %u %u\n", (int)state, cnt.tx_err_cnt, cnt.rx_err_cnt);
}

static int hexval(char c)
{
	if (c >= '0' && c <= '9') {
		return c - '0';
	}
	if (c >= 'a' && c <= 'f') {
		return c - 'a' + 10;
	}
	if (c >= 'A' && c <= 'F') {
		return c - 'A' + 10;
	}
	return -1;
}

/* cansend syntax: 3 hex digits = standard id, 8 = extended; data in hex pairs, or R[dlc]. */
static int parse_frame(const char *s, struct can_frame *f)
{
	const char *hash = strchr(s, '#');
	const char *p;

	memset(f, 0, sizeof(*f));
	if (hash == NULL || (hash - s != 3 && hash - s != 8)) {
		return -EINVAL;
	}
	for (p = s; p < hash; p++) {
		if (hexval(*p) < 0) {
			return -EINVAL;
		}
		f->id = (f->id << 4) | (uint32_t)hexval(*p);
	}
	if (hash - s == 8) {
		f->flags |= CAN_FRAME_IDE;
	}
	p = hash + 1;
	if (*p == 'R') {
		f->flags |= CAN_FRAME_RTR;
		f->dlc = (p[1] != '\0') ? (uint8_t)(p[1] - '0') : 0U;
		return f->dlc <= CAN_MAX_DLC ? 0 : -EINVAL;
	}
	while (*p != '\0') {
		if (f->dlc == CAN_MAX_DLC || hexval(p[0]) < 0 || hexval(p[1]) < 0) {
			return -EINVAL;
		}
		f->data[f->dlc++] = (uint8_t)(hexval(p[0]) << 4 | hexval(p[1]));
		p += 2;
	}

	return 0;
}

int main(void)
{
	const struct device *dev = device_get_binding("can_socketcan0");
	const struct can_filter filters[] = {
		{.id = 0x100, .mask = 0x700},
		{.id = 0x18DA0000, .mask = 0x1FFF0000, .flags = CAN_FILTER_IDE},
		{.id = GO_ID, .mask = CAN_STD_ID_MASK},
		{.id = QUIT_ID, .mask = CAN_STD_ID_MASK},
	};
	char **argv;
	int argc;
	int rc;

	if (dev == NULL) {
		printk("ERROR can_socketcan0 not ready\n");
		return 2;
	}
	for (size_t i = 0; i < ARRAY_SIZE(filters); i++) {
		rc = can_add_rx_filter(dev, rx_cb, NULL, &filters[i]);
		if (rc < 0) {
			printk("ERROR can_add_rx_filter: %d\n", rc);
			return 2;
		}
	}
	can_set_state_change_callback(dev, state_cb, NULL);
	rc = can_start(dev);
	if (rc != 0) {
		printk("ERROR can_start: %d\n", rc);
		return 2;
	}
	printk("READY\n");

	if (k_sem_take(&go_sem, K_SECONDS(120)) != 0) {
		printk("ERROR no go frame\n");
		return 1;
	}
	native_get_test_cmd_line_args(&argc, &argv);
	for (int i = 0; i < argc; i++) {
		struct can_frame f;

		if (parse_frame(argv[i], &f) != 0) {
			printk("ERROR bad frame %s\n", argv[i]);
			return 2;
		}
		rc = can_send(dev, &f, K_SECONDS(5), NULL, NULL);
		if (rc != 0) {
			printk("ERROR can_send %s: %d\n", argv[i], rc);
			return 2;
		}
		print_frame("TX", &f);
	}
	printk("SENT %d\n", argc);

	if (k_sem_take(&quit_sem, K_SECONDS(120)) != 0) {
		printk("ERROR no quit frame\n");
		return 1;
	}
	printk("QUIT\n");

	return 0;
}
