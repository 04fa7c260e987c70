/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * CAN API conformance: the same tests against each native_posix driver. The device under test
 * (dut) sends to and receives from a peer controller on the same bus.
 *
 * "Must not receive" checks never wait for silence: a sentinel frame follows, and since a bus
 * delivers in order, anything wrongly received would arrive before the sentinel.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#if defined(CONFIG_CAN_VIRTUAL)
#include <can_virtual.h>
#define DUT_NAME  "can_virtual0"
#define PEER_NAME "can_virtual1"
#else
#include <can_socketcan.h>
#define DUT_NAME  "can_socketcan0"
#define PEER_NAME "can_socketcan1"
#endif

/* Generous: inside the vcan VM every system call is slow. */
#define WAIT        K_SECONDS(5)
#define SENTINEL_ID 0x7F0U

static const struct device *dut;
static const struct device *peer;

CAN_MSGQ_DEFINE(peer_rxq, 32);
CAN_MSGQ_DEFINE(dut_rxq, 32);
K_MSGQ_DEFINE(state_q, sizeof(enum can_state), 8, 4);

static struct {
	const struct device *dev;
	int id;
} filters[64];
static int n_filters;

static int add_filter_msgq(const struct device *dev, struct k_msgq *q, uint32_t id, uint32_t mask,
			   uint8_t flags)
{
	const struct can_filter f = {.id = id, .mask = mask, .flags = flags};
	int fid = can_add_rx_filter_msgq(dev, q, &f);

	zassert_true(fid >= 0, "can_add_rx_filter_msgq: %d", fid);
	zassert_true(n_filters < (int)ARRAY_SIZE(filters));
	filters[n_filters].dev = dev;
	filters[n_filters].id = fid;
	n_filters++;

	return fid;
}

static struct can_frame frame_of(uint32_t id, uint8_t flags, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .flags = flags, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}

	return f;
}

static void send_ok(const struct device *dev, const struct can_frame *f)
{
	int rc = can_send(dev, f, WAIT, NULL, NULL);

	zassert_equal(rc, 0, "can_send(0x%x): %d", f->id, rc);
}

static void send_sentinel(const struct device *dev)
{
	const struct can_frame f = frame_of(SENTINEL_ID, 0, 1, (const uint8_t[]){0x5A});

	send_ok(dev, &f);
}

static void expect_frame(struct k_msgq *q, const struct can_frame *exp)
{
	struct can_frame got;

	zassert_equal(k_msgq_get(q, &got, WAIT), 0, "frame 0x%x not received", exp->id);
	zassert_equal(got.id, exp->id, "id 0x%x, expected 0x%x", got.id, exp->id);
	zassert_equal(got.dlc, exp->dlc, "dlc %u, expected %u", got.dlc, exp->dlc);
	zassert_equal(got.flags & (CAN_FRAME_IDE | CAN_FRAME_RTR),
		      exp->flags & (CAN_FRAME_IDE | CAN_FRAME_RTR), "flags 0x%x, expected 0x%x",
		      got.flags, exp->flags);
	if ((exp->flags & CAN_FRAME_RTR) == 0U) {
		zassert_mem_equal(got.data, exp->data, exp->dlc, "data differs (id 0x%x)", exp->id);
	}
}

static void expect_sentinel(struct k_msgq *q)
{
	const struct can_frame s = frame_of(SENTINEL_ID, 0, 1, (const uint8_t[]){0x5A});

	expect_frame(q, &s);
}

static void state_cb(const struct device *dev, enum can_state state, struct can_bus_err_cnt cnt,
		     void *user_data)
{
	zassert_equal_ptr(user_data, &state_q);
	(void)k_msgq_put(&state_q, &state, K_NO_WAIT);
}

