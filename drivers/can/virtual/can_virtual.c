/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Virtual CAN controllers on in-process buses (model and test API: include/can_virtual.h).
 *
 * The bus is a small discrete-event simulation. Events, in this order when they fall on the
 * same instant: end of the frame on the bus (delivery, then TX completion), end of a bus-off
 * recovery, a delayed delivery (receiver latency or a delay fault), start of the next frame
 * (arbitration among frames queued by then). In real-time mode a thread per bus processes events as
 * the uptime clock reaches them and sleeps until the next one (woken early by new frames). In
 * simulated mode the test moves one global clock and events run in its thread, in time order across
 * buses.
 *
 * Locking: one mutex (cv_lock) guards all bus and controller state; it is never held while a
 * callback runs. Each controller's rx_lock is held while its receive callbacks run and while
 * its filters change, so a removed filter is never called afterwards; state_cb_lock does the
 * same for the state-change callback. Callbacks must not block
 * (Zephyr's ISR rule); they may call the CAN API (k_mutex is recursive).
 */

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/init.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/util.h>

#include "can_filter_table.h"
#include "can_virtual.h"

LOG_MODULE_REGISTER(can_virtual, CONFIG_CAN_LOG_LEVEL);

#define CV_NUM_CTRL      CONFIG_CAN_VIRTUAL_NUM_CONTROLLERS
#define CV_NUM_BUSES     CONFIG_CAN_VIRTUAL_NUM_BUSES
#define CV_TXQ_SIZE      CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE
#define CV_MAX_FILTERS   CONFIG_CAN_VIRTUAL_MAX_FILTERS
#define CV_DELAY_SIZE    CONFIG_CAN_VIRTUAL_DELAY_QUEUE_SIZE
#define CV_MAX_FAULTS    8
/* State changes a controller holds for its callback; more than two at once only in a race. */
#define CV_STATE_QUEUE   4U
#define CV_NEVER         UINT64_MAX
/* Bus-off ends after 128 occurrences of 11 consecutive recessive bits (ISO 11898-1). */
#define CV_RECOVERY_BITS (128U * 11U)
#define CV_MIN_BITRATE   10000U
#define CV_MAX_BITRATE   1000000U
#define CV_CAPABILITIES                                                                            \
	(CAN_MODE_LOOPBACK | CAN_MODE_LISTENONLY | CAN_MODE_ONE_SHOT | CAN_MODE_MANUAL_RECOVERY)

BUILD_ASSERT(CV_NUM_CTRL <= 8, "the driver defines up to 8 controllers");

struct cv_tx {
	bool used;
	bool inflight;
	struct can_frame frame;
	can_tx_callback_t cb;
	void *user_data;
	uint64_t seq;
	uint64_t queued_ns;
};

struct cv_state_change {
	enum can_state state;
	struct can_bus_err_cnt cnt;
};

struct cv_config {
	struct can_driver_config common; /* first, for the generic API */
	uint8_t index;
};

struct cv_data {
	struct can_driver_data common; /* first, for the generic API */
	const struct device *dev;
	/* guarded by cv_lock */
	uint8_t bus;
	uint32_t bitrate;
	enum can_state state;
	uint16_t tec; /* 256 in bus-off */
	uint8_t rec;
	bool cut;
	bool cut_hit; /* error-passive already applied for the current cut */
	enum can_state precut_state;
	uint16_t precut_tec;
	uint8_t precut_rec;
	uint32_t latency_us;
	uint64_t recover_at_ns; /* CV_NEVER when no recovery is running */
	struct cv_tx txq[CV_TXQ_SIZE];
	/* free transmit entries; waited on by can_send() */
	struct k_sem tx_slots;
	/* given when a bus-off ends, for can_recover() */
	struct k_sem recovered;
	/* State changes not yet passed to the callback, oldest first (cv_notify_run()). */
	struct cv_state_change changes[CV_STATE_QUEUE];
	uint8_t changes_head;
	uint8_t n_changes;
	/* Held while a state-change callback runs and while it is replaced (before cv_lock). */
	struct k_mutex state_cb_lock;
	/* guarded by rx_lock */
	struct k_mutex rx_lock;
	struct can_filter_slot filters[CV_MAX_FILTERS];
};

enum cv_fault_type {
	CV_FAULT_NONE,
	CV_FAULT_DROP,
	CV_FAULT_CORRUPT,
	CV_FAULT_DELAY,
};

struct cv_fault {
	enum cv_fault_type type;
	struct can_filter filter;
	uint32_t remaining;
	uint8_t xor_mask[CAN_MAX_DLEN];
	uint32_t delay_us;
};

struct cv_delayed {
	bool used;
	uint8_t ctrl;
	uint64_t due_ns;
	uint64_t seq;
	struct can_frame frame;
};

struct cv_bus {
	bool bit_timing;
	bool busy;
	uint8_t inflight_ctrl;
	uint8_t inflight_slot;
	uint64_t inflight_end_ns;
	uint64_t idle_at_ns;
	struct cv_fault faults[CV_MAX_FAULTS];
	struct cv_delayed delayed[CV_DELAY_SIZE];
	struct can_virtual_bus_stats stats;
#if defined(CONFIG_CAN_VIRTUAL_CLOCK_REALTIME)
	struct k_sem kick;
	struct k_thread thread;
#endif
};

static K_MUTEX_DEFINE(cv_lock);
static struct cv_bus cv_buses[CV_NUM_BUSES];
static uint64_t cv_seq;
#if defined(CONFIG_CAN_VIRTUAL_CLOCK_SIMULATED)
static uint64_t cv_sim_now_ns;
static bool cv_sim_running;
#else
K_THREAD_STACK_ARRAY_DEFINE(cv_stacks, CV_NUM_BUSES, CONFIG_CAN_VIRTUAL_THREAD_STACK_SIZE);
#endif

static const struct device *cv_devs[CV_NUM_CTRL];

static inline struct cv_data *cv_data(const struct device *dev)
{
	return (struct cv_data *)dev->data;
}

static uint64_t cv_now_ns(void)
{
#if defined(CONFIG_CAN_VIRTUAL_CLOCK_SIMULATED)
	return cv_sim_now_ns;
#else
	return k_ticks_to_ns_floor64((uint64_t)k_uptime_ticks());
#endif
}

static void cv_kick(uint8_t bus)
{
#if defined(CONFIG_CAN_VIRTUAL_CLOCK_REALTIME)
	k_sem_give(&cv_buses[bus].kick);
#else
	ARG_UNUSED(bus);
#endif
}

static bool cv_is_ours(const struct device *dev)
{
	for (int i = 0; i < CV_NUM_CTRL; i++) {
		if (cv_devs[i] == dev && dev != NULL) {
			return true;
		}
	}

	return false;
}

static uint64_t bits_to_ns(uint32_t bits, uint32_t bitrate)
{
	return ((uint64_t)bits * 1000000000ULL) / bitrate;
}

/*
 * Arbitration field in transmission order (smaller wins): base id, RTR or SRR, IDE, extension,
 * RTR of an extended frame.
 */
static uint32_t cv_arb_key(const struct can_frame *f)
{
	const uint32_t rtr = (f->flags & CAN_FRAME_RTR) != 0U ? 1U : 0U;

	if ((f->flags & CAN_FRAME_IDE) != 0U) {
		return ((f->id >> 18) << 21) | (1U << 20) | (1U << 19) | ((f->id & 0x3FFFFU) << 1) |
		       rtr;
	}

	return (f->id << 21) | (rtr << 20);
}

static struct can_bus_err_cnt cv_err_cnt(const struct cv_data *d)
{
	struct can_bus_err_cnt cnt = {
		.tx_err_cnt = (uint8_t)MIN(d->tec, 255U),
		.rx_err_cnt = d->rec,
	};

	return cnt;
}

/* A controller with state changes to pass to its callback once cv_lock is released. */
struct cv_notify {
	const struct device *dev;
};

static void cv_set_state_locked(struct cv_data *d, enum can_state state, uint16_t tec, uint8_t rec,
				struct cv_notify *n)
{
	const bool changed = d->state != state;

	d->state = state;
	d->tec = tec;
	d->rec = rec;
	n->dev = NULL;
	if (changed && d->common.started) {
		struct cv_state_change *c;

		if (d->n_changes < CV_STATE_QUEUE) {
			c = &d->changes[(d->changes_head + d->n_changes) % CV_STATE_QUEUE];
			d->n_changes++;
		} else {
			/* Full: the newest entry becomes this state, so the last state still
			 * arrives. */
			c = &d->changes[(d->changes_head + CV_STATE_QUEUE - 1U) % CV_STATE_QUEUE];
		}
		c->state = state;
		c->cnt = cv_err_cnt(d);
		n->dev = d->dev;
	}
}

/*
 * Passes the controller's queued state changes to its callback, oldest first. Two threads
 * that changed the state (a test injecting one, the bus thread ending a bus-off) both come
 * here after releasing cv_lock; whichever takes state_cb_lock first delivers every change
 * queued so far, in the order they happened, so the callback never sees a later state before
 * an earlier one. The callback is read again under state_cb_lock: once
 * can_set_state_change_callback() has returned, the one it replaced never runs.
 */
static void cv_notify_run(const struct cv_notify *n)
{
	struct cv_data *d;

	if (n->dev == NULL) {
		return;
	}
	d = cv_data(n->dev);
	(void)k_mutex_lock(&d->state_cb_lock, K_FOREVER);
	for (;;) {
		struct cv_state_change c;
		can_state_change_callback_t cb;
		void *user_data;

		(void)k_mutex_lock(&cv_lock, K_FOREVER);
		if (d->n_changes == 0U) {
			(void)k_mutex_unlock(&cv_lock);
			break;
		}
		c = d->changes[d->changes_head];
		d->changes_head = (uint8_t)((d->changes_head + 1U) % CV_STATE_QUEUE);
		d->n_changes--;
		cb = d->common.state_change_cb;
		user_data = d->common.state_change_cb_user_data;
		(void)k_mutex_unlock(&cv_lock);
		if (cb != NULL) {
			cb(n->dev, c.state, c.cnt, user_data);
		}
	}
	(void)k_mutex_unlock(&d->state_cb_lock);
}

/* Completed or aborted transmissions, collected under cv_lock and called after it. */
struct cv_txdone {
	can_tx_callback_t cb;
	void *user_data;
	int error;
};

/* Frees every queued frame of @p d; returns how many callbacks were stored in @p out. */
static int cv_abort_tx_locked(struct cv_data *d, int error, struct cv_txdone out[CV_TXQ_SIZE])
{
	struct cv_bus *b = &cv_buses[d->bus];
	int n = 0;

	for (int i = 0; i < CV_TXQ_SIZE; i++) {
		struct cv_tx *tx = &d->txq[i];

		if (!tx->used) {
			continue;
		}
		if (tx->inflight) {
			/* The frame on the wire is cut short; the bus is free again. */
			b->busy = false;
			b->idle_at_ns = cv_now_ns();
		}
		out[n].cb = tx->cb;
		out[n].user_data = tx->user_data;
		out[n].error = error;
		n++;
		tx->used = false;
		tx->inflight = false;
		k_sem_give(&d->tx_slots);
	}

	return n;
}

static void cv_txdone_run(const struct device *dev, const struct cv_txdone *t, int n)
{
	for (int i = 0; i < n; i++) {
		if (t[i].cb != NULL) {
			t[i].cb(dev, t[i].error, t[i].user_data);
		}
	}
}

static void cv_schedule_recovery_locked(struct cv_data *d)
{
	if (d->recover_at_ns == CV_NEVER) {
		d->recover_at_ns = cv_now_ns() + bits_to_ns(CV_RECOVERY_BITS, d->bitrate);
		cv_kick(d->bus);
	}
}

/* ------------------------------------------------------------------------------------------ */
/* Delivery                                                                                   */

static void cv_deliver(struct cv_data *d, const struct can_frame *frame)
{
	can_filter_table_deliver(d->dev, d->filters, CV_MAX_FILTERS, &d->rx_lock, frame);
}

static bool cv_can_receive_locked(const struct cv_data *d)
{
	return d->common.started && d->state != CAN_STATE_BUS_OFF && !d->cut;
}

static void cv_stamp(struct can_frame *frame, uint64_t t_ns)
{
#if defined(CONFIG_CAN_RX_TIMESTAMP)
	frame->timestamp = (uint16_t)(t_ns / 1000U);
#else
	ARG_UNUSED(frame);
	ARG_UNUSED(t_ns);
#endif
}

static bool cv_delay_locked(struct cv_bus *b, uint8_t ctrl, uint64_t due_ns,
			    const struct can_frame *frame)
{
	for (int i = 0; i < CV_DELAY_SIZE; i++) {
		struct cv_delayed *e = &b->delayed[i];

		if (!e->used) {
			e->used = true;
			e->ctrl = ctrl;
			e->due_ns = due_ns;
			e->seq = cv_seq++;
			e->frame = *frame;
			return true;
		}
	}
	b->stats.delay_overflows++;

	return false;
}

/*
 * Applies the first matching fault. Returns false if the frame is lost; *delay_ns gets the
 * time every receiver gets it later (0 for none).
 */
static bool cv_apply_faults_locked(struct cv_bus *b, struct can_frame *frame, uint64_t *delay_ns)
{
	*delay_ns = 0U;
	for (int i = 0; i < CV_MAX_FAULTS; i++) {
		struct cv_fault *f = &b->faults[i];

		if (f->type == CV_FAULT_NONE || !can_frame_matches_filter(frame, &f->filter)) {
			continue;
		}
		const enum cv_fault_type type = f->type;

		if (--f->remaining == 0U) {
			f->type = CV_FAULT_NONE;
		}
		if (type == CV_FAULT_DROP) {
			b->stats.dropped++;
			return false;
		}
		if (type == CV_FAULT_DELAY) {
			*delay_ns = (uint64_t)f->delay_us * 1000U;
			b->stats.delayed++;
			return true;
		}
		if ((frame->flags & CAN_FRAME_RTR) == 0U) {
			for (int k = 0; k < frame->dlc && k < (int)CAN_MAX_DLEN; k++) {
				frame->data[k] ^= f->xor_mask[k];
			}
		}
		b->stats.corrupted++;
		return true;
	}

	return true;
}

/* ------------------------------------------------------------------------------------------ */
/* Event processing                                                                           */

enum cv_event {
	CV_EV_NONE,
	CV_EV_END,
	CV_EV_RECOVER,
	CV_EV_DELAYED,
	CV_EV_START,
};

static bool cv_can_send_locked(const struct cv_data *d, uint8_t bus)
{
	return d->bus == bus && d->common.started && d->state != CAN_STATE_BUS_OFF && !d->cut;
}

/* The next event of bus @p bus and its time; CV_NEVER if none. */
static uint64_t cv_next_event_locked(uint8_t bus, enum cv_event *ev, int *arg)
{
	struct cv_bus *b = &cv_buses[bus];
	uint64_t t = CV_NEVER;

	*ev = CV_EV_NONE;
	if (b->busy) {
		t = b->inflight_end_ns;
		*ev = CV_EV_END;
	}
	for (int i = 0; i < CV_NUM_CTRL; i++) {
		struct cv_data *d = cv_data(cv_devs[i]);

		if (d->bus == bus && d->recover_at_ns < t) {
			t = d->recover_at_ns;
			*ev = CV_EV_RECOVER;
			*arg = i;
		}
	}
	for (int i = 0; i < CV_DELAY_SIZE; i++) {
		struct cv_delayed *e = &b->delayed[i];

		if (e->used && (e->due_ns < t || (*ev == CV_EV_DELAYED && e->due_ns == t &&
						  e->seq < b->delayed[*arg].seq))) {
			t = e->due_ns;
			*ev = CV_EV_DELAYED;
			*arg = i;
		}
	}
	if (!b->busy) {
		uint64_t first = CV_NEVER;

		for (int i = 0; i < CV_NUM_CTRL; i++) {
			struct cv_data *d = cv_data(cv_devs[i]);

			if (!cv_can_send_locked(d, bus)) {
				continue;
			}
			for (int s = 0; s < CV_TXQ_SIZE; s++) {
				if (d->txq[s].used) {
					first = MIN(first, d->txq[s].queued_ns);
				}
			}
		}
		if (first != CV_NEVER) {
			uint64_t start = MAX(first, b->idle_at_ns);

			if (start < t) {
				t = start;
				*ev = CV_EV_START;
			}
		}
	}

	return t;
}

/* Arbitration at @p now: the lowest key among frames queued by then, first in on a tie. */
static void cv_start_frame_locked(uint8_t bus, uint64_t now)
{
	struct cv_bus *b = &cv_buses[bus];
	int best_ctrl = -1;
	int best_slot = -1;
	uint32_t best_key = 0U;
	uint64_t best_seq = 0U;

	for (int i = 0; i < CV_NUM_CTRL; i++) {
		struct cv_data *d = cv_data(cv_devs[i]);

		if (!cv_can_send_locked(d, bus)) {
			continue;
		}
		for (int s = 0; s < CV_TXQ_SIZE; s++) {
			struct cv_tx *tx = &d->txq[s];
			uint32_t key;

			if (!tx->used || tx->queued_ns > now) {
				continue;
			}
			key = cv_arb_key(&tx->frame);
			if (best_ctrl < 0 || key < best_key ||
			    (key == best_key && tx->seq < best_seq)) {
				best_ctrl = i;
				best_slot = s;
				best_key = key;
				best_seq = tx->seq;
			}
		}
	}
	if (best_ctrl < 0) {
		return;
	}

	struct cv_data *d = cv_data(cv_devs[best_ctrl]);
	uint64_t duration = 0U;

	if (b->bit_timing) {
		duration = bits_to_ns(can_virtual_frame_bits(&d->txq[best_slot].frame), d->bitrate);
		b->stats.busy_ns += duration;
	}
	d->txq[best_slot].inflight = true;
	b->busy = true;
	b->inflight_ctrl = (uint8_t)best_ctrl;
	b->inflight_slot = (uint8_t)best_slot;
	b->inflight_end_ns = now + duration;
}

/*
 * Runs the next event of @p bus if it is due at @p now. Called with cv_lock held; returns with
 * it released. @p frames counts completed frames.
 */
static bool cv_run_event(uint8_t bus, uint64_t now, int *frames)
{
	struct cv_bus *b = &cv_buses[bus];
	enum cv_event ev;
	int arg = 0;
	uint64_t t = cv_next_event_locked(bus, &ev, &arg);

	if (ev == CV_EV_NONE || t > now) {
		(void)k_mutex_unlock(&cv_lock);
		return false;
	}

	switch (ev) {
	case CV_EV_START:
		cv_start_frame_locked(bus, t);
		(void)k_mutex_unlock(&cv_lock);
		return true;

	case CV_EV_RECOVER: {
		struct cv_data *d = cv_data(cv_devs[arg]);
		struct cv_notify n;

		d->recover_at_ns = CV_NEVER;
		cv_set_state_locked(d, CAN_STATE_ERROR_ACTIVE, 0U, 0U, &n);
		k_sem_give(&d->recovered);
		(void)k_mutex_unlock(&cv_lock);
		LOG_DBG("%s: bus-off recovery done", d->dev->name);
		cv_notify_run(&n);
		return true;
	}

	case CV_EV_DELAYED: {
		struct cv_delayed *e = &b->delayed[arg];
		struct cv_data *d = cv_data(cv_devs[e->ctrl]);
		struct can_frame frame = e->frame;
		const bool ok = cv_can_receive_locked(d) && d->bus == bus;

		e->used = false;
		(void)k_mutex_unlock(&cv_lock);
		if (ok) {
			cv_deliver(d, &frame);
		}
		return true;
	}

	case CV_EV_END: {
		struct cv_data *src = cv_data(cv_devs[b->inflight_ctrl]);
		struct cv_tx *tx = &src->txq[b->inflight_slot];
		struct can_frame frame = tx->frame;
		struct cv_txdone done = {.cb = tx->cb, .user_data = tx->user_data, .error = 0};
		struct cv_data *now_rx[CV_NUM_CTRL];
		int n_rx = 0;
		const bool loopback = (src->common.mode & CAN_MODE_LOOPBACK) != 0U;
		uint64_t delay_ns = 0U;
		bool lost = false;

		b->busy = false;
		b->idle_at_ns = t;
		b->stats.frames++;
		tx->used = false;
		tx->inflight = false;
		k_sem_give(&src->tx_slots);
		(*frames)++;

		if ((frame.flags & CAN_FRAME_RTR) != 0U) {
			(void)memset(frame.data, 0, sizeof(frame.data));
		}
		if (!loopback) {
			lost = !cv_apply_faults_locked(b, &frame, &delay_ns);
		}
		for (int i = 0; !lost && i < CV_NUM_CTRL; i++) {
			struct cv_data *d = cv_data(cv_devs[i]);
			const bool self = d == src;

			if (self != loopback || d->bus != bus || !cv_can_receive_locked(d) ||
			    d->bitrate != src->bitrate) {
				continue;
			}
			/* A delayed frame adds to the receiver's own latency. */
			if (d->latency_us == 0U && delay_ns == 0U) {
				now_rx[n_rx++] = d;
			} else {
				uint64_t due = t + delay_ns + (uint64_t)d->latency_us * 1000U;
				struct can_frame late = frame;

				cv_stamp(&late, due);
				if (cv_delay_locked(b, (uint8_t)i, due, &late)) {
					cv_kick(bus);
				}
			}
		}
		(void)k_mutex_unlock(&cv_lock);

		cv_stamp(&frame, t);
		for (int i = 0; i < n_rx; i++) {
			cv_deliver(now_rx[i], &frame);
		}
		cv_txdone_run(src->dev, &done, 1);
		return true;
	}

	default:
		(void)k_mutex_unlock(&cv_lock);
		return false;
	}
}

#if defined(CONFIG_CAN_VIRTUAL_CLOCK_REALTIME)
static void cv_bus_thread(void *p1, void *p2, void *p3)
{
	const uint8_t bus = (uint8_t)(uintptr_t)p1;
	struct cv_bus *b = &cv_buses[bus];
	int frames = 0;

	for (;;) {
		enum cv_event ev;
		int arg;
		uint64_t next;

		(void)k_mutex_lock(&cv_lock, K_FOREVER);
		if (cv_run_event(bus, cv_now_ns(), &frames)) {
			continue;
		}
		(void)k_mutex_lock(&cv_lock, K_FOREVER);
		next = cv_next_event_locked(bus, &ev, &arg);
		(void)k_mutex_unlock(&cv_lock);
		/* Sleep until the next event; a new frame or state change gives the kick. */
		if (next == CV_NEVER) {
			(void)k_sem_take(&b->kick, K_FOREVER);
		} else {
			k_sem_take(&b->kick, K_TIMEOUT_ABS_TICKS(k_ns_to_ticks_ceil64(next)));
		}
	}
}
#endif

/* ------------------------------------------------------------------------------------------ */
/* Driver API                                                                                 */

static int cv_get_capabilities(const struct device *dev, can_mode_t *cap)
{
	*cap = CV_CAPABILITIES;

	return 0;
}

static int cv_start(const struct device *dev)
{
	struct cv_data *d = cv_data(dev);
	int rc = 0;

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (d->common.started) {
		rc = -EALREADY;
	} else {
		/* A (re)started controller comes out of reset: error-active, counters cleared. */
		d->state = CAN_STATE_ERROR_ACTIVE;
		d->tec = 0U;
		d->rec = 0U;
		d->recover_at_ns = CV_NEVER;
		d->cut_hit = false;
		d->common.started = true;
	}
	(void)k_mutex_unlock(&cv_lock);

	return rc;
}

static int cv_stop(const struct device *dev)
{
	struct cv_data *d = cv_data(dev);
	struct cv_txdone aborted[CV_TXQ_SIZE];
	int n;

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (!d->common.started) {
		(void)k_mutex_unlock(&cv_lock);
		return -EALREADY;
	}
	d->common.started = false;
	d->recover_at_ns = CV_NEVER;
	n = cv_abort_tx_locked(d, -ENETDOWN, aborted);
	cv_kick(d->bus);
	(void)k_mutex_unlock(&cv_lock);
	cv_txdone_run(dev, aborted, n);

	return 0;
}

static int cv_set_mode(const struct device *dev, can_mode_t mode)
{
	struct cv_data *d = cv_data(dev);
	int rc = 0;

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (d->common.started) {
		rc = -EBUSY;
	} else if ((mode & ~(can_mode_t)CV_CAPABILITIES) != 0U) {
		rc = -ENOTSUP;
	} else {
		d->common.mode = mode;
	}
	(void)k_mutex_unlock(&cv_lock);

	return rc;
}

static int cv_set_bitrate(const struct device *dev, uint32_t bitrate)
{
	struct cv_data *d = cv_data(dev);
	int rc = 0;

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (d->common.started) {
		rc = -EBUSY;
	} else {
		d->bitrate = bitrate;
	}
	(void)k_mutex_unlock(&cv_lock);

	return rc;
}

static int cv_send(const struct device *dev, const struct can_frame *frame, k_timeout_t timeout,
		   can_tx_callback_t callback, void *user_data)
{
	struct cv_data *d = cv_data(dev);
	struct cv_notify n = {.dev = NULL};
	int rc = 0;

	if ((frame->flags & ~(CAN_FRAME_IDE | CAN_FRAME_RTR)) != 0U) {
		return -ENOTSUP;
	}

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (!d->common.started) {
		rc = -ENETDOWN;
	} else if (d->state == CAN_STATE_BUS_OFF) {
		rc = -ENETUNREACH;
	} else if ((d->common.mode & CAN_MODE_LISTENONLY) != 0U) {
		rc = -EIO;
	} else {
		/* Started, not bus-off, not listen-only: the frame is sent below. */
	}
	(void)k_mutex_unlock(&cv_lock);
	if (rc != 0) {
		return rc;
	}

	if (k_sem_take(&d->tx_slots, timeout) != 0) {
		return -EAGAIN;
	}

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	/* The controller may have stopped or gone bus-off while we waited. */
	if (!d->common.started) {
		rc = -ENETDOWN;
	} else if (d->state == CAN_STATE_BUS_OFF) {
		rc = -ENETUNREACH;
	} else {
		/* Still started and not bus-off: the frame is queued below. */
	}
	if (rc != 0) {
		k_sem_give(&d->tx_slots);
		(void)k_mutex_unlock(&cv_lock);
		return rc;
	}
	for (int i = 0; i < CV_TXQ_SIZE; i++) {
		struct cv_tx *tx = &d->txq[i];

		if (!tx->used) {
			tx->used = true;
			tx->inflight = false;
			tx->frame = *frame;
			tx->cb = callback;
			tx->user_data = user_data;
			tx->seq = cv_seq++;
			tx->queued_ns = cv_now_ns();
			break;
		}
	}
	if (d->cut && !d->cut_hit) {
		/* No ACK on a cut line: the controller ends up error-passive. */
		d->cut_hit = true;
		if (d->state < CAN_STATE_ERROR_PASSIVE) {
			cv_set_state_locked(d, CAN_STATE_ERROR_PASSIVE, 128U, d->rec, &n);
		}
	}
	cv_kick(d->bus);
	(void)k_mutex_unlock(&cv_lock);
	cv_notify_run(&n);

	return 0;
}

static int cv_add_rx_filter(const struct device *dev, can_rx_callback_t callback, void *user_data,
			    const struct can_filter *filter)
{
	struct cv_data *d = cv_data(dev);

	return can_filter_table_add(d->filters, CV_MAX_FILTERS, &d->rx_lock, callback, user_data,
				    filter);
}

static void cv_remove_rx_filter(const struct device *dev, int filter_id)
{
	struct cv_data *d = cv_data(dev);

	can_filter_table_remove(d->filters, CV_MAX_FILTERS, &d->rx_lock, filter_id);
}

static int cv_get_state(const struct device *dev, enum can_state *state,
			struct can_bus_err_cnt *err_cnt)
{
	struct cv_data *d = cv_data(dev);

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (state != NULL) {
		*state = d->common.started ? d->state : CAN_STATE_STOPPED;
	}
	if (err_cnt != NULL) {
		*err_cnt = cv_err_cnt(d);
	}
	(void)k_mutex_unlock(&cv_lock);

	return 0;
}

static int cv_recover(const struct device *dev, k_timeout_t timeout)
{
	struct cv_data *d = cv_data(dev);

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if ((d->common.mode & CAN_MODE_MANUAL_RECOVERY) == 0U) {
		(void)k_mutex_unlock(&cv_lock);
		return -ENOTSUP;
	}
	if (!d->common.started) {
		(void)k_mutex_unlock(&cv_lock);
		return -ENETDOWN;
	}
	if (d->state != CAN_STATE_BUS_OFF) {
		(void)k_mutex_unlock(&cv_lock);
		return 0;
	}
	k_sem_reset(&d->recovered);
	cv_schedule_recovery_locked(d);
	(void)k_mutex_unlock(&cv_lock);

	return k_sem_take(&d->recovered, timeout) == 0 ? 0 : -EAGAIN;
}

static void cv_set_state_change_callback(const struct device *dev,
					 can_state_change_callback_t callback, void *user_data)
{
	struct cv_data *d = cv_data(dev);

	/* Also under state_cb_lock: waits for a notification under way (cv_notify_run()). */
	(void)k_mutex_lock(&d->state_cb_lock, K_FOREVER);
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	d->common.state_change_cb = callback;
	d->common.state_change_cb_user_data = user_data;
	(void)k_mutex_unlock(&cv_lock);
	(void)k_mutex_unlock(&d->state_cb_lock);
}

static int cv_get_max_filters(const struct device *dev, bool ide)
{
	return CV_MAX_FILTERS;
}

static const struct can_driver_api cv_api = {
	.get_capabilities = cv_get_capabilities,
	.start = cv_start,
	.stop = cv_stop,
	.set_mode = cv_set_mode,
	.set_bitrate = cv_set_bitrate,
	.send = cv_send,
	.add_rx_filter = cv_add_rx_filter,
	.remove_rx_filter = cv_remove_rx_filter,
	.recover = cv_recover,
	.get_state = cv_get_state,
	.set_state_change_callback = cv_set_state_change_callback,
	.get_max_filters = cv_get_max_filters,
};

/* ------------------------------------------------------------------------------------------ */
/* Test API                                                                                   */

static bool cv_bus_ok(int bus)
{
	return bus >= 0 && bus < CV_NUM_BUSES;
}

static int cv_add_fault(int bus, enum cv_fault_type type, const struct can_filter *filter,
			uint32_t count, const uint8_t *xor_mask, uint32_t delay_us)
{
	int rc = -ENOSPC;

	if (!cv_bus_ok(bus) || filter == NULL || count == 0U) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	for (int i = 0; i < CV_MAX_FAULTS; i++) {
		struct cv_fault *f = &cv_buses[bus].faults[i];

		if (f->type == CV_FAULT_NONE) {
			f->type = type;
			f->filter = *filter;
			f->remaining = count;
			(void)memset(f->xor_mask, 0, sizeof(f->xor_mask));
			if (xor_mask != NULL) {
				(void)memcpy(f->xor_mask, xor_mask, sizeof(f->xor_mask));
			}
			f->delay_us = delay_us;
			rc = 0;
			break;
		}
	}
	(void)k_mutex_unlock(&cv_lock);

	return rc;
}

int can_virtual_drop_frames(int bus, const struct can_filter *filter, uint32_t count)
{
	return cv_add_fault(bus, CV_FAULT_DROP, filter, count, NULL, 0U);
}

int can_virtual_corrupt_frames(int bus, const struct can_filter *filter, uint32_t count,
			       const uint8_t xor_mask[CAN_MAX_DLEN])
{
	if (xor_mask == NULL) {
		return -EINVAL;
	}

	return cv_add_fault(bus, CV_FAULT_CORRUPT, filter, count, xor_mask, 0U);
}

int can_virtual_delay_frames(int bus, const struct can_filter *filter, uint32_t count,
			     uint32_t delay_us)
{
	if (delay_us == 0U) {
		return -EINVAL;
	}

	return cv_add_fault(bus, CV_FAULT_DELAY, filter, count, NULL, delay_us);
}

int can_virtual_clear_faults(int bus)
{
	if (!cv_bus_ok(bus)) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	for (int i = 0; i < CV_MAX_FAULTS; i++) {
		cv_buses[bus].faults[i].type = CV_FAULT_NONE;
	}
	(void)k_mutex_unlock(&cv_lock);

	return 0;
}

int can_virtual_set_state(const struct device *dev, enum can_state state)
{
	static const uint16_t tec_of[] = {
		[CAN_STATE_ERROR_ACTIVE] = 0U,
		[CAN_STATE_ERROR_WARNING] = 96U,
		[CAN_STATE_ERROR_PASSIVE] = 128U,
		[CAN_STATE_BUS_OFF] = 256U,
	};
	struct cv_txdone aborted[CV_TXQ_SIZE];
	struct cv_notify n = {.dev = NULL};
	struct cv_data *d;
	int n_aborted = 0;

	if (!cv_is_ours(dev) || (int)state < 0 || state > CAN_STATE_BUS_OFF) {
		return -EINVAL;
	}
	d = cv_data(dev);
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (!d->common.started) {
		(void)k_mutex_unlock(&cv_lock);
		return -ENETDOWN;
	}
	const bool was_bus_off = d->state == CAN_STATE_BUS_OFF;

	cv_set_state_locked(d, state, tec_of[state], 0U, &n);
	if (state == CAN_STATE_BUS_OFF) {
		n_aborted = cv_abort_tx_locked(d, -ENETUNREACH, aborted);
		if ((d->common.mode & CAN_MODE_MANUAL_RECOVERY) == 0U) {
			cv_schedule_recovery_locked(d);
		}
	} else if (was_bus_off) {
		/* Leaving bus-off by injection ends a running recovery too. */
		d->recover_at_ns = CV_NEVER;
		k_sem_give(&d->recovered);
	} else {
		/* Between the active, warning and passive states nothing more changes. */
	}
	cv_kick(d->bus);
	(void)k_mutex_unlock(&cv_lock);
	cv_notify_run(&n);
	cv_txdone_run(dev, aborted, n_aborted);

	return 0;
}

int can_virtual_cut(const struct device *dev)
{
	struct cv_notify n = {.dev = NULL};
	struct cv_data *d;

	if (!cv_is_ours(dev)) {
		return -EINVAL;
	}
	d = cv_data(dev);
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (!d->cut) {
		bool pending = false;

		d->cut = true;
		d->cut_hit = false;
		d->precut_state = d->state;
		d->precut_tec = d->tec;
		d->precut_rec = d->rec;
		for (int i = 0; i < CV_TXQ_SIZE; i++) {
			/* A frame already on the wire completes; the others wait. */
			pending |= d->txq[i].used && !d->txq[i].inflight;
		}
		if (pending && d->common.started) {
			d->cut_hit = true;
			if (d->state < CAN_STATE_ERROR_PASSIVE) {
				cv_set_state_locked(d, CAN_STATE_ERROR_PASSIVE, 128U, d->rec, &n);
			}
		}
	}
	(void)k_mutex_unlock(&cv_lock);
	cv_notify_run(&n);

	return 0;
}

int can_virtual_restore(const struct device *dev)
{
	struct cv_notify n = {.dev = NULL};
	struct cv_data *d;

	if (!cv_is_ours(dev)) {
		return -EINVAL;
	}
	d = cv_data(dev);
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (d->cut) {
		d->cut = false;
		if (d->cut_hit && d->state == CAN_STATE_ERROR_PASSIVE) {
			cv_set_state_locked(d, d->precut_state, d->precut_tec, d->precut_rec, &n);
		}
		d->cut_hit = false;
		cv_kick(d->bus);
	}
	(void)k_mutex_unlock(&cv_lock);
	cv_notify_run(&n);

	return 0;
}

int can_virtual_set_latency(const struct device *dev, uint32_t latency_us)
{
	if (!cv_is_ours(dev)) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	cv_data(dev)->latency_us = latency_us;
	(void)k_mutex_unlock(&cv_lock);

	return 0;
}

int can_virtual_set_bus(const struct device *dev, int bus)
{
	struct cv_data *d;
	int rc = 0;

	if (!cv_is_ours(dev) || !cv_bus_ok(bus)) {
		return -EINVAL;
	}
	d = cv_data(dev);
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	if (d->common.started) {
		rc = -EBUSY;
	} else {
		d->bus = (uint8_t)bus;
	}
	(void)k_mutex_unlock(&cv_lock);

	return rc;
}

int can_virtual_get_bus(const struct device *dev)
{
	int bus;

	if (!cv_is_ours(dev)) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	bus = cv_data(dev)->bus;
	(void)k_mutex_unlock(&cv_lock);

	return bus;
}

int can_virtual_bus_set_bit_timing(int bus, bool enable)
{
	if (!cv_bus_ok(bus)) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	cv_buses[bus].bit_timing = enable;
	(void)k_mutex_unlock(&cv_lock);

	return 0;
}

int can_virtual_bus_get_stats(int bus, struct can_virtual_bus_stats *stats)
{
	if (!cv_bus_ok(bus) || stats == NULL) {
		return -EINVAL;
	}
	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	*stats = cv_buses[bus].stats;
	(void)k_mutex_unlock(&cv_lock);

	return 0;
}

uint64_t can_virtual_time_us(void)
{
	uint64_t t;

	(void)k_mutex_lock(&cv_lock, K_FOREVER);
	t = cv_now_ns() / 1000U;
	(void)k_mutex_unlock(&cv_lock);

	return t;
}

#if defined(CONFIG_CAN_VIRTUAL_CLOCK_SIMULATED)
/*
 * One step of the global simulation: the earliest event over all buses that is due by
 * @p until_ns. Returns false when there is none (cv_lock released either way).
 */
static bool cv_sim_step(uint64_t until_ns, int *frames)
{
	uint64_t best_t = CV_NEVER;
	int best_bus = -1;

	k_mutex_lock(&cv_lock, K_FOREVER);
	for (int bus = 0; bus < CV_NUM_BUSES; bus++) {
		enum cv_event ev;
		int arg;
		uint64_t t = cv_next_event_locked((uint8_t)bus, &ev, &arg);

		if (ev != CV_EV_NONE && t < best_t) {
			best_t = t;
			best_bus = bus;
		}
	}
	if (best_bus < 0 || best_t > until_ns) {
		k_mutex_unlock(&cv_lock);
		return false;
	}
	/* Callbacks of this event see the clock at the event's time. */
	cv_sim_now_ns = MAX(cv_sim_now_ns, best_t);

	return cv_run_event((uint8_t)best_bus, best_t, frames);
}

static int cv_sim_enter(void)
{
	int rc = 0;

	k_mutex_lock(&cv_lock, K_FOREVER);
	if (cv_sim_running) {
		rc = -EBUSY;
	} else {
		cv_sim_running = true;
	}
	k_mutex_unlock(&cv_lock);

	return rc;
}

static void cv_sim_leave(void)
{
	k_mutex_lock(&cv_lock, K_FOREVER);
	cv_sim_running = false;
	k_mutex_unlock(&cv_lock);
}

int can_virtual_sim_advance(uint64_t delta_us)
{
	uint64_t until;
	int frames = 0;
	int rc = cv_sim_enter();

	if (rc != 0) {
		return rc;
	}
	k_mutex_lock(&cv_lock, K_FOREVER);
	until = cv_sim_now_ns + delta_us * 1000U;
	k_mutex_unlock(&cv_lock);
	while (cv_sim_step(until, &frames)) {
	}
	k_mutex_lock(&cv_lock, K_FOREVER);
	cv_sim_now_ns = until;
	k_mutex_unlock(&cv_lock);
	cv_sim_leave();

	return frames;
}

int can_virtual_sim_run(uint32_t max_frames)
{
	int frames = 0;
	int rc = cv_sim_enter();

	if (rc != 0) {
		return rc;
	}
	while ((uint32_t)frames < max_frames && cv_sim_step(CV_NEVER - 1U, &frames)) {
	}
	cv_sim_leave();

	return frames;
}
#else
int can_virtual_sim_advance(uint64_t delta_us)
{
	ARG_UNUSED(delta_us);

	return -ENOTSUP;
}

int can_virtual_sim_run(uint32_t max_frames)
{
	ARG_UNUSED(max_frames);

	return -ENOTSUP;
}
#endif

/* ------------------------------------------------------------------------------------------ */
/* Instances                                                                                  */

static int cv_buses_init(void)
{
	for (int bus = 0; bus < CV_NUM_BUSES; bus++) {
		struct cv_bus *b = &cv_buses[bus];

		b->bit_timing = IS_ENABLED(CONFIG_CAN_VIRTUAL_BIT_TIMING);
#if defined(CONFIG_CAN_VIRTUAL_CLOCK_REALTIME)
		(void)k_sem_init(&b->kick, 0, 1);
		k_thread_create(&b->thread, cv_stacks[bus], K_THREAD_STACK_SIZEOF(cv_stacks[bus]),
				cv_bus_thread, (void *)(uintptr_t)bus, NULL, NULL,
				CONFIG_CAN_VIRTUAL_THREAD_PRIORITY, 0, K_NO_WAIT);
		(void)k_thread_name_set(&b->thread, "can_virtual_bus");
#endif
	}

	return 0;
}

/* After the controllers (priority 50): the bus threads look at every controller. */
SYS_INIT(cv_buses_init, POST_KERNEL, 60);

static int cv_init(const struct device *dev)
{
	const struct cv_config *cfg = dev->config;
	struct cv_data *d = dev->data;

	d->dev = dev;
	d->bus = (uint8_t)(cfg->index % CV_NUM_BUSES);
	d->bitrate = cfg->common.bitrate;
	d->state = CAN_STATE_ERROR_ACTIVE;
	d->recover_at_ns = CV_NEVER;
	d->common.mode = CAN_MODE_NORMAL;
	(void)k_mutex_init(&d->rx_lock);
	(void)k_mutex_init(&d->state_cb_lock);
	(void)k_sem_init(&d->tx_slots, CV_TXQ_SIZE, CV_TXQ_SIZE);
	(void)k_sem_init(&d->recovered, 0, 1);
	cv_devs[cfg->index] = dev;

	return 0;
}

#define CV_DEFINE(i)                                                                               \
	static struct cv_data cv_data_##i;                                                         \
	static const struct cv_config cv_config_##i = {                                            \
		.common =                                                                          \
			{                                                                          \
				.min_bitrate = CV_MIN_BITRATE,                                     \
				.max_bitrate = CV_MAX_BITRATE,                                     \
				.bitrate = CONFIG_CAN_VIRTUAL_BITRATE,                             \
			},                                                                         \
		.index = (i),                                                                      \
	};                                                                                         \
	DEVICE_DEFINE(can_virtual##i, "can_virtual" #i, cv_init, NULL, &cv_data_##i,               \
		      &cv_config_##i, POST_KERNEL, 50, &cv_api)

CV_DEFINE(0);
#if CV_NUM_CTRL > 1
CV_DEFINE(1);
#endif
#if CV_NUM_CTRL > 2
CV_DEFINE(2);
#endif
#if CV_NUM_CTRL > 3
CV_DEFINE(3);
#endif
#if CV_NUM_CTRL > 4
CV_DEFINE(4);
#endif
#if CV_NUM_CTRL > 5
CV_DEFINE(5);
#endif
#if CV_NUM_CTRL > 6
CV_DEFINE(6);
#endif
#if CV_NUM_CTRL > 7
CV_DEFINE(7);
#endif
