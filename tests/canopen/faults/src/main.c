/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The fault-injection matrix (doc/faults.md): one test per fault, each asserting the node's
 * whole reaction at once: the EMCY frames on the bus, 1001h, the heartbeat consumer's
 * events, the NMT state (in the node and in its heartbeat on the bus) and the RUN/ERR LEDs.
 *
 * Set-up: the node under test (5, objdict/faults_test.eds) sits on a simulation line whose
 * frames go through can_virtual0 onto the virtual bus with the simulated clock; what that
 * controller receives and every change of its state is handed to the line as the line thread
 * would (frames before deadlines, states in order). can_virtual1 is the rest of the network:
 * node 2 (heartbeat 100 ms, SDO server, SYNC and RPDO producer, NMT master) and the bus
 * monitor whose log every assertion about frames reads. can_virtual2 babbles for the floods.
 * Faults come from the virtual bus's own injection: lost, corrupted frames, controller
 * states, a cut line, bit timing with arbitration for the floods.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <can_virtual.h>
#include <led_virtual.h>

#include <canopen/emcy.h>
#include <canopen/event.h>
#include <canopen/leds.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/sdo_cli.h>

#include "line_internal.h"

#include "faults_test_od.h"

#define DUT_ID   5
#define PEER_ID  2
#define MS       1000ULL
#define STEP_US  (1 * MS)
#define EMCY_ID  (0x80 + DUT_ID)
#define HB_ID    (0x700 + DUT_ID)
#define TPDO1_ID (0x180 + DUT_ID)
#define RPDO1_ID (0x200 + DUT_ID)
#define SDO_RX   (0x600 + DUT_ID)
#define SDO_TX   (0x580 + DUT_ID)
#define CLI_TX   (0x600 + PEER_ID)
#define CLI_RX   (0x580 + PEER_ID)
#define FLOOD_ID 0x0F0
#define GREEN    0U
#define RED      1U
#define MAX_LOG  8192
#define MAX_RXQ  512
#define MAX_EV   64

/* --- The node under test on the simulated bus ------------------------------------------ */

static const struct device *dut_dev;
static const struct device *peer_dev;
static const struct device *flood_dev;
static const struct device *leds;

static struct {
	struct co_line line;
	struct co_node node;
	struct faults_test_od_ram ram;
	struct co_listener listener;
	/* What can_virtual0 received and its state changes, in order, for the line. */
	struct {
		struct can_frame frame;
		uint64_t at;
		bool is_state;
		enum can_state state;
	} rxq[MAX_RXQ];
	int rxq_n;
	/* The node's heartbeat consumer events. */
	struct {
		uint8_t node_id;
		enum co_hb_event event;
		uint64_t at;
	} hb[MAX_EV];
	int n_hb;
	int tx_refused;
} t;

/* Current time [µs]: the bus clock and the line's. */
static uint64_t now;

/* The bus as the peer's controller sees it (every frame but its own). */
static struct {
	struct can_frame frame;
	uint64_t at;
} bus_log[MAX_LOG];
static int n_log;
/* Flood frames seen (not logged). */
static int n_flood;

/* Node 2's heartbeat, while period_ms != 0. */
static struct {
	uint32_t period_ms;
	uint64_t next;
	uint8_t state;
} peer_hb;

static bool flooding;

static void dut_rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	zassert_true(t.rxq_n < MAX_RXQ, "DUT RX queue full");
	t.rxq[t.rxq_n].frame = *frame;
	t.rxq[t.rxq_n].at = can_virtual_time_us();
	t.rxq[t.rxq_n].is_state = false;
	t.rxq_n++;
}

static void dut_state_cb(const struct device *dev, enum can_state state,
			 struct can_bus_err_cnt err_cnt, void *user_data)
{
	zassert_true(t.rxq_n < MAX_RXQ, "DUT RX queue full");
	t.rxq[t.rxq_n].at = can_virtual_time_us();
	t.rxq[t.rxq_n].is_state = true;
	t.rxq[t.rxq_n].state = state;
	t.rxq_n++;
}

static void tx_done(const struct device *dev, int error, void *user_data)
{
	if (error != 0 && user_data == &t) {
		t.tx_refused++;
	}
}

/* The line's sink: the frame goes to can_virtual0, as co_line_dev_send() does it. */
static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	return can_send(dut_dev, frame, K_NO_WAIT, tx_done, &t);
}

static void peer_rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	if (frame->id == FLOOD_ID) {
		n_flood++;
		return;
	}
	zassert_true(n_log < MAX_LOG, "bus log full");
	{
		bus_log[n_log].frame = *frame;
		bus_log[n_log].at = can_virtual_time_us();
		n_log++;
	}
}

static int listener_cb(struct co_node *node, const struct co_event *ev, void *user_data)
{
	if (ev->type == CO_EV_HB && t.n_hb < MAX_EV) {
		t.hb[t.n_hb].node_id = ev->hb.node_id;
		t.hb[t.n_hb].event = ev->hb.event;
		t.hb[t.n_hb].at = now;
		t.n_hb++;
	}
	return 0;
}

static void peer_send(const struct device *dev, uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	if (data != NULL) {
		memcpy(f.data, data, dlc);
	}
	zassert_ok(can_send(dev, &f, K_NO_WAIT, tx_done, NULL), "peer send %03x", id);
}

