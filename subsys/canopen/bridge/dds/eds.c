/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What the bridge needs of a node's EDS or DCF (CiA 306): data type, access type and name of
 * each sub-index, so that clients can type the values they read and write, and the product
 * name. Sections [XXXX] and [XXXXsubY]; an object without sub-index sections is sub-index 0;
 * an ARRAY with CompactSubObj=N has sub-index 0 (UNSIGNED8, ro) and 1..N of its type.
 */

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <zephyr/logging/log.h>

#include "bridge_internal.h"

LOG_MODULE_DECLARE(canopen_bridge_dds, CONFIG_CANOPEN_LOG_LEVEL);

#define DTYPE_UNSIGNED8 0x0005U
#define NO_ACCESS       0xFFU

/* One [XXXX] or [XXXXsubY] section, as read. */
struct section {
	uint16_t index;
	int16_t sub; /* -1: the object itself */
	uint16_t dtype;
	uint8_t access;
	uint8_t objtype;
	uint8_t compact;
	bool has_subs;
	char name[64];
};

struct list {
	struct section *v;
	size_t n;
	size_t cap;
};

static struct section *list_add(struct list *l)
{
	if (l->n == l->cap) {
		size_t cap = l->cap != 0U ? l->cap * 2U : 64U;
		struct section *v = realloc(l->v, cap * sizeof(*v));

		if (v == NULL) {
			return NULL;
		}
		l->v = v;
		l->cap = cap;
	}
	(void)memset(&l->v[l->n], 0, sizeof(l->v[0]));
	return &l->v[l->n++];
}

static char *trim(char *s)
{
	char *e;

	while (isspace((unsigned char)*s) != 0) {
		s++;
	}
	e = s + strlen(s);
	while (e > s && isspace((unsigned char)e[-1])) {
		*--e = '\0';
	}
	return s;
}

static bool parse_num(const char *s, unsigned long *v)
{
	char *end;

	if (*s == '\0') {
		return false;
	}
	*v = strtoul(s, &end, 0);
	return *trim(end) == '\0';
}

static uint8_t parse_access(const char *s)
{
	static const char *const names[] = {"ro", "wo", "rw", "rwr", "rww", "const"};

	for (size_t i = 0; i < ARRAY_SIZE(names); i++) {
		if (strcasecmp(s, names[i]) == 0) {
			return (uint8_t)i;
		}
	}
	return NO_ACCESS;
}

/* "[1018]" -> index, sub -1; "[1018sub2]" -> index, 2; else false. */
static bool parse_section(const char *s, uint16_t *index, int16_t *sub)
{
	char hex[5];
	char *end;
	unsigned long v;

	if (strlen(s) < 4U) {
		return false;
	}
	for (int i = 0; i < 4; i++) {
		if (!isxdigit((unsigned char)s[i])) {
			return false;
		}
		hex[i] = s[i];
	}
	hex[4] = '\0';
	*index = (uint16_t)strtoul(hex, NULL, 16);
	if (s[4] == '\0') {
		*sub = -1;
		return true;
	}
	if (strncasecmp(&s[4], "sub", 3) != 0 || s[7] == '\0') {
		return false;
	}
	v = strtoul(&s[7], &end, 16);
	if (*end != '\0' || v > 255U) {
		return false;
	}
	*sub = (int16_t)v;
	return true;
}

static int cmp_entry(const void *a, const void *b)
{
	const struct br_eds_entry *x = a;
	const struct br_eds_entry *y = b;
	uint32_t kx = ((uint32_t)x->index << 8) | x->sub;
	uint32_t ky = ((uint32_t)y->index << 8) | y->sub;

	return (kx > ky) - (kx < ky);
}

static int add_entry(struct br_eds *eds, size_t *cap, uint16_t index, uint8_t sub, uint16_t dtype,
		     uint8_t access, const char *name)
{
	struct br_eds_entry *e;

	if (eds->n == *cap) {
		size_t ncap = *cap != 0U ? *cap * 2U : 128U;
		struct br_eds_entry *v = realloc(eds->entries, ncap * sizeof(*v));

		if (v == NULL) {
			return -ENOMEM;
		}
		eds->entries = v;
		*cap = ncap;
	}
	e = &eds->entries[eds->n++];
	e->index = index;
	e->sub = sub;
	e->dtype = dtype;
	e->access = access;
	(void)snprintf(e->name, sizeof(e->name), "%s", name);
	return 0;
}

