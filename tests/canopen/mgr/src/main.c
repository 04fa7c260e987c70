/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * NMT master and CiA 302-2 boot-up on a simulation line (simulated time, no thread).
 *
 * The master is node 01 (objdict/mgr_master.eds). Slaves are either scripted fakes (the
 * sink answers their SDO, NMT and guarding traffic; answers are fed back with co_line_rx()
 * at the same simulated time) or real SafeLine nodes on the same line (objdict/
 * mgr_slave.eds; they reach the master through local delivery). Every frame on the line is
 * logged with its time. Tests named test_s9_NN check row NN of spec/cia302-manager.md §9.
 *
 * The master's configuration (1F80h, 1F81h, ...) is applied by a restore callback, as a
 * storage module would after every reset.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#if defined(CONFIG_CANOPEN_CFG)
#include <canopen/cfg.h>
#endif
#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/sdo_abort.h>

#include "mgr_master_od.h"
#include "mgr_slave_od.h"

#define MASTER    0x01
#define MS        1000ULL
#define MAX_LOG   2048
#define MAX_CFG   64
#define MAX_OBJ   16
#define MAX_FAKES 12
#define MAX_PEND  512
#define LATENCY   200ULL /* µs */

struct cfg_entry {
	uint16_t index;
	uint8_t sub;
	uint8_t len;
	uint32_t value;
};

struct fake_obj {
	uint16_t index;
	uint8_t sub;
	uint32_t value;
	uint32_t abort_code;
};

struct fake {
	uint8_t id;
	bool present;
	bool answer_rtr;
	bool stuck_toggle; /* answers RTRs without toggling */
	uint8_t state;
	uint8_t toggle;
	uint16_t hb_ms;     /* 0: no heartbeat */
	bool hb_mute;       /* hangs: no heartbeat until reset */
	int dies_at_reset;  /* silent from this reset on (count), 0: never */
	bool mute_sdo;      /* present (NMT, boot-up, guarding) but never answers SDO */
	bool no_bootup;     /* comes back from a reset without a boot-up message */
	uint64_t bootup_us; /* time it needs to come back from a reset, 0: LATENCY */
	uint64_t up_at;     /* with bootup_us: ignores SDO requests before this time */
	int rtr_skip;       /* guarding RTRs left unanswered first */
	int n_aborts;       /* SDO abort frames received */
	uint32_t last_abort;
	uint64_t next_hb;
	struct fake_obj obj[MAX_OBJ];
	int n_obj;
	/* Downloads received (expedited). */
	struct fake_obj down[MAX_OBJ];
	int n_down;
	int n_resets;
};

struct logged {
	struct can_frame f;
	uint64_t at;
};

static struct {
	struct co_line line;
	struct co_node master;
	struct mgr_master_od_ram mram;
	struct co_node real[2];
	struct mgr_slave_od_ram sram[2];
	struct cfg_entry real_cfg[2][8];
	int n_real_cfg[2];
	struct cfg_entry cfg[MAX_CFG];
	int n_cfg;
	struct fake fakes[MAX_FAKES];
	int n_fakes;
	struct logged log[MAX_LOG];
	int n_log;
	struct can_frame pend[MAX_PEND];
	uint64_t pend_at[MAX_PEND];
	int n_pend;
	uint64_t now;
	/* Indications. */
	int n_boot_ind;
	uint8_t boot_id[64];
	uint8_t boot_status[64];
	struct co_mgr_boot_error boot_err[64];
	int n_startup_ind;
	enum co_mgr_startup startup_result;
	struct co_mgr_boot_error startup_err;
	int n_ec_ind;
	uint8_t ec_id[64];
	enum co_mgr_ec_event ec_ev[64];
	enum co_nmt_state ec_state[64];
	int sw_calls;
	int sw_result;
	int op_at_log;
#if defined(CONFIG_CANOPEN_CFG)
	struct co_cfg cfgm;
#endif
} t;

/* --- Fake slaves -------------------------------------------------------------------------- */

static struct fake *fake_add(uint8_t id)
{
	struct fake *f;

	zassert_true(t.n_fakes < MAX_FAKES);
	f = &t.fakes[t.n_fakes++];

	f->id = id;
	f->present = true;
	f->answer_rtr = true;
	f->state = 0x7f;
	return f;
}

static void fake_obj(struct fake *f, uint16_t index, uint8_t sub, uint32_t value,
		     uint32_t abort_code)
{
	f->obj[f->n_obj++] = (struct fake_obj){index, sub, value, abort_code};
}

/* A fake with the baseline identity: 1000h, 1018h:01..04, 1020h, 1F52h. */
static struct fake *fake_std(uint8_t id)
{
	struct fake *f = fake_add(id);

	fake_obj(f, 0x1000, 0, 0x00020192, 0);
	fake_obj(f, 0x1018, 1, 0x00000539, 0);
	fake_obj(f, 0x1018, 2, 0x00000042, 0);
	fake_obj(f, 0x1018, 3, 0x00010005, 0);
	fake_obj(f, 0x1018, 4, 0x00001234, 0);
	fake_obj(f, 0x1020, 1, 1000, 0);
	fake_obj(f, 0x1020, 2, 2000, 0);
	fake_obj(f, 0x1F52, 1, 3000, 0);
	fake_obj(f, 0x1F52, 2, 4000, 0);
	return f;
}

static struct fake *fake_find(uint8_t id)
{
	for (int i = 0; i < t.n_fakes; i++) {
		if (t.fakes[i].id == id) {
			return &t.fakes[i];
		}
	}
	return NULL;
}

/* Queue a frame of a fake for time @p at (kept in time order, FIFO for equal times). */
static void pend_at(uint32_t id, uint8_t dlc, const uint8_t *data, uint64_t at)
{
	struct can_frame f = {.id = id, .dlc = dlc};
	int i = t.n_pend;

	zassert_true(t.n_pend < MAX_PEND);
	memcpy(f.data, data, dlc);
	while (i > 0 && t.pend_at[i - 1] > at) {
		t.pend[i] = t.pend[i - 1];
		t.pend_at[i] = t.pend_at[i - 1];
		i--;
	}
	t.pend_at[i] = at;
	t.pend[i] = f;
	t.n_pend++;
}

static void pend(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	/* The fakes answer after a short bus and processing delay. */
	pend_at(id, dlc, data, t.now + LATENCY);
}

static void fake_ec(struct fake *f, uint8_t byte)
{
	pend(0x700 + f->id, 1, &byte);
}

static void fake_sdo(struct fake *f, const struct can_frame *rq)
{
	uint16_t index = rq->data[1] | (rq->data[2] << 8);
	uint8_t sub = rq->data[3];
	uint8_t r[8] = {0, rq->data[1], rq->data[2], sub};
	uint8_t ccs = rq->data[0] >> 5;

	if (ccs == 4) {
		/* An abort is never answered. */
		f->n_aborts++;
		f->last_abort = sys_get_le32(&rq->data[4]);
		return;
	}
	if (!f->present || f->mute_sdo || t.now < f->up_at) {
		return;
	}
	for (int i = 0; i < f->n_obj; i++) {
		struct fake_obj *o = &f->obj[i];

		if (o->index != index || o->sub != sub) {
			continue;
		}
		if (o->abort_code != 0U) {
			r[0] = 0x80;
			sys_put_le32(o->abort_code, &r[4]);
		} else if (ccs == 2) {
			r[0] = 0x43;
			sys_put_le32(o->value, &r[4]);
		} else if (ccs == 1) {
			r[0] = 0x60;
			zassert_true(f->n_down < MAX_OBJ);
			f->down[f->n_down++] =
				(struct fake_obj){index, sub, sys_get_le32(&rq->data[4]), 0};
			o->value = sys_get_le32(&rq->data[4]);
		} else {
			r[0] = 0x80;
			sys_put_le32(CO_SDO_AB_CMD, &r[4]);
		}
		pend(0x580 + f->id, 8, r);
		return;
	}
	if (ccs == 1 || ccs == 2) {
		r[0] = 0x80;
		sys_put_le32(CO_SDO_AB_NO_OBJECT, &r[4]);
		pend(0x580 + f->id, 8, r);
	}
}

static void fake_nmt(struct fake *f, uint8_t cs)
{
	switch (cs) {
	case 0x01:
		f->state = 0x05;
		break;
	case 0x02:
		f->state = 0x04;
		break;
	case 0x80:
		f->state = 0x7f;
		break;
	case 0x81:
	case 0x82:
		f->n_resets++;
		f->toggle = 0;
		f->hb_mute = false;
		if (f->dies_at_reset != 0 && f->n_resets >= f->dies_at_reset) {
			f->present = false;
		}
		f->state = 0x7f;
		if (f->present) {
			uint64_t back = t.now + (f->bootup_us != 0U ? f->bootup_us : LATENCY);
			uint8_t bootup = 0x00;

			/* A slave with its own boot time ignores SDO until it is back. */
			f->up_at = f->bootup_us != 0U ? back : 0U;
			if (!f->no_bootup) {
				pend_at(0x700 + f->id, 1, &bootup, back);
			}
			f->next_hb = (f->bootup_us != 0U ? back : t.now) + (uint64_t)f->hb_ms * MS;
		}
		break;
	default:
		break;
	}
}

static int sink(struct co_line *line, const struct can_frame *frame, void *user_data)
{
	zassert_true(t.n_log < MAX_LOG, "log full");
	t.log[t.n_log].f = *frame;
	t.log[t.n_log].at = t.now;
	t.n_log++;

	if (frame->id == 0x000 && frame->dlc == 2) {
		for (int i = 0; i < t.n_fakes; i++) {
			if (frame->data[1] == 0 || frame->data[1] == t.fakes[i].id) {
				fake_nmt(&t.fakes[i], frame->data[0]);
			}
		}
		return 0;
	}
	if (frame->id > 0x600 && frame->id <= 0x67f) {
		struct fake *f = fake_find(frame->id - 0x600);

		if (f != NULL) {
			fake_sdo(f, frame);
		}
		return 0;
	}
	if (frame->id > 0x700 && frame->id <= 0x77f && (frame->flags & CAN_FRAME_RTR) != 0U) {
		struct fake *f = fake_find(frame->id - 0x700);

		if (f != NULL && f->present && f->answer_rtr && f->rtr_skip > 0) {
			f->rtr_skip--;
		} else if (f != NULL && f->present && f->answer_rtr) {
			fake_ec(f, (uint8_t)(f->state | f->toggle));
			if (!f->stuck_toggle) {
				f->toggle ^= 0x80;
			}
		}
	}
	return 0;
}

/* --- Simulated time ------------------------------------------------------------------------ */

static void settle(void)
{
	for (int guard = 0; guard < 10000; guard++) {
		bool did = false;

		if (t.n_pend > 0 && t.pend_at[0] <= t.now) {
			struct can_frame f = t.pend[0];

			memmove(&t.pend[0], &t.pend[1], (size_t)(t.n_pend - 1) * sizeof(t.pend[0]));
			memmove(&t.pend_at[0], &t.pend_at[1],
				(size_t)(t.n_pend - 1) * sizeof(t.pend_at[0]));
			t.n_pend--;
			co_line_rx(&t.line, &f, t.now);
			did = true;
		}
		if (k_msgq_num_used_get(&t.line.rxq) > 0U) {
			co_line_process(&t.line, t.now);
			did = true;
		}
		if (!did) {
			return;
		}
	}
	zassert_unreachable("the line does not settle");
}

static uint64_t next_fake_hb(void)
{
	uint64_t next = UINT64_MAX;

	for (int i = 0; i < t.n_fakes; i++) {
		struct fake *f = &t.fakes[i];

		if (f->present && f->hb_ms != 0U && !f->hb_mute && f->next_hb < next) {
			next = f->next_hb;
		}
	}
	return next;
}

static void fake_hb_due(void)
{
	for (int i = 0; i < t.n_fakes; i++) {
		struct fake *f = &t.fakes[i];

		if (f->present && f->hb_ms != 0U && !f->hb_mute && f->next_hb <= t.now) {
			fake_ec(f, f->state);
			f->next_hb = t.now + (uint64_t)f->hb_ms * MS;
		}
	}
}

static void run_until(uint64_t at)
{
	settle();
	for (int guard = 0; guard < 100000; guard++) {
		uint64_t next = co_line_next_deadline(&t.line);
		uint64_t hb = next_fake_hb();

		if (hb < next) {
			next = hb;
		}
		if (t.n_pend > 0 && t.pend_at[0] < next) {
			next = t.pend_at[0];
		}
		if (next > at) {
			break;
		}
		if (next > t.now) {
			t.now = next;
		}
		fake_hb_due();
		co_line_process(&t.line, t.now);
		settle();
	}
	t.now = at;
	fake_hb_due();
	co_line_process(&t.line, t.now);
	settle();
}

