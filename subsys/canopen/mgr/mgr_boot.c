/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * "Boot NMT slave" (CiA 302-2 §3.4-§3.7, doc/mgr.md "Boot-up") and the boot process of one
 * slave (302-2 §3.3). The steps are a const table of states with handlers for enter, SDO
 * confirmation, error-control frame and timeout; each handler returns the next state, WAIT
 * or END, so the flow of a boot can be read from the table alone. Each slave slot owns SDO
 * client slot i, so all slaves boot in parallel. What follows an attempt (retry, halt, start
 * of the others) is the startup's business (mgr_startup.c).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/sdo_abort.h>
#if defined(CONFIG_CANOPEN_CFG)
#include <canopen/cfg.h>
#endif

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

BUILD_ASSERT(CONFIG_CANOPEN_SDO_CLIENTS >= CONFIG_CANOPEN_MGR_SLAVES,
	     "every slave slot needs its own SDO client");

/* Handler results besides a next step. */
#define NEXT_WAIT 0xfeU
#define NEXT_END  0xfdU

/*
 * A slave waiting for a configuration job is started when a download of the manager ends;
 * this poll only covers jobs of others (1F25h) ending.
 */
#define CFG_WAIT_POLL_MS 100U

/*
 * A step that waits for the slave's default SDO (held by an SRD) looks again after [ms]. The
 * SDO manager wakes it whenever it may have given one back (co_mgr_boot_sdo_recheck()): the
 * poll is the fallback.
 */
#define SDO_WAIT_POLL_MS 100U

/* "load" (CiA 301 1011h) on the wire. */
static const uint8_t sig_load[4] = {'l', 'o', 'a', 'd'};

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

	(void)memset(s->buf, 0, sizeof(s->buf));
	s->sdo_pending = true;
	s->xfer_index = index;
	s->xfer_sub = sub;
	err = co_sdo_cli_upload_req(co_mgr_cli(s), index, sub, s->buf, sizeof(s->buf),
				    CO_SDO_CLI_AUTO, CONFIG_CANOPEN_MGR_SDO_TIMEOUT, sdo_con, s);
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
	s->xfer_index = index;
	s->xfer_sub = sub;
	err = co_sdo_cli_download_req(co_mgr_cli(s), index, sub, data, len, CO_SDO_CLI_AUTO,
				      CONFIG_CANOPEN_MGR_SDO_TIMEOUT, sdo_con, s);
	if (err != 0) {
		s->sdo_pending = false;
		return boot_table[s->step].sdo(s, CO_SDO_AB_GENERAL);
	}
	return NEXT_WAIT;
}

/* --- The steps ------------------------------------------------------------------------------ */

/* a: 1F81h bit 0. */
static uint8_t st_assigned(struct co_mgr_slave *s)
{
	uint32_t as = co_mgr_assign(s->mgr, s->id);

	if ((as & AS_SLAVE) == 0U) {
		return fail(s, CO_MGR_ST_A, IDX_ASSIGN, s->id, AS_SLAVE, as, 0U);
	}
	return CO_MGR_STEP_BOOTUP;
}

/*
 * The master reset the slave (the startup's Reset Communication, 302-2 §3.1): its SDO server
 * is back with its boot-up, and a request sent before is lost (a timeout of seconds). Wait
 * for the boot-up, at most CONFIG_CANOPEN_MGR_BOOTUP_WAIT after the reset went out.
 */
static uint8_t st_bootup(struct co_mgr_slave *s)
{
	uint64_t until = s->reset_us + MS_US(CONFIG_CANOPEN_MGR_BOOTUP_WAIT);

	if (!s->await_bootup || co_time_before_eq(until, co_mgr_now(s->mgr))) {
		s->await_bootup = false;
		return CO_MGR_STEP_BOOT_ALLOWED;
	}
	co_node_timer_start(s->mgr->node, &s->timer, until);
	return NEXT_WAIT;
}