/* Hand what the controller received to the line, then run the line's deadlines. */
static void feed_line(void)
{
	for (int i = 0; i < t.rxq_n; i++) {
		if (t.rxq[i].is_state) {
			co_line_inject_event(&t.line, CO_LINE_EV_CAN_STATE, t.rxq[i].state);
		} else {
			co_line_rx(&t.line, &t.rxq[i].frame, t.rxq[i].at);
		}
	}
	t.rxq_n = 0;
	co_line_process(&t.line, now);
}

/* Keep the babbler's transmit queue full: it wins every arbitration against higher ids. */
static void flood(void)
{
	static const uint8_t junk[8] = {0xde, 0xad, 0xbe, 0xef, 0, 0, 0, 0};
	struct can_frame f = {.id = FLOOD_ID, .dlc = 8};

	memcpy(f.data, junk, sizeof(junk));
	while (can_send(flood_dev, &f, K_NO_WAIT, tx_done, NULL) == 0) {
	}
}

/* Advance bus and node to @p at [µs], in steps of at most 1 ms and at every deadline. */
static void run_until(uint64_t at)
{
	while (now < at) {
		uint64_t next = MIN(at, now + STEP_US);
		uint64_t dl = co_line_next_deadline(&t.line);

		if (dl > now && dl < next) {
			next = dl;
		}
		if (peer_hb.period_ms != 0U && peer_hb.next > now && peer_hb.next < next) {
			next = peer_hb.next;
		}
		if (flooding) {
			flood();
		}
		zassert_true(can_virtual_sim_advance(next - now) >= 0);
		now = next;
		if (peer_hb.period_ms != 0U && now >= peer_hb.next) {
			struct can_frame f = {.id = 0x700 + PEER_ID, .dlc = 1};

			f.data[0] = peer_hb.state;
			/* A full queue (peer starved by a flood) just skips this heartbeat. */
			(void)can_send(peer_dev, &f, K_NO_WAIT, tx_done, NULL);
			peer_hb.next += peer_hb.period_ms * MS;
		}
		feed_line();
	}
}

static void run_for(uint64_t us)
{
	run_until(now + us);
}

/* --- What the node shows --------------------------------------------------------------- */

static uint8_t reg1001(void)
{
	uint8_t v = 0xff;
	size_t len = 0;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), 0x1001, 0, 0, &v, 1, &len, CO_OD_WRITER_SDO),
		      0U);
	co_node_unlock(&t.node);
	return v;
}

static uint32_t od_u32(uint16_t index, uint8_t sub)
{
	/* co_od_read() gives the wire bytes (little-endian), whatever the host's byte order. */
	uint8_t v[4] = {0};
	size_t len = 0;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), index, sub, 0, v, 4, &len, CO_OD_WRITER_APP),
		      0U);
	co_node_unlock(&t.node);
	return sys_get_le32(v);
}

static uint8_t od_u8(uint16_t index, uint8_t sub)
{
	uint8_t v = 0;
	size_t len = 0;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), index, sub, 0, &v, 1, &len, CO_OD_WRITER_APP),
		      0U);
	co_node_unlock(&t.node);
	return v;
}

static void od_write(uint16_t index, uint8_t sub, uint32_t value, size_t len)
{
	uint8_t buf[4];
	uint32_t ab;

	for (size_t i = 0; i < len; i++) {
		buf[i] = (uint8_t)(value >> (8 * i));
	}
	co_node_lock(&t.node);
	ab = co_od_write(co_node_od(&t.node), index, sub, buf, len, CO_OD_WRITER_SDO);
	co_node_unlock(&t.node);
	zassert_equal(ab, 0U, "write %04x:%u: %08x", index, sub, ab);
}

/* The LEDs show @p run and @p err, the virtual LED device agreeing with the service. */
static void expect_leds(enum co_led_pattern run, enum co_led_pattern err)
{
	enum co_led_pattern r, e;
	bool g, rd, sg, sr;

	co_leds_get_patterns(&t.node, &r, &e);
	zassert_equal(r, run, "RUN pattern %d, want %d", r, run);
	zassert_equal(e, err, "ERR pattern %d, want %d", e, err);
	zassert_ok(led_virtual_get(leds, GREEN, &g));
	zassert_ok(led_virtual_get(leds, RED, &rd));
	co_leds_get(&t.node, &sg, &sr);
	zassert_equal(g, sg, "green LED device and service disagree");
	zassert_equal(rd, sr, "red LED device and service disagree");
}

static void expect_state(enum co_nmt_state want)
{
	zassert_equal(co_nmt_get_state(&t.node), want, "NMT state %02x, want %02x",
		      co_nmt_get_state(&t.node), want);
}

/* Index of the first frame with @p id in the bus log at or after @p from, or -1. */
static int log_find(uint32_t id, int from)
{
	for (int i = from; i < n_log; i++) {
		if (bus_log[i].frame.id == id) {
			return i;
		}
	}
	return -1;
}

static int log_count(uint32_t id, int from)
{
	int n = 0;

	for (int i = from; i < n_log; i++) {
		n += bus_log[i].frame.id == id ? 1 : 0;
	}
	return n;
}

/*
 * The EMCY frames on the bus from @p from on are exactly @p n of (code, register) pairs in
 * @p want ({code, reg, ...}).
 */
