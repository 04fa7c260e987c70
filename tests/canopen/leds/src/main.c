/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * CiA 303-3 indicators on simulated time. The node (5) drives LEDs 0 (green) and 1 (red) of
 * the virtual LED device; the tests sample what the device shows every 10 ms, as a camera
 * would, and compare the on/off times with the patterns (±10 %). Errors come from the real
 * services: the heartbeat consumer of node 2 (100 ms), SYNC, RPDO 1's 100 ms event timer, and
 * the line's controller state.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>
#include <zephyr/ztest.h>

#include <canopen/leds.h>
#include <canopen/node.h>

#include <led_virtual.h>

#include "line_internal.h"

#include "co_sim.h"
#include "leds_test_od.h"

#define NODE_ID  5
#define MS       1000ULL
#define SAMPLE   (10 * MS)
#define MAX_RUNS 64
#define GREEN    0U
#define RED      1U

static struct {
	struct co_node node;
	struct leds_test_od_ram ram;
} t;

static const struct device *leds;

/* While set, node 2's heartbeat / RPDO 1 arrive every 50 ms during sampling. */
static bool feed_heartbeat;
static bool feed_rpdo;

static void heartbeat_of_2(void);

static void boot(uint8_t node_id, bool bicolour)
{
	const struct co_leds_cfg cfg = {
		.dev = leds, .green = GREEN, .red = RED, .bicolour = bicolour};

	memset(&t, 0, sizeof(t));
	feed_heartbeat = false;
	feed_rpdo = false;
	co_sim_init();
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &leds_test_od_def, &t.ram, node_id));
	zassert_ok(co_leds_attach(&t.node, &cfg));
	zassert_ok(co_node_start(&t.node));
}

static void *suite_setup(void)
{
	leds = device_get_binding("led_virtual0");
	zassert_not_null(leds);
	return NULL;
}

static void before(void *f)
{
	boot(NODE_ID, false);
}

ZTEST_SUITE(co_leds, NULL, suite_setup, before, NULL, NULL);

/* --- Sampling ------------------------------------------------------------------------------- */

struct run {
	bool on;
	uint32_t ms;
};

struct trace {
	bool green[1000];
	bool red[1000];
	int n;
};

/* Sample both LEDs of the device every 10 ms for @p ms, the stack's state agreeing. */
static void sample(struct trace *tr, uint32_t ms)
{
	tr->n = 0;
	for (uint32_t at = 0; at < ms && tr->n < (int)ARRAY_SIZE(tr->green); at += 10) {
		bool g, r, sg, sr;

		co_sim_run_until(sim.now + SAMPLE);
		if (feed_heartbeat && at % 50U == 0U) {
			heartbeat_of_2();
		}
		if (feed_rpdo && at % 50U == 0U) {
			const uint8_t v = 1;

			co_sim_rx(0x205, 1, &v);
		}
		zassert_ok(led_virtual_get(leds, GREEN, &g));
		zassert_ok(led_virtual_get(leds, RED, &r));
		co_leds_get(&t.node, &sg, &sr);
		zassert_equal(g, sg, "green output at %u ms", (unsigned int)(sim.now / MS));
		zassert_equal(r, sr, "red output at %u ms", (unsigned int)(sim.now / MS));
		tr->green[tr->n] = g;
		tr->red[tr->n] = r;
		tr->n++;
	}
}

/* Complete runs (the first and last, cut by the window, are dropped). */
static int runs_of(const bool *s, int n, struct run *out)
{
	int k = 0;
	int start = 0;

	for (int i = 1; i <= n && k < MAX_RUNS; i++) {
		if (i == n || s[i] != s[start]) {
			if (start > 0 && i < n) {
				out[k++] = (struct run){s[start], (uint32_t)(i - start) * 10U};
			}
			start = i;
		}
	}
	return k;
}

/*
 * The LED's complete runs follow the cycle @p want (on/off durations [ms], starting with an
 * "on"), each within ±10 %, at least @p cycles times over.
 */
