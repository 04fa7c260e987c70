/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * CiA 301 SDO client (§7.2.4): expedited, segmented and block transfers to a server.
 *
 * I/O-free like the server: answers of the server come in through the line receiver with
 * their reception time, frames go out through co_node_send(), the only deadline is one line
 * timer per client (answer timeout, block download pacing, deferred confirmation). Everything
 * runs with the node's mutex held.
 *
 * The confirmation runs in the line thread. Events that happen in an application thread (an
 * abort request, an NMT change or a reconfiguration made by the application) do not call it
 * there: they park the result (ST_CONFIRM) and arm the timer for "now", and the line thread
 * delivers it. The blocking calls wait for the confirmation on a semaphore; when their own
 * timeout expires they abort and confirm in place (sync_wait()). The decisions are listed in
 * doc/sdo-client.md.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>
#include <zephyr/sys/util.h>

#include <canopen/node.h>
#include <canopen/sdo.h>
#include <canopen/sdo_cli.h>

#include "node_internal.h"
#include "sdo_internal.h"

LOG_MODULE_REGISTER(co_sdo_cli, CONFIG_CANOPEN_LOG_LEVEL);

#define MS_US         1000ULL
#define TIMEOUT_MS    ((uint32_t)CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT)
#define CLI_BLKSIZE   ((uint8_t)CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE)
#define CLI_PST       ((uint8_t)CONFIG_CANOPEN_SDO_CLIENT_PST)
/* Pause before offering a block download segment again to a full TX queue. */
#define TX_RETRY_US   1000U
/*
 * Places of the line's TX queue a block download leaves free, a quarter of it: a sub-block
 * of 127 segments would otherwise fill the queue, and a heartbeat, a PDO or the answer of
 * another node on the same line that comes while it is full is dropped.
 */
#define TX_RESERVE    MAX(2, CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE / 4)
/* How many times a timeout is put off while our own frames wait in the line's TX queue. */
#define TX_WAITS_MAX  8U
/* Clients 0..127 have a parameter object (1280h-12FFh). */
#define PARAM_CLIENTS MIN(CONFIG_CANOPEN_SDO_CLIENTS, 128)

#define SFF_MASK 0x7ffU
#define EFF_MASK 0x1fffffffU

#if defined(CONFIG_CANOPEN_SDO_CLIENT_BLOCK_CRC)
#define CLI_CC CO_SDO_BLK_CRC
#else
#define CLI_CC 0U
#endif

BUILD_ASSERT(CONFIG_CANOPEN_SDO_CLIENTS >= 1 && CONFIG_CANOPEN_SDO_CLIENTS <= 255,
	     "client numbers are uint8_t");

enum cli_state {
	ST_IDLE = 0,
	/* Ended; the confirmation waits for the line thread (timer armed for now). */
	ST_CONFIRM,
	/* Download: initiate sent (expedited or segmented). */
	ST_DN_INIT,
	/* Segmented download: segment sent, waiting for its response. */
	ST_DN_SEG,
	/* Upload: initiate sent. */
	ST_UP_INIT,
	/* Segmented upload: segment request sent. */
	ST_UP_SEG,
	/* Block download: initiate sent. */
	ST_BLK_DN_INIT,
	/* Block download: sub-block (being) sent, waiting for the acknowledgement. */
	ST_BLK_DN_SUB,
	/* Block download: end request sent. */
	ST_BLK_DN_END,
	/* Block upload: initiate sent (the answer may also be a protocol switch). */
	ST_BLK_UP_INIT,
	/* Block upload: receiving the segments of a sub-block. */
	ST_BLK_UP_SUB,
	/* Block upload: last segment acknowledged, waiting for the end request. */
	ST_BLK_UP_END,
};

static bool running(const struct co_sdo_cli *cli)
{
	return cli->state != ST_IDLE && cli->state != ST_CONFIRM;
}

static uint64_t cli_now(const struct co_sdo_cli *cli)
{
	return co_node_time(cli->node);
}

static void put_mux(uint8_t *d, uint16_t index, uint8_t sub)
{
	sys_put_le16(index, &d[1]);
	d[3] = sub;
}

static bool mux_matches(const struct co_sdo_cli *cli, const uint8_t *d)
{
	return sys_get_le16(&d[1]) == cli->index && d[3] == cli->sub;
}

static int cli_send(struct co_sdo_cli *cli, const uint8_t d[CO_SDO_DLC])
{
	struct can_frame f;

	(void)memset(&f, 0, sizeof(f));
	if ((cli->cob_tx & CO_SDO_COBID_FRAME) != 0U) {
		f.id = cli->cob_tx & EFF_MASK;
		f.flags = CAN_FRAME_IDE;
	} else {
		f.id = cli->cob_tx & SFF_MASK;
	}
	f.dlc = CO_SDO_DLC;
	(void)memcpy(f.data, d, CO_SDO_DLC);
	return co_node_send(cli->node, CO_ROUTE_ACTIVE, &f);
}

/* Arm the timer for the earliest deadline of the transfer. */
static void cli_arm(struct co_sdo_cli *cli)
{
	uint64_t t = cli->deadline;

	if (cli->state == ST_BLK_DN_SUB && cli->seq < cli->nseg &&
	    co_time_before_eq(cli->retry_at, t)) {
		t = cli->retry_at;
	}
	co_node_timer_start(cli->node, &cli->timer, t);
}

static void cli_wait(struct co_sdo_cli *cli, uint64_t now)
{
	cli->deadline = now + cli->timeout_us;
	cli->tx_waits = 0U;
	cli_arm(cli);
}

/* Bytes the confirmation reports. */
static size_t cli_done_size(const struct co_sdo_cli *cli, uint32_t code)
{
	if (code == CO_SDO_AB_NONE && !cli->upload) {
		return cli->len;
	}
	return cli->offset;
}

/*
 * End the transfer and confirm it: in the line thread, or for a blocking call's own
 * confirmation (sync_wait()), which only records the result.
 */
