/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * MPDO (CiA 301 §7.2.3) on a simulation line, simulated time. Built into the PDO test image;
 * the tests exist only with CONFIG_CANOPEN_MPDO (scenario canopen.pdo.mpdo).
 *
 * The node (ID 21h) gets: RPDO 1 = DAM consumer on 321h, RPDO 2 = SAM consumer on 322h,
 * TPDO 1 = DAM producer on 2A1h, TPDO 2 = SAM producer on 2A2h, all event-driven. The
 * dictionary (objdict/pdo_test.eds) has a scanner list 1FA0h and a dispatcher list 1FD0h
 * of four entries each.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/ztest.h>

#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/sdo_abort.h>

#include "co_sim.h"
#include "pdo_test_od.h"

#if defined(CONFIG_CANOPEN_MPDO)

#define NODE_ID 0x21
#define EMCY_ID (0x80 + NODE_ID)
#define DAM_RX  0x321
#define SAM_RX  0x322
#define DAM_TX  0x2A1
#define SAM_TX  0x2A2
#define INVALID 0x80000000U
#define MAX_TX  64
#define MS      1000ULL

static struct {
	struct co_node node;
	struct pdo_test_od_ram ram;
	int n_rpdo_ind;
} m;

static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	m.n_rpdo_ind++;
}

static uint8_t get_u8(uint16_t index, uint8_t sub)
{
	uint8_t v = 0xEE;

	co_node_lock(&m.node);
	zassert_ok(co_od_get_u8(co_node_od(&m.node), index, sub, &v));
	co_node_unlock(&m.node);
	return v;
}

static void rx8(uint32_t id, uint8_t dlc, uint8_t addr, uint16_t index, uint8_t sub, uint32_t value)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	f.data[0] = addr;
	f.data[1] = (uint8_t)index;
	f.data[2] = (uint8_t)(index >> 8);
	f.data[3] = sub;
	for (int i = 0; i < 4; i++) {
		f.data[4 + i] = (uint8_t)(value >> (8 * i));
	}
	co_line_rx(&sim.line, &f, sim.now);
}

static int count(uint32_t id)
{
	int n = 0;

	for (int i = 0; i < sim.n_sent; i++) {
		n += sim.sent[i].id == id;
	}
	return n;
}

static const struct can_frame *nth(uint32_t id, int k)
{
	for (int i = 0; i < sim.n_sent; i++) {
		if (sim.sent[i].id == id && k-- == 0) {
			return &sim.sent[i];
		}
	}
	return NULL;
}

static uint16_t emcy_code(int k)
{
	const struct can_frame *f = nth(EMCY_ID, k);

	zassert_not_null(f, "EMCY %d missing", k);
	return (uint16_t)(f->data[0] | (f->data[1] << 8));
}

static struct co_mpdo_stats stats(void)
{
	struct co_mpdo_stats st;

	co_mpdo_get_stats(&m.node, &st);
	return st;
}

/* An event-driven MPDO with the CiA 301 procedure (type first: MPDOs need 254/255). */
static void setup_mpdo(bool rx_pdo, int n, uint32_t cob, uint8_t type, uint8_t mode)
{
	uint16_t comm = (rx_pdo ? 0x1400 : 0x1800) + n;
	uint16_t mapi = (rx_pdo ? 0x1600 : 0x1A00) + n;

	zassert_equal(co_sim_write(&m.node, comm, 1, cob | INVALID, 4), 0U);
	zassert_equal(co_sim_write(&m.node, comm, 2, type, 1), 0U);
	zassert_equal(co_sim_write(&m.node, mapi, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&m.node, mapi, 0, mode, 1), 0U);
	zassert_equal(co_sim_write(&m.node, comm, 1, cob, 4), 0U);
}

