/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT master and the CiA 302-2 boot-up (doc/mgr.md).
 *
 * Structure:
 * - NMT commands go through a FIFO sent at least 102Ah apart; broadcasts "including self"
 *   are applied to our own NMT state once sent (we never receive our own frames).
 * - One masked receiver on 700h..77Fh sees boot-ups, heartbeats and guarding replies of
 *   every slave; the manager times heartbeats itself (from 1016h) because CiA 302-2 §4.1
 *   starts the timeout at once, not at the first heartbeat as the CiA 301 consumer does.
 * - "Boot NMT slave" is a const table of states with handlers for enter, SDO confirmation,
 *   error-control frame and timeout. Each handler returns the next state, WAIT or END.
 * - Each slave slot owns SDO client slot i, so all slaves boot in parallel.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>
#include <canopen/sdo_cli.h>
#if defined(CONFIG_CANOPEN_CFG)
#include <canopen/cfg.h>
#endif

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

BUILD_ASSERT(CONFIG_CANOPEN_SDO_CLIENTS >= CONFIG_CANOPEN_MGR_SLAVES,
	     "every slave slot needs its own SDO client");

#define IDX_DEVTYPE     0x1000U
#define IDX_HB_CONSUMER 0x1016U
#define IDX_IDENTITY    0x1018U
#define IDX_CFG_STAMP   0x1020U
#define IDX_RESTORE     0x1011U
#define IDX_INHIBIT     0x102AU
#define IDX_SW_VERIFY   0x1F52U
#define IDX_SW_DATE     0x1F53U
#define IDX_SW_TIME     0x1F54U
#define IDX_CFG_DATE    0x1F26U
#define IDX_CFG_TIME    0x1F27U
#define IDX_STARTUP     0x1F80U
#define IDX_ASSIGN      0x1F81U
#define IDX_REQ_NMT     0x1F82U
#define IDX_REQ_GUARD   0x1F83U
#define IDX_EXP_DEVTYPE 0x1F84U
#define IDX_EXP_VENDOR  0x1F85U
#define IDX_BOOT_TIME   0x1F89U
#define IDX_RESTORE_SUB 0x1F8AU

/* 1F80h bits. */
#define SU_MASTER     BIT(0)
#define SU_START_ALL  BIT(1)
#define SU_NO_SELF_OP BIT(2)
#define SU_NO_START   BIT(3)
#define SU_RESET_ALL  BIT(4)
#define SU_FLYING     BIT(5)
#define SU_STOP_ALL   BIT(6)
#define SU_SELF_START 0x08U

/* 1F81h bits. */
#define AS_SLAVE      BIT(0)
#define AS_BOOT       BIT(2)
#define AS_MANDATORY  BIT(3)
#define AS_KEEP_ALIVE BIT(4)
#define AS_SW_CHECK   BIT(5)
#define AS_SW_UPDATE  BIT(6)
#define AS_RESTORE    BIT(7)

#define ALL_NODES 0x80U

/* Handler results besides a next step. */
#define NEXT_WAIT 0xfeU
#define NEXT_END  0xfdU

/* Internal startup phases. */
enum {
	PH_NONE,
	PH_BEGIN,
	PH_RESETTING,
	PH_BOOT,
	PH_BOOTING,
};

#define MS_US(ms) ((uint64_t)(ms) * 1000U)

/*
 * A slave waiting for a configuration job is started when a download of the manager ends;
 * this poll only covers jobs of others (1F25h) ending.
 */
#define CFG_WAIT_POLL_MS 100U

/* "load" (CiA 301 1011h) on the wire. */
static const uint8_t sig_load[4] = {'l', 'o', 'a', 'd'};

/* --- Helpers -------------------------------------------------------------------------------- */

static struct co_mgr_slave *slave_of_timer(struct co_timer *t)
{
	return t->user_data;
}

static uint64_t now_of(struct co_mgr *m)
{
	return co_line_time(m->node->line);
}

static uint32_t od_u32(struct co_mgr *m, uint16_t index, uint8_t sub)
{
	uint8_t buf[8] = {0};
	size_t len = 0;

	if (co_od_read(&m->node->od, index, sub, 0, buf, sizeof(buf), &len, CO_OD_WRITER_APP) !=
	    0U) {
		return 0U;
	}
	return (uint32_t)co_od_le_get(buf, len == 0U ? 1U : len);
}

static uint32_t startup_obj(struct co_mgr *m)
{
	return od_u32(m, IDX_STARTUP, 0);
}

static uint32_t assign_of(struct co_mgr *m, uint8_t id)
{
	return od_u32(m, IDX_ASSIGN, id);
}

/* Consumer time [ms] for @p id in our 1016h, 0 if none. */
static uint16_t hb_time_of(struct co_mgr *m, uint8_t id)
{
	uint8_t n = (uint8_t)od_u32(m, IDX_HB_CONSUMER, 0);

	for (uint8_t s = 1; s <= n && s != 0U; s++) {
		uint32_t v = od_u32(m, IDX_HB_CONSUMER, s);

		if ((uint8_t)(v >> 16) == id && (v & 0xffffU) != 0U) {
			return (uint16_t)v;
		}
	}
	return 0U;
}

static struct co_sdo_cli *cli_of(struct co_mgr_slave *s)
{
	return &s->mgr->node->sdo_cli[s->slot];
}

static struct co_mgr_slave *slot_find(struct co_mgr *m, uint8_t id)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		if (m->slaves[i].id == id && id != 0U) {
			return &m->slaves[i];
		}
	}
	return NULL;
}

static struct co_mgr_slave *slot_get(struct co_mgr *m, uint8_t id)
{
	struct co_mgr_slave *s = slot_find(m, id);

	if (s != NULL) {
		return s;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		s = &m->slaves[i];
		if (s->id == 0U) {
			s->id = id;
			s->status = CO_MGR_ST_NONE;
			s->last_status = CO_MGR_ST_NONE;
			s->last_read_mask = 0U;
			memset(s->last_ident, 0, sizeof(s->last_ident));
			memset(&s->last_err, 0, sizeof(s->last_err));
			s->nmt_state = 0U;
			s->rep_state = 0U;
			return s;
		}
	}
	LOG_ERR("%s: no slave slot for node %u (CONFIG_CANOPEN_MGR_SLAVES)", m->node->name, id);
	return NULL;
}

/* Keep the 1F82h read value (the master's view of the slave's state) up to date. */
static void set_nmt_view(struct co_mgr_slave *s, uint8_t v)
{
	struct co_mgr *m = s->mgr;

	s->nmt_state = v;
	m->od_update = true;
	(void)co_od_write(&m->node->od, IDX_REQ_NMT, s->id, &v, 1, CO_OD_WRITER_APP);
	m->od_update = false;
}

static void ec_indicate(struct co_mgr *m, uint8_t id, enum co_mgr_ec_event ev, uint8_t state)
{
	if (m->ec_ind != NULL) {
		m->ec_ind(m->node, id, ev, (enum co_nmt_state)state, m->ec_user_data);
	}
}

/* --- NMT command queue (102Ah) ------------------------------------------------------------- */

static bool cs_valid(uint8_t cs)
{
	return cs == CO_NMT_CS_START || cs == CO_NMT_CS_STOP ||
	       cs == CO_NMT_CS_ENTER_PRE_OPERATIONAL || cs == CO_NMT_CS_RESET_NODE ||
	       cs == CO_NMT_CS_RESET_COMMUNICATION;
}

static void startup_resets_sent(struct co_mgr *m);
static void set_nmt_view(struct co_mgr_slave *s, uint8_t v);

/* The state a command leaves its targets in, until their heartbeat says otherwise. */
static void nmt_expect(struct co_mgr *m, uint8_t cs, uint8_t id)
{
	uint8_t v;

	switch (cs) {
	case CO_NMT_CS_START:
		v = CO_NMT_OPERATIONAL;
		break;
	case CO_NMT_CS_STOP:
		v = CO_NMT_STOPPED;
		break;
	case CO_NMT_CS_ENTER_PRE_OPERATIONAL:
		v = CO_NMT_PRE_OPERATIONAL;
		break;
	default:
		v = 0U; /* reset: unknown until the boot-up */
		break;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (id == 0U || id == s->id) && !s->ec_lost) {
			set_nmt_view(s, v);
		}
	}
}

