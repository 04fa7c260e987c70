/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Control of the virtual CAN bus from tests and benchmarks (not Zephyr API).
 *
 * The virtual driver's controllers ("can_virtual0".. "can_virtual<N-1>") implement
 * `<zephyr/drivers/can.h>`. This header adds what only a simulated bus can do: fault
 * injection, wiring controllers to buses, bit timing, statistics, and the simulated clock.
 *
 * Bus model: each bus carries one frame at a time. When it is idle and frames are pending, the
 * one with the lowest arbitration field wins (CAN-ID priority; a standard data frame beats a
 * remote frame and an extended frame of the same base id; equal fields go first in, first out).
 * At the end of the frame every other started controller on the bus at the same bit rate
 * receives it (unless cut, bus-off or faulted), then the sender gets its TX completion. There
 * is no ACK or CRC simulation and no error-counter dynamics: error states change only through
 * this API, bus-off recovery and the cut rule (see can_virtual_cut()).
 *
 * Clock: with CONFIG_CAN_VIRTUAL_CLOCK_REALTIME one thread per bus delivers frames on the
 * kernel's uptime clock. With CONFIG_CAN_VIRTUAL_CLOCK_SIMULATED there are no threads: one
 * simulated clock, shared by all buses, moves only in can_virtual_sim_advance() and
 * can_virtual_sim_run(), which deliver everything due, in time order, in the caller's thread.
 * Callbacks then run inside those calls; the same inputs give the same run every time.
 *
 * Unless said otherwise, functions return 0 or a negative errno: -EINVAL for a bad bus
 * number, device or argument.
 */

#ifndef SAFELINE_DRIVERS_CAN_VIRTUAL_H_
#define SAFELINE_DRIVERS_CAN_VIRTUAL_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/device.h>
#include <zephyr/drivers/can.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Counters of one bus since boot. */
struct can_virtual_bus_stats {
	/** Frames that completed on the bus (sent and confirmed). */
	uint32_t frames;
	/** Frames lost by can_virtual_drop_frames(). */
	uint32_t dropped;
	/** Frames altered by can_virtual_corrupt_frames(). */
	uint32_t corrupted;
	/** Frames held back by can_virtual_delay_frames(). */
	uint32_t delayed;
	/** Deliveries lost because the latency queue was full. */
	uint32_t delay_overflows;
	/** Time the bus was occupied by frames, in ns (bit timing on only). */
	uint64_t busy_ns;
};

/**
 * @brief Length of @p frame on the wire in bits at nominal bit rate: start of frame to the end
 *        of the intermission, with the stuff bits that its identifier, DLC, data and CRC need.
 *
 * @param frame A classic CAN frame.
 * @return Bits, e.g. 111 for a standard frame with 8 data bytes and no stuff bits.
 */
uint32_t can_virtual_frame_bits(const struct can_frame *frame);

/**
 * @brief Lose the next @p count frames on @p bus that match @p filter: nobody receives them,
 *        their senders still get a successful TX completion.
 *
 * Faults are checked in the order they were added; the first that matches a frame applies.
 *
 * @retval -ENOSPC The bus's fault table is full.
 */
int can_virtual_drop_frames(int bus, const struct can_filter *filter, uint32_t count);

/**
 * @brief Alter the next @p count frames on @p bus that match @p filter: receivers get the data
 *        XORed with @p xor_mask (an undetected corruption); senders see success.
 *
 * @retval -ENOSPC The bus's fault table is full.
 */
int can_virtual_corrupt_frames(int bus, const struct can_filter *filter, uint32_t count,
			       const uint8_t xor_mask[CAN_MAX_DLEN]);