static void cli_finish(struct co_sdo_cli *cli, uint32_t code)
{
	co_sdo_cli_con_t con = cli->con;
	void *user_data = cli->user_data;
	size_t size = cli_done_size(cli, code);

	co_timer_stop(&cli->timer);
	cli->state = ST_IDLE;
	cli->con = NULL;
	cli->user_data = NULL;
	cli->dn_data = NULL;
	cli->up_buf = NULL;
	if (code == CO_SDO_AB_NONE) {
		cli->stats.completed++;
	}
	if (con != NULL) {
		con(cli, code, size, user_data);
	}
}

/* End the transfer now; confirm it from the line thread (any thread). */
static void cli_finish_later(struct co_sdo_cli *cli, uint32_t code)
{
	cli->result = code;
	cli->state = ST_CONFIRM;
	co_node_timer_start(cli->node, &cli->timer, cli_now(cli));
}

static void cli_send_abort(struct co_sdo_cli *cli, uint32_t code)
{
	uint8_t d[CO_SDO_DLC] = {CO_SDO_B0(CO_SDO_CS_ABORT, 0U)};

	put_mux(d, cli->index, cli->sub);
	sys_put_le32(code, &d[4]);
	LOG_DBG("SDO client %u: abort %04x:%02x %08x (%s)", cli->num, cli->index, cli->sub, code,
		co_sdo_abort_str(code));
	(void)cli_send(cli, d);
	cli->stats.aborts_sent++;
	cli->stats.last_abort = code;
}

/* Drop a running transfer without a frame (NMT, reconfiguration). */
static void cli_drop(struct co_sdo_cli *cli)
{
	if (running(cli)) {
		cli->stats.dropped++;
		cli_finish_later(cli, CO_SDO_AB_GENERAL);
	}
}

/* --- Download ---------------------------------------------------------------------------- */

static uint32_t dn_send_segment(struct co_sdo_cli *cli)
{
	uint8_t d[CO_SDO_DLC] = {0};
	size_t chunk = MIN((size_t)CO_SDO_SEG_SIZE, cli->len - cli->offset);
	bool last = cli->offset + chunk == cli->len;

	d[0] = CO_SDO_B0(CO_SDO_CCS_DN_SEG, (cli->toggle != 0U ? CO_SDO_SEG_T : 0U) |
						    CO_SDO_SEG_N_PUT(CO_SDO_SEG_SIZE - chunk) |
						    (last ? CO_SDO_SEG_C : 0U));
	if (chunk > 0U) {
		(void)memcpy(&d[1], &cli->dn_data[cli->offset], chunk);
	}
	cli->pending = chunk;
	cli->state = ST_DN_SEG;
	(void)cli_send(cli, d);
	return CO_SDO_AB_NONE;
}

static uint32_t dn_init_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_DN_INIT || !mux_matches(cli, d)) {
		return CO_SDO_AB_CMD;
	}
	if (cli->exp) {
		cli_finish(cli, CO_SDO_AB_NONE);
		return CO_SDO_AB_NONE;
	}
	cli->toggle = 0U;
	return dn_send_segment(cli);
}

static uint32_t dn_seg_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_DN_SEG) {
		return CO_SDO_AB_CMD;
	}
	if (((d[0] & CO_SDO_SEG_T) != 0U) != (cli->toggle != 0U)) {
		return CO_SDO_AB_TOGGLE;
	}
	cli->offset += cli->pending;
	if (cli->offset == cli->len) {
		cli_finish(cli, CO_SDO_AB_NONE);
		return CO_SDO_AB_NONE;
	}
	cli->toggle ^= 1U;
	return dn_send_segment(cli);
}

/* --- Block download ---------------------------------------------------------------------- */

static size_t dn_nseg_rest(const struct co_sdo_cli *cli)
{
	size_t rest = cli->len - cli->offset;

	/* An empty value still takes one (empty) segment. */
	return rest == 0U ? 1U : DIV_ROUND_UP(rest, CO_SDO_SEG_SIZE);
}

static void blk_dn_sub_begin(struct co_sdo_cli *cli)
{
	size_t rest = dn_nseg_rest(cli);

	cli->nseg = (uint8_t)MIN(rest, (size_t)cli->blksize);
	cli->blk_last = rest <= cli->blksize;
	cli->seq = 0U;
	cli->state = ST_BLK_DN_SUB;
}

/*
 * Send the segments of the sub-block not sent yet, as the line has room: pause while no
 * more than TX_RESERVE places are free and go on from the timer as the queue drains.
 */
static void blk_dn_send(struct co_sdo_cli *cli, uint64_t now)
{
	while (cli->seq < cli->nseg) {
		uint8_t d[CO_SDO_DLC] = {0};
		uint8_t i = cli->seq + 1U;
		size_t o = cli->offset + (size_t)(i - 1U) * CO_SDO_SEG_SIZE;
		size_t chunk = MIN((size_t)CO_SDO_SEG_SIZE, cli->len - o);
		bool last = cli->blk_last && i == cli->nseg;
		int err;

		d[0] = i | (last ? CO_SDO_BLK_SEG_C : 0U);
		if (chunk > 0U) {
			(void)memcpy(&d[1], &cli->dn_data[o], chunk);
		}
		err = co_node_tx_space(cli->node, CO_ROUTE_ACTIVE) > TX_RESERVE ? cli_send(cli, d)
										: -ENOBUFS;
		if (err == -ENOBUFS) {
			cli->stats.tx_retries++;
			cli->retry_at = now + TX_RETRY_US;
			return;
		}
		if (err != 0) {
			/* The controller is down or failing: leave the rest to the timeout. */
			cli->retry_at = now + cli->timeout_us;
			return;
		}
		cli->seq = i;
	}
}

