/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The virtual bus beyond the CAN API: arbitration order, bit timing, fault injection (drop,
 * corrupt, cut, latency, error states, bus-off recovery), separate buses. Most tests run on the
 * simulated clock, where every result is exact; a few check the real-time mode.
 *
 * Wiring (see before()): c0, c1, c2 on bus 0, c3 on bus 1.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>

#define BITRATE 500000U
#define BIT_NS  (1000000000U / BITRATE)

static const struct device *c[4];

struct rx_rec {
	int ctrl;
	uint64_t t_us;
	struct can_frame frame;
};

static struct rx_rec rx_log[64];
static int n_rx;
static int filter_ids[4][2];

struct tx_rec {
	int ctrl;
	int error;
	uint64_t t_us;
};

static struct tx_rec tx_log[64];
static int n_tx;

static enum can_state states[16];
static struct can_bus_err_cnt state_cnt[16];
static int n_states;

static void rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	if (n_rx < (int)ARRAY_SIZE(rx_log)) {
		rx_log[n_rx].ctrl = (int)(intptr_t)user_data;
		rx_log[n_rx].t_us = can_virtual_time_us();
		rx_log[n_rx].frame = *frame;
		n_rx++;
	}
}

static void tx_cb(const struct device *dev, int error, void *user_data)
{
	if (n_tx < (int)ARRAY_SIZE(tx_log)) {
		tx_log[n_tx].ctrl = (int)(intptr_t)user_data;
		tx_log[n_tx].error = error;
		tx_log[n_tx].t_us = can_virtual_time_us();
		n_tx++;
	}
}

static void state_cb(const struct device *dev, enum can_state state, struct can_bus_err_cnt cnt,
		     void *user_data)
{
	if (n_states < (int)ARRAY_SIZE(states)) {
		states[n_states] = state;
		state_cnt[n_states] = cnt;
		n_states++;
	}
}

static struct can_frame frame_of(uint32_t id, uint8_t flags, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .flags = flags, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}

	return f;
}

static void queue(int ctrl, const struct can_frame *f)
{
	int rc = can_send(c[ctrl], f, K_NO_WAIT, tx_cb, (void *)(intptr_t)ctrl);

	zassert_equal(rc, 0, "c%d can_send(0x%x): %d", ctrl, f->id, rc);
}

/* Frames received by controller @p ctrl, in order. */
static int rx_of(int ctrl, struct rx_rec *out[], int max)
{
	int n = 0;

	for (int i = 0; i < n_rx && n < max; i++) {
		if (rx_log[i].ctrl == ctrl) {
			out[n++] = &rx_log[i];
		}
	}

	return n;
}

static void *suite_setup(void)
{
	static const char *const names[] = {"can_virtual0", "can_virtual1", "can_virtual2",
					    "can_virtual3"};

	for (int i = 0; i < 4; i++) {
		c[i] = device_get_binding(names[i]);
		zassert_not_null(c[i], "%s not ready", names[i]);
	}

	return NULL;
}

static void before(void *fixture)
{
	static const struct can_filter all_std = {.id = 0, .mask = 0, .flags = 0};
	static const struct can_filter all_ext = {.id = 0, .mask = 0, .flags = CAN_FILTER_IDE};

	for (int i = 0; i < 4; i++) {
		int rc = can_stop(c[i]);

		zassert_true(rc == 0 || rc == -EALREADY);
		zassert_ok(can_set_mode(c[i], CAN_MODE_NORMAL));
		zassert_ok(can_set_bitrate(c[i], BITRATE));
		zassert_ok(can_virtual_set_bus(c[i], i < 3 ? 0 : 1));
		zassert_ok(can_virtual_set_latency(c[i], 0));
		zassert_ok(can_virtual_restore(c[i]));
		can_set_state_change_callback(c[i], state_cb, NULL);
		filter_ids[i][0] = can_add_rx_filter(c[i], rx_cb, (void *)(intptr_t)i, &all_std);
		filter_ids[i][1] = can_add_rx_filter(c[i], rx_cb, (void *)(intptr_t)i, &all_ext);
		zassert_true(filter_ids[i][0] >= 0 && filter_ids[i][1] >= 0);
		zassert_ok(can_start(c[i]));
	}
	for (int bus = 0; bus < 2; bus++) {
		zassert_ok(can_virtual_clear_faults(bus));
		zassert_ok(can_virtual_bus_set_bit_timing(bus, false));
	}
	n_rx = 0;
	n_tx = 0;
	n_states = 0;
}

static void after(void *fixture)
{
	for (int i = 0; i < 4; i++) {
		can_remove_rx_filter(c[i], filter_ids[i][0]);
		can_remove_rx_filter(c[i], filter_ids[i][1]);
		can_set_state_change_callback(c[i], NULL, NULL);
	}
}

ZTEST_SUITE(can_virtual, NULL, suite_setup, before, after, NULL);

/*
 * Reference length of a frame on the wire, written independently of the driver: the whole
 * unstuffed bit string first, the CRC over it, then a stuffing pass.
 */
