/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The bridge's two files (doc/dds-bridge.md). One directive per line, words separated by
 * blanks, '#' starts a comment. Any error names FILE:LINE and stops the bridge from starting.
 *
 * Configuration file:
 *   eds    LINE NODES PATH             the EDS (or DCF) of those nodes, PATH relative to the file
 *   object LINE NODE OBJECT INTERVAL   publish OBJECT (IIII:SS, hex) on change, at most once
 *                                      per INTERVAL ms (it is polled that often)
 * Allow-list (without it: read-only):
 *   write CLIENT LINE NODES OBJECTS    CLIENT (a glob on the client's name) may write OBJECTS
 *   nmt   CLIENT LINE NODES COMMANDS   ... and send COMMANDS to NODES
 * LINE: a number or *. NODES: *, or a comma list of N and N-M (1..127). OBJECTS: *, or a
 * comma list of IIII (every sub-index), IIII:SS and IIII-JJJJ. COMMANDS: *, or a comma list of
 * start, stop, preop, reset, reset-comm.
 * A request for every node (NMT node 0; sub-index 80h of 1F25h, 1F82h, 1F83h, CiA 302-2) is
 * allowed only when the same request is allowed for each node 1..127: a broadcast reaches the
 * manager and nodes nobody listed as well.
 */

#include <ctype.h>
#include <errno.h>
#include <fnmatch.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/logging/log.h>

#include "bridge_internal.h"

LOG_MODULE_DECLARE(canopen_bridge_dds, CONFIG_CANOPEN_LOG_LEVEL);

#define MAX_WORDS 8

struct ctx {
	const char *path;
	int lineno;
};

static int fail(const struct ctx *c, const char *fmt, ...)
{
	char msg[160];
	va_list ap;

	va_start(ap, fmt);
	(void)vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	LOG_ERR("%s:%d: %s", c->path, c->lineno, msg);
	return -EINVAL;
}

static bool parse_uint(const char *s, int base, unsigned long max, unsigned long *v)
{
	char *end;

	if (*s == '\0' || *s == '-' || *s == '+' || isspace((unsigned char)*s)) {
		return false;
	}
	errno = 0;
	*v = strtoul(s, &end, base);
	return errno == 0 && *end == '\0' && *v <= max;
}

/* Hex index "2001", "0x2001" or "2001h". */
static bool parse_index(const char *s, size_t n, uint16_t *index)
{
	char buf[12];
	unsigned long v;

	if (n == 0U || n >= sizeof(buf)) {
		return false;
	}
	(void)memcpy(buf, s, n);
	buf[n] = '\0';
	if (n > 1U && (buf[n - 1] == 'h' || buf[n - 1] == 'H')) {
		buf[n - 1] = '\0';
	}
	if (!parse_uint(buf, 16, 0xFFFFU, &v)) {
		return false;
	}
	*index = (uint16_t)v;
	return true;
}

/* "IIII", "IIII:SS" (hex) into a range of one index; sub -1 when absent. */
static bool parse_object(const char *s, uint16_t *index, int16_t *sub)
{
	const char *colon = strchr(s, ':');
	unsigned long v;

	if (colon == NULL) {
		*sub = -1;
		return parse_index(s, strlen(s), index);
	}
	if (!parse_index(s, (size_t)(colon - s), index)) {
		return false;
	}
	if (colon[1] == 'h' || !parse_uint(colon + 1, 16, 0xFFU, &v)) {
		return false;
	}
	*sub = (int16_t)v;
	return true;
}

/* Split a line into words; comments removed. */
static int split(char *line, char *words[MAX_WORDS])
{
	char *hash = strchr(line, '#');
	int n = 0;

	if (hash != NULL) {
		*hash = '\0';
	}
	for (char *tok = strtok(line, " \t\r\n"); tok != NULL; tok = strtok(NULL, " \t\r\n")) {
		if (n == MAX_WORDS) {
			return MAX_WORDS + 1;
		}
		words[n++] = tok;
	}
	return n;
}

static int parse_line_no(const struct ctx *c, const char *s, bool any_ok, int16_t *line_no)
{
	unsigned long v;

	if (any_ok && strcmp(s, "*") == 0) {
		*line_no = -1;
		return 0;
	}
	if (!parse_uint(s, 10, 254U, &v)) {
		return fail(c, "line '%s': a number 0..254%s", s, any_ok ? " or *" : "");
	}
	*line_no = (int16_t)v;
	return 0;
}

static void set_bit(uint32_t bits[4], unsigned int n)
{
	bits[n / 32U] |= BIT(n % 32U);
}

static bool test_bit(const uint32_t bits[4], unsigned int n)
{
	return (bits[n / 32U] & BIT(n % 32U)) != 0U;
}

/* NODES (1..127) into a bitmap. */
static int parse_nodes(const struct ctx *c, char *s, uint32_t bits[4])
{
	char *save = NULL;

	memset(bits, 0, 4 * sizeof(bits[0]));
	if (strcmp(s, "*") == 0) {
		for (unsigned int n = 1U; n < BR_NODE_IDS; n++) {
			set_bit(bits, n);
		}
		return 0;
	}
	for (char *tok = strtok_r(s, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
		char *dash = strchr(tok, '-');
		unsigned long a;
		unsigned long b;

		if (strcmp(tok, "all") == 0) {
			/* A rule for "all" alone would let a broadcast reach unlisted nodes. */
			return fail(c, "'all' names no node: a request for all nodes is allowed "
				       "where each node 1..127 is (NODES *)");
		}
		if (dash != NULL) {
			*dash = '\0';
			if (!parse_uint(tok, 10, 127U, &a) || !parse_uint(dash + 1, 10, 127U, &b) ||
			    a == 0U || b < a) {
				return fail(c, "nodes '%s-%s': N-M with 1 <= N <= M <= 127", tok,
					    dash + 1);
			}
		} else if (!parse_uint(tok, 10, 127U, &a) || a == 0U) {
			return fail(c, "node '%s': 1..127", tok);
		} else {
			b = a;
		}
		for (unsigned long n = a; n <= b; n++) {
			set_bit(bits, (unsigned int)n);
		}
	}
	return 0;
}

static int parse_objects(const struct ctx *c, char *s, struct br_rule *r)
{
	char *save = NULL;

	if (strcmp(s, "*") == 0) {
		r->any_object = true;
		return 0;
	}
	for (char *tok = strtok_r(s, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
		struct br_obj_range *o;
		char *dash = strchr(tok, '-');

		if (r->n_objects == BR_RULE_OBJECTS) {
			return fail(c, "more than %u objects in one rule", BR_RULE_OBJECTS);
		}
		o = &r->objects[r->n_objects];
		if (dash != NULL) {
			if (!parse_index(tok, (size_t)(dash - tok), &o->first) ||
			    !parse_index(dash + 1, strlen(dash + 1), &o->last) ||
			    o->last < o->first) {
				return fail(c, "objects '%s': IIII-JJJJ (hex, IIII <= JJJJ)", tok);
			}
			o->sub = -1;
		} else if (!parse_object(tok, &o->first, &o->sub)) {
			return fail(c, "object '%s': IIII or IIII:SS (hex)", tok);
		} else {
			o->last = o->first;
		}
		r->n_objects++;
	}
	return 0;
}

static int parse_cmds(const struct ctx *c, char *s, uint8_t *cmds)
{
	static const struct {
		const char *name;
		uint8_t bit;
	} names[] = {
		{"start", BR_CMD_START},           {"stop", BR_CMD_STOP},
		{"preop", BR_CMD_PREOP},           {"reset", BR_CMD_RESET},
		{"reset-comm", BR_CMD_RESET_COMM},
	};
	char *save = NULL;

	*cmds = 0;
	if (strcmp(s, "*") == 0) {
		*cmds = BR_CMD_ALL;
		return 0;
	}
	for (char *tok = strtok_r(s, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
		size_t i;

		for (i = 0; i < ARRAY_SIZE(names); i++) {
			if (strcmp(tok, names[i].name) == 0) {
				*cmds |= names[i].bit;
				break;
			}
		}
		if (i == ARRAY_SIZE(names)) {
			return fail(c, "command '%s': start, stop, preop, reset or reset-comm",
				    tok);
		}
	}
	return 0;
}

/* PATH relative to the directory of @p file, into @p out. */
static void relative_to(const char *file, const char *path, char *out, size_t len)
{
	const char *slash = strrchr(file, '/');

	if (path[0] == '/' || slash == NULL) {
		(void)snprintf(out, len, "%s", path);
	} else {
		(void)snprintf(out, len, "%.*s/%s", (int)(slash - file), file, path);
	}
}

static int eds_line(struct br_conf *conf, const struct ctx *c, char **w, int n)
{
	uint32_t bits[4];
	struct br_eds_map *m;
	char path[256];
	int16_t line_no;
	int first = -1;
	int last = -1;
	int k;
	int err;

	if (n != 4) {
		return fail(c, "eds LINE NODES PATH");
	}
	err = parse_line_no(c, w[1], false, &line_no);
	if (err == 0) {
		err = parse_nodes(c, w[2], bits);
	}
	if (err != 0) {
		return err;
	}
	relative_to(c->path, w[3], path, sizeof(path));
	for (k = 0; k < conf->n_eds; k++) {
		if (strcmp(conf->eds[k].path, path) == 0) {
			break;
		}
	}
	if (k == conf->n_eds) {
		if (conf->n_eds == BR_MAX_EDS) {
			return fail(c, "more than %u EDS files", BR_MAX_EDS);
		}
		err = br_eds_load(path, &conf->eds[k]);
		if (err != 0) {
			(void)fail(c, "EDS '%s' not usable", path);
			return err;
		}
		conf->n_eds++;
	}
	/* One map entry per run of consecutive nodes. */
	for (int id = 1; id <= 128; id++) {
		bool in = id < 128 && test_bit(bits, (unsigned int)id);

		if (in && first < 0) {
			first = id;
		}
		if (in) {
			last = id;
			continue;
		}
		if (first < 0) {
			continue;
		}
		if (conf->n_maps == BR_MAX_EDS_MAPS) {
			return fail(c, "more than %u eds node ranges", BR_MAX_EDS_MAPS);
		}
		m = &conf->maps[conf->n_maps++];
		*m = (struct br_eds_map){.line_no = (uint8_t)line_no,
					 .first = (uint8_t)first,
					 .last = (uint8_t)last,
					 .eds = (uint8_t)k};
		first = -1;
	}
	return 0;
}

static int object_line(struct br_conf *conf, const struct ctx *c, char **w, int n)
{
	struct br_object *o;
	int16_t line_no;
	int16_t sub;
	uint16_t index;
	unsigned long node;
	unsigned long ms;
	int err;

	if (n != 5) {
		return fail(c, "object LINE NODE IIII:SS INTERVAL_MS");
	}
	err = parse_line_no(c, w[1], false, &line_no);
	if (err != 0) {
		return err;
	}
	if (!parse_uint(w[2], 10, 127U, &node) || node == 0U) {
		return fail(c, "node '%s': 1..127", w[2]);
	}
	if (!parse_object(w[3], &index, &sub)) {
		return fail(c, "object '%s': IIII:SS (hex)", w[3]);
	}
	if (!parse_uint(w[4], 10, 3600000U, &ms) || ms < 10U) {
		return fail(c, "interval '%s': 10..3600000 ms", w[4]);
	}
	if (conf->n_objects >= CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS) {
		return fail(c, "more than CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS (%d) objects",
			    CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS);
	}
	o = &conf->objects[conf->n_objects++];
	*o = (struct br_object){
		.line_no = (uint8_t)line_no,
		.node_id = (uint8_t)node,
		.index = index,
		.sub = sub < 0 ? 0U : (uint8_t)sub,
		.interval_ms = (uint32_t)ms,
	};
	return 0;
}

static int rule_line(struct br_conf *conf, const struct ctx *c, char **w, int n)
{
	struct br_rule *r;
	bool nmt = strcmp(w[0], "nmt") == 0;
	int err;

	if (n != 5) {
		return fail(c, nmt ? "nmt CLIENT LINE NODES COMMANDS"
				   : "write CLIENT LINE NODES OBJECTS");
	}
	if (conf->n_rules >= CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES) {
		return fail(c, "more than CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES (%d) rules",
			    CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES);
	}
	r = &conf->rules[conf->n_rules];
	(void)memset(r, 0, sizeof(*r));
	r->nmt = nmt;
	if (strlen(w[1]) >= sizeof(r->client)) {
		return fail(c, "client pattern longer than %zu characters", sizeof(r->client) - 1U);
	}
	(void)strcpy(r->client, w[1]);
	err = parse_line_no(c, w[2], true, &r->line_no);
	if (err == 0) {
		err = parse_nodes(c, w[3], r->nodes);
	}
	if (err == 0) {
		err = nmt ? parse_cmds(c, w[4], &r->cmds) : parse_objects(c, w[4], r);
	}
	if (err == 0) {
		conf->n_rules++;
	}
	return err;
}

typedef int (*directive_fn)(struct br_conf *conf, const struct ctx *c, char **w, int n);

static int load(struct br_conf *conf, const char *path, const char *const names[],
		const directive_fn fns[], size_t n_names)
{
	struct ctx c = {.path = path};
	char line[512];
	int err = 0;
	FILE *f = fopen(path, "r");

	if (f == NULL) {
		LOG_ERR("%s: cannot read (%s)", path, strerror(errno));
		return -ENOENT;
	}
	while (err == 0 && fgets(line, sizeof(line), f) != NULL) {
		char *w[MAX_WORDS];
		size_t i;
		int n;

		c.lineno++;
		if (strchr(line, '\n') == NULL && !feof(f)) {
			err = fail(&c, "line longer than %zu characters", sizeof(line) - 2U);
			break;
		}
		n = split(line, w);
		if (n == 0) {
			continue;
		}
		if (n > MAX_WORDS) {
			err = fail(&c, "too many words");
			break;
		}
		for (i = 0; i < n_names; i++) {
			if (strcmp(w[0], names[i]) == 0) {
				err = fns[i](conf, &c, w, n);
				break;
			}
		}
		if (i == n_names) {
			err = fail(&c, "unknown directive '%s' (%s%s%s)", w[0], names[0],
				   n_names > 1 ? " or " : "", n_names > 1 ? names[1] : "");
		}
	}
	(void)fclose(f);
	return err;
}

int br_conf_load(struct br_conf *conf, const char *path)
{
	static const char *const names[] = {"eds", "object"};
	static const directive_fn fns[] = {eds_line, object_line};

	return load(conf, path, names, fns, ARRAY_SIZE(names));
}

int br_allow_load(struct br_conf *conf, const char *path)
{
	static const char *const names[] = {"write", "nmt"};
	static const directive_fn fns[] = {rule_line, rule_line};
	int err = load(conf, path, names, fns, ARRAY_SIZE(names));

	conf->allow = err == 0;
	return err;
}

void br_conf_free(struct br_conf *conf)
{
	for (int i = 0; i < conf->n_eds; i++) {
		br_eds_free(&conf->eds[i]);
	}
	conf->n_eds = 0;
}

const struct br_eds *br_conf_eds(const struct br_conf *conf, uint8_t line_no, uint8_t node_id)
{
	for (int i = 0; i < conf->n_maps; i++) {
		const struct br_eds_map *m = &conf->maps[i];

		if (m->line_no == line_no && node_id >= m->first && node_id <= m->last) {
			return &conf->eds[m->eds];
		}
	}
	return NULL;
}

void br_client_name(const char *client_id, char *buf, size_t len)
{
	const char *at = strchr(client_id, '@');
	size_t n = at != NULL ? (size_t)(at - client_id) : strlen(client_id);

	(void)snprintf(buf, len, "%.*s", (int)n, client_id);
}

static bool rule_matches(const struct br_rule *r, bool nmt, const char *client, uint8_t line_no,
			 uint8_t node_id)
{
	return r->nmt == nmt && (r->line_no < 0 || r->line_no == line_no) &&
	       node_id < BR_NODE_IDS && test_bit(r->nodes, node_id) &&
	       fnmatch(r->client, client, 0) == 0;
}

static bool write_allowed(const struct br_conf *conf, const char *client, uint8_t line_no,
			  uint8_t node_id, uint16_t index, uint8_t sub)
{
	for (int i = 0; i < conf->n_rules; i++) {
		const struct br_rule *r = &conf->rules[i];

		if (!rule_matches(r, false, client, line_no, node_id)) {
			continue;
		}
		if (r->any_object) {
			return true;
		}
		for (int k = 0; k < r->n_objects; k++) {
			const struct br_obj_range *o = &r->objects[k];

			if (index >= o->first && index <= o->last &&
			    (o->sub < 0 || o->sub == sub)) {
				return true;
			}
		}
	}
	return false;
}

bool br_allow_is_for_all_nodes(uint16_t index, uint8_t sub)
{
	/* CiA 302-2: configuration request, request NMT, request node guarding. */
	return sub == BR_SUB_ALL_NODES &&
	       (index == 0x1F25U || index == 0x1F82U || index == 0x1F83U);
}

bool br_allow_write(const struct br_conf *conf, const char *client, uint8_t line_no,
		    uint8_t node_id, uint16_t index, uint8_t sub)
{
	if (!conf->allow || node_id == 0U ||
	    !write_allowed(conf, client, line_no, node_id, index, sub)) {
		return false;
	}
	if (br_allow_is_for_all_nodes(index, sub)) {
		for (uint8_t n = 1U; n < BR_NODE_IDS; n++) {
			if (!write_allowed(conf, client, line_no, node_id, index, n)) {
				return false;
			}
		}
	}
	return true;
}

static bool nmt_allowed(const struct br_conf *conf, const char *client, uint8_t line_no,
			uint8_t node_id, uint8_t cmd)
{
	for (int i = 0; i < conf->n_rules; i++) {
		const struct br_rule *r = &conf->rules[i];

		if (rule_matches(r, true, client, line_no, node_id) && (r->cmds & cmd) != 0U) {
			return true;
		}
	}
	return false;
}

bool br_allow_nmt(const struct br_conf *conf, const char *client, uint8_t line_no, uint8_t node_id,
		  uint8_t cmd)
{
	if (!conf->allow || cmd == 0U) {
		return false;
	}
	if (node_id != 0U) {
		return nmt_allowed(conf, client, line_no, node_id, cmd);
	}
	/* The broadcast: every node, the manager's own included. */
	for (uint8_t n = 1U; n < BR_NODE_IDS; n++) {
		if (!nmt_allowed(conf, client, line_no, n, cmd)) {
			return false;
		}
	}
	return true;
}

uint8_t br_cmd_bit(uint8_t cs)
{
	switch (cs) {
	case CO_NMT_CS_START:
		return BR_CMD_START;
	case CO_NMT_CS_STOP:
		return BR_CMD_STOP;
	case CO_NMT_CS_ENTER_PRE_OPERATIONAL:
		return BR_CMD_PREOP;
	case CO_NMT_CS_RESET_NODE:
		return BR_CMD_RESET;
	case CO_NMT_CS_RESET_COMMUNICATION:
		return BR_CMD_RESET_COMM;
	default:
		return 0U;
	}
}
