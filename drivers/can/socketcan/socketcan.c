/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SocketCAN controllers for native_posix: can_socketcan<i> is a raw CAN socket on a Linux
 * interface (Kconfig CAN_SOCKETCAN_IFNAMES, overridden by --can-if=<i>:<ifname>).
 *
 * This file sees only RTOS headers; Linux is behind socketcan_host.h (both define struct
 * can_frame). One receive thread per controller blocks in recvmsg(); it delivers frames,
 * turns the echo of our own frames into TX completions and error frames into enum can_state.
 *
 * The kernel filters: the socket's CAN_RAW_FILTER is the union of the receive filters and of
 * the identifiers we send (so that their echoes come back, whatever the receive filters), and
 * is rewritten whenever either changes. Frames nobody asked for never reach the socket, so a
 * flood on another identifier cannot fill its receive buffer.
 *
 * TX completion: a frame written to the socket waits in the in-flight queue (socketcan_txq.h)
 * for its echo. An echo that never comes (the socket's buffer overflowed in a flood, or the
 * interface does not get the frame out) must not hold the entry for ever: the entry is released
 * with -ETIMEDOUT when a later frame's echo shows that its own was lost, or when no echo has
 * come for CONFIG_CAN_SOCKETCAN_TX_ECHO_TIMEOUT_MS. The receive thread judges that bound by
 * the kernel's receive stamps of what it reads (an echo already queued is never called late
 * because the thread was slow) and, when the socket is empty, by the clock; SO_RCVTIMEO wakes
 * it a quarter of the bound after the last frame.
 *
 * Stopped means deaf: the socket stays open (its queue keeps the echoes that complete frames
 * already handed to the kernel), so it also collects the frames that arrive while the
 * controller is stopped. Whether a frame may be delivered is therefore decided by when it
 * arrived, not by when the receive thread gets to it: can_start() records the time
 * (CLOCK_REALTIME, the clock of the kernel's SO_TIMESTAMPNS stamps) and frames stamped
 * before it are dropped (see sc_rx_fresh_locked()).
 *
 * Frames handed to the kernel cannot be recalled (no socket call takes a frame back out of
 * the interface's queue), so can_stop() does not report them aborted: it waits for their
 * echoes, up to CONFIG_CAN_SOCKETCAN_STOP_DRAIN_MS, and their callbacks get 0 (sent).
 *
 * Locking: lock guards started, state, the in-flight FIFO and the receive gate; rx_lock is
 * held while receive callbacks run, while filters change and across the "started and fresh?"
 * decision for a frame and its delivery, so that no receive callback runs once can_stop() has
 * returned; it is also held while the state-change callback runs and while it is replaced, so
 * a replaced callback never runs afterwards. Order: rx_lock before lock. No callback runs with
 * lock held.
 */

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/init.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/util.h>

#include "can_filter_table.h"
#include "can_socketcan.h"
#include "cmdline.h"
#include "posix_board_if.h"
#include "posix_native_task.h"
#include "socketcan_host.h"
#include "socketcan_txq.h"

LOG_MODULE_REGISTER(can_socketcan, CONFIG_CAN_LOG_LEVEL);

#define SC_NUM_CTRL        CONFIG_CAN_SOCKETCAN_NUM_CONTROLLERS
#define SC_MAX_FILTERS     CONFIG_CAN_SOCKETCAN_MAX_FILTERS
#define SC_TXQ_SIZE        CONFIG_CAN_SOCKETCAN_TX_QUEUE_SIZE
#define SC_TX_IDS          CONFIG_CAN_SOCKETCAN_TX_ID_FILTERS
#define SC_ECHO_TIMEOUT_NS ((uint64_t)CONFIG_CAN_SOCKETCAN_TX_ECHO_TIMEOUT_MS * 1000000ULL)
/* How long the receive thread waits for a frame before it looks at the clock. */
#define SC_RECV_TIMEOUT_MS MAX(1U, CONFIG_CAN_SOCKETCAN_TX_ECHO_TIMEOUT_MS / 4U)
#define SC_IFNAMSIZ        16
/* The kernel's interface decides the bit rate; these bound what can_set_bitrate() accepts. */
#define SC_MIN_BITRATE     10000U
#define SC_MAX_BITRATE     1000000U

BUILD_ASSERT(SC_NUM_CTRL <= 8, "the driver defines up to 8 controllers");
/* Every frame in flight has its identifier in the kernel filter (sc_tx_id_use_locked()). */
BUILD_ASSERT(
	SC_TX_IDS >= SC_TXQ_SIZE,
	"CONFIG_CAN_SOCKETCAN_TX_ID_FILTERS must be at least CONFIG_CAN_SOCKETCAN_TX_QUEUE_SIZE");
BUILD_ASSERT(SC_MAX_FILTERS + SC_TX_IDS <= SOCKETCAN_HOST_MAX_FILTERS,
	     "the kernel takes at most 512 filter entries per socket");

/* A receive filter as the kernel sees it. */
struct sc_kfilter {
	struct socketcan_host_filter f;
	bool used;
};

/* An identifier we sent, kept in the kernel filter so that its echo comes back. */
struct sc_tx_id {
	uint32_t id;
	uint8_t flags; /* SOCKETCAN_HOST_F_IDE */
	bool used;
	uint32_t last_used; /* sc_data.tx_id_clock at its last send */
};

struct sc_config {
	struct can_driver_config common; /* first, for the generic API */
	uint8_t index;
};

struct sc_data {
	struct can_driver_data common; /* first, for the generic API */
	const struct device *dev;
	char ifname[SC_IFNAMSIZ];
	int fd;
	/* guarded by lock */
	struct k_mutex lock;
	enum can_state state;
	struct can_bus_err_cnt err_cnt;
	uint32_t bitrate;
	struct sc_txq txq; /* frames awaiting their echo */
	struct sc_txq_entry txq_entries[SC_TXQ_SIZE];
	/* the kernel filter: a mirror of the receive filters and the identifiers we send */
	struct sc_kfilter rx_kf[SC_MAX_FILTERS];
	struct sc_tx_id tx_ids[SC_TX_IDS];
	uint32_t tx_id_clock; /* counts sends, for tx_ids[].last_used */
	struct socketcan_host_filter kf_scratch[SC_MAX_FILTERS + SC_TX_IDS];
	struct can_socketcan_stats stats;
	/* receive gate: frames stamped before the last can_start() are not delivered */
	uint64_t start_real_ns;  /* CLOCK_REALTIME at the last can_start() */
	int64_t start_offset_ns; /* CLOCK_REALTIME - CLOCK_MONOTONIC then (to see clock steps) */
	bool draining;           /* frames from before that start may still be queued */
	struct k_sem tx_slots;
	struct k_sem echo_seen; /* given on every echo: room in the kernel queue again */
	struct k_sem tx_idle;   /* given whenever the in-flight FIFO becomes empty */
	/* guarded by rx_lock */
	struct k_mutex rx_lock;
	struct can_filter_slot filters[SC_MAX_FILTERS];
	struct k_thread rx_thread;
};

K_THREAD_STACK_ARRAY_DEFINE(sc_stacks, SC_NUM_CTRL, CONFIG_CAN_SOCKETCAN_RX_THREAD_STACK_SIZE);

/* --can-if overrides, filled in before the kernel starts (PRE_BOOT_1). */
static char sc_ifname_override[SC_NUM_CTRL][SC_IFNAMSIZ];

static void sc_can_if_found(char *argv, int offset)
{
	const char *value = argv + offset;
	const char *colon = strchr(value, ':');
	char index_str[4];
	size_t index_len = (colon != NULL) ? (size_t)(colon - value) : 0U;
	uint64_t index;

	if (colon == NULL || index_len == 0U || index_len >= sizeof(index_str) ||
	    colon[1] == '\0' || strlen(colon + 1) >= SC_IFNAMSIZ) {
		cmd_option_error("can-if", value,
				 "expected <controller 0..%d>:<ifname> (at most %d characters)",
				 SC_NUM_CTRL - 1, SC_IFNAMSIZ - 1);
	}
	(void)memcpy(index_str, value, index_len);
	index_str[index_len] = '\0';
	if (cmd_parse_uint(index_str, 0U, SC_NUM_CTRL - 1U, &index) != 0) {
		cmd_option_error("can-if", value, "the controller is not a number in 0..%d",
				 SC_NUM_CTRL - 1);
	}
	(void)strcpy(sc_ifname_override[index], colon + 1);
}

static void sc_add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "can-if",
			.name = "controller:ifname",
			.type = 's',
			.dest = NULL,
			.call_when_found = sc_can_if_found,
			.descript = "Use Linux CAN interface <ifname> for SocketCAN controller "
				    "can_socketcan<controller> (repeatable), e.g. --can-if=0:vcan0",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}

NATIVE_TASK(sc_add_options, PRE_BOOT_1, 10);

/* The i-th name of the Kconfig list, or "" if the list is shorter. */
static void sc_kconfig_ifname(int index, char out[SC_IFNAMSIZ])
{
	const char *p = CONFIG_CAN_SOCKETCAN_IFNAMES;

	out[0] = '\0';
	for (int i = 0; i < index && p != NULL; i++) {
		p = strchr(p, ',');
		p = (p != NULL) ? p + 1 : NULL;
	}
	if (p != NULL) {
		size_t len = strcspn(p, ",");

		if (len < SC_IFNAMSIZ) {
			(void)memcpy(out, p, len);
			out[len] = '\0';
		}
	}
}

/*
 * Interface of controller @p index: the --can-if override, else the Kconfig list entry.
 * "@<j>" stands for controller j's interface (two controllers on one bus, e.g. "vcan0,@0").
 */
static void sc_resolve_ifname(int index, char out[SC_IFNAMSIZ])
{
	for (int depth = 0; depth < SC_NUM_CTRL; depth++) {
		if (sc_ifname_override[index][0] != '\0') {
			(void)strcpy(out, sc_ifname_override[index]);
		} else {
			sc_kconfig_ifname(index, out);
		}
		if (out[0] != '@') {
			return;
		}
		index = atoi(&out[1]);
		if (index < 0 || index >= SC_NUM_CTRL) {
			break;
		}
	}
	out[0] = '\0';
}

/* Why socketcan_host_open() failed with @p rc, for a message ending in the errno text. */
static const char *sc_open_error(int rc)
{
	switch (rc) {
	case -EAFNOSUPPORT:
		return "the kernel has no AF_CAN, SocketCAN not available on this host (run in "
		       "scripts/vcan-vm)";
	case -ENODEV:
		return "no such interface";
	default:
		return "socket error";
	}
}

/*
 * An interface named with --can-if must be usable: probe each one once the command line is
 * parsed, so that a missing interface (or a host without AF_CAN) ends the process with the
 * reason before the boot instead of leaving the line on the virtual bus. Interfaces from
 * CONFIG_CAN_SOCKETCAN_IFNAMES alone are only reported (sc_init()).
 */
static void sc_check_can_if(void)
{
	for (int i = 0; i < SC_NUM_CTRL; i++) {
		char ifname[SC_IFNAMSIZ];
		int fd;

		if (sc_ifname_override[i][0] == '\0') {
			continue;
		}
		sc_resolve_ifname(i, ifname);
		if (ifname[0] == '\0') {
			posix_print_error_and_exit("Error: --can-if=%d:%s names no interface\n", i,
						   sc_ifname_override[i]);
		}
		fd = socketcan_host_open(ifname);
		if (fd < 0) {
			posix_print_error_and_exit(
				"Error: --can-if=%d:%s: cannot open CAN interface %s: %s "
				"(%s)\n",
				i, sc_ifname_override[i], ifname, sc_open_error(fd), strerror(-fd));
		}
		socketcan_host_close(fd);
	}
}

NATIVE_TASK(sc_check_can_if, PRE_BOOT_2, 10);

static inline struct sc_data *sc_data(const struct device *dev)
{
	return (struct sc_data *)dev->data;
}

/*
 * CLOCK_MONOTONIC minus the kernel's uptime, in ns: on native_posix the uptime is the host's
 * monotonic clock since boot, so the difference is a constant. Measured once, as the middle
 * of the tightest of a few bracketing reads: a thread preempted between two clock reads
 * would otherwise shift every stamp by the preemption, differently for each frame.
 */
static uint64_t sc_uptime_offset_ns;

static void sc_measure_uptime_offset(void)
{
	uint64_t best = UINT64_MAX;

	for (int i = 0; i < 5; i++) {
		uint64_t before = socketcan_host_mono_ns();
		uint64_t up_ns = k_ticks_to_ns_floor64((uint64_t)k_uptime_ticks());
		uint64_t after = socketcan_host_mono_ns();

		if (after - before < best) {
			best = after - before;
			sc_uptime_offset_ns = before + (after - before) / 2U - up_ns;
		}
	}
}

/* Microseconds on the kernel's uptime clock at which the host received a frame. */
static uint64_t sc_rx_time_us(uint64_t rx_mono_ns)
{
	return ((rx_mono_ns > sc_uptime_offset_ns) ? rx_mono_ns - sc_uptime_offset_ns : 0U) / 1000U;
}

/* After entries left the in-flight queue: wake can_stop() if it is empty now. Under lock. */
static void sc_txq_left_locked(struct sc_data *d)
{
	if (sc_txq_count(&d->txq) == 0U) {
		k_sem_give(&d->tx_idle);
	}
}

/* Frees the slots of entries that left the queue and runs their callbacks. Without lock. */
static void sc_complete(struct sc_data *d, const struct sc_txq_entry *t, int n, int error)
{
	for (int i = 0; i < n; i++) {
		k_sem_give(&d->tx_slots);
		if (t[i].cb != NULL) {
			t[i].cb(d->dev, error, t[i].user_data);
		}
	}
}

/*
 * Releases the entries whose echo has not come for the bound, as of @p now_ns (a receive
 * stamp, or the clock when the socket is empty).
 */
static void sc_expire(struct sc_data *d, uint64_t now_ns)
{
	struct sc_txq_entry expired[SC_TXQ_SIZE];
	int n;

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	n = sc_txq_expire(&d->txq, now_ns, expired);
	d->stats.tx_echo_timeouts += (uint32_t)n;
	sc_txq_left_locked(d);
	(void)k_mutex_unlock(&d->lock);

	if (n > 0) {
		LOG_WRN("%s (%s): %d frames without echo for %u ms, released", d->dev->name,
			d->ifname, n, CONFIG_CAN_SOCKETCAN_TX_ECHO_TIMEOUT_MS);
		sc_complete(d, expired, n, -ETIMEDOUT);
	}
}

/* ------------------------------------------------------------------------------------------ */
/* The kernel filter                                                                          */

/* Writes the receive filters and the sent identifiers into the socket's filter. Under lock. */
static int sc_program_filters_locked(struct sc_data *d)
{
	int n = 0;
	int rc;

	for (int i = 0; i < SC_MAX_FILTERS; i++) {
		if (d->rx_kf[i].used) {
			d->kf_scratch[n] = d->rx_kf[i].f;
			n++;
		}
	}
	for (int i = 0; i < SC_TX_IDS; i++) {
		if (d->tx_ids[i].used) {
			d->kf_scratch[n] = (struct socketcan_host_filter){
				.id = d->tx_ids[i].id,
				.mask = UINT32_MAX,
				.flags = d->tx_ids[i].flags,
			};
			n++;
		}
	}
	rc = socketcan_host_set_filters(d->fd, d->kf_scratch, n);
	if (rc == 0) {
		d->stats.kernel_filters = (uint16_t)n;
	} else {
		LOG_ERR("%s (%s): cannot set the kernel filter (%d entries): %d", d->dev->name,
			d->ifname, n, rc);
	}

	return rc;
}

/*
 * Makes sure the kernel filter lets the echo of a frame with this identifier through: an
 * identifier already there is marked used now; a new one takes a free entry or that of the
 * identifier sent longest ago. That one has no frame in flight: the in-flight frames are the
 * last SC_TXQ_SIZE <= SC_TX_IDS written, and their identifiers are the most recently used.
 * Under lock, in the same critical section as the write.
 */
static int sc_tx_id_use_locked(struct sc_data *d, const struct socketcan_host_frame *hf)
{
	uint8_t flags = hf->flags & SOCKETCAN_HOST_F_IDE;
	struct sc_tx_id old;
	int victim = 0;
	int rc;

	d->tx_id_clock++;
	for (int i = 0; i < SC_TX_IDS; i++) {
		struct sc_tx_id *t = &d->tx_ids[i];

		if (t->used && t->id == hf->id && t->flags == flags) {
			t->last_used = d->tx_id_clock;
			return 0;
		}
		if (!t->used) {
			victim = i;
		} else if (d->tx_ids[victim].used &&
			   (uint32_t)(d->tx_id_clock - t->last_used) >
				   (uint32_t)(d->tx_id_clock - d->tx_ids[victim].last_used)) {
			victim = i;
		} else {
			/* a free entry, or one used more recently than the candidate: keep it */
		}
	}
	old = d->tx_ids[victim];
	d->tx_ids[victim] = (struct sc_tx_id){
		.id = hf->id,
		.flags = flags,
		.used = true,
		.last_used = d->tx_id_clock,
	};
	rc = sc_program_filters_locked(d);
	if (rc != 0) {
		d->tx_ids[victim] = old;
	}

	return rc;
}

/* Mirrors receive filter @p filter_id (NULL: removed) into the kernel filter. Under lock. */
static int sc_rx_kf_set_locked(struct sc_data *d, int filter_id, const struct can_filter *filter)
{
	struct sc_kfilter *k = &d->rx_kf[filter_id];

	k->used = filter != NULL;
	if (filter != NULL) {
		k->f.id = filter->id;
		k->f.mask = filter->mask;
		k->f.flags = ((filter->flags & CAN_FILTER_IDE) != 0U) ? SOCKETCAN_HOST_F_IDE : 0U;
	}

	return sc_program_filters_locked(d);
}

/* A wall-clock step backwards of more than this since can_start() makes the stamps useless. */
#define SC_CLOCK_STEP_NS 10000000LL

/*
 * Whether a frame the kernel stamped at @p rx_real_ns arrived after the last can_start().
 * Under lock, in the same critical section that reads started (else a frame judged before a
 * start could be delivered after it).
 *
 * Why stamps: the receive thread may read a frame long after it arrived (it was busy, or the
 * frame sat in the socket while we were stopped), so "started when read" says nothing about
 * "started when it arrived". A lock cannot close that window, and closing/reopening the socket
 * would lose the echoes of frames still in flight. The kernel stamps each frame when it
 * arrives (netif_rx) with CLOCK_REALTIME; can_start() reads the same clock, so the comparison
 * is exact. The socket's queue is FIFO: once one frame stamped at or after the start has been
 * read, everything behind it arrived later, and the check is off until the next start
 * ("draining"). That also bounds what a wall-clock step can do: only a step backwards while
 * draining matters, and one larger than SC_CLOCK_STEP_NS ends the drain (stamps from before
 * the step cannot be compared any more; delivering a stale frame beats dropping live ones).
 * A frame without a stamp counts as fresh.
 */
static bool sc_rx_fresh_locked(struct sc_data *d, uint64_t rx_real_ns)
{
	uint64_t mono;
	int64_t offset;

	if (!d->draining) {
		return true;
	}
	if (rx_real_ns == 0U || rx_real_ns >= d->start_real_ns) {
		d->draining = false;
		return true;
	}
	/*
	 * Monotonic first, then wall clock: a preemption between the two reads can only make the
	 * offset look larger, never fake a step back (can_start() reads them the other way round).
	 */
	mono = socketcan_host_mono_ns();
	offset = (int64_t)(socketcan_host_real_ns() - mono);

	if (offset < d->start_offset_ns - SC_CLOCK_STEP_NS) {
		LOG_WRN("%s (%s): wall clock stepped back, cannot tell old frames from new ones",
			d->dev->name, d->ifname);
		d->draining = false;
		return true;
	}

	return false;
}

/*
 * Delivers a received frame to the filters if the controller is started and the frame arrived
 * after the start. rx_lock is held from the decision to the end of the callbacks: can_stop()
 * takes it once after clearing started, so no callback runs after can_stop() returns.
 */
static void sc_deliver(struct sc_data *d, const struct can_frame *frame, uint64_t rx_real_ns)
{
	bool deliver;

	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	deliver = sc_rx_fresh_locked(d, rx_real_ns) && d->common.started;
	(void)k_mutex_unlock(&d->lock);
	if (deliver) {
		can_filter_table_deliver(d->dev, d->filters, SC_MAX_FILTERS, &d->rx_lock, frame);
	}
	(void)k_mutex_unlock(&d->rx_lock);
}

static void sc_on_echo(struct sc_data *d, const struct socketcan_host_frame *hf,
		       const struct can_frame *frame, const struct socketcan_host_rx_info *info)
{
	struct sc_txq_entry done;
	struct sc_txq_entry lost[SC_TXQ_SIZE];
	int n_lost = 0;
	enum sc_txq_echo_result found;
	bool loopback;

	/* The echo completes its frame whenever it comes, also while stopped. */
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	found = sc_txq_echo(&d->txq, hf, info->mono_ns, &done, lost, &n_lost);
	if (found == SC_TXQ_ECHO_MATCHED) {
		d->stats.tx_confirmed++;
		d->stats.tx_echoes_lost += (uint32_t)n_lost;
	} else {
		d->stats.tx_late_echoes++;
	}
	sc_txq_left_locked(d);
	loopback = (d->common.mode & CAN_MODE_LOOPBACK) != 0U;
	(void)k_mutex_unlock(&d->lock);

	k_sem_give(&d->echo_seen);
	if (loopback) {
		/* the mode only changes while stopped; sc_deliver() checks started */
		sc_deliver(d, frame, info->real_ns);
	}
	if (n_lost > 0) {
		LOG_WRN("%s (%s): echoes of %d frames lost (receive buffer overflow?), released",
			d->dev->name, d->ifname, n_lost);
		sc_complete(d, lost, n_lost, -ETIMEDOUT);
	}
	if (found == SC_TXQ_ECHO_MATCHED) {
		sc_complete(d, &done, 1, 0);
	}
}

static void sc_on_error_frame(struct sc_data *d, const struct socketcan_host_frame *hf,
			      uint64_t rx_real_ns)
{
	struct socketcan_host_error err;
	struct sc_txq_entry aborted[SC_TXQ_SIZE];
	int n_aborted = 0;
	enum can_state state;
	struct can_bus_err_cnt cnt;
	can_state_change_callback_t cb = NULL;
	void *cb_data = NULL;
	bool changed;

	socketcan_host_decode_error(hf, &err);

	/*
	 * rx_lock from the callback's read to its end: once can_set_state_change_callback()
	 * has returned, the callback it replaced never runs.
	 */
	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (!sc_rx_fresh_locked(d, rx_real_ns)) {
		/* news from before the last can_start(), which reset the state */
		(void)k_mutex_unlock(&d->lock);
		(void)k_mutex_unlock(&d->rx_lock);
		return;
	}
	if (err.has_counters) {
		d->err_cnt.tx_err_cnt = err.tx_err_cnt;
		d->err_cnt.rx_err_cnt = err.rx_err_cnt;
	}
	switch (err.state) {
	case SOCKETCAN_HOST_STATE_ACTIVE:
		state = CAN_STATE_ERROR_ACTIVE;
		break;
	case SOCKETCAN_HOST_STATE_WARNING:
		state = CAN_STATE_ERROR_WARNING;
		break;
	case SOCKETCAN_HOST_STATE_PASSIVE:
		state = CAN_STATE_ERROR_PASSIVE;
		break;
	case SOCKETCAN_HOST_STATE_BUS_OFF:
		state = CAN_STATE_BUS_OFF;
		break;
	default:
		/* a protocol or transceiver error without news about the state */
		state = d->state;
		break;
	}
	changed = state != d->state;
	d->state = state;
	cnt = d->err_cnt;
	if (changed && d->common.started) {
		cb = d->common.state_change_cb;
		cb_data = d->common.state_change_cb_user_data;
		if (state == CAN_STATE_BUS_OFF) {
			/* their echoes, if they still come, find no entry (late echoes) */
			n_aborted = sc_txq_take_all(&d->txq, aborted);
			sc_txq_left_locked(d);
		}
	}
	(void)k_mutex_unlock(&d->lock);

	if (changed) {
		LOG_INF("%s (%s): state %d, tx %u rx %u", d->dev->name, d->ifname, (int)state,
			cnt.tx_err_cnt, cnt.rx_err_cnt);
	}
	sc_complete(d, aborted, n_aborted, -ENETUNREACH);
	if (cb != NULL) {
		cb(d->dev, state, cnt, cb_data);
	}
	(void)k_mutex_unlock(&d->rx_lock);
}

/* Socket statistics of a frame read. */
static void sc_count_rx(struct sc_data *d, const struct socketcan_host_frame *hf,
			const struct socketcan_host_rx_info *info)
{
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	/* the kernel's count only grows; a frame queued before the last drop carries less */
	d->stats.rx_overflows = MAX(d->stats.rx_overflows, info->drops);
	if (!info->own && (hf->flags & SOCKETCAN_HOST_F_ERR) == 0U) {
		d->stats.rx_frames++;
	}
	(void)k_mutex_unlock(&d->lock);
}

static void sc_on_frame(struct sc_data *d, const struct socketcan_host_frame *hf,
			const struct socketcan_host_rx_info *info)
{
	struct can_frame frame;

	(void)memset(&frame, 0, sizeof(frame));
	frame.id = hf->id;
	frame.dlc = hf->dlc;
	frame.flags = (uint8_t)(((hf->flags & SOCKETCAN_HOST_F_IDE) != 0U ? CAN_FRAME_IDE : 0U) |
				((hf->flags & SOCKETCAN_HOST_F_RTR) != 0U ? CAN_FRAME_RTR : 0U));
	(void)memcpy(frame.data, hf->data, sizeof(frame.data));
#if defined(CONFIG_CAN_RX_TIMESTAMP)
	frame.timestamp = (uint16_t)sc_rx_time_us(info->mono_ns);
#endif

	if (info->own) {
		sc_on_echo(d, hf, &frame, info);
	} else {
		sc_deliver(d, &frame, info->real_ns);
	}
}

static void sc_rx_thread(void *p1, void *p2, void *p3)
{
	struct sc_data *d = p1;
	struct socketcan_host_frame hf;
	struct socketcan_host_rx_info info;
	int last_err = 0;

	for (;;) {
		int rc = socketcan_host_recv(d->fd, &hf, &info);

		if (rc == -EINTR) {
			continue;
		}
		if (rc == -EAGAIN) {
			/* the socket is empty: every echo that came is read, judge by the clock */
			sc_expire(d, socketcan_host_mono_ns());
			continue;
		}
		if (rc < 0) {
			/*
			 * A socket error (e.g. ENETDOWN when the interface goes down) is reported
			 * once per reading and consumed by it; only a dead socket ends the thread.
			 */
			if (rc != last_err) {
				LOG_WRN("%s (%s): receive error %d", d->dev->name, d->ifname, rc);
				last_err = rc;
			}
			if (rc == -EBADF || rc == -ENOTSOCK) {
				return;
			}
			continue;
		}
		last_err = 0;
		if (info.mono_ns == 0U) {
			info.mono_ns = socketcan_host_mono_ns(); /* no stamp: it came by now */
		}
		sc_count_rx(d, &hf, &info);

		if ((hf.flags & SOCKETCAN_HOST_F_ERR) != 0U) {
			sc_on_error_frame(d, &hf, info.real_ns);
		} else {
			sc_on_frame(d, &hf, &info);
		}
		/* everything before this frame has been read: judge the bound at its stamp */
		sc_expire(d, info.mono_ns);
	}
}

/* ------------------------------------------------------------------------------------------ */
/* Driver API                                                                                 */

static int sc_get_capabilities(const struct device *dev, can_mode_t *cap)
{
	*cap = CAN_MODE_LOOPBACK;

	return 0;
}

static int sc_start(const struct device *dev)
{
	struct sc_data *d = sc_data(dev);
	int rc = 0;

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (d->common.started) {
		rc = -EALREADY;
	} else if (d->fd < 0) {
		rc = -EIO;
	} else {
		d->state = CAN_STATE_ERROR_ACTIVE;
		d->err_cnt.tx_err_cnt = 0U;
		d->err_cnt.rx_err_cnt = 0U;
		/* Frames the kernel stamps before this instant arrived while we were stopped. */
		d->start_real_ns = socketcan_host_real_ns();
		/* wall clock first: the offset can only come out smaller (sc_rx_fresh_locked()) */
		d->start_offset_ns = (int64_t)(d->start_real_ns - socketcan_host_mono_ns());
		d->draining = true;
		d->common.started = true;
	}
	(void)k_mutex_unlock(&d->lock);

	return rc;
}

/*
 * Stopping cannot abort what the kernel already holds: a frame written to the socket goes out
 * whatever we do, so reporting it aborted (-ENETDOWN) would be a lie. can_stop() refuses new
 * frames (and those still waiting in can_send() for room) with -ENETDOWN, then waits for the
 * echoes of the frames in flight; their callbacks get 0 as they are confirmed. Frames still
 * queued after CONFIG_CAN_SOCKETCAN_STOP_DRAIN_MS (a bus without acknowledgement) complete
 * when the interface sends them, possibly after can_stop() returned.
 */
static int sc_stop(const struct device *dev)
{
	struct sc_data *d = sc_data(dev);
	k_timepoint_t end = sys_timepoint_calc(K_MSEC(CONFIG_CAN_SOCKETCAN_STOP_DRAIN_MS));
	uint16_t in_flight;

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (!d->common.started) {
		(void)k_mutex_unlock(&d->lock);
		return -EALREADY;
	}
	d->common.started = false;
	(void)k_mutex_unlock(&d->lock);

	/* Barrier: a delivery that saw started before we cleared it ends before we return. */
	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	(void)k_mutex_unlock(&d->rx_lock);

	/* Only the receive thread reads echoes: from its callbacks, do not wait for them. */
	if (k_current_get() == &d->rx_thread) {
		return 0;
	}
	for (;;) {
		(void)k_mutex_lock(&d->lock, K_FOREVER);
		in_flight = sc_txq_count(&d->txq);
		(void)k_mutex_unlock(&d->lock);
		if (in_flight == 0U) {
			break;
		}
		if (k_sem_take(&d->tx_idle, sys_timepoint_timeout(end)) != 0) {
			LOG_WRN("%s (%s): %u frames still in the kernel's queue after can_stop(); "
				"they complete when sent",
				dev->name, d->ifname, in_flight);
			break;
		}
	}

	return 0;
}

static int sc_set_mode(const struct device *dev, can_mode_t mode)
{
	struct sc_data *d = sc_data(dev);
	int rc = 0;

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (d->common.started) {
		rc = -EBUSY;
	} else if ((mode & ~(can_mode_t)CAN_MODE_LOOPBACK) != 0U) {
		rc = -ENOTSUP;
	} else {
		d->common.mode = mode;
	}
	(void)k_mutex_unlock(&d->lock);

	return rc;
}

static int sc_set_bitrate(const struct device *dev, uint32_t bitrate)
{
	struct sc_data *d = sc_data(dev);
	int rc = 0;

	/* Only recorded: the interface's bit rate is set on the host (ip link ... bitrate). */
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (d->common.started) {
		rc = -EBUSY;
	} else {
		d->bitrate = bitrate;
	}
	(void)k_mutex_unlock(&d->lock);

	return rc;
}

/* Linux errno from the socket -> the CAN API's codes. */
static int sc_map_send_error(struct sc_data *d, int rc)
{
	switch (rc) {
	case -ENETDOWN:
	case -ENXIO:
	case -ENODEV:
		return -ENETDOWN;
	case -EAGAIN:
	case -EINVAL:
		return rc;
	default:
		LOG_WRN("%s (%s): send failed: %d", d->dev->name, d->ifname, rc);
		return -EIO;
	}
}

static int sc_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
		   can_tx_callback_t callback, void *user_data)
{
	struct sc_data *d = sc_data(dev);
	struct socketcan_host_frame hf = {0};
	k_timepoint_t end = sys_timepoint_calc(timeout);
	int rc = 0;

	if ((frame->flags & ~(CAN_FRAME_IDE | CAN_FRAME_RTR)) != 0U) {
		return -ENOTSUP;
	}
	hf.id = frame->id;
	hf.dlc = frame->dlc;
	hf.flags = (uint8_t)(((frame->flags & CAN_FRAME_IDE) != 0U ? SOCKETCAN_HOST_F_IDE : 0U) |
			     ((frame->flags & CAN_FRAME_RTR) != 0U ? SOCKETCAN_HOST_F_RTR : 0U));
	(void)memcpy(hf.data, frame->data, sizeof(hf.data));

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (!d->common.started) {
		rc = -ENETDOWN;
	} else if (d->state == CAN_STATE_BUS_OFF) {
		rc = -ENETUNREACH;
	} else {
		/* Started and not bus-off: the frame is sent below. */
	}
	(void)k_mutex_unlock(&d->lock);
	if (rc != 0) {
		return rc;
	}

	if (k_sem_take(&d->tx_slots, timeout) != 0) {
		return -EAGAIN;
	}

	for (;;) {
		(void)k_mutex_lock(&d->lock, K_FOREVER);
		if (!d->common.started) {
			rc = -ENETDOWN;
		} else if (d->state == CAN_STATE_BUS_OFF) {
			rc = -ENETUNREACH;
		} else {
			rc = sc_tx_id_use_locked(d, &hf);
		}
		if (rc == 0) {
			/* Queued before the write: the echo may come before send() returns. */
			(void)sc_txq_push(&d->txq, &hf, callback, user_data,
					  socketcan_host_mono_ns());
			rc = socketcan_host_send(d->fd, &hf);
			if (rc != 0) {
				sc_txq_drop_newest(&d->txq);
			}
		}
		(void)k_mutex_unlock(&d->lock);

		if (rc == 0) {
			return 0;
		}
		if (rc != -EAGAIN) {
			break;
		}
		/* The kernel's queue is full: wait for one of our frames to leave, or time out. */
		if (k_sem_take(&d->echo_seen, sys_timepoint_timeout(end)) != 0) {
			break;
		}
	}
	k_sem_give(&d->tx_slots);

	return (rc == -EAGAIN || rc == -ENETDOWN || rc == -ENETUNREACH) ? rc
									: sc_map_send_error(d, rc);
}

