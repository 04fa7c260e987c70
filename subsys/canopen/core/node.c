/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The node core: a node's mutex, dictionary and lines; its NMT slave state machine (CiA 301
 * §7.3.2), which is the node's life cycle; its listeners; and the walk over its services.
 * The core knows services only as the const records it is handed (core/services.c), so no
 * service is called from here by name.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/node.h>

#include "line_internal.h"
#include "node_internal.h"

LOG_MODULE_REGISTER(co_node, CONFIG_CANOPEN_LOG_LEVEL);

/* --- Listeners ---------------------------------------------------------------------------- */

static void listen_mask_update(struct co_node *node)
{
	struct co_listener *l;
	uint32_t mask = 0U;

	SYS_SLIST_FOR_EACH_CONTAINER(&node->listeners, l, snode) {
		mask |= l->mask;
	}
	node->listen_mask = mask;
}

int co_node_listener_add(struct co_node *node, struct co_listener *l)
{
	int err = 0;

	if (node == NULL || l == NULL || l->cb == NULL) {
		return -EINVAL;
	}
	co_node_lock(node);
	if (l->owner != NULL) {
		err = -EALREADY;
	} else {
		l->owner = node;
		sys_slist_append(&node->listeners, &l->snode);
		node->listen_mask |= l->mask;
	}
	co_node_unlock(node);
	return err;
}

void co_node_listener_remove(struct co_node *node, struct co_listener *l)
{
	if (node == NULL || l == NULL) {
		return;
	}
	co_node_lock(node);
	if (l->owner == node) {
		(void)sys_slist_find_and_remove(&node->listeners, &l->snode);
		l->owner = NULL;
		listen_mask_update(node);
	}
	co_node_unlock(node);
}

/* A veto round: the first refusal ends it and names who refused. */
static __attribute__((noinline)) int veto_round(struct co_node *node, const struct co_event *ev,
						const char **who)
{
	struct co_listener *l;
	struct co_listener *next;

	SYS_SLIST_FOR_EACH_CONTAINER_SAFE(&node->listeners, l, next, snode) {
		if ((l->mask & CO_EV_BIT(CO_EV_NMT_VETO)) == 0U) {
			continue;
		}
		int ret = l->cb(node, ev, l->user_data);

		if (ret != 0) {
			if (who != NULL) {
				*who = l->name;
			}
			return ret;
		}
	}
	return 0;
}

int co_node_publish(struct co_node *node, const struct co_event *ev, const char **who)
{
	uint32_t bit = CO_EV_BIT(ev->type);
	sys_snode_t *sn;
	sys_snode_t *next;

	CO_ASSERT_LOCKED(&node->lock);
	if ((node->listen_mask & bit) == 0U) {
		return 0;
	}
	if (ev->type == CO_EV_NMT_VETO) {
		return veto_round(node, ev, who);
	}
	/* Next is taken before the call: a listener may remove itself from its handler. */
	for (sn = sys_slist_peek_head(&node->listeners); sn != NULL; sn = next) {
		struct co_listener *l = CONTAINER_OF(sn, struct co_listener, snode);

		next = sys_slist_peek_next_no_check(sn);
		if ((l->mask & bit) != 0U) {
			(void)l->cb(node, ev, l->user_data);
		}
	}
	return 0;
}

void co_node_error(struct co_node *node, uint16_t code, uint8_t reg_bits, uint8_t info,
		   uint8_t flags)
{
	struct co_event ev = {
		.type = CO_EV_ERROR,
		.error = {.code = code, .reg_bits = reg_bits, .info = info, .flags = flags},
	};

	(void)co_node_publish(node, &ev, NULL);
}

/* --- Services ----------------------------------------------------------------------------- */

/* Whether a service runs now: every service once the node has an ID, else only those marked. */
static bool service_runs(const struct co_node *node, const struct co_service *svc)
{
	return co_node_is_configured(node) || (svc->flags & CO_SERVICE_F_UNCONFIGURED) != 0U;
}

static void services_reset_comm(struct co_node *node)
{
	for (size_t i = 0; i < node->n_services; i++) {
		const struct co_service *svc = node->services[i];

		if (svc->reset_comm != NULL && service_runs(node, svc)) {
			svc->reset_comm(node);
		}
	}
}