/**
 * @brief Deliver the next @p count frames on @p bus that match @p filter @p delay_us
 *        microseconds late to every receiver; senders get their TX completion at the end of
 *        the frame on the bus, as usual.
 *
 * Each receiver gets the frame (and its receive timestamp) at the end of the frame plus
 * @p delay_us plus its own latency (can_virtual_set_latency()). Frames that are not delayed
 * are not held back by it: they overtake a delayed frame. Works with both clocks; a delivery
 * that finds the bus's delay queue (CONFIG_CAN_VIRTUAL_DELAY_QUEUE_SIZE) full is lost for that
 * receiver and counted in delay_overflows. Faults are checked in the order they were added;
 * the first that matches a frame applies.
 *
 * @retval -EINVAL Bad bus, no filter, @p count or @p delay_us 0.
 * @retval -ENOSPC The bus's fault table is full.
 */
int can_virtual_delay_frames(int bus, const struct can_filter *filter, uint32_t count,
			     uint32_t delay_us);

/**
 * @brief Remove the drop, corrupt and delay faults of @p bus that have not run out (frames
 *        already held back by a delay still arrive).
 */
int can_virtual_clear_faults(int bus);

/**
 * @brief Put a started controller into @p state, with the matching error counters
 *        (active 0, warning 96, passive 128, bus-off 256 reported as 255), and call its state
 *        change callback if the state changed.
 *
 * Bus-off aborts the controller's pending frames (-ENETUNREACH), refuses new ones and stops
 * reception. It ends after 128 x 11 bit times: automatically, or after can_recover() in
 * CAN_MODE_MANUAL_RECOVERY; setting CAN_STATE_ERROR_ACTIVE ends it at once.
 *
 * @retval -ENETDOWN The controller is stopped.
 * @retval -EINVAL @p state is CAN_STATE_STOPPED or not a state.
 */
int can_virtual_set_state(const struct device *dev, enum can_state state);

/**
 * @brief Cut the controller off its bus: it receives nothing and its frames reach nobody.
 *
 * Its frames stay queued (no acknowledgement means retransmission): the first attempt puts it
 * error-passive (TX counter 128), as a real controller without ACK ends up.
 */
int can_virtual_cut(const struct device *dev);

/**
 * @brief Reconnect a cut controller: queued frames go out, its error state returns to what it
 *        was before the cut.
 */
int can_virtual_restore(const struct device *dev);

/**
 * @brief Delay every frame that reaches @p dev by @p latency_us microseconds after the end
 *        of the frame on the bus (0 = none). Order is kept.
 */
int can_virtual_set_latency(const struct device *dev, uint32_t latency_us);

/**
 * @brief Move a stopped controller to another bus.
 *
 * @retval -EBUSY The controller is started.
 */
int can_virtual_set_bus(const struct device *dev, int bus);

/**
 * @brief The bus a controller is on.
 *
 * @return Bus number, or -EINVAL.
 */
int can_virtual_get_bus(const struct device *dev);

/**
 * @brief Switch bit timing on @p bus: frames occupy it for can_virtual_frame_bits() bit times
 *        at the sender's bit rate (default: CONFIG_CAN_VIRTUAL_BIT_TIMING).
 */
int can_virtual_bus_set_bit_timing(int bus, bool enable);

/** @brief Copy the counters of @p bus into @p stats. */
int can_virtual_bus_get_stats(int bus, struct can_virtual_bus_stats *stats);

/**
 * @brief The virtual buses' clock in microseconds: the simulated clock, or the kernel's
 *        uptime in real-time mode.
 */
uint64_t can_virtual_time_us(void);

/**
 * @brief Advance the simulated clock by @p delta_us, delivering everything due on all buses in
 *        time order (frames, latency-delayed deliveries, bus-off recoveries).
 *
 * Must not be called from a CAN callback.
 *
 * @return Frames completed on the buses, or -ENOTSUP in real-time mode, -EBUSY when called
 *         from inside a run.
 */
int can_virtual_sim_advance(uint64_t delta_us);

/**
 * @brief Run the simulated buses until nothing is pending (advancing the clock as frames
 *        need), or @p max_frames frames have completed.
 *
 * @return Frames completed, or -ENOTSUP in real-time mode, -EBUSY from inside a run.
 */
int can_virtual_sim_run(uint32_t max_frames);

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_DRIVERS_CAN_VIRTUAL_H_ */
