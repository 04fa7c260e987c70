/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The node core on simulated time: listeners and vetoes, a node on two lines sending on each
 * route, a node without node-ID that stays silent until it gets one, an initialisation that
 * fails and leaves nothing behind, and the lock rule's alarm.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/node.h>

#include "co_sim.h"
#include "line_internal.h"
#include "node_test_od.h"

#define NODE_ID 0x21
#define MS      1000ULL

/* The scenario canopen.core.node.lock_rule: the lock rule's alarm, on purpose. */
static bool lock_rule_fault(const void *state)
{
	return IS_ENABLED(CONFIG_TEST_LOCK_RULE_FAULT) && IS_ENABLED(CONFIG_CANOPEN_LOCK_CHECK);
}

/* What one listener saw. */
struct seen {
	struct co_listener l;
	int n;
	enum co_event_type type[16];
	enum co_nmt_state to[16];
	uint8_t line_idx[16];
	/* Order across listeners: the global count when this one was called last. */
	int order;
	/* Return this for CO_EV_NMT_VETO. */
	int veto;
	/* Remove itself from its own handler. */
	bool remove_self;
};

static struct {
	struct co_node node;
	struct node_test_od_ram ram;
	struct seen a, b, c;
	int calls;
	/* The redundant line of the two-line test and what it sent. */
	struct co_line line2;
	struct can_frame sent2[32];
	int n_sent2;
} t;

static int listener(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct seen *s = user_data;

	if (s->n < (int)ARRAY_SIZE(s->type)) {
		s->type[s->n] = ev->type;
		s->to[s->n] = (ev->type == CO_EV_NMT_STATE || ev->type == CO_EV_NMT_VETO ||
			       ev->type == CO_EV_NMT_LEAVE)
				      ? ev->nmt.to
				      : CO_NMT_INITIALISING;
		s->line_idx[s->n] = ev->type == CO_EV_LINE ? ev->line.idx : 0xFFU;
		s->n++;
	}
	s->order = ++t.calls;
	if (s->remove_self) {
		co_node_listener_remove(node, &s->l);
	}
	return ev->type == CO_EV_NMT_VETO ? s->veto : 0;
}

static int sink2(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	zassert_true(t.n_sent2 < (int)ARRAY_SIZE(t.sent2));
	t.sent2[t.n_sent2++] = *frame;
	return 0;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	co_sim_init();
	co_line_init_sim(&t.line2, "sim2", sink2, NULL);
	zassert_ok(co_node_init(&t.node, "dut", &sim.line, &node_test_od_def, &t.ram, NODE_ID));
}

static void add(struct seen *s, const char *name, uint32_t mask)
{
	co_listener_init(&s->l, name, mask, listener, s);
	zassert_ok(co_node_listener_add(&t.node, &s->l));
}

static int count_id(const struct can_frame *frames, int n, uint32_t id)
{
	int c = 0;

	for (int i = 0; i < n; i++) {
		c += frames[i].id == id ? 1 : 0;
	}
	return c;
}

/* --- Listeners -------------------------------------------------------------------------- */

ZTEST(co_node, test_three_listeners_see_one_event_in_registration_order)
{
	add(&t.a, "a", CO_EV_BIT(CO_EV_NMT_STATE));
	add(&t.b, "b", CO_EV_BIT(CO_EV_NMT_STATE));
	add(&t.c, "c", CO_EV_BIT(CO_EV_NMT_STATE));
	zassert_ok(co_node_start(&t.node));
	t.a.n = t.b.n = t.c.n = 0;

	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_START));
	for (struct seen *s = &t.a; s <= &t.c; s++) {
		zassert_equal(s->n, 1, "each listener gets the event once");
		zassert_equal(s->type[0], CO_EV_NMT_STATE);
		zassert_equal(s->to[0], CO_NMT_OPERATIONAL);
	}
	zassert_true(t.a.order < t.b.order && t.b.order < t.c.order, "registration order");
}

ZTEST(co_node, test_listener_gets_only_the_events_of_its_mask)
{
	add(&t.a, "nmt", CO_EV_BIT(CO_EV_NMT_STATE));
	add(&t.b, "sync", CO_EV_BIT(CO_EV_SYNC));
	zassert_ok(co_node_start(&t.node));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_START));
	co_sim_rx(0x080, 0, NULL);

	zassert_true(t.a.n >= 1);
	for (int i = 0; i < t.a.n; i++) {
		zassert_equal(t.a.type[i], CO_EV_NMT_STATE);
	}
	zassert_equal(t.b.n, 1, "one SYNC");
	zassert_equal(t.b.type[0], CO_EV_SYNC);
}

