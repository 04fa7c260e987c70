/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Object dictionary hooks: registration, and the validate, notify and read-check passes of
 * one object.
 *
 * A hook is resolved to the objects it covers when it is registered: each dictionary entry
 * in its index range gets a link to it, appended to the entry's list (headed in the node's
 * RAM block), so an entry's list is in registration order and an access walks the hooks of
 * its own entry only, checking their sub-index ranges. An object with no hook costs one
 * load. Objects of providers outside the dictionary have no entry: their passes walk the
 * hook table and test each hook's ranges (providers are rare and serve few indexes).
 *
 * Removing hooks rebuilds every list from the table, which stays in registration order; it
 * happens when a service reconfigures, never per access.
 */

#include <errno.h>
#include <string.h>

#include "od_internal.h"

/* The walk inlined in each pass when optimising for speed; one copy in a size build (-Os). */
#if defined(__OPTIMIZE_SIZE__)
#define WALK_INLINE
#else
#define WALK_INLINE inline __attribute__((always_inline))
#endif

static void hook_gen_bump(struct co_od *od)
{
	od->hook_gen++;
	/* Never 0: a PDO that resolved nothing yet holds 0. */
	if (od->hook_gen == 0U) {
		od->hook_gen = 1U;
	}
}

/* Position of the first entry whose index is at least @p index. */
static uint16_t entry_lower(const struct co_od_def *def, uint32_t index)
{
	uint16_t lo = 0U;
	uint16_t hi = def->n_entries;

	while (lo < hi) {
		uint16_t mid = lo + (hi - lo) / 2U;

		if (def->entries[mid].index < index) {
			lo = mid + 1U;
		} else {
			hi = mid;
		}
	}
	return lo;
}

/* Links a hook needs: one per entry in its index range. */
static uint16_t links_needed(const struct co_od *od, const struct co_od_hook *hook)
{
	return entry_lower(od->def, (uint32_t)hook->index_last + 1U) -
	       entry_lower(od->def, hook->index_first);
}

/* Append a link to hook @p pos at the end of each covered entry's list. */
static void hook_link(struct co_od *od, uint16_t pos)
{
	const struct co_od_hook *hook = &od->hooks[pos].hook;
	uint16_t end = entry_lower(od->def, (uint32_t)hook->index_last + 1U);

	for (uint16_t e = entry_lower(od->def, hook->index_first); e < end; e++) {
		uint16_t *next = &od->hook_heads[e];

		while (*next != 0U) {
			next = &od->links[*next - 1U].next;
		}
		od->links[od->n_links] = (struct co_od_hook_link){.hook = pos, .next = 0U};
		od->n_links++;
		*next = od->n_links;
	}
}

/*
 * Remove the hooks of a failed batch (registration number @p first_seq on) or those
 * registered with @p user_data, keeping the others in order, and rebuild the links.
 * Returns how many were removed.
 */
static int hooks_remove(struct co_od *od, bool batch, uint32_t first_seq, const void *user_data)
{
	uint16_t w = 0U;
	int removed = 0;

	for (uint16_t r = 0U; r < od->n_hooks; r++) {
		const struct co_od_hook_ent *h = &od->hooks[r];

		if (batch ? h->seq >= first_seq : h->hook.user_data == user_data) {
			removed++;
			continue;
		}
		od->hooks[w++] = *h;
	}
	if (removed == 0) {
		return 0;
	}
	od->n_hooks = w;
	od->n_links = 0U;
	memset(od->hook_heads, 0, (size_t)od->def->n_entries * sizeof(uint16_t));
	for (uint16_t pos = 0U; pos < od->n_hooks; pos++) {
		hook_link(od, pos);
	}
	hook_gen_bump(od);
	return removed;
}

int co_od_hook_register(struct co_od *od, const struct co_od_hook *hook)
{
	if (od == NULL || hook == NULL || hook->index_last < hook->index_first ||
	    hook->sub_last < hook->sub_first || (hook->validate == NULL && hook->notify == NULL)) {
		return -EINVAL;
	}
	OD_ASSERT_LOCKED(od);
	if (od->n_hooks >= CO_OD_HOOKS_MAX ||
	    (uint32_t)od->n_links + links_needed(od, hook) > CO_OD_HOOK_LINKS) {
		return -ENOSPC;
	}
	uint16_t pos = od->n_hooks++;

	od->hooks[pos] = (struct co_od_hook_ent){.hook = *hook, .seq = od->hook_next_seq++};
	hook_link(od, pos);
	hook_gen_bump(od);
	return 0;
}

int co_od_hooks_register(struct co_od *od, const struct co_od_hook *hooks, size_t n)
{
	if (od == NULL) {
		return -EINVAL;
	}
	OD_ASSERT_LOCKED(od);
	uint32_t first = od->hook_next_seq;

	for (size_t i = 0; i < n; i++) {
		int err = co_od_hook_register(od, &hooks[i]);

		if (err != 0) {
			/* All or nothing: a service never runs with half of its hooks. */
			(void)hooks_remove(od, true, first, NULL);
			return err;
		}
	}
	return 0;
}

int co_od_hook_unregister(struct co_od *od, const void *user_data)
{
	OD_ASSERT_LOCKED(od);
	return hooks_remove(od, false, 0U, user_data);
}

/*
 * The hooks of one object, in registration order. A hook may register or unregister hooks
 * (the PDO service re-hooks its mapped objects when a mapping is written), which rebuilds
 * the lists under the walk: the walk then starts its object's list again and skips what it
 * already passed by registration number. Only hooks registered before the walk began take
 * part, so every hook present throughout runs exactly once, a removed one no more.
 */