static uint32_t ref_frame_bits(const struct can_frame *f)
{
	uint8_t bits[160];
	int n = 0;
	const bool rtr = (f->flags & CAN_FRAME_RTR) != 0U;
	uint32_t crc = 0;
	int stuff = 0;
	int run = 0;
	int prev = -1;

#define PUT(v, w)                                                                                  \
	for (int _i = (w) - 1; _i >= 0; _i--) {                                                    \
		bits[n++] = (uint8_t)(((v) >> _i) & 1U);                                           \
	}
	PUT(0U, 1);
	if ((f->flags & CAN_FRAME_IDE) != 0U) {
		PUT(f->id >> 18, 11);
		PUT(3U, 2); /* SRR, IDE */
		PUT(f->id & 0x3FFFFU, 18);
		PUT(rtr ? 1U : 0U, 1);
		PUT(0U, 2);
	} else {
		PUT(f->id, 11);
		PUT(rtr ? 1U : 0U, 1);
		PUT(0U, 2);
	}
	PUT(f->dlc, 4);
	for (int i = 0; !rtr && i < f->dlc; i++) {
		PUT(f->data[i], 8);
	}
	for (int i = 0; i < n; i++) {
		/* CRC-15/CAN, x^15 + x^14 + x^10 + x^8 + x^7 + x^4 + x^3 + 1 */
		uint32_t top = (crc >> 14) & 1U;

		crc = (crc << 1) & 0x7FFFU;
		if ((top ^ bits[i]) != 0U) {
			crc ^= 0x4599U;
		}
	}
	PUT(crc, 15);
#undef PUT
	for (int i = 0; i < n; i++) {
		if (bits[i] == prev) {
			run++;
		} else {
			prev = bits[i];
			run = 1;
		}
		if (run == 5) {
			stuff++;
			prev = !prev;
			run = 1;
		}
	}

	return (uint32_t)(n + stuff + 13);
}

ZTEST(can_virtual, test_frame_bits_match_reference)
{
	uint32_t seed = 12345U;
	bool saw_stuffing = false;

	for (int k = 0; k < 2000; k++) {
		struct can_frame f = {0};
		uint32_t bits;
		uint32_t base;
		uint32_t max_stuffable;

		seed = seed * 1103515245U + 12345U;
		f.flags = (seed >> 16) & 1U ? CAN_FRAME_IDE : 0U;
		if (((seed >> 17) & 7U) == 0U) {
			f.flags |= CAN_FRAME_RTR;
		}
		f.id = (seed >> 3) &
		       ((f.flags & CAN_FRAME_IDE) ? CAN_EXT_ID_MASK : CAN_STD_ID_MASK);
		f.dlc = (uint8_t)((seed >> 24) % 9U);
		for (int i = 0; i < 8; i++) {
			seed = seed * 1103515245U + 12345U;
			/* plenty of 0x00/0xFF bytes, which force stuffing */
			f.data[i] = ((seed >> 20) & 3U) == 0U ? 0U : (uint8_t)(seed >> 24);
		}
		bits = can_virtual_frame_bits(&f);
		zassert_equal(bits, ref_frame_bits(&f), "frame %d id 0x%x dlc %u", k, f.id, f.dlc);

		/* unstuffed length and the worst case of one stuff bit per 4 bits after the first
		 */
		max_stuffable = ((f.flags & CAN_FRAME_IDE) ? 39U : 19U) +
				((f.flags & CAN_FRAME_RTR) ? 0U : 8U * f.dlc) + 15U;
		base = max_stuffable + 13U;
		zassert_true(bits >= base && bits <= base + (max_stuffable - 1U) / 4U);
		saw_stuffing |= bits > base;
	}
	zassert_true(saw_stuffing);
}

#if defined(CONFIG_CAN_VIRTUAL_CLOCK_SIMULATED)

ZTEST(can_virtual, test_arbitration_order)
{
	static const uint32_t expected[][2] = {
		/* id, flags: lowest arbitration field first; equal fields in queue order */
		{0x050, 0}, {0x100, 0}, {0x100, CAN_FRAME_RTR}, {0x100U << 18, CAN_FRAME_IDE},
		{0x180, 0}, {0x300, 0}, /* from c0, queued first */
		{0x300, 0},             /* from c1 */
	};
	struct rx_rec *got[16];
	int n;

	queue(0, &(struct can_frame){.id = 0x300, .dlc = 1, .data = {0}});
	queue(0, &(struct can_frame){.id = 0x180, .dlc = 0});
	queue(1, &(struct can_frame){.id = 0x100, .flags = CAN_FRAME_RTR, .dlc = 0});
	queue(1, &(struct can_frame){.id = 0x300, .dlc = 1, .data = {1}});
	queue(1, &(struct can_frame){.id = 0x100U << 18, .flags = CAN_FRAME_IDE, .dlc = 0});
	queue(1, &(struct can_frame){.id = 0x100, .dlc = 0});
	queue(1, &(struct can_frame){.id = 0x050, .dlc = 0});
	zassert_equal(n_rx, 0, "delivered before the clock moved");

	zassert_equal(can_virtual_sim_run(100), 7);
	n = rx_of(2, got, ARRAY_SIZE(got));
	zassert_equal(n, 7);
	for (int i = 0; i < n; i++) {
		zassert_equal(got[i]->frame.id, expected[i][0], "position %d: 0x%x", i,
			      got[i]->frame.id);
		zassert_equal(got[i]->frame.flags, expected[i][1], "position %d", i);
	}
	zassert_equal(got[5]->frame.data[0], 0);
	zassert_equal(got[6]->frame.data[0], 1);
	zassert_equal(n_tx, 7);
}

