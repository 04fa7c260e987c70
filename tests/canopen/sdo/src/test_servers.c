/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Several servers and their COB-IDs (1200h-127Fh, CiA 301 §7.5.2.33; cia301.md §3.7, §1.1):
 * a write reconfigures the server at once, the CiA 301 rules refuse bad values.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>

#include "harness.h"

static void before(void *f)
{
	h_setup();
}

ZTEST_SUITE(sdo_servers, NULL, NULL, before, NULL, NULL);

static uint32_t write_cobid(uint16_t idx, uint8_t sub, uint32_t v)
{
	uint8_t b[4];

	sys_put_le32(v, b);
	return cli_dl_exp(idx, sub, b, 4);
}

static void use_server1(bool on)
{
	h.cli_tx = on ? SRV1_RX : 0x600 + NODE_ID;
	h.cli_rx = on ? SRV1_TX : 0x580 + NODE_ID;
}

static void enable_server1(void)
{
	zassert_ok(write_cobid(0x1201, 1, SRV1_RX));
	zassert_ok(write_cobid(0x1201, 2, SRV1_TX));
}

ZTEST(sdo_servers, test_default_server_cobids)
{
	zassert_equal(h_get_u32(0x1200, 1), 0x600 + NODE_ID);
	zassert_equal(h_get_u32(0x1200, 2), 0x580 + NODE_ID);
	zassert_equal(h_get_u32(0x1201, 1), 0x80000000);
}

ZTEST(sdo_servers, test_second_server_is_off_by_default)
{
	use_server1(true);
	h_req(0x40, 0x1000, 0, 0);
	h.cli_rx = 0x580 + NODE_ID;
	h_expect_none();
	/* Half configured is still off. */
	use_server1(false);
	zassert_ok(write_cobid(0x1201, 1, SRV1_RX));
	use_server1(true);
	h_req(0x40, 0x1000, 0, 0);
	h_expect_none();
}

ZTEST(sdo_servers, test_second_server_answers_once_configured)
{
	enable_server1();
	use_server1(true);
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
	zassert_equal(h_stats(1).completed, 1);
	zassert_equal(h_stats(0).completed, 2);
}

ZTEST(sdo_servers, test_two_transfers_at_once)
{
	/* Server 0 uploads 1008h while server 1 downloads 2003h, segments interleaved. */
	static const char name[] = "SafeLine SDO test device";
	uint8_t d[8];
	const struct can_frame *f;

	enable_server1();
	h_req(0x40, 0x1008, 0, 0);
	h_expect(0x41, 0x1008, 0, 24);
	use_server1(true);
	h_req(0x21, 0x2003, 0, 14);
	h_expect(0x60, 0x2003, 0, 0);
	use_server1(false);
	h_req(0x60, 0, 0, 0);
	f = h_next();
	zassert_mem_equal(&f->data[1], name, 7);
	use_server1(true);
	memcpy(d,
	       "\x00"
	       "interle",
	       8);
	h_send(d);
	h_expect(0x20, 0, 0, 0);
	use_server1(false);
	h_req(0x70, 0, 0, 0);
	f = h_next();
	zassert_mem_equal(&f->data[1], &name[7], 7);
	use_server1(true);
	memcpy(d,
	       "\x11"
	       "aved!!!",
	       8);
	h_send(d);
	h_expect(0x30, 0, 0, 0);
	zassert_str_equal(h.ram.manuf.x2003_string, "interleaved!!!");
}

ZTEST(sdo_servers, test_second_server_with_29_bit_cobids)
{
	zassert_ok(write_cobid(0x1201, 1, 0x20000000 | 0x1234567));
	zassert_ok(write_cobid(0x1201, 2, 0x20000000 | 0x1234568));
	h.cli_tx = 0x1234567;
	h.cli_rx = 0x1234568;
	h.cli_ext = true;
	h_req(0x40, 0x1018, 1, 0);
	h_expect(0x43, 0x1018, 1, 0x539);
	/* The 11-bit frame with the same low bits is another COB-ID. */
	h.cli_ext = false;
	h.cli_tx = 0x567;
	h_req(0x40, 0x1018, 1, 0);
	h.cli_rx = 0x568;
	h_expect_none();
}