static void expect_state(enum can_state exp)
{
	enum can_state got;
	enum can_state now;

	zassert_equal(k_msgq_get(&state_q, &got, WAIT), 0, "no state change to %d", exp);
	zassert_equal(got, exp, "state change to %d, expected %d", got, exp);
	zassert_ok(can_get_state(dut, &now, NULL));
	zassert_equal(now, exp, "can_get_state: %d, expected %d", now, exp);
}

/* Make the controller announce @p state, the way its hardware would. */
static void inject_state(const struct device *dev, enum can_state state)
{
#if defined(CONFIG_CAN_VIRTUAL)
	zassert_ok(can_virtual_set_state(dev, state));
#else
	zassert_ok(can_socketcan_inject_state(dev, state));
#endif
}

static void *suite_setup(void)
{
	dut = device_get_binding(DUT_NAME);
	peer = device_get_binding(PEER_NAME);
	zassert_not_null(dut, DUT_NAME " is not ready");
	zassert_not_null(peer, PEER_NAME " is not ready");

	return NULL;
}

static void restart(const struct device *dev, can_mode_t mode)
{
	int rc = can_stop(dev);

	zassert_true(rc == 0 || rc == -EALREADY, "can_stop: %d", rc);
	zassert_ok(can_set_mode(dev, mode));
	zassert_ok(can_start(dev));
}

static void before(void *fixture)
{
	can_set_state_change_callback(dut, NULL, NULL);
	restart(dut, CAN_MODE_NORMAL);
	restart(peer, CAN_MODE_NORMAL);
	k_msgq_purge(&peer_rxq);
	k_msgq_purge(&dut_rxq);
	k_msgq_purge(&state_q);
	n_filters = 0;
	add_filter_msgq(peer, &peer_rxq, SENTINEL_ID, CAN_STD_ID_MASK, 0);
}

static void after(void *fixture)
{
	can_set_state_change_callback(dut, NULL, NULL);
	for (int i = 0; i < n_filters; i++) {
		can_remove_rx_filter(filters[i].dev, filters[i].id);
	}
	n_filters = 0;
}

ZTEST_SUITE(can_api, NULL, suite_setup, before, after, NULL);

ZTEST(can_api, test_device_binding)
{
	zassert_equal_ptr(device_get_binding(DUT_NAME), dut);
	zassert_is_null(device_get_binding("no_such_device"));
	zassert_false(device_is_ready(NULL));
	zassert_true(device_is_ready(dut));
}

ZTEST(can_api, test_send_receive_standard)
{
	const struct can_frame f =
		frame_of(0x123, 0, 8, (const uint8_t[]){0xDE, 0xAD, 0xBE, 0xEF, 1, 2, 3, 4});

	add_filter_msgq(peer, &peer_rxq, 0x123, CAN_STD_ID_MASK, 0);
	send_ok(dut, &f);
	expect_frame(&peer_rxq, &f);
}

ZTEST(can_api, test_send_receive_extended)
{
	const struct can_frame f =
		frame_of(0x1ABCDEF0, CAN_FRAME_IDE, 3, (const uint8_t[]){0x11, 0x22, 0x33});

	add_filter_msgq(peer, &peer_rxq, 0x1ABCDEF0, CAN_EXT_ID_MASK, CAN_FILTER_IDE);
	send_ok(dut, &f);
	expect_frame(&peer_rxq, &f);
}

ZTEST(can_api, test_every_dlc)
{
	static const uint8_t payload[8] = {0x01, 0x80, 0xFF, 0x00, 0x55, 0xAA, 0x7E, 0x81};

	add_filter_msgq(peer, &peer_rxq, 0x200, 0x7F0, 0);
	for (uint8_t dlc = 0; dlc <= CAN_MAX_DLC; dlc++) {
		const struct can_frame f = frame_of(0x200 + dlc, 0, dlc, payload);

		send_ok(dut, &f);
		expect_frame(&peer_rxq, &f);
	}
}

