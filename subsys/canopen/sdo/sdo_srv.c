/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * CiA 301 SDO server (§7.2.4): expedited, segmented and block transfers in both directions.
 *
 * I/O-free: a frame and its reception time come in through the line receiver, frames go out
 * through co_node_send(), the only deadline is a line timer. Everything runs with the node's
 * mutex held (line dispatch, or the node's API for the dictionary hook).
 *
 * Data path. Downloads collect bytes in srv->buf and hand them to the dictionary's chunked
 * write (co_od_write_begin/chunk) whenever the buffer is full, committing with the last chunk;
 * the dictionary stages the value (or streams it to a provider), so a transfer that ends in an
 * abort leaves the old value intact. Uploads read the value through a window: srv->buf holds
 * bytes [buf_off, buf_off + buf_len) of it and is refilled from the dictionary at the needed
 * offset, so values of any size stream in buffer-sized chunks and a value that fits the buffer
 * is read once, consistently, at the initiate.
 *
 * The reactions to malformed and unexpected frames are listed in doc/sdo.md.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>
#include <zephyr/sys/util.h>

#include <canopen/cob_id.h>
#include <canopen/node.h>
#include <canopen/sdo.h>

#include "node_internal.h"
#include "sdo_internal.h"

LOG_MODULE_REGISTER(co_sdo_srv, CONFIG_CANOPEN_LOG_LEVEL);

#define TIMEOUT_US   ((uint64_t)CONFIG_CANOPEN_SDO_SERVER_TIMEOUT * 1000U)
/* How many times a timeout is put off while our own frames wait in the line's TX queue. */
#define TX_WAITS_MAX 8U

#if defined(CONFIG_CANOPEN_SDO_BLOCK)
#define BLKSIZE        ((uint8_t)CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE)
#define SUB_TIMEOUT_US ((uint64_t)CONFIG_CANOPEN_SDO_BLOCK_SUBBLOCK_TIMEOUT * 1000U)
#endif

/* Pause before offering a sub-block segment again to a line whose TX queue refused it. */
#define TX_RETRY_US 1000U

#define BUF_SIZE ((uint32_t)CO_SDO_SRV_BUF_SIZE)

#define SFF_MASK 0x7ffU
#define EFF_MASK 0x1fffffffU

BUILD_ASSERT(CO_SDO_SRV_BUF_SIZE >= CO_SDO_SEG_SIZE, "the buffer must hold a segment");
BUILD_ASSERT(CONFIG_CANOPEN_SDO_SERVERS >= 1 && CONFIG_CANOPEN_SDO_SERVERS <= 128,
	     "SDO server parameters are 1200h-127Fh");

enum srv_state {
	ST_IDLE = 0,
	/* Segmented download: waiting for a download segment. */
	ST_DN_SEG,
	/* Segmented upload: waiting for an upload segment request. */
	ST_UP_SEG,
	/* Block download: receiving the segments of a sub-block. */
	ST_BLK_DN_SUB,
	/* Block download: last segment acknowledged, waiting for the end request. */
	ST_BLK_DN_END,
	/* Block upload: initiate answered, waiting for the start request. */
	ST_BLK_UP_START,
	/* Block upload: sub-block (being) sent, waiting for the acknowledgement. */
	ST_BLK_UP_SUB,
	/* Block upload: end request sent, waiting for the end response. */
	ST_BLK_UP_END,
};

static struct co_od *srv_od(struct co_sdo_srv *srv)
{
	return co_node_od(srv->node);
}

static void put_mux(uint8_t *d, uint16_t index, uint8_t sub)
{
	sys_put_le16(index, &d[1]);
	d[3] = sub;
}

static int srv_send(struct co_sdo_srv *srv, const uint8_t d[CO_SDO_DLC])
{
	struct can_frame f;

	(void)memset(&f, 0, sizeof(f));
	if ((srv->cob_tx & CO_SDO_COBID_FRAME) != 0U) {
		f.id = srv->cob_tx & EFF_MASK;
		f.flags = CAN_FRAME_IDE;
	} else {
		f.id = srv->cob_tx & SFF_MASK;
	}
	f.dlc = CO_SDO_DLC;
	(void)memcpy(f.data, d, CO_SDO_DLC);
	return co_node_send(srv->node, srv->route, &f);
}

/*
 * Send a frame made of byte 0, the transfer's multiplexer and @p v in bytes 4..7 (an abort
 * code, a size, a block size or 0): one sender for every frame of that shape.
 */
static void srv_send_mux(struct co_sdo_srv *srv, uint8_t b0, uint32_t v)
{
	uint8_t r[CO_SDO_DLC] = {b0};

	put_mux(r, srv->index, srv->sub);
	sys_put_le32(v, &r[4]);
	(void)srv_send(srv, r);
}

static bool is_download(uint8_t state)
{
	return state == ST_DN_SEG || state == ST_BLK_DN_SUB || state == ST_BLK_DN_END;
}

/*
 * End the transfer (whatever the reason) and go idle; a pending write is dropped. Every way
 * back to idle passes here, so a download starts with an empty buffer; an upload's first
 * read sets the window.
 */
static void srv_end(struct co_sdo_srv *srv)
{
	if (is_download(srv->state)) {
		co_od_write_abort(srv_od(srv), &srv->xfer);
	}
	co_timer_stop(&srv->timer);
	srv->state = ST_IDLE;
	srv->buf_len = 0U;
}

static void srv_complete(struct co_sdo_srv *srv)
{
	srv->stats.completed++;
	srv_end(srv);
}

/* Drop a running transfer without a frame (NMT, reset, reconfiguration). */
static void srv_drop(struct co_sdo_srv *srv)
{
	if (srv->state != ST_IDLE) {
		srv->stats.dropped++;
		srv_end(srv);
	}
}

static void srv_abort(struct co_sdo_srv *srv, uint32_t code)
{
	LOG_DBG("SDO server %u: abort %04x:%02x %08x (%s)", srv->num, srv->index, srv->sub, code,
		co_sdo_abort_str(code));
	srv_send_mux(srv, CO_SDO_B0(CO_SDO_CS_ABORT, 0U), code);
	srv->stats.aborts_sent++;
	srv->stats.last_abort = code;
	srv_end(srv);
}

/* Arm the line timer for the earliest of the transfer's deadlines. */
static void srv_arm(struct co_sdo_srv *srv)
{
	uint64_t t = srv->deadline;

#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	if (srv->state == ST_BLK_UP_SUB && srv->seq < srv->blk_nseg &&
	    co_time_before_eq(srv->retry_at, t)) {
		t = srv->retry_at;
	}
	if (SUB_TIMEOUT_US != 0U && srv->state == ST_BLK_DN_SUB && srv->blk_flag &&
	    co_time_before_eq(srv->sub_deadline, t)) {
		t = srv->sub_deadline;
	}
#endif
	co_node_timer_start(srv->node, &srv->timer, t);
}

