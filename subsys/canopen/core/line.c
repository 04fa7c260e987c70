/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The I/O-free core of a line: receive table, timers, TX queue. The threaded binding is in
 * line_thread.c; everything here also runs on simulated time from a unit test.
 *
 * Locking: line->lock serialises changes of the receive table, protects the timer heap and
 * is a leaf lock. Receivers are looked up without it (a sequence count, see "Receive table"),
 * so a received frame takes one lock: its receiver's (the node's mutex). A timer handler is
 * taken off the heap under line->lock, which is released before the owner's lock is taken,
 * so a node lock is never acquired while line->lock is held (no lock-order inversion with an
 * application thread that holds its node lock and arms a timer).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/line.h>

#include "line_internal.h"

LOG_MODULE_REGISTER(co_line, CONFIG_CANOPEN_LOG_LEVEL);

/* Inlined on the hot paths when optimising for speed; one copy in a size build (-Os). */
#if defined(__OPTIMIZE_SIZE__)
#define CO_HOT_INLINE inline
#else
#define CO_HOT_INLINE ALWAYS_INLINE
#endif

/* The 11-bit identifiers, 0 to 7FFh. */
#define SFF_MASK 0x7ffU
#define EFF_MASK 0x1fffffffU

uint64_t co_line_now(void)
{
	return k_ticks_to_us_floor64((uint64_t)k_uptime_ticks());
}

uint64_t co_line_time(const struct co_line *line)
{
#if defined(CONFIG_CANOPEN_LINE_SIM)
	if (co_line_is_sim(line)) {
		return line->sim_now;
	}
#endif
	return co_line_now();
}

/* Simulation: one thread drives the line, whose time is the latest it was given. */
static inline void sim_advance(struct co_line *line, uint64_t now_us)
{
#if defined(CONFIG_CANOPEN_LINE_SIM)
	if (co_line_is_sim(line) && co_time_before_eq(line->sim_now, now_us)) {
		line->sim_now = now_us;
	}
#else
	ARG_UNUSED(line);
	ARG_UNUSED(now_us);
#endif
}

const struct device *co_line_device(const struct co_line *line)
{
	return line->dev;
}

static void line_init_common(struct co_line *line, const char *name)
{
	memset(line, 0, sizeof(*line));
	line->name = name;
	/* Every entry free: keys sort after every receiver's. */
	for (int i = 0; i <= CONFIG_CANOPEN_LINE_RX_SLOTS; i++) {
		line->rx_key[i] = (uint16_t)CO_LINE_KEY_FREE;
	}
	k_msgq_init(&line->rxq, line->rxq_buf, sizeof(struct co_line_rx_msg),
		    CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE);
	k_mutex_init(&line->lock);
	k_mutex_init(&line->tx_lock);
}

#if defined(CONFIG_CANOPEN_LINE_SIM)
void co_line_init_sim(struct co_line *line, const char *name, co_line_sink_t sink, void *user_data)
{
	line_init_common(line, name);
	line->sink = sink;
	line->sink_user_data = user_data;
}
#endif

int co_line_init(struct co_line *line, const char *name, const struct device *dev)
{
	if (!device_is_ready(dev)) {
		return -ENODEV;
	}
	line_init_common(line, name);
	line->dev = dev;
	line->filter_std = -1;
	line->filter_ext = -1;
	return 0;
}

void co_line_set_event_cb(struct co_line *line, co_line_event_cb_t cb, void *user_data)
{
	k_mutex_lock(&line->lock, K_FOREVER);
	line->event_cb = cb;
	line->event_user_data = user_data;
	k_mutex_unlock(&line->lock);
}

static void report_app(struct co_line *line, enum co_line_event event, int arg)
{
	co_line_event_cb_t cb;
	void *user_data;

	k_mutex_lock(&line->lock, K_FOREVER);
	cb = line->event_cb;
	user_data = line->event_user_data;
	k_mutex_unlock(&line->lock);
	if (cb != NULL) {
		cb(line, event, arg, user_data);
	}
}

/*
 * Call every listener with its owner's lock held. line->lock is only held to step through
 * the list (it is a leaf lock); a listener removed meanwhile ends the walk early.
 */
static void report_listeners(struct co_line *line, enum co_line_event event, int arg)
{
	struct co_line_listener *l;

	k_mutex_lock(&line->lock, K_FOREVER);
	l = line->listeners;
	k_mutex_unlock(&line->lock);

	while (l != NULL) {
		bool registered;

		if (l->lock != NULL) {
			k_mutex_lock(l->lock, K_FOREVER);
		}
		k_mutex_lock(&line->lock, K_FOREVER);
		registered = (l->line == line);
		k_mutex_unlock(&line->lock);
		if (registered) {
			l->cb(l, event, arg);
		}
		if (l->lock != NULL) {
			k_mutex_unlock(l->lock);
		}
		k_mutex_lock(&line->lock, K_FOREVER);
		l = (l->line == line) ? l->next : NULL;
		k_mutex_unlock(&line->lock);
	}
}

void co_line_report(struct co_line *line, enum co_line_event event, int arg)
{
	report_app(line, event, arg);
	report_listeners(line, event, arg);
}

void co_line_report_from_send(struct co_line *line, enum co_line_event event, int arg)
{
	report_app(line, event, arg);
	/* The sender may hold its node's lock: taking the other nodes' locks here could
	 * deadlock against the line thread, so the listeners hear of it from the line thread.
	 */
	if (event == CO_LINE_EV_TX_OVERFLOW) {
		atomic_set_bit(&line->flags, CO_LINE_F_TX_OVERFLOW);
	} else {
		atomic_set(&line->tx_error_pending, arg != 0 ? arg : -EIO);
	}
	co_line_wake(line);
}