/*
 * The software table decides what each callback gets; the kernel filter mirrors it so that
 * frames no filter wants do not reach the socket. Both change under rx_lock, so a table slot
 * and its kernel entry change together.
 */
static int sc_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
			    const struct can_filter *filter)
{
	struct sc_data *d = sc_data(dev);
	int id;

	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	id = can_filter_table_add(d->filters, SC_MAX_FILTERS, &d->rx_lock, callback, user_data,
				  filter);
	if (id >= 0 && d->fd >= 0) {
		int rc;

		(void)k_mutex_lock(&d->lock, K_FOREVER);
		rc = sc_rx_kf_set_locked(d, id, filter);
		if (rc != 0) {
			(void)sc_rx_kf_set_locked(d, id, NULL);
		}
		(void)k_mutex_unlock(&d->lock);
		if (rc != 0) {
			/* the kernel refused more entries (out of memory): as if out of filters */
			can_filter_table_remove(d->filters, SC_MAX_FILTERS, &d->rx_lock, id);
			id = -ENOSPC;
		}
	}
	(void)k_mutex_unlock(&d->rx_lock);

	return id;
}

static void sc_remove_rx_filter(const struct device *dev, int filter_id)
{
	struct sc_data *d = sc_data(dev);

	if (filter_id < 0 || filter_id >= SC_MAX_FILTERS) {
		return;
	}
	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	can_filter_table_remove(d->filters, SC_MAX_FILTERS, &d->rx_lock, filter_id);
	if (d->fd >= 0) {
		(void)k_mutex_lock(&d->lock, K_FOREVER);
		/* on failure the kernel keeps a wider filter: the table still drops the frames */
		(void)sc_rx_kf_set_locked(d, filter_id, NULL);
		(void)k_mutex_unlock(&d->lock);
	}
	(void)k_mutex_unlock(&d->rx_lock);
}

