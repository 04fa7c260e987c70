/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The DDS bridge: stack events to samples.
 *
 * Listeners (line threads, node lock held) and the heartbeat receiver (line thread, no lock)
 * only copy what they saw into a bounded queue or into atomics; they never wait. The bridge
 * thread applies the events to its tables (one record per line and node-ID, SRDOs) and writes
 * the samples. The request thread (requests.c) serves SDO and NMT requests. Neither holds a
 * node or line lock across a DDS call; br.lock (the tables) is never held while a node lock
 * is taken.
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <zephyr/drivers/can.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>

#include <canopen/bridge_dds.h>
#include <canopen/errctl.h>
#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/redundancy.h>
#if defined(CONFIG_CANOPEN_MGR)
#include <canopen/mgr.h>
#endif

#include "bridge_internal.h"
#include "loopback_xml.h"

LOG_MODULE_REGISTER(canopen_bridge_dds, CONFIG_CANOPEN_LOG_LEVEL);

#define TOPIC_BRIDGE "canopen/bridge_state"
#define TOPIC_LINE   "canopen/line_state"
#define TOPIC_NODE   "canopen/node_state"
#define TOPIC_EMCY   "canopen/emcy"
#define TOPIC_SRDO   "canopen/srdo_state"
#define TOPIC_VALUE  "canopen/od_value"
#define TOPIC_SDO_RQ "canopen/sdo/request"
#define TOPIC_SDO_RP "canopen/sdo/reply"
#define TOPIC_NMT_RQ "canopen/nmt/request"
#define TOPIC_NMT_RP "canopen/nmt/reply"

#define EMCY_HISTORY 16
#define STACK_SIZE   16384

struct br_state br;

/* --- Events ------------------------------------------------------------------------------- */

enum br_ev_kind {
	BR_EV_NMT,
	BR_EV_HB,
	BR_EV_HB_FRAME,
	BR_EV_LIFE,
	BR_EV_EMCY,
	BR_EV_LINE,
	BR_EV_BOOT,
	BR_EV_SRDO,
	BR_EV_SNAPSHOT,
	BR_EV_WAKE,
	BR_EV_ACTIVE,
};

struct br_event {
	uint64_t time_us;
	uint8_t kind;
	uint8_t slot;
	/* The node concerned. */
	uint8_t node_id;
	/* The bridged node that saw it (br.bnodes index). */
	uint8_t src;
	union {
		struct {
			uint8_t state;
		} nmt;
		struct {
			uint8_t what;
			uint8_t state;
		} hb;
		struct {
			/* The node's active line (enum co_node_line_id). */
			uint8_t line;
		} active;
		struct {
			bool lost;
		} life;
		struct {
			uint16_t code;
			uint16_t cob_id;
			uint8_t reg;
			uint8_t msef[5];
			bool own;
		} emcy;
		struct {
			uint8_t event;
			int32_t arg;
		} line;
		struct {
			uint8_t status;
		} boot;
		struct {
			uint8_t srdo;
			uint8_t reason;
			bool safe;
		} srdo;
	};
};

K_MSGQ_DEFINE(br_queue, sizeof(struct br_event), CONFIG_CANOPEN_BRIDGE_DDS_QUEUE_SIZE, 8);

static K_THREAD_STACK_DEFINE(bridge_stack, STACK_SIZE);
static K_THREAD_STACK_DEFINE(request_stack, STACK_SIZE);
static struct k_thread bridge_thread;
static struct k_thread request_thread;
static atomic_t started;

static uint64_t realtime_ns(void)
{
	struct timespec ts;

	(void)clock_gettime(CLOCK_REALTIME, &ts);
	return (uint64_t)ts.tv_sec * 1000000000ULL + (uint64_t)ts.tv_nsec;
}

uint64_t br_wall_ns(uint64_t line_us)
{
	return br.wall_base_ns + line_us * 1000ULL;
}

static void atomic_max(atomic_t *a, atomic_val_t v)
{
	atomic_val_t old = atomic_get(a);

	while (v > old && !atomic_cas(a, old, v)) {
		old = atomic_get(a);
	}
}

/* Line threads: never wait. A full queue loses the event, counted per line and in total. */
static void post(const struct br_event *e)
{
	if (k_msgq_put(&br_queue, e, K_NO_WAIT) != 0) {
		(void)atomic_inc(&br.events_lost);
		if (e->slot < CONFIG_CANOPEN_BRIDGE_DDS_LINES) {
			(void)atomic_inc(&br.lines[e->slot].events_lost);
		}
		return;
	}
	(void)atomic_inc(&br.events);
	atomic_max(&br.queue_max, (atomic_val_t)k_msgq_num_used_get(&br_queue));
}

/* The active line of bridged node @p b, for both lines it is on (CiA 302-6). */
static void post_active(const struct br_bnode *b, uint8_t line, uint64_t time_us)
{
	for (int i = 0; i < (int)CO_NODE_LINES; i++) {
		struct br_event e = {
			.kind = BR_EV_ACTIVE,
			.slot = b->slot[i],
			.src = b->idx,
			.node_id = b->node_id,
			.time_us = time_us,
			.active = {.line = line},
		};

		if (b->slot[i] != BR_NO_LINE &&
		    (i == (int)CO_LINE_DEFAULT || b->slot[i] != b->slot[CO_LINE_DEFAULT])) {
			post(&e);
		}
	}
}

