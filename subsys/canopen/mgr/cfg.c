/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Configuration manager (CiA 302 §6): storage of 1F20h/1F22h per node, 1F25h requests and
 * the download of a concise DCF over an SDO client.
 *
 * Storage: a 1F20h/1F22h sub-index points either at const data of the application or into
 * the instance's pool. SDO writes stream into the free end of the pool and replace the old
 * value (compacting the pool) only with their last chunk, so an aborted transfer leaves the
 * old value. Compaction moves data, so it is refused while a download runs.
 *
 * Download: the stream is checked as a whole first, then each entry is one SDO download of
 * its bytes straight from storage; the next starts from the confirmation of the previous.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/util.h>

#include <canopen/cfg.h>
#include <canopen/node.h>
#include <canopen/sdo_cli.h>

LOG_MODULE_REGISTER(co_cfg, CONFIG_CANOPEN_LOG_LEVEL);

#define NODES CO_CFG_NODES

static const struct co_od_provider_api prov_api;

static inline uint32_t get_u32(const uint8_t *p)
{
	return (uint32_t)co_od_le_get(p, 4);
}

int co_cfg_cdcf_check(const uint8_t *data, size_t len, uint32_t *entries)
{
	if (data == NULL && len > 0) {
		return -EINVAL;
	}
	if (entries != NULL) {
		*entries = 0;
	}
	if (len < CO_CFG_CDCF_HDR_SIZE) {
		return -EBADMSG;
	}
	uint32_t n = get_u32(data);
	size_t pos = CO_CFG_CDCF_HDR_SIZE;

	for (uint32_t i = 0; i < n; i++) {
		if (len - pos < CO_CFG_CDCF_ENTRY_HDR) {
			return -EBADMSG;
		}
		uint32_t size = get_u32(data + pos + 3);

		pos += CO_CFG_CDCF_ENTRY_HDR;
		if (size > len - pos) {
			return -EBADMSG;
		}
		pos += size;
	}
	if (pos != len) {
		return -EBADMSG;
	}
	if (entries != NULL) {
		*entries = n;
	}
	return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Storage */

static const uint8_t empty_cdcf[CO_CFG_CDCF_HDR_SIZE];

static const uint8_t *slot_data(const struct co_cfg *cfg, const struct co_cfg_slot *s)
{
	return s->in_pool ? cfg->pool + s->off : s->ext;
}

static bool slot_set(const struct co_cfg_slot *s)
{
	return s->in_pool || s->ext != NULL;
}

/* Downloads read their stream in place: nothing may move while one runs. */
static bool pool_pinned(const struct co_cfg *cfg)
{
	for (int i = 0; i < CO_CFG_JOBS; i++) {
		if (cfg->jobs[i].active) {
			return true;
		}
	}
	return false;
}

/* Drop the pool copy of a slot and close the gap. */
static void slot_release(struct co_cfg *cfg, struct co_cfg_slot *s)
{
	if (s->in_pool) {
		uint32_t off = s->off;
		uint32_t len = s->len;
		/* Everything after it, including a value being received. */
		uint32_t end = cfg->pool_used + (cfg->wr_slot != NULL ? cfg->wr_len : 0U);

		(void)memmove(cfg->pool + off, cfg->pool + off + len, end - off - len);
		cfg->pool_used -= len;
		for (int k = 0; k < 2; k++) {
			struct co_cfg_slot *t = k == 0 ? cfg->cdcf : cfg->dcf;

			for (unsigned int i = 0; i < NODES; i++) {
				if (t[i].in_pool && t[i].off > off) {
					t[i].off -= len;
				}
			}
		}
	}
	*s = (struct co_cfg_slot){0};
}

static struct co_cfg_slot *slot_of(struct co_cfg *cfg, uint16_t index, uint8_t sub)
{
	if (sub < 1U || sub > NODES) {
		return NULL;
	}
	return index == CO_CFG_INDEX_CDCF ? &cfg->cdcf[sub - 1U] : &cfg->dcf[sub - 1U];
}

static int set_ext(struct co_cfg *cfg, struct co_cfg_slot *table, uint8_t id, const uint8_t *data,
		   size_t len)
{
	if (cfg == NULL || cfg->node == NULL || id < 1U || id > NODES ||
	    (data == NULL && len > 0) || len > UINT32_MAX) {
		return -EINVAL;
	}
	int ret = 0;

	co_node_lock(cfg->node);
	struct co_cfg_slot *s = &table[id - 1U];

	if (s->in_pool && pool_pinned(cfg)) {
		ret = -EBUSY;
	} else if (table == cfg->cdcf && co_cfg_busy(cfg, id)) {
		ret = -EBUSY;
	} else {
		slot_release(cfg, s);
		if (len > 0) {
			s->ext = data;
			s->len = (uint32_t)len;
		}
	}
	co_node_unlock(cfg->node);
	return ret;
}

int co_cfg_set_concise_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t *data, size_t len)
{
	return set_ext(cfg, cfg != NULL ? cfg->cdcf : NULL, id, data, len);
}

