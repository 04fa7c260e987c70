/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The SDO client with real threads: the client node and a second node (no role but to be
 * there) on line A, two server nodes on line B, both lines on one virtual bus. Application
 * threads use the blocking calls: their return contract (0, -ECONNABORTED with the abort
 * code, -EAGAIN when their k_timeout_t expires, -EINVAL), and -EDEADLK from any line thread
 * or with the mutex of any node of the client's line held.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/sdo_cli.h>

#include "sdo_cli_test_od.h"

#define CLI_ID   0x10U
#define OTHER_ID 0x11U
#define SRV_ID   0x20U
#define SRV2_ID  0x21U
#define NOBODY   0x30U
#define SIZE     4000U
#define ROUNDS   20

static struct co_line line_a, line_b;
static struct co_node cnode, onode, snode, snode2;
static struct sdo_cli_test_od_ram cram, oram, sram, sram2;
static K_THREAD_STACK_ARRAY_DEFINE(line_stacks, 2, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_THREAD_STACK_ARRAY_DEFINE(app_stacks, 2, 16384);
static struct k_thread app_threads[2];

static uint8_t out[2][SIZE];
static uint8_t in[2][SIZE];

static void *setup(void)
{
	zassert_ok(co_line_init(&line_a, "lineA", device_get_binding("can_virtual0")));
	zassert_ok(co_line_init(&line_b, "lineB", device_get_binding("can_virtual1")));
	zassert_ok(co_line_start(&line_a, line_stacks[0], K_THREAD_STACK_SIZEOF(line_stacks[0]),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	zassert_ok(co_line_start(&line_b, line_stacks[1], K_THREAD_STACK_SIZEOF(line_stacks[1]),
				 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	zassert_ok(co_node_init(&cnode, "cli", &line_a, &sdo_cli_test_od_def, &cram, CLI_ID));
	zassert_ok(co_node_init(&onode, "other", &line_a, &sdo_cli_test_od_def, &oram, OTHER_ID));
	zassert_ok(co_node_init(&snode, "srv", &line_b, &sdo_cli_test_od_def, &sram, SRV_ID));
	zassert_ok(co_node_init(&snode2, "srv2", &line_b, &sdo_cli_test_od_def, &sram2, SRV2_ID));
	zassert_ok(co_node_start(&snode));
	zassert_ok(co_node_start(&snode2));
	zassert_ok(co_node_start(&onode));
	zassert_ok(co_node_start(&cnode));
	zassert_ok(co_sdo_cli_set_server(co_sdo_cli_get(&cnode, 0), SRV_ID));
	zassert_ok(co_sdo_cli_set_server(co_sdo_cli_get(&cnode, 1), SRV2_ID));
	zassert_ok(co_sdo_cli_set_server(co_sdo_cli_get(&cnode, 2), NOBODY));
	zassert_ok(co_sdo_cli_set_server(co_sdo_cli_get(&cnode, 3), NOBODY));
	return NULL;
}

static void fill(uint8_t *p, size_t len, uint32_t seed)
{
	for (size_t i = 0; i < len; i++) {
		seed = seed * 1103515245U + 12345U;
		p[i] = (uint8_t)(seed >> 16);
	}
}

ZTEST(sdo_cli_threaded, test_blocking_calls_every_protocol)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	static const enum co_sdo_cli_mode modes[] = {CO_SDO_CLI_AUTO, CO_SDO_CLI_SEGMENTED,
						     CO_SDO_CLI_BLOCK};
	static const size_t sizes[] = {1, 4, 5, 100, 889, SIZE};

	for (size_t m = 0; m < ARRAY_SIZE(modes); m++) {
		for (size_t s = 0; s < ARRAY_SIZE(sizes); s++) {
			uint32_t code = 1;
			size_t len = 0;

			fill(out[0], sizes[s], (uint32_t)(m * 10 + s));
			memset(in[0], 0, SIZE);
			zassert_ok(co_sdo_cli_download(cli, 0x2005, 0, out[0], sizes[s], modes[m],
						       K_SECONDS(10), &code));
			zassert_equal(code, 0U, "download %zu mode %zu: %08x", sizes[s], m, code);
			zassert_ok(co_sdo_cli_upload(cli, 0x2005, 0, in[0], SIZE, &len, modes[m],
						     K_SECONDS(10), &code));
			zassert_equal(code, 0U, "upload %zu mode %zu: %08x", sizes[s], m, code);
			zassert_equal(len, sizes[s]);
			zassert_mem_equal(in[0], out[0], len);
		}
	}
}

/* Nothing was started: the client is idle and sent nothing. */
static void assert_nothing_started(struct co_sdo_cli *cli, const struct co_sdo_cli_stats *before)
{
	struct co_sdo_cli_stats after;

	zassert_false(co_sdo_cli_busy(cli));
	co_sdo_cli_get_stats(cli, &after);
	zassert_mem_equal(&after, before, sizeof(after));
}

ZTEST(sdo_cli_threaded, test_success_returns_0_and_abort_code_0)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	uint32_t code = 0xdeadbeefU;
	size_t len = 99;

	sys_put_le32(0xcafe0001U, out[0]);
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_FOREVER, &code),
		0);
	zassert_equal(code, 0U);
	code = 0xdeadbeefU;
	memset(in[0], 0, 4);
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), &code),
		      0);
	zassert_equal(code, 0U);
	zassert_equal(len, 4U);
	zassert_equal(sys_get_le32(in[0]), 0xcafe0001U);
	/* An absolute timeout works as well. */
	code = 0xdeadbeefU;
	zassert_equal(co_sdo_cli_upload(cli, 0x2004, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_TIMEOUT_ABS_MS(k_uptime_get() + 5000), &code),
		      0);
	zassert_equal(code, 0U);
	zassert_equal(sys_get_le32(in[0]), 0x12345678U);
}