ZTEST(co_node, test_listener_registration_errors)
{
	struct co_listener nocb;

	co_listener_init(&nocb, "x", CO_EV_ALL, NULL, NULL);
	zassert_equal(co_node_listener_add(&t.node, &nocb), -EINVAL);
	zassert_equal(co_node_listener_add(NULL, &t.a.l), -EINVAL);
	add(&t.a, "a", CO_EV_ALL);
	zassert_equal(co_node_listener_add(&t.node, &t.a.l), -EALREADY);

	co_node_listener_remove(&t.node, &t.a.l);
	co_node_listener_remove(&t.node, &t.a.l); /* safe twice */
	zassert_ok(co_node_start(&t.node));
	zassert_equal(t.a.n, 0, "a removed listener hears nothing");
	zassert_ok(co_node_listener_add(&t.node, &t.a.l), "and may be added again");
}

ZTEST(co_node, test_listener_may_remove_itself_from_its_handler)
{
	add(&t.a, "a", CO_EV_BIT(CO_EV_NMT_STATE));
	add(&t.b, "b", CO_EV_BIT(CO_EV_NMT_STATE));
	t.a.remove_self = true;
	zassert_ok(co_node_start(&t.node));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_START));

	zassert_equal(t.a.n, 1, "removed after its first event");
	zassert_true(t.b.n >= 2, "the next listener still gets every event");
}

/* --- Vetoes ----------------------------------------------------------------------------- */

static int app_veto;

static int app_state_ind(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
			 void *user_data)
{
	return to == CO_NMT_OPERATIONAL ? app_veto : 0;
}

ZTEST(co_node, test_vetoes_compose_and_name_who_refused)
{
	int err = 0;

	app_veto = 0;
	co_nmt_set_state_ind(&t.node, app_state_ind, NULL);
	add(&t.a, "accepts", CO_EV_BIT(CO_EV_NMT_VETO));
	add(&t.b, "srdo-check", CO_EV_BIT(CO_EV_NMT_VETO));
	add(&t.c, "never-asked", CO_EV_BIT(CO_EV_NMT_VETO));
	t.b.veto = -EACCES;
	zassert_ok(co_node_start(&t.node));
	zassert_is_null(co_nmt_get_refusal(&t.node, NULL), "nothing refused yet");

	zassert_equal(co_nmt_req(&t.node, CO_NMT_CS_START), -EPERM);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_str_equal(co_nmt_get_refusal(&t.node, &err), "srdo-check");
	zassert_equal(err, -EACCES);
	zassert_equal(t.a.n, 1, "asked");
	zassert_equal(t.c.n, 0, "the first refusal ends the round");

	/* From the bus, the same. */
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);

	/* The application refuses first. */
	app_veto = -EBUSY;
	t.b.veto = 0;
	zassert_equal(co_nmt_req(&t.node, CO_NMT_CS_START), -EPERM);
	zassert_str_equal(co_nmt_get_refusal(&t.node, &err), "application");
	zassert_equal(err, -EBUSY);

	/* Everyone agrees: the change happens, and the reset forgets the refusal. */
	app_veto = 0;
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_START));
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_OPERATIONAL);
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_is_null(co_nmt_get_refusal(&t.node, NULL));
}

static enum co_nmt_state state_at_leave;

static int leave_listener(struct co_node *node, const struct co_event *ev, void *user_data)
{
	state_at_leave = node->nmt.state;
	return listener(node, ev, user_data);
}

ZTEST(co_node, test_leave_is_raised_before_the_change_and_only_when_decided)
{
	co_listener_init(&t.a.l, "leave", CO_EV_BIT(CO_EV_NMT_LEAVE), leave_listener, &t.a);
	zassert_ok(co_node_listener_add(&t.node, &t.a.l));
	add(&t.b, "refuses-stop", CO_EV_BIT(CO_EV_NMT_VETO));
	zassert_ok(co_node_start(&t.node));
	zassert_equal(t.a.n, 1, "Initialising -> Pre-operational");

	t.b.veto = -EACCES;
	zassert_equal(co_nmt_req(&t.node, CO_NMT_CS_STOP), -EPERM);
	zassert_equal(t.a.n, 1, "a refused change raises no leave");

	t.b.veto = 0;
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_STOP));
	zassert_equal(t.a.n, 2);
	zassert_equal(t.a.type[1], CO_EV_NMT_LEAVE);
	zassert_equal(t.a.to[1], CO_NMT_STOPPED);
	zassert_equal(state_at_leave, CO_NMT_PRE_OPERATIONAL, "raised before the change");
}