int co_cfg_set_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t *text, size_t len)
{
	return set_ext(cfg, cfg != NULL ? cfg->dcf : NULL, id, text, len);
}

int co_cfg_get_concise_dcf(struct co_cfg *cfg, uint8_t id, const uint8_t **data, size_t *len)
{
	if (cfg == NULL || cfg->node == NULL || id < 1U || id > NODES || data == NULL ||
	    len == NULL) {
		return -EINVAL;
	}
	int ret = -ENOENT;

	co_node_lock(cfg->node);
	const struct co_cfg_slot *s = &cfg->cdcf[id - 1U];

	if (slot_set(s)) {
		*data = slot_data(cfg, s);
		*len = s->len;
		ret = 0;
	}
	co_node_unlock(cfg->node);
	return ret;
}

int co_cfg_get_expected(struct co_cfg *cfg, uint8_t id, uint32_t *date, uint32_t *time)
{
	if (cfg == NULL || cfg->node == NULL || id < 1U || id > NODES || date == NULL ||
	    time == NULL) {
		return -EINVAL;
	}
	co_node_lock(cfg->node);
	const struct co_od *od = co_node_od(cfg->node);

	*date = co_od_uint(od, CO_CFG_INDEX_DATE, id, 0U);
	*time = co_od_uint(od, CO_CFG_INDEX_TIME, id, 0U);
	co_node_unlock(cfg->node);
	return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Object provider for 1F20h-1F27h */

static struct co_cfg *prov_cfg(const struct co_od_provider *p)
{
	return p->user_data;
}

static uint32_t prov_info(const struct co_od_provider *p, struct co_od_info *info)
{
	uint8_t sub = info->sub;
	uint8_t last = NODES;

	switch (info->index) {
	case CO_CFG_INDEX_DCF:
	case CO_CFG_INDEX_CDCF:
	case CO_CFG_INDEX_REQ:
	case CO_CFG_INDEX_DATE:
	case CO_CFG_INDEX_TIME:
		break;
	default:
		return CO_SDO_AB_NO_OBJECT;
	}
	if (info->index == CO_CFG_INDEX_REQ) {
		last = CO_CFG_ALL;
	}
	if (sub > last) {
		return CO_SDO_AB_NO_SUB;
	}
	info->objcode = CO_OD_OBJ_ARRAY;
	if (sub == 0U) {
		info->dtype = CO_DTYPE_UNSIGNED8;
		info->access = CO_OD_ACCESS_CONST;
		info->size = 1;
		return 0;
	}
	switch (info->index) {
	case CO_CFG_INDEX_DCF:
	case CO_CFG_INDEX_CDCF:
		info->dtype = CO_DTYPE_DOMAIN;
		info->access = CO_OD_ACCESS_RW;
		info->flags = CO_OD_F_STREAM;
		/* Capacity: what an SDO write may bring, or the application data if larger. */
		info->size = MAX((uint32_t)CO_CFG_POOL_SIZE,
				 slot_of(prov_cfg(p), info->index, sub)->len);
		break;
	default:
		/* 1F25h: a trigger; reads give 0 (CiA 302 §6.4 leaves them open). */
		info->dtype = CO_DTYPE_UNSIGNED32;
		info->access = CO_OD_ACCESS_RW;
		info->size = 4;
		break;
	}
	return 0;
}

static uint32_t prov_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	struct co_cfg *cfg = prov_cfg(p);

	if (info->sub == 0U || info->dtype != CO_DTYPE_DOMAIN) {
		return info->size;
	}
	const struct co_cfg_slot *s = slot_of(cfg, info->index, info->sub);

	if (slot_set(s)) {
		return s->len;
	}
	return info->index == CO_CFG_INDEX_CDCF ? CO_CFG_CDCF_HDR_SIZE : 0U;
}