static int sc_get_state(const struct device *dev, enum can_state *state,
			struct can_bus_err_cnt *err_cnt)
{
	struct sc_data *d = sc_data(dev);

	(void)k_mutex_lock(&d->lock, K_FOREVER);
	if (state != NULL) {
		*state = d->common.started ? d->state : CAN_STATE_STOPPED;
	}
	if (err_cnt != NULL) {
		*err_cnt = d->err_cnt;
	}
	(void)k_mutex_unlock(&d->lock);

	return 0;
}

static int sc_recover(const struct device *dev, k_timeout_t timeout)
{
	/* Manual recovery is not offered: the Linux interface recovers (restart-ms). */
	return -ENOTSUP;
}

static void sc_set_state_change_callback(const struct device *dev,
					 can_state_change_callback_t callback, void *user_data)
{
	struct sc_data *d = sc_data(dev);

	/* Also under rx_lock: waits for a notification under way (sc_on_error_frame()). */
	(void)k_mutex_lock(&d->rx_lock, K_FOREVER);
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	d->common.state_change_cb = callback;
	d->common.state_change_cb_user_data = user_data;
	(void)k_mutex_unlock(&d->lock);
	(void)k_mutex_unlock(&d->rx_lock);
}

static int sc_get_max_filters(const struct device *dev, bool ide)
{
	return SC_MAX_FILTERS;
}