/* --- Download ---------------------------------------------------------------------------- */

/*
 * Whether @p len more bytes fit the announced size and the object. Streamed provider objects
 * check their own capacity.
 */
static bool dn_fits(const struct co_sdo_srv *srv, uint32_t len)
{
	uint64_t end = (uint64_t)srv->offset + len;

	if (srv->size_ind && end > srv->size) {
		return false;
	}
	return (srv->xfer.info.flags & CO_OD_F_STREAM) != 0U || end <= srv->xfer.info.size;
}

/* Append received bytes; hand the buffer to the dictionary first if they do not fit. */
static uint32_t dn_put(struct co_sdo_srv *srv, const uint8_t *p, uint32_t len)
{
	if (srv->buf_len + len > BUF_SIZE) {
		uint32_t code = co_od_write_chunk(srv_od(srv), &srv->xfer, srv->done, srv->buf,
						  srv->buf_len, false);

		if (code != CO_SDO_AB_NONE) {
			return code;
		}
		srv->done += srv->buf_len;
		srv->buf_len = 0U;
	}
	(void)memcpy(&srv->buf[srv->buf_len], p, len);
	srv->buf_len += len;
	return CO_SDO_AB_NONE;
}

/* Hand the rest to the dictionary, which checks, validates and commits the whole value. */
static uint32_t dn_commit(struct co_sdo_srv *srv)
{
	uint32_t code =
		co_od_write_chunk(srv_od(srv), &srv->xfer, srv->done, srv->buf, srv->buf_len, true);

	srv->done += srv->buf_len;
	srv->buf_len = 0U;
	return code;
}

static uint32_t dn_initiate(struct co_sdo_srv *srv, const uint8_t *d)
{
	struct co_od *od = srv_od(srv);
	uint32_t code;

	if ((d[0] & CO_SDO_INIT_E) != 0U) {
		size_t len;

		if ((d[0] & CO_SDO_INIT_S) != 0U) {
			len = CO_SDO_EXP_SIZE - CO_SDO_INIT_N(d[0]);
		} else {
			/* Size not indicated: a fixed-size type up to 4 bytes is that long,
			 * anything else takes all 4 bytes.
			 */
			struct co_od_info info;
			uint32_t tsize;

			code = co_od_find(od, srv->index, srv->sub, &info);
			if (code != CO_SDO_AB_NONE) {
				return code;
			}
			tsize = co_dtype_size(info.dtype);
			len = (tsize != 0U && tsize <= CO_SDO_EXP_SIZE) ? tsize : CO_SDO_EXP_SIZE;
		}
		code = co_od_write(od, srv->index, srv->sub, &d[4], len, CO_OD_WRITER_SDO);
		if (code != CO_SDO_AB_NONE) {
			return code;
		}
		srv_send_mux(srv, CO_SDO_B0(CO_SDO_SCS_DN_INIT, 0U), 0U);
		srv->stats.completed++;
		return CO_SDO_AB_NONE;
	}

	srv->size_ind = (d[0] & CO_SDO_INIT_S) != 0U;
	srv->size = srv->size_ind ? sys_get_le32(&d[4]) : 0U;
	code = co_od_write_begin(od, &srv->xfer, srv->index, srv->sub, srv->size, CO_OD_WRITER_SDO);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv->state = ST_DN_SEG;
	srv->offset = 0U;
	srv->done = 0U;
	srv->toggle = 0U;
	srv_send_mux(srv, CO_SDO_B0(CO_SDO_SCS_DN_INIT, 0U), 0U);
	return CO_SDO_AB_NONE;
}

