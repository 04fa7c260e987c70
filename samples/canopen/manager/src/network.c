/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A small CiA 306 reader for the network objects of a manager DCF. It reads what a manager
 * needs and nothing else: values of the other objects are the bundled dictionary's. A line it
 * cannot read (a key outside a section, a malformed number, a value that needs $NODEID) is an
 * error with its file and line, never skipped.
 */

#include "network.h"

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <canopen/sdo_abort.h>

/* The network objects: arrays are replaced as a whole, variables only when the DCF has them. */
static const struct {
	uint16_t index;
	bool array;
} net_objects[] = {
	{0x1016, true},  {0x1017, false}, {0x102A, false}, {0x1F26, true}, {0x1F27, true},
	{0x1F80, false}, {0x1F81, true},  {0x1F84, true},  {0x1F85, true}, {0x1F86, true},
	{0x1F87, true},  {0x1F88, true},  {0x1F89, false},
};

#define N_OBJ     ARRAY_SIZE_(net_objects)
#define CDCF_OBJ  0x1F22U
#define MAX_LINE  512
#define MAX_FILE  256
#define MAX_BYTES (1024U * 1024U)

#define ARRAY_SIZE_(a) (sizeof(a) / sizeof((a)[0]))

struct rec {
	uint32_t param_line;
	uint32_t dflt_line;
	uint32_t param;
	uint32_t dflt;
};

/* Parser state (one load at a time: the sample loads once, before the boot). */
static struct {
	struct rec recs[N_OBJ][128];
	uint8_t compact[N_OBJ];
	uint32_t compact_line[N_OBJ];
	char file[128][MAX_FILE];
	uint32_t file_line[128];
} st;

static int fail(char *err, size_t errlen, const char *path, uint32_t line, const char *fmt, ...)
{
	va_list ap;
	int n = line != 0U ? snprintf(err, errlen, "%s:%u: ", path, line)
			   : snprintf(err, errlen, "%s: ", path);

	if (n > 0 && (size_t)n < errlen) {
		va_start(ap, fmt);
		(void)vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
		va_end(ap);
	}
	return -EINVAL;
}

static int obj_slot(uint16_t index)
{
	for (size_t i = 0; i < N_OBJ; i++) {
		if (net_objects[i].index == index) {
			return (int)i;
		}
	}
	return -1;
}

/* Whole string, decimal / 0x hex / 0 octal, no sign, fits 32 bits. */
static bool parse_u32(const char *s, uint32_t *out)
{
	unsigned long long v = 0;
	unsigned int base = 10;
	const char *p = s;

	if (*p == '\0') {
		return false;
	}
	if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
		base = 16;
		p += 2;
		if (*p == '\0') {
			return false;
		}
	} else if (p[0] == '0' && p[1] != '\0') {
		base = 8;
		p++;
	}
	for (; *p != '\0'; p++) {
		unsigned int d;

		if (isdigit((unsigned char)*p)) {
			d = (unsigned int)(*p - '0');
		} else if (isxdigit((unsigned char)*p)) {
			d = (unsigned int)(tolower((unsigned char)*p) - 'a' + 10);
		} else {
			return false;
		}
		if (d >= base) {
			return false;
		}
		v = v * base + d;
		if (v > UINT32_MAX) {
			return false;
		}
	}
	*out = (uint32_t)v;
	return true;
}

static char *trim(char *s)
{
	char *e;

	while (isspace((unsigned char)*s)) {
		s++;
	}
	e = s + strlen(s);
	while (e > s && isspace((unsigned char)e[-1])) {
		*--e = '\0';
	}
	return s;
}

/* "1F81" -> 0x1F81, "1F81sub3" -> sub 3, "1F81Value" -> kind 'v'. Returns kind or 0. */
static char section_kind(const char *name, uint16_t *index, uint8_t *sub)
{
	char hex[5];
	uint32_t v;

	if (strlen(name) < 4) {
		return 0;
	}
	memcpy(hex, name, 4);
	hex[4] = '\0';
	for (int i = 0; i < 4; i++) {
		if (!isxdigit((unsigned char)hex[i])) {
			return 0;
		}
	}
	*index = (uint16_t)strtoul(hex, NULL, 16);
	if (name[4] == '\0') {
		*sub = 0;
		return 'o';
	}
	if (strncasecmp(&name[4], "sub", 3) == 0 && name[7] != '\0' && strlen(&name[7]) <= 2) {
		char s[3] = {0};

		memcpy(s, &name[7], strlen(&name[7]));
		for (int i = 0; s[i] != '\0'; i++) {
			if (!isxdigit((unsigned char)s[i])) {
				return 0;
			}
		}
		v = (uint32_t)strtoul(s, NULL, 16);
		*sub = (uint8_t)v;
		return 's';
	}
	if (strcasecmp(&name[4], "Value") == 0) {
		return 'v';
	}
	return 0;
}