ZTEST(sdo_cli_threaded, test_server_abort_returns_econnaborted_with_its_code)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	struct co_sdo_cli_stats st0, st1;
	uint32_t code = 0;
	size_t len = 99;

	co_sdo_cli_get_stats(cli, &st0);
	/* Read-only object: the server refuses the write. */
	sys_put_le32(1U, out[0]);
	zassert_equal(co_sdo_cli_download(cli, 0x2004, 0, out[0], 4, CO_SDO_CLI_AUTO, K_SECONDS(5),
					  &code),
		      -ECONNABORTED);
	zassert_equal(code, CO_SDO_AB_READONLY, "%08x", code);
	/* No such object: the server aborts the upload. */
	code = 0;
	zassert_equal(co_sdo_cli_upload(cli, 0x6fff, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), &code),
		      -ECONNABORTED);
	zassert_equal(code, CO_SDO_AB_NO_OBJECT, "%08x", code);
	zassert_equal(len, 0U);
	co_sdo_cli_get_stats(cli, &st1);
	zassert_equal(st1.aborts_rcvd, st0.aborts_rcvd + 2U);
	zassert_equal(st1.aborts_sent, st0.aborts_sent);
	zassert_false(co_sdo_cli_busy(cli));
}

ZTEST(sdo_cli_threaded, test_protocol_timeout_returns_econnaborted_05040000)
{
	uint32_t code = 0;
	size_t len = 99;
	int64_t t0 = k_uptime_get();

	/* Client 2 talks to nobody: K_FOREVER is bounded by the protocol timeout. */
	zassert_equal(co_sdo_cli_upload(co_sdo_cli_get(&cnode, 2), 0x2000, 0, in[0], 4, &len,
					CO_SDO_CLI_AUTO, K_FOREVER, &code),
		      -ECONNABORTED);
	zassert_equal(code, CO_SDO_AB_TIMEOUT);
	zassert_equal(len, 0U);
	zassert_true(k_uptime_get() - t0 >= CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT);
}

