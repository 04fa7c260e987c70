/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Harnesses on one slave (objdict/fuzz_node.eds, node 05h): NMT, heartbeat and guarding, the
 * SDO server, PDO, SYNC, TIME and the EMCY consumer. Each harness configures the dictionary
 * for its service (by a restore callback, so the configuration survives the resets the input
 * asks for) and draws its frames mostly from that service's identifiers; every harness also
 * reaches the SDO server, so an input may reconfigure the node as a tool would.
 *
 * The first input byte picks variants of the configuration (producer or consumer, ...).
 */

#include <string.h>

#include <zephyr/sys/byteorder.h>

#include <canopen/od.h>
#include <canopen/pdo.h>

#include "fuzz.h"
#include "fuzz_node_od.h"

#define DUT 0x05U

struct cfg {
	uint16_t index;
	uint8_t sub;
	uint8_t len;
	uint32_t value;
};

static struct {
	struct co_node node;
	struct fuzz_node_od_ram ram;
	const struct cfg *cfg;
	size_t n_cfg;
	uint8_t variant;
	/* SDO server bookkeeping (default server 600h/580h + node-ID). */
	unsigned int sdo_answers;
	bool sdo_idle;
	bool sdo_block;
	uint8_t sdo_req_cmd;
} n;

static void restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (size_t i = 0; i < n.n_cfg; i++) {
		uint8_t buf[4];

		sys_put_le32(n.cfg[i].value, buf);
		/* A refused value is a harness bug: the configuration is fixed. */
		if (co_od_write(od, n.cfg[i].index, n.cfg[i].sub, buf, n.cfg[i].len,
				CO_OD_WRITER_STORAGE) != 0U) {
			fz_fail("configuration %04Xh:%02X refused", n.cfg[i].index, n.cfg[i].sub);
		}
	}
}

static void node_up(const struct cfg *cfg, size_t n_cfg, const uint8_t **data, size_t *size)
{
	memset(&n, 0, sizeof(n));
	n.cfg = cfg;
	n.n_cfg = n_cfg;
	n.sdo_idle = true;
	if (*size > 0U) {
		n.variant = (*data)[0];
		(*data)++;
		(*size)--;
	}
	if (co_node_init(&n.node, "dut", &fz.line, &fuzz_node_od_def, &n.ram, DUT) != 0) {
		fz_fail("co_node_init");
	}
	co_od_set_restore_cb(co_node_od(&n.node), restore, NULL);
	fz.dut = &n.node;
	fz.dut_id = DUT;
	if (co_node_start(&n.node) != 0) {
		fz_fail("co_node_start");
	}
	/* Half the inputs start in Operational: PDOs and SYNC consumers are live at once. */
	if ((n.variant & 0x80U) != 0U) {
		(void)co_nmt_req(&n.node, CO_NMT_CS_START);
	}
}

/* --- SDO server: one answer per request ------------------------------------------------- */

static void sdo_on_tx(const struct can_frame *f)
{
	uint8_t cmd = f->data[0];

	if (f->id != 0x580U + DUT) {
		return;
	}
	n.sdo_answers++;
	/* Idle after an abort, an expedited download's confirmation, an expedited upload. */
	n.sdo_idle = cmd == 0x80U || (cmd == 0x60U && (n.sdo_req_cmd & 0xE2U) == 0x22U) ||
		     (cmd & 0xE2U) == 0x42U;
}

static void sdo_after_time(void)
{
	/* A timeout ends a transfer with one abort; a block upload may send its sub-block. */
	if (n.sdo_answers > 1U && !n.sdo_block) {
		fz_fail("%u SDO frames on a time advance", n.sdo_answers);
	}
	n.sdo_answers = 0;
}

