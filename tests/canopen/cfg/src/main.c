/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Configuration manager (CiA 302 §6) on one simulation line (simulated time, no thread): a
 * manager node (cfg module, SDO client) and a SafeLine slave (SDO server). The concise DCFs
 * are generated at build time from objdict/cfg_slave.dcf and objdict/cfg_refused.dcf by
 * canopen_concise_dcf(); every frame sent on the line lands in a ring.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/cfg.h>
#include <canopen/node.h>
#include <canopen/sdo_cli.h>

#include "cfg_mgr_od.h"
#include "cfg_slave_od.h"
#include "cfg_slave_cdcf.h"
#include "cfg_refused_cdcf.h"

#define MGR_ID   0x01U
#define SLAVE_ID 0x22U
#define OTHER_ID 0x23U
#define MS       1000ULL
#define RING     1024U

struct rec {
	int calls;
	uint8_t id;
	uint32_t code;
	uint16_t index;
	uint8_t sub;
	uint8_t ids[8];
};

static struct {
	struct co_line line;
	struct co_node mgr;
	struct co_node slave;
	struct cfg_mgr_od_ram mram;
	struct cfg_slave_od_ram sram;
	struct co_cfg cfg;
	struct can_frame ring[RING];
	uint32_t wr;
	uint64_t now;
	struct rec con;
	struct rec ind;
	uint8_t buf[1024];
} t;

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	zassert_true(t.wr < RING, "frame ring overflow");
	t.ring[t.wr++] = *frame;
	return 0;
}

static void pump(void)
{
	for (int i = 0; i < 100000; i++) {
		co_line_process(&t.line, t.now);
		uint64_t next = co_line_next_deadline(&t.line);

		if (k_msgq_num_used_get(&t.line.rxq) == 0U &&
		    (next == UINT64_MAX || next > t.now)) {
			return;
		}
	}
	zassert_unreachable("line does not settle");
}

/* Run until @p r has been called @p calls times, or 2 s of simulated time passed. */
static void run_for(struct rec *r, int calls)
{
	uint64_t end = t.now + 2000 * MS;

	pump();
	while (r->calls < calls && t.now < end) {
		uint64_t next = co_line_next_deadline(&t.line);

		t.now = (next == UINT64_MAX || next > end) ? end : MAX(t.now, next);
		pump();
	}
}

static void record(struct rec *r, uint8_t id, uint32_t code, uint16_t index, uint8_t sub)
{
	if (r->calls < (int)ARRAY_SIZE(r->ids)) {
		r->ids[r->calls] = id;
	}
	r->calls++;
	r->id = id;
	r->code = code;
	r->index = index;
	r->sub = sub;
}

static void con(struct co_node *node, uint8_t id, uint32_t code, uint16_t index, uint8_t sub,
		void *user_data)
{
	zassert_equal_ptr(node, &t.mgr);
	zassert_equal_ptr(user_data, &t.con);
	/* Confirmations run with the manager's mutex held. */
	zassert_true(t.mgr.lock.lock_count >= 1U);
	record(&t.con, id, code, index, sub);
}

static void ind(struct co_node *node, uint8_t id, uint32_t code, uint16_t index, uint8_t sub,
		void *user_data)
{
	zassert_equal_ptr(node, &t.mgr);
	zassert_equal_ptr(user_data, &t.ind);
	record(&t.ind, id, code, index, sub);
}

static void *suite_setup(void)
{
	return NULL;
}

static void before(void *f)
{
	memset(&t, 0, sizeof(t));
	t.now = 1000 * MS;
	co_line_init_sim(&t.line, "sim", sink, NULL);
	co_line_process(&t.line, t.now);
	zassert_ok(co_node_init(&t.mgr, "mgr", &t.line, &cfg_mgr_od_def, &t.mram, MGR_ID));
	zassert_ok(co_node_init(&t.slave, "slave", &t.line, &cfg_slave_od_def, &t.sram, SLAVE_ID));
	zassert_ok(co_cfg_init(&t.cfg, &t.mgr));
	zassert_ok(co_cfg_set_ind(&t.cfg, ind, &t.ind));
	zassert_ok(co_node_start(&t.mgr));
	zassert_ok(co_node_start(&t.slave));
	pump();
	zassert_equal(t.wr, 2U, "two boot-ups");
	t.wr = 0;
}