/* A download segment (toggle checked); its answer's byte 0 goes to r[0], without the toggle. */
static uint32_t dn_segment(struct co_sdo_srv *srv, const uint8_t *d, uint8_t *r)
{
	uint32_t len = CO_SDO_SEG_SIZE - CO_SDO_SEG_N(d[0]);
	bool last = (d[0] & CO_SDO_SEG_C) != 0U;
	uint32_t code;

	if (!dn_fits(srv, len)) {
		return CO_SDO_AB_DATA_LONG;
	}
	code = dn_put(srv, &d[1], len);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv->offset += len;
	if (last) {
		if (srv->size_ind && srv->offset < srv->size) {
			return CO_SDO_AB_DATA_SHORT;
		}
		code = dn_commit(srv);
		if (code != CO_SDO_AB_NONE) {
			return code;
		}
	}
	r[0] = CO_SDO_B0(CO_SDO_SCS_DN_SEG, 0U);
	return CO_SDO_AB_NONE;
}

/* --- Upload ------------------------------------------------------------------------------ */

/*
 * Make bytes [off, off + need) of the value available in the window (need is capped at the
 * buffer size). A refill reads as much of the value from @p off as fits, so consecutive
 * segments come from memory. With @p force the dictionary is read even if nothing is needed
 * (the initiate: the read checks the access rights).
 */
static uint32_t up_fill(struct co_sdo_srv *srv, uint32_t off, uint32_t need, bool force)
{
	uint32_t want;

	need = MIN(need, BUF_SIZE);
	if (!force && off >= srv->buf_off && off + need <= srv->buf_off + srv->buf_len) {
		return CO_SDO_AB_NONE;
	}
	want = MIN(BUF_SIZE, srv->size - off);
	srv->buf_off = off;
	srv->buf_len = 0U;
	do {
		size_t got = 0U;
		uint32_t code = co_od_read_info(srv_od(srv), &srv->xfer.info, off + srv->buf_len,
						&srv->buf[srv->buf_len], want - srv->buf_len, &got,
						CO_OD_WRITER_SDO);

		if (code != CO_SDO_AB_NONE) {
			srv->buf_len = 0U;
			return code;
		}
		if (got == 0U) {
			break;
		}
		srv->buf_len += MIN((uint32_t)got, want - srv->buf_len);
	} while (srv->buf_len < want);
	if (srv->buf_len < need) {
		/* The value became shorter than the size announced to the client. */
		LOG_WRN("SDO server %u: %04x:%02x shrank during upload", srv->num, srv->index,
			srv->sub);
		return CO_SDO_AB_GENERAL;
	}
	return CO_SDO_AB_NONE;
}

/* Look the object up, take its size and read the first window (access check). */
static uint32_t up_open(struct co_sdo_srv *srv)
{
	uint32_t code = co_od_find(srv_od(srv), srv->index, srv->sub, &srv->xfer.info);

	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv->size = co_od_length(srv_od(srv), &srv->xfer.info);
	return up_fill(srv, 0U, srv->size, true);
}

/* Answer an (initiate or switched block) upload request with the normal upload protocol. */
static uint32_t up_respond(struct co_sdo_srv *srv)
{
	if (srv->size >= 1U && srv->size <= CO_SDO_EXP_SIZE) {
		/* The value's bytes, the unused ones 0 (the buffer holds at least 7 bytes). */
		uint32_t v = sys_get_le32(srv->buf) &
			     (UINT32_MAX >> (8U * (CO_SDO_EXP_SIZE - srv->size)));

		srv_send_mux(srv,
			     CO_SDO_B0(CO_SDO_SCS_UP_INIT,
				       CO_SDO_INIT_E | CO_SDO_INIT_S |
					       CO_SDO_INIT_N_PUT(CO_SDO_EXP_SIZE - srv->size)),
			     v);
		srv_complete(srv);
		return CO_SDO_AB_NONE;
	}
	/* Segmented, size indicated; an empty value is one empty last segment. */
	srv->state = ST_UP_SEG;
	srv->offset = 0U;
	srv->toggle = 0U;
	srv_send_mux(srv, CO_SDO_B0(CO_SDO_SCS_UP_INIT, CO_SDO_INIT_S), srv->size);
	return CO_SDO_AB_NONE;
}

static uint32_t up_initiate(struct co_sdo_srv *srv)
{
	uint32_t code = up_open(srv);

	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	return up_respond(srv);
}

/* The next upload segment (toggle checked) into r, its byte 0 without the toggle. */
static uint32_t up_segment(struct co_sdo_srv *srv, uint8_t *r)
{
	uint32_t len;
	uint32_t code;
	bool last;

	len = MIN(CO_SDO_SEG_SIZE, srv->size - srv->offset);
	code = up_fill(srv, srv->offset, len, false);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	last = srv->offset + len >= srv->size;
	r[0] = CO_SDO_B0(CO_SDO_SCS_UP_SEG,
			 CO_SDO_SEG_N_PUT(CO_SDO_SEG_SIZE - len) | (last ? CO_SDO_SEG_C : 0U));
	(void)memcpy(&r[1], &srv->buf[srv->offset - srv->buf_off], len);
	srv->offset += len;
	return CO_SDO_AB_NONE;
}

/*
 * A frame of a segmented download or upload: the command and toggle checks, the answer with
 * the toggle and the step to the next segment are the same both ways.
 */
