/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Program download benchmark (doc/bench.md, doc/pgm.md): figures only, nothing is judged
 * but the outcome (every update ends with the new image running).
 *
 * The manager (node 1, line A) updates the slave (node 2, line B) in its boot, CiA 302 §4
 * step 4: 1F51h:01 = 0, a 256 kB image (header and body) into 1F50h:01 by block SDO, the
 * slave verifies it (reads it back from its RAM flash, CRC-32), 1F51h:01 = 1, the slave
 * switches and restarts (boot-up), the manager reads 1F52h again and ends the boot. Both
 * lines have their own thread, on one virtual bus at 1 Mbit/s with bit timing. Each round
 * updates the slave to the other of two images, so every round downloads.
 *
 * The bound is the bus time of the frames a block download with CRC of those bytes must
 * send (initiate request and response, 7-byte segments, one acknowledgement per sub-block
 * of 127 segments, end request and response), each at its exact stuffed length
 * (can_virtual_frame_bits()). "efficiency_pct" is that bound over the measured time from the
 * start of the initiate request to the end of the end response; that time includes the
 * slave's read-back verification, which happens between the end request and its response
 * ("verify_ms"). A third controller listens and times every step with the bus clock.
 *
 * Figures are printed as `BENCH {json}` lines; scripts/bench gathers them.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/pgm.h>

#include "pgm_master_od.h"
#include "pgm_slave_od.h"

#include "pgm_offer.h"

#define MANAGER  1U
#define SLAVE    2U
#define IMAGE    (256U * 1024U) /* bytes on the wire: header and body */
#define BODY     (IMAGE - CO_PGM_HDR_SIZE)
#define SLOT     (IMAGE + 64U)
#define ROUNDS   3
#define BITRATE  1000000U
#define SEG      7U
#define WAIT_S   60
#define REQ_ID   (0x600U + SLAVE)
#define RSP_ID   (0x580U + SLAVE)
#define BOOT_ID  (0x700U + SLAVE)
#define IDX_DATA 0x1F50U
#define IDX_CTRL 0x1F51U
/* An idle gap this long (8 frame times) is the host taking the CPU, not the stack. */
#define STALL_US 1000U

static struct co_line line_a, line_b;
static struct co_node mgr, slave;
static struct pgm_master_od_ram mram;
static struct pgm_slave_od_ram sram;
static K_THREAD_STACK_ARRAY_DEFINE(line_stacks, 2, CONFIG_CANOPEN_LINE_STACK_SIZE);

static struct co_pgm_flash_ram flash;
static uint8_t flash_mem[2 * SLOT];
static uint8_t img[2][IMAGE];
static const uint32_t img_date[2] = {14000U, 15000U};
static const uint32_t img_time[2] = {3600000U, 7200000U};
static int target;             /* the image this round installs */
static struct pgm_offer offer; /* img[target]; changed under the manager's lock */

static K_SEM_DEFINE(boot_sem, 0, 1);
static uint8_t boot_status;
static struct co_mgr_boot_error boot_err;
static uint64_t boot_end_us;

/* --- The manager's boot indication --------------------------------------------------------- */

static void boot_ind(struct co_node *node, uint8_t id, uint8_t status,
		     const struct co_mgr_boot_error *err, void *user_data)
{
	if (id != SLAVE) {
		return;
	}
	boot_end_us = can_virtual_time_us();
	boot_status = status;
	if (err != NULL) {
		boot_err = *err;
	}
	k_sem_give(&boot_sem);
}

/* --- The bound (as tests/canopen/sdo/bench computes it) ------------------------------------ */

struct bound {
	uint32_t frames;
	uint64_t bits; /* exact, stuff bits included */
};

static uint32_t frame_bits(uint32_t id, const uint8_t d[8])
{
	struct can_frame f = {.id = id, .dlc = 8};

	memcpy(f.data, d, 8);
	return can_virtual_frame_bits(&f);
}

static void add(struct bound *b, uint32_t id, const uint8_t d[8])
{
	b->frames++;
	b->bits += frame_bits(id, d);
}