static uint32_t blk_dn_init_rsp(struct co_sdo_cli *cli, const uint8_t *d, uint64_t now)
{
	uint8_t blksize = d[4];

	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_BLK_DN || (d[0] & 0x3U) != CO_SDO_BLK_SUB_INIT ||
	    !mux_matches(cli, d)) {
		return CO_SDO_AB_CMD;
	}
	if (blksize == 0U || blksize > CO_SDO_BLKSIZE_MAX) {
		return CO_SDO_AB_BLK_SIZE;
	}
	cli->crc_on = CLI_CC != 0U && (d[0] & CO_SDO_BLK_CRC) != 0U;
	cli->blksize = blksize;
	cli->offset = 0U;
	blk_dn_sub_begin(cli);
	blk_dn_send(cli, now);
	return CO_SDO_AB_NONE;
}

static uint32_t blk_dn_ack(struct co_sdo_cli *cli, const uint8_t *d, uint64_t now)
{
	uint8_t ackseq = d[1];
	uint8_t blksize = d[2];

	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_BLK_DN || (d[0] & 0x3U) != CO_SDO_BLK_SUB_ACK) {
		return CO_SDO_AB_CMD;
	}
	if (ackseq > cli->seq) {
		/* Acknowledges a segment that was not sent. */
		return CO_SDO_AB_SEQ_NUM;
	}
	if (blksize == 0U || blksize > CO_SDO_BLKSIZE_MAX) {
		return CO_SDO_AB_BLK_SIZE;
	}
	if (cli->blk_last && ackseq == cli->nseg) {
		/* Everything arrived: the end request gives the bytes of the last segment. */
		uint8_t r[CO_SDO_DLC] = {0};
		size_t last_len = cli->len == 0U ? 0U : (cli->len - 1U) % CO_SDO_SEG_SIZE + 1U;

		r[0] = CO_SDO_B0(CO_SDO_CCS_BLK_DN,
				 CO_SDO_BLK_N_PUT(CO_SDO_SEG_SIZE - last_len) | CO_SDO_BLK_SUB_END);
		if (cli->crc_on) {
			sys_put_le16(crc16_itu_t(0U, cli->dn_data, cli->len), &r[1]);
		}
		cli->offset = cli->len;
		cli->state = ST_BLK_DN_END;
		(void)cli_send(cli, r);
		return CO_SDO_AB_NONE;
	}
	/* Next sub-block, or the rest of this one again (renumbered from 1). */
	cli->offset += (size_t)ackseq * CO_SDO_SEG_SIZE;
	cli->blksize = blksize;
	blk_dn_sub_begin(cli);
	blk_dn_send(cli, now);
	return CO_SDO_AB_NONE;
}

static uint32_t blk_dn_end_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_BLK_DN || (d[0] & 0x3U) != CO_SDO_BLK_SUB_END) {
		return CO_SDO_AB_CMD;
	}
	cli_finish(cli, CO_SDO_AB_NONE);
	return CO_SDO_AB_NONE;
}

/* --- Upload ------------------------------------------------------------------------------ */

static void up_send_seg_req(struct co_sdo_cli *cli)
{
	uint8_t d[CO_SDO_DLC] = {
		CO_SDO_B0(CO_SDO_CCS_UP_SEG, cli->toggle != 0U ? CO_SDO_SEG_T : 0U)};

	cli->state = ST_UP_SEG;
	(void)cli_send(cli, d);
}

/* The initiate upload response (also after a protocol switch of a block upload). */
static uint32_t up_init_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_UP_INIT || !mux_matches(cli, d)) {
		return CO_SDO_AB_CMD;
	}
	if ((d[0] & CO_SDO_INIT_E) != 0U) {
		/* Expedited; without a size indication all 4 bytes count. */
		size_t n = (d[0] & CO_SDO_INIT_S) != 0U ? CO_SDO_EXP_SIZE - CO_SDO_INIT_N(d[0])
							: CO_SDO_EXP_SIZE;

		if (n > cli->len) {
			return CO_SDO_AB_OUT_OF_MEM;
		}
		(void)memcpy(cli->up_buf, &d[4], n);
		cli->offset = n;
		cli_finish(cli, CO_SDO_AB_NONE);
		return CO_SDO_AB_NONE;
	}
	cli->size_ind = (d[0] & CO_SDO_INIT_S) != 0U;
	cli->size = cli->size_ind ? sys_get_le32(&d[4]) : 0U;
	if (cli->size_ind && cli->size > cli->len) {
		return CO_SDO_AB_OUT_OF_MEM;
	}
	cli->offset = 0U;
	cli->toggle = 0U;
	up_send_seg_req(cli);
	return CO_SDO_AB_NONE;
}

static uint32_t up_seg_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	size_t n = CO_SDO_SEG_SIZE - CO_SDO_SEG_N(d[0]);
	bool last = (d[0] & CO_SDO_SEG_C) != 0U;

	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_UP_SEG) {
		return CO_SDO_AB_CMD;
	}
	if (((d[0] & CO_SDO_SEG_T) != 0U) != (cli->toggle != 0U)) {
		return CO_SDO_AB_TOGGLE;
	}
	if (cli->size_ind && cli->offset + n > cli->size) {
		return CO_SDO_AB_DATA_LONG;
	}
	if (cli->offset + n > cli->len) {
		return CO_SDO_AB_OUT_OF_MEM;
	}
	if (n > 0U) {
		(void)memcpy(&cli->up_buf[cli->offset], &d[1], n);
	}
	cli->offset += n;
	if (last) {
		if (cli->size_ind && cli->offset < cli->size) {
			return CO_SDO_AB_DATA_SHORT;
		}
		cli_finish(cli, CO_SDO_AB_NONE);
		return CO_SDO_AB_NONE;
	}
	cli->toggle ^= 1U;
	up_send_seg_req(cli);
	return CO_SDO_AB_NONE;
}

/* --- Block upload ------------------------------------------------------------------------ */