ZTEST(sdo_cli_threaded, test_call_timeout_returns_eagain_and_client_is_reusable)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 3);
	struct co_sdo_cli_stats st0, st1;
	uint32_t code = 0xdeadbeefU;
	size_t len = 99;
	int64_t t0;

	zassert_ok(co_sdo_cli_set_server(cli, NOBODY));
	co_sdo_cli_get_stats(cli, &st0);

	/* A silent server: the call's own timeout ends it, well before the protocol timeout. */
	t0 = k_uptime_get();
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO, K_MSEC(50),
					&code),
		      -EAGAIN);
	zassert_true(k_uptime_get() - t0 >= 50);
	zassert_true(k_uptime_get() - t0 < CONFIG_CANOPEN_SDO_CLIENT_TIMEOUT);
	zassert_equal(code, 0U, "abort code only with -ECONNABORTED");
	zassert_equal(len, 0U);
	/* Idle at once (nothing left for the line thread), the abort went to the server. */
	zassert_false(co_sdo_cli_busy(cli));
	co_sdo_cli_get_stats(cli, &st1);
	zassert_equal(st1.aborts_sent, st0.aborts_sent + 1U);
	zassert_equal(st1.last_abort, CO_SDO_AB_TIMEOUT);

	/* Bounds the whole call for a download too, an absolute timeout as well. */
	code = 0xdeadbeefU;
	zassert_equal(co_sdo_cli_download(cli, 0x2005, 0, out[0], 100, CO_SDO_CLI_BLOCK,
					  K_TIMEOUT_ABS_MS(k_uptime_get() + 30), &code),
		      -EAGAIN);
	zassert_equal(code, 0U);
	zassert_false(co_sdo_cli_busy(cli));

	/* The next transfer on the same client works: bind it to a live server. */
	zassert_ok(co_sdo_cli_set_server(cli, SRV2_ID));
	fill(out[0], 500, 77);
	zassert_equal(co_sdo_cli_download(cli, 0x2005, 0, out[0], 500, CO_SDO_CLI_AUTO,
					  K_SECONDS(10), &code),
		      0);
	zassert_equal(code, 0U);
	zassert_equal(co_sdo_cli_upload(cli, 0x2005, 0, in[0], SIZE, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(10), &code),
		      0);
	zassert_equal(len, 500U);
	zassert_mem_equal(in[0], out[0], 500);
	zassert_ok(co_sdo_cli_set_server(cli, NOBODY));
}

ZTEST(sdo_cli_threaded, test_null_abort_code_and_no_wait_are_einval)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	struct co_sdo_cli_stats st;
	uint32_t code = 0xdeadbeefU;
	size_t len = 99;

	co_sdo_cli_get_stats(cli, &st);
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_SECONDS(5), NULL),
		-EINVAL);
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), NULL),
		      -EINVAL);
	zassert_equal(len, 0U);
	assert_nothing_started(cli, &st);
	/* A transfer cannot end without waiting. */
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_NO_WAIT, &code),
		-EINVAL);
	zassert_equal(code, 0U);
	code = 0xdeadbeefU;
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO, K_NO_WAIT,
					&code),
		      -EINVAL);
	zassert_equal(code, 0U);
	zassert_equal(co_sdo_cli_upload(NULL, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), &code),
		      -EINVAL);
	assert_nothing_started(cli, &st);
}

ZTEST(sdo_cli_threaded, test_edeadlk_with_own_node_lock_held)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	struct co_sdo_cli_stats st;
	uint32_t code = 0xdeadbeefU;
	size_t len = 99;

	co_sdo_cli_get_stats(cli, &st);
	co_node_lock(&cnode);
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_FOREVER, &code),
		-EDEADLK);
	zassert_equal(code, 0U);
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO, K_FOREVER,
					&code),
		      -EDEADLK);
	zassert_equal(len, 0U);
	/* Taken twice (recursive): still refused. */
	co_node_lock(&cnode);
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_FOREVER, &code),
		-EDEADLK);
	co_node_unlock(&cnode);
	co_node_unlock(&cnode);
	assert_nothing_started(cli, &st);
	/* Released: the same call works. */
	zassert_equal(co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_SECONDS(5),
					  &code),
		      0);
}