static uint8_t st_bootup_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (byte != 0U) {
		/* A heartbeat of its old life, sent before the reset reached it. */
		return NEXT_WAIT;
	}
	co_timer_stop(&s->timer);
	return CO_MGR_STEP_BOOT_ALLOWED;
}

static uint8_t st_bootup_to(struct co_mgr_slave *s)
{
	/* No boot-up: go on, the first SDO transfer tells whether the slave is there. */
	s->await_bootup = false;
	LOG_DBG("%s: node %u: no boot-up %u ms after its reset", s->mgr->node->name, s->id,
		CONFIG_CANOPEN_MGR_BOOTUP_WAIT);
	return CO_MGR_STEP_BOOT_ALLOWED;
}

/* b: 1F81h bit 2 = 0: error control only, no checks, no start (302-2 §3.4 b, §10 #13). */
static uint8_t st_boot_allowed(struct co_mgr_slave *s)
{
	s->was_operational = false;
	s->no_start = (co_mgr_assign(s->mgr, s->id) & AS_BOOT) == 0U;
	return s->no_start ? CO_MGR_STEP_START_EC : CO_MGR_STEP_DEVTYPE;
}

/* c, d: 1000h is always read (presence check), compared when 1F84h is not 0. */
static uint8_t st_devtype(struct co_mgr_slave *s)
{
	return upload(s, IDX_DEVTYPE, 0);
}

