/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Program download in the boot's "check and update software version" step (CiA 302 §4
 * step 4, §9; doc/pgm.md): stop the program (1F51h:01 = 0), download the image the
 * application gives (1F50h:01, block SDO), start it (1F51h:01 = 1), wait for the boot-up of
 * the slave restarting with it, and read 1F52h again. These are steps of mgr_boot.c's table;
 * any failure ends the attempt with I. After a failed download the slave is told to start
 * again, so that its old program runs while the manager reports I.
 */

#include <string.h>

#include <zephyr/logging/log.h>

#include <canopen/pgm.h>
#include <canopen/sdo_abort.h>

#include "mgr_internal.h"

LOG_MODULE_DECLARE(co_node, CONFIG_CANOPEN_LOG_LEVEL);

#define IDX_PGM_DATA 0x1F50U
#define IDX_PGM_CTRL 0x1F51U

static uint8_t xfer(struct co_mgr_slave *s, uint16_t index, const void *data, size_t len,
		    enum co_sdo_cli_mode mode)
{
	s->sdo_pending = true;
	s->xfer_index = index;
	s->xfer_sub = 1U;
	if (co_sdo_cli_download_req(co_mgr_cli(s), index, 1U, data, len, mode,
				    CONFIG_CANOPEN_MGR_PGM_TIMEOUT, co_mgr_boot_sdo_con, s) != 0) {
		s->sdo_pending = false;
		return co_mgr_boot_fail(s, CO_MGR_ST_I, index, 1U, 0U, 0U, CO_SDO_AB_GENERAL);
	}
	return CO_MGR_NEXT_WAIT;
}

static uint8_t ctrl(struct co_mgr_slave *s, uint8_t cmd)
{
	s->pgm_ctrl = cmd;
	return xfer(s, IDX_PGM_CTRL, &s->pgm_ctrl, 1U, CO_SDO_CLI_AUTO);
}

static uint32_t buf_u32(struct co_mgr_slave *s)
{
	return (uint32_t)co_od_le_get(s->buf, sizeof(s->buf));
}

bool co_mgr_pgm_has_image(struct co_mgr_slave *s)
{
	struct co_mgr *m = s->mgr;

	s->pgm_image = NULL;
	s->pgm_len = 0U;
	if (m->pgm_source == NULL ||
	    m->pgm_source(m->node, s->id, &s->pgm_image, &s->pgm_len, m->pgm_user_data) != 0 ||
	    s->pgm_image == NULL || s->pgm_len == 0U) {
		return false;
	}
	LOG_INF("%s: node %u: downloading a program of %u bytes", m->node->name, s->id,
		(unsigned int)s->pgm_len);
	return true;
}

uint8_t co_mgr_pgm_stop(struct co_mgr_slave *s)
{
	return ctrl(s, CO_PGM_STOP);
}

uint8_t co_mgr_pgm_stop_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_PGM_CTRL, 1U, CO_PGM_STOP, 0U, ab);
	}
	return CO_MGR_STEP_PGM_DOWNLOAD;
}

uint8_t co_mgr_pgm_download(struct co_mgr_slave *s)
{
	return xfer(s, IDX_PGM_DATA, s->pgm_image, s->pgm_len, CO_SDO_CLI_BLOCK);
}

uint8_t co_mgr_pgm_download_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		s->pgm_abort = ab;
		return CO_MGR_STEP_PGM_RESUME;
	}
	return CO_MGR_STEP_PGM_START;
}

uint8_t co_mgr_pgm_start(struct co_mgr_slave *s)
{
	return ctrl(s, CO_PGM_START);
}

uint8_t co_mgr_pgm_start_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_PGM_CTRL, 1U, CO_PGM_START, 0U, ab);
	}
	return CO_MGR_STEP_PGM_RESTART;
}

uint8_t co_mgr_pgm_restart(struct co_mgr_slave *s)
{
	if (CONFIG_CANOPEN_MGR_PGM_RESTART_WAIT == 0) {
		return CO_MGR_STEP_PGM_DATE;
	}
	co_mgr_arm(s, CONFIG_CANOPEN_MGR_PGM_RESTART_WAIT);
	return CO_MGR_NEXT_WAIT;
}

uint8_t co_mgr_pgm_restart_ec(struct co_mgr_slave *s, uint8_t byte)
{
	if (byte != 0U) {
		/* A heartbeat of the life before the restart. */
		return CO_MGR_NEXT_WAIT;
	}
	co_timer_stop(&s->timer);
	return CO_MGR_STEP_PGM_DATE;
}

uint8_t co_mgr_pgm_restart_to(struct co_mgr_slave *s)
{
	/* No boot-up: a slave may start the new program without restarting. */
	return CO_MGR_STEP_PGM_DATE;
}

uint8_t co_mgr_pgm_date(struct co_mgr_slave *s)
{
	return co_mgr_boot_upload(s, IDX_SW_VERIFY, 1U);
}

uint8_t co_mgr_pgm_date_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	if (ab != 0U) {
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_SW_VERIFY, 1U,
					co_mgr_od(s->mgr, IDX_SW_DATE, s->id), 0U, ab);
	}
	s->sw_date = buf_u32(s);
	return CO_MGR_STEP_PGM_TIME;
}

uint8_t co_mgr_pgm_time(struct co_mgr_slave *s)
{
	return co_mgr_boot_upload(s, IDX_SW_VERIFY, 2U);
}

uint8_t co_mgr_pgm_time_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	uint32_t ed = co_mgr_od(s->mgr, IDX_SW_DATE, s->id);
	uint32_t et = co_mgr_od(s->mgr, IDX_SW_TIME, s->id);
	uint32_t at = buf_u32(s);

	if (ab != 0U) {
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_SW_VERIFY, 2U, et, 0U, ab);
	}
	if (s->sw_date != ed) {
		/* The program downloaded is not the one expected: still a mismatch. */
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_SW_VERIFY, 1U, ed, s->sw_date, 0U);
	}
	if (at != et) {
		return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_SW_VERIFY, 2U, et, at, 0U);
	}
	LOG_INF("%s: node %u runs the new program", s->mgr->node->name, s->id);
	return CO_MGR_STEP_CFG_DATE;
}

uint8_t co_mgr_pgm_resume(struct co_mgr_slave *s)
{
	return ctrl(s, CO_PGM_START);
}

uint8_t co_mgr_pgm_resume_sdo(struct co_mgr_slave *s, uint32_t ab)
{
	/* The result is the download's failure, whatever the restart of the old program did. */
	ARG_UNUSED(ab);
	return co_mgr_boot_fail(s, CO_MGR_ST_I, IDX_PGM_DATA, 1U, 0U, 0U, s->pgm_abort);
}

void co_mgr_set_pgm_source(struct co_node *node, co_mgr_pgm_source_t cb, void *user_data)
{
	co_node_lock(node);
	node->mgr.pgm_source = cb;
	node->mgr.pgm_user_data = user_data;
	co_node_unlock(node);
}