static void expect_emcys(int from, const uint16_t *want, int n)
{
	int k = 0;

	for (int i = from; i < n_log; i++) {
		const struct can_frame *f = &bus_log[i].frame;

		if (f->id != EMCY_ID) {
			continue;
		}
		zassert_true(k < n, "unexpected EMCY %02x%02x reg %02x at %u ms", f->data[1],
			     f->data[0], f->data[2], (unsigned int)(bus_log[i].at / MS));
		zassert_equal(f->dlc, 8U);
		zassert_equal(f->data[0] | (f->data[1] << 8), want[2 * k],
			      "EMCY %d: %02x%02x, want %04x", k, f->data[1], f->data[0],
			      want[2 * k]);
		zassert_equal(f->data[2], want[2 * k + 1],
			      "EMCY %d (%04x): register %02x, want %02x", k, want[2 * k],
			      f->data[2], want[2 * k + 1]);
		k++;
	}
	zassert_equal(k, n, "%d EMCY frames on the bus, want %d", k, n);
}

/* The last heartbeat of the node on the bus carries @p state. */
static void expect_hb_on_bus(uint8_t state)
{
	int last = -1;

	for (int i = log_find(HB_ID, 0); i >= 0; i = log_find(HB_ID, i + 1)) {
		last = i;
	}
	zassert_true(last >= 0, "no heartbeat of the node on the bus");
	zassert_equal(bus_log[last].frame.data[0], state, "heartbeat state %02x, want %02x",
		      bus_log[last].frame.data[0], state);
}

static int count_hb(enum co_hb_event ev)
{
	int n = 0;

	for (int i = 0; i < t.n_hb; i++) {
		n += t.hb[i].event == ev && t.hb[i].node_id == PEER_ID ? 1 : 0;
	}
	return n;
}

/* --- Set-up: the node Operational, node 2's heartbeat monitored ----------------------- */

static void *suite_setup(void)
{
	const struct can_filter all = {.id = 0, .mask = 0};

	dut_dev = device_get_binding("can_virtual0");
	peer_dev = device_get_binding("can_virtual1");
	flood_dev = device_get_binding("can_virtual2");
	leds = device_get_binding("led_virtual0");
	zassert_not_null(dut_dev);
	zassert_not_null(peer_dev);
	zassert_not_null(flood_dev);
	zassert_not_null(leds);
	zassert_true(can_add_rx_filter(dut_dev, dut_rx_cb, NULL, &all) >= 0);
	zassert_true(can_add_rx_filter(peer_dev, peer_rx_cb, NULL, &all) >= 0);
	can_set_state_change_callback(dut_dev, dut_state_cb, NULL);
	return NULL;
}

static void before(void *f)
{
	static const struct co_leds_cfg cfg = {.green = GREEN, .red = RED};
	struct co_leds_cfg c = cfg;
	const uint8_t start[2] = {0x01, DUT_ID};

	memset(&t, 0, sizeof(t));
	n_log = 0;
	n_flood = 0;
	flooding = false;
	peer_hb.period_ms = 0;

	/* Controllers from a clean slate; the bus clock runs on from the previous test. */
	(void)can_stop(dut_dev);
	(void)can_stop(peer_dev);
	(void)can_stop(flood_dev);
	zassert_ok(can_virtual_clear_faults(0));
	zassert_ok(can_virtual_bus_set_bit_timing(0, false));
	zassert_ok(can_virtual_restore(dut_dev));
	zassert_ok(can_start(dut_dev));
	zassert_ok(can_start(peer_dev));
	zassert_ok(can_start(flood_dev));
	zassert_ok(can_virtual_set_state(dut_dev, CAN_STATE_ERROR_ACTIVE));
	zassert_true(can_virtual_sim_run(1000) >= 0, "bus drained");
	t.rxq_n = 0;
	n_log = 0;
	now = can_virtual_time_us();

	co_line_init_sim(&t.line, "dut", sink, NULL);
	t.line.sim_now = now;
	zassert_ok(co_node_init(&t.node, "dut", &t.line, &faults_test_od_def, &t.ram, DUT_ID));
	co_listener_init(&t.listener, "faults", CO_EV_BIT(CO_EV_HB), listener_cb, NULL);
	zassert_ok(co_node_listener_add(&t.node, &t.listener));
	c.dev = leds;
	zassert_ok(co_leds_attach(&t.node, &c));
	zassert_ok(co_node_start(&t.node));

	/* Node 2 is up; the master starts node 5. */
	peer_hb.period_ms = 100;
	peer_hb.state = 0x05;
	peer_hb.next = now + 10 * MS;
	run_for(50 * MS);
	peer_send(peer_dev, 0x000, 2, start);
	run_for(500 * MS);
	expect_state(CO_NMT_OPERATIONAL);
	zassert_equal(count_hb(CO_HB_EV_STARTED), 1, "node 2 monitored");
	zassert_equal(reg1001(), 0x00);
	expect_hb_on_bus(0x05);
	expect_leds(CO_LED_ON, CO_LED_OFF);
	n_log = 0;
	t.n_hb = 0;
}

static void after(void *f)
{
	flooding = false;
	peer_hb.period_ms = 0;
	(void)can_virtual_bus_set_bit_timing(0, false);
	(void)can_virtual_restore(dut_dev);
	(void)can_virtual_clear_faults(0);
	/* Let what the tests left on the bus go, with no line to hand it to. */
	(void)can_virtual_sim_run(100000);
	(void)can_stop(dut_dev);
	(void)can_stop(peer_dev);
	(void)can_stop(flood_dev);
}

ZTEST_SUITE(co_faults, NULL, suite_setup, before, after, NULL);

/* --- The matrix ------------------------------------------------------------------------- */