static const struct can_driver_api sc_api;

static bool sc_is_ours(const struct device *dev)
{
	return dev != NULL && dev->api == &sc_api;
}

const char *can_socketcan_ifname(const struct device *dev)
{
	return sc_is_ours(dev) ? sc_data(dev)->ifname : NULL;
}

int can_socketcan_get_stats(const struct device *dev, struct can_socketcan_stats *stats)
{
	struct sc_data *d;

	if (!sc_is_ours(dev) || stats == NULL) {
		return -EINVAL;
	}
	d = sc_data(dev);
	(void)k_mutex_lock(&d->lock, K_FOREVER);
	*stats = d->stats;
	(void)k_mutex_unlock(&d->lock);

	return 0;
}

int can_socketcan_inject_state(const struct device *dev, enum can_state state)
{
	static const enum socketcan_host_state host_state[] = {
		[CAN_STATE_ERROR_ACTIVE] = SOCKETCAN_HOST_STATE_ACTIVE,
		[CAN_STATE_ERROR_WARNING] = SOCKETCAN_HOST_STATE_WARNING,
		[CAN_STATE_ERROR_PASSIVE] = SOCKETCAN_HOST_STATE_PASSIVE,
		[CAN_STATE_BUS_OFF] = SOCKETCAN_HOST_STATE_BUS_OFF,
	};

	if (!sc_is_ours(dev) || (int)state < 0 || state > CAN_STATE_BUS_OFF) {
		return -EINVAL;
	}
	if (sc_data(dev)->fd < 0) {
		return -EIO;
	}

	return socketcan_host_send_state(sc_data(dev)->fd, host_state[state]);
}

