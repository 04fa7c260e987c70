/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * SDO block transfer benchmark (doc/bench.md): figures only, nothing is judged.
 *
 * A client node on line A and a server node on line B, both lines with their own thread,
 * on one virtual bus at 1 Mbit/s with bit timing (each frame holds the bus for its length in
 * bits, stuff bits included, plus the intermission). The client downloads 100 000 bytes
 * into a DOMAIN of the server (a streamed provider at 3000h) with block transfer, then
 * uploads them again, several rounds each.
 *
 * The bound is the bus time of the frames the protocol must send: initiate request and
 * response, the segments (7 bytes each), one acknowledgement per sub-block of blksize
 * segments, the end request and response (plus the start frame of an upload), each at its
 * exact stuffed length for the bytes sent (can_virtual_frame_bits(): reserved bytes zero,
 * CRC on, the data of this benchmark). "efficiency_pct" is that bound over the measured time
 * from the request to its confirmation: 100 % means the bus never idled. Beside it: the same
 * frames with no stuff bits (111 bits each) and with the worst-case stuffing of an 8-byte
 * standard frame (135 bits), and what the bus itself counted (frames, busy time), which
 * shows whether the stack sent anything beyond the protocol's frames.
 *
 * Where the bus idled: a third controller listens to the bus and notes the end time of every
 * frame (receive timestamps). The gap before a frame is its end minus its length minus the
 * end of the frame before; the gaps are summed by where they fall: before an
 * acknowledgement (the receiver's line thread turning the sub-block round), after one (the
 * sender's line thread starting the next sub-block), inside a sub-block (the sender not
 * keeping the controller's mailboxes filled), and the rest (initiate and end).
 *
 * The bus runs on the host's clock, so a host that takes the CPU from the process for a
 * while (other processes on a shared machine) shows as idle bus time too, whichever thread
 * it hit: the bus thread that completes frames, or a line thread. Gaps of STALL_US or more
 * (more than 8 frame times, the controller's mailboxes' worth) are summed apart as
 * "stall_ms", and "efficiency_no_stall_pct" leaves them out: it is the stack's own figure,
 * "efficiency_pct" that of the run.
 *
 * Each figure is printed as one line `BENCH {json}`; scripts/bench gathers them.
 */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/crc.h>

#include <canopen/line.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/sdo_cli.h>

#include "can_virtual.h"
#include "sdo_cli_test_od.h"

#define CLI_ID           0x10U
#define SRV_ID           0x20U
#define DOM_IDX          0x3000U
#define SIZE             100000U
#define ROUNDS           5
#define BITRATE          1000000U
#define SEG              7U
/* 8-byte standard data frame: no stuff bits / the most stuff bits it can carry. */
#define BITS_NO_STUFF    111U
#define BITS_WORST_STUFF 135U
#define STALL_US         1000U

static struct co_line line_a, line_b;
static struct co_node cnode, snode;
static struct sdo_cli_test_od_ram cram, sram;
static K_THREAD_STACK_ARRAY_DEFINE(line_stacks, 2, CONFIG_CANOPEN_LINE_STACK_SIZE);

static const struct device *spy;
static uint8_t out[SIZE];
static uint8_t in[SIZE];
static uint8_t dom[SIZE];
static uint32_t dom_len;

/* --- The server's 100 kB DOMAIN: a streamed provider ---------------------------------------- */

static uint32_t prov_info(const struct co_od_provider *p, struct co_od_info *info)
{
	if (info->index != DOM_IDX) {
		return CO_SDO_AB_NO_OBJECT;
	}
	if (info->sub != 0U) {
		return CO_SDO_AB_NO_SUB;
	}
	info->dtype = CO_DTYPE_DOMAIN;
	info->limit = NULL;
	info->access = CO_OD_ACCESS_RW;
	info->flags = CO_OD_F_STREAM;
	info->size = SIZE;
	return 0;
}

static uint32_t prov_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	return dom_len;
}

