/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The manager sample's DCF reader (samples/canopen/manager/src/network.c, --dcf). The input
 * is the file itself, written into a folder of the harness that also holds a concise DCF
 * (slave.bin) and a FIFO (fifo.bin) for UploadFile= to name. Invariants:
 *
 * - network_load() returns 0 or -EINVAL, and never blocks (libFuzzer's -timeout);
 * - a refusal names the file, and a line of it that exists ("FILE:LINE: " or "FILE: "; line 1
 *   of an empty file);
 * - an accepted file has the mandatory objects [1000], [1001] and [1018] (read independently
 *   here), ends its last line with an end of line, every value comes from one of its lines,
 *   is one of the network objects, and the slaves are ascending in 1..127;
 * - reading the same file twice gives the same network;
 * - its values go into the manager's dictionary or one is refused and named.
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz.h"
#include "fuzz_master_od.h"
#include "network.h"

static struct network net;
static struct network again;
static struct co_od od;
static struct fuzz_master_od_ram ram;
static char dir[64];
static char path[96];

static void remove_dir(void)
{
	char p[128];

	for (unsigned int i = 0; i < 3U; i++) {
		(void)snprintf(p, sizeof(p), "%s/%s", dir,
			       (const char *[]){"net.dcf", "slave.bin", "fifo.bin"}[i]);
		(void)unlink(p);
	}
	(void)rmdir(dir);
}

static void make_dir(void)
{
	/* Count 1: 1017h:00 = 100 (UNSIGNED16). */
	static const uint8_t cdcf[] = {1, 0, 0, 0, 0x17, 0x10, 0, 2, 0, 0, 0, 100, 0};
	char p[128];
	FILE *f;

	(void)snprintf(dir, sizeof(dir), "/tmp/safeline-fuzz-dcf-XXXXXX");
	if (mkdtemp(dir) == NULL) {
		fz_fail("mkdtemp: %s", strerror(errno));
	}
	(void)snprintf(path, sizeof(path), "%s/net.dcf", dir);
	(void)snprintf(p, sizeof(p), "%s/slave.bin", dir);
	f = fopen(p, "wb");
	if (f == NULL || fwrite(cdcf, 1, sizeof(cdcf), f) != sizeof(cdcf)) {
		fz_fail("cannot write %s", p);
	}
	fclose(f);
	(void)snprintf(p, sizeof(p), "%s/fifo.bin", dir);
	if (mkfifo(p, 0600) != 0) {
		fz_fail("mkfifo: %s", strerror(errno));
	}
	(void)atexit(remove_dir);
}

static unsigned int count_lines(const uint8_t *data, size_t size)
{
	unsigned int n = 0;

	for (size_t i = 0; i < size; i++) {
		n += data[i] == '\n' ? 1U : 0U;
	}
	return n + (size > 0U && data[size - 1U] != '\n' ? 1U : 0U);
}

/* A line "[name]" (blanks around allowed), independently of the reader. */
static bool has_section(const uint8_t *data, size_t size, const char *name)
{
	size_t n = strlen(name);

	for (size_t i = 0; i < size;) {
		size_t end = i;

		while (end < size && data[end] != '\n') {
			end++;
		}
		size_t a = i;
		size_t b = end;

		while (a < b && (data[a] == ' ' || data[a] == '\t' || data[a] == '\r')) {
			a++;
		}
		while (b > a &&
		       (data[b - 1U] == ' ' || data[b - 1U] == '\t' || data[b - 1U] == '\r')) {
			b--;
		}
		if (b > a + 2U && data[a] == '[' && data[b - 1U] == ']') {
			size_t p = a + 1U;
			size_t q = b - 1U;

			while (p < q && (data[p] == ' ' || data[p] == '\t')) {
				p++;
			}
			while (q > p && (data[q - 1U] == ' ' || data[q - 1U] == '\t')) {
				q--;
			}
			if (q - p == n && strncasecmp((const char *)&data[p], name, n) == 0) {
				return true;
			}
		}
		i = end + 1U;
	}
	return false;
}

static bool network_object(uint16_t index)
{
	static const uint16_t objs[] = {0x1016, 0x1017, 0x102A, 0x1F26, 0x1F27, 0x1F80, 0x1F81,
					0x1F84, 0x1F85, 0x1F86, 0x1F87, 0x1F88, 0x1F89};

	for (size_t i = 0; i < ARRAY_SIZE(objs); i++) {
		if (objs[i] == index) {
			return true;
		}
	}
	return false;
}

static void check_refusal(const char *err, unsigned int lines)
{
	size_t n = strlen(path);
	unsigned long line;
	char *end;

	if (strncmp(err, path, n) != 0 || err[n] != ':' || err[n + 1U] == '\0') {
		fz_fail("refusal names no file: '%s'", err);
	}
	if (err[n + 1U] == ' ') {
		return;
	}
	line = strtoul(&err[n + 1U], &end, 10);
	/* An empty file's missing objects are named at line 1, as scripts/eds2od does. */
	if (end == &err[n + 1U] || *end != ':' || line == 0U || line > MAX(lines, 1U)) {
		fz_fail("refusal names line %lu of %u: '%s'", line, lines, err);
	}
}

static void raw(const uint8_t *data, size_t size)
{
	char err[512];
	unsigned int lines = count_lines(data, size);
	const struct network_value *bad;
	FILE *f;
	int rc;

	if (dir[0] == '\0') {
		make_dir();
	}
	f = fopen(path, "wb");
	if (f == NULL || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
		fz_fail("cannot write %s", path);
	}
	err[0] = '\0';
	rc = network_load(&net, path, err, sizeof(err));
	if (rc != 0) {
		if (rc != -EINVAL) {
			fz_fail("network_load() = %d", rc);
		}
		check_refusal(err, lines);
		network_free(&net);
		return;
	}
	if (!has_section(data, size, "1000") || !has_section(data, size, "1001") ||
	    !has_section(data, size, "1018")) {
		fz_fail("a file without the mandatory objects accepted");
	}
	for (size_t i = size; i > 0U; i--) {
		if (data[i - 1U] == '\n') {
			break;
		}
		if (data[i - 1U] != ' ' && data[i - 1U] != '\t' && data[i - 1U] != '\r') {
			/* A last line with text and no end of line: cut short? Only a comment may.
			 */
			size_t k = i;

			while (k > 0U && data[k - 1U] != '\n') {
				k--;
			}
			while (data[k] == ' ' || data[k] == '\t') {
				k++;
			}
			if (data[k] != ';' && data[k] != '#') {
				fz_fail("a file cut inside its last line accepted");
			}
			break;
		}
	}
	for (size_t k = 0; k < net.n_values; k++) {
		const struct network_value *v = &net.values[k];

		if (v->line == 0U || v->line > lines || !network_object(v->index)) {
			fz_fail("value %04Xh:%02X from line %u of %u", v->index, v->sub, v->line,
				lines);
		}
	}
	for (unsigned int i = 0; i < net.n_slaves; i++) {
		if (net.slaves[i] == 0U || net.slaves[i] > 127U ||
		    (i > 0U && net.slaves[i] <= net.slaves[i - 1U])) {
			fz_fail("slave list out of order at %u", i);
		}
	}
	if (network_load(&again, path, err, sizeof(err)) != 0 || again.n_values != net.n_values ||
	    again.n_slaves != net.n_slaves || again.node_id != net.node_id ||
	    memcmp(again.values, net.values, net.n_values * sizeof(net.values[0])) != 0) {
		fz_fail("a second reading differs");
	}
	network_free(&again);
	if (co_od_init(&od, &fuzz_master_od_def, &ram, 1) != 0) {
		fz_fail("co_od_init");
	}
	co_od_reset_app(&od);
	co_od_reset_comm(&od);
	if (network_apply(&net, &od, &bad) != 0U &&
	    (bad < net.values || bad >= net.values + net.n_values)) {
		fz_fail("a refused value not named");
	}
	network_free(&net);
}

static const uint32_t ids[] = {0};

const struct fz_harness fz_dcf = {
	.name = "dcf",
	.what = "the manager sample's DCF reader (network_load, --dcf)",
	.ids = ids,
	.n_ids = 1,
	.raw = raw,
};
