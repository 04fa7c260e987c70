/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * k_msgq: fixed-size messages in a ring buffer. One wait queue holds either readers (queue
 * empty) or writers (queue full), never both; a message is copied straight into a waiting
 * reader's buffer, and a waiting writer's message straight into the slot a reader freed.
 */

#include <errno.h>
#include <string.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

void k_msgq_init(struct k_msgq *msgq, char *buffer, size_t msg_size, uint32_t max_msgs)
{
	z_waitq_init(&msgq->wait_q);
	msgq->msg_size = msg_size;
	msgq->max_msgs = max_msgs;
	msgq->buffer_start = buffer;
	msgq->buffer_end = buffer + (max_msgs * msg_size);
	msgq->read_ptr = buffer;
	msgq->write_ptr = buffer;
	msgq->used_msgs = 0U;
	msgq->flags = 0U;
}

int k_msgq_cleanup(struct k_msgq *msgq)
{
	int ret = 0;

	z_lock();
	if (z_waitq_head(&msgq->wait_q) != NULL) {
		ret = -EBUSY;
	}
	z_unlock();

	return ret;
}

static void ring_put(struct k_msgq *msgq, const void *data)
{
	(void)memcpy(msgq->write_ptr, data, msgq->msg_size);
	msgq->write_ptr += msgq->msg_size;
	if (msgq->write_ptr == msgq->buffer_end) {
		msgq->write_ptr = msgq->buffer_start;
	}
	msgq->used_msgs++;
}

int k_msgq_put(struct k_msgq *msgq, const void *data, k_timeout_t timeout)
{
	struct k_thread *reader;
	int ret;

	z_lock();
	if (msgq->used_msgs < msgq->max_msgs) {
		reader = z_unpend_first_thread(&msgq->wait_q);
		if (reader != NULL) {
			(void)memcpy(reader->swap_data, data, msgq->msg_size);
			z_ready_thread(reader, 0);
		} else {
			ring_put(msgq, data);
		}
		ret = 0;
	} else if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		ret = -ENOMSG;
	} else {
		/* A reader copies the message from here when it frees a slot. */
		z_current()->swap_data = (void *)data;
		ret = z_pend_curr(&msgq->wait_q, timeout);
	}
	z_unlock();

	return ret;
}

int k_msgq_get(struct k_msgq *msgq, void *data, k_timeout_t timeout)
{
	struct k_thread *writer;
	int ret;

	z_lock();
	if (msgq->used_msgs > 0U) {
		(void)memcpy(data, msgq->read_ptr, msgq->msg_size);
		msgq->read_ptr += msgq->msg_size;
		if (msgq->read_ptr == msgq->buffer_end) {
			msgq->read_ptr = msgq->buffer_start;
		}
		msgq->used_msgs--;

		writer = z_unpend_first_thread(&msgq->wait_q);
		if (writer != NULL) {
			ring_put(msgq, writer->swap_data);
			z_ready_thread(writer, 0);
		}
		ret = 0;
	} else if (K_TIMEOUT_EQ(timeout, K_NO_WAIT)) {
		ret = -ENOMSG;
	} else {
		/* A writer copies its message here. */
		z_current()->swap_data = data;
		ret = z_pend_curr(&msgq->wait_q, timeout);
	}
	z_unlock();

	return ret;
}

int k_msgq_peek(struct k_msgq *msgq, void *data)
{
	return k_msgq_peek_at(msgq, data, 0);
}

int k_msgq_peek_at(struct k_msgq *msgq, void *data, uint32_t idx)
{
	size_t offset;
	size_t size;
	int ret = -ENOMSG;

	z_lock();
	if (idx < msgq->used_msgs) {
		size = (size_t)(msgq->buffer_end - msgq->buffer_start);
		offset = (size_t)(msgq->read_ptr - msgq->buffer_start) + idx * msgq->msg_size;
		(void)memcpy(data, msgq->buffer_start + (offset % size), msgq->msg_size);
		ret = 0;
	}
	z_unlock();

	return ret;
}

void k_msgq_purge(struct k_msgq *msgq)
{
	z_lock();
	/* Waiting writers lose their messages. */
	(void)z_sched_wake_all(&msgq->wait_q, -ENOMSG);
	msgq->used_msgs = 0U;
	msgq->read_ptr = msgq->write_ptr;
	z_unlock();
}

uint32_t k_msgq_num_free_get(struct k_msgq *msgq)
{
	uint32_t n;

	z_lock();
	n = msgq->max_msgs - msgq->used_msgs;
	z_unlock();

	return n;
}

uint32_t k_msgq_num_used_get(struct k_msgq *msgq)
{
	uint32_t n;

	z_lock();
	n = msgq->used_msgs;
	z_unlock();

	return n;
}

void k_msgq_get_attrs(struct k_msgq *msgq, struct k_msgq_attrs *attrs)
{
	z_lock();
	attrs->msg_size = msgq->msg_size;
	attrs->max_msgs = msgq->max_msgs;
	attrs->used_msgs = msgq->used_msgs;
	z_unlock();
}