static void before(void *f)
{
	memset(&m, 0, sizeof(m));
	co_sim_init();
	zassert_ok(co_node_init(&m.node, "dut", &sim.line, &pdo_test_od_def, &m.ram, NODE_ID));
	co_rpdo_set_ind(&m.node, rpdo_ind, NULL);
	zassert_ok(co_node_start(&m.node));
	setup_mpdo(true, 1, DAM_RX, 255, CO_MPDO_DAM);
	setup_mpdo(true, 2, SAM_RX, 254, CO_MPDO_SAM);
	setup_mpdo(false, 1, DAM_TX, 255, CO_MPDO_DAM);
	setup_mpdo(false, 2, SAM_TX, 254, CO_MPDO_SAM);
	rx8(0x000, 2, 0x01, NODE_ID, 0, 0); /* NMT start: bytes 0-1 = 01h, node-ID */
	sim.n_sent = 0;
}

ZTEST_SUITE(co_mpdo, NULL, NULL, before, NULL, NULL);

/* --- Mapping and transmission type ------------------------------------------------------ */

ZTEST(co_mpdo, test_mpdo_needs_event_driven_type)
{
	rx8(0x000, 2, 0x80, NODE_ID, 0, 0); /* Pre-operational: mapping writes allowed */
	zassert_equal(co_sim_write(&m.node, 0x1403, 1, INVALID | 0x323, 4), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1403, 2, 1, 1), 0U, "synchronous RPDO");
	zassert_equal(co_sim_write(&m.node, 0x1603, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1603, 0, CO_MPDO_DAM, 1), CO_SDO_AB_INVALID_VALUE,
		      "type 1: no MPDO");
	zassert_equal(co_sim_write(&m.node, 0x1403, 2, 254, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1603, 0, CO_MPDO_DAM, 1), 0U, "type 254: DAM-MPDO");
	zassert_equal(co_sim_write(&m.node, 0x1403, 2, 0, 1), CO_SDO_AB_INVALID_VALUE,
		      "MPDO stays event-driven");
	zassert_equal(co_sim_write(&m.node, 0x1403, 2, 255, 1), 0U);

	zassert_equal(co_sim_write(&m.node, 0x1803, 1, INVALID | 0x2A3, 4), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1803, 2, 0, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1A03, 0, 0, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1A03, 0, CO_MPDO_SAM, 1), CO_SDO_AB_INVALID_VALUE,
		      "type 0: no MPDO");
	zassert_equal(co_sim_write(&m.node, 0x1803, 2, 255, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1A03, 0, CO_MPDO_SAM, 1), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1803, 2, 3, 1), CO_SDO_AB_INVALID_VALUE);

	rx8(0x000, 2, 0x01, NODE_ID, 0, 0);
	zassert_equal(co_tpdo_send_req(&m.node, 1), -ENOTSUP, "an MPDO names its object");
	zassert_equal(co_tpdo_send_req(&m.node, 2), -ENOTSUP);
}

/* --- DAM consumer ------------------------------------------------------------------------ */

ZTEST(co_mpdo, test_dam_to_self_to_all_and_to_others)
{
	uint32_t l = 0;

	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2000, 1, 0x5A);
	zassert_equal(get_u8(0x2000, 1), 0x5A, "DAM to this node");
	rx8(DAM_RX, 8, 0x80, 0x2000, 2, 0x11);
	zassert_equal(get_u8(0x2000, 2), 0x11, "DAM to every node (0)");
	rx8(DAM_RX, 8, 0x80 | (NODE_ID + 1), 0x2000, 3, 0x22);
	zassert_equal(get_u8(0x2000, 3), 0, "DAM to another node is ignored");
	rx8(DAM_RX, 8, NODE_ID, 0x2000, 3, 0x33);
	zassert_equal(get_u8(0x2000, 3), 0, "a SAM frame is not for a DAM consumer");
	/* SDO access rules, not PDO mappability: 2003h (rw, PDOMapping=0) takes it. */
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2003, 0, 0x12345678);
	co_node_lock(&m.node);
	zassert_ok(co_od_get_u32(co_node_od(&m.node), 0x2003, 0, &l));
	co_node_unlock(&m.node);
	zassert_equal(l, 0x12345678);

	zassert_equal(stats().written, 3);
	zassert_equal(stats().ignored, 2);
	zassert_equal(m.n_rpdo_ind, 3, "the RPDO indication follows each write");
	zassert_equal(sim.n_sent, 0, "nothing is answered");
}

