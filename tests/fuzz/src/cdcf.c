/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The concise-DCF parser of the configuration manager (subsys/canopen/mgr/cfg.c). The input
 * is the stream itself. Invariants:
 *
 * - co_cfg_cdcf_check() agrees with an independent reading of the framing (count, 7-byte
 *   entry headers, sizes within the stream, no trailing byte), entry count included;
 * - co_cfg_download_req() refuses a malformed stream with -EBADMSG and sends nothing;
 * - a well-formed stream is downloaded to a slave that accepts everything: one SDO download
 *   per entry, in stream order, each with the entry's index, sub-index and bytes, confirmed
 *   exactly once with 0.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>

#include <canopen/cfg.h>
#include <canopen/sdo_cli.h>

#include "fuzz.h"
#include "fuzz_master_od.h"

#define MASTER 0x01U
#define SLAVE  0x02U

static struct {
	struct co_node node;
	struct fuzz_master_od_ram ram;
	struct co_cfg cfg;
	const uint8_t *data;
	size_t len;
	/* Reading of the stream by the harness: where the next expected entry starts. */
	size_t next;
	uint32_t done_entries;
	/* The fake slave's view of the download in progress. */
	uint16_t index;
	uint8_t sub;
	uint8_t buf[4096];
	size_t got;
	size_t expect;
	bool segmented;
	bool have_answer;
	struct can_frame answer;
	unsigned int n_con;
	uint32_t abort_code;
	unsigned int sdo_frames;
} d;

/* The framing as CiA 302-3 describes it, read independently of cfg.c. */
static bool ref_check(const uint8_t *p, size_t len, uint32_t *count)
{
	size_t off = 4;

	if (len < 4U) {
		return false;
	}
	*count = sys_get_le32(p);
	for (uint32_t i = 0; i < *count; i++) {
		uint32_t size;

		if (len - off < 7U) {
			return false;
		}
		size = sys_get_le32(&p[off + 3]);
		off += 7U;
		if (size > len - off) {
			return false;
		}
		off += size;
	}
	return off == len;
}

static void entry_done(void)
{
	/* Compare what the slave received with the next entry of the stream. */
	const uint8_t *e = &d.data[d.next];
	uint32_t size = sys_get_le32(&e[3]);

	if (sys_get_le16(e) != d.index || e[2] != d.sub) {
		fz_fail("entry %u: %04Xh:%02X downloaded, the stream has %04Xh:%02X",
			d.done_entries, d.index, d.sub, sys_get_le16(e), e[2]);
	}
	if (size != d.got || memcmp(&e[7], d.buf, MIN(d.got, sizeof(d.buf))) != 0) {
		fz_fail("entry %u (%04Xh:%02X): %zu bytes downloaded, %u in the stream",
			d.done_entries, d.index, d.sub, d.got, size);
	}
	d.next += 7U + size;
	d.done_entries++;
}

static void answer(uint8_t cmd)
{
	d.answer = (struct can_frame){.id = 0x580U + SLAVE, .dlc = 8, .data = {cmd}};
	if ((cmd & 0xE0U) == 0x60U) {
		sys_put_le16(d.index, &d.answer.data[1]);
		d.answer.data[3] = d.sub;
	}
	d.have_answer = true;
}

