/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Plain-C boundary between the SocketCAN driver (RTOS side, socketcan.c) and the Linux side
 * (socketcan_host.c). Linux and Zephyr both define struct can_frame, so neither side's headers
 * may reach the other: this header uses only <stdbool.h>/<stdint.h>.
 *
 * All functions return 0 (or a value >= 0) on success and a negative errno on failure.
 */

#ifndef SAFELINE_DRIVERS_CAN_SOCKETCAN_HOST_H_
#define SAFELINE_DRIVERS_CAN_SOCKETCAN_HOST_H_

#include <stdbool.h>
#include <stdint.h>

/* Frame flags at the boundary. */
#define SOCKETCAN_HOST_F_IDE 0x01U /* 29-bit identifier */
#define SOCKETCAN_HOST_F_RTR 0x02U /* remote frame */
#define SOCKETCAN_HOST_F_ERR 0x04U /* error frame (received only; see decode_error) */

struct socketcan_host_frame {
	uint32_t id; /* identifier, or the error class bits of an error frame */
	uint8_t dlc;
	uint8_t flags;
	uint8_t data[8];
};

/* What an error frame says about the controller. */
enum socketcan_host_state {
	SOCKETCAN_HOST_STATE_NONE, /* no state information (e.g. only a protocol error) */
	SOCKETCAN_HOST_STATE_ACTIVE,
	SOCKETCAN_HOST_STATE_WARNING,
	SOCKETCAN_HOST_STATE_PASSIVE,
	SOCKETCAN_HOST_STATE_BUS_OFF,
};

/* Entries one socketcan_host_set_filters() call takes at most (the kernel's limit). */
#define SOCKETCAN_HOST_MAX_FILTERS 512

/*
 * One entry of the socket's kernel filter: frames whose identifier equals @p id in the bits set
 * in @p mask, of the type given by SOCKETCAN_HOST_F_IDE in @p flags (data and remote frames).
 */
struct socketcan_host_filter {
	uint32_t id;
	uint32_t mask;
	uint8_t flags;
};

/* What the kernel says about a received frame besides its content. */
struct socketcan_host_rx_info {
	uint64_t real_ns; /* receive time as stamped (CLOCK_REALTIME), 0 if none */
	uint64_t mono_ns; /* the same instant on CLOCK_MONOTONIC, 0 if none */
	uint32_t drops;   /* frames the socket dropped so far, its receive buffer being full */
	bool own;         /* the echo of a frame written through this socket */
};

struct socketcan_host_error {
	enum socketcan_host_state state;
	bool has_counters; /* the frame carried the error counters (CAN_ERR_CNT) */
	uint8_t tx_err_cnt;
	uint8_t rx_err_cnt;
};

/*
 * Open a raw CAN socket bound to @p ifname that receives all error frames, its own frames back
 * (as TX confirmations) and, until socketcan_host_set_filters() says otherwise, no other frame;
 * with kernel receive timestamps and the count of frames dropped on overflow.
 * Returns the socket (>= 0) or -errno (-ENODEV: no such interface; -EAFNOSUPPORT: no AF_CAN).
 */
int socketcan_host_open(const char *ifname);

/*
 * Replace the socket's kernel filter (CAN_RAW_FILTER) with @p n entries (0: no frame but
 * error frames). The kernel drops every other frame before it reaches the socket's buffer; a
 * frame that matches several entries is received once.
 */
int socketcan_host_set_filters(int fd, const struct socketcan_host_filter *filters, int n);

/* Make socketcan_host_recv() return -EAGAIN after @p ms without a frame (SO_RCVTIMEO). */
int socketcan_host_set_recv_timeout(int fd, uint32_t ms);

void socketcan_host_close(int fd);

/* Whether the interface is administratively and operationally up: 1, 0, or -errno. */
int socketcan_host_is_up(const char *ifname);

/*
 * Queue a frame without blocking. -EAGAIN when the interface's queue is full (-ENOBUFS from
 * the kernel is reported as -EAGAIN), -ENETDOWN when the interface is down, other -errno as is.
 */
int socketcan_host_send(int fd, const struct socketcan_host_frame *frame);

/*
 * Block until a frame arrives. @p info gets the kernel's receive time as the kernel stamped it
 * (CLOCK_REALTIME, comparable with socketcan_host_real_ns()), the same instant mapped onto
 * CLOCK_MONOTONIC, the socket's drop count and whether the frame is the echo of one written
 * through this socket. -EINTR if interrupted by a signal, -EAGAIN after the receive timeout.
 */
int socketcan_host_recv(int fd, struct socketcan_host_frame *frame,
			struct socketcan_host_rx_info *info);

/* Decode an error frame (flags has SOCKETCAN_HOST_F_ERR). */
void socketcan_host_decode_error(const struct socketcan_host_frame *frame,
				 struct socketcan_host_error *err);

/* Write the error frame that announces @p state (test helper; vcan loops it back). */
int socketcan_host_send_state(int fd, enum socketcan_host_state state);

/* CLOCK_MONOTONIC now, in nanoseconds. */
uint64_t socketcan_host_mono_ns(void);

/* CLOCK_REALTIME now, in nanoseconds: the clock of the kernel's receive stamps. */
uint64_t socketcan_host_real_ns(void);

#endif /* SAFELINE_DRIVERS_CAN_SOCKETCAN_HOST_H_ */