static uint8_t st_devtype_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint32_t exp = co_mgr_od(s->mgr, IDX_EXP_DEVTYPE, s->id);
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

	if (co_mgr_od(s->mgr, (uint16_t)(IDX_EXP_VENDOR + k), s->id) == 0U) {
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
	uint32_t exp = co_mgr_od(s->mgr, (uint16_t)(IDX_EXP_VENDOR + k), s->id);
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

	if ((co_mgr_assign(s->mgr, s->id) & AS_KEEP_ALIVE) == 0U) {
		return CO_MGR_STEP_SW_DATE;
	}
	hb = co_mgr_hb_time(s->mgr, s->id);
	if (hb != 0U) {
		co_mgr_arm(s, hb);
	} else {
		co_mgr_send_rtr(s);
		co_mgr_arm(s, CONFIG_CANOPEN_MGR_GUARD_CHECK_TIME);
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
	(void)co_mgr_nmt_queue(s->mgr, CO_NMT_CS_RESET_COMMUNICATION, s->id, false);
	return CO_MGR_STEP_KEEP_ALIVE_RESET;
}

static uint8_t st_keep_alive_to(struct co_mgr_slave *s)
{
	uint16_t hb = co_mgr_hb_time(s->mgr, s->id);

	if (hb != 0U) {
		return fail(s, CO_MGR_ST_E, IDX_HB_CONSUMER, 0, hb, 0U, 0U);
	}
	return fail(s, CO_MGR_ST_F, IDX_ASSIGN, s->id, CONFIG_CANOPEN_MGR_GUARD_CHECK_TIME, 0U, 0U);
}

/* Wait for the boot-up after our reset; heartbeats before it are the old life. */
static uint8_t st_wait_bootup(struct co_mgr_slave *s)
{
	co_mgr_arm(s, CONFIG_CANOPEN_MGR_BOOTUP_WAIT);
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

	if ((co_mgr_assign(s->mgr, s->id) & AS_SW_CHECK) == 0U) {
		return CO_MGR_STEP_CFG_DATE;
	}
	d = co_mgr_od(s->mgr, IDX_SW_DATE, s->id);
	t = co_mgr_od(s->mgr, IDX_SW_TIME, s->id);
	if (d == 0U || t == 0U) {
		return fail(s, CO_MGR_ST_G, d == 0U ? IDX_SW_DATE : IDX_SW_TIME, s->id, 1U, 0U, 0U);
	}
	return upload(s, IDX_SW_VERIFY, 1);
}

static uint8_t st_sw_date_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return fail(s, CO_MGR_ST_G, IDX_SW_VERIFY, 1, co_mgr_od(s->mgr, IDX_SW_DATE, s->id),
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
	uint32_t ed = co_mgr_od(m, IDX_SW_DATE, s->id);
	uint32_t et = co_mgr_od(m, IDX_SW_TIME, s->id);
	uint32_t at = buf_u32(s);
	bool date_ok = ed == s->sw_date;

	if (ab != 0U) {
		return fail(s, CO_MGR_ST_G, IDX_SW_VERIFY, 2, et, 0U, ab);
	}
	if (date_ok && et == at) {
		return CO_MGR_STEP_CFG_DATE;
	}
	if ((co_mgr_assign(m, s->id) & AS_SW_UPDATE) == 0U) {
		return fail(s, CO_MGR_ST_H, IDX_SW_VERIFY, date_ok ? 2 : 1, date_ok ? et : ed,
			    date_ok ? at : s->sw_date, 0U);
	}
#if defined(CONFIG_CANOPEN_MGR_PGM)
	if (co_mgr_pgm_has_image(s)) {
		return CO_MGR_STEP_PGM_STOP;
	}
#endif
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
	*date = co_mgr_od(s->mgr, IDX_CFG_DATE, s->id);
	*time = co_mgr_od(s->mgr, IDX_CFG_TIME, s->id);
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
	if ((co_mgr_assign(s->mgr, s->id) & AS_RESTORE) == 0U) {
		return 0U;
	}
	return (uint8_t)co_mgr_od(s->mgr, IDX_RESTORE_SUB, s->id);
}

static uint8_t st_restore(struct co_mgr_slave *s)
{
	uint8_t sub = restore_sub(s);

	if (sub == 0U) {
		return CO_MGR_STEP_DOWNLOAD;
	}
	(void)memcpy(s->load, sig_load, sizeof(s->load));
	return download(s, IDX_RESTORE, sub, s->load, sizeof(s->load));
}

static uint8_t st_restore_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint8_t sub = restore_sub(s);

	if (ab != 0U) {
		return fail(s, CO_MGR_ST_J, IDX_RESTORE, sub, 0x64616f6cU, 0U, ab);
	}
	/* Sub 2 restores communication parameters only: Reset Communication suffices. */
	(void)co_mgr_nmt_queue(s->mgr,
			       sub == 2U ? CO_NMT_CS_RESET_COMMUNICATION : CO_NMT_CS_RESET_NODE,
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
	sdo_con(co_mgr_cli(s), abort_code, 0, s);
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
	s->xfer_index = 0x1F22U;
	s->xfer_sub = s->id;
	err = co_cfg_download_req(cfg, co_mgr_cli(s), s->id, cfg_con, s);
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
		co_mgr_arm(s, CFG_WAIT_POLL_MS);
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
	uint32_t as = co_mgr_assign(s->mgr, s->id);
	uint16_t gt = (uint16_t)(as >> 16);
	uint8_t rf = (uint8_t)(as >> 8);

	s->hb_ms = co_mgr_hb_time(s->mgr, s->id);
	if (s->hb_ms != 0U) {
		co_mgr_arm(s, s->hb_ms);
		return NEXT_WAIT;
	}
	if (gt != 0U && rf != 0U) {
		co_mgr_guard_start(s, gt, rf);
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
	co_mgr_hb_start(s, co_mgr_now(s->mgr));
	return CO_MGR_STEP_START;
}

static uint8_t st_start_ec_to(struct co_mgr_slave *s)
{
	return fail(s, CO_MGR_ST_K, IDX_HB_CONSUMER, 0, s->hb_ms, 0U, 0U);
}

/* g..l: start the slave unless it runs already, may not be started or waits for 000#0100. */
static uint8_t st_start(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;
	uint32_t su = co_mgr_startup_obj(m);

	if (s->was_operational) {
		s->status = CO_MGR_ST_L;
		return fail(s, CO_MGR_ST_L, 0, 0, 0U, CO_NMT_OPERATIONAL, 0U);
	}
	s->status = CO_MGR_ST_OK;
	if (s->no_start || (su & SU_NO_START) != 0U || m->startup == CO_MGR_STARTUP_HALTED) {
		return NEXT_END;
	}
	if (m->startup == CO_MGR_STARTUP_RUNNING &&
	    ((su & SU_START_ALL) != 0U || co_mgr_mandatory_pending(m))) {
		/* S6 starts it: nothing may start while a mandatory slave can still fail. */
		s->start_deferred = (su & SU_START_ALL) == 0U;
		return NEXT_END;
	}
	(void)co_mgr_nmt_queue(m, CO_NMT_CS_START, s->id, false);
	return NEXT_END;
}

static const struct boot_state boot_table[CO_MGR_STEP_COUNT] = {
	[CO_MGR_STEP_IDLE] = {.name = "IDLE"},
	[CO_MGR_STEP_ASSIGNED] = {.name = "ASSIGNED", .enter = st_assigned},
	[CO_MGR_STEP_BOOTUP] = {.name = "BOOTUP",
				.enter = st_bootup,
				.ec = st_bootup_ec,
				.timeout = st_bootup_to},
	[CO_MGR_STEP_BOOT_ALLOWED] = {.name = "BOOT_ALLOWED", .enter = st_boot_allowed},
	[CO_MGR_STEP_DEVTYPE] = {.name = "DEVTYPE", .enter = st_devtype, .sdo = st_devtype_sdo},
	[CO_MGR_STEP_VENDOR] = {.name = "VENDOR", .enter = st_ident, .sdo = st_ident_sdo},
	[CO_MGR_STEP_PRODUCT] = {.name = "PRODUCT", .enter = st_ident, .sdo = st_ident_sdo},
	[CO_MGR_STEP_REVISION] = {.name = "REVISION", .enter = st_ident, .sdo = st_ident_sdo},
	[CO_MGR_STEP_SERIAL] = {.name = "SERIAL", .enter = st_ident, .sdo = st_ident_sdo},
	[CO_MGR_STEP_KEEP_ALIVE] = {.name = "KEEP_ALIVE",
				    .enter = st_keep_alive,
				    .ec = st_keep_alive_ec,
				    .timeout = st_keep_alive_to},
	[CO_MGR_STEP_KEEP_ALIVE_RESET] = {.name = "KEEP_ALIVE_RESET",
					  .enter = st_wait_bootup,
					  .ec = st_ka_reset_ec,
					  .timeout = st_ka_reset_to},
	[CO_MGR_STEP_SW_DATE] = {.name = "SW_DATE", .enter = st_sw_date, .sdo = st_sw_date_sdo},
	[CO_MGR_STEP_SW_TIME] = {.name = "SW_TIME", .enter = st_sw_time, .sdo = st_sw_time_sdo},
#if defined(CONFIG_CANOPEN_MGR_PGM)
	[CO_MGR_STEP_PGM_STOP] = {.name = "PGM_STOP",
				  .enter = co_mgr_pgm_stop,
				  .sdo = co_mgr_pgm_stop_sdo},
	[CO_MGR_STEP_PGM_DOWNLOAD] = {.name = "PGM_DOWNLOAD",
				      .enter = co_mgr_pgm_download,
				      .sdo = co_mgr_pgm_download_sdo},
	[CO_MGR_STEP_PGM_START] = {.name = "PGM_START",
				   .enter = co_mgr_pgm_start,
				   .sdo = co_mgr_pgm_start_sdo},
	[CO_MGR_STEP_PGM_RESTART] = {.name = "PGM_RESTART",
				     .enter = co_mgr_pgm_restart,
				     .ec = co_mgr_pgm_restart_ec,
				     .timeout = co_mgr_pgm_restart_to},
	[CO_MGR_STEP_PGM_DATE] = {.name = "PGM_DATE",
				  .enter = co_mgr_pgm_date,
				  .sdo = co_mgr_pgm_date_sdo},
	[CO_MGR_STEP_PGM_TIME] = {.name = "PGM_TIME",
				  .enter = co_mgr_pgm_time,
				  .sdo = co_mgr_pgm_time_sdo},
	[CO_MGR_STEP_PGM_RESUME] = {.name = "PGM_RESUME",
				    .enter = co_mgr_pgm_resume,
				    .sdo = co_mgr_pgm_resume_sdo},
#endif
	[CO_MGR_STEP_CFG_DATE] = {.name = "CFG_DATE", .enter = st_cfg_date, .sdo = st_cfg_date_sdo},
	[CO_MGR_STEP_CFG_TIME] = {.name = "CFG_TIME", .enter = st_cfg_time, .sdo = st_cfg_time_sdo},
	[CO_MGR_STEP_RESTORE] = {.name = "RESTORE", .enter = st_restore, .sdo = st_restore_sdo},
	[CO_MGR_STEP_RESTORE_RESET] = {.name = "RESTORE_RESET",
				       .enter = st_wait_bootup,
				       .ec = st_restore_reset_ec,
				       .timeout = st_restore_reset_to},
	/* The timeout is the poll of a slave waiting for a configuration job: try again. */
	[CO_MGR_STEP_DOWNLOAD] = {.name = "DOWNLOAD",
				  .enter = st_download,
				  .sdo = st_download_sdo,
				  .timeout = st_download},
	[CO_MGR_STEP_START_EC] = {.name = "START_EC",
				  .enter = st_start_ec,
				  .ec = st_start_ec_ec,
				  .timeout = st_start_ec_to},
	[CO_MGR_STEP_START] = {.name = "START", .enter = st_start},
};

const char *co_mgr_step_str(enum co_mgr_step step)
{
	return (unsigned int)step < CO_MGR_STEP_COUNT && boot_table[step].name != NULL
		       ? boot_table[step].name
		       : "?";
}

/* --- Running the table ------------------------------------------------------------------------ */

/* The attempt finished: its result becomes the one co_mgr_get_boot() reports. */
static void publish(struct co_mgr_slave *s)
{
	s->last_status = s->status;
	s->last_read_mask = s->read_mask;
	(void)memcpy(s->last_ident, s->ident, sizeof(s->last_ident));
	s->last_err = s->err;
}

static void boot_end(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;
	bool mandatory = (co_mgr_assign(m, s->id) & AS_MANDATORY) != 0U;
	uint64_t now = co_mgr_now(m);

	s->booting = false;
	s->sdo_wait = false;
	s->tried = true;
	s->finished_us = now;
	s->step = CO_MGR_STEP_IDLE;
	s->cfg_wait = false;
	publish(s);
	if (s->status == CO_MGR_ST_OK) {
		LOG_INF("%s: node %u booted", m->node->name, s->id);
	} else if (co_mgr_error_compared(&s->err)) {
		LOG_WRN("%s: boot of node %u: status %c in %s, object %04Xh:%02Xh expected %08Xh "
			"actual %08Xh",
			m->node->name, s->id, s->status, co_mgr_step_str(s->err.step), s->err.index,
			s->err.sub, s->err.expected, s->err.actual);
	} else {
		/* Nothing was compared: the object and the abort code say what failed. */
		LOG_WRN("%s: boot of node %u: status %c in %s, object %04Xh:%02Xh abort %08Xh",
			m->node->name, s->id, s->status, co_mgr_step_str(s->err.step), s->err.index,
			s->err.sub, s->err.abort_code);
	}
	if (m->boot_ind != NULL) {
		m->boot_ind(m->node, s->id, s->status, s->status == CO_MGR_ST_OK ? NULL : &s->err,
			    m->boot_user_data);
	}
	struct co_event ev = {
		.type = CO_EV_BOOT,
		.boot = {.node_id = s->id, .status = (char)s->status},
	};

	(void)co_node_publish(m->node, &ev, NULL);
	if (s->booting) {
		/* The indication restarted it. */
		return;
	}
	co_mgr_startup_boot_ended(s, mandatory, now);
}

/*
 * Whether the step about to start must wait for the slave's default SDO: an SRD holds it
 * (302 §7.1: the SDO manager lends the default SDO to one client at a time) or our SDO
 * manager's own transfer to the slave runs.
 */
static bool sdo_held(struct co_mgr_slave *s, uint8_t step)
{
#if defined(CONFIG_CANOPEN_MGR_SDOM)
	return boot_table[step].sdo != NULL && co_mgr_sdom_default_held(s->mgr, s->id);
#else
	ARG_UNUSED(s);
	ARG_UNUSED(step);
	return false;
#endif
}

static void boot_run(struct co_mgr_slave *s, uint8_t next)
{
	while (next != NEXT_WAIT) {
		if (next == NEXT_END) {
			boot_end(s);
			return;
		}
		s->step = next;
		if (sdo_held(s, next)) {
			/* Looked at again by the slave's timer; 1F89h keeps running meanwhile. */
			if (!s->sdo_wait) {
				LOG_INF("%s: boot of node %u waits in %s: its default SDO is held",
					s->mgr->node->name, s->id,
					co_mgr_step_str((enum co_mgr_step)s->step));
			}
			s->sdo_wait = true;
			co_mgr_arm(s, SDO_WAIT_POLL_MS);
			return;
		}
		s->sdo_wait = false;
		next = boot_table[next].enter(s);
	}
}

static void sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	struct co_mgr_slave *s = user_data;

	/* Transfers dropped by our own reset are not boot results. */
	if (!s->sdo_pending || co_node_nmt_state(s->mgr->node) == CO_NMT_INITIALISING) {
		s->sdo_pending = false;
		return;
	}
	s->sdo_pending = false;
	if (!s->booting || boot_table[s->step].sdo == NULL) {
		return;
	}
	boot_run(s, boot_table[s->step].sdo(s, abort_code));
}

#if defined(CONFIG_CANOPEN_MGR_PGM)
BUILD_ASSERT(NEXT_WAIT == CO_MGR_NEXT_WAIT && NEXT_END == CO_MGR_NEXT_END);

uint8_t co_mgr_boot_fail(struct co_mgr_slave *s, uint8_t status, uint16_t index, uint8_t sub,
			 uint32_t expected, uint32_t actual, uint32_t abort_code)
{
	return fail(s, status, index, sub, expected, actual, abort_code);
}

uint8_t co_mgr_boot_upload(struct co_mgr_slave *s, uint16_t index, uint8_t sub)
{
	return upload(s, index, sub);
}

void co_mgr_boot_sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data)
{
	sdo_con(cli, abort_code, size, user_data);
}
#endif