static int value_of(const char *path, uint32_t line, const char *v, uint32_t *out, char *err,
		    size_t errlen)
{
	if (strstr(v, "$NODEID") != NULL || strstr(v, "$nodeid") != NULL) {
		return fail(err, errlen, path, line,
			    "'%s': $NODEID values are not supported in the network objects", v);
	}
	if (*v == '\0') {
		*out = 0U; /* CiA 306: an empty value of a number is 0 */
		return 0;
	}
	if (!parse_u32(v, out)) {
		return fail(err, errlen, path, line, "'%s' is not an unsigned 32-bit number", v);
	}
	return 0;
}

/* A concise DCF: U32 count, then U16 index, U8 sub, U32 size, data; nothing after. */
static bool cdcf_valid(const uint8_t *p, size_t len)
{
	size_t off = 4;
	uint32_t n;

	if (len < 4) {
		return false;
	}
	n = (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
	    ((uint32_t)p[3] << 24);
	for (uint32_t i = 0; i < n; i++) {
		uint32_t size;

		if (len - off < 7) {
			return false;
		}
		size = (uint32_t)p[off + 3] | ((uint32_t)p[off + 4] << 8) |
		       ((uint32_t)p[off + 5] << 16) | ((uint32_t)p[off + 6] << 24);
		off += 7;
		if (size > len - off) {
			return false;
		}
		off += size;
	}
	return off == len;
}

static int load_cdcf(struct network *net, const char *dcf_path, uint8_t id, char *err,
		     size_t errlen)
{
	const char *name = st.file[id];
	uint32_t line = st.file_line[id];
	char full[2 * MAX_FILE];
	const char *slash = strrchr(dcf_path, '/');
	uint8_t *buf;
	long size;
	FILE *f;

	/* Relative to the DCF's folder, as lely's tools write them. */
	if (name[0] == '/' || slash == NULL) {
		(void)snprintf(full, sizeof(full), "%s", name);
	} else {
		(void)snprintf(full, sizeof(full), "%.*s/%s", (int)(slash - dcf_path), dcf_path,
			       name);
	}
	f = fopen(full, "rb");
	if (f == NULL) {
		return fail(err, errlen, dcf_path, line, "1F22h:%02X: cannot open %s: %s", id, full,
			    strerror(errno));
	}
	if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || size > (long)MAX_BYTES ||
	    fseek(f, 0, SEEK_SET) != 0) {
		fclose(f);
		return fail(err, errlen, dcf_path, line,
			    "1F22h:%02X: %s: unreadable or larger "
			    "than %u bytes",
			    id, full, MAX_BYTES);
	}
	buf = malloc(size > 0 ? (size_t)size : 1U);
	if (buf == NULL || fread(buf, 1, (size_t)size, f) != (size_t)size) {
		free(buf);
		fclose(f);
		return fail(err, errlen, dcf_path, line, "1F22h:%02X: cannot read %s", id, name);
	}
	fclose(f);
	if (size > 0 && (buf[0] == '[' || buf[0] == ';')) {
		free(buf);
		return fail(err, errlen, dcf_path, line,
			    "1F22h:%02X: %s is a DCF/EDS text; name its concise DCF instead "
			    "(scripts/dcf2cdcf FILE --node-id %u -o FILE.bin)",
			    id, name, id);
	}
	if (!cdcf_valid(buf, (size_t)size)) {
		free(buf);
		return fail(err, errlen, dcf_path, line,
			    "1F22h:%02X: %s is not a concise DCF (count, entries and length "
			    "disagree)",
			    id, name);
	}
	net->cdcf[id] = buf;
	net->cdcf_size[id] = (uint32_t)size;
	return 0;
}

