/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The request thread: SDO and NMT requests from DDS clients, and the polls of the selected
 * objects of remote nodes.
 *
 * Every request is checked before anything reaches the bus: the arguments (malformed), the
 * line and the node (unknown), then the allow-list for writes and NMT commands (refused);
 * each of these gets a reply that says why. SDO transfers use the blocking client calls of
 * canopen/sdo_cli.h: this thread is no line thread and holds no node lock, so they may wait.
 * Objects of a node of the process are read and written in its dictionary directly, with
 * the access rights of an SDO server.
 *
 * Reply race: a requester's reply reader may not be discovered yet when its first request
 * arrives (both its endpoints matched ours, ours not yet its reader), and a VOLATILE reply
 * written then is lost. Before a reply, the thread waits (bounded) until the reply writer has
 * matched a reader of the requester's participant; known requesters are cached.
 */

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/sdo_abort.h>
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
#include <canopen/sdo_cli.h>
#endif
#if defined(CONFIG_CANOPEN_MGR)
#include <canopen/mgr.h>
#endif

#include "bridge_internal.h"

LOG_MODULE_DECLARE(canopen_bridge_dds, CONFIG_CANOPEN_LOG_LEVEL);

#define KNOWN_REQUESTERS 64U
/* A poll of a remote object waits at most this long for the server. */
#define POLL_TIMEOUT_MS  300U
#define MAX_TIMEOUT_MS   600000U

/* Uploads land here (a reply points into it until dds_write returns). */
static uint8_t sdo_buf[CONFIG_CANOPEN_BRIDGE_DDS_SDO_MAX];

static dds_instance_handle_t known[KNOWN_REQUESTERS];
static unsigned int known_next;

/* --- The reply race ---------------------------------------------------------------------- */

/* 1: a reader of the requester's participant is matched; 0: not yet; -1: requester gone. */
static int requester_present(dds_entity_t rd, dds_entity_t wr, dds_instance_handle_t pub)
{
	dds_instance_handle_t subs[64];
	dds_builtintopic_endpoint_t *w = dds_get_matched_publication_data(rd, pub);
	int32_t n;
	bool found = false;

	if (w == NULL) {
		return -1;
	}
	n = dds_get_matched_subscriptions(wr, subs, ARRAY_SIZE(subs));
	for (int32_t i = 0; i < n && i < (int32_t)ARRAY_SIZE(subs) && !found; i++) {
		dds_builtintopic_endpoint_t *r = dds_get_matched_subscription_data(wr, subs[i]);

		if (r != NULL) {
			found = memcmp(&r->participant_key, &w->participant_key,
				       sizeof(w->participant_key)) == 0;
			dds_builtintopic_free_endpoint(r);
		}
	}
	dds_builtintopic_free_endpoint(w);
	return found ? 1 : 0;
}

static bool requester_ready(dds_entity_t rd, dds_entity_t wr, dds_instance_handle_t pub)
{
	const struct timespec step = {.tv_nsec = 2000000L};
	bool waited = false;
	int st;

	for (unsigned int i = 0; i < KNOWN_REQUESTERS; i++) {
		if (known[i] == pub && pub != 0U) {
			return true;
		}
	}
	for (int t = 0;; t += 2) {
		st = requester_present(rd, wr, pub);
		if (st != 0 || t >= CONFIG_CANOPEN_BRIDGE_DDS_REPLY_WAIT_MS ||
		    !atomic_get(&br.running)) {
			break;
		}
		waited = true;
		(void)nanosleep(&step, NULL);
	}
	if (waited) {
		(void)atomic_inc(&br.replies_deferred);
	}
	if (st != 1) {
		(void)atomic_inc(&br.replies_lost);
		return false;
	}
	known[known_next++ % KNOWN_REQUESTERS] = pub;
	return true;
}

/* --- SDO ------------------------------------------------------------------------------------ */

struct sdo_result {
	uint8_t status;
	uint32_t abort_code;
	char message[160];
	const struct br_eds_entry *entry;
	uint16_t dtype;
	uint8_t access;
	const uint8_t *data;
	size_t len;
};