ZTEST(can_api, test_filter_mask_standard)
{
	const struct can_frame in1 = frame_of(0x125, 0, 1, (const uint8_t[]){1});
	const struct can_frame out = frame_of(0x135, 0, 1, (const uint8_t[]){2});
	const struct can_frame in2 = frame_of(0x12F, 0, 1, (const uint8_t[]){3});

	/* id 0x120, mask 0x7F0: 0x120..0x12F match */
	add_filter_msgq(peer, &peer_rxq, 0x120, 0x7F0, 0);
	send_ok(dut, &in1);
	send_ok(dut, &out);
	send_ok(dut, &in2);
	send_sentinel(dut);
	expect_frame(&peer_rxq, &in1);
	expect_frame(&peer_rxq, &in2);
	expect_sentinel(&peer_rxq);
}

ZTEST(can_api, test_filter_mask_extended)
{
	const struct can_frame in = frame_of(0x18DA00F1, CAN_FRAME_IDE, 2, (const uint8_t[]){1, 2});
	const struct can_frame out =
		frame_of(0x18DB00F1, CAN_FRAME_IDE, 2, (const uint8_t[]){3, 4});

	add_filter_msgq(peer, &peer_rxq, 0x18DA0000, 0x1FFF0000, CAN_FILTER_IDE);
	send_ok(dut, &out);
	send_ok(dut, &in);
	send_sentinel(dut);
	expect_frame(&peer_rxq, &in);
	expect_sentinel(&peer_rxq);
}

ZTEST(can_api, test_filter_identifier_type)
{
	const struct can_frame std = frame_of(0x100, 0, 1, (const uint8_t[]){0xA});
	const struct can_frame ext = frame_of(0x100, CAN_FRAME_IDE, 1, (const uint8_t[]){0xB});

	/* A standard filter ignores extended frames with the same number, and vice versa. */
	add_filter_msgq(peer, &peer_rxq, 0x100, CAN_STD_ID_MASK, 0);
	send_ok(dut, &ext);
	send_ok(dut, &std);
	send_sentinel(dut);
	expect_frame(&peer_rxq, &std);
	expect_sentinel(&peer_rxq);

	after(NULL);
	before(NULL);
	add_filter_msgq(peer, &peer_rxq, 0x100, CAN_EXT_ID_MASK, CAN_FILTER_IDE);
	send_ok(dut, &std);
	send_ok(dut, &ext);
	send_sentinel(dut);
	expect_frame(&peer_rxq, &ext);
	expect_sentinel(&peer_rxq);
}

ZTEST(can_api, test_remote_frames)
{
	const struct can_frame rtr = frame_of(0x321, CAN_FRAME_RTR, 4, NULL);
	const struct can_frame rtr_ext = frame_of(0x1321, CAN_FRAME_IDE | CAN_FRAME_RTR, 0, NULL);
	const struct can_frame data = frame_of(0x321, 0, 2, (const uint8_t[]){7, 8});

	/* Filters match data and remote frames alike; the RTR flag and DLC come through. */
	add_filter_msgq(peer, &peer_rxq, 0x321, CAN_STD_ID_MASK, 0);
	add_filter_msgq(peer, &peer_rxq, 0x1321, CAN_EXT_ID_MASK, CAN_FILTER_IDE);
	send_ok(dut, &rtr);
	send_ok(dut, &data);
	send_ok(dut, &rtr_ext);
	expect_frame(&peer_rxq, &rtr);
	expect_frame(&peer_rxq, &data);
	expect_frame(&peer_rxq, &rtr_ext);
}

static struct k_sem tx_sem;
static int tx_errors[8];
static int n_tx;

static void tx_cb(const struct device *dev, int error, void *user_data)
{
	int slot = (int)(intptr_t)user_data;

	zassert_equal_ptr(dev, dut);
	tx_errors[slot] = error;
	n_tx++;
	k_sem_give(&tx_sem);
}