ZTEST(co_mpdo, test_dam_refused_and_missing_object)
{
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2004, 0, 0x44);
	zassert_equal(get_u8(0x2004, 0), 0, "read-only object");
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2007, 0, 0x44);
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x1000, 0, 0x44);
	zassert_equal(stats().refused, 3, "read-only, 8-byte object, const");
	zassert_equal(sim.n_sent, 0, "no frame back for a refused write (no abort for PDOs)");

	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x3000, 0, 1);
	zassert_equal(stats().missing, 1);
	zassert_equal(count(EMCY_ID), 1);
	zassert_equal(emcy_code(0), 0x8230, "DAM-MPDO not processed: destination missing");
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2000, 9, 1);
	zassert_equal(stats().missing, 2, "missing sub-index");
	zassert_equal(count(EMCY_ID), 1, "raised once while it lasts");
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2000, 1, 7);
	zassert_equal(count(EMCY_ID), 2);
	zassert_equal(emcy_code(1), 0x0000, "cleared by the next DAM-MPDO written");
	zassert_equal(get_u8(0x2000, 1), 7);
}

ZTEST(co_mpdo, test_mpdo_shorter_than_8_bytes)
{
	rx8(DAM_RX, 7, 0x80 | NODE_ID, 0x2000, 1, 0x66);
	zassert_equal(get_u8(0x2000, 1), 0, "not processed");
	zassert_equal(count(EMCY_ID), 1);
	zassert_equal(emcy_code(0), 0x8210, "length error, as for any RPDO");
	rx8(DAM_RX, 7, 0x80 | NODE_ID, 0x2000, 1, 0x66);
	zassert_equal(count(EMCY_ID), 1, "still active");
	rx8(DAM_RX, 8, 0x80 | NODE_ID, 0x2000, 1, 0x66);
	zassert_equal(get_u8(0x2000, 1), 0x66);
	zassert_equal(count(EMCY_ID), 2);
	zassert_equal(emcy_code(1), 0x0000);
}

/* --- SAM consumer ------------------------------------------------------------------------ */

static uint64_t disp(uint8_t block, uint16_t local, uint8_t local_sub, uint8_t sender_sub,
		     uint16_t sender_index, uint8_t sender)
{
	/* CiA 301 1FD0h: sender index in bits 31..16, sender sub-index in bits 15..8. */
	return ((uint64_t)block << 56) | ((uint64_t)local << 40) | ((uint64_t)local_sub << 32) |
	       ((uint64_t)sender_index << 16) | ((uint64_t)sender_sub << 8) | sender;
}

ZTEST(co_mpdo, test_sam_consumer_dispatch_with_block)
{
	/* 6000h:01..03 of node 5 -> 2000h:04..06 here; 6100h:00 of node 6 -> 2001h. */
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(3, 0x2000, 4, 1, 0x6000, 5), 8), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 3, disp(0, 0x2001, 0, 0, 0x6100, 6), 8), 0U,
		      "block 0 = 1");

	rx8(SAM_RX, 8, 5, 0x6000, 1, 0x10);
	rx8(SAM_RX, 8, 5, 0x6000, 3, 0x30);
	zassert_equal(get_u8(0x2000, 4), 0x10);
	zassert_equal(get_u8(0x2000, 5), 0, "6000h:02 not sent");
	zassert_equal(get_u8(0x2000, 6), 0x30, "last of the block");
	rx8(SAM_RX, 8, 5, 0x6000, 4, 0x40);
	zassert_equal(get_u8(0x2000, 7), 0, "beyond the block: ignored");
	rx8(SAM_RX, 8, 6, 0x6000, 1, 0x50);
	zassert_equal(get_u8(0x2000, 4), 0x10, "another producer: ignored");
	rx8(SAM_RX, 8, 5, 0x6001, 1, 0x50);
	rx8(SAM_RX, 8, 0x80 | 5, 0x6000, 1, 0x50);
	zassert_equal(get_u8(0x2000, 4), 0x10, "other index, DAM frame: ignored");

	uint16_t w = 0;

	rx8(SAM_RX, 8, 6, 0x6100, 0, 0xBEEF);
	co_node_lock(&m.node);
	zassert_ok(co_od_get_u16(co_node_od(&m.node), 0x2001, 0, &w));
	co_node_unlock(&m.node);
	zassert_equal(w, 0xBEEF);
	rx8(SAM_RX, 8, 6, 0x6100, 1, 0xBEEF);

	zassert_equal(stats().written, 3);
	zassert_equal(stats().ignored, 5);
	zassert_equal(sim.n_sent, 0);
}