static uint32_t prov_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	struct co_cfg *cfg = prov_cfg(p);
	uint8_t tmp[4];
	const uint8_t *src = tmp;
	uint32_t total;

	if (info->sub == 0U) {
		tmp[0] = info->index == CO_CFG_INDEX_REQ ? CO_CFG_ALL : NODES;
		total = 1;
	} else if (info->dtype == CO_DTYPE_DOMAIN) {
		const struct co_cfg_slot *s = slot_of(cfg, info->index, info->sub);

		if (slot_set(s)) {
			src = slot_data(cfg, s);
			total = s->len;
		} else if (info->index == CO_CFG_INDEX_CDCF) {
			/* An empty 1F22h reads as the empty data set (CiA 302 §6.2). */
			src = empty_cdcf;
			total = sizeof(empty_cdcf);
		} else {
			return CO_SDO_AB_NO_DATA;
		}
	} else {
		uint32_t v = 0;

		if (info->index == CO_CFG_INDEX_DATE) {
			v = cfg->date[info->sub - 1U];
		} else if (info->index == CO_CFG_INDEX_TIME) {
			v = cfg->time[info->sub - 1U];
		} else {
			/* 1F25h (configure request): reads as 0, its write is the request. */
		}
		co_od_le_put(tmp, 4, v);
		total = 4;
	}
	*len = 0;
	if (offset < total) {
		*len = MIN(cap, (size_t)(total - offset));
		(void)memcpy(buf, src + offset, *len);
	}
	return 0;
}

static void wr_drop(struct co_cfg *cfg)
{
	cfg->wr_slot = NULL;
	cfg->wr_len = 0;
}