ZTEST(can_api, test_tx_completion_callback)
{
	k_sem_init(&tx_sem, 0, 8);
	n_tx = 0;
	add_filter_msgq(peer, &peer_rxq, 0x400, 0x7F0, 0);
	for (int i = 0; i < 3; i++) {
		const struct can_frame f = frame_of(0x400 + i, 0, 1, (const uint8_t[]){(uint8_t)i});

		tx_errors[i] = 1;
		zassert_ok(can_send(dut, &f, WAIT, tx_cb, (void *)(intptr_t)i));
	}
	for (int i = 0; i < 3; i++) {
		zassert_ok(k_sem_take(&tx_sem, WAIT), "TX completion %d missing", i);
	}
	for (int i = 0; i < 3; i++) {
		const struct can_frame f = frame_of(0x400 + i, 0, 1, (const uint8_t[]){(uint8_t)i});

		zassert_equal(tx_errors[i], 0, "frame %d completed with %d", i, tx_errors[i]);
		expect_frame(&peer_rxq, &f);
	}
	zassert_equal(n_tx, 3);
}

#if defined(CONFIG_CAN_RX_TIMESTAMP)
#define N_STAMPS 5
static struct {
	uint16_t ts;
	uint32_t cb_us;
} stamps[N_STAMPS];
static int n_stamps;
static struct k_sem stamp_sem;

static void stamp_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	if (n_stamps < N_STAMPS) {
		stamps[n_stamps].ts = frame->timestamp;
		stamps[n_stamps].cb_us =
			(uint32_t)k_ticks_to_us_floor64((uint64_t)k_uptime_ticks());
		n_stamps++;
		k_sem_give(&stamp_sem);
	}
}

ZTEST(can_api, test_rx_timestamps)
{
	const struct can_filter flt = {.id = 0x500, .mask = CAN_STD_ID_MASK};
	int fid;

	k_sem_init(&stamp_sem, 0, N_STAMPS);
	n_stamps = 0;
	fid = can_add_rx_filter(peer, stamp_cb, NULL, &flt);
	zassert_true(fid >= 0);
	for (int i = 0; i < N_STAMPS; i++) {
		const struct can_frame f = frame_of(0x500, 0, 1, (const uint8_t[]){(uint8_t)i});

		send_ok(dut, &f);
		zassert_ok(k_sem_take(&stamp_sem, WAIT));
		k_msleep(3);
	}
	can_remove_rx_filter(peer, fid);

	for (int i = 0; i < N_STAMPS; i++) {
		/* 16-bit microsecond stamps: compare modulo 2^16 */
		uint16_t age = (uint16_t)((uint16_t)stamps[i].cb_us - stamps[i].ts);

		zassert_true(age < 50000U, "frame %d stamped %u us before its callback", i, age);
		if (i > 0) {
			uint16_t step = (uint16_t)(stamps[i].ts - stamps[i - 1].ts);

			/* the frames were sent at least 3 ms apart */
			zassert_true(step >= 2000U && step < 32768U,
				     "timestamps %u -> %u not increasing by >= 2 ms",
				     stamps[i - 1].ts, stamps[i].ts);
		}
	}
}
#endif

ZTEST(can_api, test_stop_start)
{
	const struct can_frame f = frame_of(0x111, 0, 1, (const uint8_t[]){1});
	enum can_state state;

	zassert_equal(can_start(dut), -EALREADY);
	zassert_equal(can_set_mode(dut, CAN_MODE_NORMAL), -EBUSY);
	zassert_equal(can_set_bitrate(dut, 250000), -EBUSY);

	zassert_ok(can_stop(dut));
	zassert_equal(can_stop(dut), -EALREADY);
	zassert_ok(can_get_state(dut, &state, NULL));
	zassert_equal(state, CAN_STATE_STOPPED);
	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -ENETDOWN);
	zassert_equal(can_set_mode(dut, CAN_MODE_FD), -ENOTSUP);
	zassert_ok(can_set_bitrate(dut, 500000));
	zassert_ok(can_start(dut));
	zassert_ok(can_get_state(dut, &state, NULL));
	zassert_equal(state, CAN_STATE_ERROR_ACTIVE);

	/* A stopped receiver gets nothing. */
	add_filter_msgq(peer, &peer_rxq, 0x111, CAN_STD_ID_MASK, 0);
	zassert_ok(can_stop(peer));
	send_ok(dut, &f);
	zassert_ok(can_start(peer));
	send_sentinel(dut);
	expect_sentinel(&peer_rxq);
}

