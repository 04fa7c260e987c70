/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Harness of the SDO client suites: on one simulation line (simulated time, no thread) a
 * client node and three SafeLine server nodes. Client 0 and 1 have 1280h/1281h, 2 and 3 not.
 * A "scripted server" is a node-ID nobody serves: the test reads the client's frames from
 * the sink and injects the answers with co_line_rx().
 */

#ifndef SDO_CLI_TEST_HARNESS_H_
#define SDO_CLI_TEST_HARNESS_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/sdo_cli.h>

#include "sdo_cli_test_od.h"

#define CLI_ID     0x10U
#define SRV_ID     0x20U
#define SRV2_ID    0x21U
#define SRV3_ID    0x22U
/* Served by nobody: the tests play the server. */
#define FAKE_ID    0x30U
#define MS         1000ULL
#define TIMEOUT_US ((uint64_t)CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT * MS)
#define RING       4096U
#define DOM_SIZE   4000U

#if defined(CONFIG_CANOPEN_SDO_CLIENT_BLOCK_CRC)
#define CLI_CRC true
#else
#define CLI_CRC false
#endif

struct con_rec {
	uint32_t calls;
	uint32_t code;
	size_t size;
	void *user_data;
	struct co_sdo_cli *cli;
};

struct harness {
	struct co_line line;
	struct co_node cnode;
	struct co_node snode;
	struct co_node snode2;
	struct co_node snode3;
	struct sdo_cli_test_od_ram cram;
	struct sdo_cli_test_od_ram sram;
	struct sdo_cli_test_od_ram sram2;
	struct sdo_cli_test_od_ram sram3;
	/* Every frame sent on the line, in order. */
	struct can_frame ring[RING];
	uint32_t wr;
	uint32_t rd;
	/* When each frame of ring[] reached the bus. */
	uint64_t ring_at[RING];
	int sink_result;
	/* A bus of limited rate: while set, the sink takes bus_credit more frames, then
	 * pushes back (-EAGAIN).
	 */
	bool bus_paced;
	int bus_credit;
	uint64_t now;
	struct con_rec con[4];
};

extern struct harness h;

void h_setup(void);
struct co_sdo_cli *h_cli(uint8_t num);
/* Deliver local frames and run due timers at the current time until nothing is left. */
void h_pump(void);
/* Advance simulated time to @p at, running every deadline on the way. */
void h_run_until(uint64_t at);
void h_advance(uint64_t us);
/* Run until @p rec has been called or @p max_us passed. */
void h_run_for_con(struct con_rec *rec, uint64_t max_us);

/* The confirmation for h.con[user_data index]. */
void h_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data);
#define CON(i) ((void *)&h.con[i])

/* Frames of the scripted server exchange (COB-IDs 600h/580h + FAKE_ID). */
const struct can_frame *h_next_from(uint32_t id);
void h_skip_all(void);
uint32_t h_count_from(uint32_t id);
void h_fake(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v);
void h_fake_raw(const uint8_t d[8]);
void h_fake_dlc(const uint8_t *d, uint8_t dlc);
/* Expect the client's next frame to the scripted server. */
void h_expect(uint8_t b0, uint16_t idx, uint8_t sub, uint32_t v);
void h_expect_raw(const uint8_t d[8]);
void h_expect_abort(uint16_t idx, uint8_t sub, uint32_t code);
void h_expect_none(void);

void h_fill(uint8_t *p, size_t len, uint32_t seed);
uint16_t ref_crc16(const uint8_t *p, size_t len);
void h_nmt(uint8_t cs, uint8_t id);

/* The dictionary accessors with the node's mutex held, as the lock rule wants. */
uint32_t h_od_write(struct co_node *n, uint16_t idx, uint8_t sub, const void *data, size_t len,
		    enum co_od_writer w);
uint32_t h_od_read(struct co_node *n, uint16_t idx, uint8_t sub, uint32_t off, void *buf,
		   size_t cap, size_t *len, enum co_od_writer r);
uint32_t h_od_set_u32(struct co_node *n, uint16_t idx, uint8_t sub, uint32_t v,
		      enum co_od_writer w);

#endif /* SDO_CLI_TEST_HARNESS_H_ */
