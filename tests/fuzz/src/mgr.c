/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The NMT master's CiA 302-2 boot-up against fuzzed slave answers. The master is node 01h
 * (tests/canopen/mgr/objdict/mgr_master.eds) with slaves 02h..04h; the first two input bytes
 * pick the configuration:
 *
 *   byte 0  1F80h = 01h | (byte & 56h) (start all, no self start, reset node, stop on error)
 *   byte 1  1F81h:02 = 05h | (byte & F8h) (mandatory, keep-alive, software, restore),
 *           bit 0 guarding 100 ms × 3; bit 1: 1F89h = 500 ms; bit 2: slave 04h mandatory
 *
 * The records are the slaves' answers (SDO with the request's multiplexor, boot-up,
 * heartbeat, guarding replies) and NMT commands or SDO requests to the master. Then the input
 * ends: a master left Stopped is started (000#0101), and well-behaved slaves answer for 30 s.
 * Invariant: the startup has ended (done or halted) by then, with an indication.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>

#include <canopen/mgr.h>
#include <canopen/od.h>
#include <canopen/sdo_abort.h>

#include "fuzz.h"
#include "fuzz_master_od.h"

#define MASTER   0x01U
#define N_SLAVES 3U
#define MAX_PEND 64U
#define LATENCY  200ULL

struct cfg {
	uint16_t index;
	uint8_t sub;
	uint32_t value;
};

static struct {
	struct co_node node;
	struct fuzz_master_od_ram ram;
	struct cfg cfg[8];
	size_t n_cfg;
	unsigned int n_startup_ind;
	enum co_mgr_startup result;
	/* The well-behaved slaves of the end phase. */
	bool fakes_on;
	uint8_t state[N_SLAVES];
	uint8_t toggle[N_SLAVES];
	struct can_frame pend[MAX_PEND];
	uint64_t pend_at[MAX_PEND];
	size_t n_pend;
} m;

static void restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (size_t i = 0; i < m.n_cfg; i++) {
		uint8_t buf[4];

		sys_put_le32(m.cfg[i].value, buf);
		if (co_od_write(od, m.cfg[i].index, m.cfg[i].sub, buf, 4, CO_OD_WRITER_STORAGE) !=
		    0U) {
			fz_fail("configuration %04Xh:%02X = %08Xh refused", m.cfg[i].index,
				m.cfg[i].sub, m.cfg[i].value);
		}
	}
}

static void startup_ind(struct co_node *node, enum co_mgr_startup result,
			const struct co_mgr_boot_error *err, void *user_data)
{
	m.n_startup_ind++;
	m.result = result;
}

static void cfg(uint16_t index, uint8_t sub, uint32_t value)
{
	m.cfg[m.n_cfg++] = (struct cfg){index, sub, value};
}

static void setup(const uint8_t **data, size_t *size)
{
	uint8_t v0 = 0;
	uint8_t v1 = 0;
	uint32_t s2;

	memset(&m, 0, sizeof(m));
	if (*size >= 2U) {
		v0 = (*data)[0];
		v1 = (*data)[1];
		*data += 2;
		*size -= 2;
	}
	cfg(0x1F80, 0, 0x01U | (v0 & 0x56U));
	s2 = 0x05U | (v1 & 0xF8U);
	if ((v1 & 1U) != 0U) {
		s2 |= 0x00640300U; /* guard time 100 ms, retry factor 3 */
	}
	cfg(0x1F81, 2, s2);
	cfg(0x1F81, 3, 0x05);
	cfg(0x1F81, 4, (v1 & 4U) != 0U ? 0x0DU : 0x05U);
	if ((v1 & 2U) != 0U) {
		cfg(0x1F89, 0, 500);
	}
	if (co_node_init(&m.node, "master", &fz.line, &fuzz_master_od_def, &m.ram, MASTER) != 0) {
		fz_fail("co_node_init");
	}
	co_od_set_restore_cb(co_node_od(&m.node), restore, NULL);
	co_mgr_set_startup_ind(&m.node, startup_ind, NULL);
	fz.dut = &m.node;
	fz.dut_id = MASTER;
	if (co_node_start(&m.node) != 0) {
		fz_fail("co_node_start");
	}
}

static bool may_send(const struct can_frame *f)
{
	/* NMT commands, boot SDO requests, guarding RTRs, its own SDO server and heartbeat. */
	return f->id == 0x000U || (f->id >= 0x601U && f->id <= 0x67FU) ||
	       (f->id >= 0x701U && f->id <= 0x77FU) || f->id == 0x581U;
}

/* --- Well-behaved slaves (end phase) ------------------------------------------------------ */

static void pend(uint32_t id, uint8_t dlc, const uint8_t *d)
{
	struct can_frame f = {.id = id, .dlc = dlc};

	if (m.n_pend >= MAX_PEND) {
		return;
	}
	memcpy(f.data, d, dlc);
	m.pend[m.n_pend] = f;
	m.pend_at[m.n_pend] = fz.now + LATENCY;
	m.n_pend++;
}