ZTEST(co_node, test_resets_are_not_offered_for_a_veto)
{
	add(&t.a, "refuses-all", CO_EV_BIT(CO_EV_NMT_VETO) | CO_EV_BIT(CO_EV_NMT_RESET));
	t.a.veto = -EPERM;
	zassert_ok(co_node_start(&t.node));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_RESET_NODE));
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(t.a.type[0], CO_EV_NMT_RESET, "told of the start's reset");
	zassert_equal(t.a.type[1], CO_EV_NMT_RESET, "and of the requested one");
	zassert_equal(t.a.n, 2, "never asked");
}

/* --- Events from the services ----------------------------------------------------------- */

ZTEST(co_node, test_heartbeat_loss_reaches_listeners_and_emcy)
{
	add(&t.a, "hb", CO_EV_BIT(CO_EV_HB) | CO_EV_BIT(CO_EV_ERROR) | CO_EV_BIT(CO_EV_EMCY));
	zassert_ok(co_node_start(&t.node));
	/* Consume node 5's heartbeat with 100 ms. */
	zassert_equal(co_sim_write(&t.node, 0x1016, 1, 0x00050064U, 4), 0U);
	co_sim_rx(0x705, 1, (const uint8_t[]){0x05});
	co_sim_run_until(sim.now + 200 * MS);

	bool hb_lost = false;
	bool error = false;
	bool emcy = false;

	for (int i = 0; i < t.a.n; i++) {
		hb_lost |= t.a.type[i] == CO_EV_HB;
		error |= t.a.type[i] == CO_EV_ERROR;
		emcy |= t.a.type[i] == CO_EV_EMCY;
	}
	zassert_true(hb_lost && error && emcy, "HB event, the error, and the EMCY it became");
	zassert_equal(count_id(sim.sent, sim.n_sent, 0x80 + NODE_ID), 1, "EMCY 8130h sent");
}

/* --- Two lines and routes --------------------------------------------------------------- */

ZTEST(co_node, test_node_on_two_lines_sends_on_each_route)
{
	struct can_frame f = {.id = 0x555, .dlc = 1, .data = {0xAA}};
	struct co_rx rx1;
	struct co_rx rx2;

	if (!IS_ENABLED(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)) {
		ztest_test_skip(); /* test_one_line_node_sends_every_route_on_its_line */
	}
	zassert_equal(co_node_attach_line(&t.node, CO_LINE_DEFAULT, &t.line2), -EINVAL);
	zassert_equal(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &sim.line), -EALREADY,
		      "the default line again");
	zassert_ok(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line2));
	zassert_equal(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line2), -EALREADY);
	zassert_equal_ptr(co_node_get_line(&t.node, CO_LINE_REDUNDANT), &t.line2);
	zassert_ok(co_node_start(&t.node));
	zassert_equal(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line2), -EBUSY);
	sim.n_sent = 0;
	t.n_sent2 = 0;

	co_node_lock(&t.node);
	zassert_ok(co_node_send(&t.node, CO_ROUTE_DEFAULT, &f));
	zassert_ok(co_node_send(&t.node, CO_ROUTE_REDUNDANT, &f));
	zassert_ok(co_node_send(&t.node, CO_ROUTE_BOTH, &f));
	zassert_ok(co_node_send(&t.node, CO_ROUTE_ACTIVE, &f));
	co_node_unlock(&t.node);
	zassert_equal(count_id(sim.sent, sim.n_sent, 0x555), 3, "default, both, active");
	zassert_equal(count_id(t.sent2, t.n_sent2, 0x555), 2, "redundant, both");

	/* Switch the active line. */
	zassert_equal(co_node_set_active_line(&t.node, 5), -EINVAL);
	zassert_ok(co_node_set_active_line(&t.node, CO_LINE_REDUNDANT));
	co_node_lock(&t.node);
	zassert_ok(co_node_send(&t.node, CO_ROUTE_ACTIVE, &f));
	co_node_unlock(&t.node);
	zassert_equal(count_id(sim.sent, sim.n_sent, 0x555), 3);
	zassert_equal(count_id(t.sent2, t.n_sent2, 0x555), 3, "active is now the redundant line");

	/* Receivers per line, and the route that answers them. */
	co_rx_init(&rx1, 0x321, NULL, &t.node.lock, NULL);
	co_rx_init(&rx2, 0x321, NULL, &t.node.lock, NULL);
	co_node_lock(&t.node);
	zassert_ok(co_node_rx_register(&t.node, CO_LINE_DEFAULT, &rx1));
	zassert_ok(co_node_rx_register(&t.node, CO_LINE_REDUNDANT, &rx2));
	zassert_equal(co_node_route_of(&t.node, &rx1), CO_ROUTE_DEFAULT);
	zassert_equal(co_node_route_of(&t.node, &rx2), CO_ROUTE_REDUNDANT);
	co_node_unlock(&t.node);
	co_rx_unregister(&rx1);
	co_rx_unregister(&rx2);
}