static uint32_t seg_transfer(struct co_sdo_srv *srv, const uint8_t *d)
{
	uint8_t r[CO_SDO_DLC] = {0};
	bool dn = srv->state == ST_DN_SEG;
	uint8_t t = d[0] & CO_SDO_SEG_T;
	uint32_t code;

	if (CO_SDO_CS(d[0]) != (dn ? CO_SDO_CCS_DN_SEG : CO_SDO_CCS_UP_SEG)) {
		return CO_SDO_AB_CMD;
	}
	if ((t != 0U) != (srv->toggle != 0U)) {
		return CO_SDO_AB_TOGGLE;
	}
	code = dn ? dn_segment(srv, d, r) : up_segment(srv, r);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	r[0] |= t;
	(void)srv_send(srv, r);
	/* The last segment: c is bit 0 of the request downloading, of the answer uploading. */
	if ((((dn ? d[0] : r[0]) & CO_SDO_SEG_C) != 0U)) {
		srv_complete(srv);
	} else {
		srv->toggle ^= 1U;
	}
	return CO_SDO_AB_NONE;
}

/* --- Block download ---------------------------------------------------------------------- */

#if defined(CONFIG_CANOPEN_SDO_BLOCK)

static void blk_dn_ack(struct co_sdo_srv *srv)
{
	uint8_t r[CO_SDO_DLC] = {CO_SDO_B0(CO_SDO_SCS_BLK_DN, CO_SDO_BLK_SUB_ACK), srv->seq,
				 srv->blksize};

	(void)srv_send(srv, r);
	srv->seq = 0U;
	srv->blk_flag = false;
}

static uint32_t blk_dn_initiate(struct co_sdo_srv *srv, const uint8_t *d)
{
	uint32_t code;

	srv->crc_on = (d[0] & CO_SDO_BLK_CRC) != 0U;
	srv->size_ind = (d[0] & CO_SDO_BLK_S) != 0U;
	srv->size = srv->size_ind ? sys_get_le32(&d[4]) : 0U;
	code = co_od_write_begin(srv_od(srv), &srv->xfer, srv->index, srv->sub, srv->size,
				 CO_OD_WRITER_SDO);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv->state = ST_BLK_DN_SUB;
	srv->offset = 0U;
	srv->done = 0U;
	srv->crc = 0U;
	srv->seq = 0U;
	srv->blksize = BLKSIZE;
	srv->blk_flag = false;
	/*
	 * The server supports the CRC, but says so only to a client that asked for it: the CRC
	 * is used when both sides support it, and some clients (python-canopen) read the
	 * server's bit alone.
	 */
	srv_send_mux(srv,
		     CO_SDO_B0(CO_SDO_SCS_BLK_DN,
			       (srv->crc_on ? CO_SDO_BLK_CRC : 0U) | CO_SDO_BLK_SUB_INIT),
		     srv->blksize);
	return CO_SDO_AB_NONE;
}

static uint32_t blk_dn_segment(struct co_sdo_srv *srv, const uint8_t *d, uint64_t now)
{
	uint8_t seqno = CO_SDO_BLK_SEQNO(d[0]);
	bool last = (d[0] & CO_SDO_BLK_SEG_C) != 0U;
	bool got_last = false;

	if (seqno == 0U || seqno > srv->blksize) {
		return CO_SDO_AB_SEQ_NUM;
	}
	if (seqno <= srv->seq) {
		/* A duplicate: already have it. */
		srv->stats.blk_seg_ignored++;
		return CO_SDO_AB_NONE;
	}
	srv->blk_flag = true;
	if (seqno == srv->seq + 1U) {
		if (last) {
			/* Its length is only known from the end request. */
			(void)memcpy(srv->tail, &d[1], sizeof(srv->tail));
			got_last = true;
		} else {
			uint32_t code;

			if (!dn_fits(srv, CO_SDO_SEG_SIZE)) {
				return CO_SDO_AB_DATA_LONG;
			}
			code = dn_put(srv, &d[1], CO_SDO_SEG_SIZE);
			if (code != CO_SDO_AB_NONE) {
				return code;
			}
			if (srv->crc_on) {
				srv->crc = crc16_itu_t(srv->crc, &d[1], CO_SDO_SEG_SIZE);
			}
			srv->offset += CO_SDO_SEG_SIZE;
		}
		srv->seq = seqno;
	} else {
		/* After a gap: ignored; the acknowledgement makes the client resend. */
		srv->stats.blk_seg_ignored++;
	}
	if (seqno == srv->blksize || last) {
		blk_dn_ack(srv);
		if (got_last) {
			srv->state = ST_BLK_DN_END;
		}
	} else if (SUB_TIMEOUT_US != 0U) {
		srv->sub_deadline = now + SUB_TIMEOUT_US;
	} else {
		/* No sub-block timeout configured: the whole-transfer timeout applies. */
	}
	return CO_SDO_AB_NONE;
}

static uint32_t blk_dn_end(struct co_sdo_srv *srv, const uint8_t *d)
{
	uint32_t valid = CO_SDO_SEG_SIZE - CO_SDO_BLK_N(d[0]);
	uint32_t total = srv->offset + valid;
	uint32_t code;

	if (srv->crc_on) {
		uint16_t crc = crc16_itu_t(srv->crc, srv->tail, valid);

		if (crc != sys_get_le16(&d[1])) {
			return CO_SDO_AB_CRC;
		}
	}
	if (srv->size_ind && total != srv->size) {
		return total > srv->size ? CO_SDO_AB_DATA_LONG : CO_SDO_AB_DATA_SHORT;
	}
	code = dn_put(srv, srv->tail, valid);
	if (code == CO_SDO_AB_NONE) {
		srv->offset = total;
		code = dn_commit(srv);
	}
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv_send_mux(srv, CO_SDO_B0(CO_SDO_SCS_BLK_DN, CO_SDO_BLK_SUB_END), 0U);
	srv_complete(srv);
	return CO_SDO_AB_NONE;
}