/*
 * Stress for the race between can_start() and frames that reached the controller while it was
 * stopped: each cycle stops the dut, lets the peer send 3 frames (complete: the peer saw them
 * on the bus), starts the dut and sends a sentinel. Everything the dut receives before the
 * sentinel was sent while it was stopped and must not be delivered.
 */
#define STOPPED_CYCLES 300
#define STOPPED_FRAMES 3
#define STOPPED_ID     0x112U

ZTEST(can_api, test_no_reception_while_stopped_stress)
{
	int leaked = 0;
	int first_leak = -1;

	add_filter_msgq(dut, &dut_rxq, STOPPED_ID, CAN_STD_ID_MASK, 0);
	add_filter_msgq(dut, &dut_rxq, SENTINEL_ID, CAN_STD_ID_MASK, 0);
	for (int cycle = 0; cycle < STOPPED_CYCLES; cycle++) {
		struct can_frame got;

		zassert_ok(can_stop(dut));
		for (int i = 0; i < STOPPED_FRAMES; i++) {
			const struct can_frame f =
				frame_of(STOPPED_ID, 0, 3,
					 (const uint8_t[]){(uint8_t)cycle, (uint8_t)(cycle >> 8),
							   (uint8_t)i});

			send_ok(peer, &f);
		}
		zassert_ok(can_start(dut));
		send_sentinel(peer);
		for (;;) {
			zassert_ok(k_msgq_get(&dut_rxq, &got, WAIT),
				   "cycle %d: the sentinel sent after can_start() is missing",
				   cycle);
			if (got.id == SENTINEL_ID) {
				break;
			}
			if (first_leak < 0) {
				first_leak = cycle;
			}
			leaked++;
		}
	}
	zassert_equal(leaked, 0,
		      "%d of %d frames sent while the controller was stopped were delivered after "
		      "can_start() (first in cycle %d)",
		      leaked, STOPPED_CYCLES * STOPPED_FRAMES, first_leak);
}

/*
 * can_stop() with frames in flight: a frame whose callback said -ENETDOWN (aborted) must not
 * appear on the bus, and one that completed with 0 must. Each cycle queues a few frames,
 * stops at once, restarts, and sends a sentinel: the bus keeps order, so every frame that went
 * out arrives at the peer before it.
 */
#define ABORT_CYCLES 50
#define ABORT_FRAMES 4
#define ABORT_ID     0x113U

static struct k_sem abort_sem;
static int abort_status[ABORT_FRAMES];

static void abort_cb(const struct device *dev, int error, void *user_data)
{
	abort_status[(int)(intptr_t)user_data] = error;
	k_sem_give(&abort_sem);
}