ZTEST(co_node, test_route_to_a_missing_line_is_refused)
{
	struct can_frame f = {.id = 0x555, .dlc = 0};
	struct co_rx rx;

	co_node_lock(&t.node);
	zassert_equal(co_node_send(&t.node, CO_ROUTE_REDUNDANT, &f), -ENODEV);
	zassert_ok(co_node_send(&t.node, CO_ROUTE_BOTH, &f), "both = the lines there are");
	co_rx_init(&rx, 0x321, NULL, &t.node.lock, NULL);
	zassert_equal(co_node_rx_register(&t.node, CO_LINE_REDUNDANT, &rx), -ENODEV);
	zassert_equal(co_node_tx_space(&t.node, CO_ROUTE_REDUNDANT), 0);
	co_node_unlock(&t.node);
}

/*
 * A node with its default line alone, whether it could have a second one or not (scenario
 * canopen.core.node.one_line: CONFIG_CANOPEN_NODE_REDUNDANT_LINE=n, where
 * co_node_attach_line() refuses the second one): every route that includes the default line
 * is that line, whatever the process route and the excluded lines say.
 */
ZTEST(co_node, test_one_line_node_sends_every_route_on_its_line)
{
	static const co_route_t routes[] = {CO_ROUTE_DEFAULT, CO_ROUTE_BOTH, CO_ROUTE_ACTIVE,
					    CO_ROUTE_PROCESS, CO_ROUTE_EC};
	struct can_frame f = {.id = 0x555, .dlc = 1, .data = {0xAA}};
	struct co_rx rx;
	int space;

	zassert_ok(co_node_start(&t.node));
	zassert_equal(co_node_set_active_line(&t.node, CO_LINE_REDUNDANT), -EINVAL);
	zassert_ok(co_node_set_active_line(&t.node, CO_LINE_DEFAULT));
	zassert_equal(co_node_set_process_route(&t.node, CO_ROUTE_DEFAULT), -EINVAL);
	zassert_ok(co_node_set_process_route(&t.node, CO_ROUTE_ACTIVE));
	co_node_set_tx_excluded(&t.node, CO_ROUTE_DEFAULT);
	sim.n_sent = 0;

	co_node_lock(&t.node);
	for (size_t i = 0; i < ARRAY_SIZE(routes); i++) {
		zassert_ok(co_node_send(&t.node, routes[i], &f), "route %02x", routes[i]);
	}
	zassert_equal(co_node_send(&t.node, CO_ROUTE_REDUNDANT, &f), -ENODEV);
	space = co_node_tx_space(&t.node, CO_ROUTE_DEFAULT);
	zassert_true(space > 0);
	zassert_equal(co_node_tx_space(&t.node, CO_ROUTE_EC), space);
	zassert_equal(co_node_tx_space(&t.node, CO_ROUTE_ACTIVE), space);
	zassert_equal(co_node_tx_space(&t.node, CO_ROUTE_REDUNDANT), 0);
	zassert_equal(co_node_rx_line(&t.node), CO_LINE_DEFAULT);
	zassert_equal(co_node_active_line(&t.node), CO_LINE_DEFAULT);
	co_rx_init(&rx, 0x321, NULL, &t.node.lock, NULL);
	zassert_ok(co_node_rx_register(&t.node, CO_LINE_DEFAULT, &rx));
	zassert_equal(co_node_route_of(&t.node, &rx), CO_ROUTE_DEFAULT);
	co_node_unlock(&t.node);
	co_rx_unregister(&rx);
	zassert_equal(count_id(sim.sent, sim.n_sent, 0x555), (int)ARRAY_SIZE(routes));
	zassert_is_null(co_node_get_line(&t.node, CO_LINE_REDUNDANT));
}