static void nmt_kick(struct co_mgr *m)
{
	struct co_node *node = m->node;
	uint64_t now = now_of(m);
	uint64_t inhibit_us = (uint64_t)(uint16_t)od_u32(m, IDX_INHIBIT, 0) * 100U;

	while (m->nmt_count > 0U) {
		struct co_mgr_nmt_cmd cmd = m->nmtq[m->nmt_head];
		struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2U};

		if (inhibit_us != 0U && !co_time_before_eq(m->nmt_next_us, now)) {
			co_timer_start(node->line, &m->nmt_timer, m->nmt_next_us);
			return;
		}
		if (co_line_tx_space(node->line) <= 0) {
			/* Never drop a command: wait for the queue to drain. */
			co_timer_start(node->line, &m->nmt_timer, now + MS_US(1));
			return;
		}
		m->nmt_head = (uint16_t)((m->nmt_head + 1U) % CONFIG_CANOPEN_MGR_NMT_QUEUE);
		m->nmt_count--;
		f.data[0] = cmd.cs;
		f.data[1] = cmd.id;
		(void)co_node_send(node, &f);
		m->nmt_next_us = now + inhibit_us;
		nmt_expect(m, cmd.cs, cmd.id);
		if (cmd.self) {
			/* May reset us (the queue with it): nothing of ours is valid afterwards. */
			(void)co_nmt_req(node, (enum co_nmt_cs)cmd.cs);
			if (cmd.cs == CO_NMT_CS_RESET_NODE ||
			    cmd.cs == CO_NMT_CS_RESET_COMMUNICATION) {
				return;
			}
		}
	}
	if (m->phase == PH_RESETTING) {
		startup_resets_sent(m);
	}
}

static int nmt_queue(struct co_mgr *m, uint8_t cs, uint8_t id, bool self)
{
	uint16_t tail;

	if (m->nmt_count >= CONFIG_CANOPEN_MGR_NMT_QUEUE) {
		LOG_ERR("%s: NMT queue full", m->node->name);
		return -ENOSPC;
	}
	tail = (uint16_t)((m->nmt_head + m->nmt_count) % CONFIG_CANOPEN_MGR_NMT_QUEUE);
	m->nmtq[tail] = (struct co_mgr_nmt_cmd){.cs = cs, .id = id, .self = self};
	m->nmt_count++;
	if (!co_timer_is_armed(&m->nmt_timer)) {
		nmt_kick(m);
	}
	return 0;
}

static void nmt_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	nmt_kick(timer->user_data);
}

/* --- Error control of the slaves ------------------------------------------------------------ */

static void send_rtr(struct co_mgr_slave *s)
{
	struct can_frame f = {
		.id = CO_NMT_EC_COB_ID + s->id,
		.dlc = 1U,
		.flags = CAN_FRAME_RTR,
	};

	(void)co_node_send(s->mgr->node, &f);
}

static void ec_stop(struct co_mgr_slave *s)
{
	co_timer_stop(&s->ec_timer);
	s->hb_on = false;
	s->guarding = false;
	s->ec_lost = false;
}

static void guard_start(struct co_mgr_slave *s, uint16_t gt_ms, uint8_t rf)
{
	s->guard_ms = gt_ms;
	s->guard_rf = rf;
	s->guard_missed = 0U;
	s->guard_ans = false;
	s->guard_toggle = 0xffU;
	s->guarding = true;
	s->ec_lost = false;
	send_rtr(s);
	co_timer_start(s->mgr->node->line, &s->ec_timer, now_of(s->mgr) + MS_US(gt_ms));
}

static void hb_start(struct co_mgr_slave *s, uint64_t now)
{
	s->hb_on = true;
	s->ec_lost = false;
	co_timer_start(s->mgr->node->line, &s->ec_timer, now + MS_US(s->hb_ms));
}

static void boot_process_start(struct co_mgr_slave *s);

/* CiA 302-2 §4.2 error handler. */
static void error_handler(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;
	uint32_t as = assign_of(m, s->id);
	uint32_t su = startup_obj(m);

	if ((as & AS_SLAVE) == 0U || m->startup == CO_MGR_STARTUP_IDLE) {
		return;
	}
	if ((as & AS_MANDATORY) != 0U) {
		if ((su & SU_STOP_ALL) != 0U) {
			(void)nmt_queue(m, CO_NMT_CS_STOP, 0U, true);
			return;
		}
		if ((su & SU_RESET_ALL) != 0U) {
			(void)nmt_queue(m, CO_NMT_CS_RESET_NODE, 0U, true);
			return;
		}
	}
	if (s->parked) {
		return;
	}
	if ((as & (AS_MANDATORY | AS_BOOT)) != 0U) {
		(void)nmt_queue(m, CO_NMT_CS_RESET_NODE, s->id, false);
		/* The boot-up handler re-boots it; without a boot-up, boot anyway (polls: B). */
		s->wait_reboot = (as & AS_BOOT) != 0U;
		if (s->wait_reboot && !s->booting) {
			co_timer_start(m->node->line, &s->timer,
				       now_of(m) + MS_US(CONFIG_CANOPEN_MGR_BOOTUP_WAIT));
		}
	}
}

static void ec_event(struct co_mgr_slave *s, enum co_mgr_ec_event ev)
{
	struct co_mgr *m = s->mgr;

	if (s->ec_lost) {
		return;
	}
	s->ec_lost = true;
	/* The next report after the loss is a change, whatever it says. */
	s->rep_state = 0U;
	LOG_WRN("%s: node %u %s", m->node->name, s->id,
		ev == CO_MGR_EC_HB_LOST ? "heartbeat lost" : "node guarding lost");
	set_nmt_view(s, 0x01U);
	ec_indicate(m, s->id, ev, 0x01U);
	error_handler(s);
}

static void ec_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr_slave *s = slave_of_timer(timer);

	if (s->hb_on) {
		s->hb_on = false;
		ec_event(s, CO_MGR_EC_HB_LOST);
		return;
	}
	if (!s->guarding) {
		return;
	}
	if (s->guard_ans) {
		s->guard_missed = 0U;
		s->ec_lost = false;
	} else if (s->guard_missed < 0xffU) {
		s->guard_missed++;
	}
	if (s->guard_missed >= s->guard_rf) {
		ec_event(s, CO_MGR_EC_GUARD_LOST);
		if (!s->guarding) {
			return;
		}
	}
	s->guard_ans = false;
	send_rtr(s);
	co_timer_start(s->mgr->node->line, &s->ec_timer, now_us + MS_US(s->guard_ms));
}

/* --- Boot NMT slave: the state table ------------------------------------------------------- */

struct boot_state {
	const char *name;
	uint8_t (*enter)(struct co_mgr_slave *s);
	uint8_t (*sdo)(struct co_mgr_slave *s, uint32_t abort_code);
	uint8_t (*ec)(struct co_mgr_slave *s, uint8_t byte);
	uint8_t (*timeout)(struct co_mgr_slave *s);
};

static const struct boot_state boot_table[CO_MGR_STEP_COUNT];

static uint8_t fail(struct co_mgr_slave *s, uint8_t status, uint16_t index, uint8_t sub,
		    uint32_t expected, uint32_t actual, uint32_t abort_code)
{
	s->status = status;
	s->err = (struct co_mgr_boot_error){
		.node_id = s->id,
		.status = status,
		.step = (enum co_mgr_step)s->step,
		.index = index,
		.sub = sub,
		.expected = expected,
		.actual = actual,
		.abort_code = abort_code,
	};
	return NEXT_END;
}

static void sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data);
static void boot_run(struct co_mgr_slave *s, uint8_t next);

static uint32_t buf_u32(struct co_mgr_slave *s)
{
	return (uint32_t)co_od_le_get(s->buf, sizeof(s->buf));
}

/* Start an upload of the slave's index:sub into s->buf; on refusal run the step's handler. */
static uint8_t upload(struct co_mgr_slave *s, uint16_t index, uint8_t sub)
{
	int err;

	memset(s->buf, 0, sizeof(s->buf));
	s->sdo_pending = true;
	err = co_sdo_cli_upload_req(cli_of(s), index, sub, s->buf, sizeof(s->buf), CO_SDO_CLI_AUTO,
				    CONFIG_CANOPEN_MGR_SDO_TIMEOUT, sdo_con, s);
	if (err != 0) {
		s->sdo_pending = false;
		return boot_table[s->step].sdo(s, CO_SDO_AB_GENERAL);
	}
	return NEXT_WAIT;
}