/*
 * Heartbeat producer lost (CiA 301 §7.2.8.3.2.2, §7.5.2.32): node 2 falls silent. After its
 * consumer time (250 ms) the consumer reports the loss, EMCY 8130h (register: generic +
 * communication, manufacturer byte 0 = node 2) goes out, 1029h sub1 = 0 takes the node from
 * Operational to Pre-operational, ERR double flash. Node 2 back: the event, the error reset,
 * ERR off; the node stays Pre-operational (nothing brings it back but the master).
 */
ZTEST(co_faults, test_heartbeat_producer_lost)
{
	static const uint16_t lost[] = {0x8130, 0x11};
	static const uint16_t back[] = {0x0000, 0x00};
	uint64_t silent = now;
	int i;

	peer_hb.period_ms = 0;
	run_for(200 * MS);
	zassert_equal(t.n_hb, 0, "no event within the consumer time");
	expect_state(CO_NMT_OPERATIONAL);
	run_for(200 * MS);
	zassert_equal(count_hb(CO_HB_EV_LOST), 1);
	expect_emcys(0, lost, 1);
	i = log_find(EMCY_ID, 0);
	zassert_equal(bus_log[i].frame.data[3], PEER_ID, "msef[0] = the lost node");
	zassert_true(bus_log[i].at - silent < 400 * MS);
	zassert_equal(reg1001(), 0x11);
	zassert_equal(od_u32(0x1003, 1), 0x00028130U, "1003h:1");
	zassert_equal(od_u8(0x1003, 0), 1, "one entry in 1003h");
	expect_state(CO_NMT_PRE_OPERATIONAL);
	run_for(200 * MS);
	expect_hb_on_bus(0x7f);
	expect_leds(CO_LED_BLINK, CO_LED_FLASH2);

	i = n_log;
	peer_hb.period_ms = 100;
	peer_hb.next = now + MS;
	run_for(300 * MS);
	zassert_equal(count_hb(CO_HB_EV_RECOVERED), 1);
	expect_emcys(i, back, 1);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_leds(CO_LED_BLINK, CO_LED_OFF);
}

/* Print what the bus saw of the node since @p from (for the log of a failing run). */
static void dump(const char *what, int from)
{
	for (int i = from; i < n_log; i++) {
		const struct can_frame *f = &bus_log[i].frame;

		if (f->id == EMCY_ID || f->id == SDO_TX || f->id == CLI_TX || f->id == HB_ID) {
			printk("%s: %6u ms %03x %u: %02x %02x %02x %02x %02x %02x %02x %02x\n",
			       what, (unsigned int)(bus_log[i].at / MS), f->id, f->dlc, f->data[0],
			       f->data[1], f->data[2], f->data[3], f->data[4], f->data[5],
			       f->data[6], f->data[7]);
		}
	}
}

/*
 * Bus-off and recovery (CiA 301 §7.2.7.2 Table 21, §7.5.2.32): the controller goes bus-off
 * (manual recovery, the application recovers after 100 ms). Bus-off: nothing from the node
 * on the bus, 1029h sub1 = 0 takes it to Pre-operational, ERR on. Recovered: EMCY 8140h,
 * 1001h = 11h for the hold time (1 s), then the error reset; no heartbeat event (100 ms is
 * shorter than the consumer time).
 */
ZTEST(co_faults, test_bus_off_and_recovery)
{
	static const uint16_t want[] = {0x8140, 0x11, 0x0000, 0x00};
	int i;

	zassert_ok(can_stop(dut_dev));
	zassert_ok(can_set_mode(dut_dev, CAN_MODE_MANUAL_RECOVERY));
	zassert_ok(can_start(dut_dev));

	zassert_ok(can_virtual_set_state(dut_dev, CAN_STATE_BUS_OFF));
	run_for(100 * MS);
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_leds(CO_LED_BLINK, CO_LED_ON);
	zassert_equal(log_count(HB_ID, 0) + log_count(EMCY_ID, 0), 0, "nothing sent in bus-off");

	zassert_equal(can_recover(dut_dev, K_NO_WAIT), -EAGAIN, "recovery runs on the bus clock");
	run_for(10 * MS);
	i = log_find(EMCY_ID, 0);
	zassert_true(i >= 0, "8140h after the recovery");
	zassert_equal(reg1001(), 0x11);
	zassert_equal(od_u32(0x1003, 1), 0x00008140U, "1003h:1");
	expect_leds(CO_LED_BLINK, CO_LED_BLINK);
	run_for(1200 * MS);
	dump("bus-off", 0);
	expect_emcys(0, want, 2);
	/* Sent at the next 1 ms step after each event: ±1 ms. */
	zassert_true(bus_log[log_find(EMCY_ID, i + 1)].at - bus_log[i].at >= 999 * MS,
		     "8140h held for the hold time");
	zassert_equal(reg1001(), 0x00);
	zassert_equal(t.n_hb, 0, "no heartbeat event");
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_hb_on_bus(0x7f);
	expect_leds(CO_LED_BLINK, CO_LED_OFF);

	zassert_ok(can_stop(dut_dev));
	zassert_ok(can_set_mode(dut_dev, CAN_MODE_NORMAL));
}

/*
 * Error passive (CiA 301 Table 21, CiA 303-3): EMCY 8120h while the controller is error
 * passive, ERR single flash (warning limit), no change of NMT state (1029h covers bus-off
 * only); back to error active: the error reset, ERR off.
 */