/* --- Producers --------------------------------------------------------------------------- */

ZTEST(co_mpdo, test_sam_producer_scanner_list)
{
	const struct can_frame *f;

	/* 2000h:02..04 (block 3) and 2002h:00 (block 0 = 1). */
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, (3U << 24) | (0x2000U << 8) | 2U, 4), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 4, (0x2002U << 8), 4), 0U);
	co_node_lock(&m.node);
	zassert_ok(co_od_set_u8(co_node_od(&m.node), 0x2000, 4, 0x77, CO_OD_WRITER_APP));
	zassert_ok(co_od_set_u32(co_node_od(&m.node), 0x2002, 0, 0xA1B2C3D4, CO_OD_WRITER_APP));
	co_node_unlock(&m.node);

	zassert_ok(co_mpdo_sam_req(&m.node, 2, 0x2000, 4));
	zassert_ok(co_mpdo_sam_req(&m.node, 2, 0x2002, 0));
	zassert_equal(count(SAM_TX), 2);
	f = nth(SAM_TX, 0);
	zassert_equal(f->dlc, 8);
	zassert_mem_equal(f->data, ((uint8_t[]){NODE_ID, 0x00, 0x20, 0x04, 0x77, 0, 0, 0}), 8,
			  "SAM: producer ID, own index/sub, value");
	f = nth(SAM_TX, 1);
	zassert_mem_equal(f->data, ((uint8_t[]){NODE_ID, 0x02, 0x20, 0x00, 0xD4, 0xC3, 0xB2, 0xA1}),
			  8);

	zassert_equal(co_mpdo_sam_req(&m.node, 2, 0x2000, 5), -ENOENT, "after the block");
	zassert_equal(co_mpdo_sam_req(&m.node, 2, 0x2000, 1), -ENOENT, "before the block");
	zassert_equal(co_mpdo_sam_req(&m.node, 2, 0x2001, 0), -ENOENT, "not listed");
	zassert_equal(co_mpdo_sam_req(&m.node, 1, 0x2000, 4), -EINVAL, "a DAM TPDO");
	zassert_equal(co_mpdo_sam_req(&m.node, 0, 0x2000, 4), -EINVAL, "not an MPDO");
	zassert_equal(count(SAM_TX), 2);

	rx8(0x000, 2, 0x80, NODE_ID, 0, 0); /* Pre-operational */
	zassert_equal(co_mpdo_sam_req(&m.node, 2, 0x2000, 4), -ENETDOWN);
}