static uint8_t download(struct co_mgr_slave *s, uint16_t index, uint8_t sub, const void *data,
			size_t len)
{
	int err;

	s->sdo_pending = true;
	err = co_sdo_cli_download_req(cli_of(s), index, sub, data, len, CO_SDO_CLI_AUTO,
				      CONFIG_CANOPEN_MGR_SDO_TIMEOUT, sdo_con, s);
	if (err != 0) {
		s->sdo_pending = false;
		return boot_table[s->step].sdo(s, CO_SDO_AB_GENERAL);
	}
	return NEXT_WAIT;
}

static void arm(struct co_mgr_slave *s, uint32_t ms)
{
	co_timer_start(s->mgr->node->line, &s->timer, now_of(s->mgr) + MS_US(ms));
}

/* a: 1F81h bit 0. */
static uint8_t st_assigned(struct co_mgr_slave *s)
{
	uint32_t as = assign_of(s->mgr, s->id);

	if ((as & AS_SLAVE) == 0U) {
		return fail(s, CO_MGR_ST_A, IDX_ASSIGN, s->id, AS_SLAVE, as, 0U);
	}
	return CO_MGR_STEP_BOOT_ALLOWED;
}

/* b: 1F81h bit 2 = 0: error control only, no checks, no start (302-2 §3.4 b, §10 #13). */
static uint8_t st_boot_allowed(struct co_mgr_slave *s)
{
	s->was_operational = false;
	s->no_start = (assign_of(s->mgr, s->id) & AS_BOOT) == 0U;
	return s->no_start ? CO_MGR_STEP_START_EC : CO_MGR_STEP_DEVTYPE;
}

/* c, d: 1000h is always read (presence check), compared when 1F84h is not 0. */
static uint8_t st_devtype(struct co_mgr_slave *s)
{
	return upload(s, IDX_DEVTYPE, 0);
}

static uint8_t st_devtype_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint32_t exp = od_u32(s->mgr, IDX_EXP_DEVTYPE, s->id);
	uint32_t act = buf_u32(s);

	if (ab != 0U) {
		return fail(s, CO_MGR_ST_B, IDX_DEVTYPE, 0, exp, 0U, ab);
	}
	s->ident[0] = act;
	s->read_mask |= BIT(0);
	if (exp != 0U && exp != act) {
		return fail(s, CO_MGR_ST_C, IDX_DEVTYPE, 0, exp, act, 0U);
	}
	return CO_MGR_STEP_VENDOR;
}

/* e1..e4: 1018h:01..04 against 1F85h..1F88h, read only when expected is not 0. */
static const uint8_t ident_letter[4] = {CO_MGR_ST_D, CO_MGR_ST_M, CO_MGR_ST_N, CO_MGR_ST_O};

static uint8_t ident_k(struct co_mgr_slave *s)
{
	return (uint8_t)(s->step - CO_MGR_STEP_VENDOR);
}

static uint8_t st_ident(struct co_mgr_slave *s)
{
	uint8_t k = ident_k(s);

	if (od_u32(s->mgr, (uint16_t)(IDX_EXP_VENDOR + k), s->id) == 0U) {
		return (uint8_t)(s->step + 1U);
	}
	return upload(s, IDX_IDENTITY, (uint8_t)(k + 1U));
}

/* 302-2 §6.9: same major revision, minor at least the expected one. */
static bool revision_fits(uint32_t exp, uint32_t act)
{
	return (exp >> 16) == (act >> 16) && (act & 0xffffU) >= (exp & 0xffffU);
}

static uint8_t st_ident_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint8_t k = ident_k(s);
	uint32_t exp = od_u32(s->mgr, (uint16_t)(IDX_EXP_VENDOR + k), s->id);
	uint32_t act = buf_u32(s);
	bool ok;

	if (ab != 0U) {
		/* An abort counts as a mismatch. */
		return fail(s, ident_letter[k], IDX_IDENTITY, (uint8_t)(k + 1U), exp, 0U, ab);
	}
	s->ident[k + 1U] = act;
	s->read_mask |= BIT(k + 1U);
	ok = k == 2U ? revision_fits(exp, act) : exp == act;
	if (!ok) {
		return fail(s, ident_letter[k], IDX_IDENTITY, (uint8_t)(k + 1U), exp, act, 0U);
	}
	return (uint8_t)(s->step + 1U);
}

/* Part 2 a: keep-alive; check NMT state (302-2 §3.6). */
static uint8_t st_keep_alive(struct co_mgr_slave *s)
{
	uint16_t hb;

	if ((assign_of(s->mgr, s->id) & AS_KEEP_ALIVE) == 0U) {
		return CO_MGR_STEP_SW_DATE;
	}
	hb = hb_time_of(s->mgr, s->id);
	if (hb != 0U) {
		arm(s, hb);
	} else {
		send_rtr(s);
		arm(s, CONFIG_CANOPEN_MGR_GUARD_CHECK_TIME);
	}
	return NEXT_WAIT;
}

static uint8_t st_keep_alive_ec(struct co_mgr_slave *s, uint8_t byte)
{
	co_timer_stop(&s->timer);
	if ((byte & 0x7fU) == CO_NMT_OPERATIONAL) {
		/* Never reset an Operational keep-alive slave: skip SW and configuration. */
		s->was_operational = true;
		return CO_MGR_STEP_START_EC;
	}
	(void)nmt_queue(s->mgr, CO_NMT_CS_RESET_COMMUNICATION, s->id, false);
	return CO_MGR_STEP_KEEP_ALIVE_RESET;
}

static uint8_t st_keep_alive_to(struct co_mgr_slave *s)
{
	uint16_t hb = hb_time_of(s->mgr, s->id);

	if (hb != 0U) {
		return fail(s, CO_MGR_ST_E, IDX_HB_CONSUMER, 0, hb, 0U, 0U);
	}
	return fail(s, CO_MGR_ST_F, IDX_ASSIGN, s->id, CONFIG_CANOPEN_MGR_GUARD_CHECK_TIME, 0U, 0U);
}

/* Wait for the boot-up after our reset; heartbeats before it are the old life. */
static uint8_t st_wait_bootup(struct co_mgr_slave *s)
{
	arm(s, CONFIG_CANOPEN_MGR_BOOTUP_WAIT);
	return NEXT_WAIT;
}

static uint8_t st_ka_reset_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (byte != 0U) {
		return NEXT_WAIT;
	}
	co_timer_stop(&s->timer);
	return CO_MGR_STEP_SW_DATE;
}

static uint8_t st_ka_reset_to(struct co_mgr_slave *s)
{
	/* No boot-up seen: go on, the next SDO transfer tells whether it is there. */
	return CO_MGR_STEP_SW_DATE;
}

/* Part 2 b: software version 1F52h against 1F53h/1F54h. */
static uint8_t st_sw_date(struct co_mgr_slave *s)
{
	uint32_t d;
	uint32_t t;

	if ((assign_of(s->mgr, s->id) & AS_SW_CHECK) == 0U) {
		return CO_MGR_STEP_CFG_DATE;
	}
	d = od_u32(s->mgr, IDX_SW_DATE, s->id);
	t = od_u32(s->mgr, IDX_SW_TIME, s->id);
	if (d == 0U || t == 0U) {
		return fail(s, CO_MGR_ST_G, d == 0U ? IDX_SW_DATE : IDX_SW_TIME, s->id, 1U, 0U, 0U);
	}
	return upload(s, IDX_SW_VERIFY, 1);
}

static uint8_t st_sw_date_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return fail(s, CO_MGR_ST_G, IDX_SW_VERIFY, 1, od_u32(s->mgr, IDX_SW_DATE, s->id),
			    0U, ab);
	}
	s->sw_date = buf_u32(s);
	return CO_MGR_STEP_SW_TIME;
}

static uint8_t st_sw_time(struct co_mgr_slave *s)
{
	return upload(s, IDX_SW_VERIFY, 2);
}

static uint8_t st_sw_time_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	struct co_mgr *m = s->mgr;
	uint32_t ed = od_u32(m, IDX_SW_DATE, s->id);
	uint32_t et = od_u32(m, IDX_SW_TIME, s->id);
	uint32_t at = buf_u32(s);
	bool date_ok = ed == s->sw_date;

	if (ab != 0U) {
		return fail(s, CO_MGR_ST_G, IDX_SW_VERIFY, 2, et, 0U, ab);
	}
	if (date_ok && et == at) {
		return CO_MGR_STEP_CFG_DATE;
	}
	if ((assign_of(m, s->id) & AS_SW_UPDATE) == 0U) {
		return fail(s, CO_MGR_ST_H, IDX_SW_VERIFY, date_ok ? 2 : 1, date_ok ? et : ed,
			    date_ok ? at : s->sw_date, 0U);
	}
	if (m->sw_ind == NULL ||
	    m->sw_ind(m->node, s->id, ed, et, s->sw_date, at, m->sw_user_data) != 0) {
		return fail(s, CO_MGR_ST_I, IDX_SW_VERIFY, date_ok ? 2 : 1, date_ok ? et : ed,
			    date_ok ? at : s->sw_date, 0U);
	}
	return CO_MGR_STEP_CFG_DATE;
}