static uint32_t prov_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	*len = offset >= dom_len ? 0U : MIN(cap, dom_len - offset);
	memcpy(buf, &dom[offset], *len);
	return 0;
}

static uint32_t prov_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	if (data == NULL && len == 0U) {
		return 0; /* an abort: nothing staged to drop */
	}
	if ((uint64_t)offset + len > SIZE) {
		return CO_SDO_AB_DATA_LONG;
	}
	memcpy(&dom[offset], data, len);
	if (last) {
		dom_len = offset + (uint32_t)len;
	}
	return 0;
}

static const struct co_od_provider_api prov_api = {
	.info = prov_info,
	.length = prov_length,
	.read = prov_read,
	.write = prov_write,
};

static struct co_od_provider prov = {
	.api = &prov_api,
	.index_first = DOM_IDX,
	.index_last = DOM_IDX,
};

/* --- The bound ------------------------------------------------------------------------------ */

struct bound {
	uint32_t frames;
	uint64_t bits; /* exact, stuff bits included */
};

static void add(struct bound *b, uint32_t id, const uint8_t d[8])
{
	struct can_frame f = {.id = id, .dlc = 8};

	memcpy(f.data, d, 8);
	b->frames++;
	b->bits += can_virtual_frame_bits(&f);
}

/* Segments and acknowledgements; @p seg_id carries the data, @p ack_id the acknowledgements. */
static void add_sub_blocks(struct bound *b, const uint8_t *data, uint32_t len, uint8_t blksize,
			   uint32_t seg_id, uint32_t ack_id)
{
	uint32_t nseg = len == 0U ? 1U : DIV_ROUND_UP(len, SEG);
	uint32_t seq = 0U;

	for (uint32_t i = 0U; i < nseg; i++) {
		uint8_t d[8] = {0};
		uint32_t o = i * SEG;
		bool last = i + 1U == nseg;

		seq++;
		d[0] = (uint8_t)(seq | (last ? 0x80U : 0U));
		memcpy(&d[1], &data[o], MIN(SEG, len - o));
		add(b, seg_id, d);
		if (seq == blksize || last) {
			const uint8_t ack[8] = {0xA2, (uint8_t)seq, blksize};

			add(b, ack_id, ack);
			seq = 0U;
		}
	}
}

static void put_init(uint8_t d[8], uint8_t b0, uint16_t idx, uint8_t sub)
{
	memset(d, 0, 8);
	d[0] = b0;
	sys_put_le16(idx, &d[1]);
	d[3] = sub;
}

static void add_end(struct bound *b, const uint8_t *data, uint32_t len, uint32_t end_id,
		    uint32_t rsp_id)
{
	uint8_t d[8] = {0};
	uint32_t last_len = len == 0U ? 0U : (len - 1U) % SEG + 1U;

	d[0] = (uint8_t)(0xC1U | ((SEG - last_len) << 2));
	sys_put_le16(crc16_itu_t(0U, data, len), &d[1]);
	add(b, end_id, d);
	memset(d, 0, 8);
	d[0] = 0xA1;
	add(b, rsp_id, d);
}

/* Block download with CRC: client frames on 600h + id, server frames on 580h + id. */
static struct bound bound_download(const uint8_t *data, uint32_t len, uint8_t blksize)
{
	const uint32_t c2s = 0x600U + SRV_ID, s2c = 0x580U + SRV_ID;
	struct bound b = {0};
	uint8_t d[8];

	put_init(d, 0xC6, DOM_IDX, 0); /* ccs 6, cc, s, cs 0 */
	sys_put_le32(len, &d[4]);
	add(&b, c2s, d);
	put_init(d, 0xA4, DOM_IDX, 0); /* scs 5, sc, ss 0 */
	d[4] = blksize;
	add(&b, s2c, d);
	add_sub_blocks(&b, data, len, blksize, c2s, s2c);
	add_end(&b, data, len, c2s, s2c);
	return b;
}