ZTEST(sdo_servers, test_abort_06090030_cobid_changed_while_valid)
{
	enable_server1();
	zassert_equal(write_cobid(0x1201, 1, SRV1_RX + 1), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(write_cobid(0x1201, 2, 0x20000000 | SRV1_TX), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(h_get_u32(0x1201, 1), SRV1_RX);
	/* Rewriting the same value is no change. */
	zassert_ok(write_cobid(0x1201, 1, SRV1_RX));
	/* Invalidate first, then change. */
	zassert_ok(write_cobid(0x1201, 1, 0x80000000 | SRV1_RX));
	zassert_ok(write_cobid(0x1201, 1, SRV1_RX + 1));
	h.cli_tx = SRV1_RX + 1;
	h.cli_rx = SRV1_TX;
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_servers, test_abort_06090030_restricted_can_ids)
{
	static const uint32_t restricted[] = {0x000, 0x001, 0x07F, 0x101, 0x180,
					      0x581, 0x5FF, 0x601, 0x67F, 0x6E0,
					      0x6FF, 0x701, 0x77F, 0x780, 0x7FF};
	static const uint32_t allowed[] = {0x080, 0x100, 0x181, 0x580, 0x600, 0x680, 0x6DF, 0x700};

	for (size_t i = 0; i < ARRAY_SIZE(restricted); i++) {
		zassert_equal(write_cobid(0x1201, 1, restricted[i]), CO_SDO_AB_INVALID_VALUE,
			      "%03x", restricted[i]);
		/* Not in use while invalid: accepted. */
		zassert_ok(write_cobid(0x1201, 1, 0x80000000 | restricted[i]));
	}
	for (size_t i = 0; i < ARRAY_SIZE(allowed); i++) {
		zassert_ok(write_cobid(0x1201, 2, allowed[i]), "%03x", allowed[i]);
		zassert_ok(write_cobid(0x1201, 2, 0x80000000));
	}
}

ZTEST(sdo_servers, test_abort_06090030_11_bit_cobid_with_high_bits)
{
	zassert_equal(write_cobid(0x1201, 1, 0x00000ABC), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(write_cobid(0x1201, 1, 0x80100000), CO_SDO_AB_INVALID_VALUE);
	zassert_ok(write_cobid(0x1201, 1, 0xA0100000));
}

ZTEST(sdo_servers, test_abort_06010002_default_server_cobids_read_only)
{
	zassert_equal(write_cobid(0x1200, 1, 0x80000000 | (0x600 + NODE_ID)), CO_SDO_AB_READONLY);
	zassert_equal(write_cobid(0x1200, 2, 0x580 + NODE_ID), CO_SDO_AB_READONLY);
}

ZTEST(sdo_servers, test_application_reconfigures_default_server)
{
	uint8_t b[4];

	/* The application may; changing a valid CAN-ID needs the invalid step too. */
	sys_put_le32(0x6A0, b);
	zassert_equal(h_set(0x1200, 1, b, 4, CO_OD_WRITER_APP), CO_SDO_AB_INVALID_VALUE);
	sys_put_le32(0x80000000 | (0x600 + NODE_ID), b);
	zassert_ok(h_set(0x1200, 1, b, 4, CO_OD_WRITER_APP));
	h_req(0x40, 0x1000, 0, 0);
	h_expect_none();
	/* Back to the default (restricted range, allowed for the default SDO only). */
	sys_put_le32(0x600 + NODE_ID, b);
	zassert_ok(h_set(0x1200, 1, b, 4, CO_OD_WRITER_APP));
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_servers, test_abort_06070010_cobid_object_of_wrong_type)
{
	/* 1202h declares its COB-IDs as UNSIGNED16: the server stays off and refuses them. */
	uint8_t b[2] = {0xA2, 0x06};

	h_req(0x2B, 0x1202, 1, sys_get_le16(b));
	h_expect_abort(0x1202, 1, CO_SDO_AB_TYPE_MISMATCH);
}

ZTEST(sdo_servers, test_server_invalidating_itself_answers_first)
{
	uint8_t b[4];

	enable_server1();
	use_server1(true);
	zassert_ok(write_cobid(0x1201, 1, 0x80000000 | SRV1_RX));
	h_req(0x40, 0x1000, 0, 0);
	h_expect_none();
	/* The same by a segmented transfer: it completes, it is not dropped by its own write. */
	use_server1(false);
	zassert_ok(write_cobid(0x1201, 1, SRV1_RX));
	use_server1(true);
	sys_put_le32(0x80000000 | SRV1_TX, b);
	zassert_ok(cli_dl_seg(0x1201, 2, b, 4, true));
	zassert_equal(h_stats(1).dropped, 0);
	zassert_equal(h_stats(1).completed, 2);
	h_req(0x40, 0x1000, 0, 0);
	h_expect_none();
}

ZTEST(sdo_servers, test_invalidated_server_drops_its_transfer)
{
	enable_server1();
	use_server1(true);
	h_req(0x21, 0x2003, 0, 14);
	h_expect(0x60, 0x2003, 0, 0);
	use_server1(false);
	zassert_ok(write_cobid(0x1201, 2, 0x80000000 | SRV1_TX));
	h_advance(2 * TIMEOUT_US);
	h.cli_rx = SRV1_TX;
	h_expect_none();
	zassert_equal(h_stats(1).dropped, 1);
	zassert_false(co_sdo_srv_busy(co_sdo_srv_get(&h.node, 1)));
	zassert_str_equal(h.ram.manuf.x2003_string, "init");
}

ZTEST(sdo_servers, test_reset_communication_restores_cobids)
{
	enable_server1();
	h_nmt(CO_NMT_CS_RESET_COMMUNICATION);
	h.rd = h.wr;
	zassert_equal(h_get_u32(0x1201, 1), 0x80000000);
	use_server1(true);
	h_req(0x40, 0x1000, 0, 0);
	h_expect_none();
	use_server1(false);
	h_req(0x40, 0x1000, 0, 0);
	h_expect(0x43, 0x1000, 0, 0x00020192);
}

ZTEST(sdo_servers, test_server_api)
{
	zassert_not_null(co_sdo_srv_get(&h.node, CONFIG_CANOPEN_SDO_SERVERS - 1));
	zassert_is_null(co_sdo_srv_get(&h.node, CONFIG_CANOPEN_SDO_SERVERS));
	zassert_equal(
		co_sdo_srv_init(co_sdo_srv_get(&h.node, 0), &h.node, CONFIG_CANOPEN_SDO_SERVERS),
		-EINVAL);
}