/* Part 3 c: 1020h against 1F26h/1F27h; verify only when both are set (§10 #14). */
static void cfg_expected(struct co_mgr_slave *s, uint32_t *date, uint32_t *time)
{
	*date = od_u32(s->mgr, IDX_CFG_DATE, s->id);
	*time = od_u32(s->mgr, IDX_CFG_TIME, s->id);
#if defined(CONFIG_CANOPEN_CFG)
	struct co_cfg *cfg = co_cfg_get(s->mgr->node);

	if (cfg != NULL) {
		(void)co_cfg_get_expected(cfg, s->id, date, time);
	}
#endif
}

static uint8_t st_cfg_date(struct co_mgr_slave *s)
{
	uint32_t d;
	uint32_t t;

	cfg_expected(s, &d, &t);
	if (d == 0U || t == 0U) {
		return CO_MGR_STEP_RESTORE;
	}
	return upload(s, IDX_CFG_STAMP, 1);
}

static uint8_t st_cfg_date_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return CO_MGR_STEP_RESTORE;
	}
	s->cfg_date = buf_u32(s);
	return CO_MGR_STEP_CFG_TIME;
}

static uint8_t st_cfg_time(struct co_mgr_slave *s)
{
	return upload(s, IDX_CFG_STAMP, 2);
}

static uint8_t st_cfg_time_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint32_t d;
	uint32_t t;

	cfg_expected(s, &d, &t);
	if (ab == 0U && d == s->cfg_date && t == buf_u32(s)) {
		return CO_MGR_STEP_START_EC;
	}
	return CO_MGR_STEP_RESTORE;
}

/* 302-2 §3.5 d: restore (1011h:1F8Ah[n] = "load"), then reset, then configure. */
static uint8_t restore_sub(struct co_mgr_slave *s)
{
	if ((assign_of(s->mgr, s->id) & AS_RESTORE) == 0U) {
		return 0U;
	}
	return (uint8_t)od_u32(s->mgr, IDX_RESTORE_SUB, s->id);
}

static uint8_t st_restore(struct co_mgr_slave *s)
{
	uint8_t sub = restore_sub(s);

	if (sub == 0U) {
		return CO_MGR_STEP_DOWNLOAD;
	}
	memcpy(s->load, sig_load, sizeof(s->load));
	return download(s, IDX_RESTORE, sub, s->load, sizeof(s->load));
}

static uint8_t st_restore_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint8_t sub = restore_sub(s);

	if (ab != 0U) {
		return fail(s, CO_MGR_ST_J, IDX_RESTORE, sub, 0x64616f6cU, 0U, ab);
	}
	/* Sub 2 restores communication parameters only: Reset Communication suffices. */
	(void)nmt_queue(s->mgr, sub == 2U ? CO_NMT_CS_RESET_COMMUNICATION : CO_NMT_CS_RESET_NODE,
			s->id, false);
	return CO_MGR_STEP_RESTORE_RESET;
}

static uint8_t st_restore_reset_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (byte != 0U) {
		return NEXT_WAIT;
	}
	co_timer_stop(&s->timer);
	return CO_MGR_STEP_DOWNLOAD;
}

static uint8_t st_restore_reset_to(struct co_mgr_slave *s)
{
	return fail(s, CO_MGR_ST_J, IDX_RESTORE, restore_sub(s), 0U, 0U, CO_SDO_AB_TIMEOUT);
}

/* Concise DCF through the configuration manager; nothing stored = nothing to do. */
#if defined(CONFIG_CANOPEN_CFG)
static void cfg_kick(struct co_mgr *m);

static void cfg_con(struct co_node *node, uint8_t id, uint32_t abort_code, uint16_t index,
		    uint8_t sub, void *user_data)
{
	struct co_mgr_slave *s = user_data;

	s->err.index = index;
	s->err.sub = sub;
	sdo_con(cli_of(s), abort_code, 0, s);
	/* A job slot is free now: hand it to the slave that waits longest. */
	cfg_kick(s->mgr);
}
#endif

static uint8_t st_download(struct co_mgr_slave *s)
{
#if defined(CONFIG_CANOPEN_CFG)
	struct co_cfg *cfg = co_cfg_get(s->mgr->node);
	int err;

	if (cfg == NULL) {
		return CO_MGR_STEP_START_EC;
	}
	if (!s->cfg_wait) {
		s->cfg_ticket = s->mgr->cfg_tickets++;
	}
	s->cfg_wait = false;
	s->sdo_pending = true;
	err = co_cfg_download_req(cfg, cli_of(s), s->id, cfg_con, s);
	if (err == -ENOENT) {
		s->sdo_pending = false;
		return CO_MGR_STEP_START_EC;
	}
	if (err == -EBUSY) {
		/*
		 * Every job slot is in use (or 1F25h configures this node): a matter of time,
		 * never a failure. The end of one of our downloads starts the next waiting
		 * slave (cfg_kick()); the timer retries for jobs that are not ours.
		 */
		s->sdo_pending = false;
		s->cfg_wait = true;
		arm(s, CFG_WAIT_POLL_MS);
		return NEXT_WAIT;
	}
	if (err != 0) {
		s->sdo_pending = false;
		return fail(s, CO_MGR_ST_J, 0x1F22U, s->id, 0U, 0U, CO_SDO_AB_GENERAL);
	}
	return NEXT_WAIT;
#else
	return CO_MGR_STEP_START_EC;
#endif
}

#if defined(CONFIG_CANOPEN_CFG)
/*
 * Start the waiting downloads, oldest wait first, while job slots are free. A slave whose own
 * node a 1F25h request configures right now is left to its poll.
 */
static void cfg_kick(struct co_mgr *m)
{
	struct co_cfg *cfg = co_cfg_get(m->node);

	for (;;) {
		struct co_mgr_slave *w = NULL;

		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			struct co_mgr_slave *o = &m->slaves[i];

			if (o->id != 0U && o->booting && o->cfg_wait &&
			    o->step == CO_MGR_STEP_DOWNLOAD && !co_cfg_busy(cfg, o->id) &&
			    (w == NULL || (int32_t)(o->cfg_ticket - w->cfg_ticket) < 0)) {
				w = o;
			}
		}
		if (w == NULL) {
			return;
		}
		co_timer_stop(&w->timer);
		boot_run(w, st_download(w));
		if (w->cfg_wait) {
			/* Still no slot (re-armed): the others wait too. */
			return;
		}
	}
}
#endif

static uint8_t st_download_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return fail(s, CO_MGR_ST_J, s->err.index, s->err.sub, 0U, 0U, ab);
	}
	return CO_MGR_STEP_START_EC;
}

/* 302-2 §4.1: the heartbeat timeout runs from now; guarding needs time and factor. */
static uint8_t st_start_ec(struct co_mgr_slave *s)
{
	uint32_t as = assign_of(s->mgr, s->id);
	uint16_t gt = (uint16_t)(as >> 16);
	uint8_t rf = (uint8_t)(as >> 8);

	s->hb_ms = hb_time_of(s->mgr, s->id);
	if (s->hb_ms != 0U) {
		arm(s, s->hb_ms);
		return NEXT_WAIT;
	}
	if (gt != 0U && rf != 0U) {
		guard_start(s, gt, rf);
	}
	return CO_MGR_STEP_START;
}

static uint8_t st_start_ec_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (byte == 0U) {
		/* A boot-up is not a heartbeat. */
		return NEXT_WAIT;
	}
	co_timer_stop(&s->timer);
	hb_start(s, now_of(s->mgr));
	return CO_MGR_STEP_START;
}

static uint8_t st_start_ec_to(struct co_mgr_slave *s)
{
	return fail(s, CO_MGR_ST_K, IDX_HB_CONSUMER, 0, s->hb_ms, 0U, 0U);
}

static bool status_ok(uint8_t st);