static const struct can_driver_api sc_api = {
	.get_capabilities = sc_get_capabilities,
	.start = sc_start,
	.stop = sc_stop,
	.set_mode = sc_set_mode,
	.set_bitrate = sc_set_bitrate,
	.send = sc_send,
	.add_rx_filter = sc_add_rx_filter,
	.remove_rx_filter = sc_remove_rx_filter,
	.recover = sc_recover,
	.get_state = sc_get_state,
	.set_state_change_callback = sc_set_state_change_callback,
	.get_max_filters = sc_get_max_filters,
};

static int sc_init(const struct device *dev)
{
	const struct sc_config *cfg = dev->config;
	struct sc_data *d = dev->data;
	int rc;

	d->dev = dev;
	d->fd = -1;
	d->state = CAN_STATE_ERROR_ACTIVE;
	d->bitrate = cfg->common.bitrate;
	d->common.mode = CAN_MODE_NORMAL;
	(void)k_mutex_init(&d->lock);
	(void)k_mutex_init(&d->rx_lock);
	(void)k_sem_init(&d->tx_slots, SC_TXQ_SIZE, SC_TXQ_SIZE);
	(void)k_sem_init(&d->echo_seen, 0, 1);
	(void)k_sem_init(&d->tx_idle, 0, 1);
	sc_txq_init(&d->txq, d->txq_entries, SC_TXQ_SIZE, SC_ECHO_TIMEOUT_NS);
	if (sc_uptime_offset_ns == 0U) {
		sc_measure_uptime_offset(); /* devices initialise one after the other */
	}

	sc_resolve_ifname(cfg->index, d->ifname);
	if (d->ifname[0] == '\0') {
		LOG_DBG("%s: no interface (CONFIG_CAN_SOCKETCAN_IFNAMES or --can-if=%u:<ifname>)",
			dev->name, cfg->index);
		return -ENODEV;
	}

	d->fd = socketcan_host_open(d->ifname);
	if (d->fd < 0) {
		rc = d->fd;
		LOG_ERR("%s: cannot open CAN interface %s: %s (%d)", dev->name, d->ifname,
			sc_open_error(rc), rc);
		d->fd = -1;
		return rc;
	}
	/* wakes the receive thread, which has frames in flight to judge, when the socket is quiet
	 */
	rc = socketcan_host_set_recv_timeout(d->fd, SC_RECV_TIMEOUT_MS);
	if (rc != 0) {
		LOG_ERR("%s: cannot set the receive timeout on %s: %d", dev->name, d->ifname, rc);
		socketcan_host_close(d->fd);
		d->fd = -1;
		return rc;
	}

	(void)k_thread_create(&d->rx_thread, sc_stacks[cfg->index],
			      K_THREAD_STACK_SIZEOF(sc_stacks[cfg->index]), sc_rx_thread, d, NULL,
			      NULL, CONFIG_CAN_SOCKETCAN_RX_THREAD_PRIORITY, 0, K_NO_WAIT);
	(void)k_thread_name_set(&d->rx_thread, dev->name);
	LOG_DBG("%s on %s", dev->name, d->ifname);

	return 0;
}

