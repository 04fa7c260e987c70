/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Linux side of the SocketCAN driver. This translation unit sees only host headers: Linux's
 * <linux/can.h> defines struct can_frame and struct can_filter, which clash with Zephyr's, so
 * the RTOS side talks to it through socketcan_host.h alone.
 */

#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/uio.h>

#include "socketcan_host.h"

#ifndef CAN_ERR_CNT
#define CAN_ERR_CNT 0x00000200U /* Linux >= 6.1: data[6]/data[7] hold the TX/RX counters */
#endif

static int set_opt(int fd, int level, int name, const void *val, socklen_t len)
{
	return setsockopt(fd, level, name, val, len) == 0 ? 0 : -errno;
}

int socketcan_host_open(const char *ifname)
{
	struct sockaddr_can addr;
	struct ifreq ifr;
	const int one = 1;
	const can_err_mask_t err_mask = CAN_ERR_MASK;
	int fd;
	int rc;

	if (ifname == NULL || strlen(ifname) >= sizeof(ifr.ifr_name)) {
		return -EINVAL;
	}
	fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
	if (fd < 0) {
		return -errno;
	}

	(void)memset(&ifr, 0, sizeof(ifr));
	(void)strncpy(ifr.ifr_name, ifname, sizeof(ifr.ifr_name) - 1U);
	if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
		rc = -errno;
		goto fail;
	}

	/*
	 * The echo of our own frames is the TX confirmation; error frames give the state. No data
	 * frame is wanted before the driver says which (an empty filter list).
	 */
	rc = set_opt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &one, sizeof(one));
	if (rc == 0) {
		rc = set_opt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask));
	}
	if (rc == 0) {
		rc = set_opt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, NULL, 0);
	}
	if (rc == 0) {
		rc = set_opt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof(one));
	}
	if (rc == 0) {
		rc = set_opt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one));
	}
	if (rc != 0) {
		goto fail;
	}

	(void)memset(&addr, 0, sizeof(addr));
	addr.can_family = AF_CAN;
	addr.can_ifindex = ifr.ifr_ifindex;
	if (bind(fd, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
		rc = -errno;
		goto fail;
	}

	return fd;

fail:
	(void)close(fd);
	return rc;
}

int socketcan_host_set_filters(int fd, const struct socketcan_host_filter *filters, int n)
{
	struct can_filter kf[SOCKETCAN_HOST_MAX_FILTERS];

	if (n < 0 || n > SOCKETCAN_HOST_MAX_FILTERS) {
		return -EINVAL;
	}
	for (int i = 0; i < n; i++) {
		/* CAN_EFF_FLAG in the mask: the frame's type must be the filter's. */
		if ((filters[i].flags & SOCKETCAN_HOST_F_IDE) != 0U) {
			kf[i].can_id = (filters[i].id & CAN_EFF_MASK) | CAN_EFF_FLAG;
			kf[i].can_mask = (filters[i].mask & CAN_EFF_MASK) | CAN_EFF_FLAG;
		} else {
			kf[i].can_id = filters[i].id & CAN_SFF_MASK;
			kf[i].can_mask = (filters[i].mask & CAN_SFF_MASK) | CAN_EFF_FLAG;
		}
	}

	return set_opt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, (n > 0) ? kf : NULL,
		       (socklen_t)((size_t)n * sizeof(kf[0])));
}

int socketcan_host_set_recv_timeout(int fd, uint32_t ms)
{
	const struct timeval tv = {
		.tv_sec = (time_t)(ms / 1000U),
		.tv_usec = (suseconds_t)((ms % 1000U) * 1000U),
	};

	return set_opt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
}

void socketcan_host_close(int fd)
{
	if (fd >= 0) {
		(void)close(fd);
	}
}