static void sdo_after_frame(const struct can_frame *rx)
{
	enum co_nmt_state st = co_nmt_get_state(&n.node);
	bool live = st == CO_NMT_PRE_OPERATIONAL || st == CO_NMT_OPERATIONAL;
	uint8_t ccs = rx->data[0] >> 5;

	if (rx->id == 0x600U + DUT && (rx->flags & CAN_FRAME_RTR) == 0U) {
		if (n.sdo_answers > 1U && !n.sdo_block && ccs != 5U) {
			fz_fail("%u answers to one SDO request %02Xh", n.sdo_answers, rx->data[0]);
		}
		/* An initiate request to an idle server is always answered (data or abort). */
		if (n.sdo_answers == 0U && live && n.sdo_idle && rx->dlc == 8U &&
		    (ccs == 1U || ccs == 2U)) {
			fz_fail("SDO request %02Xh %02X%02Xh:%02X not answered", rx->data[0],
				rx->data[2], rx->data[1], rx->data[3]);
		}
		if (n.sdo_idle && rx->dlc == 8U) {
			n.sdo_req_cmd = rx->data[0];
			n.sdo_block = ccs == 5U || ccs == 6U;
		}
		if (n.sdo_answers > 0U && n.sdo_idle) {
			n.sdo_block = false;
		}
	}
	if (!live) {
		n.sdo_idle = true;
		n.sdo_block = false;
	}
	n.sdo_answers = 0;
}

/* --- The harnesses ------------------------------------------------------------------------ */

static const struct cfg cfg_nmt[] = {
	{0x1017, 0, 2, 100},
};

static void setup_nmt(const uint8_t **data, size_t *size)
{
	node_up(cfg_nmt, ARRAY_SIZE(cfg_nmt), data, size);
}

static const uint32_t ids_nmt[] = {0x000,         0x000, 0x000,         0x000,
				   FZ_REL(0x600), 0x080, FZ_REL(0x700), 0x701};

