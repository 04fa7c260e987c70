/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * libFuzzer harnesses on simulated time (doc/fuzz.md). One image holds every harness; the
 * option --harness=NAME picks one. An input is a sequence of 11-byte records, each one frame
 * received by the node after a time advance:
 *
 *   byte 0      identifier: an entry of the harness's identifier table (modulo its size)
 *   byte 1      bits 0-3 DLC (above 8: 8), bit 4 RTR, bit 5 "answer": copy bytes 1-3 (an SDO
 *               multiplexor) of the last frame the line sent, bit 6 copy the SDO toggle bit
 *               (byte 0 bit 4) of that frame
 *   bytes 2-9   data
 *   byte 10     time advance before the frame: 0-127 × 100 µs, 128-255 × 10 ms (from 0)
 *
 * After every frame and every time advance the invariants of doc/fuzz.md are checked; a
 * broken invariant prints "INVARIANT: ..." and aborts, which libFuzzer reports as a crash.
 */

#ifndef SAFELINE_TESTS_FUZZ_FUZZ_H_
#define SAFELINE_TESTS_FUZZ_FUZZ_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>

#define FZ_REC      11U
#define FZ_MS       1000ULL
#define FZ_MAX_RECS 256U

struct fz_harness {
	const char *name;
	const char *what;
	/* Create the nodes on fz.line and start them (called for every input). */
	void (*setup)(const uint8_t **data, size_t *size);
	/* Identifiers the records pick from; dut_id-relative entries use FZ_REL(). */
	const uint32_t *ids;
	size_t n_ids;
	/* Whether the node under test may send this restricted identifier (NULL: the defaults). */
	bool (*may_send)(const struct can_frame *f);
	/* Every frame the line sends (after the common checks); may queue answers. */
	void (*on_tx)(const struct can_frame *f);
	/* After each time advance, before the next frame. */
	void (*after_time)(void);
	/* After each received frame, with the frames it caused (fz.tx_since). */
	void (*after_frame)(const struct can_frame *rx);
	/* After the whole input (e.g. run on and check that something ended). */
	void (*finish)(void);
	/* For harnesses that are no frame sequences (concise DCF): takes the raw input. */
	void (*raw)(const uint8_t *data, size_t size);
};

/* An identifier relative to the node under test's ID (e.g. FZ_REL(0x600): its SDO request). */
#define FZ_REL(base) (0x80000000U | (base))

struct fz_state {
	struct co_line line;
	uint64_t now;
	const struct fz_harness *h;
	/* The node whose invariants are checked. */
	struct co_node *dut;
	uint8_t dut_id;
	/* Frames sent since the last received frame or time advance. */
	unsigned int tx_since;
	unsigned int tx_total;
	/* The last frame sent, for the "answer" flags. */
	struct can_frame last_req;
	bool have_req;
	/* Test hook (SAFELINE_FUZZ_BREAK=1): Operational counts as an invalid state. */
	bool break_invariant;
	/* While set, the sink pushes back (-EAGAIN) as a stopped controller would. */
	bool tx_busy;
};

extern struct fz_state fz;

/* Print "INVARIANT: <harness>: <message>" and abort. */
void fz_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));

/* Advance simulated time to @p at_us, running every deadline on the way. */
void fz_run_until(uint64_t at_us);

/* Receive a frame at the current time. */
void fz_rx(const struct can_frame *f);

/* CiA 301 §7.3.5: identifiers no configurable COB-ID may use. */
bool fz_restricted(uint32_t id);

/* The common invariants: the node's NMT state is valid. */
void fz_check_state(void);

/* Reset fz (keeping the harness) and initialise fz.line. */
void fz_line_init(void);

extern const struct fz_harness fz_nmt, fz_errctl, fz_sdo_server, fz_pdo, fz_sync, fz_time, fz_emcy,
	fz_sdo_client, fz_mgr, fz_lss, fz_srdo, fz_cdcf, fz_dcf;

#endif /* SAFELINE_TESTS_FUZZ_FUZZ_H_ */
