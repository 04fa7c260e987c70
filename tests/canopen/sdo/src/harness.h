/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Test harness of the SDO server suites: one node on a simulation line (no thread, simulated
 * time), a frame-level SDO client written for the tests, and a provider serving 3000h-30FFh.
 */

#ifndef SDO_TEST_HARNESS_H_
#define SDO_TEST_HARNESS_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/sdo.h>

#include "sdo_test_od.h"

#define NODE_ID    0x22U
#define MS         1000ULL
#define TIMEOUT_US ((uint64_t)CONFIG_CANOPEN_SDO_SERVER_TIMEOUT * MS)
#define BUFSZ      CONFIG_CANOPEN_SDO_SERVER_BUFFER_SIZE
#define RING       1024U
#define DOM_CAP    100000U

#if defined(CONFIG_CANOPEN_SDO_BLOCK)
#define SRV_BLKSIZE CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE
#else
#define SRV_BLKSIZE 0
#endif

/* COB-IDs the tests give the second server (1201h): free, unrestricted CAN-IDs. */
#define SRV1_RX 0x6A2U
#define SRV1_TX 0x6C2U

/* Provider objects (not in the EDS). */
#define IDX_DOM     0x3000U /* DOMAIN rw, streamed, up to DOM_CAP bytes */
#define IDX_BROKEN  0x3001U /* DOMAIN ro, 2000 bytes, reads fail from offset 1000 (HW error) */
#define IDX_SHRINKS 0x3002U /* DOMAIN ro, claims 100 bytes, delivers 10 */
#define BROKEN_LEN  2000U
#define BROKEN_AT   1000U

struct harness {
	struct co_line line;
	struct co_node node;
	struct sdo_test_od_ram ram;
	/* Every frame the node sent, read in order by the tests. */
	struct can_frame ring[RING];
	uint32_t wr;
	uint32_t rd;
	/* What the sink answers (0, or -EAGAIN for a controller that pushes back). */
	int sink_result;
	uint64_t now;
	/* The client's COB-IDs: it sends on cli_tx and listens to cli_rx. */
	uint32_t cli_tx;
	uint32_t cli_rx;
	bool cli_ext;
	/* 3000h: committed value, staging of a streamed write, and what the provider saw. */
	uint8_t dom[DOM_CAP];
	uint32_t dom_len;
	uint8_t stage[DOM_CAP];
	uint32_t chunks;
	uint32_t chunk_max;
	uint32_t commits;
	uint32_t stream_aborts;
	/* Receive buffer of the client (uploads of 3000h). */
	uint8_t rx[DOM_CAP + 8];
	/* Answer of the validate hook on 2007h. */
	uint32_t hook_code;
	struct co_od_provider prov;
};

extern struct harness h;

/* Fresh node in Pre-operational, client on the default SDO, boot-up frame consumed. */
void h_setup(void);
void h_run_until(uint64_t at);
void h_advance(uint64_t us);
void h_nmt(uint8_t cs);

void h_send_dlc(const uint8_t *d, uint8_t dlc);
void h_send(const uint8_t d[8]);
void h_req(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v);
const struct can_frame *h_next(void);
uint32_t h_pending(void);
void h_expect(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v);
void h_expect_abort(uint16_t idx, uint8_t sub, uint32_t code);
void h_expect_none(void);
struct co_sdo_srv_stats h_stats(uint8_t num);

uint32_t h_get_u32(uint16_t idx, uint8_t sub);
uint32_t h_set(uint16_t idx, uint8_t sub, const void *data, size_t len, enum co_od_writer w);
void h_fill(uint8_t *p, uint32_t len, uint32_t seed);

/* Reference CRC (bit by bit, independent of the server's table). */
uint16_t ref_crc16(const uint8_t *p, uint32_t len);

/*
 * The test client. Each checks every server frame strictly and returns 0, or the abort code
 * the server sent (after checking the abort's multiplexer).
 */
uint32_t cli_dl_exp(uint16_t idx, uint8_t sub, const void *data, uint8_t len);
uint32_t cli_dl_seg(uint16_t idx, uint8_t sub, const void *data, uint32_t len, bool size_ind);
uint32_t cli_ul(uint16_t idx, uint8_t sub, void *buf, uint32_t cap, uint32_t *len);
/* Continue an upload after the server's initiate response @p f (also after a switch). */
uint32_t cli_ul_cont(uint16_t idx, uint8_t sub, const struct can_frame *f, void *buf, uint32_t cap,
		     uint32_t *len);
uint32_t cli_blk_dl(uint16_t idx, uint8_t sub, const void *data, uint32_t len, bool crc);
/* @p cap must exceed the value's size by 7 (the last segment is received whole). */
uint32_t cli_blk_ul(uint16_t idx, uint8_t sub, void *buf, uint32_t cap, uint32_t *len,
		    uint8_t blksize, bool crc, uint8_t pst, bool *switched);

#endif /* SDO_TEST_HARNESS_H_ */