ZTEST(can_api, test_stop_reports_in_flight_frames_truthfully)
{
	int aborted_but_sent = 0;
	int completed_but_lost = 0;
	int n_aborted = 0;

	add_filter_msgq(peer, &peer_rxq, ABORT_ID, CAN_STD_ID_MASK, 0);
	for (int cycle = 0; cycle < ABORT_CYCLES; cycle++) {
		bool seen[ABORT_FRAMES] = {false};
		struct can_frame got;

		k_sem_init(&abort_sem, 0, ABORT_FRAMES);
		for (int i = 0; i < ABORT_FRAMES; i++) {
			const struct can_frame f = frame_of(
				ABORT_ID, 0, 2, (const uint8_t[]){(uint8_t)cycle, (uint8_t)i});

			abort_status[i] = 1;
			zassert_ok(can_send(dut, &f, WAIT, abort_cb, (void *)(intptr_t)i));
		}
		zassert_ok(can_stop(dut));
		for (int i = 0; i < ABORT_FRAMES; i++) {
			zassert_ok(k_sem_take(&abort_sem, WAIT),
				   "cycle %d: a TX callback is missing", cycle);
		}
		zassert_ok(can_start(dut));
		send_sentinel(dut);
		for (;;) {
			zassert_ok(k_msgq_get(&peer_rxq, &got, WAIT), "cycle %d: no sentinel",
				   cycle);
			if (got.id == SENTINEL_ID) {
				break;
			}
			zassert_equal(got.data[0], (uint8_t)cycle, "a frame of another cycle");
			zassert_true(got.data[1] < ABORT_FRAMES);
			seen[got.data[1]] = true;
		}
		for (int i = 0; i < ABORT_FRAMES; i++) {
			zassert_true(abort_status[i] == 0 || abort_status[i] == -ENETDOWN,
				     "cycle %d frame %d completed with %d", cycle, i,
				     abort_status[i]);
			if (abort_status[i] == -ENETDOWN) {
				n_aborted++;
				aborted_but_sent += seen[i] ? 1 : 0;
			} else {
				completed_but_lost += seen[i] ? 0 : 1;
			}
		}
	}
	TC_PRINT("%d of %d frames aborted by can_stop()\n", n_aborted, ABORT_CYCLES * ABORT_FRAMES);
	zassert_equal(aborted_but_sent, 0,
		      "%d frames reported aborted (-ENETDOWN) by can_stop() went out on the bus",
		      aborted_but_sent);
	zassert_equal(completed_but_lost, 0, "%d frames reported sent never reached the bus",
		      completed_but_lost);
}

ZTEST(can_api, test_invalid_arguments)
{
	struct can_frame f = frame_of(0x800, 0, 0, NULL);
	struct can_filter flt = {.id = 0x800, .mask = CAN_STD_ID_MASK};

	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -EINVAL);
	f = frame_of(0x20000000, CAN_FRAME_IDE, 0, NULL);
	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -EINVAL);
	f = frame_of(0x10, 0, 9, NULL);
	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -EINVAL);
	f = frame_of(0x10, CAN_FRAME_FDF, 8, NULL);
	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -ENOTSUP);

	zassert_equal(can_add_rx_filter_msgq(peer, &peer_rxq, &flt), -EINVAL);
	flt = (struct can_filter){.id = 0x10, .mask = 0xFFF};
	zassert_equal(can_add_rx_filter_msgq(peer, &peer_rxq, &flt), -EINVAL);
	flt = (struct can_filter){.id = 0x10, .mask = CAN_STD_ID_MASK, .flags = BIT(1)};
	zassert_equal(can_add_rx_filter_msgq(peer, &peer_rxq, &flt), -ENOTSUP);
	flt = (struct can_filter){.id = 0x10, .mask = CAN_STD_ID_MASK};
	zassert_equal(can_add_rx_filter(peer, NULL, NULL, &flt), -EINVAL);
}

ZTEST(can_api, test_filter_capacity)
{
	const struct can_filter flt = {.id = 0x600, .mask = CAN_STD_ID_MASK};
	int max = can_get_max_filters(peer, false);
	int ids[256];
	int n = 0;
	int rc;

	zassert_true(max > 0 && max <= (int)ARRAY_SIZE(ids), "max filters %d", max);
	/* the sentinel filter holds one already */
	while ((rc = can_add_rx_filter_msgq(peer, &peer_rxq, &flt)) >= 0) {
		zassert_true(n < max, "more filters than can_get_max_filters()");
		ids[n++] = rc;
	}
	zassert_equal(rc, -ENOSPC);
	zassert_equal(n, max - 1);
	can_remove_rx_filter(peer, ids[0]);
	rc = can_add_rx_filter_msgq(peer, &peer_rxq, &flt);
	zassert_true(rc >= 0, "a freed filter is not reusable: %d", rc);
	ids[0] = rc;
	for (int i = 0; i < n; i++) {
		can_remove_rx_filter(peer, ids[i]);
	}
}

