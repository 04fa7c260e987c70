/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A small CiA 306 reader for the network objects of a manager DCF. It reads what a manager
 * needs and nothing else: values of the other objects are the bundled dictionary's. The file
 * itself is checked with the rules of scripts/eds2od and its messages (a malformed or
 * duplicate section, a duplicate key, a sub-index section or key that is no sub-index, an
 * NrOfEntries that disagrees with its entries, the mandatory objects 1000h, 1001h, 1018h); a
 * line it cannot read (a key outside a section, a malformed number, a value that needs
 * $NODEID) is an error too. Every error names the file and the line; nothing is skipped.
 * A file that ends inside a line (no end of line after its last value) is refused: it may
 * have been cut short in the middle of a value.
 */

#include "network.h"

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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

#define N_OBJ        ARRAY_SIZE_(net_objects)
#define CDCF_OBJ     0x1F22U
#define MAX_LINE     512
#define MAX_FILE     256
#define MAX_BYTES    (1024U * 1024U)
/* Sections and keys per section the reader keeps for its duplicate checks. */
#define MAX_SECTIONS 4096
#define MAX_KEYS     512
#define MAX_NAME     64

#define ARRAY_SIZE_(a) (sizeof(a) / sizeof((a)[0]))

struct rec {
	uint32_t param_line;
	uint32_t dflt_line;
	uint32_t param;
	uint32_t dflt;
};

struct section {
	char name[MAX_NAME];
	uint32_t line;
	/* 'o' [IIII], 's' [IIIIsubS], 'v' [IIIIValue], 'n' [IIIIName], 'd' [IIIIDenotation],
	 * 0 any other. */
	char kind;
	uint16_t index;
	uint8_t sub;
};

struct key {
	char name[MAX_NAME];
	uint32_t line;
};

/* Parser state (one load at a time: the sample loads once, before the boot). */
static struct {
	struct rec recs[N_OBJ][128];
	uint8_t compact[N_OBJ];
	uint32_t compact_line[N_OBJ];
	/* Line of the [IIIIValue] section of a network object, 0 if none. */
	uint32_t value_line[N_OBJ];
	char file[128][MAX_FILE];
	uint32_t file_line[128];
	struct section sections[MAX_SECTIONS];
	unsigned int n_sections;
	/* The keys of the current section. */
	struct key keys[MAX_KEYS];
	unsigned int n_keys;
	/* The current [IIIIValue] section: its sub-indexes given and its NrOfEntries. */
	uint32_t value_subs[8];
	uint32_t value_sub_line[256];
	unsigned int value_entries;
	uint32_t nr_of_entries;
	uint32_t nr_line;
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

static bool all_hex(const char *s, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		if (!isxdigit((unsigned char)s[i])) {
			return false;
		}
	}
	return n > 0U;
}

/*
 * "1F81" -> 'o' 0x1F81, "1F81sub3" -> 's' sub 3, "1F81Value" -> 'v' (Name 'n', Denotation
 * 'd'); 'x' for another name that starts with an index (a section the reader would otherwise
 * skip, dropping what it holds), 0 for the other sections ([FileInfo], ...).
 */
static char section_kind(const char *name, uint16_t *index, uint8_t *sub)
{
	size_t len = strlen(name);

	if (len < 4U || !all_hex(name, 4)) {
		return 0;
	}
	*index = (uint16_t)strtoul((char[5]){name[0], name[1], name[2], name[3], '\0'}, NULL, 16);
	*sub = 0;
	if (len == 4U) {
		return 'o';
	}
	if (strncasecmp(&name[4], "sub", 3) == 0) {
		if (len > 7U && len <= 9U && all_hex(&name[7], len - 7U)) {
			*sub = (uint8_t)strtoul(&name[7], NULL, 16);
			return 's';
		}
		return 'x';
	}
	if (strcasecmp(&name[4], "Value") == 0) {
		return 'v';
	}
	if (strcasecmp(&name[4], "Name") == 0) {
		return 'n';
	}
	return strcasecmp(&name[4], "Denotation") == 0 ? 'd' : 'x';
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

/* A regular file, opened without waiting: a FIFO or a device would block or never end. */
static FILE *open_regular(const char *path, const char **why)
{
	struct stat sb;
	FILE *f;
	int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);

	if (fd < 0) {
		*why = strerror(errno);
		return NULL;
	}
	if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
		(void)close(fd);
		*why = "not a regular file";
		return NULL;
	}
	f = fdopen(fd, "rb");
	if (f == NULL) {
		*why = strerror(errno);
		(void)close(fd);
	}
	return f;
}