int socketcan_host_is_up(const char *ifname)
{
	struct ifreq ifr;
	int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
	int rc;

	if (fd < 0) {
		return -errno;
	}
	(void)memset(&ifr, 0, sizeof(ifr));
	(void)strncpy(ifr.ifr_name, ifname, sizeof(ifr.ifr_name) - 1U);
	if (ioctl(fd, SIOCGIFFLAGS, &ifr) < 0) {
		rc = -errno;
	} else {
		rc = ((ifr.ifr_flags & IFF_UP) != 0 && (ifr.ifr_flags & IFF_RUNNING) != 0) ? 1 : 0;
	}
	(void)close(fd);

	return rc;
}

int socketcan_host_send(int fd, const struct socketcan_host_frame *frame)
{
	struct can_frame cf;
	ssize_t n;

	(void)memset(&cf, 0, sizeof(cf));
	cf.can_id = frame->id &
		    (((frame->flags & SOCKETCAN_HOST_F_IDE) != 0U) ? CAN_EFF_MASK : CAN_SFF_MASK);
	if ((frame->flags & SOCKETCAN_HOST_F_IDE) != 0U) {
		cf.can_id |= CAN_EFF_FLAG;
	}
	if ((frame->flags & SOCKETCAN_HOST_F_RTR) != 0U) {
		cf.can_id |= CAN_RTR_FLAG;
	}
	cf.len = frame->dlc;
	if ((frame->flags & SOCKETCAN_HOST_F_RTR) == 0U) {
		(void)memcpy(cf.data, frame->data, frame->dlc);
	}

	n = send(fd, &cf, sizeof(cf), MSG_DONTWAIT);
	if (n < 0) {
		/* A full qdisc answers ENOBUFS: that is back-pressure, not a failure. */
		return (errno == ENOBUFS || errno == EWOULDBLOCK) ? -EAGAIN : -errno;
	}

	return (n == (ssize_t)sizeof(cf)) ? 0 : -EIO;
}

uint64_t socketcan_host_mono_ns(void)
{
	struct timespec ts;

	(void)clock_gettime(CLOCK_MONOTONIC, &ts);

	return (uint64_t)ts.tv_sec * 1000000000ULL + (uint64_t)ts.tv_nsec;
}

uint64_t socketcan_host_real_ns(void)
{
	struct timespec ts;

	(void)clock_gettime(CLOCK_REALTIME, &ts);

	return (uint64_t)ts.tv_sec * 1000000000ULL + (uint64_t)ts.tv_nsec;
}

/* The kernel stamps CLOCK_REALTIME; map it onto CLOCK_MONOTONIC through the current offset. */
static uint64_t realtime_to_mono_ns(uint64_t rt_ns)
{
	uint64_t now_mono = socketcan_host_mono_ns();
	int64_t age = (int64_t)(socketcan_host_real_ns() - rt_ns);

	if (age < 0 || (uint64_t)age > now_mono) {
		/* clock step between stamp and now: the best estimate is "just now" */
		age = 0;
	}

	return now_mono - (uint64_t)age;
}

int socketcan_host_recv(int fd, struct socketcan_host_frame *frame,
			struct socketcan_host_rx_info *info)
{
	struct can_frame cf;
	struct iovec iov = {.iov_base = &cf, .iov_len = sizeof(cf)};
	union {
		char buf[CMSG_SPACE(sizeof(struct timespec)) + CMSG_SPACE(sizeof(uint32_t))];
		struct cmsghdr align;
	} ctrl;
	struct msghdr msg = {
		.msg_iov = &iov,
		.msg_iovlen = 1,
		.msg_control = ctrl.buf,
		.msg_controllen = sizeof(ctrl.buf),
	};
	ssize_t n = recvmsg(fd, &msg, 0);

	if (n < 0) {
		/* SO_RCVTIMEO ends a wait with EAGAIN (EWOULDBLOCK on some ABIs) */
		return (errno == EWOULDBLOCK) ? -EAGAIN : -errno;
	}
	if (n != (ssize_t)sizeof(cf)) {
		return -EIO; /* CAN FD frames are not enabled on the socket */
	}

