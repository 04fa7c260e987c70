/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT startup (CiA 302-2 §3.1, doc/mgr.md "Boot-up"): reset the slaves, boot every assigned
 * slave in parallel under the boot time 1F89h, wait for the mandatory ones, then enter
 * Operational and start the slaves (all at once or one by one, 1F80h). A mandatory failure
 * halts the startup so that nobody is started. The boot process's retries (302-2 §3.3) are
 * decided here because they depend on mandatory/optional and on 1F89h.
 */

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

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

void co_mgr_startup_halt_ec(struct co_mgr_slave *s, bool guarding)
{
	struct co_mgr_boot_error e = {
		.node_id = s->id,
		.status = guarding ? CO_MGR_ST_F : CO_MGR_ST_K,
		.step = CO_MGR_STEP_IDLE,
	};

	/* Boots that all ended go on to DONE (skipping S5/S6): nothing waits for the master. */
	if (co_mgr_mandatory_pending(s->mgr)) {
		halt(s->mgr, &e);
	}
}

bool co_mgr_mandatory_pending(struct co_mgr *m)
{
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *o = &m->slaves[i];

		if (o->id != 0U &&
		    (co_mgr_assign(m, o->id) & (AS_SLAVE | AS_MANDATORY)) ==
			    (AS_SLAVE | AS_MANDATORY) &&
		    !co_mgr_status_ok(o->status)) {
			return true;
		}
	}
	return false;
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
		as = co_mgr_assign(m, s->id);
		if ((as & AS_SLAVE) == 0U) {
			continue;
		}
		if ((as & AS_MANDATORY) != 0U && !co_mgr_status_ok(s->status)) {
			return;
		}
		if (!s->tried) {
			return;
		}
		all_ok = all_ok && co_mgr_status_ok(s->status);
	}
	co_timer_stop(&m->boot_timer);
	m->startup = CO_MGR_STARTUP_DONE;
	m->phase = PH_NONE;
	su = co_mgr_startup_obj(m);
	if (co_node_nmt_state(m->node) == CO_NMT_STOPPED) {
		/*
		 * An NMT Stop (of another device, or our error handler's "stop all") ended the
		 * boots: S5 and S6 are skipped, the master and the slaves stay as the command left
		 * them. Slaves booted later are started one by one (doc/mgr.md, "Decisions").
		 */
		LOG_WRN("%s: NMT startup complete while Stopped: nobody started", m->node->name);
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			m->slaves[i].start_deferred = false;
		}
		if (m->startup_ind != NULL) {
			m->startup_ind(m->node, CO_MGR_STARTUP_DONE, NULL, m->startup_user_data);
		}
		return;
	}
	LOG_INF("%s: NMT startup complete", m->node->name);
	if ((su & SU_NO_SELF_OP) == 0U) {
		(void)co_nmt_req(m->node, CO_NMT_CS_START);
	}
	if ((su & (SU_NO_START | SU_START_ALL)) == 0U) {
		for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
			struct co_mgr_slave *s = &m->slaves[i];

			if (s->id != 0U && s->start_deferred && s->status == CO_MGR_ST_OK) {
				(void)co_mgr_nmt_queue(m, CO_NMT_CS_START, s->id, false);
			}
			s->start_deferred = false;
		}
	}
	if ((su & (SU_NO_START | SU_START_ALL)) == SU_START_ALL) {
		if (all_ok) {
			(void)co_mgr_nmt_queue(m, CO_NMT_CS_START, 0U, false);
		} else {
			for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
				struct co_mgr_slave *s = &m->slaves[i];

				if (s->id != 0U && s->status == CO_MGR_ST_OK && !s->no_start) {
					(void)co_mgr_nmt_queue(m, CO_NMT_CS_START, s->id, false);
				}
			}
		}
	}
	if (m->startup_ind != NULL) {
		m->startup_ind(m->node, CO_MGR_STARTUP_DONE, NULL, m->startup_user_data);
	}
}

void co_mgr_startup_boot_ended(struct co_mgr_slave *s, bool mandatory, uint64_t now)
{
	struct co_mgr *m = s->mgr;

	if (!co_mgr_status_ok(s->status) && s->status != CO_MGR_ST_A) {
		uint32_t bt = co_mgr_od(m, IDX_BOOT_TIME, 0);

		if (mandatory) {
			if (s->status == CO_MGR_ST_B &&
			    (bt == 0U || !co_time_before_eq(s->started_us + MS_US(bt), now))) {
				co_mgr_boot_retry(s);
			} else {
				halt(m, &s->err);
			}
		} else if (s->status == CO_MGR_ST_B) {
			/* Optional slaves are polled in the background (§10 #9). */
			co_mgr_boot_retry(s);
		} else {
			/* An optional slave's other errors end its boot (reported already). */
		}
	}
	startup_check(m);
}

void co_mgr_boot_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;

	if (m->startup != CO_MGR_STARTUP_RUNNING) {
		return;
	}
	/* 1F89h expired: mandatory slaves still not booted end the startup with B. */
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];
		uint32_t as = s->id != 0U ? co_mgr_assign(m, s->id) : 0U;

		if ((as & (AS_SLAVE | AS_MANDATORY)) != (AS_SLAVE | AS_MANDATORY) ||
		    co_mgr_status_ok(s->status)) {
			continue;
		}
		co_mgr_boot_expire(s, now_us);
		halt(m, &s->err);
		return;
	}
}

