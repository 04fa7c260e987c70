/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * LSS master (CiA 305): requests on 7E5h, answers on 7E4h, on the node's default line.
 *
 * One request at a time. A request with an answer arms one timer; the answer it waits for
 * (by command specifier) ends it, anything else on 7E4h is ignored. Identify requests and
 * every fastscan step wait the whole timeout, because any number of slaves may answer and
 * a late answer must not fall into the next step.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <canopen/lss_master.h>
#include <canopen/node.h>

#include "node_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

/* fs_bit while the probe (BitCheck 80h) runs, and while a verify runs. */
#define FS_PROBE  32
#define FS_VERIFY (-1)

static struct co_lss_master *lm(struct co_node *node)
{
	return &node->lssm;
}

static int send_frame(struct co_node *node, const struct can_frame *f)
{
	int err = co_node_send(node, CO_ROUTE_DEFAULT, f);

	if (err == 0) {
		lm(node)->stats.frames_sent++;
		lm(node)->res.frames++;
	}
	return err;
}

static int send_cs(struct co_node *node, uint8_t cs, uint8_t b1, uint8_t b2)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, cs);
	f.data[1] = b1;
	f.data[2] = b2;
	return send_frame(node, &f);
}

static int send_u32(struct co_node *node, uint8_t cs, uint32_t value)
{
	struct can_frame f;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, cs);
	co_lss_frame_set_u32(&f, value);
	return send_frame(node, &f);
}

static void arm(struct co_node *node)
{
	struct co_lss_master *m = lm(node);

	m->answered = false;
	co_node_timer_start(node, &m->timer, co_node_time(node) + (uint64_t)m->timeout_ms * 1000U);
}

/* End the running request and confirm it. */
static void finish(struct co_node *node, int err)
{
	struct co_lss_master *m = lm(node);
	struct co_lss_master_result res = m->res;
	co_lss_master_con_t con = m->con;
	void *user_data = m->user_data;

	co_timer_stop(&m->timer);
	m->op = 0U;
	m->expect = 0U;
	m->con = NULL;
	if (err == -ETIMEDOUT) {
		m->stats.timeouts++;
	}
	if (con != NULL) {
		con(node, err, &res, user_data);
	}
}

/* Claim the master for a request; fails with -EBUSY while one runs. */
static int begin(struct co_node *node, uint8_t op, uint8_t expect, uint32_t timeout_ms,
		 co_lss_master_con_t con, void *user_data)
{
	struct co_lss_master *m = lm(node);

	if (m->op != 0U) {
		return -EBUSY;
	}
	m->op = op;
	m->expect = expect;
	m->timeout_ms = timeout_ms != 0U ? timeout_ms : CONFIG_CANOPEN_LSS_MASTER_TIMEOUT;
	m->con = con;
	m->user_data = user_data;
	m->res = (struct co_lss_master_result){.cs = op};
	m->answered = false;
	m->stats.requests++;
	return 0;
}

/* The first frames did not go out: nothing started, no confirmation. */
static int abandon(struct co_node *node, int err)
{
	struct co_lss_master *m = lm(node);

	co_timer_stop(&m->timer);
	m->op = 0U;
	m->expect = 0U;
	m->con = NULL;
	return err;
}

/* --- Fastscan ----------------------------------------------------------------------------- */

static int fs_send(struct co_node *node, uint32_t id, uint8_t bit, uint8_t sub, uint8_t next)
{
	struct can_frame f;
	int err;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, CO_LSS_CS_FASTSCAN);
	co_lss_frame_set_u32(&f, id);
	f.data[5] = bit;
	f.data[6] = sub;
	f.data[7] = next;
	err = send_frame(node, &f);
	if (err == 0) {
		arm(node);
	}
	return err;
}

/* The part after @p sub in the scan order (0 after the serial number). */
static uint8_t fs_next_part(uint8_t sub)
{
	return sub == CO_LSS_FASTSCAN_SERIAL ? CO_LSS_FASTSCAN_VENDOR : (uint8_t)(sub + 1U);
}