static void services_set_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to)
{
	for (size_t i = 0; i < node->n_services; i++) {
		const struct co_service *svc = node->services[i];

		if (svc->set_state != NULL && service_runs(node, svc)) {
			svc->set_state(node, from, to);
		}
	}
}

/* --- NMT slave state machine -------------------------------------------------------------- */

const char *co_nmt_state_str(enum co_nmt_state state)
{
	switch (state) {
	case CO_NMT_INITIALISING:
		return "INITIALISING";
	case CO_NMT_STOPPED:
		return "STOPPED";
	case CO_NMT_OPERATIONAL:
		return "OPERATIONAL";
	case CO_NMT_PRE_OPERATIONAL:
		return "PRE-OPERATIONAL";
	default:
		return "?";
	}
}

/*
 * The NMT commands (CiA 301 §7.3.2.2, figure 48): each leads to one state from any of
 * Pre-operational, Operational and Stopped, or to a reset (the Initialising sub-states). A
 * command for the state the node is in changes nothing.
 */
static const struct nmt_transition {
	uint8_t cs;
	bool reset;
	enum co_nmt_state to;
} nmt_transitions[] = {
	{.cs = CO_NMT_CS_START, .to = CO_NMT_OPERATIONAL},
	{.cs = CO_NMT_CS_STOP, .to = CO_NMT_STOPPED},
	{.cs = CO_NMT_CS_ENTER_PRE_OPERATIONAL, .to = CO_NMT_PRE_OPERATIONAL},
	{.cs = CO_NMT_CS_RESET_NODE, .reset = true, .to = CO_NMT_INITIALISING},
	{.cs = CO_NMT_CS_RESET_COMMUNICATION, .reset = true, .to = CO_NMT_INITIALISING},
};

/*
 * Withdraw what the node queued on every line it has. The default line is there as long as
 * the node is initialised; only a second one can be missing.
 */
static inline __attribute__((always_inline)) void
purge_lines(struct co_node *node, bool (*keep)(const struct can_frame *f, void *arg), void *arg)
{
	(void)co_line_tx_purge(node->lines[CO_LINE_DEFAULT].line, &node->lock, keep, arg);
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	if (node->lines[CO_LINE_REDUNDANT].line != NULL) {
		(void)co_line_tx_purge(node->lines[CO_LINE_REDUNDANT].line, &node->lock, keep, arg);
	}
#endif
}

/* In Stopped a node sends NMT error control only (CiA 301 §7.3.2.2); NMT commands of a master. */
static bool stopped_may_send(const struct can_frame *f, void *arg)
{
	const struct co_node *node = arg;

	return f->id == CO_NMT_EC_COB_ID + node->node_id || f->id == CO_NMT_COB_ID;
}

static void nmt_enter(struct co_node *node, enum co_nmt_state to)
{
	enum co_nmt_state from = node->nmt.state;
	struct co_event ev = {.type = CO_EV_NMT_LEAVE, .nmt = {.from = from, .to = to}};

	(void)co_node_publish(node, &ev, NULL);
	ev.type = CO_EV_NMT_STATE;
	node->nmt.state = to;
	if (to == CO_NMT_STOPPED) {
		/* Frames queued before (an SDO answer held up by back-pressure) stay unsent. */
		purge_lines(node, stopped_may_send, node);
	}
	LOG_INF("%s: %s -> %s", node->name, co_nmt_state_str(from), co_nmt_state_str(to));
	services_set_state(node, from, to);
	(void)co_node_publish(node, &ev, NULL);
}

/*
 * A change among Pre-operational, Operational and Stopped, offered first to the application's
 * state indication, then to every veto listener; any refusal keeps the node where it is.
 */
static int nmt_change(struct co_node *node, enum co_nmt_state to)
{
	enum co_nmt_state from = node->nmt.state;
	struct co_event ev = {.type = CO_EV_NMT_VETO, .nmt = {.from = from, .to = to}};
	const char *who = "application";
	int veto = 0;

	if (from == to) {
		return 0;
	}
	if (node->nmt.state_ind != NULL) {
		veto = node->nmt.state_ind(node, from, to, node->nmt.state_user_data);
	}
	if (veto == 0) {
		veto = co_node_publish(node, &ev, &who);
	}
	if (veto != 0) {
		node->refused_by = who;
		node->refusal = veto;
		LOG_INF("%s: change to %s refused by %s (%d)", node->name, co_nmt_state_str(to),
			who, veto);
		return -EPERM;
	}
	nmt_enter(node, to);
	return 0;
}

