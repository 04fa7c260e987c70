/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The libFuzzer driver: main() runs in the kernel's main thread (so the stack's mutexes and
 * timers behave as in the ztest suites) and hands the command line after --testargs to
 * LLVMFuzzerRunDriver(). The "--testargs" stays first in the arguments libFuzzer keeps, so the
 * child processes it starts (crash minimisation) get the same command line back.
 */

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/kernel.h>

#include "cmdline.h"
#include "fuzz.h"

int LLVMFuzzerRunDriver(int *argc, char ***argv, int (*cb)(const uint8_t *data, size_t size));

struct fz_state fz;

static const struct fz_harness *const harnesses[] = {
	&fz_nmt,        &fz_errctl, &fz_sdo_server, &fz_pdo,  &fz_sync, &fz_time, &fz_emcy,
	&fz_sdo_client, &fz_mgr,    &fz_lss,        &fz_srdo, &fz_cdcf, &fz_dcf,
};

void fz_fail(const char *fmt, ...)
{
	va_list ap;

	fprintf(stderr, "INVARIANT: %s: ", fz.h != NULL ? fz.h->name : "?");
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, " (t = %llu us)\n", (unsigned long long)fz.now);
	fflush(stderr);
	abort();
}

bool fz_restricted(uint32_t id)
{
	return id <= 0x07FU || (id >= 0x101U && id <= 0x180U) || (id >= 0x581U && id <= 0x5FFU) ||
	       (id >= 0x601U && id <= 0x67FU) || (id >= 0x6E0U && id <= 0x6FFU) ||
	       (id >= 0x701U && id <= 0x7FFU);
}

/* SAFELINE_FUZZ_TRACE=1: print every frame (to read a crash input). */
static bool trace;

static void print_frame(const char *dir, const struct can_frame *f)
{
	printf("%10llu us %s %03X%s [%u]", (unsigned long long)fz.now, dir, f->id,
	       (f->flags & CAN_FRAME_RTR) != 0U ? " RTR" : "", f->dlc);
	for (uint8_t i = 0; i < f->dlc && i < 8U; i++) {
		printf(" %02X", f->data[i]);
	}
	printf("\n");
}

static bool default_may_send(const struct can_frame *f)
{
	/* The node's own SDO server answers, heartbeat/boot-up/guarding reply, LSS answer. */
	return f->id == 0x580U + fz.dut_id || f->id == 0x700U + fz.dut_id || f->id == 0x7E4U;
}

void fz_check_state(void)
{
	enum co_nmt_state st;

	if (fz.dut == NULL) {
		return;
	}
	st = co_nmt_get_state(fz.dut);
	if (st != CO_NMT_STOPPED && st != CO_NMT_OPERATIONAL && st != CO_NMT_PRE_OPERATIONAL &&
	    !(st == CO_NMT_INITIALISING && co_node_id(fz.dut) == CO_NODE_ID_UNCONFIGURED)) {
		fz_fail("NMT state %02Xh", st);
	}
	if (fz.break_invariant && st == CO_NMT_OPERATIONAL) {
		fz_fail("Operational (SAFELINE_FUZZ_BREAK is set)");
	}
}

static int sink(struct co_line *line, const struct can_frame *f, void *user_data)
{
	bool ext = (f->flags & CAN_FRAME_IDE) != 0U;

	if (fz.tx_busy) {
		/* The controller is stopped (LSS bit rate switch): frames wait in the TX queue,
		 * but an LSS answer must not even be tried, the slave ignores requests then.
		 */
		if (f->id == 0x7E4U) {
			fz_fail("LSS answer %02Xh during the bit timing switch", f->data[0]);
		}
		return -EAGAIN;
	}
	if (trace) {
		print_frame("tx", f);
	}
	fz.tx_since++;
	fz.tx_total++;
	fz.last_req = *f;
	fz.have_req = true;
	if (fz.dut != NULL && !ext) {
		if (fz_restricted(f->id) &&
		    !(fz.h->may_send != NULL ? fz.h->may_send(f) : default_may_send(f))) {
			fz_fail("frame on restricted identifier %03Xh", f->id);
		}
		if (co_nmt_get_state(fz.dut) == CO_NMT_STOPPED && f->id != 0x000U &&
		    !(f->id >= 0x700U && f->id <= 0x77FU) && f->id != 0x7E4U && f->id != 0x7E5U) {
			fz_fail("frame %03Xh sent in Stopped", f->id);
		}
	}
	if (fz.h->on_tx != NULL) {
		fz.h->on_tx(f);
	}
	return 0;
}

void fz_line_init(void)
{
	const struct fz_harness *h = fz.h;
	bool brk = fz.break_invariant;

	memset(&fz, 0, sizeof(fz));
	fz.h = h;
	fz.break_invariant = brk;
	co_line_init_sim(&fz.line, "fuzz", sink, NULL);
}