static void run_for(uint64_t us)
{
	run_until(t.now + us);
}

/* --- Master configuration -------------------------------------------------------------------- */

static void cfg(uint16_t index, uint8_t sub, uint32_t value, uint8_t len)
{
	zassert_true(t.n_cfg < MAX_CFG);
	t.cfg[t.n_cfg++] = (struct cfg_entry){index, sub, len, value};
}

static void apply_cfg(struct co_od *od, const struct cfg_entry *c, int n)
{
	for (int i = 0; i < n; i++) {
		uint8_t buf[4];

		sys_put_le32(c[i].value, buf);
		zassert_equal(
			co_od_write(od, c[i].index, c[i].sub, buf, c[i].len, CO_OD_WRITER_STORAGE),
			0U, "config %04x:%02x", c[i].index, c[i].sub);
	}
}

static void master_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		apply_cfg(od, t.cfg, t.n_cfg);
	}
}

static void real_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	int i = (int)(intptr_t)user_data;

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) != 0U) {
		apply_cfg(od, t.real_cfg[i], t.n_real_cfg[i]);
	}
}

static uint32_t od_write_u(struct co_node *node, uint16_t index, uint8_t sub, uint32_t value,
			   size_t len, enum co_od_writer w)
{
	uint8_t buf[4];
	uint32_t ab;

	sys_put_le32(value, buf);
	co_node_lock(node);
	ab = co_od_write(co_node_od(node), index, sub, buf, len, w);
	co_node_unlock(node);
	return ab;
}

static uint32_t od_read_u(struct co_node *node, uint16_t index, uint8_t sub)
{
	uint8_t buf[8] = {0};
	size_t len = 0;

	co_node_lock(node);
	zassert_equal(co_od_read(co_node_od(node), index, sub, 0, buf, sizeof(buf), &len,
				 CO_OD_WRITER_SDO),
		      0U);
	co_node_unlock(node);
	return (uint32_t)co_od_le_get(buf, len);
}

/* Baseline of §9: slaves 02..04 optional with boot (05h), 1F80h = 01h. */
static void baseline(void)
{
	cfg(0x1F80, 0, 0x01, 4);
	for (uint8_t id = 2; id <= 4; id++) {
		cfg(0x1F81, id, 0x05, 4);
	}
}

static void boot_ind(struct co_node *node, uint8_t id, uint8_t status,
		     const struct co_mgr_boot_error *err, void *user_data)
{
	if (t.n_boot_ind < 64) {
		t.boot_id[t.n_boot_ind] = id;
		t.boot_status[t.n_boot_ind] = status;
		if (err != NULL) {
			t.boot_err[t.n_boot_ind] = *err;
			zassert_equal(err->node_id, id);
			zassert_equal(err->status, status);
		}
		t.n_boot_ind++;
	}
}

static void startup_ind(struct co_node *node, enum co_mgr_startup result,
			const struct co_mgr_boot_error *err, void *user_data)
{
	t.n_startup_ind++;
	t.startup_result = result;
	if (err != NULL) {
		t.startup_err = *err;
	}
}

static void ec_ind(struct co_node *node, uint8_t id, enum co_mgr_ec_event ev,
		   enum co_nmt_state state, void *user_data)
{
	if (t.n_ec_ind < 64) {
		t.ec_id[t.n_ec_ind] = id;
		t.ec_ev[t.n_ec_ind] = ev;
		t.ec_state[t.n_ec_ind] = state;
		t.n_ec_ind++;
	}
}

static int sw_ind(struct co_node *node, uint8_t id, uint32_t ed, uint32_t et, uint32_t ad,
		  uint32_t at, void *user_data)
{
	t.sw_calls++;
	return t.sw_result;
}

static int master_state_ind(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
			    void *user_data)
{
	if (to == CO_NMT_OPERATIONAL && t.op_at_log < 0) {
		t.op_at_log = t.n_log;
	}
	return 0;
}

static void start_master(void)
{
	zassert_ok(co_node_start(&t.master));
}

static void add_real(int i, uint8_t id)
{
	zassert_ok(co_node_init(&t.real[i], i == 0 ? "s0" : "s1", &t.line, &mgr_slave_od_def,
				&t.sram[i], id));
	co_od_set_restore_cb(co_node_od(&t.real[i]), real_restore, (void *)(intptr_t)i);
	zassert_ok(co_node_start(&t.real[i]));
}

static void real_cfg(int i, uint16_t index, uint8_t sub, uint32_t value, uint8_t len)
{
	t.real_cfg[i][t.n_real_cfg[i]++] = (struct cfg_entry){index, sub, len, value};
}

static void before(void *unused)
{
	memset(&t, 0, sizeof(t));
	co_line_init_sim(&t.line, "sim", sink, NULL);
	zassert_ok(co_node_init(&t.master, "master", &t.line, &mgr_master_od_def, &t.mram, MASTER));
	co_od_set_restore_cb(co_node_od(&t.master), master_restore, NULL);
#if defined(CONFIG_CANOPEN_CFG)
	zassert_ok(co_cfg_init(&t.cfgm, &t.master));
#endif
	co_mgr_set_boot_ind(&t.master, boot_ind, NULL);
	co_mgr_set_startup_ind(&t.master, startup_ind, NULL);
	co_mgr_set_ec_ind(&t.master, ec_ind, NULL);
	co_mgr_set_sw_ind(&t.master, sw_ind, NULL);
	co_nmt_set_state_ind(&t.master, master_state_ind, NULL);
	t.op_at_log = -1;
}

ZTEST_SUITE(co_mgr, NULL, NULL, before, NULL, NULL);

/* --- Log queries ---------------------------------------------------------------------------- */

static bool is_nmt(const struct can_frame *f, uint8_t cs, uint8_t id)
{
	return f->id == 0x000 && f->dlc == 2 && f->data[0] == cs && f->data[1] == id;
}

static int count_nmt(uint8_t cs, uint8_t id)
{
	int n = 0;

	for (int i = 0; i < t.n_log; i++) {
		n += is_nmt(&t.log[i].f, cs, id) ? 1 : 0;
	}
	return n;
}

static int count_nmt_cs(uint8_t cs)
{
	int n = 0;

	for (int i = 0; i < t.n_log; i++) {
		n += t.log[i].f.id == 0 && t.log[i].f.data[0] == cs ? 1 : 0;
	}
	return n;
}

static int first_nmt(uint8_t cs, uint8_t id)
{
	for (int i = 0; i < t.n_log; i++) {
		if (is_nmt(&t.log[i].f, cs, id)) {
			return i;
		}
	}
	return -1;
}

/* SDO request to @p id for index:sub (upload if @p up), -1 for any index. */
static bool is_sdo(const struct can_frame *f, uint8_t id, bool up, int index, int sub)
{
	if (f->id != 0x600U + id || f->dlc != 8) {
		return false;
	}
	if (up ? (f->data[0] != 0x40) : ((f->data[0] >> 5) != 1)) {
		return false;
	}
	return (index < 0 || (f->data[1] | (f->data[2] << 8)) == index) &&
	       (sub < 0 || f->data[3] == sub);
}

static int count_sdo(uint8_t id, bool up, int index, int sub)
{
	int n = 0;

	for (int i = 0; i < t.n_log; i++) {
		n += is_sdo(&t.log[i].f, id, up, index, sub) ? 1 : 0;
	}
	return n;
}

static int first_sdo(uint8_t id, bool up, int index, int sub)
{
	for (int i = 0; i < t.n_log; i++) {
		if (is_sdo(&t.log[i].f, id, up, index, sub)) {
			return i;
		}
	}
	return -1;
}

static int count_rtr(uint8_t id)
{
	int n = 0;

	for (int i = 0; i < t.n_log; i++) {
		n += t.log[i].f.id == 0x700U + id && (t.log[i].f.flags & CAN_FRAME_RTR) ? 1 : 0;
	}
	return n;
}

static int count_ec(uint8_t id, enum co_mgr_ec_event ev)
{
	int n = 0;

	for (int i = 0; i < t.n_ec_ind; i++) {
		n += t.ec_id[i] == id && t.ec_ev[i] == ev ? 1 : 0;
	}
	return n;
}

static int last_boot_status(uint8_t id)
{
	for (int i = t.n_boot_ind - 1; i >= 0; i--) {
		if (t.boot_id[i] == id) {
			return t.boot_status[i];
		}
	}
	return -1;
}

static const struct co_mgr_boot_error *last_boot_err(uint8_t id)
{
	for (int i = t.n_boot_ind - 1; i >= 0; i--) {
		if (t.boot_id[i] == id) {
			return &t.boot_err[i];
		}
	}
	return NULL;
}

static enum co_nmt_state master_state(void)
{
	return co_nmt_get_state(&t.master);
}

/* --- NMT startup (302-2 §3.1) --------------------------------------------------------------- */

ZTEST(co_mgr, test_s9_01_one_reset_comm_all_after_bootup_before_any_sdo)
{
	baseline();
	fake_std(2);
	fake_std(3);
	fake_std(4);
	start_master();
	run_for(10 * MS);
	zassert_true(t.n_log > 2);
	zassert_equal(t.log[0].f.id, 0x701, "own boot-up first");
	zassert_equal(t.log[0].f.data[0], 0x00);
	zassert_true(is_nmt(&t.log[1].f, 0x82, 0x00), "then 000#8200");
	zassert_equal(count_nmt(0x82, 0x00), 1, "exactly one");
	zassert_equal(count_nmt_cs(0x82), 1, "no individual resets");
	zassert_true(first_sdo(2, true, -1, -1) > 1);
}

ZTEST(co_mgr, test_s9_02_keep_alive_slave_gets_individual_resets_for_all_other_ids)
{
	baseline();
	cfg(0x1F81, 3, 0x15, 4); /* slave, boot, keep-alive */
	cfg(0x1016, 1, (3U << 16) | 500U, 4);
	fake_std(2);
	fake_std(3)->hb_ms = 100;
	fake_std(4);
	start_master();
	run_for(10 * MS);
	zassert_equal(count_nmt(0x82, 0x00), 0, "no broadcast reset");
	for (int id = 2; id <= 127; id++) {
		zassert_equal(count_nmt(0x82, id), id == 3 ? 0 : 1, "reset of %d", id);
	}
	zassert_equal(count_nmt(0x82, MASTER), 0);
	zassert_equal(count_nmt_cs(0x82), 125);
}

ZTEST(co_mgr, test_s9_03_master_never_resets_itself_and_stays_alive)
{
	baseline();
	fake_std(2);
	fake_std(3);
	fake_std(4);
	start_master();
	run_for(2000 * MS);
	zassert_equal(count_nmt(0x82, MASTER) + count_nmt(0x81, MASTER), 0);
	zassert_equal(count_nmt(0x81, 0), 0);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	/* Only one boot-up of the master: it was not reset by its own 000#8200. */
	int bootups = 0;

	for (int i = 0; i < t.n_log; i++) {
		bootups += t.log[i].f.id == 0x701 && t.log[i].f.data[0] == 0 ? 1 : 0;
	}
	zassert_equal(bootups, 1);
}

/* --- Boot NMT slave: identity (302-2 §3.4) ------------------------------------------------- */

ZTEST(co_mgr, test_s9_04_first_sdo_to_slave_is_upload_of_1000h)
{
	baseline();
	fake_std(2);
	start_master();
	run_for(10 * MS);
	int i = first_sdo(2, true, -1, -1);

	zassert_true(i >= 0);
	zassert_true(is_sdo(&t.log[i].f, 2, true, 0x1000, 0));
	zassert_equal(t.log[i].f.data[0], 0x40);
}

ZTEST(co_mgr, test_s9_05_1f84h_zero_reads_1000h_and_accepts_any)
{
	baseline();
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(count_sdo(2, true, 0x1000, 0), 1);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
}

ZTEST(co_mgr, test_s9_06_device_type_mismatch_is_C_without_1018h_upload)
{
	baseline();
	cfg(0x1F84, 2, 0x00000191, 4);
	cfg(0x1F85, 2, 0x00000539, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_C);
	const struct co_mgr_boot_error *e = last_boot_err(2);

	zassert_equal(e->step, CO_MGR_STEP_DEVTYPE);
	zassert_equal(e->index, 0x1000);
	zassert_equal(e->expected, 0x00000191);
	zassert_equal(e->actual, 0x00020192);
	zassert_equal(count_sdo(2, true, 0x1018, -1), 0);
	zassert_equal(count_nmt(0x01, 2), 0, "not started");
}