ZTEST_SUITE(co_cfg, NULL, suite_setup, before, NULL, NULL);

static struct co_sdo_cli *cli0(void)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&t.mgr, 0);

	zassert_not_null(cli);
	zassert_ok(co_sdo_cli_set_server(cli, SLAVE_ID));
	return cli;
}

static uint64_t slave_u(uint16_t index, uint8_t sub)
{
	uint8_t b[8] = {0};
	size_t len = 0;

	co_node_lock(&t.slave);
	zassert_equal(co_od_read(co_node_od(&t.slave), index, sub, 0, b, sizeof(b), &len,
				 CO_OD_WRITER_APP),
		      0U, "read %04x:%02x", index, sub);
	co_node_unlock(&t.slave);
	return co_od_le_get(b, len);
}

/* (index, sub) of every SDO initiate-download request the manager sent to the slave. */
static int downloads(uint32_t *out, int cap)
{
	int n = 0;

	for (uint32_t i = 0; i < t.wr; i++) {
		const struct can_frame *f = &t.ring[i];

		if (f->id == 0x600U + SLAVE_ID && (f->data[0] & 0xE0U) == 0x20U) {
			zassert_true(n < cap);
			out[n++] = ((uint32_t)sys_get_le16(&f->data[1]) << 8) | f->data[3];
		}
	}
	return n;
}

/* The concise DCF entries, as (index << 8 | sub). */
static int stream_keys(const uint8_t *s, size_t len, uint32_t *out, int cap)
{
	uint32_t n;
	size_t pos = 4;

	zassert_ok(co_cfg_cdcf_check(s, len, &n));
	zassert_true((int)n <= cap);
	for (uint32_t i = 0; i < n; i++) {
		out[i] = ((uint32_t)sys_get_le16(&s[pos]) << 8) | s[pos + 2];
		pos += 7 + sys_get_le32(&s[pos + 3]);
	}
	return (int)n;
}

static void assert_slave_configured(void)
{
	char label[33] = {0};
	size_t len = 0;

	zassert_equal(slave_u(0x1017, 0), 100U);
	zassert_equal(slave_u(0x1020, 1), 15000U);
	zassert_equal(slave_u(0x1020, 2), 3600000U);
	zassert_equal(slave_u(0x1400, 1), 0x222U);
	zassert_equal(slave_u(0x1400, 2), 1U);
	zassert_equal(slave_u(0x1600, 0), 2U);
	zassert_equal(slave_u(0x1600, 1), 0x20000020U);
	zassert_equal(slave_u(0x1600, 2), 0x20030010U);
	zassert_equal(slave_u(0x1800, 1), 0x1A2U, "re-enabled after the remap");
	zassert_equal(slave_u(0x1800, 2), 254U);
	zassert_equal(slave_u(0x1800, 3), 50U);
	zassert_equal(slave_u(0x1800, 5), 500U);
	zassert_equal(slave_u(0x1A00, 0), 2U);
	zassert_equal(slave_u(0x1A00, 1), 0x20030010U);
	zassert_equal(slave_u(0x1A00, 2), 0x20000020U);
	zassert_equal(slave_u(0x2000, 0), 0x12345678U);
	zassert_equal(slave_u(0x2002, 0), 42U);
	zassert_equal((int16_t)slave_u(0x2003, 0), -1234);
	co_node_lock(&t.slave);
	zassert_equal(co_od_read(co_node_od(&t.slave), 0x2001, 0, 0, label, sizeof(label) - 1, &len,
				 CO_OD_WRITER_APP),
		      0U);
	co_node_unlock(&t.slave);
	zassert_str_equal(label, "configured by the manager", "segmented entry: '%s'", label);
}

ZTEST(co_cfg, test_download_applies_every_entry_in_stream_order)
{
	uint32_t sent[64], want[64];
	int n_want = stream_keys(cfg_slave_cdcf, sizeof(cfg_slave_cdcf), want, 64);

	zassert_equal(slave_u(0x2000, 0), 0U, "slave starts unconfigured");
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	zassert_true(co_cfg_busy(&t.cfg, SLAVE_ID));
	zassert_equal(co_cfg_download_req(&t.cfg, co_sdo_cli_get(&t.mgr, 1), SLAVE_ID, con, &t.con),
		      -EBUSY, "one download per node");
	run_for(&t.con, 1);
	zassert_equal(t.con.calls, 1);
	zassert_equal(t.con.id, SLAVE_ID);
	zassert_equal(t.con.code, 0U, "abort %08x at %04x:%02x", t.con.code, t.con.index,
		      t.con.sub);
	zassert_false(co_cfg_busy(&t.cfg, SLAVE_ID));
	assert_slave_configured();
	/* One SDO download per entry, in the stream's order (PDO remap order included). */
	zassert_equal(downloads(sent, 64), n_want);
	zassert_mem_equal(sent, want, n_want * sizeof(uint32_t));
	zassert_equal(want[0], 0x101700U, "first entry 1017h");
	zassert_equal(t.ind.calls, 0, "no 1F25h indication for a direct request");
}