static int parse_line(struct network *net, const char *path, uint32_t ln, char *line, char *section,
		      size_t seclen, char *err, size_t errlen)
{
	uint16_t index = 0;
	uint8_t sub = 0;
	char kind;
	char *eq, *key, *val;
	int slot;
	uint32_t v;

	if (line[0] == '[') {
		char *end = strchr(line, ']');

		if (end == NULL || end[1] != '\0' || end == line + 1) {
			return fail(err, errlen, path, ln, "malformed section header '%s'", line);
		}
		*end = '\0';
		(void)snprintf(section, seclen, "%s", trim(line + 1));
		return 0;
	}
	eq = strchr(line, '=');
	if (eq == NULL) {
		return fail(err, errlen, path, ln, "'%s' is neither a [section] nor key=value",
			    line);
	}
	if (section[0] == '\0') {
		return fail(err, errlen, path, ln, "'%s' is outside any [section]", line);
	}
	*eq = '\0';
	key = trim(line);
	val = trim(eq + 1);

	if (strcasecmp(section, "DeviceComissioning") == 0 ||
	    strcasecmp(section, "DeviceCommissioning") == 0) {
		if (strcasecmp(key, "NodeID") == 0) {
			if (value_of(path, ln, val, &v, err, errlen) != 0) {
				return -EINVAL;
			}
			if (v < 1U || v > 127U) {
				return fail(err, errlen, path, ln, "NodeID %s is not 1..127", val);
			}
			net->node_id = (uint8_t)v;
		}
		return 0;
	}
	kind = section_kind(section, &index, &sub);
	if (kind == 0) {
		return 0;
	}
	if (index == CDCF_OBJ && kind == 's' && sub >= 1U && sub <= 127U &&
	    (strcasecmp(key, "UploadFile") == 0 || strcasecmp(key, "DownloadFile") == 0)) {
		if (val[0] == '\0') {
			return 0;
		}
		if (strlen(val) >= MAX_FILE) {
			return fail(err, errlen, path, ln, "file name longer than %d",
				    MAX_FILE - 1);
		}
		(void)snprintf(st.file[sub], MAX_FILE, "%s", val);
		st.file_line[sub] = ln;
		return 0;
	}
	if (index == CDCF_OBJ && (strcasecmp(key, "ParameterValue") == 0 ||
				  (kind == 'v' && strcasecmp(key, "NrOfEntries") != 0))) {
		return fail(err, errlen, path, ln,
			    "1F22h: name each slave's concise DCF with UploadFile= in [1F22subN]");
	}
	slot = obj_slot(index);
	if (slot < 0) {
		return 0;
	}
	if (kind == 'v') {
		/* [xxxxValue] of a CompactSubObj array: hex (0x) or decimal sub-indexes. */
		if (strcasecmp(key, "NrOfEntries") == 0) {
			return 0;
		}
		if (!parse_u32(key, &v) || v < 1U || v > 127U) {
			return fail(err, errlen, path, ln,
				    "[%s]: key '%s' is not a sub-index 1..127", section, key);
		}
		sub = (uint8_t)v;
		if (value_of(path, ln, val, &v, err, errlen) != 0) {
			return -EINVAL;
		}
		st.recs[slot][sub].param = v;
		st.recs[slot][sub].param_line = ln;
		return 0;
	}
	if (kind == 's' && sub > 127U) {
		return 0;
	}
	if (strcasecmp(key, "CompactSubObj") == 0) {
		if (!parse_u32(val, &v) || v > 127U) {
			return fail(err, errlen, path, ln, "CompactSubObj=%s is not 0..127", val);
		}
		st.compact[slot] = (uint8_t)v;
		st.compact_line[slot] = ln;
		return 0;
	}
	if (strcasecmp(key, "ParameterValue") == 0 || strcasecmp(key, "DefaultValue") == 0) {
		bool param = strcasecmp(key, "ParameterValue") == 0;

		if (value_of(path, ln, val, &v, err, errlen) != 0) {
			return -EINVAL;
		}
		if (param) {
			st.recs[slot][sub].param = v;
			st.recs[slot][sub].param_line = ln;
		} else {
			st.recs[slot][sub].dflt = v;
			st.recs[slot][sub].dflt_line = ln;
		}
	}
	return 0;
}

static int push(struct network *net, uint16_t index, uint8_t sub, uint32_t value, uint32_t line,
		char *err, size_t errlen)
{
	if (net->n_values == NETWORK_MAX_VALUES) {
		return fail(err, errlen, net->path, line, "more than %u network values",
			    NETWORK_MAX_VALUES);
	}
	net->values[net->n_values++] = (struct network_value){index, sub, value, line};
	return 0;
}