static int load_cdcf(struct network *net, const char *dcf_path, uint8_t id, char *err,
		     size_t errlen)
{
	const char *name = st.file[id];
	uint32_t line = st.file_line[id];
	char full[2 * MAX_FILE];
	const char *slash = strrchr(dcf_path, '/');
	const char *why = "";
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
	f = open_regular(full, &why);
	if (f == NULL) {
		return fail(err, errlen, dcf_path, line, "1F22h:%02X: cannot open %s: %s", id, full,
			    why);
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

/* Cut a comment after the value: ';' after white space (as scripts/eds2od reads it). */
static void strip_inline_comment(char *v)
{
	for (char *p = v; *p != '\0'; p++) {
		if (*p == ';' && p > v && isspace((unsigned char)p[-1])) {
			*p = '\0';
			return;
		}
	}
}

/* The [IIIIValue] section that ends here: its NrOfEntries must count its entries. */
static int end_section(const char *path, char *err, size_t errlen)
{
	const struct section *cur = st.n_sections > 0U ? &st.sections[st.n_sections - 1U] : NULL;

	if (cur != NULL && cur->kind == 'v' && st.nr_line != 0U &&
	    st.nr_of_entries != st.value_entries) {
		/* eds2od warns; a manager that lost an entry would lose a slave. */
		return fail(err, errlen, path, st.nr_line, "NrOfEntries=%u but [%s] has %u entries",
			    st.nr_of_entries, cur->name, st.value_entries);
	}
	return 0;
}

static int new_section(const char *path, uint32_t ln, char *line, char *err, size_t errlen)
{
	char *end = strrchr(line, ']');
	struct section *sec;
	char *name;

	if (end == NULL || end[1] != '\0') {
		return fail(err, errlen, path, ln, "malformed section header '%s'", line);
	}
	*end = '\0';
	name = trim(line + 1);
	if (strlen(name) >= MAX_NAME) {
		return fail(err, errlen, path, ln, "section name longer than %d characters",
			    MAX_NAME - 1);
	}
	if (end_section(path, err, errlen) != 0) {
		return -EINVAL;
	}
	if (st.n_sections == MAX_SECTIONS) {
		return fail(err, errlen, path, ln, "more than %d sections", MAX_SECTIONS);
	}
	sec = &st.sections[st.n_sections];
	(void)snprintf(sec->name, sizeof(sec->name), "%s", name);
	sec->line = ln;
	sec->kind = section_kind(name, &sec->index, &sec->sub);
	if (sec->kind == 'x') {
		if (strncasecmp(&name[4], "sub", 3) == 0) {
			return fail(err, errlen, path, ln,
				    "[%s]: '%s' is not a sub-index (one or two hex digits)", name,
				    &name[7]);
		}
		return fail(err, errlen, path, ln,
			    "[%s] is no object section ([IIII], [IIIIsubS], [IIIIValue], "
			    "[IIIIName] or [IIIIDenotation])",
			    name);
	}
	for (unsigned int i = 0; i < st.n_sections; i++) {
		const struct section *o = &st.sections[i];

		if (strcasecmp(o->name, name) == 0) {
			return fail(err, errlen, path, ln,
				    "duplicate section [%s] (first at line %u)", name, o->line);
		}
		if (sec->kind == 's' && o->kind == 's' && o->index == sec->index &&
		    o->sub == sec->sub) {
			return fail(err, errlen, path, ln,
				    "duplicate sub-index %u of %04Xh (first at line %u)", sec->sub,
				    sec->index, o->line);
		}
	}
	st.n_sections++;
	st.n_keys = 0;
	st.value_entries = 0;
	st.nr_line = 0;
	memset(st.value_subs, 0, sizeof(st.value_subs));
	if (sec->kind == 'v' && obj_slot(sec->index) >= 0) {
		st.value_line[obj_slot(sec->index)] = ln;
	}
	return 0;
}

static int new_key(const char *path, uint32_t ln, const char *key, const char *section, char *err,
		   size_t errlen)
{
	if (strlen(key) >= MAX_NAME) {
		return fail(err, errlen, path, ln, "key longer than %d characters", MAX_NAME - 1);
	}
	for (unsigned int i = 0; i < st.n_keys; i++) {
		if (strcasecmp(st.keys[i].name, key) == 0) {
			return fail(err, errlen, path, ln,
				    "duplicate key '%s' in [%s] (first at line %u)", key, section,
				    st.keys[i].line);
		}
	}
	if (st.n_keys == MAX_KEYS) {
		return fail(err, errlen, path, ln, "more than %d keys in [%s]", MAX_KEYS, section);
	}
	(void)snprintf(st.keys[st.n_keys].name, MAX_NAME, "%s", key);
	st.keys[st.n_keys].line = ln;
	st.n_keys++;
	return 0;
}

/* A key of an [IIIIValue] section: NrOfEntries or a sub-index (CiA 306 §4.5.2.2). */
static int value_key(const char *path, uint32_t ln, const struct section *sec, const char *key,
		     const char *val, uint8_t *sub, char *err, size_t errlen)
{
	int slot = obj_slot(sec->index);
	uint32_t n = slot >= 0 && st.compact_line[slot] != 0U ? st.compact[slot] : 254U;
	uint32_t v;

	if (strcasecmp(key, "NrOfEntries") == 0) {
		if (!parse_u32(val, &st.nr_of_entries)) {
			return fail(err, errlen, path, ln, "NrOfEntries=%s is not a number", val);
		}
		st.nr_line = ln;
		*sub = 0;
		return 0;
	}
	if (!parse_u32(key, &v)) {
		return fail(err, errlen, path, ln, "[%s]: key '%s' is not a sub-index", sec->name,
			    key);
	}
	if (v < 1U || v > n) {
		if (slot >= 0 && st.compact_line[slot] != 0U) {
			return fail(err, errlen, path, ln,
				    "[%s]: sub-index %s is not 1..%u (CompactSubObj=%u)", sec->name,
				    key, n, n);
		}
		return fail(err, errlen, path, ln, "[%s]: sub-index %s is not 1..%u", sec->name,
			    key, n);
	}
	if ((st.value_subs[v / 32U] & (1U << (v % 32U))) != 0U) {
		return fail(err, errlen, path, ln,
			    "[%s]: sub-index %u given twice (first at line %u)", sec->name, v,
			    st.value_sub_line[v]);
	}
	st.value_subs[v / 32U] |= 1U << (v % 32U);
	st.value_sub_line[v] = ln;
	st.value_entries++;
	*sub = (uint8_t)v;
	return 0;
}

static int parse_line(struct network *net, const char *path, uint32_t ln, char *line, char *err,
		      size_t errlen)
{
	const struct section *sec;
	uint16_t index = 0;
	uint8_t sub = 0;
	char kind;
	char *eq, *key, *val;
	int slot;
	uint32_t v;

	if (line[0] == '[') {
		return new_section(path, ln, line, err, errlen);
	}
	eq = strchr(line, '=');
	if (eq == NULL) {
		return fail(err, errlen, path, ln, "expected key=value, got '%s'", line);
	}
	if (st.n_sections == 0U) {
		return fail(err, errlen, path, ln,
			    "'%s' is outside any section (before the first [section])", line);
	}
	sec = &st.sections[st.n_sections - 1U];
	*eq = '\0';
	key = trim(line);
	val = eq + 1;
	strip_inline_comment(val);
	val = trim(val);
	if (new_key(path, ln, key, sec->name, err, errlen) != 0) {
		return -EINVAL;
	}

	if (strcasecmp(sec->name, "DeviceComissioning") == 0 ||
	    strcasecmp(sec->name, "DeviceCommissioning") == 0) {
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
	kind = sec->kind;
	index = sec->index;
	sub = sec->sub;
	if (kind == 'v' && value_key(path, ln, sec, key, val, &sub, err, errlen) != 0) {
		return -EINVAL;
	}
	if (kind != 'o' && kind != 's' && kind != 'v') {
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
		if (st.file[sub][0] != '\0') {
			return fail(err, errlen, path, ln,
				    "1F22h:%02X: a second file (the first at line %u)", sub,
				    st.file_line[sub]);
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
		if (sub == 0U) {
			return 0; /* NrOfEntries */
		}
		if (sub > 127U) {
			return fail(err, errlen, path, ln,
				    "[%s]: key '%s' is not a sub-index 1..127", sec->name, key);
		}
		if (value_of(path, ln, val, &v, err, errlen) != 0) {
			return -EINVAL;
		}
		st.recs[slot][sub].param = v;
		st.recs[slot][sub].param_line = ln;
		return 0;
	}
	if (kind == 's' && sub > 127U) {
		return fail(err, errlen, path, ln, "%04Xh has no sub-index %u here (1..127)", index,
			    sub);
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

/* After the last line: what eds2od checks of the whole file. */
static int check_sections(const char *path, char *err, size_t errlen)
{
	static const struct {
		uint16_t index;
		const char *name;
	} mandatory[] = {
		{0x1000, "Device type"}, {0x1001, "Error register"}, {0x1018, "Identity object"}};
	bool found;

	for (unsigned int i = 0; i < st.n_sections; i++) {
		const struct section *s = &st.sections[i];

		if (s->kind != 's' && s->kind != 'v' && s->kind != 'n') {
			continue;
		}
		found = false;
		for (unsigned int k = 0; k < st.n_sections && !found; k++) {
			found = st.sections[k].kind == 'o' && st.sections[k].index == s->index;
		}
		if (!found) {
			return fail(err, errlen, path, s->line,
				    s->kind == 's' ? "sub-index section [%s] has no object [%04X]"
						   : "[%s] has no object [%04X]",
				    s->name, s->index);
		}
	}
	for (size_t m = 0; m < ARRAY_SIZE_(mandatory); m++) {
		found = false;
		for (unsigned int k = 0; k < st.n_sections && !found; k++) {
			found = st.sections[k].kind == 'o' &&
				st.sections[k].index == mandatory[m].index;
		}
		if (!found) {
			return fail(err, errlen, path, 1U,
				    "mandatory object %04Xh (%s) is missing; CiA 306 requires "
				    "1000h, 1001h and 1018h in every EDS/DCF",
				    mandatory[m].index, mandatory[m].name);
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
	const char *why = "";
	bool cut = false;
	uint32_t ln = 0;
	int rc = 0;
	FILE *f;

	memset(net, 0, sizeof(*net));
	memset(&st, 0, sizeof(st));
	net->path = path;
	f = open_regular(path, &why);
	if (f == NULL) {
		return fail(err, errlen, path, 0, "cannot open: %s", why);
	}
	while (rc == 0 && fgets(line, sizeof(line), f) != NULL) {
		size_t len = strlen(line);
		char *s;

		ln++;
		if (len == 0U || line[len - 1U] != '\n') {
			if (!feof(f) || len == 0U) {
				rc = fail(err, errlen, path, ln,
					  "line longer than %d characters or holding a NUL byte",
					  MAX_LINE);
				break;
			}
			cut = true;
		}
		s = trim(line);
		if (s[0] == '\0' || s[0] == ';' || s[0] == '#') {
			continue;
		}
		if (cut) {
			rc = fail(err, errlen, path, ln,
				  "the file ends inside this line (no end of line): it may be cut "
				  "short");
			break;
		}
		rc = parse_line(net, path, ln, s, err, errlen);
	}
	if (rc == 0 && ferror(f)) {
		rc = fail(err, errlen, path, ln, "read error");
	}
	fclose(f);
	if (rc == 0) {
		rc = end_section(path, err, errlen);
	}
	if (rc == 0) {
		rc = check_sections(path, err, errlen);
	}
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

uint32_t network_slave_line(const struct network *net, uint8_t id)
{
	for (size_t k = 0; k < net->n_values; k++) {
		if (net->values[k].index == 0x1F81U && net->values[k].sub == id) {
			return net->values[k].line;
		}
	}
	return 0U;
}

void network_free(struct network *net)
{
	for (unsigned int id = 0; id < ARRAY_SIZE_(net->cdcf); id++) {
		free(net->cdcf[id]);
		net->cdcf[id] = NULL;
	}
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