/* Block upload with CRC: the server sends the segments and the end request. */
static struct bound bound_upload(const uint8_t *data, uint32_t len, uint8_t blksize, uint8_t pst)
{
	const uint32_t c2s = 0x600U + SRV_ID, s2c = 0x580U + SRV_ID;
	struct bound b = {0};
	uint8_t d[8];

	put_init(d, 0xA4, DOM_IDX, 0); /* ccs 5, cc, cs 0 */
	d[4] = blksize;
	d[5] = pst;
	add(&b, c2s, d);
	put_init(d, 0xC6, DOM_IDX, 0); /* scs 6, sc, s, ss 0 */
	sys_put_le32(len, &d[4]);
	add(&b, s2c, d);
	memset(d, 0, 8);
	d[0] = 0xA3; /* start */
	add(&b, c2s, d);
	add_sub_blocks(&b, data, len, blksize, s2c, c2s);
	add_end(&b, data, len, s2c, c2s);
	return b;
}

/* --- Where the bus idled --------------------------------------------------------------------- */

enum gap_kind {
	GAP_BEFORE_ACK,
	GAP_AFTER_ACK,
	GAP_IN_BLOCK,
	GAP_OTHER,
	GAP_KINDS
};

static struct {
	bool on;
	uint32_t ack_id; /* the COB-ID the acknowledgements travel on */
	bool have_last;
	uint16_t last_end; /* µs, 16-bit receive timestamp */
	bool last_was_ack;
	bool last_was_seg;
	uint64_t idle_us[GAP_KINDS];
	uint32_t gaps[GAP_KINDS];
	uint32_t max_us[GAP_KINDS];
	uint64_t stall_us;
	uint32_t stalls;
} watch;

static bool is_ack(const struct can_frame *f)
{
	return f->id == watch.ack_id && (f->data[0] & 0xE3U) == 0xA2U;
}

/* Runs in the bus thread at the end of every frame. */
static void spy_rx(const struct device *dev, struct can_frame *f, void *user_data)
{
	const bool ack = is_ack(f);
	/* A segment: the data direction, not an initiate/end command (bit 7 = c only). */
	const bool seg = f->id != watch.ack_id && !ack;
	const uint16_t bits = (uint16_t)can_virtual_frame_bits(f);

	if (!watch.on) {
		return;
	}
	if (watch.have_last) {
		/* Bus time is 1 µs per bit at 1 Mbit/s. */
		uint16_t gap =
			(uint16_t)(f->timestamp - watch.last_end - bits * (1000000U / BITRATE));
		enum gap_kind k = ack                         ? GAP_BEFORE_ACK
				  : watch.last_was_ack && seg ? GAP_AFTER_ACK
				  : watch.last_was_seg && seg ? GAP_IN_BLOCK
							      : GAP_OTHER;

		watch.idle_us[k] += gap;
		watch.gaps[k] += gap > 0U ? 1U : 0U;
		watch.max_us[k] = MAX(watch.max_us[k], gap);
		if (gap >= STALL_US) {
			watch.stall_us += gap;
			watch.stalls++;
		}
	}
	watch.have_last = true;
	watch.last_end = f->timestamp;
	watch.last_was_ack = ack;
	watch.last_was_seg = seg;
}

static void watch_start(bool down)
{
	memset(&watch, 0, sizeof(watch));
	watch.ack_id = down ? 0x580U + SRV_ID : 0x600U + SRV_ID;
	watch.on = true;
}

/* --- Runs ----------------------------------------------------------------------------------- */

struct run {
	uint64_t us;
	uint32_t bus_frames;
	uint64_t bus_busy_us;
	uint32_t tx_retries;
	uint64_t idle_us[GAP_KINDS];
	uint32_t max_us[GAP_KINDS];
	uint64_t stall_us;
	uint32_t stalls;
};