static void set_result(struct sdo_result *r, uint8_t status, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

static void set_result(struct sdo_result *r, uint8_t status, const char *fmt, ...)
{
	va_list ap;

	r->status = status;
	va_start(ap, fmt);
	(void)vsnprintf(r->message, sizeof(r->message), fmt, ap);
	va_end(ap);
}

static void send_sdo_reply(const safeline_canopen_v1_SdoRequest *rq, dds_instance_handle_t pub,
			   const struct sdo_result *r)
{
	safeline_canopen_v1_SdoReply rp = {
		.request_id = rq->request_id,
		.status = r->status,
		.abort_code = r->abort_code,
		.data_type = r->dtype,
		.access = r->access,
	};

	(void)snprintf(rp.client_id, sizeof(rp.client_id), "%s", rq->client_id);
	(void)snprintf(rp.message, sizeof(rp.message), "%s", r->message);
	if (r->entry != NULL) {
		(void)snprintf(rp.name, sizeof(rp.name), "%s", r->entry->name);
	}
	rp.data._buffer = (uint8_t *)r->data;
	rp.data._length = (uint32_t)r->len;
	rp.data._maximum = (uint32_t)r->len;
	rp.data._release = false;
	if (requester_ready(br.rd_sdo, br.wr_sdo, pub)) {
		(void)br_write(br.wr_sdo, &rp);
	} else {
		LOG_WRN("SDO reply %u to %s lost: its reader never appeared", rq->request_id,
			rq->client_id);
	}
}

static void set_abort(struct sdo_result *r, uint32_t code)
{
	r->abort_code = code;
	set_result(r, safeline_canopen_v1_STATUS_ABORTED, "SDO abort %08Xh: %s", code,
		   co_sdo_abort_str(code));
}

/* An object of a node of the process: its dictionary, with SDO access rights. */
static void local_transfer(const safeline_canopen_v1_SdoRequest *rq, struct co_node *node,
			   struct sdo_result *r)
{
	uint32_t ab;

	if (rq->op == safeline_canopen_v1_SDO_READ) {
		size_t len = 0;

		ab = br_local_read(node, rq->index, rq->subindex, sdo_buf, sizeof(sdo_buf), &len);
		if (ab == 0U) {
			r->data = sdo_buf;
			r->len = len;
		}
	} else {
		co_node_lock(node);
		ab = co_od_write(co_node_od(node), rq->index, rq->subindex, rq->data._buffer,
				 rq->data._length, CO_OD_WRITER_SDO);
		co_node_unlock(node);
	}
	if (ab != 0U) {
		set_abort(r, ab);
	}
}

#if defined(CONFIG_CANOPEN_SDO_CLIENT)
/* The first bridged node of the line with an SDO client for requests. */
static struct br_bnode *sdo_gateway(int slot)
{
	int n = (int)atomic_get(&br.n_bnodes);

	for (int i = 0; i < n; i++) {
		if (br.bnodes[i].slot[CO_LINE_DEFAULT] == slot &&
		    br.bnodes[i].sdo_client != CO_BRIDGE_DDS_NO_SDO_CLIENT) {
			return &br.bnodes[i];
		}
	}
	return NULL;
}

static void errno_result(struct sdo_result *r, int err, uint32_t abort_code, uint32_t timeout_ms)
{
	switch (err) {
	case 0:
		break;
	case -ECONNABORTED:
		set_abort(r, abort_code);
		break;
	case -EAGAIN:
		set_result(r, safeline_canopen_v1_STATUS_TIMEOUT,
			   "no complete answer within %u ms (transfer aborted with 05040000h)",
			   timeout_ms);
		break;
	case -EBUSY:
		set_result(r, safeline_canopen_v1_STATUS_FAILED,
			   "the bridge's SDO client is busy with another transfer");
		break;
	case -ENETDOWN:
		set_result(r, safeline_canopen_v1_STATUS_FAILED,
			   "the bridge's node cannot use SDO now (not Pre-operational or "
			   "Operational, or its line is down)");
		break;
	default:
		set_result(r, safeline_canopen_v1_STATUS_FAILED, "SDO client error %d (%s)", err,
			   strerror(-err));
		break;
	}
}

/* A remote node, through the line's gateway node and its SDO client. */
static void remote_transfer(const safeline_canopen_v1_SdoRequest *rq, int slot,
			    struct sdo_result *r, uint32_t timeout_ms)
{
	struct br_bnode *gw = sdo_gateway(slot);
	struct co_sdo_cli *cli = gw != NULL ? co_sdo_cli_get(gw->node, gw->sdo_client) : NULL;
	enum co_sdo_cli_mode mode = (enum co_sdo_cli_mode)rq->mode;
	uint32_t abort_code = 0;
	int err;

	if (cli == NULL) {
		set_result(r, safeline_canopen_v1_STATUS_FAILED,
			   "no node of line %u serves SDO requests (no SDO client given)",
			   rq->line);
		return;
	}
	err = co_sdo_cli_set_server(cli, rq->node_id);
	if (err != 0) {
		errno_result(r, err, 0U, timeout_ms);
		return;
	}
	if (rq->op == safeline_canopen_v1_SDO_READ) {
		size_t len = 0;

		err = co_sdo_cli_upload(cli, rq->index, rq->subindex, sdo_buf, sizeof(sdo_buf),
					&len, mode, K_MSEC(timeout_ms), &abort_code);
		if (err == 0) {
			r->data = sdo_buf;
			r->len = len;
		}
	} else {
		if (mode == CO_SDO_CLI_AUTO &&
		    rq->data._length >= CONFIG_CANOPEN_BRIDGE_DDS_BLOCK_THRESHOLD) {
			mode = CO_SDO_CLI_BLOCK;
		}
		err = co_sdo_cli_download(cli, rq->index, rq->subindex, rq->data._buffer,
					  rq->data._length, mode, K_MSEC(timeout_ms), &abort_code);
		if (err == -ECONNABORTED && abort_code == CO_SDO_AB_CMD &&
		    rq->mode == safeline_canopen_v1_MODE_AUTO && mode == CO_SDO_CLI_BLOCK) {
			/* The server has no block transfer: segmented, then. */
			err = co_sdo_cli_download(cli, rq->index, rq->subindex, rq->data._buffer,
						  rq->data._length, CO_SDO_CLI_SEGMENTED,
						  K_MSEC(timeout_ms), &abort_code);
		}
	}
	errno_result(r, err, abort_code, timeout_ms);
}
#endif

/* What the EDS (or the node's own dictionary) says of an object. */
static bool describe(int slot, uint8_t line_no, uint8_t node_id, uint16_t index, uint8_t sub,
		     struct sdo_result *r)
{
	const struct br_eds *eds = br_conf_eds(&br.conf, line_no, node_id);
	struct br_bnode *b = br_bnode_at(slot, node_id);

	r->access = 0xFFU;
	if (eds != NULL) {
		r->entry = br_eds_find(eds, index, sub);
		if (r->entry != NULL) {
			r->dtype = r->entry->dtype;
			r->access = r->entry->access;
		}
		return r->entry != NULL;
	}
	if (b != NULL) {
		struct co_od_info info;
		bool found;

		co_node_lock(b->node);
		found = co_od_find(co_node_od(b->node), index, sub, &info) == 0U;
		co_node_unlock(b->node);
		if (found) {
			r->dtype = info.dtype;
			r->access = info.access;
		}
		return found;
	}
	return false;
}

static void handle_sdo(const safeline_canopen_v1_SdoRequest *rq, dds_instance_handle_t pub)
{
	struct sdo_result r = {.message = "ok"};
	char client[64];
	int slot = br_slot_of(rq->line);
	uint32_t timeout_ms =
		rq->timeout_ms != 0U ? rq->timeout_ms : CONFIG_CANOPEN_BRIDGE_DDS_SDO_TIMEOUT;
	bool write = rq->op == safeline_canopen_v1_SDO_WRITE;

	(void)atomic_inc(&br.requests);
	br_client_name(rq->client_id, client, sizeof(client));
	if (rq->client_id[0] == '\0' || rq->request_id == 0U) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED,
			   "client_id and request_id must be set");
	} else if (rq->op > safeline_canopen_v1_SDO_INFO) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED,
			   "op %u: 0 read, 1 write or 2 info", rq->op);
	} else if (rq->mode > safeline_canopen_v1_MODE_BLOCK) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED,
			   "mode %u: 0 auto, 1 segmented or 2 block", rq->mode);
	} else if (rq->node_id == 0U || rq->node_id > 127U) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED, "node %u: 1..127",
			   rq->node_id);
	} else if (rq->timeout_ms > MAX_TIMEOUT_MS) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED, "timeout_ms %u: at most %u",
			   rq->timeout_ms, MAX_TIMEOUT_MS);
	} else if (write && rq->data._length == 0U) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED, "a write needs data");
	} else if (write && rq->data._length > CONFIG_CANOPEN_BRIDGE_DDS_SDO_MAX) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED,
			   "%u bytes: the bridge takes at most %d", rq->data._length,
			   CONFIG_CANOPEN_BRIDGE_DDS_SDO_MAX);
	} else if (!write && rq->data._length != 0U) {
		set_result(&r, safeline_canopen_v1_STATUS_MALFORMED, "only a write carries data");
	} else if (slot < 0) {
		set_result(&r, safeline_canopen_v1_STATUS_UNKNOWN_LINE, "line %u is not bridged",
			   rq->line);
	} else if (!br_node_known(slot, rq->node_id)) {
		set_result(&r, safeline_canopen_v1_STATUS_UNKNOWN_NODE,
			   "node %u is unknown on line %u", rq->node_id, rq->line);
	} else if (write && !br_allow_write(&br.conf, client, rq->line, rq->node_id, rq->index,
					    rq->subindex)) {
		char why[24] = "";

		if (br.conf.allow && br_allow_is_for_all_nodes(rq->index, rq->subindex)) {
			uint8_t n = 1U;

			while (n < 127U && br_allow_write(&br.conf, client, rq->line, rq->node_id,
							  rq->index, n)) {
				n++;
			}
			(void)snprintf(why, sizeof(why), " (not %04Xh:%02X)", rq->index, n);
		}
		set_result(&r, safeline_canopen_v1_STATUS_REFUSED,
			   "%s: client '%s' may not write %04Xh:%02X of node %u on line %u%s",
			   br.conf.allow ? "not in the allow-list" : "the bridge is read-only",
			   client, rq->index, rq->subindex, rq->node_id, rq->line, why);
		(void)atomic_inc(&br.refused);
	} else {
		bool described = describe(slot, rq->line, rq->node_id, rq->index, rq->subindex, &r);
		struct br_bnode *b = br_bnode_at(slot, rq->node_id);

		if (rq->op == safeline_canopen_v1_SDO_INFO) {
			if (!described) {
				set_result(&r, safeline_canopen_v1_STATUS_NOT_FOUND,
					   "%04Xh:%02X is not in the %s of node %u", rq->index,
					   rq->subindex, b != NULL ? "dictionary" : "EDS",
					   rq->node_id);
				if (b == NULL &&
				    br_conf_eds(&br.conf, rq->line, rq->node_id) == NULL) {
					(void)snprintf(r.message, sizeof(r.message),
						       "the bridge knows no EDS of node %u",
						       rq->node_id);
				}
			}
		} else if (b != NULL) {
			local_transfer(rq, b->node, &r);
		} else {
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
			remote_transfer(rq, slot, &r, timeout_ms);
#else
			ARG_UNUSED(timeout_ms);
			set_result(&r, safeline_canopen_v1_STATUS_FAILED,
				   "the bridge is built without SDO client");
#endif
		}
	}
	if (r.status == safeline_canopen_v1_STATUS_MALFORMED ||
	    r.status == safeline_canopen_v1_STATUS_UNKNOWN_LINE ||
	    r.status == safeline_canopen_v1_STATUS_UNKNOWN_NODE) {
		(void)atomic_inc(&br.malformed);
	}
	if (r.status != safeline_canopen_v1_STATUS_OK) {
		r.data = NULL;
		r.len = 0;
	}
	LOG_DBG("sdo %s %u %04x:%02x from %s: %u %s", write ? "write" : "read", rq->node_id,
		rq->index, rq->subindex, rq->client_id, r.status, r.message);
	send_sdo_reply(rq, pub, &r);
}