ZTEST(co_cfg, test_refused_entry_ends_the_download_and_reports_it)
{
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_refused_cdcf,
					  sizeof(cfg_refused_cdcf)));
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	run_for(&t.con, 1);
	zassert_equal(t.con.calls, 1);
	zassert_equal(t.con.code, CO_SDO_AB_VALUE_HIGH, "abort %08x", t.con.code);
	zassert_equal(t.con.index, 0x2002U);
	zassert_equal(t.con.sub, 0U);
	/* The entry before it was written, the one after it never sent. */
	zassert_equal(slave_u(0x2000, 0), 0xCAFEU);
	zassert_equal(slave_u(0x2002, 0), 10U, "refused value not stored");
	zassert_equal(slave_u(0x2003, 0), 0U);

	uint32_t sent[8];

	zassert_equal(downloads(sent, 8), 2);
	zassert_equal(sent[0], 0x200000U);
	zassert_equal(sent[1], 0x200200U);
	/* Time passes: nothing more is sent. */
	uint32_t wr = t.wr;

	t.now += 3000 * MS;
	pump();
	zassert_equal(t.wr, wr);
	zassert_equal(t.con.calls, 1, "confirmed once");
}

ZTEST(co_cfg, test_malformed_concise_dcf_sends_nothing)
{
	static uint8_t bad[sizeof(cfg_slave_cdcf) + 1];
	size_t n = sizeof(cfg_slave_cdcf);

	/* Truncated last entry. */
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, n - 1));
	zassert_equal(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con), -EBADMSG);
	/* Count says one more entry than the stream holds. */
	memcpy(bad, cfg_slave_cdcf, n);
	sys_put_le32(sys_get_le32(bad) + 1, bad);
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, bad, n));
	zassert_equal(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con), -EBADMSG);
	/* Count one less: a trailing entry. */
	sys_put_le32(sys_get_le32(cfg_slave_cdcf) - 1, bad);
	zassert_equal(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con), -EBADMSG);
	/* Shorter than the count itself. */
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, 3));
	zassert_equal(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con), -EBADMSG);
	/* Nothing stored at all. */
	zassert_equal(co_cfg_download_req(&t.cfg, cli0(), OTHER_ID, con, &t.con), -ENOENT);
	t.now += 1000 * MS;
	pump();
	zassert_equal(t.wr, 0U, "no frame sent");
	zassert_equal(t.con.calls, 0);
	zassert_equal(slave_u(0x2000, 0), 0U);
	/* The checker alone. */
	zassert_equal(co_cfg_cdcf_check(cfg_slave_cdcf, n, NULL), 0);
	zassert_equal(co_cfg_cdcf_check(cfg_slave_cdcf, n - 7, NULL), -EBADMSG);
	zassert_equal(co_cfg_cdcf_check(NULL, 4, NULL), -EINVAL);
}

ZTEST(co_cfg, test_empty_stream_confirms_after_the_request)
{
	static const uint8_t empty[4];

	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, empty, sizeof(empty)));
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	zassert_equal(t.con.calls, 0, "not inside the request");
	run_for(&t.con, 1);
	zassert_equal(t.con.calls, 1);
	zassert_equal(t.con.code, 0U);
	zassert_equal(t.wr, 0U, "nothing to send");
}

static uint32_t mgr_write_u32(uint16_t index, uint8_t sub, uint32_t v)
{
	uint8_t b[4];
	uint32_t ab;

	sys_put_le32(v, b);
	co_node_lock(&t.mgr);
	ab = co_od_write(co_node_od(&t.mgr), index, sub, b, sizeof(b), CO_OD_WRITER_SDO);
	co_node_unlock(&t.mgr);
	return ab;
}