struct hook_walk {
	const struct co_od *od;
	uint16_t entry;     /* the object's entry, CO_OD_NO_ENTRY: a provider's object */
	uint16_t index;     /* the object */
	uint8_t sub;        /* the object's sub-index */
	uint16_t next;      /* next link number (entry) or table position + 1 (provider) */
	uint32_t gen;       /* co_od.hook_gen that next belongs to */
	uint32_t last_seq;  /* registration number of the last hook returned */
	uint32_t limit_seq; /* first registration number after the walk began */
};

static WALK_INLINE uint16_t walk_start(const struct hook_walk *w)
{
	if (!CO_OD_PROVIDERS || w->entry != CO_OD_NO_ENTRY) {
		return w->od->hook_heads[w->entry];
	}
	return w->od->n_hooks > 0U ? 1U : 0U;
}

static WALK_INLINE void walk_init(struct hook_walk *w, const struct co_od *od,
				  const struct co_od_info *info)
{
	w->od = od;
	w->entry = info->entry;
	w->index = info->index;
	w->sub = info->sub;
	w->gen = od->hook_gen;
	w->last_seq = 0U;
	w->limit_seq = od->hook_next_seq;
	w->next = walk_start(w);
}

static WALK_INLINE const struct co_od_hook_ent *walk_next(struct hook_walk *w)
{
	const struct co_od *od = w->od;

	if (OD_UNLIKELY(w->gen != od->hook_gen)) {
		w->gen = od->hook_gen;
		w->next = walk_start(w);
	}
	while (w->next != 0U) {
		const struct co_od_hook_ent *h;

		if (!CO_OD_PROVIDERS || w->entry != CO_OD_NO_ENTRY) {
			const struct co_od_hook_link *l = &od->links[w->next - 1U];

			h = &od->hooks[l->hook];
			w->next = l->next;
			/* The entry's hooks cover its index: only the sub-index is tested. */
		} else {
			h = &od->hooks[w->next - 1U];
			w->next = w->next < od->n_hooks ? w->next + 1U : 0U;
			if (w->index < h->hook.index_first || w->index > h->hook.index_last) {
				continue;
			}
		}
		if (w->sub < h->hook.sub_first || w->sub > h->hook.sub_last ||
		    h->seq <= w->last_seq || h->seq >= w->limit_seq) {
			continue;
		}
		w->last_seq = h->seq;
		return h;
	}
	return NULL;
}

uint32_t co_od_run_validate(struct co_od *od, const struct co_od_req *req)
{
	struct hook_walk w;
	uint32_t result = 0U;
	const struct co_od_hook_ent *h;

	walk_init(&w, od, req->info);
	while ((h = walk_next(&w)) != NULL) {
		if (h->hook.validate == NULL) {
			continue;
		}
		/* Each hook gets its own copy of the request. */
		struct co_od_req copy = *req;
		uint32_t r = h->hook.validate(od, &copy, h->hook.user_data);

		if (r == CO_OD_HANDLED) {
			result = CO_OD_HANDLED;
		} else if (r != 0U) {
			return r;
		}
	}
	return result;
}

void co_od_run_notify(struct co_od *od, const struct co_od_req *req)
{
	struct hook_walk w;
	const struct co_od_hook_ent *h;

	walk_init(&w, od, req->info);
	while ((h = walk_next(&w)) != NULL) {
		if (h->hook.notify != NULL) {
			h->hook.notify(od, req, h->hook.user_data);
		}
	}
}

void co_od_notify(struct co_od *od, const struct co_od_info *info, const void *data, size_t len,
		  enum co_od_writer writer)
{
	const struct co_od_req req = {.info = info, .writer = writer, .data = data, .len = len};

	co_od_run_notify(od, &req);
}

uint32_t co_od_run_read_check(const struct co_od *od, const struct co_od_info *info,
			      enum co_od_writer reader)
{
	struct hook_walk w;
	const struct co_od_hook_ent *h;

	if (reader == CO_OD_WRITER_APP || reader == CO_OD_WRITER_STORAGE) {
		return 0U;
	}
	walk_init(&w, od, info);
	while ((h = walk_next(&w)) != NULL) {
		if (h->hook.read_check == NULL) {
			continue;
		}
		uint32_t r = h->hook.read_check(od, info, reader, h->hook.user_data);

		if (r != 0U) {
			return r;
		}
	}
	return 0U;
}

unsigned int co_od_hooks_has(const struct co_od *od, const struct co_od_info *info)
{
	struct hook_walk w;
	const struct co_od_hook_ent *h;
	unsigned int has = 0U;

	walk_init(&w, od, info);
	while ((h = walk_next(&w)) != NULL) {
		has |= (h->hook.validate != NULL ? CO_OD_HAS_VALIDATE : 0U) |
		       (h->hook.notify != NULL ? CO_OD_HAS_NOTIFY : 0U) |
		       (h->hook.read_check != NULL ? CO_OD_HAS_READ_CHECK : 0U);
	}
	return has;
}

int co_od_notify_only(const struct co_od *od, const struct co_od_info *info)
{
	struct hook_walk w;
	const struct co_od_hook_ent *h;
	const struct co_od_hook_ent *only = NULL;

	walk_init(&w, od, info);
	while ((h = walk_next(&w)) != NULL) {
		if (only != NULL || h->hook.validate != NULL || h->hook.read_check != NULL) {
			return -1;
		}
		only = h;
	}
	return only != NULL ? (int)(only - od->hooks) : -1;
}