static void expect_cycle(const bool *s, int n, const uint32_t *want, int n_want, int cycles,
			 const char *what)
{
	struct run r[MAX_RUNS];
	int k = runs_of(s, n, r);
	int first = -1;

	/* Align on the run that starts the cycle: the "on" before the longest "off". */
	for (int i = 0; i < k && first < 0; i++) {
		bool match = r[i].on;

		for (int j = 0; match && j < n_want && i + j < k; j++) {
			uint32_t w = want[j];

			match = r[i + j].on == (j % 2 == 0) && r[i + j].ms * 10 >= w * 9 &&
				r[i + j].ms * 10 <= w * 11;
		}
		if (match) {
			first = i;
		}
	}
	zassert_true(first >= 0, "%s: no cycle found (%d runs, first %s %u ms)", what, k,
		     k > 0 && r[0].on ? "on" : "off", k > 0 ? r[0].ms : 0);
	zassert_true(k - first >= n_want * cycles, "%s: %d runs, want %d", what, k - first,
		     n_want * cycles);
	for (int i = first; i < k; i++) {
		uint32_t w = want[(i - first) % n_want];

		zassert_equal(r[i].on, (i - first) % n_want % 2 == 0, "%s: run %d level", what, i);
		zassert_true(r[i].ms * 10 >= w * 9 && r[i].ms * 10 <= w * 11,
			     "%s: run %d is %u ms, want %u", what, i, r[i].ms, w);
	}
}

static void expect_steady(const bool *s, int n, bool on, const char *what)
{
	for (int i = 0; i < n; i++) {
		zassert_equal(s[i], on, "%s: sample %d", what, i);
	}
}

static const uint32_t flicker[] = {50, 50};
static const uint32_t blink[] = {200, 200};
static const uint32_t flash1[] = {200, 1000};
static const uint32_t flash2[] = {200, 200, 200, 1000};
static const uint32_t flash3[] = {200, 200, 200, 200, 200, 1000};
static const uint32_t flash4[] = {200, 200, 200, 200, 200, 200, 200, 1000};

static struct trace tr;

static void heartbeat_of_2(void)
{
	const uint8_t st = 0x05;

	co_sim_rx(0x702, 1, &st);
}

static void line_state(enum can_state state)
{
	co_line_inject_event(&sim.line, CO_LINE_EV_CAN_STATE, state);
}

/* --- RUN LED (40-43) ------------------------------------------------------------------------ */

ZTEST(co_leds, test_40_pre_operational_blinks_green_red_off)
{
	sample(&tr, 2000);
	expect_cycle(tr.green, tr.n, blink, 2, 3, "green");
	expect_steady(tr.red, tr.n, false, "red");
}

ZTEST(co_leds, test_41_stopped_single_flash)
{
	co_sim_nmt(CO_NMT_CS_STOP, NODE_ID);
	sample(&tr, 4000);
	expect_cycle(tr.green, tr.n, flash1, 2, 2, "green");
}

ZTEST(co_leds, test_42_operational_green_steady)
{
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	sample(&tr, 1000);
	expect_steady(tr.green, tr.n, true, "green");
}

ZTEST(co_leds, test_43_unconfigured_red_flickers_green_off)
{
	boot(CO_NODE_ID_UNCONFIGURED, false);
	sample(&tr, 1000);
	expect_cycle(tr.red, tr.n, flicker, 2, 5, "red");
	expect_steady(tr.green, tr.n, false, "green");
}

static void lss_switch_global(uint8_t mode)
{
	const uint8_t f[8] = {0x04, mode};

	co_sim_rx(0x7E5, 8, f);
}