ZTEST(co_cfg, test_1f25h_conf_configures_one_node)
{
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	zassert_equal(mgr_write_u32(0x1F25, SLAVE_ID, CO_CFG_SIGNATURE_CONF), 0U);
	run_for(&t.ind, 1);
	zassert_equal(t.ind.calls, 1);
	zassert_equal(t.ind.id, SLAVE_ID);
	zassert_equal(t.ind.code, 0U, "abort %08x at %04x:%02x", t.ind.code, t.ind.index,
		      t.ind.sub);
	assert_slave_configured();
}

ZTEST(co_cfg, test_1f25h_refuses_bad_signature_and_missing_data)
{
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	/* "save" is not "conf". */
	zassert_equal(mgr_write_u32(0x1F25, SLAVE_ID, 0x65766173U), CO_SDO_AB_INVALID_VALUE);
	zassert_equal(mgr_write_u32(0x1F25, CO_CFG_ALL, 0x666E6F64U), CO_SDO_AB_INVALID_VALUE);
	/* No concise DCF for that node. */
	zassert_equal(mgr_write_u32(0x1F25, OTHER_ID, CO_CFG_SIGNATURE_CONF), CO_SDO_AB_NO_DATA);
	/* Malformed stored data. */
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, 10));
	zassert_equal(mgr_write_u32(0x1F25, SLAVE_ID, CO_CFG_SIGNATURE_CONF), CO_SDO_AB_DATA_XFER);
	/* Sub 0 is the constant 80h. */
	zassert_equal(mgr_write_u32(0x1F25, 0, CO_CFG_SIGNATURE_CONF) != 0U, true);
	t.now += 1000 * MS;
	pump();
	zassert_equal(t.wr, 0U, "no frame sent");
	zassert_equal(t.ind.calls, 0);
}

ZTEST(co_cfg, test_1f25h_all_configures_every_stored_node)
{
	zassert_equal(mgr_write_u32(0x1F25, CO_CFG_ALL, CO_CFG_SIGNATURE_CONF), 0U,
		      "succeeds with nothing stored");
	zassert_equal(t.ind.calls, 0, "indicated later");
	run_for(&t.ind, 1);
	zassert_equal(t.ind.calls, 1);
	zassert_equal(t.ind.id, CO_CFG_ALL);
	zassert_equal(t.ind.code, 0U);
	zassert_equal(t.wr, 0U);

	t.ind = (struct rec){0};
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	zassert_equal(mgr_write_u32(0x1F25, CO_CFG_ALL, CO_CFG_SIGNATURE_CONF), 0U);
	run_for(&t.ind, 2);
	zassert_equal(t.ind.calls, 2);
	zassert_equal(t.ind.ids[0], SLAVE_ID);
	zassert_equal(t.ind.ids[1], CO_CFG_ALL);
	zassert_equal(t.ind.code, 0U);
	assert_slave_configured();
}

ZTEST(co_cfg, test_1f25h_all_reports_the_first_failure)
{
	/* 23h has data but no device: its first entry times out; 22h refuses 2002h. */
	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_refused_cdcf,
					  sizeof(cfg_refused_cdcf)));
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, OTHER_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	zassert_equal(mgr_write_u32(0x1F25, CO_CFG_ALL, CO_CFG_SIGNATURE_CONF), 0U);
	run_for(&t.ind, 3);
	zassert_equal(t.ind.calls, 3);
	zassert_equal(t.ind.ids[0], SLAVE_ID);
	zassert_equal(t.ind.ids[1], OTHER_ID);
	zassert_equal(t.ind.ids[2], CO_CFG_ALL);
	zassert_equal(t.ind.code, CO_SDO_AB_VALUE_HIGH, "first failure: %08x", t.ind.code);
	zassert_equal(t.ind.index, 0x2002U);
}

static uint32_t mgr_stream(uint16_t index, uint8_t sub, const uint8_t *data, size_t len,
			   size_t chunk, bool abort_half)
{
	struct co_od_xfer x;
	struct co_od *od = co_node_od(&t.mgr);
	uint32_t ab;

	co_node_lock(&t.mgr);
	ab = co_od_write_begin(od, &x, index, sub, (uint32_t)len, CO_OD_WRITER_SDO);
	for (size_t off = 0; ab == 0U && off < len; off += chunk) {
		size_t n = MIN(chunk, len - off);

		if (abort_half && off >= len / 2) {
			co_od_write_abort(od, &x);
			break;
		}
		ab = co_od_write_chunk(od, &x, (uint32_t)off, data + off, n, off + n == len);
	}
	co_node_unlock(&t.mgr);
	return ab;
}

