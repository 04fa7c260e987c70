/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* SDO client parameter 1280h + n (CiA 301 §7.5.2.34): binding, COB-ID rules, reconfiguration. */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static uint8_t buf[64];

static void before(void *f)
{
	h_setup();
}

static uint32_t cobid(uint16_t idx, uint8_t sub)
{
	uint32_t v = 0;
	uint32_t code;

	/* The dictionary accessors require the node's mutex. */
	co_node_lock(&h.cnode);
	code = co_od_get_u32(co_node_od(&h.cnode), idx, sub, &v);
	co_node_unlock(&h.cnode);
	zassert_equal(code, 0U);
	return v;
}

static uint32_t set(uint16_t idx, uint8_t sub, uint32_t v, enum co_od_writer w)
{
	uint32_t code;

	co_node_lock(&h.cnode);
	code = co_od_set_u32(co_node_od(&h.cnode), idx, sub, v, w);
	co_node_unlock(&h.cnode);
	return code;
}

static uint32_t read_u32(uint8_t num, uint16_t idx)
{
	struct con_rec *rec = &h.con[num];

	memset(rec, 0, sizeof(*rec));
	memset(buf, 0, sizeof(buf));
	zassert_ok(co_sdo_cli_upload_req(h_cli(num), idx, 0, buf, sizeof(buf), CO_SDO_CLI_AUTO, 0,
					 h_con, rec));
	h_run_for_con(rec, 10 * TIMEOUT_US);
	zassert_equal(rec->calls, 1U);
	zassert_equal(rec->code, 0U, "code %08x", rec->code);
	return sys_get_le32(buf);
}

ZTEST(sdo_cli_config, test_set_server_writes_1280h)
{
	uint32_t code;
	uint8_t id = 0;

	zassert_equal(cobid(0x1280, 1), 0x80000000U);
	zassert_equal(co_sdo_cli_upload_req(h_cli(0), 0x2004, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(0)),
		      -ENOTCONN);
	zassert_ok(co_sdo_cli_set_server(h_cli(0), SRV_ID));
	zassert_equal(cobid(0x1280, 1), 0x600U + SRV_ID);
	zassert_equal(cobid(0x1280, 2), 0x580U + SRV_ID);
	co_node_lock(&h.cnode);
	code = co_od_get_u8(co_node_od(&h.cnode), 0x1280, 3, &id);
	co_node_unlock(&h.cnode);
	zassert_equal(code, 0U);
	zassert_equal(id, SRV_ID);
	zassert_equal(read_u32(0, 0x2004), 0x12345678U);
	/* Re-binding a valid client to another server is allowed through the API. */
	zassert_ok(co_sdo_cli_set_server(h_cli(0), SRV2_ID));
	zassert_equal(cobid(0x1280, 1), 0x600U + SRV2_ID);
	zassert_equal(h_od_set_u32(&h.snode2, 0x2004, 0, 0xFEEDU, CO_OD_WRITER_APP), 0U);
	zassert_equal(read_u32(0, 0x2004), 0xFEEDU);
}