/* --- NMT ------------------------------------------------------------------------------------- */

static void send_nmt_reply(const safeline_canopen_v1_NmtRequest *rq, dds_instance_handle_t pub,
			   uint8_t status, const char *msg)
{
	safeline_canopen_v1_NmtReply rp = {.request_id = rq->request_id, .status = status};

	(void)snprintf(rp.client_id, sizeof(rp.client_id), "%s", rq->client_id);
	(void)snprintf(rp.message, sizeof(rp.message), "%s", msg);
	if (requester_ready(br.rd_nmt, br.wr_nmt, pub)) {
		(void)br_write(br.wr_nmt, &rp);
	}
}

/* Send the command through an NMT master of the line, or apply it to a node of the process. */
static uint8_t nmt_send(int slot, uint8_t node_id, uint8_t cs, char *msg, size_t len)
{
	int n = (int)atomic_get(&br.n_bnodes);
	struct br_bnode *local = br_bnode_at(slot, node_id);
	int err;

#if defined(CONFIG_CANOPEN_MGR)
	for (int i = 0; i < n; i++) {
		struct br_bnode *b = &br.bnodes[i];

		if (b->slot[CO_LINE_DEFAULT] != slot) {
			continue;
		}
		err = co_mgr_nmt_req(b->node, node_id, (enum co_nmt_cs)cs);
		if (err == 0) {
			(void)snprintf(msg, len, "sent by node %u (NMT master)", b->node_id);
			return safeline_canopen_v1_STATUS_OK;
		}
		if (err != -EPERM) {
			(void)snprintf(msg, len, "the NMT master (node %u) refused: %s", b->node_id,
				       strerror(-err));
			return safeline_canopen_v1_STATUS_FAILED;
		}
	}
#else
	ARG_UNUSED(n);
#endif
	if (local != NULL) {
		err = co_nmt_req(local->node, (enum co_nmt_cs)cs);
		if (err == 0) {
			(void)snprintf(msg, len, "applied to node %u of the bridge's process",
				       node_id);
			return safeline_canopen_v1_STATUS_OK;
		}
		(void)snprintf(msg, len, "node %u refused: %s", node_id, strerror(-err));
		return safeline_canopen_v1_STATUS_FAILED;
	}
	(void)snprintf(msg, len, "no NMT master among the bridged nodes of this line");
	return safeline_canopen_v1_STATUS_FAILED;
}