ZTEST(co_faults, test_error_passive)
{
	static const uint16_t want[] = {0x8120, 0x11, 0x0000, 0x00};

	zassert_ok(can_virtual_set_state(dut_dev, CAN_STATE_ERROR_PASSIVE));
	run_for(500 * MS);
	expect_emcys(0, want, 1);
	zassert_equal(reg1001(), 0x11);
	zassert_equal(od_u32(0x1003, 1), 0x00008120U);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_FLASH1);
	zassert_equal(t.n_hb, 0);
	zassert_true(log_count(HB_ID, 0) >= 4, "an error-passive node still sends");

	zassert_ok(can_virtual_set_state(dut_dev, CAN_STATE_ERROR_ACTIVE));
	run_for(100 * MS);
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * A lost frame (CiA 301 §7.2.8.3.2.2): one heartbeat of node 2 does not arrive. The consumer
 * time (250 ms) covers one lost heartbeat of a 100 ms producer, so nothing happens: no
 * event, no EMCY, 1001h 0, Operational, LEDs as before.
 */
ZTEST(co_faults, test_lost_frame)
{
	const struct can_filter hb2 = {.id = 0x700 + PEER_ID, .mask = CAN_STD_ID_MASK};
	struct can_virtual_bus_stats st;

	zassert_ok(can_virtual_drop_frames(0, &hb2, 1));
	run_for(1000 * MS);
	zassert_ok(can_virtual_bus_get_stats(0, &st));
	zassert_true(st.dropped >= 1U, "the heartbeat was lost");
	zassert_equal(t.n_hb, 0, "no heartbeat event");
	expect_emcys(0, NULL, 0);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_hb_on_bus(0x05);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

static int sdo_abort_code(int i)
{
	const uint8_t *d = bus_log[i].frame.data;

	return (int)(d[4] | (d[5] << 8) | (d[6] << 16) | ((uint32_t)d[7] << 24));
}

/*
 * A corrupted frame:
 * - wrong DLC: a SYNC of 1 byte while 1019h = 0 (CiA 301 §7.2.5): EMCY 8240h, ERR triple
 *   flash, state kept; the next good SYNC clears it;
 * - bad data: an RPDO whose byte is flipped on the bus. CAN's CRC catches this on a real bus
 *   and nothing above it can (CiA 304 SRDO can, doc/srdo-campaign.md): the node writes the
 *   value and shows nothing;
 * - toggle: the toggle bit of an SDO download segment flipped on the bus (CiA 301 §7.2.4.3.3):
 *   the server aborts with 05030000h, no EMCY, state and LEDs as before.
 */
ZTEST(co_faults, test_corrupted_frame)
{
	static const uint16_t want[] = {0x8240, 0x11, 0x0000, 0x00};
	const struct can_filter rpdo = {.id = RPDO1_ID, .mask = CAN_STD_ID_MASK};
	const struct can_filter sdo = {.id = SDO_RX, .mask = CAN_STD_ID_MASK};
	const uint8_t flip[8] = {0x10};
	const uint8_t sync_bad[1] = {0x01};
	const uint8_t out[2] = {0x12, 0x34};
	const uint8_t init[8] = {0x21, 0x00, 0x20, 0x00, 16, 0, 0, 0};
	const uint8_t seg0[8] = {0x00, 'a', 'b', 'c', 'd', 'e', 'f', 'g'};
	const uint8_t seg1[8] = {0x10, 'h', 'i', 'j', 'k', 'l', 'm', 'n'};
	int i;

	/* Wrong DLC. */
	peer_send(peer_dev, 0x080, 1, sync_bad);
	run_for(50 * MS);
	expect_emcys(0, want, 1);
	zassert_equal(reg1001(), 0x11);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_FLASH3);
	peer_send(peer_dev, 0x080, 0, NULL);
	run_for(50 * MS);
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);
	expect_leds(CO_LED_ON, CO_LED_OFF);

	/* Bad data. */
	zassert_ok(can_virtual_corrupt_frames(0, &rpdo, 1, flip));
	peer_send(peer_dev, RPDO1_ID, 2, out);
	run_for(20 * MS);
	zassert_equal(od_u8(0x6200, 1), 0x12 ^ 0x10, "the corrupted value is written");
	zassert_equal(od_u8(0x6200, 2), 0x34);
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);

	/* Toggle. */
	i = n_log;
	peer_send(peer_dev, SDO_RX, 8, init);
	run_for(5 * MS);
	peer_send(peer_dev, SDO_RX, 8, seg0);
	run_for(5 * MS);
	zassert_ok(can_virtual_corrupt_frames(0, &sdo, 1, flip));
	peer_send(peer_dev, SDO_RX, 8, seg1);
	run_for(20 * MS);
	dump("toggle", i);
	zassert_equal(log_count(SDO_TX, i), 3, "initiate, segment 0, abort");
	i = log_find(SDO_TX, log_find(SDO_TX, log_find(SDO_TX, i) + 1) + 1);
	zassert_equal(bus_log[i].frame.data[0], 0x80, "abort");
	zassert_equal(sdo_abort_code(i), 0x05030000, "toggle bit not alternated");
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
	zassert_equal(t.n_hb, 0);
}

/*
 * A frame flood on one identifier (a babbling idiot, CiA 301 §7.2.8.3.2.2 for what it
 * starves): can_virtual2 sends 0F0h back to back for 1 s with bit timing on, so only frames
 * with a lower identifier reach the bus. Node 2's heartbeat (702h) never does: the node
 * reports the loss, its EMCY 8130h (085h) wins arbitration and goes out during the flood,
 * 1029h takes it to Pre-operational, ERR double flash. Its own heartbeat waits. The flood
 * over: the held frames go out, node 2 is back, the error reset, ERR off.
 */