ZTEST(sdo_cli_config, test_cobid_rules_06090030)
{
	zassert_equal(set(0x1281, 1, 0x600U + SRV_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 2, 0x580U + SRV_ID, CO_OD_WRITER_SDO), 0U);
	/* A valid CAN-ID is not changed to another valid one: invalidate first. */
	zassert_equal(set(0x1281, 1, 0x600U + SRV2_ID, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(set(0x1281, 1, 0x600U + SRV2_ID, CO_OD_WRITER_APP), CO_SDO_AB_INVALID_VALUE);
	/* The same value again is no change. */
	zassert_equal(set(0x1281, 1, 0x600U + SRV_ID, CO_OD_WRITER_SDO), 0U);
	/* Restricted CAN-IDs (CiA 301 §7.3.5: NMT, 101h-180h, heartbeat...). */
	zassert_equal(set(0x1281, 1, 0x80000000U, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 1, 0x701, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(set(0x1281, 1, 0x101, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(set(0x1281, 1, 0x000, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	/* An 11-bit COB-ID with bits 28..11 set. */
	zassert_equal(set(0x1281, 1, 0x1000600, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	/* Wrong length: the dictionary refuses it before the hook. */
	zassert_equal(h_od_write(&h.cnode, 0x1281, 1, buf, 2, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_SHORT);
	zassert_equal(cobid(0x1281, 1), 0x80000000U);
}

ZTEST(sdo_cli_config, test_write_reconfigures_at_once)
{
	/* Configured through the dictionary (as a configuration tool would over SDO). */
	zassert_equal(set(0x1281, 1, 0x600U + SRV_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 2, 0x580U + SRV_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(read_u32(1, 0x2004), 0x12345678U);
	zassert_equal(set(0x1281, 1, 0x80000000U | (0x600U + SRV_ID), CO_OD_WRITER_SDO), 0U);
	zassert_equal(co_sdo_cli_upload_req(h_cli(1), 0x2004, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(1)),
		      -ENOTCONN);
	zassert_equal(set(0x1281, 2, 0x580U + SRV2_ID, CO_OD_WRITER_SDO), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(set(0x1281, 2, 0x80000000U, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 2, 0x580U + SRV2_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 1, 0x600U + SRV2_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(h_od_set_u32(&h.snode2, 0x2004, 0, 0xBEEFU, CO_OD_WRITER_APP), 0U);
	zassert_equal(read_u32(1, 0x2004), 0xBEEFU);
}

ZTEST(sdo_cli_config, test_invalidating_during_transfer_drops_it)
{
	struct con_rec *rec = &h.con[1];

	zassert_equal(set(0x1281, 1, 0x600U + FAKE_ID, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 2, 0x580U + FAKE_ID, CO_OD_WRITER_SDO), 0U);
	zassert_ok(
		co_sdo_cli_upload_req(h_cli(1), 0x2000, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con, rec));
	h_pump();
	h_expect(0x40, 0x2000, 0, 0);
	zassert_equal(set(0x1281, 2, 0x80000000U, CO_OD_WRITER_SDO), 0U);
	/* Confirmed from the line, without a frame (the channel is gone). */
	zassert_equal(rec->calls, 0U);
	h_pump();
	zassert_equal(rec->calls, 1U);
	zassert_equal(rec->code, CO_SDO_AB_GENERAL);
	h_expect_none();
	/* An answer on the old COB-ID reaches nobody. */
	h_fake(0x43, 0x2000, 0, 1);
	zassert_equal(rec->calls, 1U);
}

/* 29-bit COB-IDs: extended frames both ways. */
ZTEST(sdo_cli_config, test_29_bit_cobids)
{
	struct con_rec *rec = &h.con[1];
	const struct can_frame *f;
	struct can_frame a = {.id = 0x1234501,
			      .flags = CAN_FRAME_IDE,
			      .dlc = 8,
			      .data = {0x4B, 0x01, 0x20, 0x00, 0x34, 0x12}};

	zassert_equal(set(0x1281, 1, 0x20000000U | 0x1234500, CO_OD_WRITER_SDO), 0U);
	zassert_equal(set(0x1281, 2, 0x20000000U | 0x1234501, CO_OD_WRITER_SDO), 0U);
	zassert_ok(
		co_sdo_cli_upload_req(h_cli(1), 0x2001, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con, rec));
	h_pump();
	f = h_next_from(0x1234500);
	zassert_not_null(f);
	zassert_true((f->flags & CAN_FRAME_IDE) != 0U);
	zassert_equal(f->data[0], 0x40);
	/* The same id as an 11-bit frame is not the server. */
	a.flags = 0;
	a.id = 0x501;
	co_line_rx(&h.line, &a, h.now);
	h_pump();
	zassert_equal(rec->calls, 0U);
	a.flags = CAN_FRAME_IDE;
	a.id = 0x1234501;
	co_line_rx(&h.line, &a, h.now);
	h_pump();
	zassert_equal(rec->calls, 1U);
	zassert_equal(rec->code, 0U);
	zassert_equal(rec->size, 2U);
	zassert_equal(sys_get_le16(buf), 0x1234);
}

ZTEST(sdo_cli_config, test_reset_communication_restores_1280h_and_keeps_api_binding)
{
	zassert_ok(co_sdo_cli_set_server(h_cli(0), SRV_ID));
	zassert_ok(co_sdo_cli_set_server(h_cli(3), SRV_ID));
	h_nmt(0x82, CLI_ID);
	zassert_equal(cobid(0x1280, 1), 0x80000000U);
	zassert_equal(co_sdo_cli_upload_req(h_cli(0), 0x2004, 0, buf, 4, CO_SDO_CLI_AUTO, 0, h_con,
					    CON(0)),
		      -ENOTCONN);
	zassert_equal(read_u32(3, 0x2004), 0x12345678U);
}

ZTEST_SUITE(sdo_cli_config, NULL, NULL, before, NULL, NULL);