static size_t mgr_read(uint16_t index, uint8_t sub, uint32_t *ab)
{
	size_t len = 0;

	co_node_lock(&t.mgr);
	*ab = co_od_read(co_node_od(&t.mgr), index, sub, 0, t.buf, sizeof(t.buf), &len,
			 CO_OD_WRITER_SDO);
	co_node_unlock(&t.mgr);
	return len;
}

ZTEST(co_cfg, test_1f22h_sdo_writes_go_to_the_pool_and_read_back)
{
	const uint8_t *p;
	size_t len;
	uint32_t ab;

	/* Empty: 1F22h reads as the empty data set, 1F20h aborts. */
	zassert_equal(mgr_read(0x1F22, 5, &ab), 4U);
	zassert_equal(ab, 0U);
	zassert_equal(sys_get_le32(t.buf), 0U);
	mgr_read(0x1F20, 5, &ab);
	zassert_equal(ab, CO_SDO_AB_NO_DATA);
	zassert_equal(mgr_read(0x1F22, 0, &ab), 1U);
	zassert_equal(t.buf[0], 127U);

	/* Written in 7-byte chunks like a segmented download, for two nodes. */
	zassert_equal(
		mgr_stream(0x1F22, SLAVE_ID, cfg_refused_cdcf, sizeof(cfg_refused_cdcf), 7, false),
		0U);
	zassert_equal(
		mgr_stream(0x1F22, OTHER_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf), 7, false), 0U);
	/* Replacing the first moves the second: both must still read back exactly. */
	zassert_equal(
		mgr_stream(0x1F22, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf), 7, false), 0U);
	zassert_equal(mgr_read(0x1F22, SLAVE_ID, &ab), sizeof(cfg_slave_cdcf));
	zassert_mem_equal(t.buf, cfg_slave_cdcf, sizeof(cfg_slave_cdcf));
	zassert_equal(mgr_read(0x1F22, OTHER_ID, &ab), sizeof(cfg_slave_cdcf));
	zassert_mem_equal(t.buf, cfg_slave_cdcf, sizeof(cfg_slave_cdcf));
	zassert_ok(co_cfg_get_concise_dcf(&t.cfg, SLAVE_ID, &p, &len));
	zassert_equal(len, sizeof(cfg_slave_cdcf));
	zassert_true(p < (const uint8_t *)&t.cfg + sizeof(t.cfg) && p >= (const uint8_t *)&t.cfg,
		     "stored in the instance's pool");

	/* A malformed stream is refused and the old value stays. */
	zassert_equal(mgr_stream(0x1F22, SLAVE_ID, cfg_refused_cdcf, sizeof(cfg_refused_cdcf) - 1,
				 7, false),
		      CO_SDO_AB_DATA_XFER);
	/* So does an aborted one. */
	zassert_equal(
		mgr_stream(0x1F22, SLAVE_ID, cfg_refused_cdcf, sizeof(cfg_refused_cdcf), 7, true),
		0U);
	zassert_equal(mgr_read(0x1F22, SLAVE_ID, &ab), sizeof(cfg_slave_cdcf));
	zassert_mem_equal(t.buf, cfg_slave_cdcf, sizeof(cfg_slave_cdcf));
	/* More than the pool holds. */
	static uint8_t big[CONFIG_CANOPEN_CFG_POOL_SIZE];

	zassert_equal(mgr_stream(0x1F20, 7, big, sizeof(big), 64, false), CO_SDO_AB_OUT_OF_MEM);
	mgr_read(0x1F20, 7, &ab);
	zassert_equal(ab, CO_SDO_AB_NO_DATA);
	/* A DCF (1F20h) is kept as text. */
	static const char dcf[] = "[DeviceComissioning]\nNodeID=0x22\n";

	zassert_equal(mgr_stream(0x1F20, SLAVE_ID, (const uint8_t *)dcf, sizeof(dcf) - 1, 7, false),
		      0U);
	zassert_equal(mgr_read(0x1F20, SLAVE_ID, &ab), sizeof(dcf) - 1);
	zassert_mem_equal(t.buf, dcf, sizeof(dcf) - 1);
	zassert_equal(mgr_read(0x1F22, OTHER_ID, &ab), sizeof(cfg_slave_cdcf));
	zassert_mem_equal(t.buf, cfg_slave_cdcf, sizeof(cfg_slave_cdcf));

	/* The download runs from the pool; writes that would move it wait for the end. */
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	zassert_equal(
		mgr_stream(0x1F22, OTHER_ID, cfg_refused_cdcf, sizeof(cfg_refused_cdcf), 7, false),
		CO_SDO_AB_DATA_DEV_STATE);
	run_for(&t.con, 1);
	zassert_equal(t.con.code, 0U, "abort %08x at %04x:%02x", t.con.code, t.con.index,
		      t.con.sub);
	assert_slave_configured();
	/* Writing the empty data set clears the entry. */
	static const uint8_t empty[4];

	zassert_equal(mgr_stream(0x1F22, SLAVE_ID, empty, sizeof(empty), 7, false), 0U);
	zassert_equal(co_cfg_get_concise_dcf(&t.cfg, SLAVE_ID, &p, &len), -ENOENT);
	zassert_equal(mgr_write_u32(0x1F25, SLAVE_ID, CO_CFG_SIGNATURE_CONF), CO_SDO_AB_NO_DATA);
}