ZTEST(co_mgr, test_s9_07_vendor_zero_is_not_read)
{
	baseline();
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(count_sdo(2, true, 0x1018, -1), 0);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
}

ZTEST(co_mgr, test_s9_08_vendor_mismatch_is_D)
{
	baseline();
	cfg(0x1F85, 2, 0x00000540, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_D);
	zassert_equal(last_boot_err(2)->index, 0x1018);
	zassert_equal(last_boot_err(2)->sub, 1);
	zassert_equal(last_boot_err(2)->expected, 0x540);
	zassert_equal(last_boot_err(2)->actual, 0x539);
}

ZTEST(co_mgr, test_s9_09_product_mismatch_is_M_serial_mismatch_is_O)
{
	baseline();
	cfg(0x1F86, 2, 0x00000043, 4);
	cfg(0x1F88, 3, 0x00001235, 4);
	fake_std(2);
	fake_std(3);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_M);
	zassert_equal(last_boot_err(2)->sub, 2);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_PRODUCT);
	zassert_equal(last_boot_status(3), CO_MGR_ST_O);
	zassert_equal(last_boot_err(3)->sub, 4);
	zassert_equal(last_boot_err(3)->actual, 0x1234);
}

ZTEST(co_mgr, test_s9_10_revision_same_major_higher_or_equal_minor_passes)
{
	baseline();
	cfg(0x1F87, 2, 0x00010005, 4); /* slave 2 reports 00010007h */
	cfg(0x1F87, 3, 0x00010005, 4); /* slave 3 reports 00010005h: equal minor passes */
	fake_std(2)->obj[3].value = 0x00010007;
	fake_std(3);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(last_boot_status(3), CO_MGR_ST_OK);
}

ZTEST(co_mgr, test_s9_11_revision_other_major_or_lower_minor_is_N)
{
	baseline();
	cfg(0x1F87, 2, 0x00010005, 4);
	cfg(0x1F87, 3, 0x00010005, 4);
	fake_std(2)->obj[3].value = 0x00020005;
	fake_std(3)->obj[3].value = 0x00010004;
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_N);
	zassert_equal(last_boot_status(3), CO_MGR_ST_N);
	zassert_equal(last_boot_err(3)->actual, 0x00010004);
}

ZTEST(co_mgr, test_s9_12_identity_upload_order_only_nonzero_expectations)
{
	baseline();
	cfg(0x1F85, 2, 0x00000539, 4);
	cfg(0x1F86, 2, 0x00000042, 4);
	cfg(0x1F88, 2, 0x00001234, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	int a = first_sdo(2, true, 0x1000, 0);
	int b = first_sdo(2, true, 0x1018, 1);
	int c = first_sdo(2, true, 0x1018, 2);
	int d = first_sdo(2, true, 0x1018, 4);

	zassert_true(a >= 0 && a < b && b < c && c < d, "%d %d %d %d", a, b, c, d);
	zassert_equal(count_sdo(2, true, 0x1018, 3), 0, "1F87h = 0: revision not read");
	struct co_mgr_boot_info bi;

	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_equal(bi.device_type, 0x00020192);
	zassert_equal(bi.identity[0], 0x539);
	zassert_equal(bi.identity[3], 0x1234);
	zassert_equal(bi.read_mask, BIT(0) | BIT(1) | BIT(2) | BIT(4));
	zassert_equal(bi.status, CO_MGR_ST_OK);
	zassert_true(bi.finished_us >= bi.started_us && bi.finished_us != 0U);
	zassert_equal(bi.attempts, 1);
}

ZTEST(co_mgr, test_s9_13_optional_absent_polled_every_second_startup_completes)
{
	baseline();
	fake_std(2);
	fake_std(3)->present = false;
	fake_std(4);
	start_master();
	run_for(5500 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	int n = count_sdo(3, true, 0x1000, 0);

	/* 100 ms SDO timeout + 1 s retry: an attempt about every 1.1 s. */
	zassert_between_inclusive(n, 5, 6, "%d attempts", n);
	zassert_equal(last_boot_status(3), CO_MGR_ST_B);
	zassert_equal(last_boot_err(3)->abort_code, CO_SDO_AB_TIMEOUT);
	/* Found once it answers, and started individually. */
	t.fakes[1].present = true;
	run_for(1200 * MS);
	zassert_equal(last_boot_status(3), CO_MGR_ST_OK);
	zassert_equal(count_nmt(0x01, 3), 1);
}

ZTEST(co_mgr, test_s9_14_mandatory_absent_halts_after_boot_time)
{
	baseline();
	cfg(0x1F81, 3, 0x0D, 4);
	cfg(0x1F89, 0, 3000, 4);
	cfg(0x1017, 0, 100, 2);
	fake_std(2);
	fake_std(3)->present = false;
	fake_std(4);
	start_master();
	run_for(2900 * MS);
	zassert_equal(t.n_startup_ind, 0);
	run_for(200 * MS);
	zassert_equal(t.n_startup_ind, 1, "application notified at 1F89h");
	zassert_equal(t.startup_result, CO_MGR_STARTUP_HALTED);
	zassert_equal(t.startup_err.node_id, 3);
	zassert_equal(t.startup_err.status, CO_MGR_ST_B);
	run_for(2000 * MS);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(count_nmt_cs(0x01), 0, "no NMT start at all");
	/* Own heartbeat says pre-operational. */
	zassert_equal(t.log[t.n_log - 1].f.id, 0x701);
	zassert_equal(t.log[t.n_log - 1].f.data[0], 0x7f);
}

ZTEST(co_mgr, test_s9_15_mandatory_absent_without_boot_time_polls_forever)
{
	baseline();
	cfg(0x1F81, 3, 0x0D, 4);
	fake_std(2);
	fake_std(3)->present = false;
	start_master();
	run_for(20000 * MS);
	zassert_equal(t.n_startup_ind, 0);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
	zassert_true(count_sdo(3, true, 0x1000, 0) >= 17);
	zassert_equal(count_nmt_cs(0x01), 0, "nothing started while a mandatory slave is missing");
	t.fakes[1].present = true;
	run_for(1200 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_equal(count_nmt(0x01, 2), 1, "then each is started individually");
	zassert_equal(count_nmt(0x01, 3), 1);
	zassert_equal(count_nmt(0x01, 0), 0);
}

ZTEST(co_mgr, test_s9_16_mandatory_check_failure_halts_at_once)
{
	baseline();
	cfg(0x1F81, 2, 0x0D, 4);
	cfg(0x1F84, 2, 0x00000191, 4);
	cfg(0x1F89, 0, 10000, 4);
	fake_std(2);
	fake_std(3);
	start_master();
	run_for(100 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_HALTED);
	zassert_equal(t.startup_err.status, CO_MGR_ST_C);
	zassert_equal(t.startup_err.node_id, 2);
	run_for(2000 * MS);
	zassert_equal(count_sdo(2, true, 0x1000, 0), 1, "no retry of C");
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
}

ZTEST(co_mgr, test_error_A_node_not_in_1f81h)
{
	baseline();
	fake_std(5);
	start_master();
	run_for(100 * MS);
	zassert_ok(co_mgr_boot_req(&t.master, 5));
	run_for(100 * MS);
	zassert_equal(last_boot_status(5), CO_MGR_ST_A);
	zassert_equal(last_boot_err(5)->index, 0x1F81);
	zassert_equal(count_sdo(5, true, -1, -1), 0);
}

/* --- Starting the slaves (302-2 §3.1 g-h, §3.4 j-l) ---------------------------------------- */

ZTEST(co_mgr, test_s9_17_individual_start_right_after_each_boot)
{
	baseline();
	fake_std(2);
	fake_std(3);
	fake_std(4);
	start_master();
	run_for(500 * MS);
	zassert_equal(count_nmt(0x01, 0), 0);
	for (uint8_t id = 2; id <= 4; id++) {
		zassert_equal(count_nmt(0x01, id), 1);
		/* Right after the last SDO of that slave. */
		int s = first_nmt(0x01, id);
		int last = -1;

		for (int i = 0; i < t.n_log; i++) {
			if (t.log[i].f.id == 0x600U + id) {
				last = i;
			}
		}
		zassert_true(last >= 0 && s > last);
	}
}

ZTEST(co_mgr, test_s9_18_start_all_broadcast_after_master_operational)
{
	cfg(0x1F80, 0, 0x03, 4);
	cfg(0x1017, 0, 50, 2);
	for (uint8_t id = 2; id <= 4; id++) {
		cfg(0x1F81, id, 0x05, 4);
		fake_std(id);
	}
	start_master();
	run_for(500 * MS);
	zassert_equal(count_nmt(0x01, 0), 1);
	zassert_equal(count_nmt_cs(0x01), 1, "no individual starts");
	/* The master went Operational (S5) before the broadcast (S6). */
	int start = first_nmt(0x01, 0);

	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_true(t.op_at_log >= 0 && t.op_at_log <= start, "%d %d", t.op_at_log, start);
	zassert_true(start > first_sdo(4, true, 0x1000, 0));
	run_for(200 * MS);
	int hb = -1;

	for (int i = start; i < t.n_log; i++) {
		if (t.log[i].f.id == 0x701) {
			hb = t.log[i].f.data[0];
			break;
		}
	}
	zassert_equal(hb, 0x05, "own heartbeat says Operational");
}

ZTEST(co_mgr, test_s9_19_start_all_with_missing_optional_starts_individually)
{
	cfg(0x1F80, 0, 0x03, 4);
	for (uint8_t id = 2; id <= 4; id++) {
		cfg(0x1F81, id, 0x05, 4);
		fake_std(id);
	}
	t.fakes[2].present = false;
	start_master();
	/* The absent slave is tried once its boot-up wait is over. */
	run_for((CONFIG_CANOPEN_MGR_BOOTUP_WAIT + 500) * MS);
	zassert_equal(count_nmt(0x01, 0), 0);
	zassert_equal(count_nmt(0x01, 2), 1);
	zassert_equal(count_nmt(0x01, 3), 1);
	zassert_equal(count_nmt(0x01, 4), 0);
}

ZTEST(co_mgr, test_s9_20_bit3_master_never_starts_slaves)
{
	for (uint32_t su = 0x09; su <= 0x0B; su += 2) {
		before(NULL);
		cfg(0x1F80, 0, su, 4);
		for (uint8_t id = 2; id <= 4; id++) {
			cfg(0x1F81, id, 0x05, 4);
			fake_std(id);
		}
		start_master();
		run_for(3000 * MS);
		zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
		zassert_equal(count_nmt_cs(0x01), 0, "1F80h %02x", su);
		/* A late boot-up is booted but not started either. */
		fake_ec(&t.fakes[0], 0x00);
		run_for(500 * MS);
		zassert_equal(count_sdo(2, true, 0x1000, 0), 2);
		zassert_equal(count_nmt_cs(0x01), 0);
	}
}

ZTEST(co_mgr, test_s9_21_bit2_master_stays_preoperational)
{
	cfg(0x1F80, 0, 0x05, 4);
	cfg(0x1F81, 2, 0x05, 4);
	fake_std(2);
	start_master();
	run_for(3000 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
	zassert_equal(count_nmt(0x01, 2), 1, "the slave is still started");
}

ZTEST(co_mgr, test_s9_22_late_bootup_is_booted_and_started_individually)
{
	cfg(0x1F80, 0, 0x03, 4);
	for (uint8_t id = 2; id <= 4; id++) {
		cfg(0x1F81, id, 0x05, 4);
		fake_std(id);
	}
	start_master();
	run_for(500 * MS);
	zassert_equal(count_nmt(0x01, 0), 1);
	fake_ec(&t.fakes[2], 0x00);
	run_for(500 * MS);
	zassert_equal(count_sdo(4, true, 0x1000, 0), 2);
	zassert_equal(count_nmt(0x01, 4), 1);
	zassert_equal(count_nmt(0x01, 0), 1, "never a second broadcast");
}

ZTEST(co_mgr, test_s9_23_bootup_of_unassigned_node_is_only_indicated)
{
	baseline();
	fake_std(2);
	fake_std(5);
	start_master();
	run_for(500 * MS);
	int n = t.n_ec_ind;

	fake_ec(&t.fakes[1], 0x00);
	run_for(500 * MS);
	zassert_equal(count_sdo(5, true, -1, -1), 0);
	zassert_equal(count_nmt(0x01, 5), 0);
	zassert_true(t.n_ec_ind > n);
	zassert_equal(t.ec_id[t.n_ec_ind - 1], 5);
	zassert_equal(t.ec_ev[t.n_ec_ind - 1], CO_MGR_EC_BOOTUP);
}

ZTEST(co_mgr, test_s9_24_no_boot_bit_means_no_sdo_and_no_start)
{
	baseline();
	cfg(0x1F81, 4, 0x01, 4);
	fake_std(4);
	start_master();
	run_for(500 * MS);
	fake_ec(&t.fakes[0], 0x00);
	run_for(500 * MS);
	zassert_equal(count_sdo(4, true, -1, -1), 0);
	zassert_equal(count_nmt(0x01, 4), 0);
	zassert_equal(last_boot_status(4), CO_MGR_ST_OK, "error control only");
}

/* --- Keep-alive and check NMT state (302-2 §3.4 part 2, §3.6) ------------------------------ */

ZTEST(co_mgr, test_s9_25_keep_alive_operational_slave_is_L_without_reset_or_checks)
{
	baseline();
	cfg(0x1F81, 2, 0x35, 4); /* slave, boot, keep-alive, SW check */
	cfg(0x1016, 1, (2U << 16) | 500U, 4);
	cfg(0x1F26, 2, 1000, 4);
	cfg(0x1F27, 2, 2000, 4);
	struct fake *f = fake_std(2);

	f->state = 0x05;
	f->hb_ms = 100;
	f->next_hb = 50 * MS;
	start_master();
	/* Slaves 3 and 4 are absent: tried after their boot-up wait. */
	run_for((CONFIG_CANOPEN_MGR_BOOTUP_WAIT + 500) * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_L);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_START);
	zassert_equal(count_nmt(0x82, 2) + count_nmt(0x81, 2), 0, "never reset");
	zassert_equal(count_sdo(2, true, 0x1F52, -1), 0);
	zassert_equal(count_sdo(2, true, 0x1020, -1), 0);
	zassert_equal(count_nmt(0x01, 2), 0, "no start needed");
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE, "L counts as booted");
}

ZTEST(co_mgr, test_s9_26_keep_alive_preoperational_slave_is_reset_then_booted_on)
{
	baseline();
	cfg(0x1F81, 2, 0x15, 4);
	cfg(0x1016, 1, (2U << 16) | 500U, 4);
	cfg(0x1F26, 2, 1000, 4);
	cfg(0x1F27, 2, 2000, 4);
	struct fake *f = fake_std(2);

	f->hb_ms = 100;
	f->next_hb = 50 * MS;
	start_master();
	run_for(1000 * MS);
	int reset = first_nmt(0x82, 2);

	zassert_true(reset >= 0, "000#8202");
	zassert_true(first_sdo(2, true, 0x1020, 1) > reset, "configuration check after it");
	zassert_true(first_sdo(2, true, 0x1000, 0) < reset, "identity before it");
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(count_nmt(0x01, 2), 1);
}

ZTEST(co_mgr, test_s9_27_keep_alive_without_heartbeat_is_E)
{
	baseline();
	cfg(0x1F81, 2, 0x15, 4);
	cfg(0x1016, 1, (2U << 16) | 300U, 4);
	fake_std(2);
	start_master();
	run_for(1000 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_E);
	zassert_equal(last_boot_err(2)->index, 0x1016);
	zassert_equal(last_boot_err(2)->expected, 300);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_KEEP_ALIVE);
}

ZTEST(co_mgr, test_s9_28_keep_alive_guarded_without_reply_is_F_after_100ms)
{
	baseline();
	cfg(0x1F81, 2, 0x15, 4);
	fake_std(2)->answer_rtr = false;
	start_master();
	run_for(99 * MS);
	zassert_equal(count_rtr(2), 1, "one RTR");
	zassert_equal(last_boot_status(2), -1);
	run_for(5 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_F);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_KEEP_ALIVE);
}