static void send_bootup(struct co_node *node)
{
	struct can_frame f = {
		.id = CO_NMT_EC_COB_ID + node->node_id,
		.dlc = 1U,
		.data = {0U},
	};

	(void)co_node_send(node, CO_ROUTE_EC, &f);
}

/*
 * Reset Node or Reset Communication: Initialising, reload the dictionary areas, reconfigure
 * every service, boot-up, Pre-operational (and Operational when self-starting). A node
 * without node-ID stops in Initialising, silent, with only its unconfigured services
 * running (CiA 305 §8.1: it waits for LSS).
 */
static void nmt_reset(struct co_node *node, enum co_nmt_cs cs)
{
	struct co_event ev = {.type = CO_EV_NMT_RESET, .reset = {.cs = cs}};

	if (node->nmt.reset_ind != NULL) {
		node->nmt.reset_ind(node, cs, node->nmt.reset_user_data);
	}
	(void)co_node_publish(node, &ev, NULL);
	if (node->nmt.state != CO_NMT_INITIALISING) {
		nmt_enter(node, CO_NMT_INITIALISING);
	}
	/* What the node queued before (held by back-pressure or a stopped controller) belongs
	 * to the communication being reset, maybe to its old node-ID: it stays unsent.
	 */
	purge_lines(node, NULL, NULL);
	if (cs == CO_NMT_CS_RESET_NODE) {
		co_od_reset_app(&node->od);
	}
	/* A node-ID configured by LSS takes effect here (CiA 305 §8.3.2.1). */
	node->node_id = node->pending_node_id;
	(void)co_od_set_node_id(&node->od, node->node_id);
	co_od_reset_comm(&node->od);
	node->refused_by = NULL;
	node->refusal = 0;
	services_reset_comm(node);
	if (!co_node_is_configured(node)) {
		LOG_INF("%s: no node-ID, waiting in INITIALISING", node->name);
		return;
	}

	send_bootup(node);
	nmt_enter(node, CO_NMT_PRE_OPERATIONAL);
	if (node->nmt.autostart) {
		(void)nmt_change(node, CO_NMT_OPERATIONAL);
	}
}

static int nmt_command(struct co_node *node, uint8_t cs)
{
	const struct nmt_transition *t = NULL;

	for (size_t i = 0; i < ARRAY_SIZE(nmt_transitions); i++) {
		if (nmt_transitions[i].cs == cs) {
			t = &nmt_transitions[i];
			break;
		}
	}
	if (t == NULL) {
		return -EINVAL;
	}
	if (node->nmt.state == CO_NMT_INITIALISING) {
		/* Only a reset leaves Initialising, and only once the node runs: an unconfigured
		 * node is reset to take the node-ID LSS gave it.
		 */
		if (!node->started || co_node_is_configured(node) || !t->reset) {
			return -EBUSY;
		}
	}
	if (t->reset) {
		nmt_reset(node, (enum co_nmt_cs)cs);
		return 0;
	}
	return nmt_change(node, t->to);
}

/*
 * 000h: [cs, node-ID]. CiA 301 defines only DLC 2; other lengths, RTR frames, commands for
 * other nodes and unknown command specifiers are ignored without any reaction. A node
 * without node-ID takes no NMT command (CiA 305: only LSS reaches it).
 */
static void nmt_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	uint8_t target;

	ARG_UNUSED(now_us);
	if (frame->dlc != 2U || (frame->flags & CAN_FRAME_RTR) != 0U ||
	    !co_node_is_configured(node)) {
		return;
	}
	target = frame->data[1];
	if (target != 0U && target != node->node_id) {
		return;
	}
	(void)nmt_command(node, frame->data[0]);
}

enum co_nmt_state co_nmt_get_state(struct co_node *node)
{
	enum co_nmt_state state;

	co_node_lock(node);
	state = node->nmt.state;
	co_node_unlock(node);
	return state;
}

int co_nmt_req(struct co_node *node, enum co_nmt_cs cs)
{
	int err;

	co_node_lock(node);
	err = nmt_command(node, (uint8_t)cs);
	co_node_unlock(node);
	return err;
}

void co_nmt_set_state_ind(struct co_node *node, co_nmt_state_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->nmt.state_ind = cb;
	node->nmt.state_user_data = user_data;
	co_node_unlock(node);
}