ZTEST(co_faults, test_frame_flood_on_one_identifier)
{
	static const uint16_t want[] = {0x8130, 0x11, 0x0000, 0x00};
	uint64_t start;
	int i;

	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	flooding = true;
	start = now;
	run_for(1000 * MS);
	i = log_find(EMCY_ID, 0);
	zassert_true(i >= 0, "8130h during the flood");
	zassert_true(bus_log[i].at - start <= 400 * MS, "lost after the consumer time");
	zassert_equal(count_hb(CO_HB_EV_LOST), 1);
	zassert_equal(log_count(0x700 + PEER_ID, 0), 0, "node 2's heartbeats starved");
	zassert_equal(log_count(HB_ID, 0), 0, "the node's heartbeats starved");
	zassert_true(n_flood > 3000, "the bus is full: %d", n_flood);
	expect_emcys(0, want, 1);
	zassert_equal(reg1001(), 0x11);
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_leds(CO_LED_BLINK, CO_LED_FLASH2);

	flooding = false;
	run_for(500 * MS);
	zassert_equal(count_hb(CO_HB_EV_RECOVERED), 1);
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_hb_on_bus(0x7f);
	expect_leds(CO_LED_BLINK, CO_LED_OFF);
}

/*
 * A cut line (CiA 301 §7.2.8.3.2.2, Table 21): the node's controller is off the bus. It hears
 * nothing, its frames stay in the controller (no acknowledgement) and its first attempt makes
 * it error passive. Inside the node: 8120h and 8130h (node 2 lost) raised, 1001h = 11h,
 * Pre-operational, ERR double flash (the heartbeat event ranks above the warning limit).
 * On the bus: nothing from the node.
 */
ZTEST(co_faults, test_cut_line)
{
	zassert_ok(can_virtual_cut(dut_dev));
	run_for(1000 * MS);
	zassert_equal(log_count(HB_ID, 0) + log_count(EMCY_ID, 0), 0, "nothing from the node");
	zassert_equal(count_hb(CO_HB_EV_LOST), 1);
	zassert_equal(reg1001(), 0x11);
	zassert_equal(od_u32(0x1003, 1), 0x00028130U, "1003h:1 node 2 lost");
	zassert_equal(od_u32(0x1003, 2), 0x00008120U, "1003h:2 error passive");
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_leds(CO_LED_BLINK, CO_LED_FLASH2);
}

/*
 * The line comes back (after a 1 s cut): the frames the controller held go out first (the
 * oldest, the heartbeat of Operational and the EMCYs), the controller is error active again
 * (8120h cleared), node 2's heartbeat is back (8130h cleared, the last error reset with
 * register 0), ERR off. The node stays Pre-operational until the master starts it.
 */
ZTEST(co_faults, test_line_comes_back)
{
	static const uint16_t want[] = {0x8120, 0x11, 0x8130, 0x11, 0x0000, 0x11, 0x0000, 0x00};
	int i;

	zassert_ok(can_virtual_cut(dut_dev));
	run_for(1000 * MS);
	zassert_equal(log_count(HB_ID, 0) + log_count(EMCY_ID, 0), 0);
	zassert_ok(can_virtual_restore(dut_dev));
	run_for(500 * MS);
	dump("back", 0);
	expect_emcys(0, want, 4);
	i = log_find(HB_ID, 0);
	zassert_true(i >= 0 && bus_log[i].at < bus_log[log_find(EMCY_ID, 0)].at + MS,
		     "held heartbeats go out at once");
	zassert_equal(count_hb(CO_HB_EV_RECOVERED), 1);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_PRE_OPERATIONAL);
	expect_hb_on_bus(0x7f);
	expect_leds(CO_LED_BLINK, CO_LED_OFF);
}

/*
 * The TX queue full for a long time: a flood on 0F0h keeps the node's TPDO 1 (185h, made
 * event-driven with a 10 ms event timer) and heartbeats (705h) off the bus for 5 s
 * (heartbeat consumer off, so only the send side is seen). Its controller's 8 entries and
 * the line's 16 fill up, then frames are dropped and counted: 8110h
 * (manufacturer byte 02h: transmit) in 1001h and 1003h, the state kept (1029h does not cover
 * overruns). The EMCY frame waits for room in the queue instead of being dropped with the
 * frames it reports: when the flood ends it goes out first (085h wins arbitration over the
 * held heartbeats), ERR blinks, and 1 s after the last overflow the error reset follows.
 */