/* --- Block upload ------------------------------------------------------------------------ */

/* Set up the sub-block starting at srv->offset with srv->blksize segments at most. */
static uint32_t blk_up_sub_begin(struct co_sdo_srv *srv)
{
	uint32_t rest = srv->size - srv->offset;
	/* An empty value still takes one (empty) segment. */
	uint32_t nseg_rest = rest == 0U ? 1U : DIV_ROUND_UP(rest, CO_SDO_SEG_SIZE);

	srv->blk_nseg = (uint8_t)MIN(nseg_rest, (uint32_t)srv->blksize);
	srv->blk_flag = nseg_rest <= srv->blksize;
	srv->seq = 0U;
	/* Load the whole sub-block if it fits, so a partial acknowledgement is answered from
	 * the same bytes.
	 */
	return up_fill(srv, srv->offset, MIN(rest, (uint32_t)srv->blk_nseg * CO_SDO_SEG_SIZE),
		       false);
}

/*
 * Send the segments of the sub-block not sent yet. When the line's TX queue is full, pause and
 * go on from the timer (anchors.md §4: back-pressure must not kill a block transfer).
 */
static uint32_t blk_up_send(struct co_sdo_srv *srv, uint64_t now)
{
	while (srv->seq < srv->blk_nseg) {
		uint8_t r[CO_SDO_DLC] = {0};
		uint8_t i = srv->seq + 1U;
		uint32_t o = srv->offset + (uint32_t)(i - 1U) * CO_SDO_SEG_SIZE;
		uint32_t len = MIN(CO_SDO_SEG_SIZE, srv->size - o);
		bool last = srv->blk_flag && i == srv->blk_nseg;
		uint32_t code = up_fill(srv, o, len, false);
		int err;

		if (code != CO_SDO_AB_NONE) {
			return code;
		}
		r[0] = i | (last ? CO_SDO_BLK_SEG_C : 0U);
		(void)memcpy(&r[1], &srv->buf[o - srv->buf_off], len);
		/* Pause before the line's TX queue overflows rather than lose a frame to it. */
		err = co_node_tx_space(srv->node, srv->route) > 0 ? srv_send(srv, r) : -ENOBUFS;
		if (err == -ENOBUFS) {
			/* The line's TX queue is full: offer the rest again shortly. */
			srv->stats.tx_retries++;
			srv->retry_at = now + TX_RETRY_US;
			return CO_SDO_AB_NONE;
		}
		if (err != 0) {
			/* The controller is down or failing: the rest would fail too. No retry
			 * before the timeout, which (or the client) ends the transfer.
			 */
			srv->stats.tx_errors++;
			srv->retry_at = now + TIMEOUT_US;
			return CO_SDO_AB_NONE;
		}
		/* The CRC covers every byte once, when it is first sent. */
		if (o + len > srv->done) {
			if (srv->crc_on) {
				srv->crc = crc16_itu_t(srv->crc, &r[1 + (srv->done - o)],
						       o + len - srv->done);
			}
			srv->done = o + len;
		} else {
			srv->stats.blk_seg_resent++;
		}
		srv->seq = i;
	}
	return CO_SDO_AB_NONE;
}

static uint32_t blk_up_initiate(struct co_sdo_srv *srv, const uint8_t *d)
{
	uint8_t blksize = d[4];
	uint32_t code;

	if (blksize == 0U || blksize > CO_SDO_BLKSIZE_MAX) {
		return CO_SDO_AB_BLK_SIZE;
	}
	code = up_open(srv);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
#if defined(CONFIG_CANOPEN_SDO_BLOCK_PST)
	/* Protocol switch: the client prefers the normal upload for small values. */
	if (d[5] != 0U && srv->size <= d[5]) {
		return up_respond(srv);
	}
#endif
	srv->state = ST_BLK_UP_START;
	srv->crc_on = (d[0] & CO_SDO_BLK_CRC) != 0U;
	srv->crc = 0U;
	srv->done = 0U;
	srv->offset = 0U;
	srv->blksize = blksize;
	/* The CRC bit only for a client that asked for it (see blk_dn_initiate()). */
	srv_send_mux(
		srv,
		CO_SDO_B0(CO_SDO_SCS_BLK_UP, (srv->crc_on ? CO_SDO_BLK_CRC : 0U) | CO_SDO_BLK_S),
		srv->size);
	return CO_SDO_AB_NONE;
}

static uint32_t blk_up_start(struct co_sdo_srv *srv, uint64_t now)
{
	uint32_t code = blk_up_sub_begin(srv);

	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	srv->state = ST_BLK_UP_SUB;
	return blk_up_send(srv, now);
}