/* Whether a mandatory slave has not booted yet (the initial startup may still halt). */
static bool mandatory_pending(struct co_mgr *m)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *o = &m->slaves[i];

		if (o->id != 0U &&
		    (assign_of(m, o->id) & (AS_SLAVE | AS_MANDATORY)) ==
			    (AS_SLAVE | AS_MANDATORY) &&
		    !status_ok(o->status)) {
			return true;
		}
	}
	return false;
}

/* g..l: start the slave unless it runs already, may not be started or waits for 000#0100. */
static uint8_t st_start(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;
	uint32_t su = startup_obj(m);

	if (s->was_operational) {
		s->status = CO_MGR_ST_L;
		return fail(s, CO_MGR_ST_L, 0, 0, 0U, CO_NMT_OPERATIONAL, 0U);
	}
	s->status = CO_MGR_ST_OK;
	if (s->no_start || (su & SU_NO_START) != 0U || m->startup == CO_MGR_STARTUP_HALTED) {
		return NEXT_END;
	}
	if (m->startup == CO_MGR_STARTUP_RUNNING &&
	    ((su & SU_START_ALL) != 0U || mandatory_pending(m))) {
		/* S6 starts it: nothing may start while a mandatory slave can still fail. */
		s->start_deferred = (su & SU_START_ALL) == 0U;
		return NEXT_END;
	}
	(void)nmt_queue(m, CO_NMT_CS_START, s->id, false);
	return NEXT_END;
}

static const struct boot_state boot_table[CO_MGR_STEP_COUNT] = {
	[CO_MGR_STEP_IDLE] = {"IDLE", NULL, NULL, NULL, NULL},
	[CO_MGR_STEP_ASSIGNED] = {"ASSIGNED", st_assigned, NULL, NULL, NULL},
	[CO_MGR_STEP_BOOT_ALLOWED] = {"BOOT_ALLOWED", st_boot_allowed, NULL, NULL, NULL},
	[CO_MGR_STEP_DEVTYPE] = {"DEVTYPE", st_devtype, st_devtype_sdo, NULL, NULL},
	[CO_MGR_STEP_VENDOR] = {"VENDOR", st_ident, st_ident_sdo, NULL, NULL},
	[CO_MGR_STEP_PRODUCT] = {"PRODUCT", st_ident, st_ident_sdo, NULL, NULL},
	[CO_MGR_STEP_REVISION] = {"REVISION", st_ident, st_ident_sdo, NULL, NULL},
	[CO_MGR_STEP_SERIAL] = {"SERIAL", st_ident, st_ident_sdo, NULL, NULL},
	[CO_MGR_STEP_KEEP_ALIVE] = {"KEEP_ALIVE", st_keep_alive, NULL, st_keep_alive_ec,
				    st_keep_alive_to},
	[CO_MGR_STEP_KEEP_ALIVE_RESET] = {"KEEP_ALIVE_RESET", st_wait_bootup, NULL, st_ka_reset_ec,
					  st_ka_reset_to},
	[CO_MGR_STEP_SW_DATE] = {"SW_DATE", st_sw_date, st_sw_date_sdo, NULL, NULL},
	[CO_MGR_STEP_SW_TIME] = {"SW_TIME", st_sw_time, st_sw_time_sdo, NULL, NULL},
	[CO_MGR_STEP_CFG_DATE] = {"CFG_DATE", st_cfg_date, st_cfg_date_sdo, NULL, NULL},
	[CO_MGR_STEP_CFG_TIME] = {"CFG_TIME", st_cfg_time, st_cfg_time_sdo, NULL, NULL},
	[CO_MGR_STEP_RESTORE] = {"RESTORE", st_restore, st_restore_sdo, NULL, NULL},
	[CO_MGR_STEP_RESTORE_RESET] = {"RESTORE_RESET", st_wait_bootup, NULL, st_restore_reset_ec,
				       st_restore_reset_to},
	[CO_MGR_STEP_DOWNLOAD] = {"DOWNLOAD", st_download, st_download_sdo, NULL, st_download},
	[CO_MGR_STEP_START_EC] = {"START_EC", st_start_ec, NULL, st_start_ec_ec, st_start_ec_to},
	[CO_MGR_STEP_START] = {"START", st_start, NULL, NULL, NULL},
};

const char *co_mgr_step_str(enum co_mgr_step step)
{
	return (unsigned int)step < CO_MGR_STEP_COUNT ? boot_table[step].name : "?";
}

/* --- Boot process (302-2 §3.3) and NMT startup (302-2 §3.1) -------------------------------- */

static void boot_end(struct co_mgr_slave *s);

/* The attempt finished: its result becomes the one co_mgr_get_boot() reports. */
static void publish(struct co_mgr_slave *s)
{
	s->last_status = s->status;
	s->last_read_mask = s->read_mask;
	memcpy(s->last_ident, s->ident, sizeof(s->last_ident));
	s->last_err = s->err;
}

static void boot_run(struct co_mgr_slave *s, uint8_t next)
{
	while (next != NEXT_WAIT) {
		if (next == NEXT_END) {
			boot_end(s);
			return;
		}
		s->step = next;
		next = boot_table[next].enter(s);
	}
}

static void sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	struct co_mgr_slave *s = user_data;

	/* Transfers dropped by our own reset are not boot results. */
	if (!s->sdo_pending || s->mgr->node->nmt.state == CO_NMT_INITIALISING) {
		s->sdo_pending = false;
		return;
	}
	s->sdo_pending = false;
	if (!s->booting || boot_table[s->step].sdo == NULL) {
		return;
	}
	boot_run(s, boot_table[s->step].sdo(s, abort_code));
}

static void boot_attempt(struct co_mgr_slave *s)
{
	s->booting = true;
	s->attempts++;
	s->status = CO_MGR_ST_NONE;
	s->read_mask = 0U;
	s->wait_reboot = false;
	s->start_deferred = false;
	s->cfg_wait = false;
	/* The working record; co_mgr_get_boot() shows the last finished one until boot_end(). */
	memset(&s->err, 0, sizeof(s->err));
	memset(s->ident, 0, sizeof(s->ident));
	ec_stop(s);
	if (co_sdo_cli_busy(cli_of(s))) {
		s->sdo_pending = false;
		(void)co_sdo_cli_abort_req(cli_of(s), CO_SDO_AB_GENERAL);
	}
	(void)co_sdo_cli_set_server(cli_of(s), s->id);
	boot_run(s, CO_MGR_STEP_ASSIGNED);
}

static void boot_process_start(struct co_mgr_slave *s)
{
	co_timer_stop(&s->timer);
	s->started_us = now_of(s->mgr);
	s->attempts = 0U;
	s->tried = false;
	boot_attempt(s);
}

static void startup_check(struct co_mgr *m);

static void halt(struct co_mgr *m, const struct co_mgr_boot_error *err)
{
	if (m->startup != CO_MGR_STARTUP_RUNNING) {
		return;
	}
	m->startup = CO_MGR_STARTUP_HALTED;
	m->halt_err = *err;
	co_timer_stop(&m->boot_timer);
	LOG_ERR("%s: NMT startup halted: mandatory node %u failed with %c", m->node->name,
		err->node_id, err->status);
	if (m->startup_ind != NULL) {
		m->startup_ind(m->node, CO_MGR_STARTUP_HALTED, &m->halt_err, m->startup_user_data);
	}
}

static bool status_ok(uint8_t st)
{
	return st == CO_MGR_ST_OK || st == CO_MGR_ST_L;
}

static void boot_end(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;
	uint32_t as = assign_of(m, s->id);
	bool mandatory = (as & AS_MANDATORY) != 0U;
	uint64_t now = now_of(m);

	s->booting = false;
	s->tried = true;
	s->finished_us = now;
	s->step = CO_MGR_STEP_IDLE;
	s->cfg_wait = false;
	publish(s);
	if (s->status == CO_MGR_ST_OK) {
		LOG_INF("%s: node %u booted", m->node->name, s->id);
	} else {
		LOG_WRN("%s: boot of node %u: status %c in %s, object %04Xh:%02Xh expected %08Xh "
			"actual %08Xh abort %08Xh",
			m->node->name, s->id, s->status, co_mgr_step_str(s->err.step), s->err.index,
			s->err.sub, s->err.expected, s->err.actual, s->err.abort_code);
	}
	if (m->boot_ind != NULL) {
		m->boot_ind(m->node, s->id, s->status, s->status == CO_MGR_ST_OK ? NULL : &s->err,
			    m->boot_user_data);
	}
	if (s->booting) {
		/* The indication restarted it. */
		return;
	}
	if (!status_ok(s->status) && s->status != CO_MGR_ST_A) {
		uint32_t bt = od_u32(m, IDX_BOOT_TIME, 0);

		if (mandatory) {
			if (s->status == CO_MGR_ST_B &&
			    (bt == 0U || !co_time_before_eq(s->started_us + MS_US(bt), now))) {
				arm(s, CONFIG_CANOPEN_MGR_RETRY_TIME);
			} else {
				halt(m, &s->err);
			}
		} else if (s->status == CO_MGR_ST_B) {
			/* Optional slaves are polled in the background (§10 #9). */
			arm(s, CONFIG_CANOPEN_MGR_RETRY_TIME);
		}
	}
	startup_check(m);
}