static uint32_t blk_up_init_rsp(struct co_sdo_cli *cli, const uint8_t *d)
{
	uint8_t r[CO_SDO_DLC] = {CO_SDO_B0(CO_SDO_CCS_BLK_UP, CO_SDO_BLK_SUB_START)};

	if (CO_SDO_CS(d[0]) == CO_SDO_SCS_UP_INIT && cli->pst != 0U) {
		/* Protocol switch: the transfer goes on as a normal upload. */
		return up_init_rsp(cli, d);
	}
	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_BLK_UP || (d[0] & CO_SDO_BLK_UP_SS_END) != 0U ||
	    !mux_matches(cli, d)) {
		return CO_SDO_AB_CMD;
	}
	cli->size_ind = (d[0] & CO_SDO_BLK_S) != 0U;
	cli->size = cli->size_ind ? sys_get_le32(&d[4]) : 0U;
	if (cli->size_ind && cli->size > cli->len) {
		return CO_SDO_AB_OUT_OF_MEM;
	}
	cli->crc_on = CLI_CC != 0U && (d[0] & CO_SDO_BLK_CRC) != 0U;
	cli->crc = 0U;
	cli->offset = 0U;
	cli->seq = 0U;
	cli->blk_last = false;
	cli->state = ST_BLK_UP_SUB;
	(void)cli_send(cli, r);
	return CO_SDO_AB_NONE;
}

static void blk_up_send_ack(struct co_sdo_cli *cli)
{
	uint8_t r[CO_SDO_DLC] = {CO_SDO_B0(CO_SDO_CCS_BLK_UP, CO_SDO_BLK_SUB_ACK), cli->seq,
				 cli->blksize};

	(void)cli_send(cli, r);
}

static uint32_t blk_up_segment(struct co_sdo_cli *cli, const uint8_t *d)
{
	uint8_t seqno = CO_SDO_BLK_SEQNO(d[0]);
	bool c = (d[0] & CO_SDO_BLK_SEG_C) != 0U;

	if (seqno == 0U || seqno > cli->blksize) {
		return CO_SDO_AB_SEQ_NUM;
	}
	if (seqno == cli->seq + 1U) {
		if (c) {
			/* How much of it is data only the end request tells. */
			(void)memcpy(cli->last_seg, &d[1], CO_SDO_SEG_SIZE);
			cli->blk_last = true;
		} else {
			if (cli->size_ind && cli->offset + CO_SDO_SEG_SIZE > cli->size) {
				return CO_SDO_AB_DATA_LONG;
			}
			if (cli->offset + CO_SDO_SEG_SIZE > cli->len) {
				return CO_SDO_AB_OUT_OF_MEM;
			}
			(void)memcpy(&cli->up_buf[cli->offset], &d[1], CO_SDO_SEG_SIZE);
			if (cli->crc_on) {
				cli->crc = crc16_itu_t(cli->crc, &d[1], CO_SDO_SEG_SIZE);
			}
			cli->offset += CO_SDO_SEG_SIZE;
		}
		cli->seq = seqno;
	} else {
		/* A gap or a duplicate: wait for the resend after the acknowledgement. */
		cli->stats.blk_seg_ignored++;
	}
	if (seqno == cli->blksize || c) {
		/* End of the sub-block: acknowledge the last segment received in order. */
		blk_up_send_ack(cli);
		if (cli->blk_last) {
			cli->state = ST_BLK_UP_END;
		} else {
			cli->seq = 0U;
		}
	}
	return CO_SDO_AB_NONE;
}

static uint32_t blk_up_end(struct co_sdo_cli *cli, const uint8_t *d)
{
	uint8_t r[CO_SDO_DLC] = {CO_SDO_B0(CO_SDO_CCS_BLK_UP, CO_SDO_BLK_SUB_END)};
	size_t n = CO_SDO_SEG_SIZE - CO_SDO_BLK_N(d[0]);

	if (CO_SDO_CS(d[0]) != CO_SDO_SCS_BLK_UP || (d[0] & CO_SDO_BLK_UP_SS_END) == 0U) {
		return CO_SDO_AB_CMD;
	}
	if (cli->size_ind && cli->offset + n > cli->size) {
		return CO_SDO_AB_DATA_LONG;
	}
	if (cli->size_ind && cli->offset + n < cli->size) {
		return CO_SDO_AB_DATA_SHORT;
	}
	if (cli->offset + n > cli->len) {
		return CO_SDO_AB_OUT_OF_MEM;
	}
	if (n > 0U) {
		(void)memcpy(&cli->up_buf[cli->offset], cli->last_seg, n);
	}
	if (cli->crc_on) {
		cli->crc = crc16_itu_t(cli->crc, cli->last_seg, n);
		if (cli->crc != sys_get_le16(&d[1])) {
			return CO_SDO_AB_CRC;
		}
	}
	cli->offset += n;
	(void)cli_send(cli, r);
	cli_finish(cli, CO_SDO_AB_NONE);
	return CO_SDO_AB_NONE;
}

/* --- Dispatch ---------------------------------------------------------------------------- */

static uint32_t cli_dispatch(struct co_sdo_cli *cli, const uint8_t *d, uint64_t now)
{
	switch (cli->state) {
	case ST_DN_INIT:
		return dn_init_rsp(cli, d);
	case ST_DN_SEG:
		return dn_seg_rsp(cli, d);
	case ST_UP_INIT:
		return up_init_rsp(cli, d);
	case ST_UP_SEG:
		return up_seg_rsp(cli, d);
	case ST_BLK_DN_INIT:
		return blk_dn_init_rsp(cli, d, now);
	case ST_BLK_DN_SUB:
		return blk_dn_ack(cli, d, now);
	case ST_BLK_DN_END:
		return blk_dn_end_rsp(cli, d);
	case ST_BLK_UP_INIT:
		return blk_up_init_rsp(cli, d);
	case ST_BLK_UP_SUB:
		/* Every frame is a segment here: byte 0 has no command specifier. */
		return blk_up_segment(cli, d);
	case ST_BLK_UP_END:
		return blk_up_end(cli, d);
	default:
		return CO_SDO_AB_GENERAL;
	}
}