static uint32_t blk_up_ack(struct co_sdo_srv *srv, const uint8_t *d, uint64_t now)
{
	uint8_t ackseq = d[1];
	uint8_t blksize = d[2];
	uint32_t code;

	if (ackseq > srv->seq) {
		/* Acknowledges a segment that was not sent. */
		return CO_SDO_AB_SEQ_NUM;
	}
	if (blksize == 0U || blksize > CO_SDO_BLKSIZE_MAX) {
		return CO_SDO_AB_BLK_SIZE;
	}
	if (srv->blk_flag && ackseq == srv->blk_nseg) {
		/* Everything arrived: end with the bytes of the last segment and the CRC. */
		uint32_t last_len = srv->size == 0U ? 0U : (srv->size - 1U) % CO_SDO_SEG_SIZE + 1U;
		uint8_t r[CO_SDO_DLC] = {
			CO_SDO_B0(CO_SDO_SCS_BLK_UP, CO_SDO_BLK_N_PUT(CO_SDO_SEG_SIZE - last_len) |
							     CO_SDO_BLK_UP_SS_END)};

		if (srv->crc_on) {
			sys_put_le16(srv->crc, &r[1]);
		}
		srv->state = ST_BLK_UP_END;
		(void)srv_send(srv, r);
		return CO_SDO_AB_NONE;
	}
	/* Next sub-block, or the rest of this one again after a partial acknowledgement. */
	srv->offset += (uint32_t)ackseq * CO_SDO_SEG_SIZE;
	srv->blksize = blksize;
	code = blk_up_sub_begin(srv);
	if (code != CO_SDO_AB_NONE) {
		return code;
	}
	return blk_up_send(srv, now);
}

#endif /* CONFIG_CANOPEN_SDO_BLOCK */

/* --- Dispatch ---------------------------------------------------------------------------- */

/* A frame in idle: only an initiate starts a transfer. */
static uint32_t srv_initiate(struct co_sdo_srv *srv, const uint8_t *d)
{
	uint8_t cs = CO_SDO_CS(d[0]);
	bool init = cs == CO_SDO_CCS_DN_INIT || cs == CO_SDO_CCS_UP_INIT ||
		    (cs == CO_SDO_CCS_BLK_DN && CO_SDO_BLK_DN_CS(d[0]) == CO_SDO_BLK_SUB_INIT) ||
		    (cs == CO_SDO_CCS_BLK_UP && CO_SDO_BLK_UP_CS(d[0]) == CO_SDO_BLK_SUB_INIT);

	/* An abort for a frame that is no request names no object (0000h:00). */
	srv->index = init ? sys_get_le16(&d[1]) : 0U;
	srv->sub = init ? d[3] : 0U;

	switch (init ? cs : CO_SDO_CS_RESERVED) {
	case CO_SDO_CCS_DN_INIT:
		return dn_initiate(srv, d);
	case CO_SDO_CCS_UP_INIT:
		return up_initiate(srv);
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	case CO_SDO_CCS_BLK_DN:
		return blk_dn_initiate(srv, d);
	case CO_SDO_CCS_BLK_UP:
		return blk_up_initiate(srv, d);
#endif
	default:
		return CO_SDO_AB_CMD;
	}
}

static uint32_t srv_dispatch(struct co_sdo_srv *srv, const uint8_t *d, uint64_t now)
{
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	uint8_t cs = CO_SDO_CS(d[0]);
#endif

	/* A client abort (byte 0 = 80h, its reserved bits 0) ends the transfer without an
	 * answer and is ignored in idle. 81h-9Fh are no aborts: in a block download sub-block
	 * they are segments, elsewhere unknown commands.
	 */
	if (d[0] == CO_SDO_B0(CO_SDO_CS_ABORT, 0U)) {
		if (srv->state != ST_IDLE) {
			srv->stats.aborts_received++;
			srv->stats.last_abort = sys_get_le32(&d[4]);
			srv_end(srv);
		}
		return CO_SDO_AB_NONE;
	}

	switch (srv->state) {
	case ST_IDLE:
		return srv_initiate(srv, d);
	case ST_DN_SEG:
	case ST_UP_SEG:
		return seg_transfer(srv, d);
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	case ST_BLK_DN_SUB:
		/* Every frame is a segment here: byte 0 has no command specifier. */
		return blk_dn_segment(srv, d, now);
	case ST_BLK_DN_END:
		if (cs == CO_SDO_CCS_BLK_DN && CO_SDO_BLK_DN_CS(d[0]) == CO_SDO_BLK_SUB_END) {
			return blk_dn_end(srv, d);
		}
		return CO_SDO_AB_CMD;
	case ST_BLK_UP_START:
		if (cs == CO_SDO_CCS_BLK_UP && CO_SDO_BLK_UP_CS(d[0]) == CO_SDO_BLK_SUB_START) {
			return blk_up_start(srv, now);
		}
		return CO_SDO_AB_CMD;
	case ST_BLK_UP_SUB:
		if (cs == CO_SDO_CCS_BLK_UP && CO_SDO_BLK_UP_CS(d[0]) == CO_SDO_BLK_SUB_ACK) {
			return blk_up_ack(srv, d, now);
		}
		return CO_SDO_AB_CMD;
	case ST_BLK_UP_END:
		if (cs == CO_SDO_CCS_BLK_UP && CO_SDO_BLK_UP_CS(d[0]) == CO_SDO_BLK_SUB_END) {
			srv_complete(srv);
			return CO_SDO_AB_NONE;
		}
		return CO_SDO_AB_CMD;
#endif
	default:
		return CO_SDO_AB_GENERAL;
	}
}

static void srv_configure(struct co_sdo_srv *srv);