ZTEST(co_mgr, test_keep_alive_guarded_operational_reply_is_L)
{
	baseline();
	cfg(0x1F81, 2, 0x15, 4);
	fake_std(2)->state = 0x05;
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_L);
	zassert_equal(count_nmt(0x82, 2), 0);
}

/* --- Software version (302 §4 step 4) -------------------------------------------------------- */

ZTEST(co_mgr, test_s9_29_sw_check_without_expected_version_is_G_without_1f52h)
{
	baseline();
	cfg(0x1F81, 2, 0x25, 4);
	cfg(0x1F53, 2, 3000, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_G);
	zassert_equal(last_boot_err(2)->index, 0x1F54);
	zassert_equal(count_sdo(2, true, 0x1F52, -1), 0);
}

ZTEST(co_mgr, test_s9_30_sw_mismatch_without_update_is_H)
{
	baseline();
	cfg(0x1F81, 2, 0x25, 4);
	cfg(0x1F53, 2, 3000, 4);
	cfg(0x1F54, 2, 4001, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_H);
	zassert_equal(last_boot_err(2)->index, 0x1F52);
	zassert_equal(last_boot_err(2)->sub, 2);
	zassert_equal(last_boot_err(2)->expected, 4001);
	zassert_equal(last_boot_err(2)->actual, 4000);
	zassert_equal(t.sw_calls, 0);
}

ZTEST(co_mgr, test_s9_31_sw_update_failure_is_I_success_boots_on)
{
	baseline();
	cfg(0x1F81, 2, 0x65, 4);
	cfg(0x1F81, 3, 0x65, 4);
	cfg(0x1F53, 2, 3001, 4);
	cfg(0x1F54, 2, 4000, 4);
	cfg(0x1F53, 3, 3000, 4);
	cfg(0x1F54, 3, 4000, 4);
	fake_std(2);
	fake_std(3);
	t.sw_result = -EIO;
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_I);
	zassert_equal(t.sw_calls, 1, "hook asked for node 2 only");
	zassert_equal(last_boot_status(3), CO_MGR_ST_OK, "matching version needs no update");
	t.sw_result = 0;
	zassert_ok(co_mgr_boot_req(&t.master, 2));
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(t.sw_calls, 2);
}

/* --- Configuration (302-2 §3.5) -------------------------------------------------------------- */

ZTEST(co_mgr, test_s9_32_matching_1020h_skips_configuration)
{
	baseline();
	cfg(0x1F81, 2, 0x85, 4); /* restore requested: must be skipped too */
	cfg(0x1F8A, 2, 1, 1);
	cfg(0x1F26, 2, 1000, 4);
	cfg(0x1F27, 2, 2000, 4);
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_equal(count_sdo(2, true, 0x1020, 1), 1);
	zassert_equal(count_sdo(2, true, 0x1020, 2), 1);
	zassert_equal(count_sdo(2, false, -1, -1), 0, "no downloads");
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
}

ZTEST(co_mgr, test_s9_33_unset_1f26h_means_no_1020h_upload_and_update)
{
	baseline();
	cfg(0x1F81, 2, 0x85, 4);
	cfg(0x1F8A, 2, 1, 1);
	cfg(0x1F27, 2, 2000, 4);
	fake_std(2);
	fake_obj(&t.fakes[0], 0x1011, 1, 0, 0);
	start_master();
	run_for(1500 * MS);
	zassert_equal(count_sdo(2, true, 0x1020, -1), 0);
	zassert_equal(count_sdo(2, false, 0x1011, 1), 1, "update path taken");
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
}

ZTEST(co_mgr, test_s9_35_restore_writes_load_then_reset_node_then_configures)
{
	baseline();
	cfg(0x1F81, 2, 0x85, 4);
	cfg(0x1F8A, 2, 1, 1);
	struct fake *f = fake_std(2);

	fake_obj(f, 0x1011, 1, 0, 0);
	start_master();
	run_for(1500 * MS);
	int w = first_sdo(2, false, 0x1011, 1);

	zassert_true(w >= 0);
	zassert_mem_equal(&t.log[w].f.data[4], "load", 4);
	zassert_true(first_nmt(0x81, 2) > w, "000#8102 after the restore");
	zassert_equal(f->down[0].value, 0x64616f6c);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(count_nmt(0x01, 2), 1);
	zassert_true(first_nmt(0x01, 2) > first_nmt(0x81, 2));
}

ZTEST(co_mgr, test_s9_34_restore_refused_is_J_and_no_start)
{
	baseline();
	cfg(0x1F81, 2, 0x85, 4);
	cfg(0x1F8A, 2, 1, 1);
	fake_obj(fake_std(2), 0x1011, 1, 0, CO_SDO_AB_HW);
	start_master();
	run_for(1500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_J);
	zassert_equal(last_boot_err(2)->index, 0x1011);
	zassert_equal(last_boot_err(2)->abort_code, CO_SDO_AB_HW);
	zassert_equal(count_nmt(0x01, 2), 0);
}

ZTEST(co_mgr, test_restore_without_bootup_is_J)
{
	baseline();
	cfg(0x1F81, 2, 0x85, 4);
	cfg(0x1F8A, 2, 2, 1);
	struct fake *f = fake_std(2);

	fake_obj(f, 0x1011, 2, 0, 0);
	f->dies_at_reset = 2; /* the startup reset is the first */
	start_master();
	run_for(1500 * MS);
	zassert_true(first_nmt(0x82, 2) > 1, "sub 2: Reset Communication");
	zassert_equal(last_boot_status(2), CO_MGR_ST_J);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_RESTORE_RESET);
}

/* --- Start error control (302-2 §4.1) -------------------------------------------------------- */

ZTEST(co_mgr, test_s9_36_no_heartbeat_in_start_error_control_is_K)
{
	baseline();
	cfg(0x1016, 1, (2U << 16) | 500U, 4);
	fake_std(2);
	start_master();
	run_for(10 * MS);
	uint64_t began = t.now;

	run_for(480 * MS);
	zassert_equal(last_boot_status(2), -1, "still waiting");
	run_for(40 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_K);
	zassert_equal(last_boot_err(2)->expected, 500);
	zassert_equal(last_boot_err(2)->step, CO_MGR_STEP_START_EC);
	struct co_mgr_boot_info bi;

	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_within(bi.finished_us, began + 500 * MS - 10 * MS, 5 * MS);
	zassert_equal(count_nmt(0x01, 2), 0);
}

ZTEST(co_mgr, test_heartbeat_in_start_error_control_boots_ok)
{
	baseline();
	cfg(0x1016, 1, (2U << 16) | 500U, 4);
	struct fake *f = fake_std(2);

	f->hb_ms = 100;
	f->next_hb = 20 * MS;
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	struct co_mgr_boot_info bi;

	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_equal(bi.nmt_state, 0x05, "1F82h view follows the heartbeat");
	zassert_equal(od_read_u(&t.master, 0x1F82, 2), 0x05);
}

ZTEST(co_mgr, test_s9_37_guarding_rtr_every_guard_time_event_after_life_time)
{
	baseline();
	cfg(0x1F81, 3, 0x0064030D, 4); /* 100 ms, retry 3, mandatory, boot, slave */
	fake_std(2);
	struct fake *f = fake_std(3);

	start_master();
	run_for(50 * MS);
	int base = count_rtr(3);

	zassert_equal(base, 1, "guarding starts with the boot");
	run_for(1000 * MS);
	zassert_within(count_rtr(3), 11, 1);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 0);
	f->answer_rtr = false;
	run_for(250 * MS);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 0, "not yet");
	run_for(200 * MS);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 1, "life time 300 ms passed");
}

ZTEST(co_mgr, test_s9_38_guard_time_or_retry_zero_means_no_rtr)
{
	baseline();
	cfg(0x1F81, 2, 0x00000305, 4); /* retry 3, guard time 0 */
	cfg(0x1F81, 3, 0x00640005, 4); /* guard time 100, retry 0 */
	fake_std(2);
	fake_std(3);
	start_master();
	run_for(2000 * MS);
	zassert_equal(count_rtr(2), 0);
	zassert_equal(count_rtr(3), 0);
}

/* --- Error handler (302-2 §4.2) -------------------------------------------------------------- */