static uint32_t stream_write(struct co_cfg *cfg, const struct co_od_info *info, uint32_t offset,
			     const uint8_t *data, size_t len, bool last)
{
	struct co_cfg_slot *s = slot_of(cfg, info->index, info->sub);

	if (data == NULL && len == 0U && last) {
		/* The transfer was aborted (od.c signals it with an empty last chunk). */
		wr_drop(cfg);
		return 0;
	}
	if (offset == 0U) {
		if (pool_pinned(cfg)) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
		cfg->wr_slot = s;
		cfg->wr_len = 0;
	} else if (cfg->wr_slot != s || offset != cfg->wr_len) {
		wr_drop(cfg);
		return CO_SDO_AB_GENERAL;
	} else {
		/* The next chunk of the transfer under way. */
	}
	if (len > CO_CFG_POOL_SIZE - cfg->pool_used - cfg->wr_len) {
		wr_drop(cfg);
		return CO_SDO_AB_OUT_OF_MEM;
	}
	if (len > 0U) {
		(void)memcpy(cfg->pool + cfg->pool_used + cfg->wr_len, data, len);
		cfg->wr_len += (uint32_t)len;
	}
	if (!last) {
		return 0;
	}
	const uint8_t *val = cfg->pool + cfg->pool_used;
	uint32_t n = 0;

	if (info->index == CO_CFG_INDEX_CDCF && co_cfg_cdcf_check(val, cfg->wr_len, &n) != 0) {
		wr_drop(cfg);
		return CO_SDO_AB_DATA_XFER;
	}
	if (pool_pinned(cfg)) {
		wr_drop(cfg);
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	uint32_t wlen = cfg->wr_len;
	bool empty = wlen == 0U || (info->index == CO_CFG_INDEX_CDCF && n == 0U);

	/* Release the old value while wr_slot still marks the new one as data to move. */
	slot_release(cfg, s);
	wr_drop(cfg);
	if (!empty) {
		*s = (struct co_cfg_slot){.off = cfg->pool_used, .len = wlen, .in_pool = true};
		cfg->pool_used += wlen;
	}
	return 0;
}

static uint32_t prov_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	struct co_cfg *cfg = prov_cfg(p);

	if (info->dtype == CO_DTYPE_DOMAIN) {
		return stream_write(cfg, info, offset, data, len, last);
	}
	if (len != 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	if (info->index == CO_CFG_INDEX_DATE) {
		cfg->date[info->sub - 1U] = get_u32(data);
	} else if (info->index == CO_CFG_INDEX_TIME) {
		cfg->time[info->sub - 1U] = get_u32(data);
	} else {
		/* 1F25h: see below. */
	}
	/* 1F25h is carried out by its validate hook and never stored. */
	return 0;
}

static const struct co_od_provider_api prov_api = {
	.info = prov_info,
	.length = prov_length,
	.read = prov_read,
	.write = prov_write,
};

/* ---------------------------------------------------------------------------------------- */
/* Download engine */

static void job_finish(struct co_cfg_job *job, uint32_t ab, uint16_t index, uint8_t sub)
{
	co_cfg_con_t con = job->con;
	void *user_data = job->user_data;
	uint8_t id = job->id;

	/* Free the slot first: the confirmation may start the next download. */
	job->active = false;
	co_timer_stop(&job->defer);
	if (ab != 0U) {
		LOG_WRN("node %u: configuration of %04Xh:%02Xh aborted (%08Xh)", id, index, sub,
			ab);
	}
	con(job->cfg->node, id, ab, index, sub, user_data);
}

static void job_sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data);

static int job_send_next(struct co_cfg_job *job)
{
	const uint8_t *e = job->data + job->pos;
	uint32_t size = get_u32(e + 3);

	job->index = (uint16_t)co_od_le_get(e, 2);
	job->sub = e[2];
	job->pos += CO_CFG_CDCF_ENTRY_HDR + size;
	job->remaining--;
	return co_sdo_cli_download_req(job->cli, job->index, job->sub, e + CO_CFG_CDCF_ENTRY_HDR,
				       size, CO_SDO_CLI_AUTO, CO_CFG_SDO_TIMEOUT, job_sdo_con, job);
}

static void job_sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	struct co_cfg_job *job = user_data;

	ARG_UNUSED(cli);
	ARG_UNUSED(size);
	if (!job->active) {
		return;
	}
	if (abort_code != 0U) {
		job_finish(job, abort_code, job->index, job->sub);
		return;
	}
	if (job->remaining == 0U) {
		job_finish(job, 0U, 0U, 0U);
		return;
	}
	if (job_send_next(job) != 0) {
		/* The client refused the next entry (node stopped or reset meanwhile). */
		job_finish(job, CO_SDO_AB_GENERAL, job->index, job->sub);
	}
}

static void job_defer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_cfg_job *job = timer->user_data;

	ARG_UNUSED(now_us);
	if (job->active) {
		job_finish(job, 0U, 0U, 0U);
	}
}

static struct co_cfg_job *job_of(struct co_cfg *cfg, uint8_t id)
{
	for (int i = 0; i < CO_CFG_JOBS; i++) {
		if (cfg->jobs[i].active && cfg->jobs[i].id == id) {
			return &cfg->jobs[i];
		}
	}
	return NULL;
}