static int build(struct br_eds *eds, struct list *objs, struct list *subs)
{
	size_t cap = 0;
	int err = 0;

	for (size_t i = 0; i < subs->n && err == 0; i++) {
		const struct section *s = &subs->v[i];

		err = add_entry(eds, &cap, s->index, (uint8_t)s->sub, s->dtype, s->access, s->name);
		for (size_t k = 0; k < objs->n; k++) {
			if (objs->v[k].index == s->index) {
				objs->v[k].has_subs = true;
			}
		}
	}
	for (size_t i = 0; i < objs->n && err == 0; i++) {
		const struct section *o = &objs->v[i];

		if (o->has_subs) {
			continue;
		}
		if (o->compact != 0U) {
			char name[64];

			err = add_entry(eds, &cap, o->index, 0U, DTYPE_UNSIGNED8, 0U,
					"Highest sub-index supported");
			for (unsigned int s = 1; s <= o->compact && err == 0; s++) {
				(void)snprintf(name, sizeof(name), "%.56s %u", o->name, s);
				err = add_entry(eds, &cap, o->index, (uint8_t)s, o->dtype,
						o->access, name);
			}
		} else if (o->dtype != 0U) {
			err = add_entry(eds, &cap, o->index, 0U, o->dtype, o->access, o->name);
		} else {
			/* A plain VAR without a data type has nothing to list. */
		}
	}
	if (err == 0 && eds->n > 1U) {
		qsort(eds->entries, eds->n, sizeof(eds->entries[0]), cmp_entry);
	}
	return err;
}

int br_eds_load(const char *path, struct br_eds *eds)
{
	struct list objs = {0};
	struct list subs = {0};
	struct section *cur = NULL;
	bool device_info = false;
	char line[512];
	int lineno = 0;
	int err = 0;
	FILE *f;

	(void)memset(eds, 0, sizeof(*eds));
	(void)snprintf(eds->path, sizeof(eds->path), "%s", path);
	f = fopen(path, "r");
	if (f == NULL) {
		LOG_ERR("%s: cannot read the EDS (%s)", path, strerror(errno));
		return -ENOENT;
	}
	while (err == 0 && fgets(line, sizeof(line), f) != NULL) {
		char *s = trim(line);
		char *eq;
		unsigned long v;

		lineno++;
		if (*s == '\0' || *s == ';' || *s == '#') {
			continue;
		}
		if (*s == '[') {
			char *close = strchr(s, ']');
			uint16_t index;
			int16_t sub;

			cur = NULL;
			device_info = false;
			if (close == NULL) {
				LOG_ERR("%s:%d: section without ']'", path, lineno);
				err = -EINVAL;
				break;
			}
			*close = '\0';
			s = trim(s + 1);
			if (strcasecmp(s, "DeviceInfo") == 0) {
				device_info = true;
			} else if (parse_section(s, &index, &sub)) {
				cur = list_add(sub < 0 ? &objs : &subs);
				if (cur == NULL) {
					err = -ENOMEM;
					break;
				}
				cur->index = index;
				cur->sub = sub;
				cur->access = NO_ACCESS;
			} else {
				/* Another section ([FileInfo], comments ...): its keys are skipped.
				 */
			}
			continue;
		}
		eq = strchr(s, '=');
		if (eq == NULL) {
			continue;
		}
		*eq = '\0';
		s = trim(s);
		eq = trim(eq + 1);
		if (device_info) {
			if (strcasecmp(s, "ProductName") == 0) {
				(void)snprintf(eds->product, sizeof(eds->product), "%s", eq);
			}
			continue;
		}
		if (cur == NULL) {
			continue;
		}
		if (strcasecmp(s, "ParameterName") == 0) {
			(void)snprintf(cur->name, sizeof(cur->name), "%s", eq);
		} else if (strcasecmp(s, "AccessType") == 0) {
			cur->access = parse_access(eq);
		} else if (strcasecmp(s, "DataType") == 0 && parse_num(eq, &v) && v <= 0xFFFFU) {
			cur->dtype = (uint16_t)v;
		} else if (strcasecmp(s, "ObjectType") == 0 && parse_num(eq, &v) && v <= 0xFFU) {
			cur->objtype = (uint8_t)v;
		} else if (strcasecmp(s, "CompactSubObj") == 0 && parse_num(eq, &v) && v <= 254U) {
			cur->compact = (uint8_t)v;
		} else {
			/* Other keys, or a value out of range, are not used by the bridge. */
		}
	}
	(void)fclose(f);
	if (err == 0) {
		err = build(eds, &objs, &subs);
	}
	free(objs.v);
	free(subs.v);
	if (err == 0 && eds->n == 0U) {
		LOG_ERR("%s: no objects in the EDS", path);
		err = -EINVAL;
	}
	if (err != 0) {
		br_eds_free(eds);
	}
	return err;
}

void br_eds_free(struct br_eds *eds)
{
	free(eds->entries);
	eds->entries = NULL;
	eds->n = 0;
}

const struct br_eds_entry *br_eds_find(const struct br_eds *eds, uint16_t index, uint8_t sub)
{
	struct br_eds_entry key = {.index = index, .sub = sub};

	if (eds == NULL || eds->n == 0U) {
		return NULL;
	}
	return bsearch(&key, eds->entries, eds->n, sizeof(key), cmp_entry);
}