ZTEST(can_api, test_removed_filter_is_silent)
{
	const struct can_frame f = frame_of(0x222, 0, 1, (const uint8_t[]){9});
	const struct can_filter flt = {.id = 0x222, .mask = CAN_STD_ID_MASK};
	int fid = can_add_rx_filter_msgq(peer, &peer_rxq, &flt);

	zassert_true(fid >= 0);
	send_ok(dut, &f);
	expect_frame(&peer_rxq, &f);
	can_remove_rx_filter(peer, fid);
	send_ok(dut, &f);
	send_sentinel(dut);
	expect_sentinel(&peer_rxq);
}

ZTEST(can_api, test_loopback_mode)
{
	const struct can_frame f = frame_of(0x0AB, 0, 2, (const uint8_t[]){0xAB, 0xCD});

	restart(dut, CAN_MODE_LOOPBACK);
	zassert_equal(can_get_mode(dut), CAN_MODE_LOOPBACK);
	add_filter_msgq(dut, &dut_rxq, 0x0AB, CAN_STD_ID_MASK, 0);
	send_ok(dut, &f);
	expect_frame(&dut_rxq, &f);
}

ZTEST(can_api, test_own_frames_not_received)
{
	const struct can_frame f = frame_of(0x0AC, 0, 1, (const uint8_t[]){1});

	/* Outside loopback mode a controller does not receive what it sends. */
	add_filter_msgq(dut, &dut_rxq, 0x0AC, CAN_STD_ID_MASK, 0);
	add_filter_msgq(dut, &dut_rxq, SENTINEL_ID, CAN_STD_ID_MASK, 0);
	send_ok(dut, &f);
	send_sentinel(peer);
	expect_sentinel(&dut_rxq);
}

ZTEST(can_api, test_state_changes)
{
	const struct can_frame f = frame_of(0x0CC, 0, 1, (const uint8_t[]){0xCC});
	struct can_bus_err_cnt cnt;
	can_mode_t cap;

	zassert_ok(can_get_capabilities(dut, &cap));
	if ((cap & CAN_MODE_MANUAL_RECOVERY) != 0U) {
		/* keeps bus-off until the test ends it */
		restart(dut, CAN_MODE_MANUAL_RECOVERY);
	}
	zassert_equal(can_recover(dut, K_NO_WAIT),
		      (cap & CAN_MODE_MANUAL_RECOVERY) != 0U ? 0 : -ENOTSUP);
	can_set_state_change_callback(dut, state_cb, &state_q);

	inject_state(dut, CAN_STATE_ERROR_WARNING);
	expect_state(CAN_STATE_ERROR_WARNING);
	inject_state(dut, CAN_STATE_ERROR_PASSIVE);
	expect_state(CAN_STATE_ERROR_PASSIVE);
#if defined(CONFIG_CAN_VIRTUAL)
	zassert_ok(can_get_state(dut, NULL, &cnt));
	zassert_true(cnt.tx_err_cnt >= 128U, "passive with TEC %u", cnt.tx_err_cnt);
#else
	ARG_UNUSED(cnt);
#endif
	inject_state(dut, CAN_STATE_BUS_OFF);
	expect_state(CAN_STATE_BUS_OFF);
	zassert_equal(can_send(dut, &f, K_NO_WAIT, NULL, NULL), -ENETUNREACH);

	inject_state(dut, CAN_STATE_ERROR_ACTIVE);
	expect_state(CAN_STATE_ERROR_ACTIVE);
	add_filter_msgq(peer, &peer_rxq, 0x0CC, CAN_STD_ID_MASK, 0);
	send_ok(dut, &f);
	expect_frame(&peer_rxq, &f);
}

#if defined(CONFIG_CAN_SOCKETCAN)
CAN_MSGQ_DEFINE(dut_all_q, 32);