static int job_start(struct co_cfg *cfg, struct co_sdo_cli *cli, uint8_t id, co_cfg_con_t con,
		     void *user_data)
{
	const struct co_cfg_slot *s = &cfg->cdcf[id - 1U];
	struct co_cfg_job *job = NULL;
	uint32_t n;

	if (!slot_set(s)) {
		return -ENOENT;
	}
	const uint8_t *data = slot_data(cfg, s);

	if (co_cfg_cdcf_check(data, s->len, &n) != 0) {
		LOG_ERR("node %u: malformed concise DCF (%u bytes)", id, s->len);
		return -EBADMSG;
	}
	if (job_of(cfg, id) != NULL || co_sdo_cli_busy(cli)) {
		return -EBUSY;
	}
	for (int i = 0; i < CO_CFG_JOBS; i++) {
		if (!cfg->jobs[i].active) {
			job = &cfg->jobs[i];
			break;
		}
	}
	if (job == NULL) {
		return -EBUSY;
	}
	job->cli = cli;
	job->con = con;
	job->user_data = user_data;
	job->data = data;
	job->len = s->len;
	job->pos = CO_CFG_CDCF_HDR_SIZE;
	job->remaining = n;
	job->id = id;
	job->index = 0;
	job->sub = 0;
	job->active = true;
	if (n == 0U) {
		/* Confirm from the line thread, never inside the request. */
		co_node_timer_start(cfg->node, &job->defer, co_node_time(cfg->node));
		return 0;
	}
	int ret = job_send_next(job);

	if (ret != 0) {
		job->active = false;
	}
	return ret;
}

int co_cfg_download_req(struct co_cfg *cfg, struct co_sdo_cli *cli, uint8_t id, co_cfg_con_t con,
			void *user_data)
{
	if (cfg == NULL || cfg->node == NULL || cli == NULL || con == NULL || id < 1U ||
	    id > NODES) {
		return -EINVAL;
	}
	co_node_lock(cfg->node);
	int ret = job_start(cfg, cli, id, con, user_data);

	co_node_unlock(cfg->node);
	return ret;
}

bool co_cfg_busy(struct co_cfg *cfg, uint8_t id)
{
	bool busy;

	if (cfg == NULL || cfg->node == NULL) {
		return false;
	}
	co_node_lock(cfg->node);
	busy = id == CO_CFG_ALL ? pool_pinned(cfg) || cfg->all_next != 0U : job_of(cfg, id) != NULL;
	co_node_unlock(cfg->node);
	return busy;
}

/* ---------------------------------------------------------------------------------------- */
/* 1F25h configuration request */

static void indicate(struct co_cfg *cfg, uint8_t id, uint32_t ab, uint16_t index, uint8_t sub)
{
	if (cfg->ind != NULL) {
		cfg->ind(cfg->node, id, ab, index, sub, cfg->ind_user_data);
	}
}

/*
 * Clients a 1F25h request may use: the NMT master boots slave slot i on client i and aborts
 * whatever that client does when the slot's slave (re)boots, so the slot clients are never
 * lent to 1F25h (doc/cfg.md: CONFIG_CANOPEN_SDO_CLIENTS >= CONFIG_CANOPEN_MGR_SLAVES + 1).
 */
#if defined(CONFIG_CANOPEN_MGR)
#define REQ_CLI_FIRST CONFIG_CANOPEN_MGR_SLAVES
#else
#define REQ_CLI_FIRST 0
#endif

/* The idle client with the highest number among those 1F25h may use. */
static struct co_sdo_cli *idle_client(struct co_cfg *cfg)
{
	for (int i = CONFIG_CANOPEN_SDO_CLIENTS - 1; i >= REQ_CLI_FIRST; i--) {
		struct co_sdo_cli *cli = co_sdo_cli_get(cfg->node, (uint8_t)i);
		bool used = false;

		if (cli == NULL || co_sdo_cli_busy(cli)) {
			continue;
		}
		for (int j = 0; j < CO_CFG_JOBS; j++) {
			used = used || (cfg->jobs[j].active && cfg->jobs[j].cli == cli);
		}
		if (!used) {
			return cli;
		}
	}
	return NULL;
}