const struct fz_harness fz_nmt = {
	.name = "nmt",
	.what = "NMT commands to a slave (heartbeat producer)",
	.setup = setup_nmt,
	.ids = ids_nmt,
	.n_ids = ARRAY_SIZE(ids_nmt),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

/* Heartbeat consumer of 10h (200 ms) and 11h (50 ms); guarding 100 ms × 3; 1029h:01 = 0. */
static const struct cfg cfg_hb[] = {
	{0x1016, 1, 4, 0x001000C8},
	{0x1016, 2, 4, 0x00110032},
	{0x100C, 0, 2, 100},
	{0x100D, 0, 1, 3},
};

static void setup_errctl(const uint8_t **data, size_t *size)
{
	node_up(cfg_hb, ARRAY_SIZE(cfg_hb), data, size);
}

static const uint32_t ids_errctl[] = {0x710,         0x711, 0x710, 0x711,
				      FZ_REL(0x700), 0x712, 0x000, FZ_REL(0x600)};

const struct fz_harness fz_errctl = {
	.name = "errctl",
	.what = "heartbeat consumer, node and life guarding",
	.setup = setup_errctl,
	.ids = ids_errctl,
	.n_ids = ARRAY_SIZE(ids_errctl),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

static void setup_sdo(const uint8_t **data, size_t *size)
{
	node_up(NULL, 0, data, size);
}

static const uint32_t ids_sdo[] = {FZ_REL(0x600), FZ_REL(0x600), FZ_REL(0x600), FZ_REL(0x600),
				   FZ_REL(0x600), FZ_REL(0x600), FZ_REL(0x600), 0x000};

const struct fz_harness fz_sdo_server = {
	.name = "sdo_server",
	.what = "SDO server: expedited, segmented, block, aborts, timeouts",
	.setup = setup_sdo,
	.ids = ids_sdo,
	.n_ids = ARRAY_SIZE(ids_sdo),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

/* SYNC consumer with a 1006h window, so synchronous PDOs run; TPDOs and RPDOs from the EDS. */
static const struct cfg cfg_pdo[] = {
	{0x1006, 0, 4, 10000},
	{0x1007, 0, 4, 5000},
};

/* Variant bit 0: RPDO 2/3 and TPDO 2/3 as MPDOs (DAM on 321h/2A1h, SAM on 322h/2A2h). */
#define MPDO(comm, map, cob, type, mode)                                                           \
	{comm, 1, 4, 0x80000000U | (cob)}, {comm, 2, 1, type}, {map, 0, 1, 0}, {map, 0, 1, mode},  \
	{                                                                                          \
		comm, 1, 4, cob                                                                    \
	}
static const struct cfg cfg_mpdo[] = {
	{0x1006, 0, 4, 10000},
	MPDO(0x1401, 0x1601, 0x321, 255, CO_MPDO_DAM),
	MPDO(0x1402, 0x1602, 0x322, 254, CO_MPDO_SAM),
	MPDO(0x1801, 0x1A01, 0x2A1, 255, CO_MPDO_DAM),
	MPDO(0x1802, 0x1A02, 0x2A2, 254, CO_MPDO_SAM),
};

static void setup_pdo(const uint8_t **data, size_t *size)
{
	if (*size > 0U && ((*data)[0] & 1U) != 0U) {
		node_up(cfg_mpdo, ARRAY_SIZE(cfg_mpdo), data, size);
	} else {
		node_up(cfg_pdo, ARRAY_SIZE(cfg_pdo), data, size);
	}
}

static const uint32_t ids_pdo[] = {FZ_REL(0x200), FZ_REL(0x300), FZ_REL(0x400), FZ_REL(0x500),
				   FZ_REL(0x180), FZ_REL(0x280), 0x080,         0x000,
				   FZ_REL(0x600), 0x321,         0x322,         0x2A1};

const struct fz_harness fz_pdo = {
	.name = "pdo",
	.what = "RPDOs, RTR on TPDOs, SYNC-driven PDOs; DAM and SAM MPDOs (variant bit 0)",
	.setup = setup_pdo,
	.ids = ids_pdo,
	.n_ids = ARRAY_SIZE(ids_pdo),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

/* Variant bit 0: SYNC producer (10 ms, counter overflow 4); else a consumer. */
static const struct cfg cfg_sync_prod[] = {
	{0x1006, 0, 4, 10000},
	{0x1019, 0, 1, 4},
	{0x1005, 0, 4, 0x40000080},
};
static const struct cfg cfg_sync_cons[] = {
	{0x1006, 0, 4, 10000},
	{0x1007, 0, 4, 2000},
	{0x1019, 0, 1, 4},
};

static void setup_sync(const uint8_t **data, size_t *size)
{
	if (*size > 0U && ((*data)[0] & 1U) != 0U) {
		node_up(cfg_sync_prod, ARRAY_SIZE(cfg_sync_prod), data, size);
	} else {
		node_up(cfg_sync_cons, ARRAY_SIZE(cfg_sync_cons), data, size);
	}
}

static const uint32_t ids_sync[] = {0x080, 0x080, 0x080, 0x000, FZ_REL(0x600), 0x081};

const struct fz_harness fz_sync = {
	.name = "sync",
	.what = "SYNC consumer and producer (counter, window, 1005h/1006h/1019h)",
	.setup = setup_sync,
	.ids = ids_sync,
	.n_ids = ARRAY_SIZE(ids_sync),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

static const struct cfg cfg_time_prod[] = {
	{0x1012, 0, 4, 0x40000100},
};
static const struct cfg cfg_time_cons[] = {
	{0x1012, 0, 4, 0x80000100},
};

static void setup_time(const uint8_t **data, size_t *size)
{
	if (*size > 0U && ((*data)[0] & 1U) != 0U) {
		node_up(cfg_time_prod, ARRAY_SIZE(cfg_time_prod), data, size);
	} else {
		node_up(cfg_time_cons, ARRAY_SIZE(cfg_time_cons), data, size);
	}
}

static const uint32_t ids_time[] = {0x100, 0x100, 0x100, 0x000, FZ_REL(0x600), 0x101};

const struct fz_harness fz_time = {
	.name = "time",
	.what = "TIME consumer and producer (1012h)",
	.setup = setup_time,
	.ids = ids_time,
	.n_ids = ARRAY_SIZE(ids_time),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};

/* EMCY consumer of nodes 10h and 11h. */
static const struct cfg cfg_emcy[] = {
	{0x1028, 1, 4, 0x00000090},
	{0x1028, 2, 4, 0x00000091},
};

static void setup_emcy(const uint8_t **data, size_t *size)
{
	node_up(cfg_emcy, ARRAY_SIZE(cfg_emcy), data, size);
}

static const uint32_t ids_emcy[] = {0x090, 0x091, 0x090, 0x091, 0x000, FZ_REL(0x600), 0x092};

const struct fz_harness fz_emcy = {
	.name = "emcy",
	.what = "EMCY consumer (1028h) and the node's own EMCY",
	.setup = setup_emcy,
	.ids = ids_emcy,
	.n_ids = ARRAY_SIZE(ids_emcy),
	.on_tx = sdo_on_tx,
	.after_time = sdo_after_time,
	.after_frame = sdo_after_frame,
};