/* S4 done: every mandatory slave OK, every optional slave tried once. S5, S6. */
static void startup_check(struct co_mgr *m)
{
	uint32_t su;
	bool all_ok = true;

	if (m->startup != CO_MGR_STARTUP_RUNNING || m->phase != PH_BOOTING) {
		return;
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];
		uint32_t as;

		if (s->id == 0U) {
			continue;
		}
		as = assign_of(m, s->id);
		if ((as & AS_SLAVE) == 0U) {
			continue;
		}
		if ((as & AS_MANDATORY) != 0U && !status_ok(s->status)) {
			return;
		}
		if (!s->tried) {
			return;
		}
		all_ok = all_ok && status_ok(s->status);
	}
	co_timer_stop(&m->boot_timer);
	m->startup = CO_MGR_STARTUP_DONE;
	m->phase = PH_NONE;
	su = startup_obj(m);
	LOG_INF("%s: NMT startup complete", m->node->name);
	if ((su & SU_NO_SELF_OP) == 0U) {
		(void)co_nmt_req(m->node, CO_NMT_CS_START);
	}
	if ((su & (SU_NO_START | SU_START_ALL)) == 0U) {
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			struct co_mgr_slave *s = &m->slaves[i];

			if (s->id != 0U && s->start_deferred && s->status == CO_MGR_ST_OK) {
				(void)nmt_queue(m, CO_NMT_CS_START, s->id, false);
			}
			s->start_deferred = false;
		}
	}
	if ((su & (SU_NO_START | SU_START_ALL)) == SU_START_ALL) {
		if (all_ok) {
			(void)nmt_queue(m, CO_NMT_CS_START, 0U, false);
		} else {
			for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
				struct co_mgr_slave *s = &m->slaves[i];

				if (s->id != 0U && s->status == CO_MGR_ST_OK && !s->no_start) {
					(void)nmt_queue(m, CO_NMT_CS_START, s->id, false);
				}
			}
		}
	}
	if (m->startup_ind != NULL) {
		m->startup_ind(m->node, CO_MGR_STARTUP_DONE, NULL, m->startup_user_data);
	}
}

static void boot_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;

	if (m->startup != CO_MGR_STARTUP_RUNNING) {
		return;
	}
	/* 1F89h expired: mandatory slaves still not booted end the startup with B. */
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];
		uint32_t as = s->id != 0U ? assign_of(m, s->id) : 0U;

		if ((as & (AS_SLAVE | AS_MANDATORY)) != (AS_SLAVE | AS_MANDATORY) ||
		    status_ok(s->status)) {
			continue;
		}
		if (s->booting || co_timer_is_armed(&s->timer)) {
			co_timer_stop(&s->timer);
			if (s->sdo_pending) {
				s->sdo_pending = false;
				(void)co_sdo_cli_abort_req(cli_of(s), CO_SDO_AB_TIMEOUT);
			}
			if (s->booting) {
				(void)fail(s, CO_MGR_ST_B, IDX_BOOT_TIME, 0,
					   od_u32(m, IDX_BOOT_TIME, 0), 0U, 0U);
				s->booting = false;
				s->cfg_wait = false;
				s->step = CO_MGR_STEP_IDLE;
				s->finished_us = now_us;
				publish(s);
			}
		}
		halt(m, &s->err);
		return;
	}
}

static void slave_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr_slave *s = slave_of_timer(timer);

	if (s->booting) {
		if (boot_table[s->step].timeout != NULL) {
			boot_run(s, boot_table[s->step].timeout(s));
		}
		return;
	}
	if (s->wait_reboot) {
		s->wait_reboot = false;
		boot_process_start(s);
		return;
	}
	/* Retry (status B) within the running boot process. */
	boot_attempt(s);
}

/* S3 sent: boot all slaves (from the line thread, after the resets went out). */
static void startup_resets_sent(struct co_mgr *m)
{
	m->phase = PH_BOOT;
	co_timer_start(m->node->line, &m->start_timer, now_of(m));
}

static void startup_begin(struct co_mgr *m)
{
	uint32_t su = startup_obj(m);
	bool keep = false;

	if ((su & SU_MASTER) == 0U) {
		m->phase = PH_NONE;
		if (su == SU_SELF_START) {
			(void)co_nmt_req(m->node, CO_NMT_CS_START);
		}
		return;
	}
	if ((su & SU_FLYING) != 0U) {
		LOG_WRN("%s: flying master not supported; acting as the only master",
			m->node->name);
	}
	m->startup = CO_MGR_STARTUP_RUNNING;
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (assign_of(m, s->id) & (AS_SLAVE | AS_KEEP_ALIVE)) ==
					   (AS_SLAVE | AS_KEEP_ALIVE)) {
			keep = true;
		}
	}
	/* S3: never reset ourselves; spare the keep-alive slaves (checked in boot part 2). */
	if (!keep) {
		(void)nmt_queue(m, CO_NMT_CS_RESET_COMMUNICATION, 0U, false);
	} else {
		for (uint8_t id = 1; id <= 127U; id++) {
			uint32_t as = assign_of(m, id);

			if (id == m->node->node_id ||
			    ((as & AS_SLAVE) != 0U && (as & AS_KEEP_ALIVE) != 0U)) {
				continue;
			}
			(void)nmt_queue(m, CO_NMT_CS_RESET_COMMUNICATION, id, false);
		}
	}
	/* S4 once the last reset is out (at once without an inhibit time). */
	m->phase = PH_RESETTING;
	if (m->nmt_count == 0U) {
		startup_resets_sent(m);
	}
}

static void startup_boot(struct co_mgr *m)
{
	uint32_t bt = od_u32(m, IDX_BOOT_TIME, 0);

	m->phase = PH_BOOTING;
	/* A mandatory slave without a slot can never boot: the startup cannot complete. */
	for (uint8_t id = 1; id <= 127U; id++) {
		if (id != m->node->node_id && slot_find(m, id) == NULL &&
		    (assign_of(m, id) & (AS_SLAVE | AS_MANDATORY)) == (AS_SLAVE | AS_MANDATORY)) {
			struct co_mgr_boot_error e = {
				.node_id = id,
				.status = CO_MGR_ST_B,
				.step = CO_MGR_STEP_IDLE,
				.index = IDX_ASSIGN,
				.sub = id,
				.expected = CONFIG_CANOPEN_MGR_SLAVES,
			};

			halt(m, &e);
			return;
		}
	}
	if (bt != 0U) {
		co_timer_start(m->node->line, &m->boot_timer, now_of(m) + MS_US(bt));
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (assign_of(m, s->id) & AS_SLAVE) != 0U) {
			boot_process_start(s);
			if (m->startup != CO_MGR_STARTUP_RUNNING) {
				break;
			}
		}
	}
	startup_check(m);
}

static void start_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;

	if (m->phase == PH_BEGIN) {
		startup_begin(m);
	} else if (m->phase == PH_BOOT) {
		startup_boot(m);
	}
}

/* --- Boot-up handler and error-control frames ------------------------------------------------ */

static void bootup_handler(struct co_mgr *m, uint8_t id, struct co_mgr_slave *s)
{
	if (m->startup == CO_MGR_STARTUP_IDLE) {
		return;
	}
	ec_indicate(m, id, CO_MGR_EC_BOOTUP, 0U);
	if (s != NULL) {
		/* The boot-up reports Pre-operational (its own event, not a state change). */
		s->rep_state = CO_NMT_PRE_OPERATIONAL;
	}
	if (s == NULL || (assign_of(m, id) & AS_SLAVE) == 0U) {
		/* Not in 1F81h: the application's business (302-2 §3.1). */
		return;
	}
	if (s->booting) {
		/* Our own reset inside the boot: that process waits for it. */
		if (boot_table[s->step].ec != NULL) {
			boot_run(s, boot_table[s->step].ec(s, 0U));
		}
		return;
	}
	ec_stop(s);
	set_nmt_view(s, CO_NMT_PRE_OPERATIONAL);
	if (m->startup == CO_MGR_STARTUP_RUNNING && m->phase != PH_BOOTING) {
		/* The startup is about to boot it. */
		return;
	}
	if (s->parked) {
		return;
	}
	s->wait_reboot = false;
	if ((assign_of(m, id) & AS_BOOT) != 0U) {
		boot_process_start(s);
	} else {
		co_timer_stop(&s->timer);
	}
}

