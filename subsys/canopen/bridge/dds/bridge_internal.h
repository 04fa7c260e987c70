/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The DDS bridge's parts: configuration files (conf.c), EDS files (eds.c), events to
 * samples (bridge.c), requests and object polls (requests.c).
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_BRIDGE_DDS_BRIDGE_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_BRIDGE_DDS_BRIDGE_INTERNAL_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/kernel.h>
#include <zephyr/sys/atomic.h>

#include <canopen/bridge_dds.h>
#include <canopen/line.h>
#include <canopen/node.h>

#include <dds/dds.h>

#include "safeline_canopen.h"

#define BR_NODE_IDS    128U
#define BR_NMT_UNKNOWN 0xFFU
#define BR_BOOT_NONE   0xFFU
#define BR_VALUE_MAX   256U
#define BR_NAME_LEN    32U
#define BR_NO_LINE     0xFFU

/* The version in canopen/bridge_state. */
#define BR_VERSION "safeline-dds 1.0"

/* NodeState.heartbeat and .guarding. */
enum br_hb {
	BR_HB_NONE = 0,
	BR_HB_WAITING = 1,
	BR_HB_ACTIVE = 2,
	BR_HB_LOST = 3,
};

/* --- EDS (eds.c) --------------------------------------------------------------------------- */

struct br_eds_entry {
	uint16_t index;
	uint8_t sub;
	/* enum co_od_access; 0xFF unknown */
	uint8_t access;
	uint16_t dtype;
	char name[64];
};

struct br_eds {
	char path[256];
	char product[BR_NAME_LEN + 1];
	size_t n;
	struct br_eds_entry *entries;
};

/* Read an EDS or DCF. 0, -ENOENT (cannot read), -EINVAL (logged) or -ENOMEM. */
int br_eds_load(const char *path, struct br_eds *eds);
void br_eds_free(struct br_eds *eds);
const struct br_eds_entry *br_eds_find(const struct br_eds *eds, uint16_t index, uint8_t sub);

/* --- Configuration files (conf.c) ---------------------------------------------------------- */

#define BR_MAX_EDS      16U
#define BR_MAX_EDS_MAPS 32U
#define BR_RULE_OBJECTS 16U

/* Bits of br_rule.cmds. */
#define BR_CMD_START      BIT(0)
#define BR_CMD_STOP       BIT(1)
#define BR_CMD_PREOP      BIT(2)
#define BR_CMD_RESET      BIT(3)
#define BR_CMD_RESET_COMM BIT(4)
#define BR_CMD_ALL        (BIT(5) - 1U)

struct br_obj_range {
	uint16_t first;
	uint16_t last;
	/* -1: any sub-index */
	int16_t sub;
};

/* One line of the allow-list. */
struct br_rule {
	char client[64];
	bool nmt;
	/* -1: any line */
	int16_t line_no;
	/* Nodes 1..127 (bit 0 unused). */
	uint32_t nodes[4];
	bool any_object;
	uint8_t n_objects;
	struct br_obj_range objects[BR_RULE_OBJECTS];
	uint8_t cmds;
};

/* One object the bridge publishes, with its polling state. */
struct br_object {
	uint8_t line_no;
	uint8_t node_id;
	uint16_t index;
	uint8_t sub;
	uint32_t interval_ms;
	/* Polling state (the thread that polls it). */
	uint64_t next_us;
	bool published;
	uint32_t abort_code;
	uint32_t size;
	uint32_t changes;
	uint8_t data[BR_VALUE_MAX];
};

struct br_eds_map {
	uint8_t line_no;
	uint8_t first;
	uint8_t last;
	uint8_t eds;
};

struct br_conf {
	struct br_eds eds[BR_MAX_EDS];
	uint8_t n_eds;
	struct br_eds_map maps[BR_MAX_EDS_MAPS];
	uint8_t n_maps;
	struct br_object objects[MAX(CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS, 1)];
	uint16_t n_objects;
	struct br_rule rules[CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES];
	uint16_t n_rules;
	/* An allow-list was given (else read-only). */
	bool allow;
};

/* The configuration file: "eds" and "object" lines. */
int br_conf_load(struct br_conf *c, const char *path);
/* The allow-list: "write" and "nmt" lines. */
int br_allow_load(struct br_conf *c, const char *path);
void br_conf_free(struct br_conf *c);
const struct br_eds *br_conf_eds(const struct br_conf *c, uint8_t line_no, uint8_t node_id);
/* The name part of a client id ("name@host:pid" -> "name"), into @p buf. */
void br_client_name(const char *client_id, char *buf, size_t len);
/* A write of an object whose sub-index 80h means every node (1F25h, 1F82h, 1F83h) is allowed
 * only when the write of each sub-index 01h..7Fh is. */
bool br_allow_write(const struct br_conf *c, const char *client, uint8_t line_no, uint8_t node_id,
		    uint16_t index, uint8_t sub);
#define BR_SUB_ALL_NODES 0x80U
/* CiA 302-2's "all nodes" sub-index of a request object. */
bool br_allow_is_for_all_nodes(uint16_t index, uint8_t sub);
/* @p node_id 0: broadcast, allowed only when @p cmd is allowed for each node 1..127. @p cmd:
 * BR_CMD_* bit. */
bool br_allow_nmt(const struct br_conf *c, const char *client, uint8_t line_no, uint8_t node_id,
		  uint8_t cmd);