ZTEST(co_leds, test_43_lss_configuration_green_flickers_in_antiphase_with_red)
{
	boot(CO_NODE_ID_UNCONFIGURED, false);
	lss_switch_global(1);
	sample(&tr, 1000);
	expect_cycle(tr.green, tr.n, flicker, 2, 5, "green");
	expect_cycle(tr.red, tr.n, flicker, 2, 5, "red");
	for (int i = 0; i < tr.n; i++) {
		zassert_false(tr.green[i] && tr.red[i], "antiphase at sample %d", i);
	}
	lss_switch_global(0);
	sample(&tr, 500);
	expect_steady(tr.green, tr.n, false, "green back to Initialising");
}

ZTEST(co_leds, test_lss_configuration_of_a_configured_node_over_its_nmt_state)
{
	lss_switch_global(1);
	sample(&tr, 1000);
	expect_cycle(tr.green, tr.n, flicker, 2, 5, "green");
	expect_steady(tr.red, tr.n, false, "red");
	lss_switch_global(0);
	sample(&tr, 2000);
	expect_cycle(tr.green, tr.n, blink, 2, 3, "green: Pre-operational again");
}

/* --- ERR LED (44, 45) ----------------------------------------------------------------------- */

ZTEST(co_leds, test_44_heartbeat_timeout_double_flash_cleared_when_heartbeats_return)
{
	enum co_led_pattern err;

	heartbeat_of_2();
	co_sim_run_until(sim.now + 150 * MS);
	co_leds_get_patterns(&t.node, NULL, &err);
	zassert_equal(err, CO_LED_FLASH2);
	sample(&tr, 4000);
	expect_cycle(tr.red, tr.n, flash2, 4, 2, "red");
	feed_heartbeat = true;
	sample(&tr, 1600);
	/* Cleared within one cycle; the EMCY's error register may blink until 8130h clears. */
	co_leds_get_patterns(&t.node, NULL, &err);
	zassert_true(err == CO_LED_OFF || err == CO_LED_BLINK, "pattern %d", err);
	expect_steady(&tr.red[160], tr.n - 160, false, "red after the heartbeat returned");
}

ZTEST(co_leds, test_45_priority_sync_over_heartbeat_rpdo_over_sync_bus_off_over_all)
{
	const uint8_t one = 1;
	enum co_led_pattern err;

	heartbeat_of_2();
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	co_sim_rx(0x205, 1, &one);            /* RPDO 1 once: its event timer runs */
	co_sim_rx(0x080, 1, &one);            /* a SYNC of the wrong length: 8240h */
	co_sim_run_until(sim.now + 150 * MS); /* heartbeat lost, RPDO timeout */
	co_leds_get_patterns(&t.node, NULL, &err);
	zassert_equal(err, CO_LED_FLASH4, "RPDO timeout over SYNC and heartbeat");
	sample(&tr, 7500);
	expect_cycle(tr.red, tr.n, flash4, 8, 2, "red quadruple");

	feed_rpdo = true; /* the RPDO is back: SYNC error and heartbeat remain */
	sample(&tr, 5000);
	expect_cycle(tr.red, tr.n, flash3, 6, 2, "red triple");

	line_state(CAN_STATE_BUS_OFF);
	sample(&tr, 500);
	expect_steady(tr.red, tr.n, true, "bus-off");
	line_state(CAN_STATE_ERROR_ACTIVE);
	co_sim_rx(0x080, 0, NULL); /* a good SYNC clears 8240h: the heartbeat's double flash */
	co_leds_get_patterns(&t.node, NULL, &err);
	zassert_equal(err, CO_LED_FLASH2);
}

ZTEST(co_leds, test_warning_limit_single_flash_and_error_register_blinks)
{
	enum co_led_pattern err;

	line_state(CAN_STATE_ERROR_PASSIVE);
	sample(&tr, 4000);
	expect_cycle(tr.red, tr.n, flash1, 2, 2, "red single flash");
	line_state(CAN_STATE_ERROR_ACTIVE);
	co_leds_get_patterns(&t.node, NULL, &err);
	/* The passive state raised EMCY 8120h, still in the error register until cleared. */
	zassert_true(err == CO_LED_BLINK || err == CO_LED_OFF);
}

/* --- Bicolour and antiphase (46, 47) -------------------------------------------------------- */