static void handle_nmt(const safeline_canopen_v1_NmtRequest *rq, dds_instance_handle_t pub)
{
	static const char *const names[] = {"start", "stop", "preop", "reset", "reset-comm"};
	char client[64];
	char msg[160] = "ok";
	int slot = br_slot_of(rq->line);
	uint8_t bit = br_cmd_bit(rq->command);
	uint8_t status = safeline_canopen_v1_STATUS_OK;

	(void)atomic_inc(&br.requests);
	br_client_name(rq->client_id, client, sizeof(client));
	if (rq->client_id[0] == '\0' || rq->request_id == 0U) {
		status = safeline_canopen_v1_STATUS_MALFORMED;
		(void)snprintf(msg, sizeof(msg), "client_id and request_id must be set");
	} else if (bit == 0U) {
		status = safeline_canopen_v1_STATUS_MALFORMED;
		(void)snprintf(msg, sizeof(msg),
			       "command %u: 1 start, 2 stop, 128 preop, 129 reset, 130 reset-comm",
			       rq->command);
	} else if (rq->node_id > 127U) {
		status = safeline_canopen_v1_STATUS_MALFORMED;
		(void)snprintf(msg, sizeof(msg), "node %u: 0 (all) or 1..127", rq->node_id);
	} else if (slot < 0) {
		status = safeline_canopen_v1_STATUS_UNKNOWN_LINE;
		(void)snprintf(msg, sizeof(msg), "line %u is not bridged", rq->line);
	} else if (rq->node_id != 0U && !br_node_known(slot, rq->node_id)) {
		status = safeline_canopen_v1_STATUS_UNKNOWN_NODE;
		(void)snprintf(msg, sizeof(msg), "node %u is unknown on line %u", rq->node_id,
			       rq->line);
	} else if (!br_allow_nmt(&br.conf, client, rq->line, rq->node_id, bit)) {
		char target[40] = "all nodes";

		if (rq->node_id != 0U) {
			(void)snprintf(target, sizeof(target), "node %u", rq->node_id);
		} else if (br.conf.allow) {
			/* The broadcast reaches every node: name the first one not allowed. */
			uint8_t n = 1U;

			while (n < 127U && br_allow_nmt(&br.conf, client, rq->line, n, bit)) {
				n++;
			}
			(void)snprintf(target, sizeof(target), "all nodes (not to node %u)", n);
		}
		status = safeline_canopen_v1_STATUS_REFUSED;
		(void)snprintf(msg, sizeof(msg), "%s: client '%s' may not send %s to %s on line %u",
			       br.conf.allow ? "not in the allow-list" : "the bridge is read-only",
			       client, names[__builtin_ctz(bit)], target, rq->line);
		(void)atomic_inc(&br.refused);
	} else {
		status = nmt_send(slot, rq->node_id, rq->command, msg, sizeof(msg));
	}
	if (status == safeline_canopen_v1_STATUS_MALFORMED ||
	    status == safeline_canopen_v1_STATUS_UNKNOWN_LINE ||
	    status == safeline_canopen_v1_STATUS_UNKNOWN_NODE) {
		(void)atomic_inc(&br.malformed);
	}
	send_nmt_reply(rq, pub, status, msg);
}