	info->real_ns = 0U;
	info->mono_ns = 0U;
	info->drops = 0U; /* the kernel adds the count only once it is not zero */
	for (struct cmsghdr *c = CMSG_FIRSTHDR(&msg); c != NULL; c = CMSG_NXTHDR(&msg, c)) {
		if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
			struct timespec ts;

			(void)memcpy(&ts, CMSG_DATA(c), sizeof(ts));
			info->real_ns = (uint64_t)ts.tv_sec * 1000000000ULL + (uint64_t)ts.tv_nsec;
			info->mono_ns = realtime_to_mono_ns(info->real_ns);
		} else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
			(void)memcpy(&info->drops, CMSG_DATA(c), sizeof(info->drops));
		} else {
			/* no other ancillary data is enabled */
		}
	}
	info->own = (msg.msg_flags & MSG_CONFIRM) != 0;

	(void)memset(frame, 0, sizeof(*frame));
	frame->dlc = cf.len > 8U ? 8U : cf.len;
	if ((cf.can_id & CAN_ERR_FLAG) != 0U) {
		frame->flags = SOCKETCAN_HOST_F_ERR;
		frame->id = cf.can_id & CAN_ERR_MASK;
		(void)memcpy(frame->data, cf.data, sizeof(frame->data));
		return 0;
	}
	if ((cf.can_id & CAN_EFF_FLAG) != 0U) {
		frame->flags |= SOCKETCAN_HOST_F_IDE;
		frame->id = cf.can_id & CAN_EFF_MASK;
	} else {
		frame->id = cf.can_id & CAN_SFF_MASK;
	}
	if ((cf.can_id & CAN_RTR_FLAG) != 0U) {
		frame->flags |= SOCKETCAN_HOST_F_RTR;
	} else {
		(void)memcpy(frame->data, cf.data, frame->dlc);
	}

	return 0;
}

void socketcan_host_decode_error(const struct socketcan_host_frame *frame,
				 struct socketcan_host_error *err)
{
	const uint8_t ctrl = frame->data[1];

	(void)memset(err, 0, sizeof(*err));
	err->state = SOCKETCAN_HOST_STATE_NONE;

	/* The most severe piece of news wins: bus-off, then passive, then warning. */
	if ((frame->id & CAN_ERR_BUSOFF) != 0U) {
		err->state = SOCKETCAN_HOST_STATE_BUS_OFF;
	} else if ((frame->id & CAN_ERR_CRTL) != 0U &&
		   (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0U) {
		err->state = SOCKETCAN_HOST_STATE_PASSIVE;
	} else if ((frame->id & CAN_ERR_CRTL) != 0U &&
		   (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0U) {
		err->state = SOCKETCAN_HOST_STATE_WARNING;
	} else if ((frame->id & CAN_ERR_RESTARTED) != 0U ||
		   ((frame->id & CAN_ERR_CRTL) != 0U && (ctrl & CAN_ERR_CRTL_ACTIVE) != 0U)) {
		err->state = SOCKETCAN_HOST_STATE_ACTIVE;
	} else {
		/* Other error frames (lost arbitration, protocol errors ...) leave the state as it
		 * is. */
	}

	if ((frame->id & CAN_ERR_CNT) != 0U) {
		err->has_counters = true;
		err->tx_err_cnt = frame->data[6];
		err->rx_err_cnt = frame->data[7];
	}
}

int socketcan_host_send_state(int fd, enum socketcan_host_state state)
{
	struct can_frame cf;

	(void)memset(&cf, 0, sizeof(cf));
	cf.len = CAN_ERR_DLC;
	switch (state) {
	case SOCKETCAN_HOST_STATE_ACTIVE:
		cf.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
		break;
	case SOCKETCAN_HOST_STATE_WARNING:
		cf.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
		cf.data[1] = CAN_ERR_CRTL_TX_WARNING;
		break;
	case SOCKETCAN_HOST_STATE_PASSIVE:
		cf.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
		cf.data[1] = CAN_ERR_CRTL_TX_PASSIVE;
		break;
	case SOCKETCAN_HOST_STATE_BUS_OFF:
		cf.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
		break;
	default:
		return -EINVAL;
	}

	return send(fd, &cf, sizeof(cf), 0) == (ssize_t)sizeof(cf) ? 0 : -errno;
}
