/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The threaded binding of a line: CAN driver callbacks feed the RX queue, the line thread
 * sleeps in k_msgq_get() until a frame arrives or the next deadline passes.
 *
 * Driver callbacks (RX, TX completion, state change) may run in interrupt context on a real
 * target: they only stamp and queue frames, set atomic flags and wake the thread.
 */

#include <errno.h>

#include <zephyr/kernel.h>
#include <zephyr/drivers/can.h>
#include <zephyr/logging/log.h>

#include <canopen/line.h>

#include "line_internal.h"

LOG_MODULE_DECLARE(co_line, CONFIG_CANOPEN_LOG_LEVEL);

/* How long co_line_stop() waits for the TX completions of frames the controller holds. */
#define CO_LINE_STOP_TX_WAIT_MS 100

struct co_line *co_line_current(void)
{
#if defined(CONFIG_THREAD_CUSTOM_DATA)
	struct co_line *line = k_thread_custom_data_get();

	/* Custom data of other threads may be anything: only an address match counts (no read
	 * through the pointer).
	 */
	if (line != NULL && &line->thread == k_current_get()) {
		return line;
	}
#endif
	return NULL;
}

void co_line_wake(struct co_line *line)
{
	struct co_line_rx_msg msg = {.frame.dlc = CO_LINE_MSG_WAKE};

	if (co_line_is_sim(line) || !atomic_test_bit(&line->flags, CO_LINE_F_RUNNING)) {
		return;
	}
	/* The line thread re-reads its deadline before sleeping anyway. Compared by address:
	 * line->tid is written by co_line_start() while the new thread may already be sending.
	 */
	if (k_current_get() == &line->thread) {
		return;
	}
	/* One wake message at a time, so wakes never crowd frames out of the queue; a full
	 * queue wakes the thread anyway.
	 */
	if (!atomic_test_and_set_bit(&line->flags, CO_LINE_F_WAKE_PENDING)) {
		if (k_msgq_put(&line->rxq, &msg, K_NO_WAIT) != 0) {
			atomic_clear_bit(&line->flags, CO_LINE_F_WAKE_PENDING);
		}
	}
}

/*
 * The frame's reception time: the driver's timestamp (low 16 bits of the uptime in µs on this
 * board's drivers) extended with the current time, so timing checks (SRDO's SRVT, RPDO and
 * heartbeat deadlines) measure from the frame's arrival, not from the driver callback. Frames
 * are handed over well within the 32 ms that half the 16 bits span.
 */
static uint64_t line_rx_time(const struct can_frame *frame)
{
	uint64_t now = co_line_now();

#if defined(CONFIG_CAN_RX_TIMESTAMP)
	uint16_t age = (uint16_t)((uint16_t)now - frame->timestamp);

	/* A stamp "ahead" of now (the tick clock is coarser than the driver's) is a zero age. */
	if (age < 0x8000U && age < now) {
		now -= age;
	}
#else
	ARG_UNUSED(frame);
#endif
	return now;
}

static void line_rx_cb(const struct device *dev, struct can_frame *frame, void *user_data)
{
	struct co_line *line = user_data;
	struct co_line_rx_msg msg = {
		.frame = *frame,
		.time_lo = (uint32_t)line_rx_time(frame),
	};
	if (k_msgq_put(&line->rxq, &msg, K_NO_WAIT) != 0) {
		/* Counted here; reported by the thread, which is busy draining the queue. */
		co_line_rx_overrun(line);
	}
}

static void line_tx_cb(const struct device *dev, int error, void *user_data)
{
	struct co_line *line = user_data;

	if (error != 0) {
		atomic_set(&line->tx_async_err, error);
	}
	if (error != 0 || atomic_test_bit(&line->flags, CO_LINE_F_TX_WAITING)) {
		co_line_wake(line);
	}
	/* The last access to the line: once the count is zero co_line_stop() may return. */
	(void)atomic_dec(&line->tx_inflight);
}

static void line_state_cb(const struct device *dev, enum can_state state,
			  struct can_bus_err_cnt err_cnt, void *user_data)
{
	struct co_line *line = user_data;

	atomic_set(&line->can_state, (atomic_val_t)state);
	if (state == CAN_STATE_BUS_OFF) {
		atomic_set_bit(&line->flags, CO_LINE_F_BUS_OFF);
	}
	atomic_set_bit(&line->flags, CO_LINE_F_STATE);
	co_line_wake(line);
}

