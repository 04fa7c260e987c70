/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Object dictionary lookup: an index by binary search over the generated entries, then its
 * sub-index; indexes the dictionary does not hold go to the object providers.
 */

#include <errno.h>
#include <string.h>

#include "od_internal.h"

const struct co_od_entry *co_od_entry_find(const struct co_od_def *def, uint16_t index)
{
	size_t lo = 0;
	size_t hi = def->n_entries;

	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2U;
		uint16_t v = def->entries[mid].index;

		if (v == index) {
			return &def->entries[mid];
		}
		if (v < index) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return NULL;
}

static const struct co_od_sub *sub_find(const struct co_od_def *def, const struct co_od_entry *e,
					uint8_t sub)
{
	const struct co_od_sub *subs = &def->subs[e->first];

	/* Sub-indexes are usually dense: try the direct position first. */
	if (sub < e->n_subs && subs[sub].sub == sub) {
		return &subs[sub];
	}
	size_t lo = 0;
	size_t hi = e->n_subs;

	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2U;

		if (subs[mid].sub == sub) {
			return &subs[mid];
		}
		if (subs[mid].sub < sub) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return NULL;
}

int co_od_provider_register(struct co_od *od, const struct co_od_provider *p)
{
	if (od == NULL || p == NULL || p->api == NULL || p->api->info == NULL ||
	    p->api->read == NULL || p->api->write == NULL || p->index_last < p->index_first) {
		return -EINVAL;
	}
#if CO_OD_PROVIDERS
	for (uint8_t i = 0; i < od->n_prov; i++) {
		if (p->index_first <= od->prov[i]->index_last &&
		    od->prov[i]->index_first <= p->index_last) {
			return -EEXIST;
		}
	}
	if (od->n_prov >= CO_OD_PROVIDERS_MAX) {
		return -ENOSPC;
	}
	od->prov[od->n_prov++] = p;
	return 0;
#else
	return -ENOTSUP;
#endif
}

const struct co_od_provider *co_od_provider_of(const struct co_od *od, uint16_t index)
{
#if CO_OD_PROVIDERS
	for (uint8_t i = 0; i < od->n_prov; i++) {
		if (index >= od->prov[i]->index_first && index <= od->prov[i]->index_last) {
			return od->prov[i];
		}
	}
#endif
	return NULL;
}

static uint32_t provider_info(const struct co_od_provider *p, uint16_t index, uint8_t sub,
			      struct co_od_info *info)
{
	memset(info, 0, sizeof(*info));
	info->prov = p;
	info->index = index;
	info->sub = sub;
	info->objcode = CO_OD_OBJ_VAR;
	uint32_t ab = p->api->info(p, info);

	/* Set after the provider's answer, which describes the value only. */
	info->entry = CO_OD_NO_ENTRY;
	return ab;
}

uint32_t co_od_find(const struct co_od *od, uint16_t index, uint8_t sub, struct co_od_info *info)
{
	const struct co_od_def *def = od->def;
	const struct co_od_entry *e = co_od_entry_find(def, index);

	if (e == NULL) {
		const struct co_od_provider *p = co_od_provider_of(od, index);

		return p != NULL ? provider_info(p, index, sub, info) : CO_SDO_AB_NO_OBJECT;
	}
	const struct co_od_sub *desc = sub_find(def, e, sub);

	if (desc == NULL) {
		return CO_SDO_AB_NO_SUB;
	}
	uint16_t pos = (uint16_t)(e - def->entries);

	if (!co_od_has_storage(desc)) {
		/* A DOMAIN without RAM is served by the provider of its index, if any. */
		const struct co_od_provider *p = co_od_provider_of(od, index);

		if (p != NULL && provider_info(p, index, sub, info) == 0U) {
			info->objcode = e->objcode;
			/* Its hooks are the entry's. */
			info->entry = pos;
			return 0;
		}
	}
#if defined(__OPTIMIZE_SIZE__)
	/* One copy, shared with the PDO mapping entries, which rebuild their objects' info. */
	co_od_info_fill(od, pos, desc, info);
#else
	co_od_info_fill_inline(od, pos, desc, info);
#endif
	return 0;
}

void co_od_info_fill(const struct co_od *od, uint16_t entry, const struct co_od_sub *desc,
		     struct co_od_info *info)
{
	co_od_info_fill_inline(od, entry, desc, info);
}

const void *co_od_value_ptr(const struct co_od *od, const struct co_od_info *info)
{
	if (info->desc == NULL || !co_od_has_storage(info->desc)) {
		return NULL;
	}
	return co_od_mem(od->def, od->ram, info->desc);
}

uint32_t co_od_length(const struct co_od *od, const struct co_od_info *info)
{
	if (INFO_PROV(info) != NULL) {
		return info->prov->api->length != NULL ? info->prov->api->length(info->prov, info)
						       : info->size;
	}
	return co_od_mem_length(info->desc, co_od_mem(od->def, od->ram, info->desc));
}

bool co_od_is_nodeid_default(const struct co_od *od, const struct co_od_info *info)
{
	if (info->desc == NULL || !(info->desc->flags & CO_OD_F_NODEID)) {
		return false;
	}
	const struct co_od_nodeid *n =
		co_od_nodeid_of(od->def, (uint32_t)(info->desc - od->def->subs));
	uint8_t wire[8];

	if (n == NULL) {
		return false;
	}
	co_od_encode_fixed(info->dtype, co_od_mem(od->def, od->ram, info->desc), wire);
	uint32_t size = co_dtype_size(info->dtype);
	uint64_t mask = size >= 8U ? UINT64_MAX : (((uint64_t)1 << (8U * size)) - 1U);
	uint64_t want = (uint64_t)(n->base + (int64_t)co_od_nid(od)) & mask;

	return co_od_le_get(wire, size) == want;
}