/*
 * A late answer to a transfer this client already ended (a timeout, an abort): it names
 * another object in bytes 1-3. Only frames that carry the multiplexer count: anything while
 * an initiate response is awaited, and server aborts (one naming object 0000h:00h is
 * taken, as a server that cannot tell the object may send it). Aborting the running
 * transfer for it would leave every later transfer one answer behind.
 */
static bool late_answer(const struct co_sdo_cli *cli, const uint8_t *d)
{
	bool init = cli->state == ST_DN_INIT || cli->state == ST_UP_INIT ||
		    cli->state == ST_BLK_DN_INIT || cli->state == ST_BLK_UP_INIT;

	if (mux_matches(cli, d)) {
		return false;
	}
	if (d[0] == CO_SDO_B0(CO_SDO_CS_ABORT, 0U)) {
		return (sys_get_le16(&d[1]) != 0U) || (d[3] != 0U);
	}
	return init;
}

static void cli_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_sdo_cli *cli = rx->user_data;
	const uint8_t *d = frame->data;
	uint32_t code;

	/* CiA 301: an SDO frame has 8 data bytes. */
	if (frame->dlc != CO_SDO_DLC || (frame->flags & CAN_FRAME_RTR) != 0U) {
		cli->stats.rx_malformed++;
		return;
	}
	if (!running(cli) || late_answer(cli, d)) {
		cli->stats.rx_stray++;
		return;
	}
	/* An abort of the server (byte 0 = 80h) ends the transfer with its code, unanswered.
	 * 81h..FFh in a block upload sub-block are segments.
	 */
	if (d[0] == CO_SDO_B0(CO_SDO_CS_ABORT, 0U)) {
		code = sys_get_le32(&d[4]);
		cli->stats.aborts_rcvd++;
		cli->stats.last_abort = code;
		LOG_DBG("SDO client %u: server aborted %04x:%02x with %08x (%s)", cli->num,
			cli->index, cli->sub, code, co_sdo_abort_str(code));
		/* A zero code would read as success: report it as a general error. */
		cli_finish(cli, code != CO_SDO_AB_NONE ? code : CO_SDO_AB_GENERAL);
		return;
	}
	code = cli_dispatch(cli, d, now_us);
	if (code != CO_SDO_AB_NONE) {
		cli_send_abort(cli, code);
		cli_finish(cli, code);
	} else if (running(cli)) {
		cli_wait(cli, now_us);
	} else {
		/* The frame ended the transfer: cli_dispatch() already reported it. */
	}
}

static void cli_timer(struct co_timer *timer, uint64_t now_us)
{
	struct co_sdo_cli *cli = timer->user_data;

	if (cli->state == ST_CONFIRM) {
		cli_finish(cli, cli->result);
		return;
	}
	if (!running(cli)) {
		return;
	}
	if (co_time_before_eq(cli->deadline, now_us)) {
		/* The server cannot answer frames that still wait in our TX queue (see the
		 * server): put the timeout off, a bounded number of times.
		 */
		if (co_node_tx_space(cli->node, CO_ROUTE_ACTIVE) <
			    CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE &&
		    cli->tx_waits < TX_WAITS_MAX) {
			cli->tx_waits++;
			cli->deadline = now_us + cli->timeout_us;
			cli_arm(cli);
			return;
		}
		cli_send_abort(cli, CO_SDO_AB_TIMEOUT);
		cli_finish(cli, CO_SDO_AB_TIMEOUT);
		return;
	}
	if (cli->state == ST_BLK_DN_SUB && cli->seq < cli->nseg &&
	    co_time_before_eq(cli->retry_at, now_us)) {
		blk_dn_send(cli, now_us);
		if (cli->seq == cli->nseg) {
			/* The whole sub-block is out: wait for the acknowledgement from now. */
			cli->deadline = now_us + cli->timeout_us;
		}
	}
	cli_arm(cli);
}

/* --- Configuration ----------------------------------------------------------------------- */

static bool cobid_valid(uint32_t cobid)
{
	return (cobid & CO_SDO_COBID_INVALID) == 0U;
}

static bool has_param(const struct co_sdo_cli *cli)
{
	uint32_t v;

	return cli->num < 128U &&
	       co_od_get_u32(co_node_od(cli->node), CO_SDO_CLI_PARAM_INDEX + cli->num, 1U, &v) ==
		       CO_SDO_AB_NONE;
}

/* (Un)register the receiver for the current COB-IDs. */
static void cli_bind(struct co_sdo_cli *cli)
{
	bool ext = (cli->cob_rx & CO_SDO_COBID_FRAME) != 0U;
	int err;

	co_rx_unregister(&cli->rx);
	if (!cobid_valid(cli->cob_rx) || !cobid_valid(cli->cob_tx)) {
		return;
	}
	cli->rx.ext = ext;
	cli->rx.mask = ext ? EFF_MASK : SFF_MASK;
	cli->rx.id = cli->cob_rx & cli->rx.mask;
	err = co_node_rx_register(cli->node, CO_LINE_DEFAULT, &cli->rx);
	if (err != 0) {
		LOG_ERR("SDO client %u: cannot receive COB-ID %x (%d)", cli->num, cli->rx.id, err);
		cli->cob_rx |= CO_SDO_COBID_INVALID;
	}
}