static void srv_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_sdo_srv *srv = rx->user_data;
	uint32_t code;

	/* CiA 301: an SDO frame has 8 data bytes. Anything else is not an SDO request. */
	if (frame->dlc != CO_SDO_DLC || (frame->flags & CAN_FRAME_RTR) != 0U) {
		srv->stats.rx_malformed++;
		return;
	}
	if (!srv->active) {
		srv->stats.rx_inactive++;
		return;
	}
	/* Answers go back on the line the request came on. */
	srv->route = co_node_route_of(srv->node, rx);
	srv->in_rx = true;
	code = srv_dispatch(srv, frame->data, now_us);
	if (code != CO_SDO_AB_NONE) {
		srv_abort(srv, code);
	} else if (srv->state != ST_IDLE) {
		srv->deadline = now_us + TIMEOUT_US;
		srv->tx_waits = 0U;
		srv_arm(srv);
	} else {
		/* The transfer ended with this answer: no timer to arm. */
	}
	srv->in_rx = false;
	/* A write to this server's own COB-IDs takes effect after its answer went out. */
	if (srv->reconf) {
		srv->reconf = false;
		srv_configure(srv);
	}
}

static void srv_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_sdo_srv *srv = timer->user_data;

	if (srv->state == ST_IDLE) {
		return;
	}
	if (co_time_before_eq(srv->deadline, now_us)) {
		/*
		 * The client cannot answer frames that still wait in the line's TX queue (a
		 * sub-block behind a slow controller): the timeout runs from when they can have
		 * left. Bounded, so a queue that never drains still ends the transfer.
		 */
		if (co_node_tx_space(srv->node, srv->route) < CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE &&
		    srv->tx_waits < TX_WAITS_MAX) {
			srv->tx_waits++;
			srv->deadline = now_us + TIMEOUT_US;
			srv_arm(srv);
			return;
		}
		srv_abort(srv, CO_SDO_AB_TIMEOUT);
		return;
	}
#if defined(CONFIG_CANOPEN_SDO_BLOCK)
	if (srv->state == ST_BLK_UP_SUB && srv->seq < srv->blk_nseg &&
	    co_time_before_eq(srv->retry_at, now_us)) {
		uint32_t code = blk_up_send(srv, now_us);

		if (code != CO_SDO_AB_NONE) {
			srv_abort(srv, code);
			return;
		}
	}
	if (SUB_TIMEOUT_US != 0U && srv->state == ST_BLK_DN_SUB && srv->blk_flag &&
	    co_time_before_eq(srv->sub_deadline, now_us)) {
		/* The end of the sub-block got lost: make the client resend after the last
		 * segment received in order.
		 */
		blk_dn_ack(srv);
	}
#endif
	srv_arm(srv);
}

/* --- Configuration ----------------------------------------------------------------------- */

static uint32_t default_cobid(const struct co_sdo_srv *srv, uint8_t sub)
{
	uint8_t id = co_node_id(srv->node);

	if (srv->num != 0U) {
		return CO_SDO_COBID_INVALID;
	}
	return (sub == 1U ? CO_SDO_SRV_DEFAULT_RX : CO_SDO_SRV_DEFAULT_TX) + id;
}

static uint32_t read_cobid(struct co_sdo_srv *srv, uint8_t sub)
{
	uint32_t v;

	if (co_od_get_u32(srv_od(srv), CO_SDO_SRV_PARAM_INDEX + srv->num, sub, &v) !=
	    CO_SDO_AB_NONE) {
		/* 1200h may be absent: the default SDO exists anyway. */
		v = default_cobid(srv, sub);
	}
	return v;
}

static bool cobid_valid(uint32_t cobid)
{
	return (cobid & CO_SDO_COBID_INVALID) == 0U;
}

/* Read the COB-IDs and (un)register the receiver; a transfer does not survive a change. */
static void srv_configure(struct co_sdo_srv *srv)
{
	uint32_t rx = read_cobid(srv, 1U);
	uint32_t tx = read_cobid(srv, 2U);
	bool ext = (rx & CO_SDO_COBID_FRAME) != 0U;
	int err;

	if (rx != srv->cob_rx || tx != srv->cob_tx) {
		srv_drop(srv);
	}
	srv->cob_rx = rx;
	srv->cob_tx = tx;
	co_rx_unregister(&srv->rx);
	if (!cobid_valid(rx) || !cobid_valid(tx)) {
		return;
	}
	srv->rx.ext = ext;
	srv->rx.mask = ext ? EFF_MASK : SFF_MASK;
	srv->rx.id = rx & srv->rx.mask;
	err = co_node_rx_register(srv->node, CO_LINE_DEFAULT, &srv->rx);
	if (err != 0) {
		LOG_ERR("SDO server %u: cannot receive COB-ID %x (%d)", srv->num, srv->rx.id, err);
	}
}