static void ec_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us)
{
	struct co_mgr *m = rx->user_data;
	uint8_t id = (uint8_t)(frame->id - CO_NMT_EC_COB_ID);
	struct co_mgr_slave *s;
	uint8_t byte;
	uint8_t state;

	if (id == 0U || id > 127U || id == m->node->node_id ||
	    (frame->flags & CAN_FRAME_RTR) != 0U || frame->dlc < 1U) {
		return;
	}
	byte = frame->data[0];
	s = slot_find(m, id);
	if (byte == 0U) {
		bootup_handler(m, id, s);
		return;
	}
	if (s == NULL) {
		return;
	}
	state = byte & 0x7fU;
	if (s->guarding && !s->hb_on) {
		/*
		 * CiA 301 §7.2.8.3.2.1: the toggle bit alternates; a reply that repeats the
		 * last one is not an answer. The first reply sets the phase (the slave's toggle
		 * runs on from any earlier guarding, e.g. the keep-alive check).
		 */
		uint8_t tg = byte & 0x80U;

		if (s->guard_toggle == 0xffU || tg == s->guard_toggle) {
			s->guard_ans = true;
		}
		s->guard_toggle = tg ^ 0x80U;
	}
	if (s->hb_on) {
		co_timer_start(m->node->line, &s->ec_timer, now_us + MS_US(s->hb_ms));
	} else if (s->ec_lost && s->hb_ms != 0U && !s->booting) {
		/* Heartbeat back after a loss: monitor again. */
		hb_start(s, now_us);
	}
	if (state != s->nmt_state) {
		set_nmt_view(s, state);
	}
	/*
	 * The event follows what the slave reports, not the master's view: a start the master
	 * sent set the view already, its confirmation by the heartbeat is still a change.
	 */
	if (state != s->rep_state) {
		s->rep_state = state;
		ec_indicate(m, id, CO_MGR_EC_STATE, state);
	}
	if (s->booting && boot_table[s->step].ec != NULL) {
		boot_run(s, boot_table[s->step].ec(s, byte));
	}
}

/* --- 1F82h request NMT, 1F83h request guarding -------------------------------------------------
 */

static uint8_t req_cs(uint8_t v)
{
	switch (v & 0x7fU) {
	case 0x04:
		return CO_NMT_CS_STOP;
	case 0x05:
		return CO_NMT_CS_START;
	case 0x06:
		return CO_NMT_CS_RESET_NODE;
	case 0x07:
		return CO_NMT_CS_RESET_COMMUNICATION;
	case 0x7f:
		return CO_NMT_CS_ENTER_PRE_OPERATIONAL;
	default:
		return 0U;
	}
}

static bool is_master(struct co_mgr *m)
{
	return (startup_obj(m) & SU_MASTER) != 0U && m->startup != CO_MGR_STARTUP_IDLE;
}

static uint32_t req_nmt_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t sub = req->info->sub;
	uint8_t v = (uint8_t)co_od_req_uint(req);
	bool excl = v == 0x84U || v == 0x85U || v == 0x86U || v == 0x87U || v == 0x8fU;
	uint8_t cs = req_cs(v);

	if (m->od_update) {
		return 0U;
	}
	if (sub == 0U) {
		return CO_SDO_AB_READONLY;
	}
	if (cs == 0U || (v >= 0x80U && !excl) || (excl && sub != ALL_NODES)) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (excl && req->writer != CO_OD_WRITER_APP) {
		/* 302-2 §6.4: the requester must be known; over SDO it is not. */
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (!is_master(m)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (sub == ALL_NODES) {
		if (excl) {
			/* Individual frames: a broadcast plus "undo" cannot undo a reset. */
			for (uint8_t id = 1; id <= 127U; id++) {
				if (id != m->node->node_id && nmt_queue(m, cs, id, false) != 0) {
					return CO_SDO_AB_DATA_DEV_STATE;
				}
			}
		} else if (nmt_queue(m, cs, 0U, true) != 0) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
		return CO_OD_HANDLED;
	}
	if (sub == m->node->node_id) {
		(void)co_nmt_req(m->node, (enum co_nmt_cs)cs);
		return CO_OD_HANDLED;
	}
	{
		struct co_mgr_slave *s = slot_get(m, sub);

		if (s != NULL) {
			/* No automatic re-boot of a slave an operator parked (302 §5.4). */
			s->parked = true;
		}
	}
	if (nmt_queue(m, cs, sub, false) != 0) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	return CO_OD_HANDLED;
}

static uint32_t guard_one(struct co_mgr *m, uint8_t id, uint8_t v)
{
	struct co_mgr_slave *s;
	uint32_t as = assign_of(m, id);

	if (id == m->node->node_id) {
		return 0U;
	}
	if (v == 0U) {
		s = slot_find(m, id);
		if (s != NULL && s->guarding) {
			ec_stop(s);
		}
		return 0U;
	}
	if ((uint16_t)(as >> 16) == 0U || (uint8_t)(as >> 8) == 0U) {
		/* Guard time and retry factor come from 1F81h. */
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	s = slot_get(m, id);
	if (s == NULL) {
		return CO_SDO_AB_NO_RESOURCE;
	}
	co_timer_stop(&s->ec_timer);
	s->hb_on = false;
	guard_start(s, (uint16_t)(as >> 16), (uint8_t)(as >> 8));
	return 0U;
}

static uint32_t req_guard_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t sub = req->info->sub;
	uint8_t v = (uint8_t)co_od_req_uint(req);
	uint32_t ab = 0U;

	if (m->od_update) {
		return 0U;
	}
	if (sub == 0U) {
		return CO_SDO_AB_READONLY;
	}
	if (v > 1U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	if (!is_master(m)) {
		return CO_SDO_AB_DATA_DEV_STATE;
	}
	if (sub != ALL_NODES) {
		return guard_one(m, sub, v);
	}
	/* All or nothing: every assigned slave needs its guard time and retry factor. */
	for (uint8_t id = 1; id <= 127U && v == 1U; id++) {
		uint32_t as = assign_of(m, id);

		if (id != m->node->node_id && (as & AS_SLAVE) != 0U &&
		    ((uint16_t)(as >> 16) == 0U || (uint8_t)(as >> 8) == 0U)) {
			return CO_SDO_AB_DATA_DEV_STATE;
		}
	}
	for (uint8_t id = 1; id <= 127U && ab == 0U; id++) {
		if ((assign_of(m, id) & AS_SLAVE) != 0U) {
			ab = guard_one(m, id, v);
		}
	}
	if (ab == 0U) {
		/* Reads of the per-node entries follow. */
		m->od_update = true;
		for (uint8_t id = 1; id <= 127U; id++) {
			if ((assign_of(m, id) & AS_SLAVE) != 0U) {
				(void)co_od_write(od, IDX_REQ_GUARD, id, &v, 1, CO_OD_WRITER_APP);
			}
		}
		m->od_update = false;
	}
	return ab;
}

/* 302-2 §6.2/§6.3: unsupported bits are refused. */
static uint32_t startup_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint32_t v = (uint32_t)co_od_req_uint(req);

	if ((v & ~(uint32_t)(SU_MASTER | SU_START_ALL | SU_NO_SELF_OP | SU_NO_START | SU_RESET_ALL |
			     SU_STOP_ALL)) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

static uint32_t assign_validate(struct co_od *od, struct co_od_req *req, void *user_data)
{
	uint32_t v = (uint32_t)co_od_req_uint(req);

	if (req->info->sub != 0U && (v & BIT(1)) != 0U) {
		return CO_SDO_AB_INVALID_VALUE;
	}
	return 0U;
}

/* A slave assigned at run time gets a slot; one removed loses its supervision. */
static void assign_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct co_mgr *m = user_data;
	uint8_t id = req->info->sub;
	uint32_t v = (uint32_t)co_od_req_uint(req);
	struct co_mgr_slave *s;

	if (id == 0U || id > 127U || id == m->node->node_id) {
		return;
	}
	if ((v & AS_SLAVE) != 0U) {
		(void)slot_get(m, id);
		return;
	}
	s = slot_find(m, id);
	if (s != NULL && !s->booting && !s->sdo_pending) {
		ec_stop(s);
		co_timer_stop(&s->timer);
		s->id = 0U;
	}
}

/* --- Node interface ------------------------------------------------------------------------ */

static void slaves_reset(struct co_mgr *m)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		co_timer_stop(&s->timer);
		co_timer_stop(&s->ec_timer);
		s->id = 0U;
		s->booting = false;
		s->sdo_pending = false;
		s->hb_on = false;
		s->guarding = false;
		s->ec_lost = false;
		s->parked = false;
		s->wait_reboot = false;
		s->start_deferred = false;
		s->tried = false;
		s->cfg_wait = false;
		s->status = CO_MGR_ST_NONE;
		s->last_status = CO_MGR_ST_NONE;
		s->rep_state = 0U;
		s->step = CO_MGR_STEP_IDLE;
		s->attempts = 0U;
	}
}