/* Read 1280h + n when the dictionary has it; a transfer does not survive a change. */
static void cli_configure(struct co_sdo_cli *cli)
{
	struct co_od *od = co_node_od(cli->node);
	uint16_t index = CO_SDO_CLI_PARAM_INDEX + cli->num;
	uint32_t tx;
	uint32_t rx;
	uint8_t id;

	if (!has_param(cli)) {
		/* No parameter object: the binding of co_sdo_cli_set_server() stays. */
		return;
	}
	if (co_od_get_u32(od, index, 1U, &tx) != CO_SDO_AB_NONE ||
	    co_od_get_u32(od, index, 2U, &rx) != CO_SDO_AB_NONE) {
		tx = CO_SDO_COBID_INVALID;
		rx = CO_SDO_COBID_INVALID;
	}
	if (co_od_get_u8(od, index, 3U, &id) == CO_SDO_AB_NONE) {
		cli->server_id = id;
	}
	if (tx != cli->cob_tx || rx != cli->cob_rx) {
		cli_drop(cli);
	}
	cli->cob_tx = tx;
	cli->cob_rx = rx;
	cli_bind(cli);
}

/* CAN-IDs an SDO client may not use (CiA 301 §7.3.5), the default SDO ranges excepted. */
static bool can_id_restricted(uint32_t id)
{
	return id <= 0x07fU || (id >= 0x101U && id <= 0x180U) || (id >= 0x6e0U && id <= 0x6ffU) ||
	       (id >= 0x701U && id <= 0x7ffU);
}

