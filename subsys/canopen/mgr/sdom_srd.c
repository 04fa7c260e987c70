/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* SDO requesting device (CiA 302 §7, doc/sdo-manager.md): the SRD's side of the exchange. */

#include <errno.h>

#include <zephyr/sys/byteorder.h>

#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/sdo_abort.h>
#include <canopen/sdom.h>

#define IDX_REQ_SDO  0x1F00U
#define IDX_REL_SDO  0x1F01U
#define IDX_SRD_STAT 0x1F10U
#define IDX_CLI_PAR  0x1280U
#define TRIGGER_ID   0x6E0U

static bool cli_index_ok(uint16_t idx)
{
	return idx >= IDX_CLI_PAR && idx <= 0x12FFU;
}

int co_sdom_srd_register(struct co_sdom_srd *srd, struct co_node *node, uint16_t reg_index)
{
	/* 302 §7.2.3: Rq indication plus the index, or the raw value 3 for the default SDOs. */
	uint32_t v = reg_index == 0U ? 0x00000003U : (((uint32_t)reg_index << 16) | 0x1U);
	struct can_frame f = {.id = TRIGGER_ID, .dlc = 0};
	uint8_t b[4];

	if (srd == NULL || node == NULL || (reg_index != 0U && !cli_index_ok(reg_index))) {
		return -EINVAL;
	}
	srd->node = node;
	srd->reg_index = reg_index;
	sys_put_le32(v, b);
	if (co_od_write(co_node_od(node), IDX_SRD_STAT, 0, b, 4, CO_OD_WRITER_APP) != 0U) {
		return -EIO;
	}
	return co_node_send(node, CO_ROUTE_ACTIVE, &f);
}

int co_sdom_srd_status(const struct co_sdom_srd *srd, struct co_sdom_status *st)
{
	uint8_t b[4];
	size_t len = 0U;
	uint32_t v;

	if (srd == NULL || srd->node == NULL || st == NULL) {
		return -EINVAL;
	}
	if (co_od_read(co_node_od(srd->node), IDX_SRD_STAT, 0, 0, b, sizeof(b), &len,
		       CO_OD_WRITER_APP) != CO_SDO_AB_NONE ||
	    len != 4U) {
		return -EIO;
	}
	v = sys_get_le32(b);
	st->index = (uint16_t)(v >> 16);
	st->error = (uint8_t)(v >> 8);
	/* Our own request value 3 is not "state 1": it is pending until the manager writes. */
	st->pending = (v & 0x1U) != 0U;
	st->state = v == 0x3U ? (uint8_t)CO_SDOM_FAILED : (uint8_t)((v >> 1) & 0x3U);
	return 0;
}

static int write_mgr(struct co_sdom_srd *srd, uint16_t index, uint32_t v, co_sdo_cli_con_t con,
		     void *user_data)
{
	struct co_sdo_cli *cli;

	if (!cli_index_ok(srd->reg_index)) {
		return -ENOTCONN;
	}
	cli = co_sdo_cli_get(srd->node, (uint8_t)(srd->reg_index - IDX_CLI_PAR));
	if (cli == NULL) {
		return -ENOTCONN;
	}
	sys_put_le32(v, srd->buf);
	return co_sdo_cli_download_req(cli, index, 0, srd->buf, 4, CO_SDO_CLI_AUTO, 1000, con,
				       user_data);
}

static uint32_t value(const struct co_sdom_srd *srd, uint16_t cli_index, uint8_t slave)
{
	return ((uint32_t)cli_index << 16) | ((uint32_t)co_node_id(srd->node) << 8) | slave;
}

int co_sdom_srd_request(struct co_sdom_srd *srd, uint16_t cli_index, uint8_t slave,
			co_sdo_cli_con_t con, void *user_data)
{
	if (srd == NULL || srd->node == NULL || !cli_index_ok(cli_index) || slave == 0U ||
	    slave > 127U) {
		return -EINVAL;
	}
	return write_mgr(srd, IDX_REQ_SDO, value(srd, cli_index, slave), con, user_data);
}

int co_sdom_srd_release(struct co_sdom_srd *srd, uint16_t cli_index, uint8_t slave,
			co_sdo_cli_con_t con, void *user_data)
{
	if (srd == NULL || srd->node == NULL || (cli_index != 0U && !cli_index_ok(cli_index)) ||
	    slave > 127U) {
		return -EINVAL;
	}
	return write_mgr(srd, IDX_REL_SDO, value(srd, cli_index, slave), con, user_data);
}
