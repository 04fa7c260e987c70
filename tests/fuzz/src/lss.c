/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS slave (CiA 305) on a node without a node-ID (variant byte bit 0 = 0) or with 20h
 * (tests/canopen/lss/objdict/lss_test.eds). The records are LSS master requests (7E5h), NMT
 * commands and LSS answers of other slaves (7E4h). The bit rate handler plays the controller
 * as the LSS tests' does: stopped from SILENCE to RESUME, so the node's frames wait in the
 * line's TX queue. Invariants beyond the common ones: at most one answer on 7E4h per request,
 * no LSS answer even tried during a switch, and a switch always ends (the node speaks again
 * after its two delays).
 */

#include <errno.h>
#include <string.h>

#include <canopen/lss.h>

#include "fuzz.h"
#include "fuzz_lss_od.h"

static struct {
	struct co_node node;
	struct fuzz_lss_od_ram ram;
	unsigned int answers;
	bool silent;
} l;

static int bitrate(struct co_node *node, enum co_lss_bitrate_step step, uint32_t bps,
		   void *user_data)
{
	switch (step) {
	case CO_LSS_BITRATE_SILENCE:
		l.silent = true;
		fz.tx_busy = true;
		return 0;
	case CO_LSS_BITRATE_RESUME:
		l.silent = false;
		fz.tx_busy = false;
		return 0;
	case CO_LSS_BITRATE_SWITCH:
		/* Some rates "fail" in the controller, so both outcomes are covered. */
		return bps == 10000U ? -EIO : 0;
	default:
		return 0;
	}
}

static void setup(const uint8_t **data, size_t *size)
{
	uint8_t v = 0;

	memset(&l, 0, sizeof(l));
	if (*size > 0U) {
		v = (*data)[0];
		(*data)++;
		(*size)--;
	}
	if (co_node_init(&l.node, "dut", &fz.line, &fuzz_lss_od_def, &l.ram,
			 (v & 1U) != 0U ? 0x20U : CO_NODE_ID_UNCONFIGURED) != 0) {
		fz_fail("co_node_init");
	}
	co_lss_set_bitrate_handler(&l.node, bitrate, NULL);
	fz.dut = &l.node;
	fz.dut_id = (v & 1U) != 0U ? 0x20U : 0U;
	if (co_node_start(&l.node) != 0) {
		fz_fail("co_node_start");
	}
}

static bool may_send(const struct can_frame *f)
{
	uint8_t id = co_node_id(&l.node);

	return f->id == 0x7E4U ||
	       (id != CO_NODE_ID_UNCONFIGURED && (f->id == 0x700U + id || f->id == 0x580U + id));
}

static void on_tx(const struct can_frame *f)
{
	if (f->id == 0x7E4U) {
		l.answers++;
	}
}

static void after_frame(const struct can_frame *rx)
{
	if (rx->id == 0x7E5U && l.answers > 1U) {
		fz_fail("%u LSS answers to one request %02Xh", l.answers, rx->data[0]);
	}
	l.answers = 0;
}

static void after_time(void)
{
	l.answers = 0;
}

static void finish(void)
{
	/* Two delays of at most 65535 ms each; deadline by deadline, to stop at the resume. */
	uint64_t end = fz.now + 2ULL * 65536ULL * FZ_MS;

	while (l.silent && fz.now < end) {
		fz_run_until(MAX(fz.now, MIN(co_line_next_deadline(&fz.line), end)));
	}
	if (l.silent) {
		fz_fail("still silent 131 s after a bit timing switch began");
	}
}

static const uint32_t ids[] = {0x7E5, 0x7E5, 0x7E5, 0x7E5, 0x7E5, 0x7E5, 0x000, 0x7E4};

const struct fz_harness fz_lss = {
	.name = "lss",
	.what = "LSS slave: switch state, configure node-ID and bit timing, inquire, fastscan",
	.setup = setup,
	.ids = ids,
	.n_ids = ARRAY_SIZE(ids),
	.may_send = may_send,
	.on_tx = on_tx,
	.after_time = after_time,
	.after_frame = after_frame,
	.finish = finish,
};