static uint32_t cobid_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_sdo_srv *srv0 = user_data;
	uint16_t index = req->info->index;
	uint8_t sub = req->info->sub;
	uint8_t num = (uint8_t)(index - CO_SDO_SRV_PARAM_INDEX);
	uint32_t val;
	uint32_t cur;

	if (req->len != 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	/* The default SDO's COB-IDs are read-only on the network (CiA 301 §7.5.2.33). */
	if (num == 0U && req->writer != CO_OD_WRITER_APP && req->writer != CO_OD_WRITER_STORAGE) {
		return CO_SDO_AB_READONLY;
	}
	val = (uint32_t)co_od_req_uint(req);
	if ((val & CO_SDO_COBID_FRAME) == 0U && (val & EFF_MASK & ~SFF_MASK) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* The CAN-ID of a valid channel is changed by invalidating it first. A restore of
	 * stored values at Reset Communication replaces defaults and is exempt.
	 */
	if (req->writer != CO_OD_WRITER_STORAGE &&
	    co_od_get_u32(od, index, sub, &cur) == CO_SDO_AB_NONE && cobid_valid(cur) &&
	    cobid_valid(val) && cur != val) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (cobid_valid(val) && (val & CO_SDO_COBID_FRAME) == 0U &&
	    co_cob_id_restricted(val & SFF_MASK)) {
		bool is_default =
			num == 0U && srv0->node != NULL &&
			val == (sub == 1U ? CO_SDO_SRV_DEFAULT_RX : CO_SDO_SRV_DEFAULT_TX) +
					co_node_id(srv0->node);

		if (!is_default) {
			return CO_SDO_AB_INVALID_VALUE;
		}
	}
	return CO_SDO_AB_NONE;
}

static void cobid_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_sdo_srv *srv0 = user_data;
	uint8_t num = (uint8_t)(req->info->index - CO_SDO_SRV_PARAM_INDEX);
	struct co_sdo_srv *srv = co_sdo_srv_get(srv0->node, num);

	ARG_UNUSED(od);
	if (srv == NULL || srv->node == NULL) {
		return;
	}
	if (srv->in_rx) {
		srv->reconf = true;
		return;
	}
	srv_configure(srv);
}

/* --- API --------------------------------------------------------------------------------- */

int co_sdo_srv_init(struct co_sdo_srv *srv, struct co_node *node, uint8_t num)
{
	if (srv == NULL || node == NULL || num >= CONFIG_CANOPEN_SDO_SERVERS) {
		return -EINVAL;
	}
	(void)memset(srv, 0, sizeof(*srv));
	srv->node = node;
	srv->num = num;
	/* The COB-IDs and the route are set before their first use: srv_configure() at Reset
	 * Communication, srv_rx() for each request.
	 */
	srv->rx.handler = srv_rx;
	srv->rx.lock = &node->lock;
	srv->rx.user_data = srv;
	co_timer_init(&srv->timer, srv_timer, &node->lock, srv);

	if (num == 0U) {
		/* One hook for the COB-IDs of every server of the node. */
		const struct co_od_hook hook = {
			.index_first = CO_SDO_SRV_PARAM_INDEX,
			.index_last = CO_SDO_SRV_PARAM_INDEX + CONFIG_CANOPEN_SDO_SERVERS - 1,
			.sub_first = 1U,
			.sub_last = 2U,
			.validate = cobid_validate,
			.notify = cobid_notify,
			.user_data = srv,
		};

		(void)co_od_hook_unregister(co_node_od(node), srv);
		return co_od_hook_register(co_node_od(node), &hook);
	}
	return 0;
}

void co_sdo_srv_reset_comm(struct co_sdo_srv *srv)
{
	srv_drop(srv);
	srv->reconf = false;
	srv_configure(srv);
}

void co_sdo_srv_set_state(struct co_sdo_srv *srv, enum co_nmt_state state)
{
	srv->active = state == CO_NMT_PRE_OPERATIONAL || state == CO_NMT_OPERATIONAL;
	if (!srv->active) {
		srv_drop(srv);
	}
}

/* The node's servers as one service (canopen/services.h). */
static int srv_service_init(struct co_node *node)
{
	for (uint8_t i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		int err = co_sdo_srv_init(&node->sdo_srv[i], node, i);

		if (err != 0) {
			return err;
		}
	}
	return 0;
}

static void srv_service_reset_comm(struct co_node *node)
{
	for (int i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		co_sdo_srv_reset_comm(&node->sdo_srv[i]);
	}
}

static void srv_service_set_state(struct co_node *node, enum co_nmt_state from,
				  enum co_nmt_state to)
{
	ARG_UNUSED(from);
	for (int i = 0; i < CONFIG_CANOPEN_SDO_SERVERS; i++) {
		co_sdo_srv_set_state(&node->sdo_srv[i], to);
	}
}

const struct co_service co_service_sdo_srv = {
	.name = "sdo_srv",
	.init = srv_service_init,
	.reset_comm = srv_service_reset_comm,
	.set_state = srv_service_set_state,
};

struct co_sdo_srv *co_sdo_srv_get(struct co_node *node, uint8_t num)
{
	if (node == NULL || num >= CONFIG_CANOPEN_SDO_SERVERS) {
		return NULL;
	}
	return &node->sdo_srv[num];
}

void co_sdo_srv_get_stats(struct co_sdo_srv *srv, struct co_sdo_srv_stats *stats)
{
	(void)k_mutex_lock(&srv->node->lock, K_FOREVER);
	*stats = srv->stats;
	(void)k_mutex_unlock(&srv->node->lock);
}

bool co_sdo_srv_busy(struct co_sdo_srv *srv)
{
	bool busy;

	(void)k_mutex_lock(&srv->node->lock, K_FOREVER);
	busy = srv->state != ST_IDLE;
	(void)k_mutex_unlock(&srv->node->lock);
	return busy;
}