static struct bound bound_download(const uint8_t *data, uint32_t len, uint8_t blksize)
{
	uint32_t nseg = DIV_ROUND_UP(len, SEG);
	uint32_t last_len = (len - 1U) % SEG + 1U;
	struct bound b = {0};
	uint32_t seq = 0U;
	uint8_t d[8] = {0xC6, (uint8_t)IDX_DATA, (uint8_t)(IDX_DATA >> 8), 1}; /* ccs 6, cc, s */

	sys_put_le32(len, &d[4]);
	add(&b, REQ_ID, d);
	memset(&d[4], 0, 4);
	d[0] = 0xA4; /* scs 5, sc */
	d[4] = blksize;
	add(&b, RSP_ID, d);
	for (uint32_t i = 0U; i < nseg; i++) {
		const uint32_t o = i * SEG;
		const bool last = i + 1U == nseg;

		memset(d, 0, sizeof(d));
		seq++;
		d[0] = (uint8_t)(seq | (last ? 0x80U : 0U));
		memcpy(&d[1], &data[o], MIN(SEG, len - o));
		add(&b, REQ_ID, d);
		if (seq == blksize || last) {
			const uint8_t ack[8] = {0xA2, (uint8_t)seq, blksize};

			add(&b, RSP_ID, ack);
			seq = 0U;
		}
	}
	memset(d, 0, sizeof(d));
	d[0] = (uint8_t)(0xC1U | ((SEG - last_len) << 2));
	sys_put_le16(crc16_itu_t(0U, data, len), &d[1]);
	add(&b, REQ_ID, d);
	memset(d, 0, sizeof(d));
	d[0] = 0xA1;
	add(&b, RSP_ID, d);
	return b;
}

/* --- The listening controller: when each step happened on the bus ------------------------- */

/* End times (bus clock, µs) of the frames that mark the steps of one update. */
static struct {
	bool on;
	uint64_t stop_req_start; /* 1F51h:01 = 0 request, start of the frame */
	uint64_t dl_start;       /* block download initiate request, start of the frame */
	uint64_t last_req;       /* end of the last client frame seen */
	uint64_t end_req;        /* end of the block download end request */
	uint64_t dl_end;         /* end of the end response */
	uint64_t start_req;      /* end of the 1F51h:01 = 1 request */
	uint64_t bootup;         /* end of the boot-up message after it */
	uint32_t dl_frames;      /* frames of the download on the bus, both directions */
	bool in_dl;
	uint64_t prev_end; /* end of the frame before, during the download */
	uint64_t stall_us; /* idle gaps of STALL_US or more during the download */
	uint32_t stalls;
} watch;

static bool is_init_dn(const struct can_frame *f, uint16_t index)
{
	return f->id == REQ_ID && f->dlc == 8 && sys_get_le16(&f->data[1]) == index &&
	       ((f->data[0] & 0xE0U) == 0x20U || (f->data[0] & 0xE1U) == 0xC0U);
}

/*
 * The bus time of the end of @p f: the latest time not after now whose low 16 bits are its
 * receive timestamp (µs, taken when the frame ended on the bus), so that a callback the
 * host runs late (by less than 65 ms) still gets the frame's own time.
 */
static uint64_t frame_end(const struct can_frame *f)
{
	const uint64_t now = can_virtual_time_us();

	return now - (uint16_t)((uint16_t)now - f->timestamp);
}

/* Runs in the bus thread at the end of every frame. */
static void spy_rx(const struct device *dev, struct can_frame *f, void *user_data)
{
	const uint64_t now = frame_end(f);

	if (!watch.on) {
		return;
	}
	if (watch.in_dl && (f->id == REQ_ID || f->id == RSP_ID)) {
		const uint64_t gap = now - can_virtual_frame_bits(f) - watch.prev_end;

		watch.dl_frames++;
		if (gap >= STALL_US) {
			watch.stall_us += gap;
			watch.stalls++;
		}
	}
	if (is_init_dn(f, IDX_CTRL) && f->data[4] == 0U && watch.stop_req_start == 0U) {
		watch.stop_req_start = now - can_virtual_frame_bits(f);
	} else if (is_init_dn(f, IDX_DATA) && watch.dl_start == 0U) {
		watch.dl_start = now - can_virtual_frame_bits(f);
		watch.in_dl = true;
		watch.dl_frames = 1U;
	} else if (watch.in_dl && f->id == RSP_ID && f->data[0] == 0xA1U) {
		watch.end_req = watch.last_req;
		watch.dl_end = now;
		watch.in_dl = false;
	} else if (is_init_dn(f, IDX_CTRL) && f->data[4] == 1U && watch.dl_end != 0U) {
		watch.start_req = now;
	} else if (f->id == BOOT_ID && f->dlc == 1U && f->data[0] == 0U && watch.start_req != 0U &&
		   watch.bootup == 0U) {
		watch.bootup = now;
	}
	if (f->id == REQ_ID) {
		watch.last_req = now;
	}
	watch.prev_end = now;
}

