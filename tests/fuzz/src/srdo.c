/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SRDO (CiA 304) on node 05h with tests/canopen/srdo/objdict/srdo_test.eds: variant byte
 * bit 0 signs the configuration and declares it valid (13FEh = A5h), bit 7 starts the node.
 * The records are SRDO frame pairs (FFh-10Ch), SYNC, NMT and SDO requests. Invariants
 * beyond the common ones: every SRDO the node sends on an even COB-ID comes right after the
 * frame of the same length on the odd COB-ID below it (the pair; the inverted data are the
 * application's objects, so their values are not compared), and SRDO identifiers stay within
 * FFh-180h.
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include <canopen/od.h>
#include <canopen/srdo.h>

#include "fuzz.h"
#include "fuzz_srdo_od.h"

#define DUT 0x05U

static struct {
	struct co_node node;
	struct fuzz_srdo_od_ram ram;
	struct can_frame last_odd;
	bool have_odd;
} s;

static void setup(const uint8_t **data, size_t *size)
{
	uint8_t v = 0;

	memset(&s, 0, sizeof(s));
	if (*size > 0U) {
		v = (*data)[0];
		(*data)++;
		(*size)--;
	}
	if (co_node_init(&s.node, "dut", &fz.line, &fuzz_srdo_od_def, &s.ram, DUT) != 0) {
		fz_fail("co_node_init");
	}
	fz.dut = &s.node;
	fz.dut_id = DUT;
	if (co_node_start(&s.node) != 0) {
		fz_fail("co_node_start");
	}
	if ((v & 1U) != 0U) {
		struct co_od *od = co_node_od(&s.node);
		uint8_t a5 = CO_SRDO_VALID;

		co_node_lock(&s.node);
		for (uint8_t n = 1; n <= 3; n++) {
			uint16_t crc;
			uint8_t b[2];

			if (co_srdo_signature(&s.node, n, &crc) == 0) {
				sys_put_le16(crc, b);
				(void)co_od_write(od, 0x13FF, n, b, 2, CO_OD_WRITER_SDO);
			}
		}
		(void)co_od_write(od, 0x13FE, 0, &a5, 1, CO_OD_WRITER_SDO);
		co_node_unlock(&s.node);
	}
	if ((v & 0x80U) != 0U) {
		(void)co_nmt_req(&s.node, CO_NMT_CS_START);
	}
}

static bool may_send(const struct can_frame *f)
{
	return (f->id >= 0x101U && f->id <= 0x180U) || f->id == 0x580U + DUT ||
	       f->id == 0x700U + DUT;
}

static void on_tx(const struct can_frame *f)
{
	if (f->id < 0x0FFU || f->id > 0x180U) {
		return;
	}
	if ((f->id & 1U) != 0U) {
		s.last_odd = *f;
		s.have_odd = true;
		return;
	}
	if (!s.have_odd || s.last_odd.id + 1U != f->id || s.last_odd.dlc != f->dlc) {
		fz_fail("SRDO %03Xh without its normal frame just before", f->id);
	}
	s.have_odd = false;
}

static const uint32_t ids[] = {0x0FF, 0x100, 0x101, 0x102, 0x109,         0x10A,
			       0x10B, 0x10C, 0x080, 0x000, FZ_REL(0x600), 0x001};

const struct fz_harness fz_srdo = {
	.name = "srdo",
	.what = "SRDO consumer and producer (pairs, SCT, SRVT, GFC, configuration check)",
	.setup = setup,
	.ids = ids,
	.n_ids = ARRAY_SIZE(ids),
	.may_send = may_send,
	.on_tx = on_tx,
};