/* Start part @p sub: a known part is verified at once, an unknown one scanned from bit 31. */
static int fs_part(struct co_node *node, uint8_t sub)
{
	struct co_lss_master *m = lm(node);

	m->fs_sub = sub;
	if ((m->fs_known & BIT(sub)) != 0U) {
		m->fs_id = m->fs_known_addr.part[sub];
		m->fs_bit = FS_VERIFY;
		return fs_send(node, m->fs_id, 0U, sub, fs_next_part(sub));
	}
	m->fs_id = 0U;
	m->fs_bit = 31;
	/* The bit under test is 0 in IDNumber: an answer says a slave has a 0 there. */
	return fs_send(node, m->fs_id, 31U, sub, sub);
}

static int fs_probe(struct co_node *node)
{
	struct co_lss_master *m = lm(node);

	m->fs_bit = FS_PROBE;
	return fs_send(node, 0U, CO_LSS_FASTSCAN_CONFIRM, 0U, 0U);
}

/* A fastscan step's timeout ran out: decide, then send the next step. */
static void fs_step_done(struct co_node *node)
{
	struct co_lss_master *m = lm(node);
	int err;

	if (m->fs_bit == FS_PROBE) {
		if (!m->answered) {
			finish(node, -ENODEV);
			return;
		}
		err = fs_part(node, CO_LSS_FASTSCAN_VENDOR);
	} else if (m->fs_bit == FS_VERIFY) {
		if (!m->answered) {
			/* The slave followed so far is gone (or a known part matched none). */
			if (m->res.restarts >= CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_RESTARTS) {
				finish(node, -EIO);
				return;
			}
			m->res.restarts++;
			LOG_WRN("%s: LSS master: fastscan lost its slave at part %u, restarting",
				node->name, m->fs_sub);
			err = fs_probe(node);
		} else {
			m->res.address.part[m->fs_sub] = m->fs_id;
			if (m->fs_sub == CO_LSS_FASTSCAN_SERIAL) {
				finish(node, 0);
				return;
			}
			err = fs_part(node, (uint8_t)(m->fs_sub + 1U));
		}
	} else {
		if (!m->answered) {
			/* No slave has a 0 there: the bit is 1. */
			m->fs_id |= BIT(m->fs_bit);
		}
		if (m->fs_bit == 0) {
			m->fs_bit = FS_VERIFY;
			err = fs_send(node, m->fs_id, 0U, m->fs_sub, fs_next_part(m->fs_sub));
		} else {
			m->fs_bit--;
			err = fs_send(node, m->fs_id, (uint8_t)m->fs_bit, m->fs_sub, m->fs_sub);
		}
	}
	if (err != 0) {
		finish(node, err);
	}
}

/* --- Line side ---------------------------------------------------------------------------- */

static void timer_handler(struct co_timer *timer, uint64_t now_us)
{
	struct co_node *node = timer->user_data;
	struct co_lss_master *m = lm(node);

	ARG_UNUSED(now_us);
	switch (m->op) {
	case 0U:
		return;
	case CO_LSS_CS_FASTSCAN:
		fs_step_done(node);
		return;
	case CO_LSS_CS_IDENT_SERIAL_HIGH:
	case CO_LSS_CS_IDENT_NON_CONFIGURED:
		finish(node, m->res.answers > 0U ? 0 : -ENODEV);
		return;
	default:
		finish(node, -ETIMEDOUT);
		return;
	}
}

static void rx_handler(struct co_rx *rx, const struct can_frame *f, uint64_t now_us)
{
	struct co_node *node = rx->user_data;
	struct co_lss_master *m = lm(node);
	uint8_t cs = f->data[0];

	ARG_UNUSED(now_us);
	if (!co_lss_frame_valid(f) || m->expect == 0U || cs != m->expect) {
		m->stats.ignored++;
		return;
	}
	m->stats.answers++;
	switch (m->op) {
	case CO_LSS_CS_FASTSCAN:
		/* Decided when the step's time is up. */
		m->answered = true;
		return;
	case CO_LSS_CS_IDENT_SERIAL_HIGH:
	case CO_LSS_CS_IDENT_NON_CONFIGURED:
		m->res.answers++;
		return;
	case CO_LSS_CS_CONFIG_NODE_ID:
	case CO_LSS_CS_CONFIG_BIT_TIMING:
	case CO_LSS_CS_STORE:
		m->res.lss_err = f->data[1];
		m->res.lss_spec = f->data[2];
		finish(node, f->data[1] == CO_LSS_ERR_OK ? 0 : -EREMOTEIO);
		return;
	case CO_LSS_CS_INQUIRE_NODE_ID:
		m->res.value = f->data[1];
		finish(node, 0);
		return;
	case CO_LSS_CS_INQUIRE_VENDOR:
	case CO_LSS_CS_INQUIRE_PRODUCT:
	case CO_LSS_CS_INQUIRE_REVISION:
	case CO_LSS_CS_INQUIRE_SERIAL:
		m->res.value = co_lss_frame_get_u32(f);
		finish(node, 0);
		return;
	default: /* switch selective: 44h */
		finish(node, 0);
		return;
	}
}