ZTEST(co_node, test_second_line_refused_only_on_a_one_line_node)
{
	int err;

	err = co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line2);
	if (IS_ENABLED(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)) {
		zassert_ok(err);
		zassert_equal(CO_NODE_LINES, 2U);
		zassert_equal_ptr(co_node_get_line(&t.node, CO_LINE_REDUNDANT), &t.line2);
	} else {
		zassert_equal(err, -ENOTSUP);
		zassert_equal(co_node_attach_line(&t.node, CO_LINE_DEFAULT, NULL), -ENOTSUP,
			      "whatever the arguments");
		zassert_equal(CO_NODE_LINES, 1U);
		zassert_is_null(co_node_get_line(&t.node, CO_LINE_REDUNDANT));
	}
	zassert_ok(co_node_start(&t.node), "the node runs on its default line either way");
	zassert_equal(co_nmt_get_state(&t.node), CO_NMT_PRE_OPERATIONAL);
}

ZTEST(co_node, test_line_events_name_their_line)
{
	bool two = IS_ENABLED(CONFIG_CANOPEN_NODE_REDUNDANT_LINE);

	add(&t.a, "lines", CO_EV_BIT(CO_EV_LINE));
	zassert_equal(co_node_attach_line(&t.node, CO_LINE_REDUNDANT, &t.line2),
		      two ? 0 : -ENOTSUP);
	zassert_ok(co_node_start(&t.node));

	co_line_inject_event(&sim.line, CO_LINE_EV_CAN_STATE, CAN_STATE_ERROR_PASSIVE);
	co_line_inject_event(&t.line2, CO_LINE_EV_RX_OVERRUN, 0);
	zassert_equal(t.a.n, two ? 2 : 1, "a line the node is not on is not heard");
	zassert_equal(t.a.line_idx[0], CO_LINE_DEFAULT);
	if (two) {
		zassert_equal(t.a.line_idx[1], CO_LINE_REDUNDANT);
	}
}

/* --- Stopped ---------------------------------------------------------------------------- */

static int blocked;

static int slow_sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	if (blocked) {
		return -EAGAIN;
	}
	zassert_true(t.n_sent2 < (int)ARRAY_SIZE(t.sent2));
	t.sent2[t.n_sent2++] = *frame;
	return 0;
}

ZTEST(co_node, test_stopped_node_sends_nothing_it_queued_before)
{
	static struct co_line slow;
	static struct co_node n;
	static struct node_test_od_ram ram;
	static const uint8_t sdo_read[8] = {0x40, 0x00, 0x10, 0x00};
	struct can_frame f = {.id = 0x600 + 9, .dlc = 8};
	struct can_frame stop = {.id = 0x000, .dlc = 2, .data = {CO_NMT_CS_STOP, 9}};

	memcpy(f.data, sdo_read, 8);
	blocked = 0;
	co_line_init_sim(&slow, "slow", slow_sink, NULL);
	zassert_ok(co_node_init(&n, "n9", &slow, &node_test_od_def, &ram, 9));
	zassert_ok(co_node_start(&n));
	blocked = 1;
	/* An SDO request: its answer waits in the line's queue (back-pressure). */
	zassert_equal(co_line_rx(&slow, &f, 1000), 1);
	zassert_ok(co_nmt_req(&n, CO_NMT_CS_START));
	zassert_equal(co_line_rx(&slow, &stop, 2000), 1);
	zassert_equal(co_nmt_get_state(&n), CO_NMT_STOPPED);

	t.n_sent2 = 0;
	blocked = 0;
	co_line_process(&slow, 3000);
	co_line_process(&slow, 1003000);
	for (int i = 0; i < t.n_sent2; i++) {
		zassert_equal(t.sent2[i].id, 0x709, "only error control in Stopped, not %03x",
			      t.sent2[i].id);
	}
	zassert_true(t.n_sent2 >= 1, "the heartbeat still goes out");
	co_line_detach(&slow, &n.lines[CO_LINE_DEFAULT].member);
}

/*
 * What the node queued while its controller pushed back is withdrawn on every route that
 * includes its line, and on none without it; receivers move on that line only.
 */