/* Node events (line thread or the API caller, node lock held). */
static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct br_bnode *b = user_data;
	uint8_t own = co_node_id(node);
	struct br_event e = {
		.slot = b->slot[CO_LINE_DEFAULT],
		.src = b->idx,
		.node_id = own,
	};

	if (!atomic_get(&br.running) || own == 0U || own > 127U) {
		return 0;
	}
	e.time_us = co_node_time(node);
	switch (ev->type) {
	case CO_EV_NMT_STATE:
		/* A reset chose the default line again without a switch event. */
		post_active(b, co_node_active_line(node), e.time_us);
		e.kind = BR_EV_NMT;
		e.nmt.state = (uint8_t)ev->nmt.to;
		break;
	case CO_EV_REDUNDANCY:
		if (ev->redundancy.what == CO_RDN_EV_SWITCH) {
			post_active(b, ev->redundancy.line, e.time_us);
		}
		return 0;
	case CO_EV_HB:
		e.kind = BR_EV_HB;
		e.node_id = ev->hb.node_id;
		e.hb.what = (uint8_t)ev->hb.event;
		e.hb.state = (uint8_t)ev->hb.state;
		break;
	case CO_EV_LIFE:
		e.kind = BR_EV_LIFE;
		e.life.lost = ev->life.lost;
		break;
	case CO_EV_EMCY:
		e.kind = BR_EV_EMCY;
		e.node_id = ev->emcy.node_id;
		e.emcy.code = ev->emcy.code;
		e.emcy.cob_id = ev->emcy.cob_id;
		e.emcy.reg = ev->emcy.reg;
		e.emcy.own = ev->emcy.own;
		(void)memcpy(e.emcy.msef, ev->emcy.msef, sizeof(e.emcy.msef));
		break;
	case CO_EV_ERROR:
		/*
		 * A node that sends no EMCY (no valid 1014h) still reports its communication
		 * errors: published as emergencies with COB-ID 0 (not on the bus), a clear as
		 * 0000h.
		 */
		if ((co_od_uint(co_node_od(node), 0x1014U, 0U, BIT(31)) & BIT(31)) == 0U) {
			return 0;
		}
		e.kind = BR_EV_EMCY;
		e.emcy.own = true;
		if ((ev->error.flags & CO_ERROR_F_ACTIVE) != 0U) {
			e.emcy.code = ev->error.code;
			e.emcy.reg = ev->error.reg_bits;
		}
		e.emcy.msef[0] = ev->error.info;
		sys_put_le32(ev->error.detail, &e.emcy.msef[1]);
		break;
	case CO_EV_LINE:
		if (ev->line.idx >= CO_NODE_LINES || b->slot[ev->line.idx] == BR_NO_LINE) {
			return 0;
		}
		e.kind = BR_EV_LINE;
		e.slot = b->slot[ev->line.idx];
		e.line.event = (uint8_t)ev->line.event;
		e.line.arg = ev->line.arg;
		break;
	case CO_EV_BOOT:
		e.kind = BR_EV_BOOT;
		e.node_id = ev->boot.node_id;
		e.boot.status = (uint8_t)ev->boot.status;
		break;
	case CO_EV_SRDO:
		e.kind = BR_EV_SRDO;
		e.srdo.srdo = ev->srdo.srdo;
		e.srdo.safe = ev->srdo.safe;
		e.srdo.reason = ev->srdo.reason;
		e.time_us = ev->srdo.time_us;
		break;
	default:
		return 0;
	}
	if (e.node_id == 0U || e.node_id > 127U) {
		return 0;
	}
	post(&e);
	return 0;
}

#define EVENT_MASK                                                                                 \
	(CO_EV_BIT(CO_EV_NMT_STATE) | CO_EV_BIT(CO_EV_HB) | CO_EV_BIT(CO_EV_LIFE) |                \
	 CO_EV_BIT(CO_EV_ERROR) | CO_EV_BIT(CO_EV_EMCY) | CO_EV_BIT(CO_EV_LINE) |                  \
	 CO_EV_BIT(CO_EV_BOOT) | CO_EV_BIT(CO_EV_SRDO) | CO_EV_BIT(CO_EV_REDUNDANCY))

/*
 * Heartbeats, boot-ups and node-guarding replies (700h + node-ID), line thread, no lock: the
 * time of the last one per node goes into an atomic (the bridge thread publishes its age);
 * only a change of the reported state is an event.
 */