void co_line_report_deferred(struct co_line *line)
{
	atomic_val_t err;

	/* Several overflows since the last look are one event for the listeners. */
	if (atomic_test_and_clear_bit(&line->flags, CO_LINE_F_TX_OVERFLOW)) {
		report_listeners(line, CO_LINE_EV_TX_OVERFLOW, 0);
	}
	err = atomic_set(&line->tx_error_pending, 0);
	if (err != 0) {
		report_listeners(line, CO_LINE_EV_TX_ERROR, (int)err);
	}
}

static void listener_unlink(struct co_line *line, struct co_line_listener *l)
{
	struct co_line_listener **pp = &line->listeners;

	while (*pp != NULL && *pp != l) {
		pp = &(*pp)->next;
	}
	if (*pp == l) {
		*pp = l->next;
	}
	l->next = NULL;
	l->line = NULL;
}

int co_line_listener_add(struct co_line *line, struct co_line_listener *l)
{
	struct co_line_listener **pp;
	struct co_line *old = l->line;

	if (old != NULL && old != line) {
		co_line_listener_remove(l);
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	pp = &line->listeners;
	while (*pp != NULL && *pp != l) {
		pp = &(*pp)->next;
	}
	if (*pp == NULL) {
		/* Append: listeners hear events in registration order. */
		*pp = l;
		l->next = NULL;
	}
	l->line = line;
	k_mutex_unlock(&line->lock);
	return 0;
}

void co_line_listener_remove(struct co_line_listener *l)
{
	struct co_line *line = l->line;

	if (line == NULL) {
		return;
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	listener_unlink(line, l);
	k_mutex_unlock(&line->lock);
}

/* --- Receive table --------------------------------------------------------------------- */

/*
 * One table per line (struct co_line): rx_tab[] holds the receivers and rx_key[] their keys,
 * ascending over the whole capacity. The exact 11-bit receivers come first with their id as
 * key, those of one id adjacent in registration order; then the masked and 29-bit ones
 * (CO_LINE_KEY_MASKED) in registration order; then the free entries (CO_LINE_KEY_FREE). A
 * frame's exact receivers are the run of its id, found by a lower-bound search over the whole
 * capacity: always ceil(log2(CONFIG_CANOPEN_LINE_RX_SLOTS)) steps, so the receivers of other
 * ids cost a frame nothing. The masked part is walked only by frames that one of its
 * receivers can match: rx_masked_codes has bit g when a masked 11-bit receiver matches some
 * id of function code g, so a heartbeat-range receiver costs an RPDO one test.
 *
 * Lookups take no lock. Changes (register, unregister, move, detach) are made under
 * line->lock, between two increments of line->rx_seq: odd while a change is under way. A
 * lookup reads rx_seq, walks the table and reads rx_seq again; it keeps what it found only
 * when both reads gave the same even count, else (or while a writer is at work) it looks
 * again under the lock. Every word a lookup reads (keys, receiver pointers, counts, the
 * function-code summary, the masked receivers' match keys, rx_seq) is written with a release
 * store and read with an acquire load: a lookup that sees any part of a change also sees the
 * odd count the change began with, so it cannot keep a half-made table (no fences needed,
 * TSan sees every pair). Receivers are never freed (they live in the services), so a lookup
 * that follows a pointer a writer has just moved reads valid memory, and throws the result
 * away. Every walk stays within the table's capacity.
 */

#define KEY_EXT BIT(31)

/* Function codes of 11-bit ids: the four high bits. */
#define FC_SHIFT 7U
#define FC_MASK  0x780U
#define FC_COUNT 16U

#define LD_ACQ(p)    __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define ST_REL(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)

static bool rx_is_direct(const struct co_rx *rx)
{
	return !rx->ext && (rx->mask & SFF_MASK) == SFF_MASK;
}

static void tbl_change_begin(struct co_line *line)
{
	__atomic_store_n(&line->rx_seq, line->rx_seq + 1U, __ATOMIC_RELAXED);
}

static void tbl_change_end(struct co_line *line)
{
	ST_REL(&line->rx_seq, line->rx_seq + 1U);
}

/* The largest power of two not above the table's capacity (8 to 128). */
#define RX_POW2                                                                                    \
	(CONFIG_CANOPEN_LINE_RX_SLOTS >= 128  ? 128U                                               \
	 : CONFIG_CANOPEN_LINE_RX_SLOTS >= 64 ? 64U                                                \
	 : CONFIG_CANOPEN_LINE_RX_SLOTS >= 32 ? 32U                                                \
	 : CONFIG_CANOPEN_LINE_RX_SLOTS >= 16 ? 16U                                                \
					      : 8U)

/* One halving of the search window: @p step is a constant, so are the steps taken. */
#define LB_STEP(step)                                                                              \
	do {                                                                                       \
		if ((step) < RX_POW2) {                                                            \
			base = (LD_ACQ(&keys[base + (step) - 1U]) < key) ? base + (step) : base;   \
		}                                                                                  \
	} while (false)

/*
 * The first position whose key is not below @p key (CONFIG_CANOPEN_LINE_RX_SLOTS if none), by
 * a binary search over the whole capacity: log2(RX_POW2) + 1 comparisons, one more when the
 * capacity is not a power of two, whatever the table holds (6 for 32 entries, 8 for 96). The
 * steps are written out and each is a conditional move, not a branch.
 */
static CO_HOT_INLINE unsigned int key_lower_bound(const uint16_t *keys, uint16_t key)
{
	unsigned int base = 0U;

	/* The first RX_POW2 entries or the last: they overlap and cover the table. */
	if (CONFIG_CANOPEN_LINE_RX_SLOTS != RX_POW2) {
		base = (LD_ACQ(&keys[RX_POW2 - 1U]) < key) ? CONFIG_CANOPEN_LINE_RX_SLOTS - RX_POW2
							   : 0U;
	}
	/* The answer is in [base, base + RX_POW2]; each step halves the window. */
	LB_STEP(128U);
	LB_STEP(64U);
	LB_STEP(32U);
	LB_STEP(16U);
	LB_STEP(8U);
	LB_STEP(4U);
	LB_STEP(2U);
	LB_STEP(1U);
	return base + ((LD_ACQ(&keys[base]) < key) ? 1U : 0U);
}

/* Position of @p rx in the table, or -1 (writers). */
static int rx_pos(const struct co_line *line, const struct co_rx *rx)
{
	for (int i = 0; i < line->rx_used; i++) {
		if (line->rx_tab[i] == rx) {
			return i;
		}
	}
	return -1;
}

/* The bits of rx_masked_codes a masked or 29-bit receiver sets. */
static uint32_t masked_codes_of(const struct co_rx *rx)
{
	uint32_t codes = 0U;

	if ((rx->key_id & KEY_EXT) != 0U) {
		return CO_LINE_MASKED_EXT;
	}
	for (uint32_t fc = 0U; fc < FC_COUNT; fc++) {
		if ((((fc << FC_SHIFT) ^ rx->key_id) & rx->key_mask & FC_MASK) == 0U) {
			codes |= BIT(fc);
		}
	}
	return codes;
}

/* Recompute rx_masked_codes from the masked part; table lock held. */
static void masked_codes_update(struct co_line *line)
{
	uint32_t codes = 0U;

	for (int i = line->rx_exact; i < line->rx_used; i++) {
		codes |= masked_codes_of(line->rx_tab[i]);
	}
	ST_REL(&line->rx_masked_codes, codes);
}

/*
 * rx->line changes under the table lock but is read without it: by the dispatcher, which has
 * let go of the table lock before it calls a receiver, and by co_rx_unregister(). Atomic
 * accesses keep those reads cheap (no second table lock per frame) and race-free.
 */
static inline struct co_line *rx_line_get(const struct co_rx *rx)
{
	return __atomic_load_n(&rx->line, __ATOMIC_ACQUIRE);
}

static inline void rx_line_set(struct co_rx *rx, struct co_line *line)
{
	__atomic_store_n(&rx->line, line, __ATOMIC_RELEASE);
}

/* Link a receiver; table lock held, between tbl_change_begin() and tbl_change_end(). */
static int rx_link(struct co_line *line, struct co_rx *rx)
{
	int n = line->rx_used;
	bool direct = rx_is_direct(rx);
	uint16_t key = direct ? (uint16_t)(rx->id & SFF_MASK) : (uint16_t)CO_LINE_KEY_MASKED;
	/* An exact receiver goes behind those of its id: they keep registration order. */
	int p = direct ? (int)key_lower_bound(line->rx_key, (uint16_t)(key + 1U)) : n;

	if (n >= CONFIG_CANOPEN_LINE_RX_SLOTS) {
		return -ENOSPC;
	}
	if (!direct) {
		ST_REL(&rx->key_id, rx->id | (rx->ext ? KEY_EXT : 0U));
		ST_REL(&rx->key_mask, rx->mask | KEY_EXT);
	}
	for (int i = n; i > p; i--) {
		ST_REL(&line->rx_key[i], line->rx_key[i - 1]);
		ST_REL(&line->rx_tab[i], line->rx_tab[i - 1]);
	}
	ST_REL(&line->rx_key[p], key);
	ST_REL(&line->rx_tab[p], rx);
	line->rx_used = (uint8_t)(n + 1);
	if (direct) {
		ST_REL(&line->rx_exact, (uint8_t)(line->rx_exact + 1U));
	} else {
		masked_codes_update(line);
	}
	rx_line_set(rx, line);
	return 0;
}

/* Unlink the receiver at @p pos; as rx_link(). */
static void rx_unlink_at(struct co_line *line, int pos)
{
	struct co_rx *rx = line->rx_tab[pos];
	int n = line->rx_used;

	for (int i = pos; i + 1 < n; i++) {
		ST_REL(&line->rx_key[i], line->rx_key[i + 1]);
		ST_REL(&line->rx_tab[i], line->rx_tab[i + 1]);
	}
	ST_REL(&line->rx_key[n - 1], (uint16_t)CO_LINE_KEY_FREE);
	ST_REL(&line->rx_tab[n - 1], NULL);
	line->rx_used = (uint8_t)(n - 1);
	if (pos < line->rx_exact) {
		ST_REL(&line->rx_exact, (uint8_t)(line->rx_exact - 1U));
	} else {
		masked_codes_update(line);
	}
	rx_line_set(rx, NULL);
}

/* Unlink a receiver; as rx_link(). */
static void rx_unlink(struct co_line *line, struct co_rx *rx)
{
	int pos = rx_pos(line, rx);

	if (pos >= 0) {
		rx_unlink_at(line, pos);
	} else {
		rx_line_set(rx, NULL);
	}
}

static bool id_fits(const struct co_rx *rx, uint32_t id)
{
	return (id & ~(rx->ext ? EFF_MASK : SFF_MASK)) == 0U;
}

void co_rx_unregister(struct co_rx *rx)
{
	struct co_line *line = rx_line_get(rx);

	if (line == NULL) {
		return;
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	if (rx->line == line) {
		tbl_change_begin(line);
		rx_unlink(line, rx);
		tbl_change_end(line);
	}
	k_mutex_unlock(&line->lock);
}

/*
 * Register @p rx with @p id, or (@p move) move it there from wherever it is registered. A
 * receiver on another line leaves that line's table under that line's lock; the two table
 * locks are never held together.
 */
static int rx_place(struct co_line *line, struct co_rx *rx, uint32_t id, bool move)
{
	struct co_line *old;
	int err = -EALREADY;

	if (!id_fits(rx, id)) {
		return -EINVAL;
	}
	old = rx_line_get(rx);
	if (move && old != NULL && old != line) {
		co_rx_unregister(rx);
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	if (move || rx->line == NULL) {
		tbl_change_begin(line);
		if (rx->line != NULL) {
			rx_unlink(line, rx);
		}
		rx->id = id;
		err = rx_link(line, rx);
		tbl_change_end(line);
	}
	k_mutex_unlock(&line->lock);
	return err;
}

int co_rx_set_id(struct co_line *line, struct co_rx *rx, uint32_t id)
{
	return rx_place(line, rx, id, true);
}

int co_rx_register(struct co_line *line, struct co_rx *rx)
{
	return rx_place(line, rx, rx->id, false);
}

/*
 * Call one receiver. The receiver is re-checked under its owner's lock: the owner may have
 * unregistered it between the lookup and now (receivers are static, so the memory is valid).
 */
static void rx_call(struct co_line *line, struct co_rx *rx, const struct can_frame *frame,
		    uint64_t now_us)
{
	if (rx->lock != NULL) {
		k_mutex_lock(rx->lock, K_FOREVER);
	}
	/* Found by a lookup; its owner may have removed it since. */
	if (rx_line_get(rx) == line) {
		rx->handler(rx, frame, now_us);
	}
	if (rx->lock != NULL) {
		k_mutex_unlock(rx->lock);
	}
}

/* Whether a receiver takes part: only those of @p lock, or all but those of @p origin. */
static inline bool rx_selected(const struct co_rx *rx, const struct k_mutex *lock, bool only)
{
	return only ? rx->lock == lock : (lock == NULL || rx->lock != lock);
}

/*
 * The receivers of a frame, in table order, into batch (the first
 * CONFIG_CANOPEN_LINE_RX_FANOUT of them). Returns how many matched.
 */
static CO_HOT_INLINE int rx_collect(const struct co_line *line, const struct can_frame *frame,
				    const struct k_mutex *lock, bool only, struct co_rx **batch)
{
	bool ext = (frame->flags & CAN_FRAME_IDE) != 0U;
	uint32_t codes = LD_ACQ(&line->rx_masked_codes);
	struct co_rx *rx;
	int m = 0;

	if (!ext) {
		uint16_t key = (uint16_t)(frame->id & SFF_MASK);

		/* The free key behind the last entry ends the run. */
		for (unsigned int i = key_lower_bound(line->rx_key, key);
		     LD_ACQ(&line->rx_key[i]) == key; i++) {
			rx = LD_ACQ(&line->rx_tab[i]);
			if (rx != NULL && rx_selected(rx, lock, only)) {
				if (m < CONFIG_CANOPEN_LINE_RX_FANOUT) {
					batch[m] = rx;
				}
				m++;
			}
		}
		codes &= BIT(key >> FC_SHIFT);
	} else {
		codes &= CO_LINE_MASKED_EXT;
	}
	if (codes != 0U) {
		uint32_t fkey = frame->id | (ext ? KEY_EXT : 0U);

		for (unsigned int i = LD_ACQ(&line->rx_exact);
		     LD_ACQ(&line->rx_key[i]) == (uint16_t)CO_LINE_KEY_MASKED; i++) {
			rx = LD_ACQ(&line->rx_tab[i]);
			if (rx != NULL &&
			    ((fkey ^ LD_ACQ(&rx->key_id)) & LD_ACQ(&rx->key_mask)) == 0U &&
			    rx_selected(rx, lock, only)) {
				if (m < CONFIG_CANOPEN_LINE_RX_FANOUT) {
					batch[m] = rx;
				}
				m++;
			}
		}
	}
	return m;
}

/*
 * The lookup met a change of the table: once more under the lock, which waits for the change
 * to end (the table changes at registrations and COB-ID writes, rarely enough that a second
 * try without the lock would not pay for its code).
 */
static __attribute__((noinline)) int rx_collect_again(struct co_line *line,
						      const struct can_frame *frame,
						      const struct k_mutex *lock, bool only,
						      struct co_rx **batch)
{
	int m;

	k_mutex_lock(&line->lock, K_FOREVER);
	m = rx_collect(line, frame, lock, only, batch);
	k_mutex_unlock(&line->lock);
	return m;
}

/* Receivers a frame could not reach: more matched than CONFIG_CANOPEN_LINE_RX_FANOUT. */
static __attribute__((noinline)) void rx_fanout_dropped(struct co_line *line, uint32_t drops)
{
	if (__atomic_fetch_add(&line->stats.rx_fanout_drops, drops, __ATOMIC_RELAXED) == 0U) {
		LOG_WRN("%s: a frame matched more than %d receivers; raise "
			"CONFIG_CANOPEN_LINE_RX_FANOUT",
			line->name, CONFIG_CANOPEN_LINE_RX_FANOUT);
	}
}

/* A counter only the line's dispatcher writes; read by co_line_get_stats(). */
static inline void stat_inc(uint32_t *counter)
{
	__atomic_store_n(counter, __atomic_load_n(counter, __ATOMIC_RELAXED) + 1U,
			 __ATOMIC_RELAXED);
}

/*
 * A frame from the bus. The common case, an 11-bit id with one exact receiver and no masked
 * receiver that could match it, is called from here on the same lookup, without a batch; any
 * other frame goes through co_line_dispatch_sel(), which collects its receivers first.
 */
int co_line_rx(struct co_line *line, const struct can_frame *frame, uint64_t now_us)
{
	uint32_t seq = LD_ACQ(&line->rx_seq);
	uint16_t key = (uint16_t)(frame->id & SFF_MASK);

	if (likely((frame->flags & CAN_FRAME_IDE) == 0U && (seq & 1U) == 0U &&
		   (LD_ACQ(&line->rx_masked_codes) & BIT(key >> FC_SHIFT)) == 0U)) {
		unsigned int i = key_lower_bound(line->rx_key, key);

		/* The free key behind the last entry: i + 1 stays inside rx_key. */
		if (LD_ACQ(&line->rx_key[i]) == key && LD_ACQ(&line->rx_key[i + 1U]) != key) {
			struct co_rx *rx = LD_ACQ(&line->rx_tab[i]);

			if (rx != NULL && LD_ACQ(&line->rx_seq) == seq) {
				sim_advance(line, now_us);
				stat_inc(&line->stats.rx_frames);
				rx_call(line, rx, frame, now_us);
				return 1;
			}
		}
	}
	return co_line_dispatch_sel(line, frame, now_us, NULL, false);
}

int co_line_dispatch(struct co_line *line, const struct can_frame *frame, uint64_t now_us,
		     const struct k_mutex *origin)
{
	return co_line_dispatch_sel(line, frame, now_us, origin, false);
}

/* Look the receivers up (without the table lock, see above), then call each with its owner's
 * lock held.
 */
int co_line_dispatch_sel(struct co_line *line, const struct can_frame *frame, uint64_t now_us,
			 const struct k_mutex *lock, bool only)
{
	/* only: the receivers of @p lock alone; else every receiver but those of @p lock. */
	struct co_rx *batch[CONFIG_CANOPEN_LINE_RX_FANOUT];
	uint32_t seq = LD_ACQ(&line->rx_seq);
	int n = -1;

	sim_advance(line, now_us);
	if (likely((seq & 1U) == 0U)) {
		n = rx_collect(line, frame, lock, only, batch);
	}
	if (unlikely(n < 0 || LD_ACQ(&line->rx_seq) != seq)) {
		n = rx_collect_again(line, frame, lock, only, batch);
	}
	if (unlikely(n > CONFIG_CANOPEN_LINE_RX_FANOUT)) {
		rx_fanout_dropped(line, (uint32_t)(n - CONFIG_CANOPEN_LINE_RX_FANOUT));
		n = CONFIG_CANOPEN_LINE_RX_FANOUT;
	}
	if (lock == NULL && !only) {
		stat_inc(&line->stats.rx_frames);
		if (n == 0) {
			stat_inc(&line->stats.rx_unhandled);
		}
	}
	for (int i = 0; i < n; i++) {
		rx_call(line, batch[i], frame, now_us);
	}
	return n;
}

/* --- Timers ----------------------------------------------------------------------------- */

void co_timer_init(struct co_timer *timer, co_timer_handler_t handler, struct k_mutex *lock,
		   void *user_data)
{
	memset(timer, 0, sizeof(*timer));
	timer->handler = handler;
	timer->lock = lock;
	timer->user_data = user_data;
	timer->slot = CO_TIMER_UNARMED;
}

/*
 * Armed timers: a binary min-heap per line (line->timers[0..n_timers-1]), each timer knowing
 * its place (slot), so a start or stop costs O(log n) and the next deadline is timers[0].
 * Equal deadlines keep arming order through the timer's arming number (seq).
 */

/* Whether @p a runs before @p b: earlier deadline, or the same one and armed earlier. */
static bool timer_before(const struct co_timer *a, const struct co_timer *b)
{
	if (a->deadline != b->deadline) {
		return co_time_before_eq(a->deadline, b->deadline);
	}
	return (int32_t)(a->seq - b->seq) < 0;
}

static void heap_put(struct co_line *line, struct co_timer *t, unsigned int i)
{
	line->timers[i] = t;
	t->slot = (uint16_t)i;
}

/* Move the timer at @p i towards the root while it runs before its parent. */
static void heap_up(struct co_line *line, unsigned int i)
{
	struct co_timer *t = line->timers[i];

	while (i > 0U) {
		unsigned int parent = (i - 1U) / 2U;

		if (!timer_before(t, line->timers[parent])) {
			break;
		}
		heap_put(line, line->timers[parent], i);
		i = parent;
	}
	heap_put(line, t, i);
}

/* Move the timer at @p i towards the leaves while a child runs before it. */
static void heap_down(struct co_line *line, unsigned int i)
{
	struct co_timer *t = line->timers[i];
	unsigned int n = line->n_timers;

	for (;;) {
		unsigned int c = 2U * i + 1U;

		if (c >= n) {
			break;
		}
		if (c + 1U < n && timer_before(line->timers[c + 1U], line->timers[c])) {
			c++;
		}
		if (!timer_before(line->timers[c], t)) {
			break;
		}
		heap_put(line, line->timers[c], i);
		i = c;
	}
	heap_put(line, t, i);
}

/* Take an armed timer out of the heap: the last one fills its place and moves up or down. */
static void heap_remove(struct co_line *line, struct co_timer *t)
{
	unsigned int i = t->slot;
	unsigned int last = line->n_timers - 1U;

	t->slot = CO_TIMER_UNARMED;
	line->n_timers = (uint16_t)last;
	if (i != last) {
		struct co_timer *moved = line->timers[last];

		heap_put(line, moved, i);
		if (i > 0U && timer_before(moved, line->timers[(i - 1U) / 2U])) {
			heap_up(line, i);
		} else {
			heap_down(line, i);
		}
	}
	line->timers[last] = NULL;
}

/* Whether a timer is in its line's heap (line lock held). */
static bool timer_armed(const struct co_line *line, const struct co_timer *timer)
{
	return timer->line == line && timer->slot != CO_TIMER_UNARMED;
}

static void timer_unlink(struct co_line *line, struct co_timer *timer)
{
	if (timer_armed(line, timer)) {
		heap_remove(line, timer);
	}
	/* Any start or stop makes the timer stale if co_line_process() has just taken it. */
	if (line->popped == timer) {
		line->popped = NULL;
	}
}

/* The heap is full: the timer stays disarmed, counted and logged (the first time). */
static __attribute__((noinline)) void timer_overflow(struct co_line *line)
{
	if (line->stats.timer_overflows++ == 0U) {
		LOG_ERR("%s: more than %d timers armed; raise CONFIG_CANOPEN_LINE_TIMERS",
			line->name, CONFIG_CANOPEN_LINE_TIMERS);
	}
}

void co_timer_start(struct co_line *line, struct co_timer *timer, uint64_t deadline_us)
{
	struct co_line *old = timer->line;
	bool first = false;

	if (old != NULL && old != line) {
		co_timer_stop(timer);
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	timer_unlink(line, timer);
	timer->deadline = deadline_us;
	timer->line = line;
	if (line->n_timers < CONFIG_CANOPEN_LINE_TIMERS) {
		timer->seq = line->timer_seq++;
		heap_put(line, timer, line->n_timers);
		line->n_timers++;
		heap_up(line, timer->slot);
		first = (timer->slot == 0U);
	} else {
		/* Not armed, whatever a zeroed timer's slot said. */
		timer->slot = CO_TIMER_UNARMED;
		timer_overflow(line);
	}
	k_mutex_unlock(&line->lock);

	if (first) {
		co_line_wake(line);
	}
}

void co_timer_stop(struct co_timer *timer)
{
	struct co_line *line = timer->line;

	if (line == NULL) {
		return;
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	timer_unlink(line, timer);
	k_mutex_unlock(&line->lock);
}

bool co_timer_is_armed(const struct co_timer *timer)
{
	struct co_line *line = timer->line;
	bool armed;

	if (line == NULL) {
		return false;
	}
	k_mutex_lock(&line->lock, K_FOREVER);
	armed = timer_armed(line, timer);
	k_mutex_unlock(&line->lock);
	return armed;
}

uint64_t co_line_next_deadline(struct co_line *line)
{
	uint64_t next = UINT64_MAX;

	k_mutex_lock(&line->lock, K_FOREVER);
	if (line->n_timers > 0U) {
		next = line->timers[0]->deadline;
	}
	k_mutex_unlock(&line->lock);
	return next;
}

/* Take the first expired timer out of the heap, or return NULL. */
static struct co_timer *timer_pop_expired(struct co_line *line, uint64_t now_us)
{
	struct co_timer *t = NULL;

	k_mutex_lock(&line->lock, K_FOREVER);
	if (line->n_timers > 0U && co_time_before_eq(line->timers[0]->deadline, now_us)) {
		t = line->timers[0];
		heap_remove(line, t);
		line->popped = t;
	}
	k_mutex_unlock(&line->lock);
	return t;
}

uint64_t co_line_process(struct co_line *line, uint64_t now_us)
{
	struct co_timer *t;

	if (co_line_is_sim(line)) {
		k_mutex_lock(&line->lock, K_FOREVER);
		sim_advance(line, now_us);
		k_mutex_unlock(&line->lock);
	}

	if (IS_ENABLED(CONFIG_CANOPEN_LINE_SHARED) && co_line_is_sim(line)) {
		co_line_local_drain(line);
	}

	/* A handler may re-arm its timer for a deadline already passed; bound the work so a
	 * zero-period timer cannot starve the line.
	 */
	for (int budget = 4 * CONFIG_CANOPEN_LINE_RX_SLOTS; budget > 0; budget--) {
		t = timer_pop_expired(line, now_us);
		if (t == NULL) {
			break;
		}
		bool due;

		if (t->lock != NULL) {
			k_mutex_lock(t->lock, K_FOREVER);
		}
		/* Started or stopped by another thread since it was popped: not due any more. */
		k_mutex_lock(&line->lock, K_FOREVER);
		due = line->popped == t && t->line == line;
		line->popped = NULL;
		k_mutex_unlock(&line->lock);
		if (due) {
			t->handler(t, now_us);
		}
		if (t->lock != NULL) {
			k_mutex_unlock(t->lock);
		}
	}
	co_line_tx_drain(line);
	co_line_report_deferred(line);
	if (co_line_is_sim(line) && k_msgq_num_used_get(&line->rxq) > 0U) {
		/* Local frames sent by the handlers above are due at once. */
		return now_us;
	}
	return co_line_next_deadline(line);
}

/* --- Transmission ------------------------------------------------------------------------ */

/* A simulated line's send: its sink (never called without CONFIG_CANOPEN_LINE_SIM). */
static inline int sim_sink(struct co_line *line, const struct can_frame *frame)
{
#if defined(CONFIG_CANOPEN_LINE_SIM)
	return line->sink(line, frame, line->sink_user_data);
#else
	ARG_UNUSED(line);
	ARG_UNUSED(frame);
	return -ENODEV;
#endif
}

/* Hand one frame to the driver or the sink. Returns 0, -EAGAIN (back-pressure) or an error. */
static inline int tx_submit(struct co_line *line, const struct can_frame *frame)
{
	int err;

	if (co_line_is_sim(line)) {
		err = sim_sink(line, frame);
	} else if (!atomic_test_bit(&line->flags, CO_LINE_F_RUNNING)) {
		/* Not started yet (a node's boot-up before co_line_start()): wait in the queue. */
		err = -EAGAIN;
	} else {
		err = co_line_dev_send(line, frame);
	}
	if (err == -ENOBUFS || err == -ENOSPC) {
		err = -EAGAIN;
	}
	return err;
}

/* tx_count changes under the TX lock and is read without it by line_send(). */
static inline void tx_count_set(struct co_line *line, uint16_t n)
{
	__atomic_store_n(&line->tx_count, n, __ATOMIC_RELEASE);
}

/* Sends that take no lock count here too. */
static inline void tx_frames_inc(struct co_line *line)
{
	(void)__atomic_fetch_add(&line->stats.tx_frames, 1U, __ATOMIC_RELAXED);
}

static void txq_push(struct co_line *line, const struct can_frame *frame,
		     const struct k_mutex *origin)
{
	uint16_t tail =
		(uint16_t)((line->tx_head + line->tx_count) % CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);

	line->txq[tail] = *frame;
	line->txq_origin[tail] = origin;
	tx_count_set(line, line->tx_count + 1U);
	line->stats.tx_queued++;
	atomic_set_bit(&line->flags, CO_LINE_F_TX_WAITING);
	if (line->tx_count > line->stats.tx_queue_max) {
		line->stats.tx_queue_max = line->tx_count;
	}
}

/*
 * The rest of line_send(), under the TX lock: the driver refused the frame with @p err
 * (-EAGAIN: it is full, the frame waits in the queue), or (@p err == 1) frames were waiting:
 * the frame queues behind them, or goes to the driver if they have gone meanwhile.
 */
static __attribute__((noinline)) int line_send_slow(struct co_line *line,
						    const struct can_frame *frame,
						    const struct k_mutex *origin, int err)
{
	bool overflow = false;
	bool error = false;

	k_mutex_lock(&line->tx_lock, K_FOREVER);
	if (err == 1) {
		err = line->tx_count == 0U ? tx_submit(line, frame) : -EAGAIN;
	}
	if (err == 0) {
		tx_frames_inc(line);
	} else if (err != -EAGAIN) {
		line->stats.tx_errors++;
		error = true;
	} else if (line->tx_count < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE) {
		/* Frames are waiting or the driver is full: queue to keep the order. */
		txq_push(line, frame, origin);
		err = 0;
	} else {
		line->stats.tx_dropped++;
		overflow = true;
		err = -ENOBUFS;
	}
	k_mutex_unlock(&line->tx_lock);

	if (overflow) {
		LOG_WRN("%s: TX queue full, frame %03x dropped", line->name, frame->id);
		co_line_report_from_send(line, CO_LINE_EV_TX_OVERFLOW, 0);
	} else if (error) {
		co_line_report_from_send(line, CO_LINE_EV_TX_ERROR, err);
	}
	return err;
}

/*
 * While nothing waits in the TX queue a frame goes straight to the driver, without the TX
 * lock (the driver serialises its own callers). Order is kept: a frame queued before this
 * send began has made tx_count non-zero (release store under the lock, acquire load here),
 * so this one queues behind it; a queued frame is drained before tx_count drops to zero.
 * Only sends that overlap in time may go out in either order, as they would on a bus.
 */
static CO_HOT_INLINE int line_send(struct co_line *line, const struct can_frame *frame,
				   const struct k_mutex *origin)
{
	int err = 1;

	if (likely(__atomic_load_n(&line->tx_count, __ATOMIC_ACQUIRE) == 0U)) {
		err = tx_submit(line, frame);
		if (likely(err == 0)) {
			tx_frames_inc(line);
			return 0;
		}
	}
	return line_send_slow(line, frame, origin, err);
}

int co_line_send(struct co_line *line, const struct can_frame *frame)
{
	return line_send(line, frame, NULL);
}

int co_line_tx_purge(struct co_line *line, const struct k_mutex *origin,
		     bool (*keep)(const struct can_frame *frame, void *arg), void *arg)
{
	uint16_t w = 0;
	int purged = 0;

	k_mutex_lock(&line->tx_lock, K_FOREVER);
	/* Compact the ring in place, oldest first, so the frames kept stay in order. */
	for (uint16_t r = 0; r < line->tx_count; r++) {
		uint16_t from = (uint16_t)((line->tx_head + r) % CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
		uint16_t to = (uint16_t)((line->tx_head + w) % CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);

		if (line->txq_origin[from] == origin &&
		    (keep == NULL || !keep(&line->txq[from], arg))) {
			purged++;
			continue;
		}
		if (to != from) {
			line->txq[to] = line->txq[from];
			line->txq_origin[to] = line->txq_origin[from];
		}
		w++;
	}
	tx_count_set(line, w);
	line->stats.tx_purged += (uint32_t)purged;
	if (line->tx_count == 0U) {
		atomic_clear_bit(&line->flags, CO_LINE_F_TX_WAITING);
	}
	k_mutex_unlock(&line->tx_lock);
	return purged;
}

int co_line_tx_space(struct co_line *line)
{
	int space;

	k_mutex_lock(&line->tx_lock, K_FOREVER);
	space = CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE - (int)line->tx_count;
	k_mutex_unlock(&line->tx_lock);
	return space;
}

int co_line_attach(struct co_line *line, struct co_line_member *m, const struct k_mutex *lock)
{
	k_mutex_lock(&line->lock, K_FOREVER);
	if (!IS_ENABLED(CONFIG_CANOPEN_LINE_SHARED) && line->members != NULL) {
		k_mutex_unlock(&line->lock);
		return -EBUSY;
	}
	m->lock = lock;
	m->next = line->members;
	line->members = m;
	if (line->n_nodes < UINT8_MAX) {
		/* Read without the lock by every co_line_send_from(). */
		__atomic_store_n(&line->n_nodes, (uint8_t)(line->n_nodes + 1U), __ATOMIC_RELAXED);
	}
	k_mutex_unlock(&line->lock);
	return 0;
}

/* Drop every receiver and timer of one owner (a node leaving the line). */
static void purge_owner(struct co_line *line, const struct k_mutex *lock)
{
	/* From the top: rx_unlink_at() moves the entries above down. */
	for (int i = line->rx_used - 1; i >= 0; i--) {
		if (line->rx_tab[i]->lock == lock) {
			rx_unlink_at(line, i);
		}
	}
	/* From the start again after each removal: the heap moves timers around. */
	for (unsigned int i = 0U; i < line->n_timers;) {
		struct co_timer *t = line->timers[i];

		if (t->lock == lock) {
			timer_unlink(line, t);
			i = 0U;
		} else {
			i++;
		}
	}
}

void co_line_detach(struct co_line *line, struct co_line_member *m)
{
	k_mutex_lock(&line->lock, K_FOREVER);
	for (struct co_line_member **pp = &line->members; *pp != NULL; pp = &(*pp)->next) {
		if (*pp == m) {
			tbl_change_begin(line);
			purge_owner(line, m->lock);
			tbl_change_end(line);
			*pp = m->next;
			m->next = NULL;
			__atomic_store_n(&line->n_nodes, (uint8_t)(line->n_nodes - 1U),
					 __ATOMIC_RELAXED);
			break;
		}
	}
	k_mutex_unlock(&line->lock);
}

bool co_line_owner_held(struct co_line *line)
{
	k_tid_t self = k_current_get();
	bool held = false;

	k_mutex_lock(&line->lock, K_FOREVER);
	for (const struct co_line_member *m = line->members; m != NULL && !held; m = m->next) {
		/* Only this thread can make the answer true, so an unlocked look is exact. */
		held = __atomic_load_n(&m->lock->owner, __ATOMIC_RELAXED) == self;
	}
	k_mutex_unlock(&line->lock);
	return held;
}

#if defined(CONFIG_CANOPEN_LINE_SHARED)
/* A frame a node sent, for the line's other nodes: through the RX queue to the line thread. */
static __attribute__((noinline)) void
local_deliver(struct co_line *line, const struct can_frame *frame, const struct k_mutex *origin)
{
	struct co_line_rx_msg msg = {
		.frame = *frame,
		.time_lo = (uint32_t)co_line_time(line),
		.origin = origin,
	};

	/* The frame went to the driver or the sink: its dlc has none of the kind's bits. */
	msg.frame.dlc |= CO_LINE_MSG_LOCAL;

	if (k_msgq_put(&line->rxq, &msg, K_NO_WAIT) != 0) {
		co_line_rx_overrun(line);
	}
}

int co_line_send_from(struct co_line *line, const struct can_frame *frame,
		      const struct k_mutex *origin)
{
	int err = line_send(line, frame, origin);

	if (err == 0 && __atomic_load_n(&line->n_nodes, __ATOMIC_RELAXED) > 1U) {
		local_deliver(line, frame, origin);
	}
	return err;
}
#else
/* One node per line: no other node to deliver to. */
int co_line_send_from(struct co_line *line, const struct can_frame *frame,
		      const struct k_mutex *origin)
{
	return line_send(line, frame, origin);
}
#endif /* CONFIG_CANOPEN_LINE_SHARED */

void co_line_local_drain(struct co_line *line)
{
#if defined(CONFIG_CANOPEN_LINE_SHARED)
	struct co_line_rx_msg msg;

	/* Bounded: handlers may send (and so queue) more local frames. */
	for (int i = 0; i < CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE; i++) {
		if (k_msgq_get(&line->rxq, &msg, K_NO_WAIT) != 0) {
			break;
		}
		if ((msg.frame.dlc & CO_LINE_MSG_KINDS) == CO_LINE_MSG_LOCAL) {
			msg.frame.dlc &= (uint8_t)~CO_LINE_MSG_LOCAL;
			co_line_dispatch(line, &msg.frame,
					 co_line_msg_time(&msg, co_line_time(line)), msg.origin);
		}
	}
#else
	ARG_UNUSED(line);
#endif
}

void co_line_tx_drain(struct co_line *line)
{
	int err = 0;

	k_mutex_lock(&line->tx_lock, K_FOREVER);
	while (line->tx_count > 0U) {
		err = tx_submit(line, &line->txq[line->tx_head]);
		if (err == -EAGAIN) {
			err = 0;
			break;
		}
		if (err == 0) {
			tx_frames_inc(line);
		} else {
			line->stats.tx_errors++;
		}
		line->tx_head =
			(uint16_t)((line->tx_head + 1U) % CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
		tx_count_set(line, line->tx_count - 1U);
		if (err != 0) {
			break;
		}
	}
	if (line->tx_count == 0U) {
		atomic_clear_bit(&line->flags, CO_LINE_F_TX_WAITING);
	}
	k_mutex_unlock(&line->tx_lock);

	if (err != 0) {
		co_line_report(line, CO_LINE_EV_TX_ERROR, err);
	}
}

void co_line_get_stats(struct co_line *line, struct co_line_stats *stats)
{
	const struct co_line_stats *s = &line->stats;

	memset(stats, 0, sizeof(*stats));
	k_mutex_lock(&line->tx_lock, K_FOREVER);
	stats->tx_frames = __atomic_load_n(&s->tx_frames, __ATOMIC_RELAXED);
	stats->tx_queued = s->tx_queued;
	stats->tx_dropped = s->tx_dropped;
	stats->tx_errors = s->tx_errors;
	stats->tx_queue_max = s->tx_queue_max;
	stats->tx_purged = s->tx_purged;
	k_mutex_unlock(&line->tx_lock);
	/* Counted by the dispatcher, which takes no lock. */
	stats->rx_frames = __atomic_load_n(&line->stats.rx_frames, __ATOMIC_RELAXED);
	stats->rx_unhandled = __atomic_load_n(&line->stats.rx_unhandled, __ATOMIC_RELAXED);
	stats->rx_fanout_drops = __atomic_load_n(&line->stats.rx_fanout_drops, __ATOMIC_RELAXED);
	stats->rx_overruns = __atomic_load_n(&line->stats.rx_overruns, __ATOMIC_RELAXED);
	k_mutex_lock(&line->lock, K_FOREVER);
	stats->timer_overflows = line->stats.timer_overflows;
	k_mutex_unlock(&line->lock);
}