ZTEST(co_node, test_one_line_node_withdraws_and_moves_receivers_on_its_line)
{
	static struct co_line slow;
	static struct co_node n;
	static struct node_test_od_ram ram;
	struct can_frame f = {.id = 0x555, .dlc = 0};
	struct co_rx rx;
	int space;

	blocked = 0;
	co_line_init_sim(&slow, "slow", slow_sink, NULL);
	zassert_ok(co_node_init(&n, "n9", &slow, &node_test_od_def, &ram, 9));
	zassert_ok(co_node_start(&n));
	blocked = 1;
	co_node_lock(&n);
	space = co_node_tx_space(&n, CO_ROUTE_PROCESS);
	for (int i = 0; i < 3; i++) {
		zassert_ok(co_node_send(&n, CO_ROUTE_PROCESS, &f), "queued");
	}
	zassert_equal(co_node_tx_space(&n, CO_ROUTE_PROCESS), space - 3);
	zassert_equal(co_node_tx_withdraw(&n, CO_ROUTE_REDUNDANT, NULL, NULL), 0);
	zassert_equal(co_node_tx_withdraw(&n, CO_ROUTE_EC, NULL, NULL), 3);
	zassert_equal(co_node_tx_space(&n, CO_ROUTE_DEFAULT), space);

	co_rx_init(&rx, 0x321, NULL, &n.lock, NULL);
	zassert_equal(co_node_rx_set_id(&n, CO_LINE_REDUNDANT, &rx, 0x322), -ENODEV);
	zassert_ok(co_node_rx_set_id(&n, CO_LINE_DEFAULT, &rx, 0x322));
	zassert_equal_ptr(rx.line, &slow);
	co_node_unlock(&n);
	co_rx_unregister(&rx);
	blocked = 0;
	co_line_detach(&slow, &n.lines[CO_LINE_DEFAULT].member);
}

/* --- Unconfigured node-ID --------------------------------------------------------------- */