static void hb_lost_setup(uint32_t startup, uint32_t assign2)
{
	cfg(0x1F80, 0, startup, 4);
	cfg(0x1F81, 2, assign2, 4);
	cfg(0x1F81, 3, 0x05, 4);
	cfg(0x1016, 1, (2U << 16) | 300U, 4);
	cfg(0x1016, 2, (3U << 16) | 300U, 4);
	for (uint8_t id = 2; id <= 3; id++) {
		struct fake *f = fake_std(id);

		f->hb_ms = 100;
		f->next_hb = 10 * MS;
	}
	start_master();
	run_for(1000 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
}

ZTEST(co_mgr, test_s9_39_mandatory_hb_lost_with_bit6_stops_all_including_master)
{
	cfg(0x1017, 0, 100, 2);
	hb_lost_setup(0x41, 0x0D);
	t.fakes[0].present = false;
	run_for(500 * MS);
	zassert_equal(count_nmt(0x02, 0), 1);
	zassert_equal(master_state(), CO_NMT_STOPPED);
	zassert_equal(count_ec(2, CO_MGR_EC_HB_LOST), 1);
	run_for(1100 * MS);
	int hb = -1;

	for (int i = t.n_log - 1; i >= 0; i--) {
		if (t.log[i].f.id == 0x701) {
			hb = t.log[i].f.data[0];
			break;
		}
	}
	zassert_equal(hb, 0x04, "master heartbeat says Stopped");
}

ZTEST(co_mgr, test_s9_40_mandatory_hb_lost_with_bit4_resets_all_including_master)
{
	hb_lost_setup(0x11, 0x0D);
	t.fakes[0].present = false;
	int before_n = t.n_log;

	run_for(500 * MS);
	int r = first_nmt(0x81, 0);

	zassert_true(r >= before_n, "000#8100");
	/* Then the master boots again: own boot-up and a new startup. */
	zassert_true(r + 1 < t.n_log);
	zassert_equal(t.log[r + 1].f.id, 0x701);
	zassert_equal(t.log[r + 1].f.data[0], 0x00);
	zassert_equal(count_nmt(0x82, 0), 2, "full restart resets the network again");
}

ZTEST(co_mgr, test_s9_41_mandatory_hb_lost_resets_that_node_and_reboots_it)
{
	hb_lost_setup(0x01, 0x0D);
	struct fake *f = &t.fakes[0];

	zassert_equal(count_sdo(2, true, 0x1000, 0), 1);
	f->hb_mute = true; /* hangs until reset */
	run_for(1000 * MS);
	zassert_equal(count_ec(2, CO_MGR_EC_HB_LOST), 1);
	zassert_equal(count_nmt(0x81, 2), 1, "000#8102");
	zassert_equal(count_nmt(0x81, 0), 0);
	zassert_equal(count_nmt(0x02, 0), 0);
	/* Its boot-up after the reset runs the boot again, which ends with a start. */
	zassert_equal(count_sdo(2, true, 0x1000, 0), 2);
	zassert_true(first_sdo(2, true, 0x1000, 0) < first_nmt(0x81, 2));
	zassert_equal(count_nmt(0x01, 2), 2);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
}

ZTEST(co_mgr, test_s9_42_optional_hb_lost_never_stops_or_resets_all)
{
	hb_lost_setup(0x51, 0x0D);
	t.fakes[1].present = false;
	run_for(2000 * MS);
	zassert_equal(count_nmt(0x02, 0), 0);
	zassert_equal(count_nmt(0x81, 0), 0);
	zassert_equal(count_nmt(0x81, 3), 1, "individual reset (bit 2)");
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_equal(od_read_u(&t.master, 0x1F82, 3), 0x01, "1F82h: missing");
}

/* --- Request NMT 1F82h, request guarding 1F83h (302 §5.4, 302-2 §6.4-6.5) --------------------- */

static void started_network(void)
{
	baseline();
	cfg(0x1F81, 3, 0x0064030D, 4);
	fake_std(2);
	fake_std(3);
	fake_std(4);
	start_master();
	run_for(500 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
}

ZTEST(co_mgr, test_s9_43_request_nmt_sends_the_matching_command)
{
	static const uint8_t req[5] = {0x05, 0x04, 0x06, 0x07, 0x7f};
	static const uint8_t cs[5] = {0x01, 0x02, 0x81, 0x82, 0x80};

	started_network();
	for (int i = 0; i < 5; i++) {
		int n = t.n_log;

		zassert_equal(od_write_u(&t.master, 0x1F82, 3, req[i], 1, CO_OD_WRITER_SDO), 0U);
		run_for(10 * MS);
		zassert_true(t.n_log > n);
		zassert_true(is_nmt(&t.log[n].f, cs[i], 3), "value %02x", req[i]);
	}
}

ZTEST(co_mgr, test_s9_44_request_nmt_reserved_values_are_refused_without_frame)
{
	static const uint8_t bad[] = {0x00, 0x01, 0x02, 0x08, 0x7e, 0x80, 0x84, 0x90, 0xff};

	started_network();
	int n = count_nmt_cs(0x01) + count_nmt_cs(0x02) + count_nmt_cs(0x80) + count_nmt_cs(0x81) +
		count_nmt_cs(0x82);

	for (size_t i = 0; i < ARRAY_SIZE(bad); i++) {
		zassert_equal(od_write_u(&t.master, 0x1F82, 3, bad[i], 1, CO_OD_WRITER_SDO),
			      CO_SDO_AB_INVALID_VALUE, "value %02x", bad[i]);
	}
	/* 84h..8Fh over SDO: the requester is unknown. */
	zassert_equal(od_write_u(&t.master, 0x1F82, 0x80, 0x85, 1, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE);
	run_for(10 * MS);
	zassert_equal(count_nmt_cs(0x01) + count_nmt_cs(0x02) + count_nmt_cs(0x80) +
			      count_nmt_cs(0x81) + count_nmt_cs(0x82),
		      n);
}

ZTEST(co_mgr, test_s9_45_request_nmt_all_includes_the_master)
{
	started_network();
	zassert_equal(od_write_u(&t.master, 0x1F82, 0x80, 0x7f, 1, CO_OD_WRITER_SDO), 0U);
	run_for(10 * MS);
	zassert_equal(count_nmt(0x80, 0), 1);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL, "applied to itself");
	zassert_equal(od_write_u(&t.master, 0x1F82, 0x80, 0x05, 1, CO_OD_WRITER_SDO), 0U);
	run_for(10 * MS);
	zassert_equal(count_nmt(0x01, 0), 1);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	/* The API does the same. */
	zassert_ok(co_mgr_nmt_req(&t.master, 0, CO_NMT_CS_STOP));
	run_for(10 * MS);
	zassert_equal(count_nmt(0x02, 0), 1);
	zassert_equal(master_state(), CO_NMT_STOPPED);
}

ZTEST(co_mgr, test_request_nmt_excluding_master_and_requester)
{
	started_network();
	int n = t.n_log;

	/* A local application write: the requester is the master itself. */
	zassert_equal(od_write_u(&t.master, 0x1F82, 0x80, 0x84, 1, CO_OD_WRITER_APP), 0U);
	run_for(10 * MS);
	zassert_equal(count_nmt(0x02, 0), 0, "no broadcast");
	zassert_equal(count_nmt(0x02, MASTER), 0);
	for (int id = 2; id <= 127; id++) {
		zassert_equal(count_nmt(0x02, id), 1, "stop %d", id);
	}
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_true(t.n_log - n >= 126);
}

ZTEST(co_mgr, test_s9_46_request_nmt_parks_the_slave)
{
	started_network();
	zassert_equal(od_write_u(&t.master, 0x1F82, 2, 0x7f, 1, CO_OD_WRITER_SDO), 0U);
	run_for(10 * MS);
	int n = count_sdo(2, true, 0x1000, 0);

	/* It keeps answering pre-operational, even reboots: no automatic re-boot or start. */
	fake_ec(&t.fakes[0], 0x7f);
	fake_ec(&t.fakes[0], 0x00);
	run_for(2000 * MS);
	zassert_equal(count_sdo(2, true, 0x1000, 0), n);
	zassert_equal(count_nmt(0x01, 2), 1, "only the start of the startup");
	/* Released: the next boot-up is handled again. */
	co_mgr_release(&t.master, 2);
	fake_ec(&t.fakes[0], 0x00);
	run_for(500 * MS);
	zassert_equal(count_sdo(2, true, 0x1000, 0), n + 1);
	zassert_equal(count_nmt(0x01, 2), 2);
}

ZTEST(co_mgr, test_s9_47_request_nmt_read_gives_the_slave_state)
{
	started_network();
	zassert_equal(od_read_u(&t.master, 0x1F82, 4), 0x05, "after its start");
	fake_ec(&t.fakes[2], 0x7f);
	run_for(10 * MS);
	zassert_equal(od_read_u(&t.master, 0x1F82, 4), 0x7f, "from its heartbeat");
	fake_ec(&t.fakes[2], 0x04);
	run_for(10 * MS);
	zassert_equal(od_read_u(&t.master, 0x1F82, 4), 0x04);
	zassert_equal(od_read_u(&t.master, 0x1F82, 5), 0x00, "unknown node");
	/* Guarded node 3 goes silent: missing. */
	t.fakes[1].present = false;
	run_for(500 * MS);
	zassert_equal(od_read_u(&t.master, 0x1F82, 3), 0x01);
}

ZTEST(co_mgr, test_s9_48_request_guarding_starts_and_stops_rtrs)
{
	baseline();
	cfg(0x1F81, 3, 0x00640305, 4);        /* guard fields but no guarding without 1F83h... */
	cfg(0x1016, 1, (3U << 16) | 500U, 4); /* ...because 1016h wins for node 3 */
	struct fake *f = fake_std(3);

	f->hb_ms = 100;
	start_master();
	run_for(500 * MS);
	zassert_equal(count_rtr(3), 0, "heartbeat has priority over guarding");
	zassert_equal(od_write_u(&t.master, 0x1F83, 3, 1, 1, CO_OD_WRITER_SDO), 0U);
	run_for(1000 * MS);
	zassert_within(count_rtr(3), 11, 1);
	zassert_equal(od_read_u(&t.master, 0x1F83, 3), 1);
	zassert_equal(od_write_u(&t.master, 0x1F83, 3, 0, 1, CO_OD_WRITER_SDO), 0U);
	int n = count_rtr(3);

	run_for(1000 * MS);
	zassert_equal(count_rtr(3), n);
	zassert_equal(od_read_u(&t.master, 0x1F83, 3), 0);
	zassert_equal(od_write_u(&t.master, 0x1F83, 3, 2, 1, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE);
}

/* --- NMT inhibit time 102Ah (302-2 §6.1) ---------------------------------------------------- */

ZTEST(co_mgr, test_s9_51_inhibit_time_spaces_nmt_frames_in_order)
{
	baseline();
	cfg(0x102A, 0, 10, 2);   /* 1 ms */
	cfg(0x1F81, 3, 0x15, 4); /* keep-alive: 125 individual resets */
	fake_std(2);
	fake_std(3)->state = 0x05;
	fake_std(4);
	start_master();
	run_for(1000 * MS);
	uint64_t prev = 0;
	int n = 0;
	int last_id = 1;

	for (int i = 0; i < t.n_log; i++) {
		if (t.log[i].f.id != 0x000) {
			continue;
		}
		if (n > 0) {
			zassert_true(t.log[i].at - prev >= 1 * MS, "frame %d %llu after %llu", n,
				     (unsigned long long)t.log[i].at, (unsigned long long)prev);
		}
		if (t.log[i].f.data[0] == 0x82) {
			zassert_true(t.log[i].f.data[1] > last_id, "request order");
			last_id = t.log[i].f.data[1];
		}
		prev = t.log[i].at;
		n++;
	}
	zassert_true(n >= 125 + 2, "none dropped (%d)", n);
	zassert_equal(count_nmt_cs(0x82), 125);
	zassert_true(first_sdo(2, true, 0x1000, 0) > first_nmt(0x82, 127), "boot after the resets");
}

ZTEST(co_mgr, test_inhibit_time_queues_api_requests_never_drops)
{
	started_network();
	zassert_equal(od_write_u(&t.master, 0x102A, 0, 50, 2, CO_OD_WRITER_SDO), 0U); /* 5 ms */
	uint64_t t0 = t.now;

	for (uint8_t id = 10; id < 30; id++) {
		zassert_ok(co_mgr_nmt_req(&t.master, id, CO_NMT_CS_ENTER_PRE_OPERATIONAL));
	}
	run_for(200 * MS);
	for (uint8_t id = 10; id < 30; id++) {
		int i = first_nmt(0x80, id);

		zassert_true(i >= 0, "node %u", id);
		zassert_true(t.log[i].at >= t0 + (uint64_t)(id - 10) * 5 * MS);
	}
	zassert_equal(co_mgr_nmt_req(&t.master, 200, CO_NMT_CS_START), -EINVAL);
	zassert_equal(co_mgr_nmt_req(&t.master, 2, (enum co_nmt_cs)0x55), -EINVAL);
}

/* --- Object checks (302-2 §6.2-6.3) ------------------------------------------------------- */

ZTEST(co_mgr, test_s9_52_unsupported_1f80h_bits_are_refused)
{
	start_master();
	zassert_equal(od_write_u(&t.master, 0x1F80, 0, 0x21, 4, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "flying master");
	zassert_equal(od_write_u(&t.master, 0x1F80, 0, 0x81, 4, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "reserved bit 7");
	zassert_equal(od_write_u(&t.master, 0x1F80, 0, 0x5F, 4, CO_OD_WRITER_SDO), 0U);
	zassert_equal(od_write_u(&t.master, 0x1F81, 2, 0x07, 4, CO_OD_WRITER_SDO),
		      CO_SDO_AB_INVALID_VALUE, "1F81h bit 1 is reserved");
}

ZTEST(co_mgr, test_not_master_sends_no_nmt)
{
	cfg(0x1F80, 0, 0x00, 4);
	cfg(0x1F81, 2, 0x05, 4);
	fake_std(2);
	start_master();
	run_for(2000 * MS);
	zassert_equal(count_nmt_cs(0x82) + count_nmt_cs(0x01), 0);
	zassert_equal(count_sdo(2, true, -1, -1), 0);
	zassert_equal(co_mgr_nmt_req(&t.master, 2, CO_NMT_CS_START), -EPERM);
	zassert_equal(od_write_u(&t.master, 0x1F82, 2, 0x05, 1, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
}

ZTEST(co_mgr, test_s9_61_self_starting_device_goes_operational_silently)
{
	cfg(0x1F80, 0, 0x08, 4);
	start_master();
	run_for(100 * MS);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	for (int i = 0; i < t.n_log; i++) {
		zassert_not_equal(t.log[i].f.id, 0x000, "no NMT frame");
	}
}

/* --- Real SafeLine slaves on the same line -----------------------------------------------------
 */

ZTEST(co_mgr, test_real_slaves_boot_in_parallel_with_identity_and_heartbeat)
{
	baseline();
	cfg(0x1F81, 4, 0x00, 4);
	cfg(0x1F81, 2, 0x0D, 4);
	cfg(0x1F84, 2, 0x00020192, 4);
	cfg(0x1F85, 2, 0x00000539, 4);
	cfg(0x1F86, 2, 0x00000042, 4);
	cfg(0x1F87, 2, 0x00010003, 4);
	cfg(0x1F88, 2, 0x00001234, 4);
	cfg(0x1F85, 3, 0x00000539, 4);
	cfg(0x1016, 1, (2U << 16) | 300U, 4);
	cfg(0x1016, 2, (3U << 16) | 300U, 4);
	real_cfg(0, 0x1017, 0, 100, 2);
	real_cfg(1, 0x1017, 0, 100, 2);
	add_real(0, 2);
	add_real(1, 3);
	start_master();
	run_for(1000 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(last_boot_status(3), CO_MGR_ST_OK);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(co_nmt_get_state(&t.real[0]), CO_NMT_OPERATIONAL);
	zassert_equal(co_nmt_get_state(&t.real[1]), CO_NMT_OPERATIONAL);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	/* In parallel: the first request to 3 went out before the last one to 2. */
	int last2 = -1;

	for (int i = 0; i < t.n_log; i++) {
		if (t.log[i].f.id == 0x602) {
			last2 = i;
		}
	}
	zassert_true(first_sdo(3, true, 0x1000, 0) < last2);
	struct co_mgr_boot_info bi;

	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_equal(bi.identity[2], 0x00010005);
	zassert_true(bi.mandatory);
	zassert_equal(bi.nmt_state, 0x05);
	/* Their heartbeats (1017h from their own configuration) keep them supervised. */
	run_for(1000 * MS);
	zassert_equal(count_ec(2, CO_MGR_EC_HB_LOST), 0);
}

#if defined(CONFIG_CANOPEN_CFG)
/* --- Concise DCF through the configuration manager (302-2 §3.5, 302 §6.2) --------------------- */

/* 1017h:00 = 100 (U16), 2000h:00 = 0000CAFEh (U32). */
static const uint8_t cdcf_ok[] = {
	0x02, 0x00, 0x00, 0x00, 0x17, 0x10, 0x00, 0x02, 0x00, 0x00, 0x00, 0x64,
	0x00, 0x00, 0x20, 0x00, 0x04, 0x00, 0x00, 0x00, 0xfe, 0xca, 0x00, 0x00,
};

ZTEST(co_mgr, test_s9_33_concise_dcf_entries_downloaded_in_stream_order)
{
	baseline();
	struct fake *f = fake_std(2);

	fake_obj(f, 0x1017, 0, 0, 0);
	fake_obj(f, 0x2000, 0, 0, 0);
	zassert_ok(co_cfg_set_concise_dcf(&t.cfgm, 2, cdcf_ok, sizeof(cdcf_ok)));
	start_master();
	run_for(500 * MS);
	zassert_equal(count_sdo(2, true, 0x1020, -1), 0, "1F26h/1F27h unset: no verification");
	zassert_equal(f->n_down, 2);
	zassert_equal(f->down[0].index, 0x1017);
	zassert_equal(f->down[0].value & 0xffff, 100);
	zassert_equal(f->down[1].index, 0x2000);
	zassert_equal(f->down[1].value, 0xcafe);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_true(first_nmt(0x01, 2) > first_sdo(2, false, 0x2000, 0), "started after config");
}

ZTEST(co_mgr, test_s9_34_concise_dcf_entry_aborted_is_J_and_no_start)
{
	baseline();
	struct fake *f = fake_std(2);

	fake_obj(f, 0x1017, 0, 0, 0);
	fake_obj(f, 0x2000, 0, 0, CO_SDO_AB_VALUE_HIGH);
	zassert_ok(co_cfg_set_concise_dcf(&t.cfgm, 2, cdcf_ok, sizeof(cdcf_ok)));
	start_master();
	run_for(500 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_J);
	const struct co_mgr_boot_error *e = last_boot_err(2);

	zassert_equal(e->step, CO_MGR_STEP_DOWNLOAD);
	zassert_equal(e->index, 0x2000);
	zassert_equal(e->sub, 0);
	zassert_equal(e->abort_code, CO_SDO_AB_VALUE_HIGH);
	zassert_equal(count_nmt(0x01, 2), 0);
}

ZTEST(co_mgr, test_real_slave_configured_by_concise_dcf_then_heartbeat_supervised)
{
	baseline();
	cfg(0x1F81, 2, 0x0D, 4);
	cfg(0x1F81, 3, 0x00, 4);
	cfg(0x1F81, 4, 0x00, 4);
	cfg(0x1016, 1, (2U << 16) | 300U, 4);
	zassert_ok(co_cfg_set_concise_dcf(&t.cfgm, 2, cdcf_ok, sizeof(cdcf_ok)));
	add_real(0, 2);
	start_master();
	run_for(1000 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(od_read_u(&t.real[0], 0x2000, 0), 0xcafe);
	zassert_equal(od_read_u(&t.real[0], 0x1017, 0), 100);
	zassert_equal(co_nmt_get_state(&t.real[0]), CO_NMT_OPERATIONAL);
	zassert_equal(od_read_u(&t.master, 0x1F82, 2), 0x05);
	/* The heartbeat from the configured producer keeps it supervised. */
	run_for(2000 * MS);
	zassert_equal(count_ec(2, CO_MGR_EC_HB_LOST), 0);
	/* A reset slave reboots: boot-up handler, new boot (configuration again), start. */
	zassert_ok(co_nmt_req(&t.real[0], CO_NMT_CS_RESET_NODE));
	run_for(1000 * MS);
	zassert_equal(count_sdo(2, true, 0x1000, 0), 2);
	zassert_equal(co_nmt_get_state(&t.real[0]), CO_NMT_OPERATIONAL);
	zassert_equal(od_read_u(&t.real[0], 0x2000, 0), 0xcafe, "configured again");
	zassert_equal(count_ec(2, CO_MGR_EC_BOOTUP), 2);
}

#endif /* CONFIG_CANOPEN_CFG */

/* --- More error control and startup variants -----------------------------------------------------
 */

ZTEST(co_mgr, test_guard_reply_without_toggle_is_not_an_answer)
{
	baseline();
	cfg(0x1F81, 3, 0x00640305, 4);
	struct fake *f = fake_std(3);

	start_master();
	run_for(500 * MS);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 0, "toggling replies keep it alive");
	f->stuck_toggle = true;
	run_for(250 * MS);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 0);
	run_for(200 * MS);
	zassert_equal(count_ec(3, CO_MGR_EC_GUARD_LOST), 1, "repeated toggle = missed replies");
}

ZTEST(co_mgr, test_request_guarding_all_nodes_sub_80h)
{
	baseline();
	cfg(0x1F81, 2, 0x00320305, 4); /* 50 ms x 3 */
	cfg(0x1F81, 3, 0x00320305, 4);
	fake_std(2);
	fake_std(3);
	fake_std(4);
	cfg(0x1F81, 4, 0x00000005, 4); /* no guard fields (replaces the baseline) */
	start_master();
	run_for(500 * MS);
	int n2 = count_rtr(2);
	int n3 = count_rtr(3);

	zassert_equal(od_write_u(&t.master, 0x1F83, 0x80, 0, 1, CO_OD_WRITER_SDO), 0U);
	run_for(500 * MS);
	zassert_equal(count_rtr(2), n2, "guarding of all stopped");
	zassert_equal(count_rtr(3), n3);
	zassert_equal(od_read_u(&t.master, 0x1F83, 2), 0);
	/* Node 4 has no guard time: starting all nodes is refused, nothing changes. */
	zassert_equal(od_write_u(&t.master, 0x1F83, 0x80, 1, 1, CO_OD_WRITER_SDO),
		      CO_SDO_AB_DATA_DEV_STATE);
	run_for(200 * MS);
	zassert_equal(count_rtr(2), n2, "refused: no node guarded");
	zassert_equal(count_rtr(3), n3);
	zassert_equal(od_write_u(&t.master, 0x1F81, 4, 0x00320305, 4, CO_OD_WRITER_SDO), 0U);
	zassert_equal(od_write_u(&t.master, 0x1F83, 0x80, 1, 1, CO_OD_WRITER_SDO), 0U);
	run_for(500 * MS);
	for (uint8_t id = 2; id <= 4; id++) {
		zassert_equal(od_read_u(&t.master, 0x1F83, id), 1);
	}
	zassert_within(count_rtr(4), 10, 1);
	zassert_equal(count_ec(2, CO_MGR_EC_GUARD_LOST), 0);
}

ZTEST(co_mgr, test_nmt_startup_simple)
{
	/* 302-2 §3.2: master bit only, slaves without any check: reset, 1000h, start. */
	cfg(0x1F80, 0, 0x03, 4);
	cfg(0x1F81, 2, 0x05, 4);
	cfg(0x1F81, 3, 0x05, 4);
	fake_std(2);
	fake_std(3);
	start_master();
	run_for(200 * MS);
	int reset = first_nmt(0x82, 0);
	int start = first_nmt(0x01, 0);

	zassert_true(reset >= 1 && start > reset);
	zassert_equal(count_sdo(2, true, -1, -1), 1, "only 1000h");
	zassert_equal(count_sdo(3, true, -1, -1), 1);
	zassert_equal(count_sdo(2, false, -1, -1) + count_sdo(3, false, -1, -1), 0);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_equal(t.n_startup_ind, 1);
	zassert_equal(t.startup_result, CO_MGR_STARTUP_DONE);
}

ZTEST(co_mgr, test_boot_table_reports_every_slave)
{
	baseline();
	cfg(0x1F81, 3, 0x0D, 4);
	cfg(0x1F86, 3, 0x99, 4);
	fake_std(2);
	fake_std(3);
	fake_std(4)->present = false;
	start_master();
	run_for(2500 * MS);
	struct co_mgr_boot_info bi;

	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_true(bi.assigned && !bi.mandatory && !bi.booting);
	zassert_equal(bi.status, CO_MGR_ST_OK);
	zassert_equal(bi.attempts, 1);
	zassert_ok(co_mgr_get_boot(&t.master, 3, &bi));
	zassert_true(bi.mandatory);
	zassert_equal(bi.status, CO_MGR_ST_M);
	zassert_equal(bi.error.index, 0x1018);
	zassert_equal(bi.error.sub, 2);
	zassert_equal(bi.error.expected, 0x99);
	zassert_equal(bi.error.actual, 0x42);
	zassert_ok(co_mgr_get_boot(&t.master, 4, &bi));
	zassert_equal(bi.status, CO_MGR_ST_B);
	zassert_true(bi.attempts >= 2, "retried in the background");
	zassert_equal(co_mgr_get_boot(&t.master, 9, &bi), -ENOENT);
	zassert_str_equal(co_mgr_step_str(CO_MGR_STEP_PRODUCT), "PRODUCT");
}

ZTEST(co_mgr, test_request_nmt_own_id_applies_to_master_without_frame)
{
	started_network();
	int n = t.n_log;

	zassert_equal(od_write_u(&t.master, 0x1F82, MASTER, 0x7f, 1, CO_OD_WRITER_SDO), 0U);
	run_for(10 * MS);
	zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
	for (int i = n; i < t.n_log; i++) {
		zassert_not_equal(t.log[i].f.id, 0x000, "no NMT frame");
	}
}

ZTEST(co_mgr, test_more_slaves_than_slots_mandatory_without_slot_halts)
{
	cfg(0x1F80, 0, 0x01, 4);
	for (uint8_t id = 2; id <= 2 + CONFIG_CANOPEN_MGR_SLAVES; id++) {
		cfg(0x1F81, id, 0x05, 4);
		fake_std(id);
	}
	start_master();
	run_for(500 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE, "optional: skipped");
	struct co_mgr_boot_info bi;

	zassert_equal(co_mgr_get_boot(&t.master, 2 + CONFIG_CANOPEN_MGR_SLAVES, &bi), -ENOENT);
	before(NULL);
	cfg(0x1F80, 0, 0x01, 4);
	for (uint8_t id = 2; id <= 2 + CONFIG_CANOPEN_MGR_SLAVES; id++) {
		cfg(0x1F81, id, 0x0D, 4);
		fake_std(id);
	}
	start_master();
	run_for(500 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_HALTED);
	zassert_equal(t.startup_err.node_id, 2 + CONFIG_CANOPEN_MGR_SLAVES);
	zassert_equal(t.startup_err.index, 0x1F81);
	zassert_equal(count_nmt_cs(0x01), 0);
}

/* --- Regressions: retry view, reported states, job slots, 1F25h clients ----------------------- */

ZTEST(co_mgr, test_boot_table_keeps_last_result_during_a_retry)
{
	struct co_mgr_boot_info bi;
	bool seen_retry = false;

	baseline();
	fake_std(2);
	fake_std(3)->present = false;
	fake_std(4);
	start_master();
	/* Absent: no boot-up, its first attempt follows the boot-up wait. Run until it ended. */
	do {
		run_for(10 * MS);
		zassert_ok(co_mgr_get_boot(&t.master, 3, &bi));
	} while (bi.status == CO_MGR_ST_NONE &&
		 t.now < (CONFIG_CANOPEN_MGR_BOOTUP_WAIT + 500) * MS);
	zassert_false(bi.booting);
	zassert_equal(bi.status, CO_MGR_ST_B);
	zassert_equal(bi.attempts, 1);
	/* The second attempt: 1 s retry period, 100 ms SDO timeout. */
	for (int i = 0; i < 150 && !seen_retry; i++) {
		run_for(10 * MS);
		zassert_ok(co_mgr_get_boot(&t.master, 3, &bi));
		seen_retry = bi.booting && bi.attempts == 2;
	}
	zassert_true(seen_retry, "no retry seen");
	/* Mid-retry: the table still shows the last finished boot (mgr.h). */
	zassert_equal(bi.status, CO_MGR_ST_B, "mid-retry status %02x", bi.status);
	zassert_equal(bi.error.status, CO_MGR_ST_B);
	zassert_equal(bi.error.node_id, 3);
	zassert_equal(bi.error.abort_code, CO_SDO_AB_TIMEOUT);
	zassert_equal(bi.error.index, 0x1000);
	/* It answers now: the attempt in progress ends OK and replaces the old result. */
	t.fakes[1].present = true;
	run_for(1200 * MS);
	zassert_ok(co_mgr_get_boot(&t.master, 3, &bi));
	zassert_false(bi.booting);
	zassert_equal(bi.status, CO_MGR_ST_OK);
	zassert_equal(bi.read_mask & BIT(0), BIT(0));
	zassert_equal(bi.device_type, 0x00020192);
}

ZTEST(co_mgr, test_boot_table_keeps_identity_of_last_boot_while_rebooting)
{
	struct co_mgr_boot_info bi;

	baseline();
	fake_std(2);
	start_master();
	run_for(500 * MS);
	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_equal(bi.status, CO_MGR_ST_OK);
	/* The slave goes silent and reboots (boot-up, then no SDO answer). */
	t.fakes[0].present = false;
	fake_ec(&t.fakes[0], 0x00);
	run_for(50 * MS);
	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_true(bi.booting);
	zassert_equal(bi.status, CO_MGR_ST_OK, "mid-boot status %02x", bi.status);
	zassert_equal(bi.read_mask & BIT(0), BIT(0), "identity of the last boot kept");
	zassert_equal(bi.device_type, 0x00020192);
	run_for(100 * MS);
	zassert_ok(co_mgr_get_boot(&t.master, 2, &bi));
	zassert_equal(bi.status, CO_MGR_ST_B);
	zassert_equal(bi.read_mask, 0);
}

static int count_ec_state(uint8_t id, enum co_nmt_state st)
{
	int n = 0;

	for (int i = 0; i < t.n_ec_ind; i++) {
		n += t.ec_id[i] == id && t.ec_ev[i] == CO_MGR_EC_STATE && t.ec_state[i] == st ? 1
											      : 0;
	}
	return n;
}

ZTEST(co_mgr, test_state_event_fires_for_reported_states_the_master_commanded)
{
	baseline();
	cfg(0x1016, 1, (2U << 16) | 300U, 4);
	struct fake *f = fake_std(2);

	f->hb_ms = 100;
	f->next_hb = 20 * MS;
	start_master();
	run_for(1000 * MS);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(f->state, 0x05, "started");
	/* The boot-up reported Pre-operational; the heartbeats then confirmed Operational. */
	zassert_equal(count_ec(2, CO_MGR_EC_BOOTUP), 1);
	zassert_equal(count_ec_state(2, CO_NMT_PRE_OPERATIONAL), 0);
	zassert_equal(count_ec_state(2, CO_NMT_OPERATIONAL), 1, "confirmation of the start");
	zassert_equal(count_ec(2, CO_MGR_EC_STATE), 1);
	/* A commanded stop: the event comes with the heartbeat that reports it. */
	zassert_equal(od_write_u(&t.master, 0x1F82, 2, 0x04, 1, CO_OD_WRITER_SDO), 0U);
	run_for(1 * MS);
	zassert_equal(count_ec_state(2, CO_NMT_STOPPED), 0, "not reported yet");
	run_for(200 * MS);
	zassert_equal(count_ec_state(2, CO_NMT_STOPPED), 1);
	zassert_equal(count_ec(2, CO_MGR_EC_STATE), 2);
	zassert_equal(od_read_u(&t.master, 0x1F82, 2), 0x04);
	/* Unchanged heartbeats raise nothing. */
	run_for(500 * MS);
	zassert_equal(count_ec(2, CO_MGR_EC_STATE), 2);
}

#if defined(CONFIG_CANOPEN_CFG)
ZTEST(co_mgr, test_more_slaves_than_cfg_jobs_wait_for_a_job_never_J)
{
	/* More slaves with a concise DCF than download jobs: the rest must wait, not fail. */
	const uint8_t n = (uint8_t)MIN(CO_CFG_JOBS + 2, CONFIG_CANOPEN_MGR_SLAVES);
	int first[16];
	int last[16];

	zassert_true(n > CO_CFG_JOBS, "needs more slots than jobs");
	cfg(0x1F80, 0, 0x01, 4);
	for (uint8_t i = 0; i < n; i++) {
		struct fake *f;

		cfg(0x1F81, 2 + i, 0x05, 4);
		f = fake_std(2 + i);
		fake_obj(f, 0x1017, 0, 0, 0);
		fake_obj(f, 0x2000, 0, 0, 0);
		zassert_ok(co_cfg_set_concise_dcf(&t.cfgm, 2 + i, cdcf_ok, sizeof(cdcf_ok)));
	}
	start_master();
	run_for(1000 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	for (uint8_t i = 0; i < n; i++) {
		struct co_mgr_boot_info bi;
		uint8_t id = 2 + i;

		zassert_equal(last_boot_status(id), CO_MGR_ST_OK, "node %u: %c", id,
			      last_boot_status(id));
		zassert_ok(co_mgr_get_boot(&t.master, id, &bi));
		zassert_equal(bi.attempts, 1, "node %u", id);
		zassert_equal(fake_find(id)->n_down, 2, "node %u configured", id);
		zassert_equal(count_nmt(0x01, id), 1, "node %u started", id);
		first[i] = first_sdo(id, false, 0x1017, 0);
		last[i] = first_sdo(id, false, 0x2000, 0);
		zassert_true(first[i] >= 0 && last[i] > first[i]);
	}
	/* Never more than CO_CFG_JOBS downloads at once. */
	for (int k = 0; k < t.n_log; k++) {
		int running = 0;

		for (uint8_t i = 0; i < n; i++) {
			running += first[i] <= k && k <= last[i] ? 1 : 0;
		}
		zassert_true(running <= CO_CFG_JOBS, "%d downloads at frame %d", running, k);
	}
}

static struct {
	int n;
	uint8_t id;
	uint32_t ab;
} req_ind;

static void req_ind_cb(struct co_node *node, uint8_t id, uint32_t abort_code, uint16_t index,
		       uint8_t sub, void *user_data)
{
	req_ind.n++;
	req_ind.id = id;
	req_ind.ab = abort_code;
}

/*
 * 1F25h never borrows a slave slot's SDO client: that slot's boot would abort the transfer.
 * With SDO_CLIENTS == MGR_SLAVES there is none to spare (refused); with one more it runs on
 * the spare client even while the slave of the last slot reboots.
 */
ZTEST(co_mgr, test_1f25h_uses_only_clients_above_the_slave_slots)
{
	const uint8_t last_id = 1 + CONFIG_CANOPEN_MGR_SLAVES; /* slot MGR_SLAVES - 1 */
	struct fake *f2;
	uint32_t ab;

	zassert_true(CONFIG_CANOPEN_MGR_SLAVES + 1 <= MAX_FAKES);
	memset(&req_ind, 0, sizeof(req_ind));
	cfg(0x1F80, 0, 0x01, 4);
	for (uint8_t id = 2; id <= last_id; id++) {
		cfg(0x1F81, id, 0x05, 4);
		fake_std(id);
	}
	f2 = fake_find(2);
	fake_obj(f2, 0x1017, 0, 0, 0);
	fake_obj(f2, 0x2000, 0, 0, 0);
	zassert_ok(co_cfg_set_concise_dcf(&t.cfgm, 2, cdcf_ok, sizeof(cdcf_ok)));
	zassert_ok(co_cfg_set_ind(&t.cfgm, req_ind_cb, NULL));
	start_master();
	run_for(500 * MS);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	zassert_equal(last_boot_status(last_id), CO_MGR_ST_OK);
	zassert_equal(f2->n_down, 2);
	int n = t.n_log;

	ARG_UNUSED(n);
	ab = od_write_u(&t.master, 0x1F25, 2, CO_CFG_SIGNATURE_CONF, 4, CO_OD_WRITER_SDO);
#if CONFIG_CANOPEN_SDO_CLIENTS > CONFIG_CANOPEN_MGR_SLAVES
	zassert_equal(ab, 0U, "abort %08x", ab);
#else
	zassert_equal(ab, CO_SDO_AB_NO_RESOURCE, "no spare client, yet abort %08x", ab);
#endif
	/* The slave of the last slot reboots while the request runs. */
	fake_ec(fake_find(last_id), 0x00);
	run_for(500 * MS);
	zassert_equal(count_sdo(last_id, true, 0x1000, 0), 2, "slave of the last slot rebooted");
	zassert_equal(last_boot_status(last_id), CO_MGR_ST_OK);
#if CONFIG_CANOPEN_SDO_CLIENTS > CONFIG_CANOPEN_MGR_SLAVES
	zassert_equal(req_ind.n, 1);
	zassert_equal(req_ind.id, 2);
	zassert_equal(req_ind.ab, 0U, "1F25h download cut: %08x", req_ind.ab);
	zassert_equal(f2->n_down, 4, "both entries again");
#else
	zassert_equal(req_ind.n, 0);
	for (int i = n; i < t.n_log; i++) {
		zassert_false(is_sdo(&t.log[i].f, 2, false, -1, -1), "no download to 2");
	}
#endif
}
#endif /* CONFIG_CANOPEN_CFG */

/* --- The master leaves Pre-operational during the startup (302-2 §3.1, §4.2) ------------------ */

/* An NMT frame from another device on the bus, received by the master now. */
static void bus_nmt(uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = 0x000, .dlc = 2, .data = {cs, id}};

	co_line_rx(&t.line, &f, t.now);
}

/* The SDO abort frame the master sent to @p id, its index in the log or -1. */
static int find_sdo_abort(uint8_t id, uint16_t index, uint32_t code)
{
	for (int i = 0; i < t.n_log; i++) {
		const struct can_frame *f = &t.log[i].f;

		if (f->id == 0x600U + id && f->dlc == 8 && f->data[0] == 0x80 &&
		    sys_get_le16(&f->data[1]) == index && sys_get_le32(&f->data[4]) == code) {
			return i;
		}
	}
	return -1;
}

static int count_boot_ind(uint8_t id, uint8_t status)
{
	int n = 0;

	for (int i = 0; i < t.n_boot_ind; i++) {
		n += t.boot_id[i] == id && t.boot_status[i] == status ? 1 : 0;
	}
	return n;
}

/*
 * The fuzzer's case: the master is stopped and started again (by another device) while the
 * first SDO of an optional keep-alive slave's boot waits for its answer. The cut transfer is
 * aborted on the bus, the attempt ends (B, reported), the startup ends, and the slave is
 * booted again as soon as the master runs again.
 */
ZTEST(co_mgr, test_master_stopped_during_boot_ends_attempt_startup_and_reboots_slave_when_started)
{
	struct co_mgr_boot_info info;
	struct fake *f;
	int i;

	cfg(0x1F80, 0, 0x01, 4);
	cfg(0x1F89, 0, 500, 4);
	cfg(0x1F81, 2, 0x75, 4); /* optional: slave, boot, keep-alive, SW check and update */
	cfg(0x1F53, 2, 3000, 4);
	cfg(0x1F54, 2, 4000, 4);
	f = fake_std(2);
	f->present = false; /* the first request is not answered before the stop */
	start_master();
	run_until(0);
	i = first_sdo(2, true, 0x1000, 0);
	zassert_true(i >= 0 && t.log[i].at < 1 * MS, "602#40 00 10 00 before 1 ms");
	run_until(1 * MS);
	bus_nmt(0x02, MASTER);
	bus_nmt(0x01, MASTER);
	f->present = true;
	run_for(30000 * MS);

	zassert_equal(t.n_startup_ind, 1, "the startup ends");
	zassert_equal(t.startup_result, CO_MGR_STARTUP_DONE);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
	i = find_sdo_abort(2, 0x1000, CO_SDO_AB_DATA_DEV_STATE);
	zassert_true(i >= 0, "the cut upload is aborted on the bus");
	zassert_equal(t.log[i].at, 1 * MS);
	zassert_equal(f->n_aborts, 1);
	/* The cut attempt is reported, then the new attempt boots the slave. */
	zassert_equal(count_boot_ind(2, CO_MGR_ST_B), 1);
	zassert_equal(t.boot_status[0], CO_MGR_ST_B);
	zassert_equal(t.boot_err[0].step, CO_MGR_STEP_DEVTYPE);
	zassert_equal(t.boot_err[0].index, 0x1000);
	zassert_equal(t.boot_err[0].abort_code, CO_SDO_AB_DATA_DEV_STATE);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_ok(co_mgr_get_boot(&t.master, 2, &info));
	zassert_equal(info.status, CO_MGR_ST_OK);
	zassert_false(info.booting);
	zassert_equal(info.attempts, 2);
	zassert_equal(count_sdo(2, true, 0x1000, 0), 2);
	zassert_true(t.log[first_nmt(0x01, 2)].at < 1 * MS + 200 * MS, "booted after the start");
	zassert_equal(count_nmt(0x01, 2), 1);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
}

/*
 * 1F80h bit 6: a mandatory slave misses its first guarding answer while an optional slave's
 * boot waits for an SDO answer. The master stops the network and itself; the optional slave's
 * upload is aborted on the bus, its attempt ends (B), and the startup ends with the master left
 * Stopped and nothing started. Started again, the master boots the optional slave.
 */
ZTEST(co_mgr, test_stop_all_on_mandatory_guarding_loss_aborts_boot_sdo_and_ends_startup)
{
	struct co_mgr_boot_info info;
	struct fake *o;
	int stop;
	int ab;

	cfg(0x1F80, 0, 0x41, 4);
	cfg(0x1F81, 2, 0x0032010D, 4); /* mandatory, guard time 50 ms, retry factor 1 */
	cfg(0x1F81, 3, 0x05, 4);       /* optional */
	fake_std(2)->rtr_skip = 1;
	o = fake_std(3);
	o->mute_sdo = true;
	start_master();
	run_for(90 * MS);

	stop = first_nmt(0x02, 0);
	zassert_true(stop >= 0, "000#0200");
	zassert_equal(master_state(), CO_NMT_STOPPED);
	zassert_equal(t.n_startup_ind, 1, "the startup ends");
	zassert_equal(t.startup_result, CO_MGR_STARTUP_DONE);
	ab = find_sdo_abort(3, 0x1000, CO_SDO_AB_DATA_DEV_STATE);
	zassert_true(ab > stop, "the optional slave's upload is aborted on the bus");
	zassert_equal(t.log[ab].at, t.log[stop].at);
	zassert_ok(co_mgr_get_boot(&t.master, 3, &info));
	zassert_false(info.booting);
	zassert_equal(info.status, CO_MGR_ST_B);
	zassert_equal(info.attempts, 1);
	zassert_equal(info.error.step, CO_MGR_STEP_DEVTYPE);
	zassert_equal(info.error.abort_code, CO_SDO_AB_DATA_DEV_STATE);

	/* Stopped: no SDO, no start, the error handler's stop stands. */
	run_for(3000 * MS);
	zassert_equal(count_nmt(0x02, 0), 1);
	zassert_equal(count_sdo(3, true, 0x1000, 0), 1);
	for (int i = stop; i < t.n_log; i++) {
		zassert_false(t.log[i].f.id == 0x000 && t.log[i].f.data[0] == 0x01,
			      "nothing started after the stop");
	}
	zassert_equal(master_state(), CO_NMT_STOPPED);
	zassert_equal(t.n_startup_ind, 1);

	/* Started again: the optional slave is booted and started. */
	o->mute_sdo = false;
	bus_nmt(0x01, MASTER);
	run_for(500 * MS);
	zassert_equal(master_state(), CO_NMT_OPERATIONAL);
	zassert_equal(last_boot_status(3), CO_MGR_ST_OK);
	zassert_equal(count_nmt(0x01, 3), 1);
	zassert_ok(co_mgr_get_boot(&t.master, 3, &info));
	zassert_equal(info.attempts, 2);
}

/*
 * Found by fuzzing: the same stop while a second mandatory slave has not booted and 1F89h is
 * 0 (wait for ever). The Stopped master cannot boot it, so the startup would run for ever; it
 * halts with the lost slave's error instead: F for guarding, K for heartbeat.
 */
static void stop_all_with_a_mandatory_slave_pending(bool guarding)
{
	struct fake *f;

	cfg(0x1F80, 0, 0x41, 4);
	cfg(0x1F81, 2, guarding ? 0x0032010DU : 0x0DU, 4);
	cfg(0x1F81, 3, 0x0D, 4); /* mandatory, never answers */
	if (!guarding) {
		cfg(0x1016, 1, (2U << 16) | 100U, 4);
	}
	f = fake_std(2);
	if (guarding) {
		f->rtr_skip = 1;
	} else {
		f->hb_ms = 50;
		f->next_hb = 10 * MS;
	}
	start_master();
	run_for(guarding ? 90 * MS : 300 * MS);
	if (!guarding) {
		zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
		zassert_equal(master_state(), CO_NMT_PRE_OPERATIONAL);
		zassert_equal(t.n_startup_ind, 0, "waits for node 3");
		f->present = false;
		run_for(300 * MS);
	}
	zassert_equal(master_state(), CO_NMT_STOPPED);
	zassert_equal(count_nmt(0x02, 0), 1);
	zassert_equal(t.n_startup_ind, 1, "the startup ends");
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_HALTED);
	zassert_equal(t.startup_result, CO_MGR_STARTUP_HALTED);
	zassert_equal(t.startup_err.node_id, 2);
	zassert_equal(t.startup_err.status, guarding ? CO_MGR_ST_F : CO_MGR_ST_K);
	run_for(3000 * MS);
	zassert_equal(t.n_startup_ind, 1);
	zassert_equal(master_state(), CO_NMT_STOPPED);
	for (int i = 0; i < t.n_log; i++) {
		zassert_false(t.log[i].f.id == 0x000 && t.log[i].f.data[0] == 0x01,
			      "nothing started");
	}
}

ZTEST(co_mgr, test_stop_all_on_guarding_loss_halts_a_startup_waiting_for_a_mandatory_slave)
{
	stop_all_with_a_mandatory_slave_pending(true);
}

ZTEST(co_mgr, test_stop_all_on_heartbeat_loss_halts_a_startup_waiting_for_a_mandatory_slave)
{
	stop_all_with_a_mandatory_slave_pending(false);
}

/* --- The boot waits for the slave's boot-up after the startup's reset (302-2 §3.1) ------------ */

/*
 * A slave that needs 5 ms to come back from Reset Communication ignores SDO requests before
 * its boot-up. Its boot starts with the boot-up: milliseconds, not an SDO timeout, so a
 * mandatory slave boots well within 1F89h.
 */
ZTEST(co_mgr, test_boot_waits_for_the_bootup_after_the_startup_reset_communication)
{
	struct fake *f;
	int reset;
	int up;
	int start;

	cfg(0x1F80, 0, 0x01, 4);
	cfg(0x1F81, 2, 0x0D, 4); /* mandatory */
	cfg(0x1F89, 0, 500, 4);
	f = fake_std(2);
	f->bootup_us = 5 * MS;
	start_master();
	run_for(600 * MS);

	reset = first_nmt(0x82, 0);
	up = first_sdo(2, true, 0x1000, 0);
	start = first_nmt(0x01, 2);
	zassert_true(reset >= 0 && up > reset && start > up);
	zassert_true(t.log[up].at >= t.log[reset].at + 5 * MS, "first SDO after the boot-up");
	zassert_equal(count_sdo(2, true, 0x1000, 0), 1, "no SDO timeout, no retry");
	zassert_true(t.log[start].at - t.log[reset].at < 50 * MS, "OPERATIONAL after %llu us",
		     t.log[start].at - t.log[reset].at);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
}

/* A slave that sends no boot-up after the reset is booted after the bounded wait. */
ZTEST(co_mgr, test_boot_without_bootup_after_the_startup_reset_starts_after_bounded_wait)
{
	const uint64_t wait = (uint64_t)CONFIG_CANOPEN_MGR_BOOTUP_WAIT * MS;
	struct fake *f;
	int reset;
	int up;

	cfg(0x1F80, 0, 0x01, 4);
	cfg(0x1F81, 2, 0x05, 4);
	f = fake_std(2);
	f->no_bootup = true;
	start_master();
	run_for(wait + 500 * MS);

	reset = first_nmt(0x82, 0);
	up = first_sdo(2, true, 0x1000, 0);
	zassert_true(reset >= 0 && up > reset);
	zassert_true(t.log[up].at - t.log[reset].at >= wait, "waited for a boot-up");
	zassert_true(t.log[up].at - t.log[reset].at < wait + 10 * MS, "bounded");
	zassert_equal(count_sdo(2, true, 0x1000, 0), 1);
	zassert_equal(last_boot_status(2), CO_MGR_ST_OK);
	zassert_equal(count_nmt(0x01, 2), 1);
	zassert_equal(co_mgr_get_startup(&t.master), CO_MGR_STARTUP_DONE);
}
