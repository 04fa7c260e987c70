/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Chunked writes (segmented and block SDO, streamed domains): chunks are staged and the
 * value is checked, validated and committed with the last one (od_access.c).
 */

#include <string.h>

#include "od_internal.h"

static bool streaming(const struct co_od_xfer *x)
{
	return INFO_PROV(&x->info) != NULL && (x->info.flags & CO_OD_F_STREAM);
}

static void xfer_end(struct co_od *od, struct co_od_xfer *x)
{
	if (od->scratch_owner == x) {
		od->scratch_owner = NULL;
	}
	x->scratch = false;
	x->active = false;
}

uint32_t co_od_write_begin(struct co_od *od, struct co_od_xfer *x, uint16_t index, uint8_t sub,
			   uint32_t total, enum co_od_writer writer)
{
	uint32_t ab;

	OD_ASSERT_LOCKED(od);
	/* A transfer restarted without an abort gives its staging buffer back first. */
	xfer_end(od, x);
	memset(x, 0, sizeof(*x));
	ab = co_od_find(od, index, sub, &x->info);
	if (ab == 0U) {
		ab = co_od_check_access(&x->info, writer);
	}
	if (ab != 0U) {
		return ab;
	}
	x->writer = writer;
	x->total = total;
	if (!streaming(x)) {
		if (total > x->info.size) {
			return CO_SDO_AB_DATA_LONG;
		}
		if (total != 0U && co_od_check_size(&x->info, total) != 0U) {
			return co_od_check_size(&x->info, total);
		}
		if (x->info.size > sizeof(x->small)) {
			if (x->info.size > CO_OD_SCRATCH_SIZE) {
				return CO_SDO_AB_OUT_OF_MEM;
			}
			if (od->scratch_owner != NULL) {
				return CO_SDO_AB_OUT_OF_MEM;
			}
			od->scratch_owner = x;
			x->scratch = true;
		}
	}
	x->active = true;
	return 0;
}

uint32_t co_od_write_chunk(struct co_od *od, struct co_od_xfer *x, uint32_t offset,
			   const void *data, size_t len, bool last)
{
	uint32_t ab = 0;

	OD_ASSERT_LOCKED(od);
	if (!x->active || offset != x->offset) {
		xfer_end(od, x);
		return CO_SDO_AB_GENERAL;
	}
	if (streaming(x)) {
		ab = x->info.prov->api->write(x->info.prov, &x->info, offset, data, len, last);
		x->offset += (uint32_t)len;
		if (ab == 0U && last) {
			struct co_od_req req = {
				.info = &x->info, .writer = x->writer, .data = data, .len = len};

			ab = co_od_run_validate(od, &req);
			if (ab == 0U || ab == CO_OD_HANDLED) {
				ab = 0U;
				co_od_run_notify(od, &req);
			}
		}
		if (ab != 0U || last) {
			xfer_end(od, x);
		}
		return ab;
	}
	if ((uint64_t)offset + len > x->info.size) {
		xfer_end(od, x);
		return CO_SDO_AB_DATA_LONG;
	}
	uint8_t *stage = x->scratch ? od->scratch : x->small;

	memcpy(stage + offset, data, len);
	x->offset += (uint32_t)len;
	if (last) {
		if (x->total != 0U && x->offset != x->total) {
			ab = x->offset < x->total ? CO_SDO_AB_DATA_SHORT : CO_SDO_AB_DATA_LONG;
		} else {
			ab = co_od_finish_write(od, &x->info, stage, x->offset, x->writer);
		}
		xfer_end(od, x);
	}
	return ab;
}

void co_od_write_abort(struct co_od *od, struct co_od_xfer *x)
{
	if (x->active && streaming(x)) {
		/* Tell a streaming provider the transfer is over (zero-length last chunk). */
		(void)x->info.prov->api->write(x->info.prov, &x->info, x->offset, NULL, 0, true);
	}
	xfer_end(od, x);
}