ZTEST(can_virtual, test_bit_timing_and_timestamps)
{
	const struct can_frame f = frame_of(0x181, 0, 8, (const uint8_t[]){0, 0, 0, 0, 0, 0, 0, 0});
	const uint64_t len_ns = (uint64_t)can_virtual_frame_bits(&f) * BIT_NS;
	struct can_virtual_bus_stats s0;
	struct can_virtual_bus_stats s1;
	struct rx_rec *got[16];
	uint64_t t0;

	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	zassert_ok(can_virtual_bus_get_stats(0, &s0));
	zassert_equal(len_ns % 1000U, 0U, "choose a frame that ends on a microsecond");
	t0 = can_virtual_time_us();
	queue(0, &f);
	zassert_equal(can_virtual_sim_advance(len_ns / 1000U - 1U), 0);
	zassert_equal(n_rx, 0, "frame delivered before its last bit");
	zassert_equal(can_virtual_sim_advance(1), 1);
	zassert_equal(rx_of(2, got, 16), 1);
	zassert_equal(got[0]->t_us, t0 + len_ns / 1000U);
	zassert_equal(got[0]->frame.timestamp, (uint16_t)(t0 + len_ns / 1000U));

	/* back to back: each frame ends one frame length after the previous */
	n_rx = 0;
	n_tx = 0;
	t0 = can_virtual_time_us();
	for (int i = 0; i < CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE; i++) {
		queue(0, &f);
	}
	zassert_equal(can_virtual_sim_run(100), CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE);
	zassert_equal(n_tx, CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE);
	for (int i = 0; i < n_tx; i++) {
		zassert_equal(tx_log[i].t_us, t0 + (i + 1) * len_ns / 1000U, "frame %d", i);
	}
	zassert_ok(can_virtual_bus_get_stats(0, &s1));
	zassert_equal(s1.busy_ns - s0.busy_ns, (CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE + 1) * len_ns);
}

ZTEST(can_virtual, test_no_bit_timing_is_instant)
{
	const uint64_t t0 = can_virtual_time_us();

	queue(0, &(struct can_frame){.id = 0x10, .dlc = 0});
	zassert_equal(can_virtual_sim_advance(0), 1);
	zassert_equal(n_tx, 1);
	zassert_equal(tx_log[0].t_us, t0);
}