void co_mgr_boot_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (boot_table[s->step].ec != NULL) {
		boot_run(s, boot_table[s->step].ec(s, byte));
	}
}

/* --- Boot process (302-2 §3.3) -----------------------------------------------------------------
 */

/* The master can run SDO transfers (CiA 301: not while Stopped or Initialising). */
static bool master_runs(struct co_mgr *m)
{
	enum co_nmt_state st = co_node_nmt_state(m->node);

	return st == CO_NMT_PRE_OPERATIONAL || st == CO_NMT_OPERATIONAL;
}

static void boot_attempt(struct co_mgr_slave *s)
{
	if (!master_runs(s->mgr)) {
		/* Stopped: the attempt starts when the master runs again (co_mgr_boot_resume()). */
		s->held = true;
		return;
	}
	s->held = false;
	s->booting = true;
	s->attempts++;
	s->status = CO_MGR_ST_NONE;
	s->read_mask = 0U;
	s->wait_reboot = false;
	s->start_deferred = false;
	s->cfg_wait = false;
	s->sdo_wait = false;
	/* The working record; co_mgr_get_boot() shows the last finished one until boot_end(). */
	(void)memset(&s->err, 0, sizeof(s->err));
	(void)memset(s->ident, 0, sizeof(s->ident));
	co_mgr_ec_stop(s);
	if (co_sdo_cli_busy(co_mgr_cli(s))) {
		s->sdo_pending = false;
		(void)co_sdo_cli_abort_req(co_mgr_cli(s), CO_SDO_AB_GENERAL);
	}
	(void)co_sdo_cli_set_server(co_mgr_cli(s), s->id);
	boot_run(s, CO_MGR_STEP_ASSIGNED);
}