/* --- Node interface ----------------------------------------------------------------------- */

static int lssm_init(struct co_node *node)
{
	struct co_lss_master *m = lm(node);

	co_timer_init(&m->timer, timer_handler, &node->lock, node);
	co_rx_init(&m->rx, CO_LSS_SLAVE_COB_ID, rx_handler, &node->lock, node);
	return co_node_rx_register(node, CO_LINE_DEFAULT, &m->rx);
}

/* A reset of the master's node ends its request: the application starts anew. */
static void lssm_reset_comm(struct co_node *node)
{
	if (lm(node)->op != 0U) {
		finish(node, -ECANCELED);
	}
}

const struct co_service co_service_lss_master = {
	.name = "lss_master",
	.init = lssm_init,
	.reset_comm = lssm_reset_comm,
};

/* --- Asynchronous API --------------------------------------------------------------------- */

int co_lss_master_switch_global(struct co_node *node, uint8_t mode)
{
	int err;

	if (mode != CO_LSS_MODE_WAITING && mode != CO_LSS_MODE_CONFIGURATION) {
		return -EINVAL;
	}
	co_node_lock(node);
	err = lm(node)->op != 0U ? -EBUSY : send_cs(node, CO_LSS_CS_SWITCH_GLOBAL, mode, 0U);
	co_node_unlock(node);
	return err;
}

int co_lss_master_activate_bit_timing(struct co_node *node, uint16_t delay_ms)
{
	struct can_frame f;
	int err;

	co_lss_frame_init(&f, CO_LSS_MASTER_COB_ID, CO_LSS_CS_ACTIVATE_BIT_TIMING);
	sys_put_le16(delay_ms, &f.data[1]);
	co_node_lock(node);
	err = lm(node)->op != 0U ? -EBUSY : send_frame(node, &f);
	co_node_unlock(node);
	return err;
}

/* A request of one frame and one answer of the same command specifier. */
static int simple_req(struct co_node *node, uint8_t cs, uint8_t b1, uint8_t b2, uint32_t timeout_ms,
		      co_lss_master_con_t con, void *user_data)
{
	int err;

	co_node_lock(node);
	err = begin(node, cs, cs, timeout_ms, con, user_data);
	if (err == 0) {
		err = send_cs(node, cs, b1, b2);
		if (err == 0) {
			arm(node);
		} else {
			(void)abandon(node, err);
		}
	}
	co_node_unlock(node);
	return err;
}

int co_lss_master_config_node_id_req(struct co_node *node, uint8_t node_id, uint32_t timeout_ms,
				     co_lss_master_con_t con, void *user_data)
{
	if (node_id == 0U || (node_id > 127U && node_id != CO_NODE_ID_UNCONFIGURED)) {
		return -EINVAL;
	}
	return simple_req(node, CO_LSS_CS_CONFIG_NODE_ID, node_id, 0U, timeout_ms, con, user_data);
}

int co_lss_master_config_bit_timing_req(struct co_node *node, uint8_t table, uint8_t index,
					uint32_t timeout_ms, co_lss_master_con_t con,
					void *user_data)
{
	return simple_req(node, CO_LSS_CS_CONFIG_BIT_TIMING, table, index, timeout_ms, con,
			  user_data);
}

int co_lss_master_store_req(struct co_node *node, uint32_t timeout_ms, co_lss_master_con_t con,
			    void *user_data)
{
	return simple_req(node, CO_LSS_CS_STORE, 0U, 0U, timeout_ms, con, user_data);
}

int co_lss_master_inquire_req(struct co_node *node, uint8_t cs, uint32_t timeout_ms,
			      co_lss_master_con_t con, void *user_data)
{
	if (cs < CO_LSS_CS_INQUIRE_VENDOR || cs > CO_LSS_CS_INQUIRE_NODE_ID) {
		return -EINVAL;
	}
	return simple_req(node, cs, 0U, 0U, timeout_ms, con, user_data);
}