void co_mgr_startup_resets_sent(struct co_mgr *m)
{
	m->phase = PH_BOOT;
	co_node_timer_start(m->node, &m->start_timer, co_mgr_now(m));
}

static void startup_begin(struct co_mgr *m)
{
	uint32_t su = co_mgr_startup_obj(m);
	bool keep = false;

	if ((su & SU_MASTER) == 0U) {
		m->phase = PH_NONE;
		if (su == SU_SELF_START) {
			(void)co_nmt_req(m->node, CO_NMT_CS_START);
		}
#if defined(CONFIG_CANOPEN_MGR_FLYING)
		if (su == (SU_SELF_START | SU_FLYING)) {
			/* 28h (CiA 302 only): a self-starting slave as 08h. */
			(void)co_nmt_req(m->node, CO_NMT_CS_START);
		} else if ((su & ~(uint32_t)SU_FLYING) == SU_START_ALL) {
			/* 02h: start the network only if no master-capable device answers. */
			co_mgr_fm_begin(m);
		} else {
			/* A slave that waits for a master's start command. */
		}
#endif
		return;
	}
#if defined(CONFIG_CANOPEN_MGR_FLYING)
	if ((su & SU_FLYING) != 0U && !co_mgr_fm_active(m)) {
		/* A candidate runs the startup once it won the negotiation (mgr_fm.c). */
		m->phase = PH_NONE;
		co_mgr_fm_begin(m);
		return;
	}
#endif
	m->startup = CO_MGR_STARTUP_RUNNING;
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (co_mgr_assign(m, s->id) & (AS_SLAVE | AS_KEEP_ALIVE)) ==
					   (AS_SLAVE | AS_KEEP_ALIVE)) {
			keep = true;
		}
	}
	/* S3: never reset ourselves; spare the keep-alive slaves (checked in boot part 2). */
	if (!keep) {
		(void)co_mgr_nmt_queue(m, CO_NMT_CS_RESET_COMMUNICATION, 0U, false);
	} else {
		for (uint8_t id = 1; id <= 127U; id++) {
			uint32_t as = co_mgr_assign(m, id);

			if (id == m->node->node_id ||
			    ((as & AS_SLAVE) != 0U && (as & AS_KEEP_ALIVE) != 0U)) {
				continue;
			}
			(void)co_mgr_nmt_queue(m, CO_NMT_CS_RESET_COMMUNICATION, id, false);
		}
	}
	/* S4 once the last reset is out (at once without an inhibit time). */
	m->phase = PH_RESETTING;
	if (m->nmt_count == 0U) {
		co_mgr_startup_resets_sent(m);
	}
}

static void startup_boot(struct co_mgr *m)
{
	uint32_t bt = co_mgr_od(m, IDX_BOOT_TIME, 0);

	m->phase = PH_BOOTING;
	/* A mandatory slave without a slot can never boot: the startup cannot complete. */
	for (uint8_t id = 1; id <= 127U; id++) {
		if (id != m->node->node_id && co_mgr_slot_find(m, id) == NULL &&
		    (co_mgr_assign(m, id) & (AS_SLAVE | AS_MANDATORY)) ==
			    (AS_SLAVE | AS_MANDATORY)) {
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
		co_node_timer_start(m->node, &m->boot_timer, co_mgr_now(m) + MS_US(bt));
	}
	for (int i = 0; i < CONFIG_CANOPEN_MGR_SLAVES; i++) {
		struct co_mgr_slave *s = &m->slaves[i];

		if (s->id != 0U && (co_mgr_assign(m, s->id) & AS_SLAVE) != 0U) {
			co_mgr_boot_process_start(s);
			if (m->startup != CO_MGR_STARTUP_RUNNING) {
				break;
			}
		}
	}
	startup_check(m);
}

/*
 * The startup process (CiA 302-2, NMT startup) as a const table: what the start timer does in
 * each phase. The phases without a step wait for something else: the NMT queue to send the
 * last reset (co_mgr_startup_resets_sent()), the boots to end (startup_check()).
 */
static const struct startup_phase {
	const char *name;
	void (*step)(struct co_mgr *m);
} startup_phases[] = {
	[PH_NONE] = {.name = "idle"},
	[PH_BEGIN] = {.name = "begin: reset the slaves", .step = startup_begin},
	[PH_RESETTING] = {.name = "resetting"},
	[PH_BOOT] = {.name = "boot every slave", .step = startup_boot},
	[PH_BOOTING] = {.name = "booting"},
};

/* Startup steps run from the line thread: after our own boot-up, and after the resets. */
void co_mgr_start_timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_mgr *m = timer->user_data;
	const struct startup_phase *p = &startup_phases[m->phase];

	ARG_UNUSED(now_us);
	if (p->step != NULL) {
		LOG_DBG("%s: startup: %s", m->node->name, p->name);
		p->step(m);
	}
}