int co_line_dev_send(struct co_line *line, const struct can_frame *frame)
{
	int err;

	/*
	 * Counted before the stop flag is read, and co_line_stop() sets the flag before it reads
	 * the count (both sequentially consistent): either this send sees the flag and the frame
	 * waits in the TX queue, or co_line_stop() sees the count and waits for the callback.
	 */
	(void)atomic_inc(&line->tx_inflight);
	if (atomic_test_bit(&line->flags, CO_LINE_F_STOP)) {
		err = -EAGAIN;
	} else {
		err = can_send(line->dev, frame, K_NO_WAIT, line_tx_cb, line);
	}
	if (err != 0) {
		/* Refused: the driver does not call back (Zephyr's can_send() contract). */
		(void)atomic_dec(&line->tx_inflight);
	}
	return err;
}

static void line_report_async(struct co_line *line)
{
	atomic_val_t err;

	if (atomic_test_and_clear_bit(&line->flags, CO_LINE_F_RX_OVERRUN)) {
		LOG_WRN("%s: RX queue overrun", line->name);
		co_line_report(line, CO_LINE_EV_RX_OVERRUN, 0);
	}
	if (atomic_test_and_clear_bit(&line->flags, CO_LINE_F_STATE)) {
		int state = (int)atomic_get(&line->can_state);

		/* States are coalesced, but a bus-off already over is still reported. */
		if (atomic_test_and_clear_bit(&line->flags, CO_LINE_F_BUS_OFF) &&
		    state != CAN_STATE_BUS_OFF) {
			co_line_report(line, CO_LINE_EV_CAN_STATE, CAN_STATE_BUS_OFF);
		}
		co_line_report(line, CO_LINE_EV_CAN_STATE, state);
	}
	err = atomic_set(&line->tx_async_err, 0);
	if (err != 0) {
		co_line_report(line, CO_LINE_EV_TX_ERROR, (int)err);
	}
}

/*
 * Hand queued frames to their receivers, at most a queue's worth so that a flood cannot hold
 * deadlines off for long. @p msg is the first one, already taken.
 */
static void line_drain(struct co_line *line, struct co_line_rx_msg *msg)
{
	int budget = CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE;
	/* Read after the first message was taken: within 2^31 µs of every queued time. */
	uint64_t ref = co_line_now();

	do {
		unsigned int kind = msg->frame.dlc & CO_LINE_MSG_KINDS;

		if (kind == CO_LINE_MSG_FRAME) {
			co_line_rx(line, &msg->frame, co_line_msg_time(msg, ref));
#if defined(CONFIG_CANOPEN_LINE_SHARED)
		} else if (kind == CO_LINE_MSG_LOCAL) {
			msg->frame.dlc &= (uint8_t)~CO_LINE_MSG_LOCAL;
			co_line_dispatch(line, &msg->frame, co_line_msg_time(msg, ref),
					 msg->origin);
#endif
		} else {
			atomic_clear_bit(&line->flags, CO_LINE_F_WAKE_PENDING);
		}
	} while (--budget > 0 && k_msgq_get(&line->rxq, msg, K_NO_WAIT) == 0);
}

static void line_thread(void *p1, void *p2, void *p3)
{
	struct co_line *line = p1;
	struct co_line_rx_msg msg;

#if defined(CONFIG_THREAD_CUSTOM_DATA)
	/* co_line_current() finds the line from here: blocking calls refuse to run on it. */
	k_thread_custom_data_set(line);
#endif
	while (!atomic_test_bit(&line->flags, CO_LINE_F_STOP)) {
		/*
		 * A frame is judged by when it was received: frames queued before a deadline are
		 * handled before that deadline's timer runs. So "now" is read before the queue is
		 * drained and the timers run only up to it: every frame queued by then, which
		 * includes every frame received before a deadline that is due, is dispatched first
		 * (SRDO's inverted frame, a heartbeat, an RPDO before its SCT/SRVT/event timer),
		 * however late the thread runs and however long the reports below take. Frames
		 * queued later are after "now", so after any deadline run in this pass.
		 */
		uint64_t now = co_line_now();

		if (k_msgq_get(&line->rxq, &msg, K_NO_WAIT) == 0) {
			line_drain(line, &msg);
		}
		line_report_async(line);

		uint64_t next = co_line_process(line, now);
		k_timeout_t timeout = K_FOREVER;

		if (next != UINT64_MAX) {
			timeout = K_TIMEOUT_ABS_TICKS(k_us_to_ticks_ceil64(next));
		}
		if (k_msgq_get(&line->rxq, &msg, timeout) == 0) {
			line_drain(line, &msg);
		}
	}
}