int co_lss_master_identify_non_configured_req(struct co_node *node, uint32_t timeout_ms,
					      co_lss_master_con_t con, void *user_data)
{
	int err;

	co_node_lock(node);
	err = begin(node, CO_LSS_CS_IDENT_NON_CONFIGURED, CO_LSS_CS_IDENT_NON_CONFIGURED_SLAVE,
		    timeout_ms, con, user_data);
	if (err == 0) {
		err = send_cs(node, CO_LSS_CS_IDENT_NON_CONFIGURED, 0U, 0U);
		if (err == 0) {
			arm(node);
		} else {
			(void)abandon(node, err);
		}
	}
	co_node_unlock(node);
	return err;
}

/* Several frames in a row (selective switch, identify remote), then one timeout. */
static int sequence_req(struct co_node *node, uint8_t op, uint8_t expect, uint8_t first_cs,
			const uint32_t *values, size_t n, uint32_t timeout_ms,
			co_lss_master_con_t con, void *user_data)
{
	int err;

	co_node_lock(node);
	err = begin(node, op, expect, timeout_ms, con, user_data);
	for (size_t i = 0U; err == 0 && i < n; i++) {
		err = send_u32(node, (uint8_t)(first_cs + i), values[i]);
		if (err != 0) {
			(void)abandon(node, err);
		}
	}
	if (err == 0) {
		arm(node);
	}
	co_node_unlock(node);
	return err;
}

int co_lss_master_switch_selective_req(struct co_node *node, const struct co_lss_address *addr,
				       uint32_t timeout_ms, co_lss_master_con_t con,
				       void *user_data)
{
	if (addr == NULL) {
		return -EINVAL;
	}
	return sequence_req(node, CO_LSS_CS_SWITCH_SEL_SERIAL, CO_LSS_CS_SWITCH_SEL_RESULT,
			    CO_LSS_CS_SWITCH_SEL_VENDOR, addr->part, 4U, timeout_ms, con,
			    user_data);
}

int co_lss_master_identify_remote_req(struct co_node *node, uint32_t vendor, uint32_t product,
				      uint32_t rev_low, uint32_t rev_high, uint32_t serial_low,
				      uint32_t serial_high, uint32_t timeout_ms,
				      co_lss_master_con_t con, void *user_data)
{
	const uint32_t values[6] = {vendor, product, rev_low, rev_high, serial_low, serial_high};

	if (rev_low > rev_high || serial_low > serial_high) {
		return -EINVAL;
	}
	return sequence_req(node, CO_LSS_CS_IDENT_SERIAL_HIGH, CO_LSS_CS_IDENT_SLAVE,
			    CO_LSS_CS_IDENT_VENDOR, values, 6U, timeout_ms, con, user_data);
}

int co_lss_master_fastscan_req(struct co_node *node, const struct co_lss_address *known,
			       uint8_t known_mask, uint32_t timeout_ms, co_lss_master_con_t con,
			       void *user_data)
{
	struct co_lss_master *m = lm(node);
	int err;

	if (known_mask > 0x0FU || (known_mask != 0U && known == NULL)) {
		return -EINVAL;
	}
	co_node_lock(node);
	err = begin(node, CO_LSS_CS_FASTSCAN, CO_LSS_CS_IDENT_SLAVE,
		    timeout_ms != 0U ? timeout_ms : CONFIG_CANOPEN_LSS_MASTER_FASTSCAN_TIMEOUT, con,
		    user_data);
	if (err == 0) {
		m->fs_known = known_mask;
		if (known != NULL) {
			m->fs_known_addr = *known;
		}
		err = fs_probe(node);
		if (err != 0) {
			(void)abandon(node, err);
		}
	}
	co_node_unlock(node);
	return err;
}

int co_lss_master_cancel(struct co_node *node)
{
	int err = 0;

	co_node_lock(node);
	if (lm(node)->op == 0U) {
		err = -EALREADY;
	} else {
		finish(node, -ECANCELED);
	}
	co_node_unlock(node);
	return err;
}

bool co_lss_master_busy(struct co_node *node)
{
	bool busy;

	co_node_lock(node);
	busy = lm(node)->op != 0U;
	co_node_unlock(node);
	return busy;
}

void co_lss_master_get_stats(struct co_node *node, struct co_lss_master_stats *stats)
{
	co_node_lock(node);
	*stats = lm(node)->stats;
	co_node_unlock(node);
}