/* --- Rounds -------------------------------------------------------------------------------- */

struct run {
	uint64_t dl_us;     /* download: initiate request to end response */
	uint64_t verify_us; /* end request to end response: the slave's read-back */
	uint64_t update_us; /* stop request to the boot-up of the new image */
	uint64_t boot_us;   /* the manager's reset to the end of the slave's boot */
	uint32_t dl_frames;
	uint64_t stall_us;
	uint32_t stalls;
};

static void fail(const char *what)
{
	printf("pgm_bench: %s\n", what);
	exit(1);
}

static void make_image(uint8_t *p, uint32_t date, uint32_t time, uint32_t seed)
{
	for (uint32_t i = 0; i < BODY; i++) {
		seed = seed * 1103515245U + 12345U;
		p[CO_PGM_HDR_SIZE + i] = (uint8_t)(seed >> 16);
	}
	co_pgm_image_header(p, p + CO_PGM_HDR_SIZE, BODY, date, time);
}

static void round_run(int r, struct run *out)
{
	struct co_pgm_image_info info;
	uint64_t t0;
	int rc;

	co_node_lock(&mgr);
	target = (r + 1) % 2;
	offer = (struct pgm_offer){.slave = SLAVE,
				   .image = img[target],
				   .len = IMAGE,
				   .date = img_date[target],
				   .time = img_time[target]};
	co_node_unlock(&mgr);
	memset(&watch, 0, sizeof(watch));
	watch.on = true;
	k_sem_reset(&boot_sem);
	t0 = can_virtual_time_us();
	rc = r == 0 ? co_node_start(&mgr) : co_nmt_req(&mgr, CO_NMT_CS_RESET_COMMUNICATION);
	if (rc != 0) {
		fail("manager start failed");
	}
	if (k_sem_take(&boot_sem, K_SECONDS(WAIT_S)) != 0) {
		fail("no end of the slave's boot");
	}
	k_msleep(2); /* the last frames seen by the listener */
	watch.on = false;
	if (boot_status != CO_MGR_ST_OK) {
		printf("pgm_bench: round %d: boot status %c in %s, %04Xh:%02Xh abort %08X\n", r,
		       boot_status, co_mgr_step_str(boot_err.step), boot_err.index, boot_err.sub,
		       boot_err.abort_code);
		fail("the update failed");
	}
	if (co_pgm_get_running(&slave, &info, NULL) != 0 || info.date != img_date[target] ||
	    info.time != img_time[target]) {
		fail("the slave does not run the new image");
	}
	if (watch.dl_end == 0U || watch.bootup == 0U || watch.stop_req_start == 0U) {
		fail("a step of the update was not seen on the bus");
	}
	out->dl_us = watch.dl_end - watch.dl_start;
	out->verify_us = watch.dl_end - watch.end_req;
	out->update_us = watch.bootup - watch.stop_req_start;
	out->boot_us = boot_end_us - t0;
	out->dl_frames = watch.dl_frames;
	out->stall_us = watch.stall_us;
	out->stalls = watch.stalls;
}

