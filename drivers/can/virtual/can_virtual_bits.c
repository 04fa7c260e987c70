/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Length of a classic CAN frame on the wire, with bit stuffing. The stuffed part (start of
 * frame to the end of the CRC) is built bit by bit, because stuff bits depend on the CRC,
 * which depends on the identifier and data.
 */

#include <stdint.h>

#include <zephyr/drivers/can.h>

#include "can_virtual.h"

#define CRC15_POLY      0x4599U
/* CRC delimiter, ACK slot, ACK delimiter, end of frame (7), intermission (3). */
#define FIXED_TAIL_BITS (1U + 1U + 1U + 7U + 3U)

struct bitseq {
	uint32_t bits;    /* bits so far, unstuffed */
	uint32_t stuffed; /* stuff bits inserted so far */
	uint16_t crc;
	uint8_t last;
	uint8_t run;
};

static void put_bit(struct bitseq *s, uint8_t bit, bool crc)
{
	if (crc) {
		uint16_t next = (uint16_t)(bit ^ ((s->crc >> 14) & 1U));

		s->crc = (uint16_t)((s->crc << 1) & 0x7FFFU);
		if (next != 0U) {
			s->crc ^= CRC15_POLY;
		}
	}
	s->bits++;
	if (s->run > 0U && bit == s->last) {
		s->run++;
	} else {
		s->last = bit;
		s->run = 1U;
	}
	if (s->run == 5U) {
		/* The stuff bit is the complement and starts a new run. */
		s->stuffed++;
		s->last = (bit != 0U) ? 0U : 1U;
		s->run = 1U;
	}
}

static void put_bits(struct bitseq *s, uint32_t value, unsigned int n, bool crc)
{
	while (n-- > 0U) {
		put_bit(s, (uint8_t)((value >> n) & 1U), crc);
	}
}

uint32_t can_virtual_frame_bits(const struct can_frame *frame)
{
	struct bitseq s = {0};
	const bool rtr = (frame->flags & CAN_FRAME_RTR) != 0U;
	const uint8_t dlc = frame->dlc > CAN_MAX_DLC ? CAN_MAX_DLC : frame->dlc;
	uint16_t crc;

	put_bit(&s, 0U, true); /* SOF */
	if ((frame->flags & CAN_FRAME_IDE) != 0U) {
		put_bits(&s, (frame->id >> 18) & 0x7FFU, 11U, true);
		put_bits(&s, 1U, 1U, true); /* SRR */
		put_bits(&s, 1U, 1U, true); /* IDE */
		put_bits(&s, frame->id & 0x3FFFFU, 18U, true);
		put_bits(&s, rtr ? 1U : 0U, 1U, true);
		put_bits(&s, 0U, 2U, true); /* r1, r0 */
	} else {
		put_bits(&s, frame->id & 0x7FFU, 11U, true);
		put_bits(&s, rtr ? 1U : 0U, 1U, true);
		put_bits(&s, 0U, 2U, true); /* IDE, r0 */
	}
	put_bits(&s, frame->dlc & 0xFU, 4U, true);
	if (!rtr) {
		for (uint8_t i = 0U; i < dlc; i++) {
			put_bits(&s, frame->data[i], 8U, true);
		}
	}
	crc = s.crc;
	put_bits(&s, crc, 15U, false);

	return s.bits + s.stuffed + FIXED_TAIL_BITS;
}