void fz_run_until(uint64_t at_us)
{
	while (true) {
		uint64_t next = co_line_next_deadline(&fz.line);

		if (next == UINT64_MAX || next > at_us) {
			break;
		}
		fz.now = next > fz.now ? next : fz.now;
		co_line_process(&fz.line, fz.now);
		fz_check_state();
	}
	fz.now = at_us;
	co_line_process(&fz.line, fz.now);
	fz_check_state();
}

void fz_rx(const struct can_frame *f)
{
	if (trace) {
		print_frame("rx", f);
	}
	co_line_rx(&fz.line, f, fz.now);
}

static uint32_t record_id(uint8_t sel)
{
	uint32_t id = fz.h->ids[sel % fz.h->n_ids];

	if ((id & 0x80000000U) != 0U) {
		id = (id & 0x7FFU) + fz.dut_id;
	}
	return id;
}

static int one_input(const uint8_t *data, size_t size)
{
	const struct fz_harness *h = fz.h;
	size_t n = 0;

	if (h->raw != NULL) {
		h->raw(data, size);
		return 0;
	}
	fz_line_init();
	h->setup(&data, &size);
	fz_check_state();
	while (size >= FZ_REC && n++ < FZ_MAX_RECS) {
		struct can_frame f = {.id = record_id(data[0])};
		uint8_t dt = data[10];
		uint8_t dlc = data[1] & 0x0FU;

		f.dlc = dlc > 8U ? 8U : dlc;
		if ((data[1] & 0x10U) != 0U) {
			f.flags |= CAN_FRAME_RTR;
		}
		memcpy(f.data, &data[2], 8);
		if ((data[1] & 0x20U) != 0U && fz.have_req) {
			/* An answer to the node's last request: same multiplexor. */
			memcpy(&f.data[1], &fz.last_req.data[1], 3);
		}
		if ((data[1] & 0x40U) != 0U && fz.have_req) {
			/* The SDO toggle bit of the last frame sent. */
			f.data[0] = (f.data[0] & ~0x10U) | (fz.last_req.data[0] & 0x10U);
		}
		data += FZ_REC;
		size -= FZ_REC;

		fz.tx_since = 0;
		fz_run_until(fz.now + (dt < 128U ? dt * 100ULL : (dt - 128ULL) * 10ULL * FZ_MS));
		if (h->after_time != NULL) {
			h->after_time();
		}
		fz.tx_since = 0;
		fz_rx(&f);
		fz_check_state();
		if (h->after_frame != NULL) {
			h->after_frame(&f);
		}
	}
	if (h->finish != NULL) {
		h->finish();
	}
	return 0;
}

static void usage(void)
{
	printf("usage: zephyr.exe --testargs --harness=NAME [libFuzzer options] [corpus...]\n"
	       "harnesses:\n");
	for (size_t i = 0; i < ARRAY_SIZE(harnesses); i++) {
		printf("  %-12s %s\n", harnesses[i]->name, harnesses[i]->what);
	}
}

int main(void)
{
	int targc;
	char **targv;
	char *argv0;
	int dummy;
	char **all;
	static char *args[256];
	int n = 0;
	char **argp = args;
	const char *brk = getenv("SAFELINE_FUZZ_BREAK");

	native_get_cmd_line_args(&dummy, &all);
	argv0 = all[0];
	native_get_test_cmd_line_args(&targc, &targv);
	fz.break_invariant = brk != NULL && strcmp(brk, "1") == 0;
	trace = getenv("SAFELINE_FUZZ_TRACE") != NULL;
	args[n++] = argv0;
	args[n++] = "--testargs";
	for (int i = 0; i < targc && n < (int)ARRAY_SIZE(args) - 1; i++) {
		if (strncmp(targv[i], "--harness=", 10) == 0) {
			for (size_t k = 0; k < ARRAY_SIZE(harnesses); k++) {
				if (strcmp(harnesses[k]->name, targv[i] + 10) == 0) {
					fz.h = harnesses[k];
				}
			}
			if (fz.h == NULL) {
				fprintf(stderr, "unknown harness '%s'\n", targv[i] + 10);
				usage();
				return 2;
			}
		} else if (strcmp(targv[i], "--list") == 0) {
			for (size_t k = 0; k < ARRAY_SIZE(harnesses); k++) {
				printf("%s\t%s\n", harnesses[k]->name, harnesses[k]->what);
			}
			return 0;
		}
		args[n++] = targv[i];
	}
	args[n] = NULL;
	if (fz.h == NULL) {
		usage();
		return 2;
	}
	return LLVMFuzzerRunDriver(&n, &argp, one_input);
}