/* BR_CMD_* bit of an NMT command specifier, 0 if unknown. */
uint8_t br_cmd_bit(uint8_t cs);

/* --- The bridge (bridge.c) ----------------------------------------------------------------- */

/* A node as the bridge knows it (one per line and node-ID). */
struct br_node_rec {
	bool known;
	bool dirty;
	bool local;
	char name[BR_NAME_LEN + 1];
	uint8_t nmt;
	uint8_t hb;
	uint64_t hb_ns;
	/* Line time of the heartbeat last taken into hb_ns. */
	uint64_t hb_seen_us;
	uint8_t guarding;
	uint8_t boot_status;
	uint64_t boot_ns;
	uint8_t id_mask;
	uint32_t ident[5];
	uint8_t err_reg;
	uint32_t emcy_count;
	uint64_t time_ns;
};

struct br_line {
	struct co_line *line;
	uint8_t line_no;
	char name[BR_NAME_LEN + 1];
	/* Heartbeats, boot-ups and guarding replies on the line (no lock: atomics only). */
	struct co_rx hb_rx;
	/* Line time of the last one per node, 0: none. */
	atomic_t hb_us[BR_NODE_IDS];
	/* Last state byte + 1 per node, 0: none. */
	atomic_t hb_state[BR_NODE_IDS];
	atomic_t events_lost;
	/* Bridge thread. */
	uint8_t can_state;
	uint8_t tec;
	uint8_t rec;
	/* CiA 302-6: the active line of the bridged nodes on this line (the last to change). */
	uint8_t active_line;
	bool dirty;
	struct co_line_stats stats;
	uint32_t nodes;
	struct br_node_rec rec_of[BR_NODE_IDS];
};

struct br_bnode {
	struct co_listener listener;
	struct co_node *node;
	/* Slot of the node's default and redundant line, BR_NO_LINE: not followed. */
	uint8_t slot[CO_NODE_LINES];
	uint8_t idx;
	uint8_t node_id;
	uint8_t sdo_client;
	char name[BR_NAME_LEN + 1];
};

struct br_srdo_rec {
	bool used;
	uint8_t slot;
	uint8_t node_id;
	uint8_t srdo;
	bool safe;
	uint8_t reason;
	uint32_t transitions;
	uint64_t time_ns;
};

#define BR_SRDO_RECS 128U

struct br_state {
	atomic_t running;
	/* Protects the tables below against the request thread (never held with a node lock). */
	struct k_mutex lock;
	char name[BR_NAME_LEN + 1];
	uint32_t domain_id;
	uint64_t started_ns;
	/* Wall clock [ns] at line time 0. */
	uint64_t wall_base_ns;
	struct br_conf conf;
	struct br_line lines[CONFIG_CANOPEN_BRIDGE_DDS_LINES];
	atomic_t n_lines;
	struct br_bnode bnodes[CONFIG_CANOPEN_BRIDGE_DDS_NODES];
	atomic_t n_bnodes;
	struct br_srdo_rec srdos[BR_SRDO_RECS];

	dds_entity_t domain;
	dds_entity_t pp;
	dds_entity_t wr_bridge, wr_line, wr_node, wr_emcy, wr_srdo, wr_value;
	dds_entity_t rd_sdo, wr_sdo, rd_nmt, wr_nmt;
	dds_entity_t ws;
	dds_entity_t guard;

	atomic_t events;
	atomic_t events_lost;
	atomic_t queue_max;
	atomic_t samples;
	atomic_t requests;
	atomic_t refused;
	atomic_t malformed;
	atomic_t replies_deferred;
	atomic_t replies_lost;
	/* Lines or nodes were added: canopen/bridge_state is written again at once. */
	atomic_t bridge_dirty;
	atomic_t bridge_done;
	atomic_t req_done;
};

extern struct br_state br;

/* Wall clock [ns] of a line time [µs]. */
uint64_t br_wall_ns(uint64_t line_us);
/* Slot of a line number, -1 if not followed. Caller holds br.lock or runs in a bridge thread. */
int br_slot_of(uint8_t line_no);
/* The bridged node with @p node_id on line slot @p slot, or NULL. */
struct br_bnode *br_bnode_at(int slot, uint8_t node_id);
/* Whether a node is known on a line (bridged, seen, or with an EDS). Takes br.lock. */
bool br_node_known(int slot, uint8_t node_id);
/* NMT state and heartbeat state of a node as published (BR_NMT_UNKNOWN). Takes br.lock. */
void br_node_status(int slot, uint8_t node_id, uint8_t *nmt, uint8_t *hb);
/* Write a sample, counting it. */
int br_write(dds_entity_t wr, const void *sample);
/* Publish one object value if it changed; the poll state lives in @p o. */
void br_publish_value(struct br_object *o, uint32_t abort_code, const uint8_t *data, size_t len,
		      uint64_t now_us);
/* Read an object of a bridged node from its dictionary (SDO access rights). */
uint32_t br_local_read(struct co_node *node, uint16_t index, uint8_t sub, uint8_t *buf, size_t cap,
		       size_t *len);
/* Poll the objects of bridged nodes that are due; returns the next due time [µs]. */
uint64_t br_poll_local_objects(uint64_t now_us);

/* --- Requests (requests.c) ----------------------------------------------------------------- */

void br_request_thread(void *p1, void *p2, void *p3);

#endif /* SAFELINE_SUBSYS_CANOPEN_BRIDGE_DDS_BRIDGE_INTERNAL_H_ */