static void one_con(struct co_node *node, uint8_t id, uint32_t ab, uint16_t index, uint8_t sub,
		    void *user_data)
{
	ARG_UNUSED(node);
	indicate(user_data, id, ab, index, sub);
}

static uint32_t start_one(struct co_cfg *cfg, struct co_sdo_cli *cli, uint8_t id, co_cfg_con_t con)
{
	if (co_sdo_cli_set_server(cli, id) != 0) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	switch (job_start(cfg, cli, id, con, cfg)) {
	case 0:
		return 0U;
	case -ENOENT:
		return CO_SDO_AB_NO_DATA;
	case -EBADMSG:
		return CO_SDO_AB_DATA_XFER;
	default:
		return CO_SDO_AB_DATA_DEV_STATE;
	}
}

static void all_con(struct co_node *node, uint8_t id, uint32_t ab, uint16_t index, uint8_t sub,
		    void *user_data);

/* Start the next node of a 1F25h:80h sweep, from cfg->all_next; false when none is left. */
static bool all_next(struct co_cfg *cfg, struct co_sdo_cli *cli)
{
	for (unsigned int id = cfg->all_next; id <= NODES; id++) {
		if (!slot_set(&cfg->cdcf[id - 1U])) {
			continue;
		}
		cfg->all_next = (uint8_t)(id + 1U);
		uint32_t ab = start_one(cfg, cli, (uint8_t)id, all_con);

		if (ab == 0U) {
			return true;
		}
		/* Not started (malformed data, node down): report it and go on. */
		indicate(cfg, (uint8_t)id, ab, 0, 0);
		if (cfg->all_abort == 0U) {
			cfg->all_abort = ab;
		}
	}
	return false;
}

static void all_done(struct co_cfg *cfg)
{
	uint32_t ab = cfg->all_abort;
	uint16_t index = cfg->all_index;
	uint8_t sub = cfg->all_sub;

	cfg->all_next = 0;
	indicate(cfg, CO_CFG_ALL, ab, index, sub);
}

static void all_con(struct co_node *node, uint8_t id, uint32_t ab, uint16_t index, uint8_t sub,
		    void *user_data)
{
	struct co_cfg *cfg = user_data;
	struct co_sdo_cli *cli = NULL;

	ARG_UNUSED(node);
	if (ab != 0U && cfg->all_abort == 0U) {
		cfg->all_abort = ab;
		cfg->all_index = index;
		cfg->all_sub = sub;
	}
	indicate(cfg, id, ab, index, sub);
	if (cfg->all_next > NODES || cfg->all_next == 0U) {
		all_done(cfg);
		return;
	}
	cli = idle_client(cfg);
	if (cli == NULL || !all_next(cfg, cli)) {
		if (cli == NULL && cfg->all_abort == 0U) {
			cfg->all_abort = CO_SDO_AB_NO_RESOURCE;
		}
		all_done(cfg);
	}
}

static void all_empty_con(struct co_node *node, uint8_t id, uint32_t ab, uint16_t index,
			  uint8_t sub, void *user_data)
{
	ARG_UNUSED(node);
	ARG_UNUSED(id);
	ARG_UNUSED(ab);
	ARG_UNUSED(index);
	ARG_UNUSED(sub);
	all_done(user_data);
}

/* A deferred "nothing to configure" answer for 1F25h:80h: a job slot with its timer. */
static uint32_t all_nothing(struct co_cfg *cfg)
{
	for (int i = 0; i < CO_CFG_JOBS; i++) {
		struct co_cfg_job *job = &cfg->jobs[i];

		if (!job->active) {
			job->con = all_empty_con;
			job->user_data = cfg;
			job->cli = NULL;
			job->id = CO_CFG_ALL;
			job->remaining = 0;
			job->active = true;
			co_node_timer_start(cfg->node, &job->defer, co_node_time(cfg->node));
			return CO_OD_HANDLED;
		}
	}
	return CO_SDO_AB_DATA_DEV_STATE;
}