static void on_hb_frame(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct br_line *l = CONTAINER_OF(rx, struct br_line, hb_rx);
	uint32_t id = frame->id - CO_NMT_EC_COB_ID;
	uint8_t state;

	if (!atomic_get(&br.running) || (frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc < 1U ||
	    id == 0U || id > 127U) {
		return;
	}
	state = frame->data[0] & 0x7FU;
	atomic_set(&l->hb_us[id], (atomic_val_t)(now_us != 0U ? now_us : 1U));
	if (atomic_set(&l->hb_state[id], (atomic_val_t)state + 1) != (atomic_val_t)state + 1) {
		struct br_event e = {
			.kind = BR_EV_HB_FRAME,
			.slot = (uint8_t)(l - br.lines),
			.node_id = (uint8_t)id,
			.time_us = now_us,
			.nmt.state = state,
		};

		post(&e);
	}
}

/* --- Tables ------------------------------------------------------------------------------- */

int br_slot_of(uint8_t line_no)
{
	int n = (int)atomic_get(&br.n_lines);

	for (int i = 0; i < n; i++) {
		if (br.lines[i].line_no == line_no) {
			return i;
		}
	}
	return -1;
}

struct br_bnode *br_bnode_at(int slot, uint8_t node_id)
{
	int n = (int)atomic_get(&br.n_bnodes);

	for (int i = 0; i < n; i++) {
		if (br.bnodes[i].slot[CO_LINE_DEFAULT] == slot && br.bnodes[i].node_id == node_id) {
			return &br.bnodes[i];
		}
	}
	return NULL;
}

bool br_node_known(int slot, uint8_t node_id)
{
	bool known;

	if (slot < 0 || node_id == 0U || node_id > 127U) {
		return false;
	}
	(void)k_mutex_lock(&br.lock, K_FOREVER);
	known = br.lines[slot].rec_of[node_id].known ||
		atomic_get(&br.lines[slot].hb_us[node_id]) != 0 ||
		br_bnode_at(slot, node_id) != NULL ||
		br_conf_eds(&br.conf, br.lines[slot].line_no, node_id) != NULL;
	(void)k_mutex_unlock(&br.lock);
	return known;
}

void br_node_status(int slot, uint8_t node_id, uint8_t *nmt, uint8_t *hb)
{
	(void)k_mutex_lock(&br.lock, K_FOREVER);
	*nmt = br.lines[slot].rec_of[node_id].known ? br.lines[slot].rec_of[node_id].nmt
						    : BR_NMT_UNKNOWN;
	*hb = br.lines[slot].rec_of[node_id].hb;
	(void)k_mutex_unlock(&br.lock);
}

static struct br_node_rec *rec(int slot, uint8_t node_id)
{
	return &br.lines[slot].rec_of[node_id];
}

/* Make a record known (first time: the name from its EDS). */
static struct br_node_rec *touch(int slot, uint8_t node_id, uint64_t t_ns)
{
	struct br_node_rec *n = rec(slot, node_id);

	if (!n->known) {
		const struct br_eds *eds = br_conf_eds(&br.conf, br.lines[slot].line_no, node_id);

		n->known = true;
		n->nmt = BR_NMT_UNKNOWN;
		n->boot_status = BR_BOOT_NONE;
		if (n->name[0] == '\0' && eds != NULL) {
			(void)snprintf(n->name, sizeof(n->name), "%s", eds->product);
		}
	}
	n->dirty = true;
	n->time_ns = t_ns;
	return n;
}

static struct br_srdo_rec *srdo_rec(uint8_t slot, uint8_t node_id, uint8_t srdo)
{
	struct br_srdo_rec *free_rec = NULL;

	for (size_t i = 0; i < BR_SRDO_RECS; i++) {
		struct br_srdo_rec *s = &br.srdos[i];

		if (s->used && s->slot == slot && s->node_id == node_id && s->srdo == srdo) {
			return s;
		}
		if (!s->used && free_rec == NULL) {
			free_rec = s;
		}
	}
	if (free_rec != NULL) {
		*free_rec = (struct br_srdo_rec){
			.used = true, .slot = slot, .node_id = node_id, .srdo = srdo};
	}
	return free_rec;
}

/* --- Samples ------------------------------------------------------------------------------ */

int br_write(dds_entity_t wr, const void *sample)
{
	dds_return_t rc = dds_write(wr, sample);

	if (rc < 0) {
		LOG_WRN("dds_write: %s", dds_strretcode(rc));
		return -EIO;
	}
	(void)atomic_inc(&br.samples);
	return 0;
}

static void publish_node(int slot, uint8_t node_id)
{
	struct br_node_rec *n = rec(slot, node_id);
	safeline_canopen_v1_NodeState s = {
		.line = br.lines[slot].line_no,
		.node_id = node_id,
		.local = n->local,
		.nmt_state = n->nmt,
		.heartbeat = n->hb,
		.heartbeat_ns = n->hb_ns,
		.guarding = n->guarding,
		.boot_status = n->boot_status,
		.boot_ns = n->boot_ns,
		.identity_mask = n->id_mask,
		.device_type = n->ident[0],
		.vendor_id = n->ident[1],
		.product_code = n->ident[2],
		.revision = n->ident[3],
		.serial = n->ident[4],
		.error_register = n->err_reg,
		.emcy_count = n->emcy_count,
		.time_ns = n->time_ns,
	};

	(void)snprintf(s.name, sizeof(s.name), "%s", n->name);
	n->dirty = false;
	(void)br_write(br.wr_node, &s);
}

static void publish_line(int slot)
{
	struct br_line *l = &br.lines[slot];
	safeline_canopen_v1_LineState s = {
		.line = l->line_no,
		.can_state = l->can_state,
		.tx_err_cnt = l->tec,
		.rx_err_cnt = l->rec,
		.active_line = l->active_line,
		.rx_frames = l->stats.rx_frames,
		.tx_frames = l->stats.tx_frames,
		.rx_overruns = l->stats.rx_overruns,
		.rx_unhandled = l->stats.rx_unhandled,
		.tx_dropped = l->stats.tx_dropped,
		.tx_errors = l->stats.tx_errors,
		.events_lost = (uint32_t)atomic_get(&l->events_lost),
		.nodes = l->nodes,
		.time_ns = realtime_ns(),
	};

	(void)snprintf(s.name, sizeof(s.name), "%s", l->name);
	l->dirty = false;
	(void)br_write(br.wr_line, &s);
}

static void publish_bridge(void)
{
	safeline_canopen_v1_BridgeState s = {
		.domain_id = br.domain_id,
		.started_ns = br.started_ns,
		.time_ns = realtime_ns(),
		.lines = (uint32_t)atomic_get(&br.n_lines),
		.nodes = (uint32_t)atomic_get(&br.n_bnodes),
		.read_only = !br.conf.allow,
		.events = (uint32_t)atomic_get(&br.events),
		.events_lost = (uint32_t)atomic_get(&br.events_lost),
		.queue_max = (uint32_t)atomic_get(&br.queue_max),
		.queue_size = CONFIG_CANOPEN_BRIDGE_DDS_QUEUE_SIZE,
		.samples = (uint32_t)atomic_get(&br.samples) + 1U,
		.requests = (uint32_t)atomic_get(&br.requests),
		.refused = (uint32_t)atomic_get(&br.refused),
		.malformed = (uint32_t)atomic_get(&br.malformed),
		.replies_deferred = (uint32_t)atomic_get(&br.replies_deferred),
		.replies_lost = (uint32_t)atomic_get(&br.replies_lost),
	};

	(void)snprintf(s.bridge, sizeof(s.bridge), "%s", br.name);
	(void)snprintf(s.version, sizeof(s.version), "%s", BR_VERSION);
	(void)br_write(br.wr_bridge, &s);
}

static const char *srdo_reason_text(uint8_t reason)
{
	static const char *const names[] = {
		"none", "not operational", "starting",    "configuration", "SCT",
		"SRVT", "not inverted",    "short frame", "send failed",   "GFC",
	};

	return reason < ARRAY_SIZE(names) ? names[reason] : "?";
}

static void publish_srdo(const struct br_srdo_rec *r)
{
	safeline_canopen_v1_SrdoState s = {
		.line = br.lines[r->slot].line_no,
		.node_id = r->node_id,
		.srdo = r->srdo,
		.safe = r->safe,
		.reason = r->reason,
		.transitions = r->transitions,
		.time_ns = r->time_ns,
	};

	(void)snprintf(s.reason_text, sizeof(s.reason_text), "%s", srdo_reason_text(r->reason));
	(void)br_write(br.wr_srdo, &s);
}

void br_publish_value(struct br_object *o, uint32_t abort_code, const uint8_t *data, size_t len,
		      uint64_t now_us)
{
	int slot = br_slot_of(o->line_no);
	size_t keep = MIN(len, (size_t)BR_VALUE_MAX);
	const struct br_eds *eds;
	const struct br_eds_entry *ent;
	safeline_canopen_v1_OdValue s = {
		.line = o->line_no,
		.node_id = o->node_id,
		.index = o->index,
		.subindex = o->sub,
		.abort_code = abort_code,
		.size = (uint32_t)len,
	};

	if (data == NULL) {
		data = o->data;
		len = 0;
		keep = 0;
	}
	if (o->published && o->abort_code == abort_code && o->size == (uint32_t)len &&
	    memcmp(o->data, data, keep) == 0) {
		return;
	}
	o->published = true;
	o->abort_code = abort_code;
	o->size = (uint32_t)len;
	(void)memmove(o->data, data, keep);
	o->changes++;
	eds = br_conf_eds(&br.conf, o->line_no, o->node_id);
	ent = br_eds_find(eds, o->index, o->sub);
	if (ent != NULL) {
		s.data_type = ent->dtype;
	} else if (slot >= 0 && br_bnode_at(slot, o->node_id) != NULL) {
		struct co_node *node = br_bnode_at(slot, o->node_id)->node;
		struct co_od_info info;

		co_node_lock(node);
		if (co_od_find(co_node_od(node), o->index, o->sub, &info) == 0U) {
			s.data_type = info.dtype;
		}
		co_node_unlock(node);
	} else {
		/* An object neither the EDS nor the node knows keeps data type 0 (unknown). */
	}
	s.data._length = (uint32_t)keep;
	s.data._maximum = (uint32_t)keep;
	s.data._buffer = o->data;
	s.data._release = false;
	s.changes = o->changes;
	s.time_ns = br_wall_ns(now_us);
	(void)br_write(br.wr_value, &s);
}

uint32_t br_local_read(struct co_node *node, uint16_t index, uint8_t sub, uint8_t *buf, size_t cap,
		       size_t *len)
{
	struct co_od_info info;
	uint32_t ab;

	*len = 0;
	co_node_lock(node);
	ab = co_od_find(co_node_od(node), index, sub, &info);
	if (ab == 0U && co_od_length(co_node_od(node), &info) > cap) {
		ab = CO_SDO_AB_OUT_OF_MEM;
	}
	if (ab == 0U) {
		ab = co_od_read_info(co_node_od(node), &info, 0U, buf, cap, len, CO_OD_WRITER_SDO);
	}
	co_node_unlock(node);
	return ab;
}

uint64_t br_poll_local_objects(uint64_t now_us)
{
	uint64_t next = UINT64_MAX;
	uint8_t buf[BR_VALUE_MAX];

	for (int i = 0; i < br.conf.n_objects; i++) {
		struct br_object *o = &br.conf.objects[i];
		int slot = br_slot_of(o->line_no);
		struct br_bnode *b = slot >= 0 ? br_bnode_at(slot, o->node_id) : NULL;
		size_t len;
		uint32_t ab;

		if (b == NULL) {
			continue;
		}
		if (co_time_before_eq(o->next_us, now_us)) {
			ab = br_local_read(b->node, o->index, o->sub, buf, sizeof(buf), &len);
			br_publish_value(o, ab, buf, ab == 0U ? len : 0U, now_us);
			o->next_us = now_us + (uint64_t)o->interval_ms * 1000U;
		}
		next = MIN(next, o->next_us);
	}
	return next;
}

/* --- Applying events ------------------------------------------------------------------------ */

/* Identity and boot result of @p id as the manager @p b knows it (no bridge lock held). */
static void boot_info(struct br_bnode *b, int slot, uint8_t id, uint64_t t_ns, bool only_known)
{
#if defined(CONFIG_CANOPEN_MGR)
	struct co_mgr_boot_info info;
	struct br_node_rec *n;

	if (co_mgr_get_boot(b->node, id, &info) != 0) {
		return;
	}
	(void)k_mutex_lock(&br.lock, K_FOREVER);
	n = rec(slot, id);
	if (!only_known || n->known || info.assigned) {
		n = touch(slot, id, t_ns);
		if (info.status != CO_MGR_ST_NONE) {
			n->boot_status = info.status;
			n->boot_ns = br_wall_ns(info.finished_us);
		}
		if (info.read_mask != 0U) {
			n->id_mask = info.read_mask & 0x1FU;
			n->ident[0] = info.device_type;
			(void)memcpy(&n->ident[1], info.identity, sizeof(info.identity));
		}
		if (n->nmt == BR_NMT_UNKNOWN && !n->local && info.nmt_state != 0U) {
			n->nmt = info.nmt_state;
		}
	}
	(void)k_mutex_unlock(&br.lock);
#endif
}

/* Everything a bridged node knows, when it is added (no bridge lock held). */
static void snapshot(struct br_bnode *b, int slot, uint64_t t_ns)
{
	uint32_t ident[5] = {0};
	uint8_t mask = 0;
	enum co_nmt_state remote;
	uint8_t state = (uint8_t)co_nmt_get_state(b->node);
	struct br_node_rec *n;

	/* Its identity: 1000h and 1018h:01..04 of its own dictionary. */
	co_node_lock(b->node);
	for (unsigned int i = 0U; i < 5U; i++) {
		uint16_t index = i == 0U ? 0x1000U : 0x1018U;
		uint8_t sub = i == 0U ? 0U : (uint8_t)i;
		struct co_od_info info;

		if (co_od_find(co_node_od(b->node), index, sub, &info) == 0U) {
			ident[i] = co_od_uint(co_node_od(b->node), index, sub, 0U);
			mask |= BIT(i);
		}
	}
	co_node_unlock(b->node);

	(void)k_mutex_lock(&br.lock, K_FOREVER);
	n = touch(slot, b->node_id, t_ns);
	n->local = true;
	n->nmt = state;
	n->id_mask = mask;
	(void)memcpy(n->ident, ident, sizeof(ident));
	if (b->name[0] != '\0') {
		(void)snprintf(n->name, sizeof(n->name), "%s", b->name);
	}
	(void)k_mutex_unlock(&br.lock);

	for (uint8_t id = 1; id <= 127U; id++) {
		int err;

		if (id == b->node_id) {
			continue;
		}
		err = co_hb_get_remote_state(b->node, id, &remote);
		if (err != -ENOENT) {
			(void)k_mutex_lock(&br.lock, K_FOREVER);
			n = touch(slot, id, t_ns);
			if (err == 0) {
				n->hb = BR_HB_ACTIVE;
				n->nmt = (uint8_t)remote;
			} else if (n->hb == BR_HB_NONE) {
				n->hb = BR_HB_WAITING;
			} else {
				/* Still waiting or already seen: nothing new to record. */
			}
			(void)k_mutex_unlock(&br.lock);
		}
		boot_info(b, slot, id, t_ns, true);
	}
}

/* The controller's state and error counters now (not for a simulation line). */
static void read_can_state(struct br_line *l)
{
	enum can_state cs;
	struct can_bus_err_cnt cnt = {0};

	if (co_line_device(l->line) != NULL &&
	    can_get_state(co_line_device(l->line), &cs, &cnt) == 0 &&
	    (l->can_state != (uint8_t)cs || l->tec != cnt.tx_err_cnt || l->rec != cnt.rx_err_cnt)) {
		l->can_state = (uint8_t)cs;
		l->tec = cnt.tx_err_cnt;
		l->rec = cnt.rx_err_cnt;
		l->dirty = true;
	}
}

static void apply_line_event(struct br_line *l, const struct br_event *e)
{
	if (e->line.event == CO_LINE_EV_CAN_STATE) {
		l->can_state = (uint8_t)e->line.arg;
		read_can_state(l);
	}
	l->dirty = true;
}

static void write_emcy(int slot, const struct br_event *e, struct br_node_rec *n)
{
	safeline_canopen_v1_Emcy s = {
		.line = br.lines[slot].line_no,
		.node_id = e->node_id,
		.code = e->emcy.code,
		.error_register = e->emcy.reg,
		.own = e->emcy.own,
		.cob_id = e->emcy.cob_id,
		.seq = n->emcy_count,
		.time_ns = br_wall_ns(e->time_us),
	};

	(void)memcpy(s.msef, e->emcy.msef, sizeof(s.msef));
	(void)br_write(br.wr_emcy, &s);
}

/* The bridge thread, bridge lock held (except where noted). */
static void apply(const struct br_event *e)
{
	int slot = e->slot;
	uint64_t t = br_wall_ns(e->time_us);
	struct br_node_rec *n;
	struct br_srdo_rec *s;

	if (slot >= (int)atomic_get(&br.n_lines)) {
		return;
	}
	switch (e->kind) {
	case BR_EV_NMT:
		n = touch(slot, e->node_id, t);
		n->local = true;
		n->nmt = e->nmt.state;
		break;
	case BR_EV_HB:
		n = touch(slot, e->node_id, t);
		switch (e->hb.what) {
		case CO_HB_EV_BOOTUP:
			n->nmt = CO_NMT_INITIALISING;
			n->hb = BR_HB_WAITING;
			break;
		case CO_HB_EV_LOST:
			n->hb = BR_HB_LOST;
			break;
		default:
			n->hb = BR_HB_ACTIVE;
			n->nmt = e->hb.state;
			break;
		}
		break;
	case BR_EV_HB_FRAME:
		n = touch(slot, e->node_id, t);
		if (!n->local) {
			n->nmt = e->nmt.state;
		}
		n->hb_ns = t;
		n->hb_seen_us = e->time_us;
		break;
	case BR_EV_LIFE:
		n = touch(slot, e->node_id, t);
		n->guarding = e->life.lost ? BR_HB_LOST : BR_HB_ACTIVE;
		break;
	case BR_EV_EMCY:
		n = touch(slot, e->node_id, t);
		n->err_reg = e->emcy.reg;
		n->emcy_count++;
		write_emcy(slot, e, n);
		break;
	case BR_EV_LINE:
		apply_line_event(&br.lines[slot], e);
		break;
	case BR_EV_ACTIVE:
		if (br.lines[slot].active_line != e->active.line) {
			br.lines[slot].active_line = e->active.line;
			br.lines[slot].dirty = true;
		}
		break;
	case BR_EV_BOOT:
		n = touch(slot, e->node_id, t);
		n->boot_status = e->boot.status;
		n->boot_ns = t;
		(void)k_mutex_unlock(&br.lock);
		boot_info(&br.bnodes[e->src], slot, e->node_id, t, false);
		(void)k_mutex_lock(&br.lock, K_FOREVER);
		break;
	case BR_EV_SRDO:
		n = touch(slot, e->node_id, t);
		s = srdo_rec((uint8_t)slot, e->node_id, e->srdo.srdo);
		if (s == NULL) {
			LOG_WRN("no room for SRDO %u of node %u", e->srdo.srdo, e->node_id);
			break;
		}
		s->safe = e->srdo.safe;
		s->reason = e->srdo.reason;
		s->transitions++;
		s->time_ns = t;
		publish_srdo(s);
		break;
	case BR_EV_SNAPSHOT:
		(void)k_mutex_unlock(&br.lock);
		snapshot(&br.bnodes[e->src], slot, t);
		(void)k_mutex_lock(&br.lock, K_FOREVER);
		break;
	default:
		break;
	}
}

/* The time of the last heartbeat of each node, when it moved. */
static void refresh_heartbeats(void)
{
	int n_lines = (int)atomic_get(&br.n_lines);

	for (int slot = 0; slot < n_lines; slot++) {
		struct br_line *l = &br.lines[slot];

		for (uint8_t id = 1; id <= 127U; id++) {
			uint64_t seen = (uint64_t)atomic_get(&l->hb_us[id]);
			struct br_node_rec *n = &l->rec_of[id];

			if (seen != 0U && seen != n->hb_seen_us) {
				bool first = !n->known;

				n = touch(slot, id, first ? br_wall_ns(seen) : n->time_ns);
				n->hb_seen_us = seen;
				n->hb_ns = br_wall_ns(seen);
				if (first && !n->local) {
					n->nmt = (uint8_t)(atomic_get(&l->hb_state[id]) - 1);
				}
			}
		}
	}
}

/* Refresh: line counters and controller state, the bridge's own state. */
static void refresh(void)
{
	int n_lines = (int)atomic_get(&br.n_lines);

	for (int slot = 0; slot < n_lines; slot++) {
		struct br_line *l = &br.lines[slot];
		struct co_line_stats st;

		co_line_get_stats(l->line, &st);
		read_can_state(l);
		/* Byte images compared and copied whole: co_line_get_stats() zeroes the padding. */
		if (memcmp(&st, &l->stats, sizeof(st)) != 0) {
			(void)memcpy(&l->stats, &st, sizeof(st));
			l->dirty = true;
		}
		if (l->dirty) {
			publish_line(slot);
		}
	}
	publish_bridge();
}

static void publish_dirty(void)
{
	int n_lines = (int)atomic_get(&br.n_lines);

	if (atomic_cas(&br.bridge_dirty, 1, 0)) {
		publish_bridge();
	}

	for (int slot = 0; slot < n_lines; slot++) {
		struct br_line *l = &br.lines[slot];

		for (uint8_t id = 1; id <= 127U; id++) {
			if (l->rec_of[id].dirty) {
				publish_node(slot, id);
			}
		}
		if (l->dirty) {
			publish_line(slot);
		}
	}
}

static void bridge_main(void *p1, void *p2, void *p3)
{
	const uint64_t period_us = (uint64_t)CONFIG_CANOPEN_BRIDGE_DDS_REFRESH_MS * 1000U;
	const uint64_t hb_period_us =
		(uint64_t)CONFIG_CANOPEN_BRIDGE_DDS_HEARTBEAT_REFRESH_MS * 1000U;
	uint64_t next_refresh = co_line_now();
	uint64_t next_hb = next_refresh;
	uint32_t lost_logged = 0;
	struct br_event e;

	while (atomic_get(&br.running) != 0) {
		uint64_t now = co_line_now();
		uint64_t next_poll;
		uint64_t wake;
		int got;

		next_poll = br_poll_local_objects(now);
		wake = MIN(MIN(next_refresh, next_hb), next_poll);
		got = k_msgq_get(&br_queue, &e,
				 co_time_before_eq(wake, now) ? K_NO_WAIT
							      : K_USEC((int64_t)(wake - now)));
		(void)k_mutex_lock(&br.lock, K_FOREVER);
		/* Everything queued now, then the samples of what changed. */
		for (int i = 0; got == 0 && i < 4096; i++) {
			apply(&e);
			got = k_msgq_get(&br_queue, &e, K_NO_WAIT);
		}
		if (got == 0) {
			apply(&e);
		}
		now = co_line_now();
		if (co_time_before_eq(next_hb, now)) {
			refresh_heartbeats();
			next_hb = now + hb_period_us;
		}
		if (co_time_before_eq(next_refresh, now)) {
			refresh();
			next_refresh = now + period_us;
		}
		publish_dirty();
		(void)k_mutex_unlock(&br.lock);
		if ((uint32_t)atomic_get(&br.events_lost) != lost_logged) {
			lost_logged = (uint32_t)atomic_get(&br.events_lost);
			LOG_WRN("%u events lost so far: the queue (%d) was full", lost_logged,
				CONFIG_CANOPEN_BRIDGE_DDS_QUEUE_SIZE);
		}
	}
	(void)atomic_set(&br.bridge_done, 1);
}

/* --- Set-up ---------------------------------------------------------------------------------- */

static dds_qos_t *qos_state(int depth)
{
	dds_qos_t *q = dds_create_qos();

	dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
	dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
	/* What a late joiner gets: as much as the history (the default would be 1 sample). */
	dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, depth, DDS_LENGTH_UNLIMITED,
				    DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
	/* "Bridge gone" is NOT_ALIVE_NO_WRITERS, not DISPOSED. */
	dds_qset_writer_data_lifecycle(q, false);
	return q;
}

static dds_qos_t *qos_rpc(void)
{
	dds_qos_t *q = dds_create_qos();

	dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
	dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
	dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
	return q;
}

static dds_entity_t writer(const dds_topic_descriptor_t *desc, const char *name, dds_qos_t *q)
{
	dds_entity_t tp = dds_create_topic(br.pp, desc, name, NULL, NULL);

	if (tp < 0) {
		LOG_ERR("topic %s: %s", name, dds_strretcode(tp));
		return tp;
	}
	return dds_create_writer(br.pp, tp, q, NULL);
}

static dds_entity_t reader(const dds_topic_descriptor_t *desc, const char *name, dds_qos_t *q)
{
	dds_entity_t tp = dds_create_topic(br.pp, desc, name, NULL, NULL);

	if (tp < 0) {
		LOG_ERR("topic %s: %s", name, dds_strretcode(tp));
		return tp;
	}
	return dds_create_reader(br.pp, tp, q, NULL);
}

static int create_entities(const struct co_bridge_dds_config *cfg)
{
	char uri[600];
	const char *conf = loopback_xml;
	dds_qos_t *q;
	int err = 0;

	if (cfg->dds_config != NULL) {
		conf = cfg->dds_config;
		if (conf[0] != '<' && strncmp(conf, "file://", 7) != 0) {
			FILE *f = fopen(conf, "r");

			if (f == NULL) {
				LOG_ERR("DDS configuration %s: %s", conf, strerror(errno));
				return -ENOENT;
			}
			(void)fclose(f);
			(void)snprintf(uri, sizeof(uri), "file://%s", conf);
			conf = uri;
		}
	}
	if (getenv("CYCLONEDDS_URI") != NULL) {
		LOG_INF("CYCLONEDDS_URI is ignored: the bridge uses %s",
			cfg->dds_config != NULL ? "the configuration it was given"
						: "its loopback configuration");
	}
	br.domain = dds_create_domain(br.domain_id, conf);
	if (br.domain < 0) {
		LOG_ERR("DDS domain %u: %s", br.domain_id, dds_strretcode(br.domain));
		return -EIO;
	}
	br.pp = dds_create_participant(br.domain_id, NULL, NULL);
	if (br.pp < 0) {
		LOG_ERR("DDS participant: %s", dds_strretcode(br.pp));
		(void)dds_delete(br.domain);
		return -EIO;
	}

	q = qos_state(1);
	br.wr_bridge = writer(&safeline_canopen_v1_BridgeState_desc, TOPIC_BRIDGE, q);
	br.wr_line = writer(&safeline_canopen_v1_LineState_desc, TOPIC_LINE, q);
	br.wr_node = writer(&safeline_canopen_v1_NodeState_desc, TOPIC_NODE, q);
	br.wr_srdo = writer(&safeline_canopen_v1_SrdoState_desc, TOPIC_SRDO, q);
	br.wr_value = writer(&safeline_canopen_v1_OdValue_desc, TOPIC_VALUE, q);
	dds_delete_qos(q);
	q = qos_state(EMCY_HISTORY);
	br.wr_emcy = writer(&safeline_canopen_v1_Emcy_desc, TOPIC_EMCY, q);
	dds_delete_qos(q);
	q = qos_rpc();
	br.rd_sdo = reader(&safeline_canopen_v1_SdoRequest_desc, TOPIC_SDO_RQ, q);
	br.wr_sdo = writer(&safeline_canopen_v1_SdoReply_desc, TOPIC_SDO_RP, q);
	br.rd_nmt = reader(&safeline_canopen_v1_NmtRequest_desc, TOPIC_NMT_RQ, q);
	br.wr_nmt = writer(&safeline_canopen_v1_NmtReply_desc, TOPIC_NMT_RP, q);
	dds_delete_qos(q);
	const dds_entity_t e[] = {br.wr_bridge, br.wr_line, br.wr_node, br.wr_srdo, br.wr_value,
				  br.wr_emcy,   br.rd_sdo,  br.wr_sdo,  br.rd_nmt,  br.wr_nmt};

	for (size_t i = 0; i < ARRAY_SIZE(e); i++) {
		if (e[i] < 0) {
			LOG_ERR("DDS endpoint %zu: %s", i, dds_strretcode(e[i]));
			err = -EIO;
		}
	}
	if (err == 0) {
		br.ws = dds_create_waitset(br.pp);
		br.guard = dds_create_guardcondition(br.pp);
		if (br.ws < 0 || br.guard < 0 ||
		    dds_waitset_attach(br.ws, dds_create_readcondition(br.rd_sdo, DDS_ANY_STATE),
				       1) < 0 ||
		    dds_waitset_attach(br.ws, dds_create_readcondition(br.rd_nmt, DDS_ANY_STATE),
				       2) < 0 ||
		    dds_waitset_attach(br.ws, br.guard, 0) < 0) {
			LOG_ERR("DDS waitset");
			err = -EIO;
		}
	}
	if (err != 0) {
		(void)dds_delete(br.pp);
		(void)dds_delete(br.domain);
	}
	return err;
}

int co_bridge_dds_init(const struct co_bridge_dds_config *cfg)
{
	static const struct co_bridge_dds_config none;
	const char *name;
	int err = 0;

	if (cfg == NULL) {
		cfg = &none;
	}
	name = cfg->name != NULL ? cfg->name : "safeline";
	if (strlen(name) > BR_NAME_LEN) {
		LOG_ERR("bridge name longer than %u characters", BR_NAME_LEN);
		return -EINVAL;
	}
	if (!atomic_cas(&started, 0, 1)) {
		return -EALREADY;
	}
	/* br is zero from the start and initialised once (started): no memset, which a thread
	 * stopping the bridge at exit could see half done.
	 */
	(void)k_mutex_init(&br.lock);
	(void)strcpy(br.name, name);
	br.domain_id = cfg->domain_id == CO_BRIDGE_DDS_DOMAIN_DEFAULT
			       ? CONFIG_CANOPEN_BRIDGE_DDS_DOMAIN
			       : cfg->domain_id;
	br.started_ns = realtime_ns();
	br.wall_base_ns = br.started_ns - co_line_now() * 1000ULL;

	if (cfg->config_file != NULL) {
		err = br_conf_load(&br.conf, cfg->config_file);
	}
	if (err == 0 && cfg->allow_file != NULL) {
		err = br_allow_load(&br.conf, cfg->allow_file);
	}
	if (err == 0) {
		err = create_entities(cfg);
	}
	if (err != 0) {
		br_conf_free(&br.conf);
		(void)memset(&br.conf, 0, sizeof(br.conf));
		(void)atomic_set(&started, 0);
		return err;
	}
	(void)atomic_set(&br.running, 1);
	(void)k_thread_create(&bridge_thread, bridge_stack, K_THREAD_STACK_SIZEOF(bridge_stack),
			      bridge_main, NULL, NULL, NULL,
			      CONFIG_CANOPEN_BRIDGE_DDS_THREAD_PRIORITY, 0, K_NO_WAIT);
	(void)k_thread_name_set(&bridge_thread, "dds_bridge");
	(void)k_thread_create(&request_thread, request_stack, K_THREAD_STACK_SIZEOF(request_stack),
			      br_request_thread, NULL, NULL, NULL,
			      CONFIG_CANOPEN_BRIDGE_DDS_THREAD_PRIORITY, 0, K_NO_WAIT);
	(void)k_thread_name_set(&request_thread, "dds_requests");
	LOG_INF("bridge %s on DDS domain %u (%s), %s", br.name, br.domain_id,
		cfg->dds_config != NULL ? cfg->dds_config : "loopback configuration",
		br.conf.allow ? "allow-list" : "read-only");
	return 0;
}

int co_bridge_dds_add_line(struct co_line *line, uint8_t line_no, const char *name)
{
	struct br_line *l;
	int n;
	int err;

	if (line == NULL || line_no == BR_NO_LINE || (name != NULL && strlen(name) > BR_NAME_LEN)) {
		return -EINVAL;
	}
	if (!atomic_get(&br.running)) {
		return -ESRCH;
	}
	(void)k_mutex_lock(&br.lock, K_FOREVER);
	n = (int)atomic_get(&br.n_lines);
	for (int i = 0; i < n; i++) {
		if (br.lines[i].line == line || br.lines[i].line_no == line_no) {
			(void)k_mutex_unlock(&br.lock);
			return -EALREADY;
		}
	}
	if (n == CONFIG_CANOPEN_BRIDGE_DDS_LINES) {
		(void)k_mutex_unlock(&br.lock);
		return -ENOSPC;
	}
	l = &br.lines[n];
	(void)memset(l, 0, sizeof(*l));
	l->line = line;
	l->line_no = line_no;
	l->can_state = 0xFFU;
	l->dirty = true;
	read_can_state(l);
	co_line_get_stats(line, &l->stats);
	if (name != NULL) {
		(void)strcpy(l->name, name);
	}
	/* 701h..77Fh: heartbeats, boot-ups, guarding replies. */
	l->hb_rx = (struct co_rx){
		.id = CO_NMT_EC_COB_ID,
		.mask = 0x780U,
		.handler = on_hb_frame,
	};
	err = co_rx_register(line, &l->hb_rx);
	if (err == 0) {
		struct br_event wake = {.kind = BR_EV_WAKE, .slot = 0xFFU};

		(void)atomic_set(&br.n_lines, n + 1);
		(void)atomic_set(&br.bridge_dirty, 1);
		(void)k_msgq_put(&br_queue, &wake, K_NO_WAIT);
	}
	(void)k_mutex_unlock(&br.lock);
	return err;
}

int co_bridge_dds_add_node(struct co_node *node, const struct co_bridge_dds_node_config *cfg)
{
	struct br_bnode *b;
	struct br_event e = {.kind = BR_EV_SNAPSHOT};
	int n;
	int err;

	if (node == NULL || (cfg != NULL && cfg->name != NULL && strlen(cfg->name) > BR_NAME_LEN)) {
		return -EINVAL;
	}
	if (!atomic_get(&br.running)) {
		return -ESRCH;
	}
	(void)k_mutex_lock(&br.lock, K_FOREVER);
	n = (int)atomic_get(&br.n_bnodes);
	for (int i = 0; i < n; i++) {
		if (br.bnodes[i].node == node) {
			(void)k_mutex_unlock(&br.lock);
			return -EALREADY;
		}
	}
	if (n == CONFIG_CANOPEN_BRIDGE_DDS_NODES) {
		(void)k_mutex_unlock(&br.lock);
		return -ENOSPC;
	}
	b = &br.bnodes[n];
	(void)memset(b, 0, sizeof(*b));
	b->node = node;
	b->idx = (uint8_t)n;
	b->node_id = co_node_id(node);
	b->sdo_client = cfg != NULL ? cfg->sdo_client : CO_BRIDGE_DDS_NO_SDO_CLIENT;
	if (cfg != NULL && cfg->name != NULL) {
		(void)strcpy(b->name, cfg->name);
	}
	for (int i = 0; i < (int)CO_NODE_LINES; i++) {
		struct co_line *line = co_node_get_line(node, (enum co_node_line_id)i);
		int slot = -1;

		for (int k = 0; line != NULL && k < (int)atomic_get(&br.n_lines); k++) {
			if (br.lines[k].line == line) {
				slot = k;
			}
		}
		b->slot[i] = slot < 0 ? BR_NO_LINE : (uint8_t)slot;
	}
	if (b->slot[CO_LINE_DEFAULT] == BR_NO_LINE || b->node_id == 0U || b->node_id > 127U) {
		(void)k_mutex_unlock(&br.lock);
		return b->slot[CO_LINE_DEFAULT] == BR_NO_LINE ? -ENOENT : -EINVAL;
	}
	co_listener_init(&b->listener, "dds bridge", EVENT_MASK, on_event, b);
	err = co_node_listener_add(node, &b->listener);
	if (err == 0) {
		br.lines[b->slot[CO_LINE_DEFAULT]].nodes++;
		br.lines[b->slot[CO_LINE_DEFAULT]].dirty = true;
		(void)atomic_set(&br.n_bnodes, n + 1);
		(void)atomic_set(&br.bridge_dirty, 1);
		e.slot = b->slot[CO_LINE_DEFAULT];
		e.node_id = b->node_id;
		e.src = b->idx;
		e.time_us = co_line_now();
	}
	(void)k_mutex_unlock(&br.lock);
	if (err == 0) {
		/* The snapshot must not be lost: wait for room (this is not a line thread). */
		(void)k_msgq_put(&br_queue, &e, K_MSEC(1000));
	}
	return err;
}

static void wait_flag(atomic_t *flag, int ms)
{
	struct timespec ts = {.tv_nsec = 2000000L};

	for (int i = 0; i < ms / 2 && !atomic_get(flag); i++) {
		(void)nanosleep(&ts, NULL);
	}
}

void co_bridge_dds_stop(void)
{
	struct br_event wake = {.kind = BR_EV_WAKE, .slot = 0xFFU};

	if (!atomic_cas(&br.running, 1, 0)) {
		return;
	}
	(void)dds_set_guardcondition(br.guard, true);
	(void)k_msgq_put(&br_queue, &wake, K_NO_WAIT);
	/* The request thread may be in an SDO transfer; do not wait for it forever. */
	wait_flag(&br.bridge_done, 2000);
	wait_flag(&br.req_done, 2000);
	(void)dds_delete(br.pp);
	(void)dds_delete(br.domain);
	LOG_INF("bridge %s stopped", br.name);
}

bool co_bridge_dds_running(void)
{
	return atomic_get(&br.running) != 0;
}

void co_bridge_dds_get_stats(struct co_bridge_dds_stats *stats)
{
	*stats = (struct co_bridge_dds_stats){
		.events = (uint32_t)atomic_get(&br.events),
		.events_lost = (uint32_t)atomic_get(&br.events_lost),
		.queue_max = (uint32_t)atomic_get(&br.queue_max),
		.samples = (uint32_t)atomic_get(&br.samples),
		.requests = (uint32_t)atomic_get(&br.requests),
		.refused = (uint32_t)atomic_get(&br.refused),
		.malformed = (uint32_t)atomic_get(&br.malformed),
		.replies_deferred = (uint32_t)atomic_get(&br.replies_deferred),
		.replies_lost = (uint32_t)atomic_get(&br.replies_lost),
	};
}

const char *co_bridge_dds_loopback_config(void)
{
	return loopback_xml;
}