static uint32_t cobid_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_sdo_cli *cli0 = user_data;
	uint16_t index = req->info->index;
	uint8_t sub = req->info->sub;
	struct co_sdo_cli *cli =
		co_sdo_cli_get(cli0->node, (uint8_t)(index - CO_SDO_CLI_PARAM_INDEX));
	uint32_t val;
	uint32_t cur;

	if (req->len != 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	val = (uint32_t)co_od_req_uint(req);
	if ((val & CO_SDO_COBID_FRAME) == 0U && (val & EFF_MASK & ~SFF_MASK) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	/* The CAN-ID of a valid channel is changed by invalidating it first (as the server's).
	 * Storage restores and co_sdo_cli_set_server() are exempt.
	 */
	if (req->writer != CO_OD_WRITER_STORAGE && (cli == NULL || !cli->own_write) &&
	    co_od_get_u32(od, index, sub, &cur) == CO_SDO_AB_NONE && cobid_valid(cur) &&
	    cobid_valid(val) && cur != val) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (cobid_valid(val) && (val & CO_SDO_COBID_FRAME) == 0U &&
	    can_id_restricted(val & SFF_MASK)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return CO_SDO_AB_NONE;
}

static void cobid_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_sdo_cli *cli0 = user_data;
	struct co_sdo_cli *cli =
		co_sdo_cli_get(cli0->node, (uint8_t)(req->info->index - CO_SDO_CLI_PARAM_INDEX));

	ARG_UNUSED(od);
	if (cli == NULL || cli->node == NULL || cli->own_write) {
		return;
	}
	cli_configure(cli);
}

/* --- Node interface ---------------------------------------------------------------------- */

int co_sdo_cli_init(struct co_sdo_cli *cli, struct co_node *node, uint8_t num)
{
	if (cli == NULL || node == NULL || num >= CONFIG_CANOPEN_SDO_CLIENTS) {
		return -EINVAL;
	}
	(void)memset(cli, 0, sizeof(*cli));
	cli->node = node;
	cli->num = num;
	cli->cob_tx = CO_SDO_COBID_INVALID;
	cli->cob_rx = CO_SDO_COBID_INVALID;
	cli->rx.handler = cli_rx;
	cli->rx.lock = &node->lock;
	cli->rx.user_data = cli;
	co_timer_init(&cli->timer, cli_timer, &node->lock, cli);

	if (num == 0U) {
		/* One hook for the COB-IDs of every client of the node. */
		const struct co_od_hook hook = {
			.index_first = CO_SDO_CLI_PARAM_INDEX,
			.index_last = CO_SDO_CLI_PARAM_INDEX + PARAM_CLIENTS - 1,
			.sub_first = 1U,
			.sub_last = 2U,
			.validate = cobid_validate,
			.notify = cobid_notify,
			.user_data = cli,
		};

		(void)co_od_hook_unregister(co_node_od(node), cli);
		return co_od_hook_register(co_node_od(node), &hook);
	}
	return 0;
}

void co_sdo_cli_reset_comm(struct co_sdo_cli *cli)
{
	cli_drop(cli);
	cli_configure(cli);
}

void co_sdo_cli_set_state(struct co_sdo_cli *cli, enum co_nmt_state to)
{
	cli->active = to == CO_NMT_PRE_OPERATIONAL || to == CO_NMT_OPERATIONAL;
	if (!cli->active) {
		cli_drop(cli);
	}
}

/* The node's clients as one service (canopen/services.h). */
static int cli_service_init(struct co_node *node)
{
	for (uint8_t i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		int err = co_sdo_cli_init(&node->sdo_cli[i], node, i);

		if (err != 0) {
			return err;
		}
	}
	return 0;
}

static void cli_service_reset_comm(struct co_node *node)
{
	for (int i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		co_sdo_cli_reset_comm(&node->sdo_cli[i]);
	}
}

static void cli_service_set_state(struct co_node *node, enum co_nmt_state from,
				  enum co_nmt_state to)
{
	ARG_UNUSED(from);
	for (int i = 0; i < CONFIG_CANOPEN_SDO_CLIENTS; i++) {
		co_sdo_cli_set_state(&node->sdo_cli[i], to);
	}
}

const struct co_service co_service_sdo_cli = {
	.name = "sdo_cli",
	.init = cli_service_init,
	.reset_comm = cli_service_reset_comm,
	.set_state = cli_service_set_state,
};

/* --- API --------------------------------------------------------------------------------- */

struct co_sdo_cli *co_sdo_cli_get(struct co_node *node, uint8_t num)
{
	if (node == NULL || num >= CONFIG_CANOPEN_SDO_CLIENTS) {
		return NULL;
	}
	return &node->sdo_cli[num];
}

int co_sdo_cli_set_server(struct co_sdo_cli *cli, uint8_t server_id)
{
	uint32_t tx = CO_SDO_SRV_DEFAULT_RX + server_id;
	uint32_t rx = CO_SDO_SRV_DEFAULT_TX + server_id;
	int err = 0;

	if (cli == NULL || server_id < 1U || server_id > 127U) {
		return -EINVAL;
	}
	co_node_lock(cli->node);
	if (running(cli)) {
		err = -EBUSY;
	} else if (has_param(cli)) {
		struct co_od *od = co_node_od(cli->node);
		uint16_t index = CO_SDO_CLI_PARAM_INDEX + cli->num;

		cli->own_write = true;
		if (co_od_set_u32(od, index, 1U, tx, CO_OD_WRITER_APP) != CO_SDO_AB_NONE ||
		    co_od_set_u32(od, index, 2U, rx, CO_OD_WRITER_APP) != CO_SDO_AB_NONE) {
			err = -EIO;
		}
		/* Sub-index 3 is optional. */
		(void)co_od_set_u8(od, index, 3U, server_id, CO_OD_WRITER_APP);
		cli->own_write = false;
		cli_configure(cli);
	} else {
		cli->cob_tx = tx;
		cli->cob_rx = rx;
		cli->server_id = server_id;
		cli_bind(cli);
	}
	co_node_unlock(cli->node);
	return err;
}

/* Checks shared by both requests; on success the transfer's common fields are set. */
static int req_begin(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, size_t len,
		     enum co_sdo_cli_mode mode, uint32_t timeout_ms, co_sdo_cli_con_t con,
		     void *user_data, bool upload)
{
	if (running(cli) || cli->state == ST_CONFIRM) {
		return -EBUSY;
	}
	if (!cli->active) {
		return -ENETDOWN;
	}
	/* cli_bind() marks cob_rx invalid when the receiver could not be registered. */
	if (!cobid_valid(cli->cob_tx) || !cobid_valid(cli->cob_rx)) {
		return -ENOTCONN;
	}
	if ((uint64_t)len > UINT32_MAX && !upload) {
		/* The size field of an SDO transfer has 32 bits. */
		return -EINVAL;
	}
	cli->index = index;
	cli->sub = sub;
	cli->mode = mode;
	cli->upload = upload;
	cli->len = len;
	cli->offset = 0U;
	cli->size = 0U;
	cli->size_ind = false;
	cli->exp = false;
	cli->crc_on = false;
	cli->blk_last = false;
	cli->toggle = 0U;
	cli->seq = 0U;
	cli->nseg = 0U;
	cli->pst = 0U;
	cli->timeout_us = (uint64_t)(timeout_ms != 0U ? timeout_ms : TIMEOUT_MS) * MS_US;
	cli->con = con;
	cli->user_data = user_data;
	return 0;
}

/* Send the initiate frame and start waiting; on a send error nothing has started. */
static int req_start(struct co_sdo_cli *cli, const uint8_t d[CO_SDO_DLC], uint8_t state)
{
	int err = cli_send(cli, d);

	if (err != 0) {
		cli->con = NULL;
		cli->user_data = NULL;
		return err;
	}
	cli->state = state;
	cli_wait(cli, cli_now(cli));
	return 0;
}

int co_sdo_cli_download_req(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, const void *data,
			    size_t len, enum co_sdo_cli_mode mode, uint32_t timeout_ms,
			    co_sdo_cli_con_t con, void *user_data)
{
	uint8_t d[CO_SDO_DLC] = {0};
	uint8_t state;
	int err;

	if (cli == NULL || con == NULL || (data == NULL && len > 0U)) {
		return -EINVAL;
	}
	co_node_lock(cli->node);
	err = req_begin(cli, index, sub, len, mode, timeout_ms, con, user_data, false);
	if (err == 0) {
		cli->dn_data = data;
		put_mux(d, index, sub);
		if (mode == CO_SDO_CLI_BLOCK) {
			d[0] = CO_SDO_B0(CO_SDO_CCS_BLK_DN,
					 CLI_CC | CO_SDO_BLK_S | CO_SDO_BLK_SUB_INIT);
			sys_put_le32((uint32_t)len, &d[4]);
			state = ST_BLK_DN_INIT;
		} else if (mode == CO_SDO_CLI_AUTO && len >= 1U && len <= CO_SDO_EXP_SIZE) {
			d[0] = CO_SDO_B0(CO_SDO_CCS_DN_INIT,
					 CO_SDO_INIT_E | CO_SDO_INIT_S |
						 CO_SDO_INIT_N_PUT(CO_SDO_EXP_SIZE - len));
			(void)memcpy(&d[4], data, len);
			cli->exp = true;
			state = ST_DN_INIT;
		} else {
			/* Segmented with the size indicated (also for 0 bytes). */
			d[0] = CO_SDO_B0(CO_SDO_CCS_DN_INIT, CO_SDO_INIT_S);
			sys_put_le32((uint32_t)len, &d[4]);
			state = ST_DN_INIT;
		}
		err = req_start(cli, d, state);
	}
	co_node_unlock(cli->node);
	return err;
}

int co_sdo_cli_upload_req(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, void *buf,
			  size_t cap, enum co_sdo_cli_mode mode, uint32_t timeout_ms,
			  co_sdo_cli_con_t con, void *user_data)
{
	uint8_t d[CO_SDO_DLC] = {0};
	uint8_t state;
	int err;

	if (cli == NULL || con == NULL || (buf == NULL && cap > 0U)) {
		return -EINVAL;
	}
	co_node_lock(cli->node);
	err = req_begin(cli, index, sub, cap, mode, timeout_ms, con, user_data, true);
	if (err == 0) {
		cli->up_buf = buf;
		put_mux(d, index, sub);
		if (mode == CO_SDO_CLI_BLOCK) {
			cli->blksize = CLI_BLKSIZE;
			cli->pst = CLI_PST;
			d[0] = CO_SDO_B0(CO_SDO_CCS_BLK_UP, CLI_CC | CO_SDO_BLK_SUB_INIT);
			d[4] = cli->blksize;
			d[5] = cli->pst;
			state = ST_BLK_UP_INIT;
		} else {
			d[0] = CO_SDO_B0(CO_SDO_CCS_UP_INIT, 0U);
			state = ST_UP_INIT;
		}
		err = req_start(cli, d, state);
	}
	co_node_unlock(cli->node);
	return err;
}

int co_sdo_cli_abort_req(struct co_sdo_cli *cli, uint32_t abort_code)
{
	int err = 0;

	/* Code 0 would confirm the transfer as a success. */
	if (cli == NULL || abort_code == CO_SDO_AB_NONE) {
		return -EINVAL;
	}
	co_node_lock(cli->node);
	if (!running(cli)) {
		err = -EALREADY;
	} else {
		cli_send_abort(cli, abort_code);
		cli_finish_later(cli, abort_code);
	}
	co_node_unlock(cli->node);
	return err;
}

bool co_sdo_cli_busy(struct co_sdo_cli *cli)
{
	bool busy;

	co_node_lock(cli->node);
	busy = cli->state != ST_IDLE;
	co_node_unlock(cli->node);
	return busy;
}

void co_sdo_cli_get_stats(struct co_sdo_cli *cli, struct co_sdo_cli_stats *stats)
{
	co_node_lock(cli->node);
	*stats = cli->stats;
	co_node_unlock(cli->node);
}

/* --- Blocking calls ---------------------------------------------------------------------- */

/* One blocking call: lives on the caller's stack until the call returns. */
struct sync_call {
	struct k_sem sem;
	uint32_t code;
	size_t size;
};

/* Runs with the node's mutex held: in the line thread, or in sync_wait() after a timeout. */
static void sync_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	struct sync_call *call = user_data;

	ARG_UNUSED(cli);
	call->code = abort_code;
	call->size = size;
	k_sem_give(&call->sem);
}