/* --- Blocking API ------------------------------------------------------------------------- */

/* One blocking call: lives on the caller's stack until the call returns. */
struct sync_call {
	struct k_sem sem;
	int err;
	struct co_lss_master_result res;
};

static void sync_con(struct co_node *node, int err, const struct co_lss_master_result *res,
		     void *user_data)
{
	struct sync_call *call = user_data;

	ARG_UNUSED(node);
	call->err = err;
	call->res = *res;
	k_sem_give(&call->sem);
}

/*
 * The confirmation comes from the master's line thread, which takes the mutex of every node
 * on its line around their dispatches: waiting in a line thread or with one of those mutexes
 * held could stop it for good (the rule of the blocking SDO client).
 */
static int sync_check(struct co_node *node, k_timeout_t timeout)
{
	struct co_line *line;

	if (node == NULL || K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		return -EINVAL;
	}
	line = co_node_line(node);
	if (co_line_current() != NULL || k_current_get() == &line->thread ||
	    co_line_owner_held(line)) {
		return -EDEADLK;
	}
	return 0;
}

/*
 * Wait for the confirmation. When @p timeout expires first the request is cancelled under
 * the node's mutex: either the line thread confirmed it already (the master no longer
 * carries @p call) or it cannot until we are done.
 */
static int sync_wait(struct co_node *node, struct sync_call *call, k_timeout_t timeout,
		     struct co_lss_master_result *res)
{
	bool expired = false;

	if (k_sem_take(&call->sem, timeout) != 0) {
		co_node_lock(node);
		if (lm(node)->op != 0U && lm(node)->con == sync_con &&
		    lm(node)->user_data == call) {
			finish(node, -ECANCELED);
			expired = true;
		}
		co_node_unlock(node);
		(void)k_sem_take(&call->sem, K_NO_WAIT);
	}
	if (res != NULL) {
		*res = call->res;
	}
	return expired ? -EAGAIN : call->err;
}

#define SYNC_CALL(node, timeout, res, start)                                                       \
	do {                                                                                       \
		struct sync_call call = {0};                                                       \
		int err = sync_check(node, timeout);                                               \
                                                                                                   \
		if (err != 0) {                                                                    \
			return err;                                                                \
		}                                                                                  \
		k_sem_init(&call.sem, 0, 1);                                                       \
		err = (start);                                                                     \
		if (err != 0) {                                                                    \
			return err;                                                                \
		}                                                                                  \
		return sync_wait(node, &call, timeout, res);                                       \
	} while (0)

int co_lss_master_switch_selective(struct co_node *node, const struct co_lss_address *addr,
				   k_timeout_t timeout, struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_switch_selective_req(node, addr, 0U, sync_con, &call));
}

int co_lss_master_config_node_id(struct co_node *node, uint8_t node_id, k_timeout_t timeout,
				 struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_config_node_id_req(node, node_id, 0U, sync_con, &call));
}

int co_lss_master_config_bit_timing(struct co_node *node, uint8_t table, uint8_t index,
				    k_timeout_t timeout, struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_config_bit_timing_req(node, table, index, 0U, sync_con, &call));
}

int co_lss_master_store(struct co_node *node, k_timeout_t timeout, struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res, co_lss_master_store_req(node, 0U, sync_con, &call));
}

int co_lss_master_inquire(struct co_node *node, uint8_t cs, k_timeout_t timeout,
			  struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res, co_lss_master_inquire_req(node, cs, 0U, sync_con, &call));
}

int co_lss_master_identify_remote(struct co_node *node, uint32_t vendor, uint32_t product,
				  uint32_t rev_low, uint32_t rev_high, uint32_t serial_low,
				  uint32_t serial_high, k_timeout_t timeout,
				  struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_identify_remote_req(node, vendor, product, rev_low, rev_high,
						    serial_low, serial_high, 0U, sync_con, &call));
}

int co_lss_master_identify_non_configured(struct co_node *node, k_timeout_t timeout,
					  struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_identify_non_configured_req(node, 0U, sync_con, &call));
}

int co_lss_master_fastscan(struct co_node *node, const struct co_lss_address *known,
			   uint8_t known_mask, k_timeout_t timeout,
			   struct co_lss_master_result *res)
{
	SYNC_CALL(node, timeout, res,
		  co_lss_master_fastscan_req(node, known, known_mask, 0U, sync_con, &call));
}