int network_load(struct network *net, const char *path, char *err, size_t errlen)
{
	char line[MAX_LINE + 2];
	char section[64] = "";
	uint32_t ln = 0;
	int rc = 0;
	FILE *f;

	memset(net, 0, sizeof(*net));
	memset(&st, 0, sizeof(st));
	net->path = path;
	f = fopen(path, "r");
	if (f == NULL) {
		return fail(err, errlen, path, 0, "cannot open: %s", strerror(errno));
	}
	while (rc == 0 && fgets(line, sizeof(line), f) != NULL) {
		char *s;

		ln++;
		if (strchr(line, '\n') == NULL && !feof(f)) {
			rc = fail(err, errlen, path, ln, "line longer than %d characters",
				  MAX_LINE);
			break;
		}
		s = trim(line);
		if (s[0] == '\0' || s[0] == ';' || s[0] == '#') {
			continue;
		}
		rc = parse_line(net, path, ln, s, section, sizeof(section), err, errlen);
	}
	if (rc == 0 && ferror(f)) {
		rc = fail(err, errlen, path, ln, "read error");
	}
	fclose(f);
	if (rc != 0) {
		return rc;
	}

	/* Values: ParameterValue, else DefaultValue (lely's dcfgen writes only DefaultValue). */
	for (size_t i = 0; i < N_OBJ && rc == 0; i++) {
		uint16_t index = net_objects[i].index;

		if (!net_objects[i].array) {
			struct rec *r = &st.recs[i][0];

			if (r->param_line != 0U) {
				rc = push(net, index, 0, r->param, r->param_line, err, errlen);
			} else if (r->dflt_line != 0U) {
				rc = push(net, index, 0, r->dflt, r->dflt_line, err, errlen);
			}
			continue;
		}
		for (unsigned int sub = 1; sub <= 127U && rc == 0; sub++) {
			struct rec *r = &st.recs[i][sub];

			if (r->param_line != 0U) {
				rc = push(net, index, (uint8_t)sub, r->param, r->param_line, err,
					  errlen);
			} else if (r->dflt_line != 0U) {
				rc = push(net, index, (uint8_t)sub, r->dflt, r->dflt_line, err,
					  errlen);
			} else if (sub <= st.compact[i] && st.recs[i][0].dflt != 0U) {
				/* A compact array's DefaultValue is every entry's. */
				rc = push(net, index, (uint8_t)sub, st.recs[i][0].dflt,
					  st.recs[i][0].dflt_line, err, errlen);
			}
		}
	}
	for (size_t k = 0; k < net->n_values && rc == 0; k++) {
		const struct network_value *nv = &net->values[k];

		if (nv->index == 0x1F81U && (nv->value & 1U) != 0U) {
			net->slaves[net->n_slaves++] = nv->sub;
		}
	}
	for (unsigned int id = 1; id <= 127U && rc == 0; id++) {
		if (st.file[id][0] != '\0') {
			rc = load_cdcf(net, path, (uint8_t)id, err, errlen);
		}
	}
	return rc;
}

static uint32_t write_u32(struct co_od *od, uint16_t index, uint8_t sub, uint32_t value)
{
	struct co_od_info info;
	uint8_t le[4];
	uint32_t ab = co_od_find(od, index, sub, &info);

	if (ab != 0U) {
		return ab;
	}
	if (info.size == 0U || info.size > 4U) {
		return CO_SDO_AB_TYPE_MISMATCH;
	}
	if (info.size < 4U && (value >> (8U * info.size)) != 0U) {
		return CO_SDO_AB_VALUE_HIGH;
	}
	co_od_le_put(le, info.size, value);
	return co_od_write_info(od, &info, le, info.size, CO_OD_WRITER_STORAGE);
}

uint32_t network_apply(const struct network *net, struct co_od *od,
		       const struct network_value **bad)
{
	uint32_t ab;

	*bad = NULL;
	/* The arrays are the DCF's alone: clear what the bundled dictionary put there. */
	for (size_t i = 0; i < N_OBJ; i++) {
		uint16_t index = net_objects[i].index;
		struct co_od_info info;
		uint32_t hi;

		if (!net_objects[i].array || co_od_find(od, index, 0, &info) != 0U) {
			continue;
		}
		hi = co_od_uint(od, index, 0, 0U);
		for (uint32_t sub = 1; sub <= hi && sub <= 127U; sub++) {
			(void)write_u32(od, index, (uint8_t)sub, 0U);
		}
	}
	for (size_t k = 0; k < net->n_values; k++) {
		ab = write_u32(od, net->values[k].index, net->values[k].sub, net->values[k].value);
		if (ab != 0U) {
			*bad = &net->values[k];
			return ab;
		}
	}
	return 0U;
}