ZTEST(co_faults, test_tx_queue_full_for_a_long_time)
{
	static const uint16_t want[] = {0x8110, 0x11, 0x0000, 0x00};
	struct co_line_stats st;
	uint64_t end;
	int i;

	od_write(0x1016, 1, 0, 4);
	od_write(0x1800, 2, 255, 1);
	od_write(0x1800, 5, 10, 2);
	zassert_ok(can_virtual_bus_set_bit_timing(0, true));
	flooding = true;
	run_for(5000 * MS);
	co_line_get_stats(&t.line, &st);
	zassert_true(st.tx_dropped > 0U);
	zassert_equal(st.tx_queue_max, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE);
	zassert_equal(log_count(HB_ID, 0) + log_count(EMCY_ID, 0), 0, "nothing got through");
	zassert_equal(reg1001(), 0x11);
	zassert_equal(od_u32(0x1003, 1), 0x00028110U, "1003h:1 TX overrun");
	expect_state(CO_NMT_OPERATIONAL);
	/* ERR follows the EMCYs sent; this one has not been yet. */
	expect_leds(CO_LED_ON, CO_LED_OFF);

	flooding = false;
	end = now;
	run_for(100 * MS);
	i = log_find(EMCY_ID, 0);
	zassert_true(i >= 0, "8110h once there is room");
	zassert_true(bus_log[i].at - end <= 20 * MS, "8110h %u ms after the flood",
		     (unsigned int)((bus_log[i].at - end) / MS));
	zassert_equal(bus_log[i].frame.data[3], 0x02, "transmit overrun");
	expect_leds(CO_LED_ON, CO_LED_BLINK);
	run_for(2000 * MS);
	expect_emcys(0, want, 2);
	zassert_true(log_count(HB_ID, 0) >= 15, "the queue drained, heartbeats again");
	zassert_true(log_count(TPDO1_ID, 0) >= 150, "and TPDOs");
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * Held heartbeats (a line blocked for 1 s, then back): a heartbeat still waiting in the
 * line's TX queue is replaced by the next one, so the line sends one, not every one it
 * missed. What the controller itself holds (8 entries, the oldest from before the fault)
 * goes out as it is: the stack cannot take frames back from the driver. The last heartbeat
 * of the burst, and every one after, shows the state the node is in.
 */
ZTEST(co_faults, test_held_heartbeats_are_replaced_not_sent_in_a_burst)
{
	struct co_line_stats st;
	int i;

	zassert_ok(can_virtual_cut(dut_dev));
	run_for(1000 * MS);
	co_line_get_stats(&t.line, &st);
	zassert_true(st.tx_purged >= 1U, "older heartbeats withdrawn: %u", st.tx_purged);
	zassert_true(st.tx_queue_max <= 2U, "one heartbeat (and EMCYs) in the line: %u",
		     st.tx_queue_max);
	zassert_ok(can_virtual_restore(dut_dev));
	run_for(5 * MS);
	zassert_true(log_count(HB_ID, 0) <= 9, "%d heartbeats in 5 ms", log_count(HB_ID, 0));
	for (i = log_find(HB_ID, 0); log_find(HB_ID, i + 1) >= 0; i = log_find(HB_ID, i + 1)) {
	}
	zassert_equal(bus_log[i].frame.data[0], 0x7f, "the last one is the state now");
}

static struct {
	int n;
	uint32_t abort_code;
	size_t size;
} con;

static void sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	con.n++;
	con.abort_code = abort_code;
	con.size = size;
}

/*
 * A peer that answers SDO too late (CiA 301 §7.2.4.3.17): the node's client uploads 1000h
 * from node 2 with a 100 ms timeout; node 2 answers after 150 ms. At 100 ms the client sends
 * abort 05040000h and confirms with it; the late answer is ignored (no frame, no second
 * confirmation). No EMCY, state and LEDs as before.
 */