ZTEST(co_cfg, test_expected_date_time_and_lookup)
{
	uint32_t date = 1, time = 1;

	zassert_equal_ptr(co_cfg_get(&t.mgr), &t.cfg);
	zassert_is_null(co_cfg_get(&t.slave));
	zassert_ok(co_cfg_get_expected(&t.cfg, SLAVE_ID, &date, &time));
	zassert_equal(date, 0U);
	zassert_equal(time, 0U);
	zassert_equal(mgr_write_u32(0x1F26, SLAVE_ID, 15000), 0U);
	zassert_equal(mgr_write_u32(0x1F27, SLAVE_ID, 3600000), 0U);
	zassert_ok(co_cfg_get_expected(&t.cfg, SLAVE_ID, &date, &time));
	zassert_equal(date, 15000U);
	zassert_equal(time, 3600000U);
	zassert_ok(co_cfg_get_expected(&t.cfg, OTHER_ID, &date, &time));
	zassert_equal(date, 0U);
	zassert_equal(co_cfg_get_expected(&t.cfg, 0, &date, &time), -EINVAL);
	zassert_equal(co_cfg_set_concise_dcf(&t.cfg, 128, cfg_slave_cdcf, 4), -EINVAL);
	zassert_equal(mgr_write_u32(0x1F26, 128, 1), CO_SDO_AB_NO_SUB);
}

#if defined(CONFIG_CANOPEN_PDO)
ZTEST(co_cfg, test_remap_without_disabling_is_refused_by_the_pdo_service)
{
	/* The order dcf2cdcf avoids: mapping count 0 while TPDO 1 is valid (CiA 301 §7.5.2.36). */
	static const uint8_t wrong[] = {1, 0, 0, 0, 0x00, 0x1A, 0x00, 1, 0, 0, 0, 0x00};

	zassert_ok(co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, wrong, sizeof(wrong)));
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	run_for(&t.con, 1);
	zassert_equal(t.con.calls, 1);
	zassert_not_equal(t.con.code, 0U, "the slave's PDO service must refuse it");
	zassert_equal(t.con.index, 0x1A00U);
	zassert_equal(slave_u(0x1A00, 0), 1U);
	/* The generated stream, which disables first, is accepted (PDO checks included). */
	t.con = (struct rec){0};
	zassert_ok(
		co_cfg_set_concise_dcf(&t.cfg, SLAVE_ID, cfg_slave_cdcf, sizeof(cfg_slave_cdcf)));
	zassert_ok(co_cfg_download_req(&t.cfg, cli0(), SLAVE_ID, con, &t.con));
	run_for(&t.con, 1);
	zassert_equal(t.con.code, 0U, "abort %08x at %04x:%02x", t.con.code, t.con.index,
		      t.con.sub);
	assert_slave_configured();
}
#endif

static struct {
	int calls;
	uint32_t code;
	size_t size;
} sdo;

static void sdo_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data)
{
	sdo.calls++;
	sdo.code = code;
	sdo.size = size;
}