static void on_tx(const struct can_frame *f)
{
	uint8_t c = f->data[0];

	if (f->id != 0x600U + SLAVE) {
		return;
	}
	d.sdo_frames++;
	if ((c & 0xE0U) == 0x20U) {
		/* Initiate download: expedited (e) or segmented with the size (s). */
		d.index = sys_get_le16(&f->data[1]);
		d.sub = f->data[3];
		d.got = 0;
		if ((c & 0x02U) != 0U) {
			d.got = (c & 0x01U) != 0U ? 4U - ((c >> 2) & 3U) : 4U;
			memcpy(d.buf, &f->data[4], d.got);
			answer(0x60);
			entry_done();
		} else {
			d.segmented = true;
			d.expect = sys_get_le32(&f->data[4]);
			answer(0x60);
		}
	} else if ((c & 0xE0U) == 0x00U && d.segmented) {
		size_t n = 7U - ((c >> 1) & 7U);

		if (d.got + n <= sizeof(d.buf)) {
			memcpy(&d.buf[d.got], &f->data[1], n);
		}
		d.got += n;
		answer((uint8_t)(0x20U | (c & 0x10U)));
		if ((c & 0x01U) != 0U) {
			d.segmented = false;
			entry_done();
		}
	} else if ((c & 0xE0U) == 0x80U) {
		fz_fail("the client aborted entry %04Xh:%02X (%08Xh)", d.index, d.sub,
			sys_get_le32(&f->data[4]));
	}
}

static void con(struct co_node *node, uint8_t id, uint32_t abort_code, uint16_t index, uint8_t sub,
		void *user_data)
{
	d.n_con++;
	d.abort_code = abort_code;
}

static void raw(const uint8_t *data, size_t len)
{
	uint32_t ref_count = 0;
	uint32_t count = 0;
	bool ok = ref_check(data, len, &ref_count);
	int rc = co_cfg_cdcf_check(data, len, &count);
	struct co_sdo_cli *cli;

	if ((rc == 0) != ok || (ok && count != ref_count)) {
		fz_fail("co_cfg_cdcf_check() = %d (%u entries), the framing says %s (%u)", rc,
			count, ok ? "well formed" : "malformed", ref_count);
	}
	if (ok && len > 2048U) {
		return; /* the slave's buffer; long streams only get the check */
	}
	fz_line_init();
	memset(&d, 0, sizeof(d));
	d.data = data;
	d.len = len;
	d.next = 4;
	if (co_node_init(&d.node, "master", &fz.line, &fuzz_master_od_def, &d.ram, MASTER) != 0 ||
	    co_cfg_init(&d.cfg, &d.node) != 0 || co_node_start(&d.node) != 0) {
		fz_fail("master set-up");
	}
	cli = co_sdo_cli_get(&d.node, 0);
	if (cli == NULL || co_sdo_cli_set_server(cli, SLAVE) != 0 ||
	    co_cfg_set_concise_dcf(&d.cfg, SLAVE, data, len) != 0) {
		fz_fail("client set-up");
	}
	rc = co_cfg_download_req(&d.cfg, cli, SLAVE, con, NULL);
	if (len == 0U) {
		/* An empty stream clears 1F22h:02: nothing to download. */
		if (rc != -ENOENT) {
			fz_fail("empty stream: download_req() = %d", rc);
		}
		return;
	}
	if (!ok) {
		if (rc != -EBADMSG || d.sdo_frames > 0U) {
			fz_fail("malformed stream: download_req() = %d, %u frames", rc,
				d.sdo_frames);
		}
		return;
	}
	if (rc != 0) {
		fz_fail("well-formed stream refused: %d", rc);
	}
	for (int step = 0; step < 100000 && d.n_con == 0U; step++) {
		fz_run_until(fz.now + 100U);
		if (d.have_answer) {
			struct can_frame f = d.answer;

			d.have_answer = false;
			fz_rx(&f);
		}
	}
	if (d.n_con != 1U || d.abort_code != 0U) {
		fz_fail("%u confirmations, abort %08Xh", d.n_con, d.abort_code);
	}
	if (d.done_entries != count || d.next != len) {
		fz_fail("%u of %u entries downloaded", d.done_entries, count);
	}
	fz_run_until(fz.now + 10000U);
	if (d.n_con != 1U) {
		fz_fail("a second confirmation");
	}
}

static const uint32_t ids[] = {0};

const struct fz_harness fz_cdcf = {
	.name = "cdcf",
	.what = "concise-DCF parser and download (co_cfg_cdcf_check, co_cfg_download_req)",
	.ids = ids,
	.n_ids = 1,
	.on_tx = on_tx,
	.raw = raw,
};