ZTEST(co_faults, test_sdo_answer_too_late)
{
	const uint8_t answer[8] = {0x43, 0x00, 0x10, 0x00, 0x91, 0x01, 0x0f, 0x00};
	struct co_sdo_cli *cli = co_sdo_cli_get(&t.node, 0);
	struct co_sdo_cli_stats st;
	uint8_t buf[4];
	uint64_t start = now;
	int i;

	memset(&con, 0, sizeof(con));
	zassert_not_null(cli);
	zassert_ok(co_sdo_cli_upload_req(cli, 0x1000, 0, buf, sizeof(buf), CO_SDO_CLI_AUTO, 100,
					 sdo_con, NULL));
	run_for(150 * MS);
	peer_send(peer_dev, CLI_RX, 8, answer);
	run_for(100 * MS);
	dump("late", 0);
	zassert_equal(log_count(CLI_TX, 0), 2, "request and abort");
	i = log_find(CLI_TX, log_find(CLI_TX, 0) + 1);
	zassert_equal(bus_log[i].frame.data[0], 0x80);
	zassert_equal(sdo_abort_code(i), 0x05040000);
	zassert_true(bus_log[i].at - start >= 100 * MS && bus_log[i].at - start < 110 * MS);
	zassert_equal(con.n, 1);
	zassert_equal(con.abort_code, 0x05040000U);
	co_sdo_cli_get_stats(cli, &st);
	zassert_equal(st.rx_stray, 1U, "the late answer ignored");
	expect_emcys(0, NULL, 0);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * A peer that answers SDO twice: an expedited answer sent twice is confirmed once, the copy
 * ignored; a segment of a segmented upload sent twice arrives when the client waits for the
 * other toggle value: abort 05030000h (CiA 301 §7.2.4.3.5), confirmed with it. No EMCY,
 * state and LEDs as before.
 */
ZTEST(co_faults, test_sdo_answered_twice)
{
	const uint8_t exp[8] = {0x43, 0x00, 0x10, 0x00, 0x91, 0x01, 0x0f, 0x00};
	const uint8_t init[8] = {0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0};
	const uint8_t seg0[8] = {0x00, 'S', 'a', 'f', 'e', 'L', 'i', 'n'};
	struct co_sdo_cli *cli = co_sdo_cli_get(&t.node, 0);
	uint8_t buf[16];
	int i;

	memset(&con, 0, sizeof(con));
	zassert_ok(
		co_sdo_cli_upload_req(cli, 0x1000, 0, buf, 4, CO_SDO_CLI_AUTO, 500, sdo_con, NULL));
	run_for(5 * MS);
	peer_send(peer_dev, CLI_RX, 8, exp);
	peer_send(peer_dev, CLI_RX, 8, exp);
	run_for(50 * MS);
	zassert_equal(con.n, 1);
	zassert_equal(con.abort_code, 0U);
	zassert_equal(log_count(CLI_TX, 0), 1, "the copy is not answered");

	memset(&con, 0, sizeof(con));
	i = n_log;
	zassert_ok(co_sdo_cli_upload_req(cli, 0x1008, 0, buf, sizeof(buf), CO_SDO_CLI_AUTO, 500,
					 sdo_con, NULL));
	run_for(5 * MS);
	peer_send(peer_dev, CLI_RX, 8, init);
	run_for(5 * MS);
	peer_send(peer_dev, CLI_RX, 8, seg0);
	run_for(5 * MS);
	peer_send(peer_dev, CLI_RX, 8, seg0);
	run_for(50 * MS);
	dump("twice", i);
	zassert_equal(log_count(CLI_TX, i), 4, "initiate, segment 0 and 1 requests, abort");
	i = log_find(CLI_TX, log_find(CLI_TX, log_find(CLI_TX, log_find(CLI_TX, i) + 1) + 1) + 1);
	zassert_equal(bus_log[i].frame.data[0], 0x80);
	zassert_equal(sdo_abort_code(i), 0x05030000);
	zassert_equal(con.n, 1);
	zassert_equal(con.abort_code, 0x05030000U);
	expect_emcys(0, NULL, 0);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * SYNC lost (CiA 301 §7.2.5): node 2 stops producing SYNC. The synchronous TPDO 1 stops with
 * it; the stack has no SYNC timeout (CiA 301 requires none), so nothing else happens.
 */
ZTEST(co_faults, test_sync_lost)
{
	for (int k = 0; k < 10; k++) {
		peer_send(peer_dev, 0x080, 0, NULL);
		run_for(10 * MS);
	}
	zassert_equal(log_count(TPDO1_ID, 0), 10, "TPDO 1 on every SYNC");
	run_for(1000 * MS);
	zassert_equal(log_count(TPDO1_ID, 0), 10, "no SYNC, no TPDO 1");
	expect_emcys(0, NULL, 0);
	zassert_equal(reg1001(), 0x00);
	zassert_equal(t.n_hb, 0);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * SYNC counter jump (CiA 301 §7.2.5, 1019h = 10): counters 1, 2, 3, 7, 8. A consumer has no
 * rule for a gap; TPDO 1 (type 1) goes out on each SYNC, no EMCY, nothing shown.
 */
ZTEST(co_faults, test_sync_counter_jump)
{
	const uint8_t counters[] = {1, 2, 3, 7, 8};

	od_write(0x1019, 0, 10, 1);
	for (size_t k = 0; k < ARRAY_SIZE(counters); k++) {
		peer_send(peer_dev, 0x080, 1, &counters[k]);
		run_for(10 * MS);
	}
	zassert_equal(log_count(TPDO1_ID, 0), 5, "TPDO 1 on every SYNC");
	expect_emcys(0, NULL, 0);
	zassert_equal(reg1001(), 0x00);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * RPDO too short (CiA 301 §7.2.2.2, Table 21): RPDO 1 maps two bytes, one arrives. Not
 * processed, EMCY 8210h, ERR blinking (error register), state kept; a frame of the right
 * length is processed and clears it.
 */
ZTEST(co_faults, test_rpdo_too_short)
{
	static const uint16_t want[] = {0x8210, 0x11, 0x0000, 0x00};
	const uint8_t out[2] = {0x56, 0x78};

	peer_send(peer_dev, RPDO1_ID, 1, out);
	run_for(20 * MS);
	dump("short", 0);
	expect_emcys(0, want, 1);
	zassert_equal(od_u8(0x6200, 1), 0, "not processed");
	zassert_equal(reg1001(), 0x11);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_BLINK);

	peer_send(peer_dev, RPDO1_ID, 2, out);
	run_for(20 * MS);
	expect_emcys(0, want, 2);
	zassert_equal(od_u8(0x6200, 1), 0x56);
	zassert_equal(reg1001(), 0x00);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}

/*
 * RPDO timeout (CiA 301 §7.5.2.35 event timer of an RPDO, CiA 303-3): 1400h sub5 = 100 ms;
 * one RPDO, then none: EMCY 8250h, ERR quadruple flash, state kept; the next RPDO clears it.
 */
ZTEST(co_faults, test_rpdo_timeout)
{
	static const uint16_t want[] = {0x8250, 0x11, 0x0000, 0x00};
	const uint8_t out[2] = {1, 2};
	uint64_t last;
	int i;

	od_write(0x1400, 5, 100, 2);
	peer_send(peer_dev, RPDO1_ID, 2, out);
	run_for(MS);
	last = now;
	run_for(300 * MS);
	dump("rpdo timeout", 0);
	expect_emcys(0, want, 1);
	i = log_find(EMCY_ID, 0);
	zassert_true(bus_log[i].at - last >= 99 * MS && bus_log[i].at - last <= 102 * MS,
		     "8250h %u us after the RPDO", (unsigned int)(bus_log[i].at - last));
	zassert_equal(reg1001(), 0x11);
	expect_state(CO_NMT_OPERATIONAL);
	expect_leds(CO_LED_ON, CO_LED_FLASH4);

	peer_send(peer_dev, RPDO1_ID, 2, out);
	run_for(20 * MS);
	expect_emcys(0, want, 2);
	zassert_equal(reg1001(), 0x00);
	expect_leds(CO_LED_ON, CO_LED_OFF);
}