/*
 * The confirmation comes from the line thread of the client's node, which takes the mutex of
 * every node on its line around their dispatches. Waiting in any line thread (this one, or
 * one whose nodes the others depend on) or with one of those mutexes held could stop it for
 * good. Checked before the client takes its own node's mutex, so that mutex counts only when
 * the caller holds it.
 */
static bool would_deadlock(struct co_sdo_cli *cli)
{
	struct co_line *line = co_node_line(cli->node);

	/* The second test covers the client's own line without CONFIG_THREAD_CUSTOM_DATA. */
	if (co_line_current() != NULL || k_current_get() == &line->thread) {
		return true;
	}
	return co_line_owner_held(line);
}

static int sync_check(struct co_sdo_cli *cli, k_timeout_t timeout, uint32_t *abort_code)
{
	if (abort_code != NULL) {
		*abort_code = CO_SDO_AB_NONE;
	}
	if (cli == NULL || abort_code == NULL || K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		return -EINVAL;
	}
	return would_deadlock(cli) ? -EDEADLK : 0;
}

/*
 * Wait for the confirmation of the transfer started with @p call. When @p timeout expires
 * first, abort the transfer and confirm it here, under the node's mutex (sync_con only records
 * and wakes): the call returns at once and the client is idle, without waiting for the line
 * thread. The mutex orders this against the line thread: either it has confirmed already (the
 * transfer no longer carries @p call) or it cannot until we are done.
 */
static int sync_wait(struct co_sdo_cli *cli, struct sync_call *call, k_timeout_t timeout,
		     uint32_t *abort_code)
{
	bool expired = false;

	if (k_sem_take(&call->sem, timeout) != 0) {
		co_node_lock(cli->node);
		if (cli->state != ST_IDLE && cli->con == sync_con && cli->user_data == call) {
			uint32_t code = cli->result;

			if (running(cli)) {
				cli_send_abort(cli, CO_SDO_AB_TIMEOUT);
				code = CO_SDO_AB_TIMEOUT;
				expired = true;
			}
			/* Otherwise it ended meanwhile (ST_CONFIRM): report its own result. */
			cli_finish(cli, code);
		}
		co_node_unlock(cli->node);
		/* Confirmed by now, by the line thread or just above. */
		(void)k_sem_take(&call->sem, K_NO_WAIT);
	}
	if (expired) {
		return -EAGAIN;
	}
	if (call->code != CO_SDO_AB_NONE) {
		*abort_code = call->code;
		return -ECONNABORTED;
	}
	return 0;
}

int co_sdo_cli_download(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, const void *data,
			size_t len, enum co_sdo_cli_mode mode, k_timeout_t timeout,
			uint32_t *abort_code)
{
	struct sync_call call = {0};
	int err = sync_check(cli, timeout, abort_code);

	if (err != 0) {
		return err;
	}
	(void)k_sem_init(&call.sem, 0, 1);
	/* Protocol timeout 0: CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT per answer of the server. */
	err = co_sdo_cli_download_req(cli, index, sub, data, len, mode, 0U, sync_con, &call);
	if (err != 0) {
		return err;
	}
	return sync_wait(cli, &call, timeout, abort_code);
}

int co_sdo_cli_upload(struct co_sdo_cli *cli, uint16_t index, uint8_t sub, void *buf, size_t cap,
		      size_t *len, enum co_sdo_cli_mode mode, k_timeout_t timeout,
		      uint32_t *abort_code)
{
	struct sync_call call = {0};
	int err;

	if (len != NULL) {
		*len = 0U;
	}
	err = sync_check(cli, timeout, abort_code);
	if (err != 0) {
		return err;
	}
	(void)k_sem_init(&call.sem, 0, 1);
	err = co_sdo_cli_upload_req(cli, index, sub, buf, cap, mode, 0U, sync_con, &call);
	if (err != 0) {
		return err;
	}
	err = sync_wait(cli, &call, timeout, abort_code);
	if (len != NULL) {
		*len = call.size;
	}
	return err;
}