ZTEST(sdo_cli_threaded, test_edeadlk_with_another_node_of_the_line_locked)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	struct co_sdo_cli_stats st;
	uint32_t code = 0xdeadbeefU;
	size_t len = 99;

	co_sdo_cli_get_stats(cli, &st);
	/* The other node shares the client's line: its thread takes that mutex too. */
	co_node_lock(&onode);
	zassert_true(co_line_owner_held(co_node_line(&cnode)));
	zassert_equal(
		co_sdo_cli_download(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, K_FOREVER, &code),
		-EDEADLK);
	zassert_equal(code, 0U);
	zassert_equal(co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), &code),
		      -EDEADLK);
	co_node_unlock(&onode);
	assert_nothing_started(cli, &st);
	zassert_false(co_line_owner_held(co_node_line(&cnode)));
	zassert_equal(co_sdo_cli_upload(cli, 0x2004, 0, in[0], 4, &len, CO_SDO_CLI_AUTO,
					K_SECONDS(5), &code),
		      0);
	zassert_equal(sys_get_le32(in[0]), 0x12345678U);
}

/* From a timer of the servers' line: a line thread other than the client's. */
static K_SEM_DEFINE(other_line_done, 0, 1);
static struct co_timer other_line_timer;
static struct co_line *other_line_current;
static bool other_line_lock_held;
static int other_line_dn_err, other_line_up_err;

static void other_line_timer_fn(struct co_timer *timer, uint64_t now_us)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	uint32_t code;
	size_t len;

	other_line_current = co_line_current();
	other_line_lock_held = co_line_owner_held(co_node_line(&cnode));
	other_line_dn_err =
		co_sdo_cli_download(cli, 0x2000, 0, out[1], 4, CO_SDO_CLI_AUTO, K_MSEC(100), &code);
	other_line_up_err = co_sdo_cli_upload(cli, 0x2000, 0, in[1], 4, &len, CO_SDO_CLI_AUTO,
					      K_MSEC(100), &code);
	k_sem_give(&other_line_done);
}

ZTEST(sdo_cli_threaded, test_edeadlk_in_another_line_thread)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);
	struct co_sdo_cli_stats st;

	co_sdo_cli_get_stats(cli, &st);
	/* No node's mutex with the timer: only "a line thread" can refuse. */
	co_timer_init(&other_line_timer, other_line_timer_fn, NULL, NULL);
	co_timer_start(&line_b, &other_line_timer, co_line_time(&line_b));
	zassert_ok(k_sem_take(&other_line_done, K_SECONDS(10)));
	zassert_equal_ptr(other_line_current, &line_b);
	zassert_false(other_line_lock_held);
	zassert_equal(other_line_dn_err, -EDEADLK);
	zassert_equal(other_line_up_err, -EDEADLK);
	assert_nothing_started(cli, &st);
}

/* From a confirmation (line thread): the blocking call refuses, a request works. */
static K_SEM_DEFINE(done, 0, 1);
static int in_line_err;
static bool in_line_thread;
static uint32_t chained_code = 1;

static void chained_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data)
{
	chained_code = code;
	k_sem_give(&done);
}

static void first_con(struct co_sdo_cli *cli, uint32_t code, size_t size, void *user_data)
{
	uint32_t c;

	in_line_thread = k_current_get() == line_a.tid;
	in_line_err =
		co_sdo_cli_upload(cli, 0x2000, 0, in[0], 4, NULL, CO_SDO_CLI_AUTO, K_MSEC(100), &c);
	if (co_sdo_cli_upload_req(cli, 0x2004, 0, in[0], 4, CO_SDO_CLI_AUTO, 0, chained_con,
				  NULL) != 0) {
		chained_code = 2;
		k_sem_give(&done);
	}
}