void co_nmt_set_reset_ind(struct co_node *node, co_nmt_reset_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->nmt.reset_ind = cb;
	node->nmt.reset_user_data = user_data;
	co_node_unlock(node);
}

void co_nmt_set_autostart(struct co_node *node, bool autostart)
{
	co_node_lock(node);
	node->nmt.autostart = autostart;
	co_node_unlock(node);
}

const char *co_nmt_get_refusal(struct co_node *node, int *err)
{
	const char *who;

	co_node_lock(node);
	who = node->refused_by;
	if (err != NULL) {
		*err = node->refusal;
	}
	co_node_unlock(node);
	return who;
}

/* --- Lines -------------------------------------------------------------------------------- */

/* A line's events become the node's (CO_EV_LINE), with the line's index. */
static void line_event(struct co_line_listener *l, enum co_line_event event, int arg)
{
	struct co_node *node = l->user_data;
	struct co_event ev = {
		.type = CO_EV_LINE,
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
		.line = {.idx = (uint8_t)(l == &node->lines[CO_LINE_REDUNDANT].listener
						  ? CO_LINE_REDUNDANT
						  : CO_LINE_DEFAULT),
#else
		.line = {.idx = (uint8_t)CO_LINE_DEFAULT,
#endif
			 .event = event,
			 .arg = arg},
	};

	(void)co_node_publish(node, &ev, NULL);
}

static int line_join(struct co_node *node, enum co_node_line_id idx, struct co_line *line)
{
	struct co_node_line *nl = &node->lines[idx];
	int err;

	co_line_listener_init(&nl->listener, line_event, &node->lock, node);
	err = co_line_listener_add(line, &nl->listener);
	if (err != 0) {
		return err;
	}
	err = co_line_attach(line, &nl->member, &node->lock);
	if (err != 0) {
		co_line_listener_remove(&nl->listener);
		return err;
	}
	nl->line = line;
	return 0;
}

static void line_leave(struct co_node *node, enum co_node_line_id idx)
{
	struct co_node_line *nl = &node->lines[idx];

	if (nl->line != NULL) {
		co_line_listener_remove(&nl->listener);
		co_line_detach(nl->line, &nl->member);
		nl->line = NULL;
	}
}

#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_attach_line(struct co_node *node, enum co_node_line_id idx, struct co_line *line)
{
	int err;

	if (node == NULL || line == NULL || idx != CO_LINE_REDUNDANT) {
		return -EINVAL;
	}
	co_node_lock(node);
	if (node->started) {
		err = -EBUSY;
	} else if (node->lines[idx].line != NULL || node->lines[CO_LINE_DEFAULT].line == line) {
		err = -EALREADY;
	} else {
		err = line_join(node, idx, line);
	}
	co_node_unlock(node);
	return err;
}
#else
int co_node_attach_line(struct co_node *node, enum co_node_line_id idx, struct co_line *line)
{
	ARG_UNUSED(node);
	ARG_UNUSED(idx);
	ARG_UNUSED(line);
	return -ENOTSUP;
}
#endif

struct co_line *co_node_line(struct co_node *node)
{
	return node->lines[CO_LINE_DEFAULT].line;
}

struct co_line *co_node_get_line(struct co_node *node, enum co_node_line_id idx)
{
	return (unsigned int)idx < CO_NODE_LINES ? node->lines[idx].line : NULL;
}

#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
int co_node_set_active_line(struct co_node *node, enum co_node_line_id idx)
{
	int err = -EINVAL;

	co_node_lock(node);
	if ((unsigned int)idx < CO_NODE_LINES && node->lines[idx].line != NULL) {
		node->active_line = (uint8_t)idx;
		err = 0;
	}
	co_node_unlock(node);
	return err;
}

static inline co_route_t active_resolve(const struct co_node *node, co_route_t route)
{
	if ((route & CO_ROUTE_ACTIVE) != 0U) {
		route = (co_route_t)((route & ~CO_ROUTE_ACTIVE) | BIT(node->active_line));
	}
	return route;
}

static inline co_route_t route_resolve(const struct co_node *node, co_route_t route)
{
	co_route_t out = (co_route_t)(route & ~(CO_ROUTE_PROCESS | CO_ROUTE_EC));

	if ((route & (CO_ROUTE_PROCESS | CO_ROUTE_EC)) != 0U) {
		co_route_t lines = active_resolve(node, node->process_route);
		co_route_t live = (co_route_t)(lines & ~node->tx_excluded);

		/* Error control reaches every line; process data the lines that can send. */
		out |= ((route & CO_ROUTE_EC) != 0U || live == 0U) ? lines : live;
	}
	return active_resolve(node, out);
}

/*
 * Sending on a route other than the one line (co_node_send() in node.h takes that path
 * inline): every line of the route, the first error kept.
 */
int co_node_send_routed(struct co_node *node, co_route_t route, const struct can_frame *frame)
{
	int ret = -ENODEV;
	bool sent = false;

	CO_ASSERT_LOCKED(&node->lock);
	route = route_resolve(node, route);
	for (unsigned int i = 0; i < CO_NODE_LINES; i++) {
		struct co_line *line = node->lines[i].line;

		if ((route & BIT(i)) == 0U || line == NULL) {
			continue;
		}
		int err = co_line_send_from(line, frame, &node->lock);

		if (!sent || (ret == 0 && err != 0)) {
			ret = err;
		}
		sent = true;
	}
	return ret;
}

co_route_t co_node_route_of(const struct co_node *node, const struct co_rx *rx)
{
	/* rx->line is stable while the receiver's handler runs (it holds the node's mutex). */
	if (node->lines[CO_LINE_REDUNDANT].line == NULL) {
		return CO_ROUTE_DEFAULT;
	}
	return (node->rx_line == CO_LINE_REDUNDANT ||
		rx->line == node->lines[CO_LINE_REDUNDANT].line)
		       ? CO_ROUTE_REDUNDANT
		       : CO_ROUTE_DEFAULT;
}

int co_node_dispatch_from(struct co_node *node, enum co_node_line_id idx,
			  const struct can_frame *frame, uint64_t now_us)
{
	uint8_t outer = node->rx_line;
	int n;

	CO_ASSERT_LOCKED(&node->lock);
	node->rx_line = (uint8_t)idx;
	n = co_line_dispatch_sel(node->lines[CO_LINE_DEFAULT].line, frame, now_us, &node->lock,
				 true);
	node->rx_line = outer;
	return n;
}

void co_node_set_tx_excluded(struct co_node *node, co_route_t lines)
{
	co_node_lock(node);
	node->tx_excluded = (co_route_t)(lines & CO_ROUTE_BOTH);
	co_node_unlock(node);
}

int co_node_set_process_route(struct co_node *node, co_route_t route)
{
	if (route != CO_ROUTE_BOTH && route != CO_ROUTE_ACTIVE) {
		return -EINVAL;
	}
	co_node_lock(node);
	node->process_route = route;
	co_node_unlock(node);
	return 0;
}

int co_node_tx_withdraw(struct co_node *node, co_route_t route,
			bool (*keep)(const struct can_frame *frame, void *arg), void *arg)
{
	int n = 0;

	route = route_resolve(node, route);
	for (unsigned int i = 0; i < CO_NODE_LINES; i++) {
		if ((route & BIT(i)) != 0U && node->lines[i].line != NULL) {
			n += co_line_tx_purge(node->lines[i].line, &node->lock, keep, arg);
		}
	}
	return n;
}

int co_node_tx_space(struct co_node *node, co_route_t route)
{
	int space = INT32_MAX;

	route = route_resolve(node, route);
	for (unsigned int i = 0; i < CO_NODE_LINES; i++) {
		if ((route & BIT(i)) != 0U && node->lines[i].line != NULL) {
			space = MIN(space, co_line_tx_space(node->lines[i].line));
		}
	}
	return space == INT32_MAX ? 0 : space;
}

int co_node_rx_register(struct co_node *node, enum co_node_line_id idx, struct co_rx *rx)
{
	struct co_line *line = co_node_get_line(node, idx);

	return line != NULL ? co_rx_register(line, rx) : -ENODEV;
}

int co_node_rx_set_id(struct co_node *node, enum co_node_line_id idx, struct co_rx *rx, uint32_t id)
{
	struct co_line *line = co_node_get_line(node, idx);

	return line != NULL ? co_rx_set_id(line, rx, id) : -ENODEV;
}
#else
/* co_node_tx_withdraw(), _tx_space(), _rx_register(), _rx_set_id() are inline (node.h). */
int co_node_set_active_line(struct co_node *node, enum co_node_line_id idx)
{
	ARG_UNUSED(node);
	return idx == CO_LINE_DEFAULT ? 0 : -EINVAL;
}

void co_node_set_tx_excluded(struct co_node *node, co_route_t lines)
{
	/* A route never loses its last line. */
	ARG_UNUSED(node);
	ARG_UNUSED(lines);
}

int co_node_set_process_route(struct co_node *node, co_route_t route)
{
	ARG_UNUSED(node);
	return (route != CO_ROUTE_BOTH && route != CO_ROUTE_ACTIVE) ? -EINVAL : 0;
}
#endif

#if defined(CONFIG_CANOPEN_LOCK_CHECK)
void co_node_assert_locked(const struct co_node *node)
{
	CO_ASSERT_LOCKED(&node->lock);
}
#endif

void co_node_timer_start(struct co_node *node, struct co_timer *timer, uint64_t deadline_us)
{
	CO_ASSERT_LOCKED(&node->lock);
	co_timer_start(node->lines[CO_LINE_DEFAULT].line, timer, deadline_us);
}

uint64_t co_node_time(const struct co_node *node)
{
	return co_line_time(node->lines[CO_LINE_DEFAULT].line);
}

/* --- Life cycle --------------------------------------------------------------------------- */

int co_node_setup(struct co_node *node, const char *name, struct co_line *line,
		  const struct co_od_def *def, void *ram, uint8_t node_id,
		  const struct co_service *const *services, size_t n_services)
{
	int err;

	if (node == NULL || line == NULL || def == NULL || ram == NULL ||
	    !((node_id >= 1U && node_id <= 127U) || node_id == CO_NODE_ID_UNCONFIGURED) ||
	    n_services > UINT8_MAX) {
		return -EINVAL;
	}
	(void)memset(node, 0, sizeof(*node));
	(void)k_mutex_init(&node->lock);
	node->name = name;
	node->node_id = node_id;
	node->pending_node_id = node_id;
	node->nmt.state = CO_NMT_INITIALISING;
#if defined(CONFIG_CANOPEN_NODE_REDUNDANT_LINE)
	node->process_route = CO_ROUTE_BOTH;
#endif
	node->services = services;
	node->n_services = (uint8_t)n_services;
	sys_slist_init(&node->listeners);

	err = co_od_init(&node->od, def, ram, node_id);
	if (err != 0) {
		return err;
	}
	node->od.lock = &node->lock;

	co_node_lock(node);
	err = line_join(node, CO_LINE_DEFAULT, line);
	if (err == 0) {
		co_rx_init(&node->nmt_rx, CO_NMT_COB_ID, nmt_rx, &node->lock, node);
		err = co_node_rx_register(node, CO_LINE_DEFAULT, &node->nmt_rx);
	}
	for (size_t i = 0; err == 0 && i < n_services; i++) {
		const struct co_service *svc = services[i];

		if (svc->init != NULL) {
			err = svc->init(node);
			if (err != 0) {
				LOG_ERR("%s: %s: initialisation failed (%d)", name, svc->name, err);
			}
		}
	}
	if (err != 0) {
		/* Leaving the line drops every receiver and timer of the node's mutex. */
		line_leave(node, CO_LINE_DEFAULT);
		/* And a fresh dictionary drops every hook the services registered. */
		(void)co_od_init(&node->od, def, ram, node_id);
	}
	co_node_unlock(node);
	return err;
}

int co_node_start(struct co_node *node)
{
	int err = 0;

	co_node_lock(node);
	if (node->started) {
		err = -EALREADY;
	} else {
		node->started = true;
		nmt_reset(node, CO_NMT_CS_RESET_NODE);
	}
	co_node_unlock(node);
	return err;
}

void co_node_lock(struct co_node *node)
{
	(void)k_mutex_lock(&node->lock, K_FOREVER);
}

void co_node_unlock(struct co_node *node)
{
	(void)k_mutex_unlock(&node->lock);
}

struct co_od *co_node_od(struct co_node *node)
{
	return &node->od;
}

uint8_t co_node_id(const struct co_node *node)
{
	return node->node_id;
}

int co_node_set_pending_id(struct co_node *node, uint8_t node_id)
{
	if (!((node_id >= 1U && node_id <= 127U) || node_id == CO_NODE_ID_UNCONFIGURED)) {
		return -EINVAL;
	}
	co_node_lock(node);
	node->pending_node_id = node_id;
	co_node_unlock(node);
	return 0;
}
