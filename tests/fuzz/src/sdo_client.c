/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SDO client against fuzzed server answers. The node (05h) runs one transfer with server 10h;
 * the first three input bytes pick it:
 *
 *   byte 0  bits 0-1 mode (0 and 3 auto, 1 segmented, 2 block), bit 2 upload
 *   byte 1-2 length of the download, or capacity of the upload buffer (modulo 1025)
 *
 * Invariants: the confirmation comes exactly once, at the latest after the transfer's
 * timeout once the answers stop; an upload never reports more than its buffer; a download
 * confirmed with 0 reports its length; at most one request per answer (a block download's
 * sub-block excepted) and at most one abort per time advance.
 */

#include <string.h>

#include <canopen/sdo_cli.h>

#include "fuzz.h"
#include "fuzz_node_od.h"

#define DUT     0x05U
#define SERVER  0x10U
#define MAX_LEN 1024U

static struct {
	struct co_node node;
	struct fuzz_node_od_ram ram;
	struct co_sdo_cli *cli;
	uint8_t buf[MAX_LEN];
	size_t len;
	bool upload;
	bool block;
	bool started;
	unsigned int n_con;
	uint32_t abort_code;
	size_t size;
	unsigned int requests;
} c;

static void con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	c.n_con++;
	c.abort_code = abort_code;
	c.size = size;
	if (c.n_con > 1U) {
		fz_fail("second confirmation (%08Xh after the first)", abort_code);
	}
	if (c.upload && size > c.len) {
		fz_fail("upload of %zu bytes into a buffer of %zu", size, c.len);
	}
	if (!c.upload && abort_code == 0U && size != c.len) {
		fz_fail("download of %zu bytes confirmed with %zu", c.len, size);
	}
}

static void setup(const uint8_t **data, size_t *size)
{
	uint8_t sel = 0;
	enum co_sdo_cli_mode mode;
	int rc;

	memset(&c, 0, sizeof(c));
	if (*size >= 3U) {
		sel = (*data)[0];
		c.len = ((*data)[1] | ((*data)[2] << 8)) % (MAX_LEN + 1U);
		*data += 3;
		*size -= 3;
	}
	c.upload = (sel & 4U) != 0U;
	mode = (sel & 3U) == 1U   ? CO_SDO_CLI_SEGMENTED
	       : (sel & 3U) == 2U ? CO_SDO_CLI_BLOCK
				  : CO_SDO_CLI_AUTO;
	c.block = mode == CO_SDO_CLI_BLOCK;
	for (size_t i = 0; i < sizeof(c.buf); i++) {
		c.buf[i] = (uint8_t)i;
	}
	if (co_node_init(&c.node, "cli", &fz.line, &fuzz_node_od_def, &c.ram, DUT) != 0 ||
	    co_node_start(&c.node) != 0) {
		fz_fail("node start");
	}
	fz.dut = &c.node;
	fz.dut_id = DUT;
	c.cli = co_sdo_cli_get(&c.node, 0);
	if (c.cli == NULL || co_sdo_cli_set_server(c.cli, SERVER) != 0) {
		fz_fail("client set-up");
	}
	if (c.upload) {
		rc = co_sdo_cli_upload_req(c.cli, 0x2000, 0, c.buf, c.len, mode, 200, con, NULL);
	} else {
		rc = co_sdo_cli_download_req(c.cli, 0x2000, 0, c.buf, c.len, mode, 200, con, NULL);
	}
	if (rc != 0) {
		fz_fail("request refused: %d", rc);
	}
	c.started = true;
	c.requests = 0;
}

static bool may_send(const struct can_frame *f)
{
	return f->id == 0x600U + SERVER || f->id == 0x580U + DUT || f->id == 0x700U + DUT;
}

static void on_tx(const struct can_frame *f)
{
	if (f->id == 0x600U + SERVER) {
		c.requests++;
	}
}

static void after_time(void)
{
	if (c.requests > 1U && !c.block) {
		fz_fail("%u requests on a time advance", c.requests);
	}
	c.requests = 0;
}

static void after_frame(const struct can_frame *rx)
{
	if (rx->id == 0x580U + SERVER && c.requests > 1U && !c.block) {
		fz_fail("%u requests for one answer %02Xh", c.requests, rx->data[0]);
	}
	c.requests = 0;
}

static void finish(void)
{
	/* The server falls silent: the transfer must end by its timeout. */
	fz_run_until(fz.now + 2000ULL * FZ_MS);
	if (c.started && c.n_con != 1U) {
		fz_fail("%u confirmations after the server fell silent", c.n_con);
	}
	if (co_sdo_cli_busy(c.cli)) {
		fz_fail("client still busy after its confirmation");
	}
}

static const uint32_t ids[] = {0x590, 0x590, 0x590, 0x590, 0x590, 0x590, 0x000, FZ_REL(0x600)};

const struct fz_harness fz_sdo_client = {
	.name = "sdo_client",
	.what = "SDO client (expedited, segmented, block) against fuzzed server answers",
	.setup = setup,
	.ids = ids,
	.n_ids = ARRAY_SIZE(ids),
	.may_send = may_send,
	.on_tx = on_tx,
	.after_time = after_time,
	.after_frame = after_frame,
	.finish = finish,
};