ZTEST(co_node, test_unconfigured_node_stays_silent_until_it_gets_an_id)
{
	static const uint8_t sdo_read[8] = {0x40, 0x00, 0x10, 0x00};
	struct co_node n;
	struct node_test_od_ram ram;

	zassert_equal(co_node_init(&n, "nid", &sim.line, &node_test_od_def, &ram, 0), -EINVAL);
	zassert_equal(co_node_init(&n, "nid", &sim.line, &node_test_od_def, &ram, 128), -EINVAL);
	zassert_ok(co_node_init(&n, "nid", &sim.line, &node_test_od_def, &ram,
				CO_NODE_ID_UNCONFIGURED));
	zassert_ok(co_node_start(&n));
	zassert_equal(co_node_id(&n), CO_NODE_ID_UNCONFIGURED);

	/* Everything a configured node would answer or act on. */
	co_sim_nmt(CO_NMT_CS_START, 0);
	co_sim_nmt(CO_NMT_CS_RESET_COMMUNICATION, 0);
	co_sim_nmt(CO_NMT_CS_START, CO_NODE_ID_UNCONFIGURED);
	co_sim_rx(0x600, 8, sdo_read);
	co_sim_rx(0x67F, 8, sdo_read);
	co_sim_rx(0x6FF, 8, sdo_read);
	co_sim_rx(0x080, 0, NULL);
	co_sim_rx_flags(0x77F, 0, NULL, CAN_FRAME_RTR);
	co_sim_rx_flags(0x7FF, 0, NULL, CAN_FRAME_RTR);
	co_sim_run_until(sim.now + 5000 * MS);
	zassert_equal(sim.n_sent, 0, "silent: no boot-up, heartbeat, SDO answer or PDO");
	zassert_equal(co_nmt_get_state(&n), CO_NMT_INITIALISING);
	zassert_equal(co_nmt_req(&n, CO_NMT_CS_START), -EBUSY, "only a reset leaves it");

	/* LSS's part: a pending ID, then Reset Communication. */
	zassert_equal(co_node_set_pending_id(&n, 0), -EINVAL);
	zassert_ok(co_node_set_pending_id(&n, 0x05));
	zassert_ok(co_nmt_req(&n, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(co_node_id(&n), 0x05);
	zassert_equal(co_nmt_get_state(&n), CO_NMT_PRE_OPERATIONAL);
	zassert_true(sim.n_sent >= 1);
	zassert_equal(sim.sent[0].id, 0x705, "boot-up with the new ID");
	zassert_equal(sim.sent[0].data[0], 0x00);
	co_sim_run_until(sim.now + 1000 * MS);
	zassert_equal(count_id(sim.sent, sim.n_sent, 0x705), 2, "then heartbeats (1017h)");

	/* Back to unconfigured: silent again after the next reset. */
	zassert_ok(co_node_set_pending_id(&n, CO_NODE_ID_UNCONFIGURED));
	zassert_ok(co_nmt_req(&n, CO_NMT_CS_RESET_COMMUNICATION));
	zassert_equal(co_nmt_get_state(&n), CO_NMT_INITIALISING);
	sim.n_sent = 0;
	co_sim_run_until(sim.now + 3000 * MS);
	zassert_equal(sim.n_sent, 0);
	co_line_detach(&sim.line, &n.lines[CO_LINE_DEFAULT].member);
}

/* --- Initialisation that fails ----------------------------------------------------------- */

/*
 * In the scenario canopen.core.node.unwind the node's hook table is too small for every
 * service: SYNC's initialisation fails after error control and EMCY have registered their
 * hooks and listener and the node its line receivers, listener and membership.
 */
static bool small_hook_table(const void *state)
{
	return CONFIG_CANOPEN_OD_HOOKS_MAX < 12;
}

static bool full_hook_table(const void *state)
{
	return !small_hook_table(state) && !lock_rule_fault(state);
}

ZTEST(co_node_unwind, test_failed_init_leaves_nothing_behind)
{
	static struct co_line line;
	static struct co_node n;
	static struct node_test_od_ram ram;
	struct can_frame nmt = {.id = 0x000, .dlc = 2, .data = {CO_NMT_CS_START, 0}};

	co_line_init_sim(&line, "unwind", NULL, NULL);
	zassert_equal(co_node_init(&n, "bad", &line, &node_test_od_def, &ram, 7), -ENOSPC);
	zassert_equal(co_line_rx(&line, &nmt, 0), 0, "no receiver of the node is left");
	zassert_equal(co_line_next_deadline(&line), UINT64_MAX, "nor a timer");
	zassert_equal(line.n_nodes, 0, "nor the node itself");
	zassert_is_null(line.listeners, "nor its line listener");
	zassert_equal(n.od.n_hooks, 0, "and no hook, not even half of a service's");

	/* A batch that does not fit is not half registered. */
	const struct co_od_hook hooks[CONFIG_CANOPEN_OD_HOOKS_MAX + 1] = {
		[0 ... CONFIG_CANOPEN_OD_HOOKS_MAX] = {.index_first = 0x2000,
						       .index_last = 0x2000,
						       .notify = (co_od_notify_cb)1},
	};

	co_node_lock(&n);
	zassert_equal(co_od_hooks_register(&n.od, hooks, ARRAY_SIZE(hooks)), -ENOSPC);
	zassert_equal(n.od.n_hooks, 0, "rolled back");
	zassert_ok(co_od_hooks_register(&n.od, hooks, 2));
	zassert_equal(n.od.n_hooks, 2);
	co_node_unlock(&n);
}

/* Suites that do not belong to this scenario skip themselves (a suite that never runs fails). */
static void *unwind_setup(void)
{
	if (!small_hook_table(NULL)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST_SUITE(co_node_unwind, NULL, unwind_setup, NULL, NULL, NULL);

/* --- The lock rule ---------------------------------------------------------------------- */

static volatile unsigned int fatal_reason = UINT32_MAX;
static volatile bool expect_fatal;

void k_sys_fatal_error_handler(unsigned int reason, const struct arch_esf *esf)
{
	ARG_UNUSED(esf);
	if (!expect_fatal) {
		k_fatal_halt(reason);
	}
	fatal_reason = reason;
	/* Returning lets the system run on; only the faulting thread ends. */
}

static K_THREAD_STACK_DEFINE(breaker_stack, 4096);
static struct k_thread breaker;

static void read_without_lock(void *p1, void *p2, void *p3)
{
	uint8_t buf[4];
	size_t len;

	(void)co_od_read(co_node_od(&t.node), 0x1017, 0, 0, buf, sizeof(buf), &len,
			 CO_OD_WRITER_APP);
}

ZTEST(co_node_lock, test_dictionary_access_without_the_lock_stops_the_program)
{
	before(NULL);
	expect_fatal = true;
	fatal_reason = UINT32_MAX;
	k_thread_create(&breaker, breaker_stack, K_THREAD_STACK_SIZEOF(breaker_stack),
			read_without_lock, NULL, NULL, NULL, K_PRIO_PREEMPT(1), 0, K_NO_WAIT);
	zassert_ok(k_thread_join(&breaker, K_SECONDS(5)));
	expect_fatal = false;
	zassert_equal(fatal_reason, K_ERR_KERNEL_PANIC, "the accessor panicked");

	/* With the lock, the same read is fine. */
	uint8_t buf[4];
	size_t len;

	co_node_lock(&t.node);
	zassert_equal(co_od_read(co_node_od(&t.node), 0x1017, 0, 0, buf, sizeof(buf), &len,
				 CO_OD_WRITER_APP),
		      0U);
	co_node_unlock(&t.node);
}

static void *node_setup(void)
{
	/* Its tests put several nodes on one line. */
	if (!full_hook_table(NULL) || !IS_ENABLED(CONFIG_CANOPEN_SYNC) ||
	    !IS_ENABLED(CONFIG_CANOPEN_LINE_SHARED)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST_SUITE(co_node, NULL, node_setup, before, NULL, NULL);

static void *lock_setup(void)
{
	if (!lock_rule_fault(NULL)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST_SUITE(co_node_lock, NULL, lock_setup, NULL, NULL, NULL);

/* --- Synchronous PDOs need SYNC (scenario canopen.core.node.no_sync) ------------------------ */

static void *no_sync_setup(void)
{
	if (IS_ENABLED(CONFIG_CANOPEN_SYNC)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST(co_pdo_without_sync, test_synchronous_pdo_from_the_dictionary_stays_off)
{
	/* RPDO 2 of the dictionary is synchronous (1401h:02 = 1) on 300h + node-ID. */
	struct can_frame rpdo2 = {.id = 0x300 + NODE_ID, .dlc = 8};
	struct can_frame rpdo1 = {.id = 0x200 + NODE_ID, .dlc = 8};

	before(NULL);
	zassert_ok(co_node_start(&t.node));
	zassert_ok(co_nmt_req(&t.node, CO_NMT_CS_START));
	zassert_equal(co_line_rx(&sim.line, &rpdo2, sim.now), 0, "no receiver: the PDO is off");
	zassert_equal(co_line_rx(&sim.line, &rpdo1, sim.now), 1, "the event-driven one runs");
}

ZTEST(co_pdo_without_sync, test_synchronous_types_are_refused_06090030)
{
	before(NULL);
	zassert_ok(co_node_start(&t.node));
	/* RPDO 1 and TPDO 1: off first, as the mapping procedure wants. */
	zassert_equal(co_sim_write(&t.node, 0x1400, 1, 0x80000000U | (0x200U + NODE_ID), 4), 0U);
	zassert_equal(co_sim_write(&t.node, 0x1800, 1, 0x80000000U | (0x180U + NODE_ID), 4), 0U);

	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 0, 1), CO_SDO_AB_INVALID_VALUE, "acyclic");
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 1, 1), CO_SDO_AB_INVALID_VALUE, "cyclic");
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 240, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1400, 2, 254, 1), 0U, "event-driven is served");
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 0, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 10, 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(co_sim_write(&t.node, 0x1800, 2, 255, 1), 0U);
}

ZTEST_SUITE(co_pdo_without_sync, NULL, no_sync_setup, NULL, NULL, NULL);

/* --- One node per line (scenario canopen.core.node.line_alone) ------------------------------ */

ZTEST(co_node_line_nodes, test_second_node_on_a_line_refused_only_when_not_shared)
{
	static struct co_node a;
	static struct co_node b;
	static struct node_test_od_ram ram_a;
	static struct node_test_od_ram ram_b;
	const bool shared = IS_ENABLED(CONFIG_CANOPEN_LINE_SHARED);

	co_sim_init();
	zassert_ok(co_node_init(&a, "a", &sim.line, &node_test_od_def, &ram_a, NODE_ID));
	zassert_equal(co_node_init(&b, "b", &sim.line, &node_test_od_def, &ram_b, NODE_ID + 1),
		      shared ? 0 : -EBUSY);
	zassert_ok(co_node_start(&a));
	if (shared) {
		zassert_ok(co_node_start(&b));
	}
	/* The refused node left nothing on the line: the first one still gets its commands. */
	co_sim_nmt(CO_NMT_CS_START, NODE_ID);
	zassert_equal(co_nmt_get_state(&a), CO_NMT_OPERATIONAL);
	co_sim_nmt(CO_NMT_CS_START, 0);
	zassert_equal(co_nmt_get_state(&a), CO_NMT_OPERATIONAL);
	if (shared) {
		zassert_equal(co_nmt_get_state(&b), CO_NMT_OPERATIONAL);
		co_line_detach(&sim.line, &b.lines[CO_LINE_DEFAULT].member);
	}
	co_line_detach(&sim.line, &a.lines[CO_LINE_DEFAULT].member);
}

static void *line_nodes_setup(void)
{
	if (!full_hook_table(NULL)) {
		ztest_test_skip();
	}
	return NULL;
}

ZTEST_SUITE(co_node_line_nodes, NULL, line_nodes_setup, NULL, NULL, NULL);