ZTEST(can_virtual, test_drop_frames)
{
	const struct can_filter flt = {.id = 0x181, .mask = CAN_STD_ID_MASK};
	struct can_virtual_bus_stats s0;
	struct can_virtual_bus_stats s1;
	struct rx_rec *got[16];

	zassert_ok(can_virtual_bus_get_stats(0, &s0));
	zassert_ok(can_virtual_drop_frames(0, &flt, 2));
	for (uint8_t i = 0; i < 3; i++) {
		queue(0, &(struct can_frame){.id = 0x181, .dlc = 1, .data = {i}});
	}
	queue(0, &(struct can_frame){.id = 0x182, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 4);

	zassert_equal(rx_of(2, got, 16), 2);
	zassert_equal(got[0]->frame.id, 0x181);
	zassert_equal(got[0]->frame.data[0], 2, "the third 0x181 is the first to arrive");
	zassert_equal(got[1]->frame.id, 0x182);
	zassert_equal(rx_of(1, got, 16), 2, "a dropped frame is lost for every receiver");
	zassert_equal(n_tx, 4);
	for (int i = 0; i < n_tx; i++) {
		zassert_equal(tx_log[i].error, 0, "the sender does not notice");
	}
	zassert_ok(can_virtual_bus_get_stats(0, &s1));
	zassert_equal(s1.dropped - s0.dropped, 2);
}

ZTEST(can_virtual, test_corrupt_frames)
{
	const struct can_filter flt = {.id = 0x1A0, .mask = CAN_STD_ID_MASK};
	static const uint8_t mask[CAN_MAX_DLEN] = {0xFF, 0x00, 0x01};
	struct rx_rec *got[16];

	zassert_ok(can_virtual_corrupt_frames(0, &flt, 1, mask));
	queue(0, &(struct can_frame){.id = 0x1A0, .dlc = 3, .data = {0x11, 0x22, 0x33}});
	queue(0, &(struct can_frame){.id = 0x1A0, .dlc = 3, .data = {0x11, 0x22, 0x33}});
	zassert_equal(can_virtual_sim_run(100), 2);
	zassert_equal(rx_of(2, got, 16), 2);
	zassert_mem_equal(got[0]->frame.data, ((uint8_t[]){0xEE, 0x22, 0x32}), 3);
	zassert_mem_equal(got[1]->frame.data, ((uint8_t[]){0x11, 0x22, 0x33}), 3);
}

ZTEST(can_virtual, test_clear_faults)
{
	const struct can_filter all = {.id = 0, .mask = 0};

	zassert_ok(can_virtual_drop_frames(0, &all, 100));
	queue(0, &(struct can_frame){.id = 0x1, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(n_rx, 0);
	zassert_ok(can_virtual_clear_faults(0));
	queue(0, &(struct can_frame){.id = 0x2, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(n_rx, 2, "c1 and c2 receive once the fault is cleared");
}

ZTEST(can_virtual, test_cut_receiver)
{
	struct rx_rec *got[16];

	zassert_ok(can_virtual_cut(c[2]));
	queue(0, &(struct can_frame){.id = 0x11, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(1, got, 16), 1, "the frame was on the bus");
	zassert_equal(rx_of(2, got, 16), 0, "but the cut controller did not get it");
	zassert_equal(n_states, 0, "a receiver does not notice a cut");

	zassert_ok(can_virtual_restore(c[2]));
	queue(0, &(struct can_frame){.id = 0x12, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(2, got, 16), 1);
	zassert_equal(got[0]->frame.id, 0x12);
}

ZTEST(can_virtual, test_cut_sender)
{
	struct rx_rec *got[16];

	zassert_ok(can_virtual_cut(c[0]));
	queue(0, &(struct can_frame){.id = 0x21, .dlc = 0});
	zassert_equal(n_states, 1);
	zassert_equal(states[0], CAN_STATE_ERROR_PASSIVE, "no ACK makes the sender passive");
	zassert_true(state_cnt[0].tx_err_cnt >= 128U);
	zassert_equal(can_virtual_sim_advance(10000), 0);
	zassert_equal(n_rx, 0);
	zassert_equal(n_tx, 0, "an unacknowledged frame does not complete");

	zassert_ok(can_virtual_restore(c[0]));
	zassert_equal(n_states, 2);
	zassert_equal(states[1], CAN_STATE_ERROR_ACTIVE);
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(2, got, 16), 1);
	zassert_equal(n_tx, 1);
	zassert_equal(tx_log[0].error, 0);
}

ZTEST(can_virtual, test_latency)
{
	struct rx_rec *got[16];
	uint64_t t0 = can_virtual_time_us();

	zassert_ok(can_virtual_set_latency(c[2], 500));
	queue(0, &(struct can_frame){.id = 0x31, .dlc = 0});
	queue(0, &(struct can_frame){.id = 0x32, .dlc = 0});
	zassert_equal(can_virtual_sim_advance(0), 2);
	zassert_equal(rx_of(1, got, 16), 2, "others get the frames at once");
	zassert_equal(rx_of(2, got, 16), 0);
	zassert_equal(can_virtual_sim_advance(499), 0);
	zassert_equal(rx_of(2, got, 16), 0);
	can_virtual_sim_advance(1);
	zassert_equal(rx_of(2, got, 16), 2);
	zassert_equal(got[0]->frame.id, 0x31, "order is kept");
	zassert_equal(got[1]->frame.id, 0x32);
	zassert_equal(got[0]->t_us, t0 + 500);
	zassert_equal(got[0]->frame.timestamp, (uint16_t)(t0 + 500));
}

ZTEST(can_virtual, test_delay_frames)
{
	const struct can_filter flt = {.id = 0x41, .mask = CAN_STD_ID_MASK};
	struct can_virtual_bus_stats s0;
	struct can_virtual_bus_stats s1;
	struct rx_rec *got[16];
	uint64_t t0 = can_virtual_time_us();

	zassert_equal(can_virtual_delay_frames(0, &flt, 1, 0), -EINVAL, "a delay of 0");
	zassert_equal(can_virtual_delay_frames(0, &flt, 0, 300), -EINVAL, "a count of 0");
	zassert_equal(can_virtual_delay_frames(2, &flt, 1, 300), -EINVAL, "no bus 2");
	zassert_equal(can_virtual_delay_frames(0, NULL, 1, 300), -EINVAL);
	zassert_ok(can_virtual_bus_get_stats(0, &s0));
	zassert_ok(can_virtual_set_latency(c[2], 100));
	zassert_ok(can_virtual_delay_frames(0, &flt, 1, 300));
	queue(0, &(struct can_frame){.id = 0x41, .dlc = 1, .data = {1}});
	queue(0, &(struct can_frame){.id = 0x41, .dlc = 1, .data = {2}});
	zassert_equal(can_virtual_sim_advance(0), 2);
	zassert_equal(n_tx, 2, "the sender completes at the end of the frame");
	zassert_equal(tx_log[0].t_us, t0);
	zassert_equal(rx_of(1, got, 16), 1, "the second frame overtakes the delayed one");
	zassert_equal(got[0]->frame.data[0], 2);

	zassert_equal(can_virtual_sim_advance(100), 0);
	zassert_equal(rx_of(2, got, 16), 1, "c2: the undelayed frame after its own latency");
	zassert_equal(got[0]->frame.data[0], 2);
	zassert_equal(can_virtual_sim_advance(199), 0);
	zassert_equal(rx_of(1, got, 16), 1, "not yet");
	can_virtual_sim_advance(1);
	zassert_equal(rx_of(1, got, 16), 2);
	zassert_equal(got[1]->frame.data[0], 1);
	zassert_equal(got[1]->t_us, t0 + 300);
	zassert_equal(got[1]->frame.timestamp, (uint16_t)(t0 + 300), "stamped when delivered");
	zassert_equal(rx_of(2, got, 16), 1, "c2 adds its latency of 100 us");
	can_virtual_sim_advance(100);
	zassert_equal(rx_of(2, got, 16), 2);
	zassert_equal(got[1]->frame.data[0], 1);
	zassert_equal(got[1]->t_us, t0 + 400);

	/* Used up: the next frame is on time. Unused delays go with the other faults. */
	zassert_ok(can_virtual_set_latency(c[2], 0));
	queue(0, &(struct can_frame){.id = 0x41, .dlc = 1, .data = {3}});
	zassert_equal(can_virtual_sim_advance(0), 1);
	zassert_equal(rx_of(1, got, 16), 3);
	zassert_ok(can_virtual_delay_frames(0, &flt, 5, 300));
	zassert_ok(can_virtual_clear_faults(0));
	queue(0, &(struct can_frame){.id = 0x41, .dlc = 1, .data = {4}});
	zassert_equal(can_virtual_sim_advance(0), 1);
	zassert_equal(rx_of(1, got, 16), 4);
	zassert_ok(can_virtual_bus_get_stats(0, &s1));
	zassert_equal(s1.delayed - s0.delayed, 1);
}

ZTEST(can_virtual, test_error_warning_and_passive)
{
	struct can_bus_err_cnt cnt;
	enum can_state state;

	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_ERROR_WARNING));
	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_ERROR_PASSIVE));
	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_ERROR_PASSIVE));
	zassert_equal(n_states, 2, "a repeated state is not a change");
	zassert_equal(states[0], CAN_STATE_ERROR_WARNING);
	zassert_true(state_cnt[0].tx_err_cnt >= 96U && state_cnt[0].tx_err_cnt < 128U);
	zassert_equal(states[1], CAN_STATE_ERROR_PASSIVE);
	zassert_ok(can_get_state(c[0], &state, &cnt));
	zassert_equal(state, CAN_STATE_ERROR_PASSIVE);
	zassert_true(cnt.tx_err_cnt >= 128U);

	/* a passive controller still sends and receives */
	queue(0, &(struct can_frame){.id = 0x41, .dlc = 0});
	queue(1, &(struct can_frame){.id = 0x42, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 2);
	zassert_equal(n_tx, 2);

	zassert_equal(can_virtual_set_state(c[0], CAN_STATE_STOPPED), -EINVAL);
	zassert_ok(can_stop(c[0]));
	zassert_equal(can_virtual_set_state(c[0], CAN_STATE_ERROR_PASSIVE), -ENETDOWN);
}

ZTEST(can_virtual, test_bus_off_automatic_recovery)
{
	const uint64_t recovery_us = 128U * 11U * BIT_NS / 1000U;
	struct rx_rec *got[16];

	queue(0, &(struct can_frame){.id = 0x51, .dlc = 0});
	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_BUS_OFF));
	zassert_equal(n_tx, 1);
	zassert_equal(tx_log[0].error, -ENETUNREACH, "bus-off aborts pending frames");
	zassert_equal(can_send(c[0], &(struct can_frame){.id = 0x52}, K_NO_WAIT, NULL, NULL),
		      -ENETUNREACH);
	/* a bus-off controller does not receive either */
	queue(1, &(struct can_frame){.id = 0x53, .dlc = 0});
	zassert_equal(can_virtual_sim_advance(recovery_us - 1U), 1);
	zassert_equal(rx_of(0, got, 16), 0);
	zassert_equal(n_states, 1);
	zassert_equal(states[0], CAN_STATE_BUS_OFF);

	can_virtual_sim_advance(1);
	zassert_equal(n_states, 2, "recovered after 128 x 11 bit times");
	zassert_equal(states[1], CAN_STATE_ERROR_ACTIVE);
	zassert_equal(state_cnt[1].tx_err_cnt, 0);
	queue(0, &(struct can_frame){.id = 0x54, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
}

ZTEST(can_virtual, test_bus_off_manual_recovery)
{
	const uint64_t recovery_us = 128U * 11U * BIT_NS / 1000U;

	zassert_ok(can_stop(c[0]));
	zassert_ok(can_set_mode(c[0], CAN_MODE_MANUAL_RECOVERY));
	zassert_ok(can_start(c[0]));
	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_BUS_OFF));
	can_virtual_sim_advance(100000);
	zassert_equal(n_states, 1, "no automatic recovery");
	zassert_equal(can_recover(c[0], K_NO_WAIT), -EAGAIN);
	can_virtual_sim_advance(recovery_us - 1U);
	zassert_equal(n_states, 1);
	can_virtual_sim_advance(1);
	zassert_equal(n_states, 2);
	zassert_equal(states[1], CAN_STATE_ERROR_ACTIVE);
	zassert_equal(can_recover(c[0], K_NO_WAIT), 0);
}