#define SC_DEFINE(i)                                                                               \
	static struct sc_data sc_data_##i;                                                         \
	static const struct sc_config sc_config_##i = {                                            \
		.common =                                                                          \
			{                                                                          \
				.min_bitrate = SC_MIN_BITRATE,                                     \
				.max_bitrate = SC_MAX_BITRATE,                                     \
				.bitrate = 500000U,                                                \
			},                                                                         \
		.index = (i),                                                                      \
	};                                                                                         \
	DEVICE_DEFINE(can_socketcan##i, "can_socketcan" #i, sc_init, NULL, &sc_data_##i,           \
		      &sc_config_##i, POST_KERNEL, 50, &sc_api)

SC_DEFINE(0);
#if SC_NUM_CTRL > 1
SC_DEFINE(1);
#endif
#if SC_NUM_CTRL > 2
SC_DEFINE(2);
#endif
#if SC_NUM_CTRL > 3
SC_DEFINE(3);
#endif
#if SC_NUM_CTRL > 4
SC_DEFINE(4);
#endif
#if SC_NUM_CTRL > 5
SC_DEFINE(5);
#endif
#if SC_NUM_CTRL > 6
SC_DEFINE(6);
#endif
#if SC_NUM_CTRL > 7
SC_DEFINE(7);
#endif
