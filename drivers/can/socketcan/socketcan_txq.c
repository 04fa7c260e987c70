/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <string.h>

#include <zephyr/sys/util.h>

#include "socketcan_txq.h"

void sc_txq_init(struct sc_txq *q, struct sc_txq_entry *entries, uint16_t size, uint64_t timeout_ns)
{
	q->entries = entries;
	q->size = size;
	q->head = 0U;
	q->count = 0U;
	q->timeout_ns = timeout_ns;
	q->last_echo_ns = 0U;
}

static struct sc_txq_entry *sc_txq_at(const struct sc_txq *q, uint16_t i)
{
	return &q->entries[(q->head + i) % q->size];
}

static void sc_txq_pop(struct sc_txq *q, struct sc_txq_entry *out)
{
	*out = q->entries[q->head];
	q->head = (uint16_t)((q->head + 1U) % q->size);
	q->count--;
}

bool sc_txq_push(struct sc_txq *q, const struct socketcan_host_frame *frame, can_tx_callback_t cb,
		 void *user_data, uint64_t written_ns)
{
	struct sc_txq_entry *e;

	if (q->count == q->size) {
		return false;
	}
	e = sc_txq_at(q, q->count);
	e->cb = cb;
	e->user_data = user_data;
	e->frame = *frame;
	e->written_ns = written_ns;
	q->count++;

	return true;
}

void sc_txq_drop_newest(struct sc_txq *q)
{
	if (q->count > 0U) {
		q->count--;
	}
}

/* The echo carries what was written: identifier, flags, DLC and, for data frames, the data. */
static bool sc_txq_same_frame(const struct socketcan_host_frame *a,
			      const struct socketcan_host_frame *b)
{
	if (a->id != b->id || a->flags != b->flags || a->dlc != b->dlc) {
		return false;
	}
	if ((a->flags & SOCKETCAN_HOST_F_RTR) != 0U) {
		return true;
	}

	return memcmp(a->data, b->data, MIN(a->dlc, sizeof(a->data))) == 0;
}

enum sc_txq_echo_result sc_txq_echo(struct sc_txq *q, const struct socketcan_host_frame *frame,
				    uint64_t at_ns, struct sc_txq_entry *done,
				    struct sc_txq_entry *lost, int *n_lost)
{
	uint16_t match = q->count;

	q->last_echo_ns = at_ns;
	*n_lost = 0;
	for (uint16_t i = 0U; i < q->count; i++) {
		if (sc_txq_same_frame(&sc_txq_at(q, i)->frame, frame)) {
			match = i;
			break;
		}
	}
	if (match == q->count) {
		return SC_TXQ_ECHO_LATE;
	}
	for (uint16_t i = 0U; i < match; i++) {
		sc_txq_pop(q, &lost[i]);
	}
	*n_lost = (int)match;
	sc_txq_pop(q, done);

	return SC_TXQ_ECHO_MATCHED;
}

/* When the oldest entry expires if no echo comes; UINT64_MAX if the queue is empty. */
static uint64_t sc_txq_next_expiry(const struct sc_txq *q)
{
	uint64_t since;

	if (q->count == 0U) {
		return UINT64_MAX;
	}
	since = MAX(sc_txq_at(q, 0U)->written_ns, q->last_echo_ns);

	return (since > UINT64_MAX - q->timeout_ns) ? UINT64_MAX : since + q->timeout_ns;
}

int sc_txq_expire(struct sc_txq *q, uint64_t now_ns, struct sc_txq_entry *out)
{
	int n = 0;

	while (q->count > 0U && now_ns >= sc_txq_next_expiry(q)) {
		sc_txq_pop(q, &out[n]);
		n++;
	}

	return n;
}

int sc_txq_take_all(struct sc_txq *q, struct sc_txq_entry *out)
{
	int n = 0;

	while (q->count > 0U) {
		sc_txq_pop(q, &out[n]);
		n++;
	}

	return n;
}