static bool transfer(struct co_sdo_cli *cli, bool down, struct run *r)
{
	struct can_virtual_bus_stats s0, s1;
	struct co_sdo_cli_stats c0, c1;
	uint32_t code = 0;
	size_t len = 0;
	uint64_t t0, t1;
	int rc;

	co_sdo_cli_get_stats(cli, &c0);
	(void)can_virtual_bus_get_stats(0, &s0);
	watch_start(down);
	t0 = can_virtual_time_us();
	if (down) {
		rc = co_sdo_cli_download(cli, DOM_IDX, 0, out, SIZE, CO_SDO_CLI_BLOCK,
					 K_SECONDS(60), &code);
	} else {
		rc = co_sdo_cli_upload(cli, DOM_IDX, 0, in, SIZE, &len, CO_SDO_CLI_BLOCK,
				       K_SECONDS(60), &code);
	}
	t1 = can_virtual_time_us();
	k_msleep(2); /* the last frame off the bus and seen by the spy */
	watch.on = false;
	(void)can_virtual_bus_get_stats(0, &s1);
	co_sdo_cli_get_stats(cli, &c1);
	if (rc != 0 || code != 0U) {
		printf("sdo_bench: %s failed: %d, abort code %08x\n", down ? "download" : "upload",
		       rc, code);
		return false;
	}
	if (down ? (dom_len != SIZE || memcmp(dom, out, SIZE) != 0)
		 : (len != SIZE || memcmp(in, out, SIZE) != 0)) {
		printf("sdo_bench: %s delivered other data\n", down ? "download" : "upload");
		return false;
	}
	r->us = t1 - t0;
	r->bus_frames = s1.frames - s0.frames;
	r->bus_busy_us = (s1.busy_ns - s0.busy_ns) / 1000U;
	r->tx_retries = c1.tx_retries - c0.tx_retries;
	memcpy(r->idle_us, watch.idle_us, sizeof(r->idle_us));
	memcpy(r->max_us, watch.max_us, sizeof(r->max_us));
	r->stall_us = watch.stall_us;
	r->stalls = watch.stalls;
	return true;
}

static void report(const char *name, const struct bound *b, const struct run *best,
		   const struct run *worst, uint8_t blksize)
{
	const double bound_us = (double)b->bits * (1e6 / BITRATE);

	printf("BENCH {\"name\": \"%s\", \"bytes\": %u, \"blksize\": %u, \"rounds\": %d, "
	       "\"ms\": %.1f, \"bytes_per_s\": %.0f, \"bound_ms\": %.1f, "
	       "\"bound_bytes_per_s\": %.0f, \"efficiency_pct\": %.2f, "
	       "\"efficiency_worst_round_pct\": %.2f, \"frames\": %u, \"bits\": %llu, "
	       "\"bound_no_stuff_ms\": %.1f, \"bound_worst_stuff_ms\": %.1f, "
	       "\"bus_frames\": %u, \"bus_busy_ms\": %.1f, \"tx_retries\": %u, "
	       "\"idle_before_ack_ms\": %.2f, \"idle_after_ack_ms\": %.2f, "
	       "\"idle_in_block_ms\": %.2f, \"idle_other_ms\": %.2f, "
	       "\"max_gap_before_ack_us\": %u, \"max_gap_after_ack_us\": %u, "
	       "\"max_gap_in_block_us\": %u, \"stalls\": %u, \"stall_ms\": %.1f, "
	       "\"efficiency_no_stall_pct\": %.2f, \"bitrate\": %u}\n",
	       name, SIZE, blksize, ROUNDS, best->us / 1e3, SIZE * 1e6 / (double)best->us,
	       bound_us / 1e3, SIZE * 1e6 / bound_us, 100.0 * bound_us / (double)best->us,
	       100.0 * bound_us / (double)worst->us, b->frames, (unsigned long long)b->bits,
	       b->frames * (double)BITS_NO_STUFF / 1e3, b->frames * (double)BITS_WORST_STUFF / 1e3,
	       best->bus_frames, best->bus_busy_us / 1e3, best->tx_retries,
	       best->idle_us[GAP_BEFORE_ACK] / 1e3, best->idle_us[GAP_AFTER_ACK] / 1e3,
	       best->idle_us[GAP_IN_BLOCK] / 1e3, best->idle_us[GAP_OTHER] / 1e3,
	       best->max_us[GAP_BEFORE_ACK], best->max_us[GAP_AFTER_ACK],
	       best->max_us[GAP_IN_BLOCK], best->stalls, best->stall_us / 1e3,
	       100.0 * bound_us / (double)(best->us - best->stall_us), BITRATE);
}