int co_line_start(struct co_line *line, k_thread_stack_t *stack, size_t stack_size, int prio)
{
	const struct can_filter std = {.id = 0U, .mask = 0U, .flags = 0U};
	const struct can_filter ext = {.id = 0U, .mask = 0U, .flags = CAN_FILTER_IDE};
	int err;

	if (line->dev == NULL) {
		return -ENODEV;
	}
	if (atomic_test_and_set_bit(&line->flags, CO_LINE_F_RUNNING)) {
		return -EALREADY;
	}
	atomic_clear_bit(&line->flags, CO_LINE_F_STOP);

	/* Everything goes to the software table; CANopen needs most 11-bit ids anyway. */
	line->filter_std = can_add_rx_filter(line->dev, line_rx_cb, line, &std);
	line->filter_ext = can_add_rx_filter(line->dev, line_rx_cb, line, &ext);
	if (line->filter_std < 0 || line->filter_ext < 0) {
		err = -ENOSPC;
		goto fail;
	}
	can_set_state_change_callback(line->dev, line_state_cb, line);
	err = can_start(line->dev);
	if (err != 0 && err != -EALREADY) {
		LOG_ERR("%s: cannot start CAN controller (%d)", line->name, err);
		err = -EIO;
		goto fail;
	}

	line->tid = k_thread_create(&line->thread, stack, stack_size, line_thread, line, NULL, NULL,
				    prio, 0, K_NO_WAIT);
	k_thread_name_set(line->tid, line->name);
	return 0;

fail:
	if (line->filter_std >= 0) {
		can_remove_rx_filter(line->dev, line->filter_std);
	}
	if (line->filter_ext >= 0) {
		can_remove_rx_filter(line->dev, line->filter_ext);
	}
	line->filter_std = -1;
	line->filter_ext = -1;
	atomic_clear_bit(&line->flags, CO_LINE_F_RUNNING);
	return err;
}

/* Wait up to @p ms for the TX completions of the frames the driver holds; true if none is left. */
static bool line_tx_settled(struct co_line *line, int ms)
{
	int waited = 0;

	while (atomic_get(&line->tx_inflight) != 0 && waited < ms) {
		k_msleep(1);
		waited++;
	}
	return atomic_get(&line->tx_inflight) == 0;
}

int co_line_stop(struct co_line *line)
{
	struct co_line_rx_msg msg = {.frame.dlc = CO_LINE_MSG_WAKE};

	if (!atomic_test_bit(&line->flags, CO_LINE_F_RUNNING)) {
		/* Stopped, but a TX completion was still due: ask again. */
		if (line->dev != NULL && atomic_get(&line->tx_inflight) != 0) {
			return line_tx_settled(line, CO_LINE_STOP_TX_WAIT_MS) ? 0 : -EBUSY;
		}
		return -EALREADY;
	}
	/* From here on sends queue in the line (co_line_dev_send()) instead of the driver. */
	atomic_set_bit(&line->flags, CO_LINE_F_STOP);
	(void)k_msgq_put(&line->rxq, &msg, K_NO_WAIT);
	k_thread_join(&line->thread, K_FOREVER);

	/* No receive or state callback runs once these return (the driver's contract). */
	can_remove_rx_filter(line->dev, line->filter_std);
	can_remove_rx_filter(line->dev, line->filter_ext);
	can_set_state_change_callback(line->dev, NULL, NULL);
	line->filter_std = -1;
	line->filter_ext = -1;

	/*
	 * TX completions come from the driver's own context (the virtual bus's thread, the
	 * SocketCAN receive thread) and may still be due for frames handed over before the
	 * flag was set. Wait for them: frames on a working bus end within milliseconds. A bus
	 * that does not take them (no acknowledgement) gets the controller stopped, which
	 * aborts them (-ENETDOWN) on drivers that can; a frame the driver cannot recall even
	 * then (SocketCAN: the kernel holds it) leaves -EBUSY.
	 */
	int err = 0;

	if (!line_tx_settled(line, CO_LINE_STOP_TX_WAIT_MS)) {
		LOG_WRN("%s: %d frames still in the controller; stopping it", line->name,
			(int)atomic_get(&line->tx_inflight));
		(void)can_stop(line->dev);
		if (!line_tx_settled(line, CO_LINE_STOP_TX_WAIT_MS)) {
			err = -EBUSY;
		}
	}
	atomic_clear_bit(&line->flags, CO_LINE_F_RUNNING);
	return err;
}