static uint32_t req_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_cfg *cfg = user_data;
	uint8_t sub = req->info->sub;

	ARG_UNUSED(od);
	if (sub == 0U) {
		return 0U;
	}
	if (req->len != 4U || get_u32(req->data) != CO_CFG_SIGNATURE_CONF) {
		/* CiA 302 §6.4 names no code; 302-2 uses 06090030h for reserved values. */
		return CO_SDO_AB_INVALID_VALUE;
	}
	struct co_sdo_cli *cli;

	if (sub != CO_CFG_ALL) {
		if (!slot_set(&cfg->cdcf[sub - 1U])) {
			return CO_SDO_AB_NO_DATA;
		}
		if (job_of(cfg, sub) != NULL || cfg->all_next != 0U) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
		cli = idle_client(cfg);
		if (cli == NULL) {
			return CO_SDO_AB_NO_RESOURCE;
		}
		uint32_t ab = start_one(cfg, cli, sub, one_con);

		return ab != 0U ? ab : CO_OD_HANDLED;
	}
	if (cfg->all_next != 0U || pool_pinned(cfg)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	cfg->all_abort = 0;
	cfg->all_index = 0;
	cfg->all_sub = 0;
	cfg->all_next = 1;
	cli = idle_client(cfg);
	if (cli == NULL) {
		cfg->all_next = 0;
		return CO_SDO_AB_NO_RESOURCE;
	}
	if (all_next(cfg, cli)) {
		return CO_OD_HANDLED;
	}
	/* No node has data (the request still succeeds, CiA 302 §6.4), or none started. */
	uint32_t ab = all_nothing(cfg);

	if (ab != CO_OD_HANDLED) {
		cfg->all_next = 0;
	}
	return ab;
}

/* ---------------------------------------------------------------------------------------- */
/* Life cycle */

int co_cfg_init(struct co_cfg *cfg, struct co_node *node)
{
	if (cfg == NULL || node == NULL) {
		return -EINVAL;
	}
	(void)memset(cfg, 0, sizeof(*cfg));
	cfg->node = node;
	cfg->prov = (struct co_od_provider){
		.api = &prov_api,
		.index_first = CO_CFG_INDEX_DCF,
		.index_last = CO_CFG_INDEX_TIME,
		.user_data = cfg,
	};
	for (int i = 0; i < CO_CFG_JOBS; i++) {
		cfg->jobs[i].cfg = cfg;
		co_timer_init(&cfg->jobs[i].defer, job_defer_handler, &node->lock, &cfg->jobs[i]);
	}
	const struct co_od_hook hook = {
		.index_first = CO_CFG_INDEX_REQ,
		.index_last = CO_CFG_INDEX_REQ,
		.sub_first = 1,
		.sub_last = CO_CFG_ALL,
		.validate = req_validate,
		.user_data = cfg,
	};
	int ret;

	co_node_lock(node);
	struct co_od *od = co_node_od(node);

	ret = co_od_provider_register(od, &cfg->prov);
	if (ret == 0) {
		ret = co_od_hook_register(od, &hook);
	}
	co_node_unlock(node);
	if (ret != 0) {
		cfg->node = NULL;
	}
	return ret;
}

struct co_cfg *co_cfg_get(struct co_node *node)
{
	struct co_cfg *cfg = NULL;

	if (node == NULL) {
		return NULL;
	}
	co_node_lock(node);
	const struct co_od *od = co_node_od(node);

	for (uint8_t i = 0; i < od->n_prov; i++) {
		if (od->prov[i]->api == &prov_api) {
			cfg = od->prov[i]->user_data;
			break;
		}
	}
	co_node_unlock(node);
	return cfg;
}

int co_cfg_set_ind(struct co_cfg *cfg, co_cfg_con_t ind, void *user_data)
{
	if (cfg == NULL || cfg->node == NULL) {
		return -EINVAL;
	}
	co_node_lock(cfg->node);
	cfg->ind = ind;
	cfg->ind_user_data = user_data;
	co_node_unlock(cfg->node);
	return 0;
}