int main(void)
{
	struct co_sdo_cli *cli;
	struct run best[2] = {0}, worst[2] = {0};
	uint32_t seed = 1U;
	struct bound bd, bu;

	for (uint32_t i = 0; i < SIZE; i++) {
		seed = seed * 1103515245U + 12345U;
		out[i] = (uint8_t)(seed >> 16);
	}
	if (co_line_init(&line_a, "cli", device_get_binding("can_virtual0")) != 0 ||
	    co_line_init(&line_b, "srv", device_get_binding("can_virtual1")) != 0 ||
	    co_line_start(&line_a, line_stacks[0], K_THREAD_STACK_SIZEOF(line_stacks[0]),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_line_start(&line_b, line_stacks[1], K_THREAD_STACK_SIZEOF(line_stacks[1]),
			  CONFIG_CANOPEN_LINE_THREAD_PRIORITY) != 0 ||
	    co_node_init(&cnode, "cli", &line_a, &sdo_cli_test_od_def, &cram, CLI_ID) != 0 ||
	    co_node_init(&snode, "srv", &line_b, &sdo_cli_test_od_def, &sram, SRV_ID) != 0) {
		printf("sdo_bench: setup failed\n");
		return 1;
	}
	co_node_lock(&snode);
	if (co_od_provider_register(co_node_od(&snode), &prov) != 0) {
		printf("sdo_bench: provider refused\n");
		return 1;
	}
	co_node_unlock(&snode);
	cli = co_sdo_cli_get(&cnode, 0);
	if (co_node_start(&snode) != 0 || co_node_start(&cnode) != 0 ||
	    co_sdo_cli_set_server(cli, SRV_ID) != 0) {
		printf("sdo_bench: start failed\n");
		return 1;
	}
	spy = device_get_binding("can_virtual2");
	if (spy == NULL || can_start(spy) != 0 ||
	    can_add_rx_filter(spy, spy_rx, NULL, &(struct can_filter){.id = 0, .mask = 0}) < 0) {
		printf("sdo_bench: the listening controller failed\n");
		return 1;
	}
	k_msleep(20); /* boot-up frames out of the way */

	for (int r = 0; r < ROUNDS; r++) {
		for (int dir = 0; dir < 2; dir++) {
			struct run x;

			if (!transfer(cli, dir == 0, &x)) {
				return 1;
			}
			if (r == 0 || x.us < best[dir].us) {
				best[dir] = x;
			}
			if (r == 0 || x.us > worst[dir].us) {
				worst[dir] = x;
			}
		}
		memset(in, 0, sizeof(in));
	}
	bd = bound_download(out, SIZE, CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE);
	bu = bound_upload(out, SIZE, CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE,
			  CONFIG_CANOPEN_SDO_CLIENT_PST);
	report("sdo.block_download", &bd, &best[0], &worst[0],
	       CONFIG_CANOPEN_SDO_BLOCK_MAX_BLKSIZE);
	report("sdo.block_upload", &bu, &best[1], &worst[1], CONFIG_CANOPEN_SDO_CLIENT_BLKSIZE);
	printf("sdo_bench: done\n");
	return 0;
}