int main(void)
{
	const struct device *spy;
	struct run best = {0}, worst = {0};
	struct bound b;
	double bound_us;

	printf("pgm_bench: %u-byte image at %u bit/s (bit timing on), %d rounds\n", IMAGE, BITRATE,
	       ROUNDS);
	make_image(img[0], img_date[0], img_time[0], 1U);
	make_image(img[1], img_date[1], img_time[1], 2U);
	if (co_pgm_flash_ram_init(&flash, flash_mem, SLOT) != 0 ||
	    co_pgm_slot_program(&flash.flash, 0, img[0], IMAGE, 1U) != 0) {
		fail("factory programming failed");
	}
	if (co_line_init(&line_a, "mgr", device_get_binding("can_virtual0")) != 0 ||
	    co_line_init(&line_b, "slave", device_get_binding("can_virtual1")) != 0 ||
	    co_node_init(&mgr, "manager", &line_a, &pgm_master_od_def, &mram, MANAGER) != 0 ||
	    co_node_init(&slave, "slave", &line_b, &pgm_slave_od_def, &sram, SLAVE) != 0 ||
	    co_pgm_attach(&slave, &flash.flash) != 0) {
		fail("set-up failed");
	}
	co_od_set_restore_cb(co_node_od(&mgr), pgm_offer_restore, &offer);
	co_mgr_set_boot_ind(&mgr, boot_ind, NULL);
	co_mgr_set_pgm_source(&mgr, pgm_offer_source, &offer);
	spy = device_get_binding("can_virtual2");
	if (spy == NULL || can_start(spy) != 0 ||
	    can_add_rx_filter(spy, spy_rx, NULL, &(struct can_filter){.id = 0, .mask = 0}) < 0) {
		fail("the listening controller failed");
	}
	if (co_line_start(&line_a, line_stacks[0], K_THREAD_STACK_SIZEOF(line_stacks[0]),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_line_start(&line_b, line_stacks[1], K_THREAD_STACK_SIZEOF(line_stacks[1]),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_node_start(&slave) != 0) {
		fail("start failed");
	}
	k_msleep(20);

	for (int r = 0; r < ROUNDS; r++) {
		struct run x;

		round_run(r, &x);
		printf("pgm_bench: round %d: download %.1f ms, update %.1f ms, boot %.1f ms\n", r,
		       x.dl_us / 1e3, x.update_us / 1e3, x.boot_us / 1e3);
		if (r == 0 || x.dl_us < best.dl_us) {
			best = x;
		}
		if (r == 0 || x.dl_us > worst.dl_us) {
			worst = x;
		}
	}

	/* Every round downloads one of the two images; their bounds differ by a few bits. */
	b = bound_download(img[1], IMAGE, CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE);
	bound_us = (double)b.bits * (1e6 / BITRATE);
	printf("BENCH {\"name\": \"pgm.download_256k\", \"bytes\": %u, \"rounds\": %d, "
	       "\"ms\": %.1f, \"bytes_per_s\": %.0f, \"bound_ms\": %.1f, "
	       "\"bound_bytes_per_s\": %.0f, \"efficiency_pct\": %.2f, "
	       "\"efficiency_worst_round_pct\": %.2f, \"verify_ms\": %.2f, "
	       "\"efficiency_without_verify_pct\": %.2f, \"frames\": %u, \"bits\": %llu, "
	       "\"bus_frames\": %u, \"stalls\": %u, \"stall_ms\": %.1f, "
	       "\"efficiency_no_stall_pct\": %.2f, \"blksize\": %u, \"bitrate\": %u}\n",
	       IMAGE, ROUNDS, best.dl_us / 1e3, IMAGE * 1e6 / (double)best.dl_us, bound_us / 1e3,
	       IMAGE * 1e6 / bound_us, 100.0 * bound_us / (double)best.dl_us,
	       100.0 * bound_us / (double)worst.dl_us, best.verify_us / 1e3,
	       100.0 * bound_us / (double)(best.dl_us - best.verify_us), b.frames,
	       (unsigned long long)b.bits, best.dl_frames, best.stalls, best.stall_us / 1e3,
	       100.0 * bound_us / (double)(best.dl_us - best.stall_us),
	       CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE, BITRATE);
	printf("BENCH {\"name\": \"pgm.update_256k\", \"bytes\": %u, \"rounds\": %d, "
	       "\"ms\": %.1f, \"download_ms\": %.1f, \"overhead_ms\": %.1f, "
	       "\"boot_ms\": %.1f, \"bitrate\": %u}\n",
	       IMAGE, ROUNDS, best.update_us / 1e3, best.dl_us / 1e3,
	       (best.update_us - best.dl_us) / 1e3, best.boot_us / 1e3, BITRATE);
	printf("pgm_bench: done\n");
	return 0;
}
