/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Two nodes, each on its own line (own thread) on one virtual bus, exchange PDOs:
 *  - A's TPDO 0 (181h, type 254, inhibit 1 ms) carries 2002h (U32) to B's RPDO 0, which maps
 *    it onto 2000h:01..04; an application thread writes 2002h of A as fast as it can, so
 *    most writes fall into the inhibit time and the last value must still arrive;
 *  - A produces SYNC every 2 ms; B's TPDO 1 (282h, type 1) carries 2001h (U16) to A's
 *    RPDO 1 (type 0), committed at A's next SYNC.
 */

#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/ztest.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/pdo.h>
#include <canopen/sync.h>

#include "pdo_test_od.h"

#define ID_A    1
#define ID_B    2
#define WAIT_MS 10000
#define N_WRITE 2000U

struct test_node {
	struct co_node node;
	struct pdo_test_od_ram ram;
	uint32_t rpdo_count[4];
	uint32_t sync_count;
	uint16_t last_word;
	bool word_went_back;
};

static struct co_line lines[2];
static struct test_node na, nb;
static K_THREAD_STACK_ARRAY_DEFINE(stacks, 2, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_SEM_DEFINE(events, 0, K_SEM_MAX_LIMIT);

static void rpdo_ind(struct co_node *node, uint16_t num, void *user_data)
{
	struct test_node *tn = user_data;
	uint16_t w = 0;

	tn->rpdo_count[num]++;
	if (num == 1U) {
		(void)co_od_get_u16(co_node_od(node), 0x2001, 0, &w);
		if (w < tn->last_word) {
			tn->word_went_back = true;
		}
		tn->last_word = w;
	}
	k_sem_give(&events);
}

static void post_sync(struct co_node *node, uint8_t counter, void *user_data)
{
	struct test_node *tn = user_data;

	tn->sync_count++;
}

static void set_u32(struct co_node *node, uint16_t index, uint8_t sub, uint32_t v)
{
	zassert_ok(co_od_set_u32(co_node_od(node), index, sub, v, CO_OD_WRITER_APP), "%04Xh:%u",
		   index, sub);
}

static void set_u8(struct co_node *node, uint16_t index, uint8_t sub, uint8_t v)
{
	zassert_ok(co_od_set_u8(co_node_od(node), index, sub, v, CO_OD_WRITER_APP), "%04Xh:%u",
		   index, sub);
}

/* The CiA 301 mapping procedure, as the application (same checks as over SDO). */
static void map_pdo(struct co_node *node, bool rx, int n, uint32_t cob, uint8_t type,
		    const uint32_t *map, uint8_t n_map)
{
	uint16_t comm = (rx ? 0x1400 : 0x1800) + n;
	uint16_t mapi = (rx ? 0x1600 : 0x1A00) + n;

	set_u32(node, comm, 1, cob | 0x80000000U);
	set_u8(node, mapi, 0, 0);
	for (uint8_t i = 0; i < n_map; i++) {
		set_u32(node, mapi, i + 1, map[i]);
	}
	set_u8(node, mapi, 0, n_map);
	set_u8(node, comm, 2, type);
	set_u32(node, comm, 1, cob);
}

static void *setup(void)
{
	const uint32_t a_tx[] = {0x20020020};
	const uint32_t b_rx[] = {0x20000108, 0x20000208, 0x20000308, 0x20000408};
	const uint32_t word[] = {0x20010010};

	for (int l = 0; l < 2; l++) {
		char name[16];

		snprintk(name, sizeof(name), "can_virtual%d", l);
		zassert_ok(co_line_init(&lines[l], l == 0 ? "lineA" : "lineB",
					device_get_binding(name)));
		zassert_ok(co_line_start(&lines[l], stacks[l], K_THREAD_STACK_SIZEOF(stacks[l]),
					 CONFIG_CANOPEN_LINE_THREAD_PRIORITY));
	}
	zassert_ok(co_node_init(&na.node, "A", &lines[0], &pdo_test_od_def, &na.ram, ID_A));
	zassert_ok(co_node_init(&nb.node, "B", &lines[1], &pdo_test_od_def, &nb.ram, ID_B));
	co_rpdo_set_ind(&na.node, rpdo_ind, &na);
	co_rpdo_set_ind(&nb.node, rpdo_ind, &nb);
	co_sync_set_post_ind(&na.node, post_sync, &na);
	zassert_ok(co_node_start(&na.node));
	zassert_ok(co_node_start(&nb.node));

	co_node_lock(&na.node);
	map_pdo(&na.node, false, 0, 0x80000181U, 254, a_tx, 1);
	zassert_ok(co_od_set_u16(co_node_od(&na.node), 0x1800, 3, 10, CO_OD_WRITER_APP));
	set_u32(&na.node, 0x1800, 1, 0x181);
	map_pdo(&na.node, true, 1, 0x282, 0, word, 1);
	set_u32(&na.node, 0x1005, 0, 0x40000080U);
	set_u32(&na.node, 0x1006, 0, 2000U);
	co_node_unlock(&na.node);

	co_node_lock(&nb.node);
	map_pdo(&nb.node, true, 0, 0x181, 255, b_rx, 4);
	map_pdo(&nb.node, false, 1, 0x282, 1, word, 1);
	co_node_unlock(&nb.node);

	zassert_ok(co_nmt_req(&na.node, CO_NMT_CS_START));
	zassert_ok(co_nmt_req(&nb.node, CO_NMT_CS_START));
	return NULL;
}

static bool wait_until(bool (*cond)(void))
{
	int64_t end = k_uptime_get() + WAIT_MS;

	while (!cond()) {
		if (k_sem_take(&events, K_TIMEOUT_ABS_MS(end)) != 0) {
			return cond();
		}
	}
	return true;
}

static uint32_t b_received(void)
{
	uint8_t b[4] = {0};

	co_node_lock(&nb.node);
	for (uint8_t i = 0; i < 4; i++) {
		(void)co_od_get_u8(co_node_od(&nb.node), 0x2000, i + 1, &b[i]);
	}
	co_node_unlock(&nb.node);
	return b[0] | (b[1] << 8) | (b[2] << 16) | ((uint32_t)b[3] << 24);
}

static bool b_has_last_value(void)
{
	return b_received() == N_WRITE;
}

static void writer(void *p1, void *p2, void *p3)
{
	struct co_node *node = p1;

	for (uint32_t i = 1; i <= N_WRITE; i++) {
		co_node_lock(node);
		(void)co_od_set_u32(co_node_od(node), 0x2002, 0, i, CO_OD_WRITER_APP);
		co_node_unlock(node);
		if ((i % 64U) == 0U) {
			k_msleep(1);
		}
	}
}

static K_THREAD_STACK_DEFINE(writer_stack, 4096);
static struct k_thread writer_thread;

ZTEST_SUITE(co_pdo_threaded, NULL, setup, NULL, NULL, NULL);

ZTEST(co_pdo_threaded, test_event_pdo_delivers_the_last_value_through_the_inhibit_time)
{
	struct co_line_stats a;
	uint32_t got;

	k_thread_create(&writer_thread, writer_stack, K_THREAD_STACK_SIZEOF(writer_stack), writer,
			&na.node, NULL, NULL, 5, 0, K_NO_WAIT);
	zassert_ok(k_thread_join(&writer_thread, K_MSEC(30000)));
	zassert_true(wait_until(b_has_last_value), "B got %u", b_received());

	co_node_lock(&nb.node);
	got = nb.rpdo_count[0];
	co_node_unlock(&nb.node);
	co_line_get_stats(&lines[0], &a);
	zassert_true(got > 0U && got < N_WRITE, "changes merged by the inhibit time (%u frames)",
		     got);
	zassert_equal(a.tx_dropped, 0U, "no frame lost on A's line");
}

static bool a_committed_enough(void)
{
	bool ok;

	co_node_lock(&na.node);
	ok = na.rpdo_count[1] >= 50U;
	co_node_unlock(&na.node);
	return ok;
}

ZTEST(co_pdo_threaded, test_sync_pdos_between_two_line_threads)
{
	uint32_t syncs, commits;
	bool back;

	for (uint16_t w = 1; w <= 200; w++) {
		co_node_lock(&nb.node);
		zassert_ok(co_od_set_u16(co_node_od(&nb.node), 0x2001, 0, w, CO_OD_WRITER_APP));
		co_node_unlock(&nb.node);
		k_usleep(500);
	}
	zassert_true(wait_until(a_committed_enough), "A commits B's synchronous TPDO at SYNC");
	co_node_lock(&na.node);
	syncs = na.sync_count;
	commits = na.rpdo_count[1];
	back = na.word_went_back;
	co_node_unlock(&na.node);
	zassert_true(commits <= syncs, "at most one commit per SYNC (%u, %u)", commits, syncs);
	zassert_false(back, "samples arrive in order");
}