int co_mgr_init(struct co_node *node)
{
	struct co_mgr *m = &node->mgr;
	const struct co_od_hook hooks[] = {
		{IDX_STARTUP, IDX_STARTUP, 0, 0, startup_validate, NULL, m},
		{IDX_ASSIGN, IDX_ASSIGN, 0, 127, assign_validate, assign_notify, m},
		{IDX_REQ_NMT, IDX_REQ_NMT, 0, ALL_NODES, req_nmt_validate, NULL, m},
		{IDX_REQ_GUARD, IDX_REQ_GUARD, 0, ALL_NODES, req_guard_validate, NULL, m},
	};

	memset(m, 0, sizeof(*m));
	m->node = node;
	co_timer_init(&m->nmt_timer, nmt_timer_handler, &node->lock, m);
	co_timer_init(&m->start_timer, start_timer_handler, &node->lock, m);
	co_timer_init(&m->boot_timer, boot_timer_handler, &node->lock, m);
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		s->mgr = m;
		s->slot = (uint8_t)i;
		s->status = CO_MGR_ST_NONE;
		s->last_status = CO_MGR_ST_NONE;
		co_timer_init(&s->timer, slave_timer_handler, &node->lock, s);
		co_timer_init(&s->ec_timer, ec_timer_handler, &node->lock, s);
	}
	/* Every error-control frame 700h..77Fh; ours never comes back to us. */
	co_rx_init(&m->ec_rx, CO_NMT_EC_COB_ID, ec_rx, &node->lock, m);
	m->ec_rx.mask = 0x780U;
	if (co_rx_register(node->line, &m->ec_rx) != 0) {
		return -ENOSPC;
	}
	return co_od_hooks_register(&node->od, hooks, ARRAY_SIZE(hooks));
}

void co_mgr_reset_comm(struct co_node *node)
{
	struct co_mgr *m = &node->mgr;

	co_timer_stop(&m->nmt_timer);
	co_timer_stop(&m->start_timer);
	co_timer_stop(&m->boot_timer);
	m->nmt_head = 0U;
	m->nmt_count = 0U;
	m->nmt_next_us = 0U;
	m->startup = CO_MGR_STARTUP_IDLE;
	m->phase = PH_NONE;
	slaves_reset(m);
	for (uint8_t id = 1; id <= 127U; id++) {
		if (id != node->node_id && (assign_of(m, id) & AS_SLAVE) != 0U) {
			(void)slot_get(m, id);
		}
	}
	m->boot_pending = true;
}

void co_mgr_set_state(struct co_node *node, enum co_nmt_state to)
{
	struct co_mgr *m = &node->mgr;

	switch (to) {
	case CO_NMT_INITIALISING:
		co_timer_stop(&m->nmt_timer);
		co_timer_stop(&m->start_timer);
		co_timer_stop(&m->boot_timer);
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			co_timer_stop(&m->slaves[i].timer);
			co_timer_stop(&m->slaves[i].ec_timer);
			m->slaves[i].booting = false;
			m->slaves[i].sdo_pending = false;
		}
		break;
	case CO_NMT_PRE_OPERATIONAL:
		if (m->boot_pending) {
			/* Run the startup after the boot-up message, from the line thread. */
			m->boot_pending = false;
			m->phase = PH_BEGIN;
			co_timer_start(node->line, &m->start_timer, co_line_time(node->line));
		}
		break;
	case CO_NMT_STOPPED:
		/* Boots stop with the SDO clients; supervision goes on. */
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			struct co_mgr_slave *s = &m->slaves[i];

			if (s->booting) {
				s->booting = false;
				s->sdo_pending = false;
				s->step = CO_MGR_STEP_IDLE;
				co_timer_stop(&s->timer);
			}
		}
		break;
	default:
		break;
	}
}

/* --- API --------------------------------------------------------------------------------- */

int co_mgr_nmt_req(struct co_node *node, uint8_t id, enum co_nmt_cs cs)
{
	struct co_mgr *m = &node->mgr;
	int err;

	if (id > 127U || !cs_valid((uint8_t)cs)) {
		return -EINVAL;
	}
	co_node_lock(node);
	if ((startup_obj(m) & SU_MASTER) == 0U) {
		err = -EPERM;
	} else if (id == node->node_id) {
		err = co_nmt_req(node, cs);
	} else {
		err = nmt_queue(m, (uint8_t)cs, id, id == 0U);
		if (err == 0 && id != 0U) {
			struct co_mgr_slave *s = slot_find(m, id);

			if (s != NULL) {
				s->parked = true;
			}
		}
	}
	co_node_unlock(node);
	return err;
}

int co_mgr_boot_req(struct co_node *node, uint8_t id)
{
	struct co_mgr *m = &node->mgr;
	struct co_mgr_slave *s;
	int err = 0;

	if (id == 0U || id > 127U || id == node->node_id) {
		return -EINVAL;
	}
	co_node_lock(node);
	s = slot_get(m, id);
	if (s == NULL) {
		err = -ENOSPC;
	} else if (s->booting) {
		err = -EALREADY;
	} else {
		s->parked = false;
		boot_process_start(s);
	}
	co_node_unlock(node);
	return err;
}

int co_mgr_get_boot(struct co_node *node, uint8_t id, struct co_mgr_boot_info *info)
{
	struct co_mgr *m = &node->mgr;
	struct co_mgr_slave *s;
	uint32_t as;
	int err = 0;

	co_node_lock(node);
	s = slot_find(m, id);
	as = id != 0U && id <= 127U ? assign_of(m, id) : 0U;
	if (s == NULL) {
		err = -ENOENT;
	} else {
		*info = (struct co_mgr_boot_info){
			.node_id = id,
			.assigned = (as & AS_SLAVE) != 0U,
			.mandatory = (as & AS_MANDATORY) != 0U,
			.booting = s->booting,
			.status = s->last_status,
			.device_type = s->last_ident[0],
			.identity = {s->last_ident[1], s->last_ident[2], s->last_ident[3],
				     s->last_ident[4]},
			.read_mask = s->last_read_mask,
			.attempts = s->attempts,
			.started_us = s->started_us,
			.finished_us = s->finished_us,
			.nmt_state = s->nmt_state,
			.error = s->last_err,
		};
	}
	co_node_unlock(node);
	return err;
}

enum co_mgr_startup co_mgr_get_startup(struct co_node *node)
{
	enum co_mgr_startup st;

	co_node_lock(node);
	st = (enum co_mgr_startup)node->mgr.startup;
	co_node_unlock(node);
	return st;
}

void co_mgr_release(struct co_node *node, uint8_t id)
{
	struct co_mgr_slave *s;

	co_node_lock(node);
	s = slot_find(&node->mgr, id);
	if (s != NULL) {
		s->parked = false;
	}
	co_node_unlock(node);
}

void co_mgr_set_boot_ind(struct co_node *node, co_mgr_boot_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.boot_ind = cb;
	node->mgr.boot_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_startup_ind(struct co_node *node, co_mgr_startup_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.startup_ind = cb;
	node->mgr.startup_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_ec_ind(struct co_node *node, co_mgr_ec_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.ec_ind = cb;
	node->mgr.ec_user_data = user_data;
	co_node_unlock(node);
}

void co_mgr_set_sw_ind(struct co_node *node, co_mgr_sw_ind_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.sw_ind = cb;
	node->mgr.sw_user_data = user_data;
	co_node_unlock(node);
}