ZTEST(can_virtual, test_stop_aborts_pending)
{
	queue(0, &(struct can_frame){.id = 0x61, .dlc = 0});
	queue(0, &(struct can_frame){.id = 0x62, .dlc = 0});
	zassert_ok(can_stop(c[0]));
	zassert_equal(n_tx, 2);
	zassert_equal(tx_log[0].error, -ENETDOWN);
	zassert_equal(tx_log[1].error, -ENETDOWN);
	zassert_equal(can_virtual_sim_run(100), 0);
	zassert_equal(n_rx, 0);
}

ZTEST(can_virtual, test_tx_queue_full)
{
	const struct can_frame f = {.id = 0x71, .dlc = 0};

	for (int i = 0; i < CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE; i++) {
		queue(0, &f);
	}
	zassert_equal(can_send(c[0], &f, K_NO_WAIT, tx_cb, NULL), -EAGAIN);
	zassert_equal(can_send(c[0], &f, K_MSEC(5), tx_cb, NULL), -EAGAIN);
	zassert_equal(can_virtual_sim_run(100), CONFIG_CAN_VIRTUAL_TX_QUEUE_SIZE);
	queue(0, &f);
}

ZTEST(can_virtual, test_buses_are_separate)
{
	struct rx_rec *got[16];

	queue(0, &(struct can_frame){.id = 0x81, .dlc = 0});
	queue(3, &(struct can_frame){.id = 0x82, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 2);
	zassert_equal(rx_of(3, got, 16), 0, "bus 1 does not hear bus 0");
	zassert_equal(rx_of(2, got, 16), 1);
	zassert_equal(got[0]->frame.id, 0x81);

	zassert_equal(can_virtual_set_bus(c[3], 0), -EBUSY);
	zassert_ok(can_stop(c[3]));
	zassert_ok(can_virtual_set_bus(c[3], 0));
	zassert_equal(can_virtual_get_bus(c[3]), 0);
	zassert_ok(can_start(c[3]));
	queue(0, &(struct can_frame){.id = 0x83, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(3, got, 16), 1);
	zassert_equal(got[0]->frame.id, 0x83);
	zassert_equal(can_virtual_set_bus(c[3], 2), -EINVAL);
}

ZTEST(can_virtual, test_bit_rate_mismatch)
{
	struct rx_rec *got[16];

	zassert_ok(can_stop(c[2]));
	zassert_ok(can_set_bitrate(c[2], 250000));
	zassert_ok(can_start(c[2]));
	queue(0, &(struct can_frame){.id = 0x91, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(1, got, 16), 1);
	zassert_equal(rx_of(2, got, 16), 0, "a controller at another bit rate hears nothing");
	zassert_equal(can_set_bitrate(c[2], 2000000), -ENOTSUP);
}

ZTEST(can_virtual, test_listen_only)
{
	struct rx_rec *got[16];

	zassert_ok(can_stop(c[2]));
	zassert_ok(can_set_mode(c[2], CAN_MODE_LISTENONLY));
	zassert_ok(can_start(c[2]));
	zassert_equal(can_send(c[2], &(struct can_frame){.id = 0x1}, K_NO_WAIT, NULL, NULL), -EIO);
	queue(0, &(struct can_frame){.id = 0xA1, .dlc = 0});
	zassert_equal(can_virtual_sim_run(100), 1);
	zassert_equal(rx_of(2, got, 16), 1);
}

/* A busy mixed scenario; returns a digest of who received what when. */
static uint32_t scenario_digest(void)
{
	uint64_t t0 = can_virtual_time_us();
	uint32_t h = 2166136261U;

	n_rx = 0;
	n_tx = 0;
	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	zassert_ok(can_virtual_set_latency(c[1], 37));
	for (int round = 0; round < 5; round++) {
		queue(round % 3, &(struct can_frame){.id = 0x700 - round * 0x101,
						     .dlc = 2,
						     .data = {(uint8_t)round, 0xA5}});
		queue((round + 1) % 3, &(struct can_frame){.id = 0x80 + round, .dlc = 0});
		can_virtual_sim_advance(100 + round * 37);
	}
	can_virtual_sim_run(100);
	for (int i = 0; i < n_rx; i++) {
		const uint32_t words[] = {(uint32_t)rx_log[i].ctrl, (uint32_t)(rx_log[i].t_us - t0),
					  rx_log[i].frame.id, rx_log[i].frame.data[0]};

		for (size_t k = 0; k < ARRAY_SIZE(words); k++) {
			h = (h ^ words[k]) * 16777619U;
		}
	}
	zassert_equal(n_rx, 20, "every frame reaches the two other controllers");

	return h;
}

ZTEST(can_virtual, test_simulation_is_deterministic)
{
	uint32_t first = scenario_digest();

	after(NULL);
	before(NULL);
	zassert_equal(scenario_digest(), first);
}

#else /* CONFIG_CAN_VIRTUAL_CLOCK_REALTIME */

static struct k_sem done_sem;

static void done_cb(const struct device *dev, int error, void *user_data)
{
	k_sem_give(&done_sem);
}

ZTEST(can_virtual, test_realtime_respects_the_physical_limit)
{
	const int n = 100;
	const struct can_frame f = frame_of(0x181, 0, 8, (const uint8_t[]){1, 2, 3, 4, 5, 6, 7, 8});
	const uint64_t bits = can_virtual_frame_bits(&f);
	int64_t t0;
	int64_t elapsed_us;

	zassert_ok(can_stop(c[0]));
	zassert_ok(can_stop(c[2]));
	zassert_ok(can_set_bitrate(c[0], 1000000));
	zassert_ok(can_set_bitrate(c[2], 1000000));
	zassert_ok(can_start(c[0]));
	zassert_ok(can_start(c[2]));
	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	k_sem_init(&done_sem, 0, n);

	t0 = k_uptime_ticks();
	for (int i = 0; i < n; i++) {
		zassert_ok(can_send(c[0], &f, K_FOREVER, done_cb, NULL));
	}
	for (int i = 0; i < n; i++) {
		zassert_ok(k_sem_take(&done_sem, K_SECONDS(10)));
	}
	elapsed_us = (int64_t)k_ticks_to_us_floor64((uint64_t)(k_uptime_ticks() - t0));
	/* 1 bit = 1 us at 1 Mbit/s: never faster than the wire */
	zassert_true(elapsed_us >= (int64_t)(n * bits) - 10, "%d frames of %u bits in %lld us", n,
		     (unsigned int)bits, (long long)elapsed_us);
	zassert_equal(can_virtual_sim_advance(1), -ENOTSUP);
	zassert_equal(can_virtual_sim_run(1), -ENOTSUP);
}

ZTEST(can_virtual, test_realtime_delay_frames)
{
	const struct can_filter flt = {.id = 0x42, .mask = CAN_STD_ID_MASK};
	struct rx_rec *got[16];
	uint64_t t0;

	zassert_ok(can_virtual_delay_frames(0, &flt, 1, 20000));
	k_sem_init(&done_sem, 0, 2);
	t0 = can_virtual_time_us();
	zassert_ok(can_send(c[0], &(struct can_frame){.id = 0x42, .dlc = 1, .data = {1}}, K_FOREVER,
			    done_cb, NULL));
	zassert_ok(can_send(c[0], &(struct can_frame){.id = 0x43, .dlc = 1, .data = {2}}, K_FOREVER,
			    done_cb, NULL));
	zassert_ok(k_sem_take(&done_sem, K_SECONDS(10)));
	zassert_ok(k_sem_take(&done_sem, K_SECONDS(10)));
	for (int i = 0; i < 300 && rx_of(1, got, 16) < 2; i++) {
		k_msleep(1);
	}
	zassert_equal(rx_of(1, got, 16), 2);
	zassert_equal(got[0]->frame.id, 0x43, "the undelayed frame first");
	zassert_equal(got[1]->frame.id, 0x42);
	zassert_true(got[0]->t_us - t0 < 20000U, "0x43 on time (%u us)",
		     (unsigned int)(got[0]->t_us - t0));
	zassert_true(got[1]->t_us - t0 >= 20000U, "0x42 held back 20 ms (%u us)",
		     (unsigned int)(got[1]->t_us - t0));
	zassert_true((uint16_t)(got[1]->frame.timestamp - (uint16_t)t0) >= 20000U,
		     "stamped when delivered");
}

ZTEST(can_virtual, test_realtime_bus_off_recovers)
{
	zassert_ok(can_virtual_set_state(c[0], CAN_STATE_BUS_OFF));
	for (int i = 0; i < 100 && n_states < 2; i++) {
		k_msleep(10);
	}
	zassert_equal(n_states, 2);
	zassert_equal(states[0], CAN_STATE_BUS_OFF);
	zassert_equal(states[1], CAN_STATE_ERROR_ACTIVE);
}

/* A state callback that holds the first change it gets until the test lets it go. */
static K_SEM_DEFINE(held_cb_entered, 0, 1);
static K_SEM_DEFINE(held_cb_release, 0, 1);

static void holding_state_cb(const struct device *dev, enum can_state state,
			     struct can_bus_err_cnt cnt, void *user_data)
{
	state_cb(dev, state, cnt, user_data);
	if (n_states == 1) {
		k_sem_give(&held_cb_entered);
		(void)k_sem_take(&held_cb_release, K_SECONDS(5));
	}
}

static void set_state_thread(void *p1, void *p2, void *p3)
{
	(void)can_virtual_set_state(c[0], (enum can_state)(intptr_t)p1);
}

static K_THREAD_STACK_ARRAY_DEFINE(setter_stacks, 2, 4096);
static struct k_thread setters[2];

/*
 * Three changes that race for the callback: error passive (its callback still running), a
 * bus-off injected by another thread, and the bus thread's automatic recovery 1 408 bit times
 * later. The callback must see them in the order they happened: a recovery reported before
 * its bus-off would leave a CANopen line believing it is still bus-off.
 */
ZTEST(can_virtual, test_realtime_state_changes_arrive_in_order)
{
	can_set_state_change_callback(c[0], holding_state_cb, NULL);
	k_sem_reset(&held_cb_entered);
	k_sem_reset(&held_cb_release);
	k_thread_create(&setters[0], setter_stacks[0], K_THREAD_STACK_SIZEOF(setter_stacks[0]),
			set_state_thread, (void *)(intptr_t)CAN_STATE_ERROR_PASSIVE, NULL, NULL, 0,
			0, K_NO_WAIT);
	zassert_ok(k_sem_take(&held_cb_entered, K_SECONDS(5)));

	k_thread_create(&setters[1], setter_stacks[1], K_THREAD_STACK_SIZEOF(setter_stacks[1]),
			set_state_thread, (void *)(intptr_t)CAN_STATE_BUS_OFF, NULL, NULL, 0, 0,
			K_NO_WAIT);
	/* Wait for the bus-off and then for the recovery that ends it (both not reported yet). */
	enum can_state now = CAN_STATE_ERROR_PASSIVE;

	for (int i = 0; i < 500 && now != CAN_STATE_BUS_OFF; i++) {
		zassert_ok(can_get_state(c[0], &now, NULL));
		k_usleep(100);
	}
	zassert_equal(now, CAN_STATE_BUS_OFF, "the bus-off was injected");
	for (int i = 0; i < 500 && now != CAN_STATE_ERROR_ACTIVE; i++) {
		k_msleep(1);
		zassert_ok(can_get_state(c[0], &now, NULL));
	}
	zassert_equal(now, CAN_STATE_ERROR_ACTIVE, "the bus-off recovered by itself");
	zassert_equal(n_states, 1, "only the first change has reached the callback");

	k_sem_give(&held_cb_release);
	zassert_ok(k_thread_join(&setters[0], K_SECONDS(5)));
	zassert_ok(k_thread_join(&setters[1], K_SECONDS(5)));
	zassert_equal(n_states, 3, "every change is reported (%d)", n_states);
	zassert_equal(states[0], CAN_STATE_ERROR_PASSIVE);
	zassert_equal(states[1], CAN_STATE_BUS_OFF);
	zassert_equal(states[2], CAN_STATE_ERROR_ACTIVE);
}

static K_THREAD_STACK_ARRAY_DEFINE(queue_setter_stacks, 5, 4096);
static struct k_thread queue_setters[5];

/*
 * Five changes while the callback holds the first one: the queue keeps four, and the fifth
 * takes the place of the newest, so the state the controller ends in is still the last one
 * the callback sees (doc/can-virtual.md).
 */
ZTEST(can_virtual, test_realtime_full_state_queue_keeps_the_last_state)
{
	static const enum can_state seq[5] = {CAN_STATE_ERROR_PASSIVE, CAN_STATE_ERROR_ACTIVE,
					      CAN_STATE_ERROR_WARNING, CAN_STATE_ERROR_PASSIVE,
					      CAN_STATE_ERROR_ACTIVE};
	enum can_state now;

	can_set_state_change_callback(c[0], holding_state_cb, NULL);
	k_sem_reset(&held_cb_entered);
	k_sem_reset(&held_cb_release);
	k_thread_create(&setters[0], setter_stacks[0], K_THREAD_STACK_SIZEOF(setter_stacks[0]),
			set_state_thread, (void *)(intptr_t)CAN_STATE_ERROR_WARNING, NULL, NULL, 0,
			0, K_NO_WAIT);
	zassert_ok(k_sem_take(&held_cb_entered, K_SECONDS(5)));

	/* One thread per change (each waits for the callback); each change made before the next. */
	for (int k = 0; k < 5; k++) {
		k_thread_create(&queue_setters[k], queue_setter_stacks[k],
				K_THREAD_STACK_SIZEOF(queue_setter_stacks[k]), set_state_thread,
				(void *)(intptr_t)seq[k], NULL, NULL, 0, 0, K_NO_WAIT);
		now = CAN_STATE_STOPPED;
		for (int i = 0; i < 500 && now != seq[k]; i++) {
			k_usleep(100);
			zassert_ok(can_get_state(c[0], &now, NULL));
		}
		zassert_equal(now, seq[k], "change %d made", k);
	}
	zassert_equal(n_states, 1, "only the first change has reached the callback");

	k_sem_give(&held_cb_release);
	zassert_ok(k_thread_join(&setters[0], K_SECONDS(5)));
	for (int k = 0; k < 5; k++) {
		zassert_ok(k_thread_join(&queue_setters[k], K_SECONDS(5)));
	}
	zassert_equal(n_states, 5, "the first change and the four queued (%d)", n_states);
	zassert_equal(states[0], CAN_STATE_ERROR_WARNING);
	zassert_equal(states[1], CAN_STATE_ERROR_PASSIVE);
	zassert_equal(states[2], CAN_STATE_ERROR_ACTIVE);
	zassert_equal(states[3], CAN_STATE_ERROR_WARNING);
	zassert_equal(states[4], CAN_STATE_ERROR_ACTIVE, "the fifth replaced the newest");
	zassert_equal(state_cnt[4].tx_err_cnt, 0, "with its own error counters");
}

#endif