void co_mgr_boot_process_start(struct co_mgr_slave *s)
{
	co_timer_stop(&s->timer);
	s->started_us = co_mgr_now(s->mgr);
	s->attempts = 0U;
	s->tried = false;
	boot_attempt(s);
}

void co_mgr_boot_expire(struct co_mgr_slave *s, uint64_t now_us)
{
	bool never_ran = s->held && !s->tried;

	if (!s->booting && !s->held && !co_timer_is_armed(&s->timer)) {
		return;
	}
	co_timer_stop(&s->timer);
	s->held = false;
	if (s->sdo_pending) {
		s->sdo_pending = false;
		(void)co_sdo_cli_abort_req(co_mgr_cli(s), CO_SDO_AB_TIMEOUT);
	}
	if (s->booting || never_ran) {
		(void)fail(s, CO_MGR_ST_B, IDX_BOOT_TIME, 0, co_mgr_od(s->mgr, IDX_BOOT_TIME, 0),
			   0U, 0U);
		s->booting = false;
		s->cfg_wait = false;
		s->sdo_wait = false;
		s->step = CO_MGR_STEP_IDLE;
		s->finished_us = now_us;
		publish(s);
	}
}

void co_mgr_boot_retry(struct co_mgr_slave *s)
{
	if (!master_runs(s->mgr)) {
		s->held = true;
		return;
	}
	co_mgr_arm(s, CONFIG_CANOPEN_MGR_RETRY_TIME);
}