/* --- Polls of remote objects ------------------------------------------------------------------ */

static uint64_t poll_remote_objects(uint64_t now_us)
{
	uint64_t next = UINT64_MAX;

	for (int i = 0; i < br.conf.n_objects && atomic_get(&br.running); i++) {
		struct br_object *o = &br.conf.objects[i];
		int slot = br_slot_of(o->line_no);

		if (slot < 0 || br_bnode_at(slot, o->node_id) != NULL) {
			continue;
		}
		if (co_time_before_eq(o->next_us, now_us)) {
#if defined(CONFIG_CANOPEN_SDO_CLIENT)
			struct br_bnode *gw = sdo_gateway(slot);
			struct co_sdo_cli *cli =
				gw != NULL ? co_sdo_cli_get(gw->node, gw->sdo_client) : NULL;
			uint8_t nmt;
			uint8_t hb;
			uint32_t ab = 0;
			size_t len = 0;
			int err = -ENOTCONN;

			br_node_status(slot, o->node_id, &nmt, &hb);
			/* A node that is not there, or cannot answer, is not asked. */
			if (cli != NULL && nmt != BR_NMT_UNKNOWN && nmt != CO_NMT_STOPPED &&
			    nmt != CO_NMT_INITIALISING && hb != BR_HB_LOST &&
			    co_sdo_cli_set_server(cli, o->node_id) == 0) {
				err = co_sdo_cli_upload(
					cli, o->index, o->sub, sdo_buf, BR_VALUE_MAX, &len,
					CO_SDO_CLI_AUTO,
					K_MSEC(MIN(POLL_TIMEOUT_MS, o->interval_ms)), &ab);
				if (err == 0) {
					br_publish_value(o, 0U, sdo_buf, len, co_line_now());
				} else if (err == -ECONNABORTED) {
					br_publish_value(o, ab, NULL, 0U, co_line_now());
				} else if (err == -EAGAIN) {
					br_publish_value(o, CO_SDO_AB_TIMEOUT, NULL, 0U,
							 co_line_now());
				} else {
					/* Another error (node gone, client busy): the next poll
					 * tries again. */
				}
			}
#endif
			o->next_us = co_line_now() + (uint64_t)o->interval_ms * 1000U;
		}
		next = MIN(next, o->next_us);
	}
	return next;
}