ZTEST(sdo_cli_threaded, test_line_thread_gets_edeadlk_and_may_chain_requests)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 0);

	sys_put_le32(0x11U, out[0]);
	zassert_ok(co_sdo_cli_download_req(cli, 0x2000, 0, out[0], 4, CO_SDO_CLI_AUTO, 0, first_con,
					   NULL));
	zassert_ok(k_sem_take(&done, K_SECONDS(10)));
	zassert_true(in_line_thread);
	zassert_equal(in_line_err, -EDEADLK);
	zassert_equal(chained_code, 0U);
	zassert_equal(sys_get_le32(in[0]), 0x12345678U);
}

/* Two application threads, each on its own client and server, block transfers in a loop. */
static void app_entry(void *p1, void *p2, void *p3)
{
	int i = (int)(intptr_t)p1;
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, (uint8_t)i);
	int *failures = p2;

	for (int r = 0; r < ROUNDS; r++) {
		uint32_t code = 1;
		size_t len = 0;
		size_t n = 100 + (size_t)r * 150;

		fill(out[i], n, (uint32_t)(i * 1000 + r));
		if (co_sdo_cli_download(cli, 0x2005, 0, out[i], n,
					(r & 1) ? CO_SDO_CLI_BLOCK : CO_SDO_CLI_AUTO, K_SECONDS(10),
					&code) != 0 ||
		    code != 0U) {
			(*failures)++;
			continue;
		}
		if (co_sdo_cli_upload(cli, 0x2005, 0, in[i], SIZE, &len,
				      (r & 2) ? CO_SDO_CLI_BLOCK : CO_SDO_CLI_AUTO, K_SECONDS(10),
				      &code) != 0 ||
		    code != 0U || len != n || memcmp(in[i], out[i], n) != 0) {
			(*failures)++;
		}
	}
}

ZTEST(sdo_cli_threaded, test_two_application_threads_two_clients)
{
	static int failures[2];

	for (int i = 0; i < 2; i++) {
		k_thread_create(&app_threads[i], app_stacks[i],
				K_THREAD_STACK_SIZEOF(app_stacks[i]), app_entry,
				(void *)(intptr_t)i, &failures[i], NULL,
				K_LOWEST_APPLICATION_THREAD_PRIO, 0, K_NO_WAIT);
	}
	for (int i = 0; i < 2; i++) {
		zassert_ok(k_thread_join(&app_threads[i], K_SECONDS(60)));
		zassert_equal(failures[i], 0, "thread %d: %d failures", i, failures[i]);
	}
	/* The RX queues took every sub-block: nothing was lost and resent by luck. */
	{
		struct co_line_stats a, b;

		co_line_get_stats(&line_a, &a);
		co_line_get_stats(&line_b, &b);
		zassert_equal(a.rx_overruns + b.rx_overruns, 0U);
	}
}

ZTEST(sdo_cli_threaded, test_abort_from_another_thread)
{
	struct co_sdo_cli *cli = co_sdo_cli_get(&cnode, 2);
	uint32_t code = 0;

	/* Client 2 talks to nobody: abort it from here while a request waits (async). */
	zassert_ok(co_sdo_cli_upload_req(cli, 0x2000, 0, in[0], 4, CO_SDO_CLI_AUTO, 5000,
					 chained_con, NULL));
	k_msleep(10);
	zassert_ok(co_sdo_cli_abort_req(cli, CO_SDO_AB_DATA_LOC_CTRL));
	zassert_ok(k_sem_take(&done, K_SECONDS(2)));
	zassert_equal(chained_code, CO_SDO_AB_DATA_LOC_CTRL);
	zassert_false(co_sdo_cli_busy(cli));
	ARG_UNUSED(code);
}

static void teardown(void *f)
{
	co_line_stop(&line_a);
	co_line_stop(&line_b);
}

ZTEST_SUITE(sdo_cli_threaded, NULL, setup, NULL, NULL, teardown);