void co_mgr_boot_abort_sdo(struct co_mgr_slave *s, uint32_t abort_code)
{
	/*
	 * The confirmation still comes (line thread): if the master really leaves, the boot is
	 * cancelled by then and it is ignored; if the change was refused, it ends the step.
	 */
	if (s->booting && s->sdo_pending && co_sdo_cli_busy(co_mgr_cli(s))) {
		(void)co_sdo_cli_abort_req(co_mgr_cli(s), abort_code);
	}
}

void co_mgr_boot_stopped(struct co_mgr_slave *s)
{
	bool xfer = s->sdo_pending;

	if (!s->booting) {
		return;
	}
	co_timer_stop(&s->timer);
	s->sdo_pending = false;
	/* An attempt that ended: B (retried), with the step and the transfer it was in. */
	(void)fail(s, CO_MGR_ST_B, xfer ? s->xfer_index : 0U, xfer ? s->xfer_sub : 0U, 0U,
		   CO_NMT_STOPPED, CO_SDO_AB_DATA_DEV_STATE);
	s->held = true;
	boot_end(s);
}

void co_mgr_boot_resume(struct co_mgr_slave *s)
{
	if (s->held && s->id != 0U) {
		s->held = false;
		/* From the line thread, after the SDO client confirmed the cut transfer. */
		co_node_timer_start(s->mgr->node, &s->timer, co_mgr_now(s->mgr));
	}
}

void co_mgr_boot_sdo_recheck(struct co_mgr *m)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && s->booting && s->sdo_wait) {
			/* From the slave's timer, once the SDO manager's own call has returned. */
			co_node_timer_start(m->node, &s->timer, co_mgr_now(m));
		}
	}
}

void co_mgr_slave_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr_slave *s = timer->user_data;

	if (s->booting && s->sdo_wait) {
		/* The step that waited for the default SDO: try it again. */
		boot_run(s, s->step);
		return;
	}
	if (s->booting) {
		if (boot_table[s->step].timeout != NULL) {
			boot_run(s, boot_table[s->step].timeout(s));
		}
		return;
	}
	if (s->wait_reboot) {
		s->wait_reboot = false;
		co_mgr_boot_process_start(s);
		return;
	}
	/* Retry (status B) within the running boot process. */
	boot_attempt(s);
}