static struct can_socketcan_stats dut_stats(void)
{
	struct can_socketcan_stats st;

	zassert_ok(can_socketcan_get_stats(dut, &st));
	return st;
}

/* Peer sends @p n frames of @p id and a sentinel; the dut gets the sentinel. Frames read. */
static uint32_t frames_read_for(uint32_t id, int n)
{
	const struct can_frame f = frame_of(id, 0, 1, (const uint8_t[]){0x3B});
	uint32_t before = dut_stats().rx_frames;

	for (int i = 0; i < n; i++) {
		send_ok(peer, &f);
	}
	send_sentinel(peer);
	/* the socket reads in order: once the sentinel is here, so are the frames before it */
	expect_sentinel(&dut_rxq);

	return dut_stats().rx_frames - before;
}

ZTEST(can_api, test_the_kernel_filter_keeps_frames_no_filter_wants_out_of_the_socket)
{
	int all;

	add_filter_msgq(dut, &dut_rxq, SENTINEL_ID, CAN_STD_ID_MASK, 0);
	zassert_equal(frames_read_for(0x3B0, 5), 1, "the socket read frames no filter wants");

	/* a catch-all filter gives the whole bus, and once removed the kernel drops it again */
	all = can_add_rx_filter_msgq(dut, &dut_all_q, &(struct can_filter){.id = 0, .mask = 0});
	zassert_true(all >= 0);
	zassert_equal(frames_read_for(0x3B0, 5), 6, "a catch-all filter missed frames");
	for (int i = 0; i < 6; i++) {
		struct can_frame got;

		zassert_ok(k_msgq_get(&dut_all_q, &got, WAIT), "not delivered to the catch-all");
		zassert_equal(got.id, i < 5 ? 0x3B0 : SENTINEL_ID);
	}
	can_remove_rx_filter(dut, all);
	zassert_equal(frames_read_for(0x3B0, 5), 1, "a removed filter still lets frames in");
}

ZTEST(can_api, test_every_frame_is_confirmed_whatever_the_receive_filters)
{
	/* More identifiers than the kernel filter keeps for echoes: the oldest make room. */
	const int n = CONFIG_CAN_SOCKETCAN_TX_ID_FILTERS + 8;
	struct can_socketcan_stats before = dut_stats();
	struct can_socketcan_stats after;

	add_filter_msgq(dut, &dut_rxq, SENTINEL_ID, CAN_STD_ID_MASK, 0);
	for (int round = 0; round < 2; round++) {
		for (int i = 0; i < n; i++) {
			const struct can_frame f =
				frame_of(0x200 + (uint32_t)i, 0, 1, (const uint8_t[]){(uint8_t)i});

			send_ok(dut, &f); /* 0: its echo came, no receive filter wants it */
		}
	}
	after = dut_stats();
	zassert_equal(after.tx_confirmed - before.tx_confirmed, 2U * (uint32_t)n);
	zassert_equal(after.tx_echo_timeouts, before.tx_echo_timeouts);
	zassert_equal(after.tx_echoes_lost, before.tx_echoes_lost);
	/* the sentinel filters of both (@0: one socket each) plus the sent identifiers kept */
	zassert_equal(after.kernel_filters, 1 + CONFIG_CAN_SOCKETCAN_TX_ID_FILTERS, "%u entries",
		      after.kernel_filters);
}
#endif

ZTEST(can_api, test_dlc_conversion)
{
	/* ISO 11898-1:2015 DLC table */
	static const uint8_t bytes[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

	for (uint8_t dlc = 0; dlc < 16; dlc++) {
		zassert_equal(can_dlc_to_bytes(dlc), bytes[dlc], "dlc %u", dlc);
		zassert_equal(can_bytes_to_dlc(bytes[dlc]), dlc, "%u bytes", bytes[dlc]);
	}
	zassert_equal(can_bytes_to_dlc(9), 9);
	zassert_equal(can_bytes_to_dlc(33), 14);
}