ZTEST(co_leds, test_46_bicolour_bus_off_in_operational_turns_green_off)
{
	boot(NODE_ID, true);
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	sample(&tr, 200);
	expect_steady(tr.green, tr.n, true, "green before");
	line_state(CAN_STATE_BUS_OFF);
	sample(&tr, 1000);
	expect_steady(tr.red, tr.n, true, "red");
	expect_steady(tr.green, tr.n, false, "green under red");
}

ZTEST(co_leds, test_46_two_leds_both_on_without_bicolour)
{
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	line_state(CAN_STATE_BUS_OFF);
	sample(&tr, 500);
	expect_steady(tr.red, tr.n, true, "red");
	expect_steady(tr.green, tr.n, true, "green");
}

ZTEST(co_leds, test_47_antiphase_green_blink_red_single_flash)
{
	int red_on = 0;

	line_state(CAN_STATE_ERROR_WARNING);
	sample(&tr, 4000);
	expect_cycle(tr.green, tr.n, blink, 2, 3, "green");
	expect_cycle(tr.red, tr.n, flash1, 2, 2, "red");
	for (int i = 0; i < tr.n; i++) {
		zassert_false(tr.green[i] && tr.red[i], "both on at sample %d", i);
		red_on += tr.red[i];
	}
	zassert_true(red_on > 0);
}

ZTEST(co_leds, test_antiphase_flicker_and_blink_of_both_leds)
{
	/* An unconfigured node's red flicker never meets a green that is on: green is off. */
	boot(CO_NODE_ID_UNCONFIGURED, true);
	sample(&tr, 500);
	for (int i = 0; i < tr.n; i++) {
		zassert_false(tr.green[i] && tr.red[i]);
	}
}

ZTEST(co_leds, test_steady_leds_arm_no_timer)
{
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_line_next_deadline(&sim.line), UINT64_MAX,
		      "green on, red off: nothing to time");
	co_sim_nmt(CO_NMT_CS_ENTER_PRE_OPERATIONAL, NODE_ID);
	zassert_true(co_line_next_deadline(&sim.line) != UINT64_MAX, "blinking needs ticks");
}

ZTEST(co_leds, test_attach_refuses_bad_configuration)
{
	struct co_leds_cfg cfg = {.dev = leds, .green = CO_LED_NONE, .red = CO_LED_NONE};

	zassert_equal(co_leds_attach(&t.node, &cfg), -EINVAL);
	cfg.dev = NULL;
	cfg.green = 0;
	zassert_equal(co_leds_attach(&t.node, &cfg), -EINVAL);
	zassert_equal(co_leds_attach(&t.node, NULL), -EINVAL);
}

ZTEST(co_leds, test_single_led_device_drives_only_its_led)
{
	const struct co_leds_cfg cfg = {.dev = leds, .green = CO_LED_NONE, .red = 2};
	bool on;

	bool g0, r0, g1, r1;

	zassert_ok(led_virtual_get(leds, GREEN, &g0));
	zassert_ok(led_virtual_get(leds, RED, &r0));
	zassert_ok(co_leds_attach(&t.node, &cfg));
	line_state(CAN_STATE_BUS_OFF);
	co_sim_run_until(sim.now + 100 * MS);
	zassert_ok(led_virtual_get(leds, 2, &on));
	zassert_true(on);
	line_state(CAN_STATE_ERROR_ACTIVE);
	for (int i = 0; i < 200; i++) {
		bool red;

		co_sim_run_until(sim.now + SAMPLE);
		zassert_ok(led_virtual_get(leds, 2, &on));
		co_leds_get(&t.node, NULL, &red);
		zassert_equal(on, red, "LED 2 follows the ERR pattern");
	}
	zassert_ok(led_virtual_get(leds, GREEN, &g1));
	zassert_ok(led_virtual_get(leds, RED, &r1));
	zassert_true(g0 == g1 && r0 == r1, "the other LEDs are not driven any more");
}