ZTEST(co_mpdo, test_dam_producer_and_inhibit_time)
{
	const uint8_t v = 0xAB;
	const uint8_t w[4] = {1, 2, 3, 4};

	zassert_ok(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 1, &v, 1));
	zassert_equal(count(DAM_TX), 1);
	zassert_mem_equal(nth(DAM_TX, 0)->data,
			  ((uint8_t[]){0x85, 0x00, 0x62, 0x01, 0xAB, 0, 0, 0}), 8);
	zassert_equal(nth(DAM_TX, 0)->dlc, 8);
	zassert_ok(co_mpdo_dam_req(&m.node, 1, 0, 0x6200, 2, w, 4), "to every node");
	zassert_mem_equal(nth(DAM_TX, 1)->data, ((uint8_t[]){0x80, 0x00, 0x62, 0x02, 1, 2, 3, 4}),
			  8);
	zassert_equal(co_mpdo_dam_req(&m.node, 1, 128, 0x6200, 1, &v, 1), -EINVAL);
	zassert_equal(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 1, w, 5), -EINVAL);
	zassert_equal(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 1, w, 0), -EINVAL);
	zassert_equal(co_mpdo_dam_req(&m.node, 2, 5, 0x6200, 1, &v, 1), -EINVAL, "a SAM TPDO");

	/* 10 ms inhibit time: one frame waits, a third request is refused. */
	zassert_equal(co_sim_write(&m.node, 0x1801, 1, INVALID | DAM_TX, 4), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1801, 3, 100, 2), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1801, 1, DAM_TX, 4), 0U);
	sim.n_sent = 0;
	zassert_ok(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 1, &v, 1));
	zassert_ok(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 3, &v, 1), "waits");
	zassert_equal(co_mpdo_dam_req(&m.node, 1, 5, 0x6200, 4, &v, 1), -EBUSY);
	zassert_equal(count(DAM_TX), 1);
	co_sim_run_until(sim.now + 10 * MS);
	zassert_equal(count(DAM_TX), 2, "sent when the inhibit time ends");
	zassert_equal(nth(DAM_TX, 1)->data[3], 3);
	co_sim_run_until(sim.now + 100 * MS);
	zassert_equal(count(DAM_TX), 2, "no event timer, nothing else");
}

/* --- 1FA0h / 1FD0h writes ---------------------------------------------------------------- */

ZTEST(co_mpdo, test_scanner_and_dispatcher_write_rules)
{
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0, 4), 0U, "0 = empty entry");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0x3000U << 8, 4), CO_SDO_AB_NO_OBJECT);
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, (0x2000U << 8) | 9U, 4), CO_SDO_AB_NO_SUB);
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, (3U << 24) | (0x2000U << 8) | 7U, 4),
		      CO_SDO_AB_NO_SUB, "the block runs past 2000h:08");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, (2U << 24) | (0x2000U << 8) | 0xFFU, 4),
		      CO_SDO_AB_INVALID_VALUE, "the block runs past sub-index FFh");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0x2007U << 8, 4), CO_SDO_AB_NO_MAP,
		      "8 bytes");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0x2003U << 8, 4), CO_SDO_AB_NO_MAP,
		      "PDOMapping=0");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0x2008U << 8, 4), CO_SDO_AB_NO_MAP,
		      "rww: RPDO only");
	zassert_equal(co_sim_write(&m.node, 0x1FA0, 1, 0x2004U << 8, 4), 0U, "ro input");

	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, 0, 8), 0U);
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(1, 0x2000, 1, 1, 0x6000, 0), 8),
		      CO_SDO_AB_INVALID_VALUE, "sender node-ID 0");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(1, 0x2000, 1, 1, 0x6000, 128), 8),
		      CO_SDO_AB_INVALID_VALUE, "sender node-ID 128");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(2, 0x2000, 1, 0xFF, 0x6000, 5), 8),
		      CO_SDO_AB_INVALID_VALUE, "sender block past FFh");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(1, 0x3000, 0, 1, 0x6000, 5), 8),
		      CO_SDO_AB_NO_OBJECT);
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(3, 0x2000, 7, 1, 0x6000, 5), 8),
		      CO_SDO_AB_NO_SUB, "local block past 2000h:08");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(1, 0x2004, 0, 1, 0x6000, 5), 8),
		      CO_SDO_AB_NO_MAP, "read-only local object");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(1, 0x2007, 0, 1, 0x6000, 5), 8),
		      CO_SDO_AB_NO_MAP, "8-byte local object");
	zassert_equal(co_sim_write(&m.node, 0x1FD0, 1, disp(8, 0x2000, 1, 1, 0x6000, 5), 8), 0U);
}

#endif /* CONFIG_CANOPEN_MPDO */