/* A request names the bridge that serves it, or none (any bridge). */
static bool for_us(const void *sample, bool sdo)
{
	const char *bridge = sdo ? ((const safeline_canopen_v1_SdoRequest *)sample)->bridge
				 : ((const safeline_canopen_v1_NmtRequest *)sample)->bridge;

	return bridge[0] == '\0' || strcmp(bridge, br.name) == 0;
}

/* --- The thread --------------------------------------------------------------------------------
 */

void br_request_thread(void *p1, void *p2, void *p3)
{
	while (atomic_get(&br.running) != 0) {
		uint64_t now = co_line_now();
		uint64_t next = MIN(poll_remote_objects(now), now + 1000000U);
		dds_attach_t hits[4];
		void *samples[1];
		dds_sample_info_t info[1];
		int n;

		now = co_line_now();
		if (dds_waitset_wait(br.ws, hits, ARRAY_SIZE(hits),
				     co_time_before_eq(next, now)
					     ? 0
					     : DDS_USECS((int64_t)(next - now))) < 0) {
			break;
		}
		/* One request at a time of each kind, so neither starves the other. */
		do {
			n = 0;
			samples[0] = NULL;
			if (dds_take(br.rd_sdo, samples, info, 1, 1) == 1) {
				if (info[0].valid_data && for_us(samples[0], true)) {
					handle_sdo(samples[0], info[0].publication_handle);
				}
				(void)dds_return_loan(br.rd_sdo, samples, 1);
				n++;
			}
			samples[0] = NULL;
			if (dds_take(br.rd_nmt, samples, info, 1, 1) == 1) {
				if (info[0].valid_data && for_us(samples[0], false)) {
					handle_nmt(samples[0], info[0].publication_handle);
				}
				(void)dds_return_loan(br.rd_nmt, samples, 1);
				n++;
			}
		} while (n > 0 && atomic_get(&br.running));
	}
	(void)atomic_set(&br.req_done, 1);
}