static uint32_t tool_transfer(bool upload, uint16_t index, uint8_t sub, void *data, size_t len,
			      enum co_sdo_cli_mode mode)
{
	/* The slave's own SDO client plays the configuration tool writing to the manager. */
	struct co_sdo_cli *cli = co_sdo_cli_get(&t.slave, 0);
	uint64_t end = t.now + 2000 * MS;

	zassert_ok(co_sdo_cli_set_server(cli, MGR_ID));
	sdo.calls = 0;
	if (upload) {
		zassert_ok(
			co_sdo_cli_upload_req(cli, index, sub, data, len, mode, 0, sdo_con, NULL));
	} else {
		zassert_ok(co_sdo_cli_download_req(cli, index, sub, data, len, mode, 0, sdo_con,
						   NULL));
	}
	pump();
	while (sdo.calls == 0 && t.now < end) {
		uint64_t next = co_line_next_deadline(&t.line);

		t.now = (next == UINT64_MAX || next > end) ? end : MAX(t.now, next);
		pump();
	}
	zassert_equal(sdo.calls, 1);
	return sdo.code;
}

ZTEST(co_cfg, test_1f22h_and_1f25h_over_sdo_from_a_tool)
{
	static uint8_t back[sizeof(cfg_slave_cdcf) + 16];
	uint8_t conf[4];

	/* Segmented download of the stream into the manager's pool, then read it back. */
	zassert_equal(tool_transfer(false, 0x1F22, SLAVE_ID, (void *)cfg_slave_cdcf,
				    sizeof(cfg_slave_cdcf), CO_SDO_CLI_AUTO),
		      0U, "abort %08x", sdo.code);
	zassert_equal(tool_transfer(true, 0x1F22, SLAVE_ID, back, sizeof(back), CO_SDO_CLI_AUTO),
		      0U, "abort %08x", sdo.code);
	zassert_equal(sdo.size, sizeof(cfg_slave_cdcf));
	zassert_mem_equal(back, cfg_slave_cdcf, sizeof(cfg_slave_cdcf));
	/* Block download of another node's stream. */
	zassert_equal(tool_transfer(false, 0x1F22, OTHER_ID, (void *)cfg_refused_cdcf,
				    sizeof(cfg_refused_cdcf), CO_SDO_CLI_BLOCK),
		      0U, "abort %08x", sdo.code);
	zassert_equal(tool_transfer(true, 0x1F22, OTHER_ID, back, sizeof(back), CO_SDO_CLI_AUTO),
		      0U);
	zassert_equal(sdo.size, sizeof(cfg_refused_cdcf));
	zassert_mem_equal(back, cfg_refused_cdcf, sizeof(cfg_refused_cdcf));
	/* A malformed stream over SDO is aborted with 08000020h. */
	zassert_equal(
		tool_transfer(false, 0x1F22, OTHER_ID, (void *)cfg_slave_cdcf, 20, CO_SDO_CLI_AUTO),
		CO_SDO_AB_DATA_XFER);
	/* An empty 1F22h sub-index reads as 00 00 00 00; an empty 1F20h aborts. */
	zassert_equal(tool_transfer(true, 0x1F22, 9, back, sizeof(back), CO_SDO_CLI_AUTO), 0U);
	zassert_equal(sdo.size, 4U);
	zassert_equal(sys_get_le32(back), 0U);
	zassert_equal(tool_transfer(true, 0x1F20, 9, back, sizeof(back), CO_SDO_CLI_AUTO),
		      CO_SDO_AB_NO_DATA);
	/* A wrong signature on 1F25h over SDO. */
	sys_put_le32(0x12345678U, conf);
	zassert_equal(tool_transfer(false, 0x1F25, SLAVE_ID, conf, 4, CO_SDO_CLI_AUTO),
		      CO_SDO_AB_INVALID_VALUE);
	zassert_equal(t.ind.calls, 0);
	/* "conf": the manager configures the slave from the pool. */
	sys_put_le32(CO_CFG_SIGNATURE_CONF, conf);
	zassert_equal(tool_transfer(false, 0x1F25, SLAVE_ID, conf, 4, CO_SDO_CLI_AUTO), 0U);
	run_for(&t.ind, 1);
	zassert_equal(t.ind.calls, 1);
	zassert_equal(t.ind.id, SLAVE_ID);
	zassert_equal(t.ind.code, 0U, "abort %08x at %04x:%02x", t.ind.code, t.ind.index,
		      t.ind.sub);
	assert_slave_configured();
}
