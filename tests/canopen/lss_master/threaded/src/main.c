/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The LSS master's blocking calls, made from an application thread (the test's) while the
 * master's node runs on a real line thread over the virtual bus (controller 0) and two
 * unconfigured slaves on another line (controller 1).
 */

#include <errno.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>
#include <canopen/lss.h>
#include <canopen/lss_master.h>
#include <canopen/node.h>

#include "lss_test_od.h"

#define MASTER_ID 0x01
#define WAIT      K_SECONDS(10)
/*
 * A scan is up to 133 steps of 50 ms (6.7 s); a late answer on a loaded host restarts it, so
 * the call waits for several scans (with 10 s one restart made it -EAGAIN under ASan in CI).
 */
#define SCAN_WAIT K_SECONDS(60)

static struct co_line mline;
static struct co_line sline;
static struct co_node master;
static struct co_node slave[2];
static struct lss_test_od_ram mram;
static struct lss_test_od_ram sram[2];
static K_THREAD_STACK_DEFINE(mstack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_THREAD_STACK_DEFINE(sstack, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* What a blocking call made in the line thread returned. */
static int in_line_err;
static K_SEM_DEFINE(in_line_sem, 0, 1);

static void set_serial(struct co_node *node, uint32_t serial)
{
	uint8_t buf[4];

	sys_put_le32(serial, buf);
	co_node_lock(node);
	zassert_ok(co_od_write(co_node_od(node), 0x1018, 4, buf, 4, CO_OD_WRITER_APP));
	co_node_unlock(node);
}

static void *setup(void)
{
	zassert_ok(co_line_init(&mline, "mline", device_get_binding("can_virtual0")));
	zassert_ok(co_line_init(&sline, "sline", device_get_binding("can_virtual1")));
	zassert_ok(co_node_init(&master, "master", &mline, &lss_test_od_def, &mram, MASTER_ID));
	zassert_ok(co_node_start(&master));
	for (int i = 0; i < 2; i++) {
		zassert_ok(co_node_init(&slave[i], "slave", &sline, &lss_test_od_def, &sram[i],
					CO_NODE_ID_UNCONFIGURED));
		zassert_ok(co_node_start(&slave[i]));
		set_serial(&slave[i], 0x2000U - (uint32_t)i);
	}
	zassert_ok(co_line_start(&mline, mstack, K_THREAD_STACK_SIZEOF(mstack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	zassert_ok(co_line_start(&sline, sstack, K_THREAD_STACK_SIZEOF(sstack),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	return NULL;
}

static void teardown(void *f)
{
	co_line_stop(&mline);
	co_line_stop(&sline);
}

ZTEST_SUITE(co_lss_master_threaded, NULL, setup, NULL, NULL, teardown);

/* Runs in the master's line thread. */
static void con_calls_blocking(struct co_node *node, int err,
			       const struct co_lss_master_result *res, void *user_data)
{
	in_line_err = co_lss_master_identify_non_configured(node, K_MSEC(100), NULL);
	k_sem_give(&in_line_sem);
}

ZTEST(co_lss_master_threaded, test_1_blocking_calls_from_an_application_thread)
{
	struct co_lss_master_result res;
	int64_t t0;

	zassert_ok(co_lss_master_identify_non_configured(&master, WAIT, &res));
	zassert_equal(res.answers, 2, "both slaves answered");

	for (int n = 0; n < 2; n++) {
		struct co_node *found = &slave[1 - n]; /* the lower serial number first */

		memset(&res, 0, sizeof(res));
		zassert_ok(co_lss_master_fastscan(&master, NULL, 0, SCAN_WAIT, &res), "slave %d",
			   n);
		zassert_equal(res.address.part[3], 0x2000U - 1U + (uint32_t)n);
		/* 133 without a restart; the simulated-time suite asserts the exact count, here a
		 * late answer on a loaded host may cost a restart.
		 */
		zassert_true(res.frames >= 133, "%u frames", res.frames);
		zassert_equal(co_lss_get_state(found), CO_LSS_STATE_CONFIGURATION);
		zassert_ok(co_lss_master_inquire(&master, CO_LSS_CS_INQUIRE_SERIAL, WAIT, &res));
		zassert_equal(res.value, 0x2000U - 1U + (uint32_t)n);
		zassert_ok(co_lss_master_config_node_id(&master, (uint8_t)(0x40 + n), WAIT, &res));
		zassert_ok(co_lss_master_switch_global(&master, CO_LSS_MODE_WAITING));
		t0 = k_uptime_get();
		while (co_node_id(found) != 0x40 + n && k_uptime_get() - t0 < 2000) {
			k_msleep(5);
		}
		zassert_equal(co_node_id(found), 0x40 + n, "booted with its node-ID");
	}
	zassert_equal(co_lss_master_fastscan(&master, NULL, 0, WAIT, &res), -ENODEV);
	/* Configuration state without any slave in it: no answer. */
	zassert_equal(co_lss_master_store(&master, WAIT, &res), -ETIMEDOUT);
}

ZTEST(co_lss_master_threaded, test_2_call_timeout_cancels_the_request)
{
	struct co_lss_master_result res;
	int64_t t0 = k_uptime_get();

	/* Nobody answers a store in waiting; the call gives up before the protocol timeout. */
	zassert_equal(co_lss_master_store(&master, K_MSEC(20), &res), -EAGAIN);
	zassert_true(k_uptime_get() - t0 < CONFIG_CANOPEN_LSS_MASTER_TIMEOUT);
	zassert_false(co_lss_master_busy(&master), "idle at once");
	zassert_equal(co_lss_master_store(&master, K_FOREVER, &res), -ETIMEDOUT);
}

ZTEST(co_lss_master_threaded, test_3_blocking_call_in_a_line_thread_is_edeadlk)
{
	zassert_ok(co_lss_master_inquire_req(&master, CO_LSS_CS_INQUIRE_NODE_ID, 5,
					     con_calls_blocking, NULL));
	zassert_ok(k_sem_take(&in_line_sem, WAIT));
	zassert_equal(in_line_err, -EDEADLK);

	co_node_lock(&master);
	zassert_equal(co_lss_master_identify_non_configured(&master, K_MSEC(10), NULL), -EDEADLK,
		      "with the master's mutex held");
	co_node_unlock(&master);
}