static uint32_t ident(uint16_t index, uint8_t sub, bool *found)
{
	*found = true;
	if (index == 0x1000U && sub == 0U) {
		return 0x00020192U;
	}
	if (index == 0x1018U && sub >= 1U && sub <= 4U) {
		return sub;
	}
	*found = false;
	return 0;
}

static void fake_sdo(uint8_t id, const struct can_frame *rq)
{
	uint16_t index = sys_get_le16(&rq->data[1]);
	uint8_t sub = rq->data[3];
	uint8_t r[8] = {0x80, rq->data[1], rq->data[2], sub};
	uint8_t ccs = rq->data[0] >> 5;
	bool found;
	uint32_t v = ident(index, sub, &found);

	if (ccs == 4U) {
		return;
	}
	if (ccs == 2U && found) {
		r[0] = 0x43;
		sys_put_le32(v, &r[4]);
	} else if (ccs == 1U) {
		r[0] = 0x60;
	} else {
		sys_put_le32(CO_SDO_AB_NO_OBJECT, &r[4]);
	}
	pend(0x580U + id, 8, r);
}

static void on_tx(const struct can_frame *f)
{
	if (!m.fakes_on) {
		return;
	}
	if (f->id == 0x000U && f->dlc == 2U) {
		for (uint8_t i = 0; i < N_SLAVES; i++) {
			uint8_t id = 2U + i;
			uint8_t boot = 0;

			if (f->data[1] != 0U && f->data[1] != id) {
				continue;
			}
			switch (f->data[0]) {
			case 0x01:
				m.state[i] = 0x05;
				break;
			case 0x02:
				m.state[i] = 0x04;
				break;
			case 0x81:
			case 0x82:
				m.toggle[i] = 0;
				pend(0x700U + id, 1, &boot);
				m.state[i] = 0x7F;
				break;
			default:
				m.state[i] = 0x7F;
				break;
			}
		}
	} else if (f->id >= 0x602U && f->id < 0x602U + N_SLAVES) {
		fake_sdo((uint8_t)(f->id - 0x600U), f);
	} else if (f->id >= 0x702U && f->id < 0x702U + N_SLAVES &&
		   (f->flags & CAN_FRAME_RTR) != 0U) {
		uint8_t i = (uint8_t)(f->id - 0x702U);
		uint8_t b = m.state[i] | m.toggle[i];

		m.toggle[i] ^= 0x80U;
		pend(f->id, 1, &b);
	}
}

static void finish(void)
{
	const uint8_t start[2] = {0x01, MASTER};
	uint64_t end;

	for (uint8_t i = 0; i < N_SLAVES; i++) {
		m.state[i] = 0x7F;
	}
	m.fakes_on = true;
	if (co_nmt_get_state(&m.node) == CO_NMT_STOPPED) {
		struct can_frame f = {.id = 0x000, .dlc = 2};

		memcpy(f.data, start, 2);
		fz_rx(&f);
	}
	end = fz.now + 30000ULL * FZ_MS;
	while (fz.now < end) {
		/* Event by event: the next deadline of the line or the next answer due. */
		uint64_t next = co_line_next_deadline(&fz.line);
		size_t k = 0;

		for (size_t i = 0; i < m.n_pend; i++) {
			next = MIN(next, m.pend_at[i]);
		}
		fz_run_until(MAX(MIN(next, end), fz.now));
		/* Deliver what is due; answers queued meanwhile are appended and kept. */
		for (size_t i = 0; i < m.n_pend; i++) {
			if (m.pend_at[i] <= fz.now) {
				struct can_frame f = m.pend[i];

				fz_rx(&f);
			} else {
				m.pend[k] = m.pend[i];
				m.pend_at[k] = m.pend_at[i];
				k++;
			}
		}
		m.n_pend = k;
	}
	if (getenv("SAFELINE_FUZZ_TRACE") != NULL) {
		printf("startup %d after %u indications, master %s\n", co_mgr_get_startup(&m.node),
		       m.n_startup_ind, co_nmt_state_str(co_nmt_get_state(&m.node)));
	}
	if (co_mgr_get_startup(&m.node) == CO_MGR_STARTUP_RUNNING) {
		fz_fail("the NMT startup still runs 30 s after the input (master %s, %u "
			"indications)",
			co_nmt_state_str(co_nmt_get_state(&m.node)), m.n_startup_ind);
	}
}

static const uint32_t ids[] = {0x582, 0x583, 0x584, 0x582, 0x583, 0x584,
			       0x702, 0x703, 0x704, 0x000, 0x601, 0x081};

const struct fz_harness fz_mgr = {
	.name = "mgr",
	.what = "NMT master boot-up (CiA 302-2) against fuzzed slave answers",
	.setup = setup,
	.ids = ids,
	.n_ids = ARRAY_SIZE(ids),
	.may_send = may_send,
	.on_tx = on_tx,
	.finish = finish,
};
