/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The DDS bridge's configuration file, allow-list and EDS reader (conf.c, eds.c): what each
 * directive means, and every error refused with FILE:LINE and its reason. No DDS participant
 * is created.
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <zephyr/ztest.h>

#include "bridge_internal.h"

static struct br_conf conf;

static void before(void *f)
{
	br_conf_free(&conf);
	memset(&conf, 0, sizeof(conf));
}

/* Run @p fn with stdout going to a file; the output into @p out. */
static int captured(int (*fn)(struct br_conf *, const char *), const char *path, char *out,
		    size_t len)
{
	char tmp[] = "/tmp/bridge_conf_log_XXXXXX";
	int fd = mkstemp(tmp);
	int saved = dup(STDOUT_FILENO);
	int err;
	ssize_t n;

	zassert_true(fd >= 0 && saved >= 0);
	(void)fflush(stdout);
	(void)dup2(fd, STDOUT_FILENO);
	err = fn(&conf, path);
	(void)fflush(stdout);
	(void)dup2(saved, STDOUT_FILENO);
	(void)close(saved);
	(void)lseek(fd, 0, SEEK_SET);
	n = read(fd, out, len - 1U);
	out[n > 0 ? n : 0] = '\0';
	(void)close(fd);
	(void)unlink(tmp);
	return err;
}

/* One directive in a file of its own; returns the loader's result and its log. */
static int load_line(bool allow, const char *line, char *log, size_t len, char *path, size_t plen)
{
	FILE *f;

	(void)snprintf(path, plen, "/tmp/bridge_case_%d.conf", getpid());
	f = fopen(path, "w");
	zassert_not_null(f);
	(void)fprintf(f, "# case\n%s\n", line);
	(void)fclose(f);
	before(NULL);
	return captured(allow ? br_allow_load : br_conf_load, path, log, len);
}

ZTEST_SUITE(bridge_conf, NULL, NULL, before, NULL, NULL);

ZTEST(bridge_conf, test_eds_reader_types_access_names_product)
{
	struct br_eds eds;
	const struct br_eds_entry *e;

	zassert_equal(br_eds_load(BRIDGE_TEST_EDS, &eds), 0);
	zassert_str_equal(eds.product, "bridge_test");
	e = br_eds_find(&eds, 0x1017, 0);
	zassert_not_null(e);
	zassert_equal(e->dtype, 0x0006);
	zassert_equal(e->access, 2); /* rw */
	zassert_str_equal(e->name, "Producer heartbeat time");
	e = br_eds_find(&eds, 0x1018, 4);
	zassert_not_null(e);
	zassert_equal(e->dtype, 0x0007);
	zassert_equal(e->access, 0); /* ro */
	zassert_str_equal(e->name, "Serial number");
	e = br_eds_find(&eds, 0x2002, 0);
	zassert_not_null(e);
	zassert_equal(e->dtype, 0x0003, "INTEGER16");
	/* An array's sub-index 0, and objects that are not there. */
	zassert_not_null(br_eds_find(&eds, 0x1016, 0));
	zassert_is_null(br_eds_find(&eds, 0x1016, 5));
	zassert_is_null(br_eds_find(&eds, 0x1018, 0x10));
	zassert_is_null(br_eds_find(&eds, 0x6000, 0));
	br_eds_free(&eds);
}

ZTEST(bridge_conf, test_eds_compact_sub_objects)
{
	static const char text[] = "[DeviceInfo]\nProductName=compact\n\n"
				   "[1016]\nParameterName=Consumer heartbeat time\nObjectType=0x8\n"
				   "DataType=0x0007\nAccessType=rw\nCompactSubObj=3\n\n"
				   "[2000]\nParameterName=Plain\nObjectType=0x7\nDataType=0x0005\n"
				   "AccessType=const\n";
	char path[] = "/tmp/bridge_compact_XXXXXX";
	int fd = mkstemp(path);
	struct br_eds eds;
	const struct br_eds_entry *e;

	zassert_true(fd >= 0);
	zassert_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
	(void)close(fd);
	zassert_equal(br_eds_load(path, &eds), 0);
	(void)unlink(path);
	e = br_eds_find(&eds, 0x1016, 0);
	zassert_not_null(e);
	zassert_equal(e->dtype, 0x0005, "sub-index 0 of a compact array is UNSIGNED8");
	e = br_eds_find(&eds, 0x1016, 3);
	zassert_not_null(e);
	zassert_equal(e->dtype, 0x0007);
	zassert_equal(e->access, 2);
	zassert_str_equal(e->name, "Consumer heartbeat time 3");
	zassert_is_null(br_eds_find(&eds, 0x1016, 4));
	e = br_eds_find(&eds, 0x2000, 0);
	zassert_not_null(e);
	zassert_equal(e->access, 5, "const");
	br_eds_free(&eds);
}

ZTEST(bridge_conf, test_configuration_file_eds_maps_and_objects)
{
	const struct br_eds *a;
	const struct br_eds *b;

	zassert_equal(br_conf_load(&conf, CONF_TEST_DIR "/good.conf"), 0);
	zassert_equal(conf.n_eds, 1, "one EDS file read once for every node that has it");
	a = br_conf_eds(&conf, 0, 1);
	b = br_conf_eds(&conf, 2, 11);
	zassert_not_null(a);
	zassert_equal(a, b);
	zassert_equal(br_conf_eds(&conf, 0, 7), a);
	zassert_is_null(br_conf_eds(&conf, 0, 2), "node 2 of line 0 has no EDS");
	zassert_is_null(br_conf_eds(&conf, 1, 7), "line 1 has no EDS at all");
	zassert_equal(br_conf_eds(&conf, 2, 12), a);
	zassert_is_null(br_conf_eds(&conf, 2, 13));

	zassert_equal(conf.n_objects, 3);
	zassert_equal(conf.objects[0].line_no, 0);
	zassert_equal(conf.objects[0].node_id, 7);
	zassert_equal(conf.objects[0].index, 0x2001);
	zassert_equal(conf.objects[0].sub, 0);
	zassert_equal(conf.objects[0].interval_ms, 100);
	zassert_equal(conf.objects[1].index, 0x2002, "0x prefix");
	zassert_equal(conf.objects[1].sub, 0, "sub-index 0 when absent");
	zassert_equal(conf.objects[2].index, 0x2000, "h suffix");
	zassert_equal(conf.objects[2].interval_ms, 10);
	zassert_false(conf.allow, "no allow-list read: read-only");
}

ZTEST(bridge_conf, test_allow_list_rules)
{
	zassert_equal(br_allow_load(&conf, CONF_TEST_DIR "/good_allow.conf"), 0);
	zassert_true(conf.allow);
	zassert_equal(conf.n_rules, 8);

	/* write ops 0 7 2001:00,2002 */
	zassert_true(br_allow_write(&conf, "ops", 0, 7, 0x2001, 0));
	zassert_false(br_allow_write(&conf, "ops", 0, 7, 0x2001, 1), "only sub-index 0");
	zassert_true(br_allow_write(&conf, "ops", 0, 7, 0x2002, 9), "every sub-index");
	zassert_false(br_allow_write(&conf, "ops", 1, 7, 0x2001, 0), "another line");
	zassert_false(br_allow_write(&conf, "ops", 0, 8, 0x2001, 0), "another node");
	zassert_false(br_allow_write(&conf, "ops", 0, 7, 0x1017, 0), "another object");
	zassert_false(br_allow_write(&conf, "opsx", 0, 7, 0x2001, 0), "the whole name matches");
	/* write admin* * * * */
	zassert_true(br_allow_write(&conf, "admin", 5, 127, 0x1017, 0));
	zassert_true(br_allow_write(&conf, "admin-2", 0, 1, 0x1000, 0));
	zassert_false(br_allow_write(&conf, "xadmin", 0, 1, 0x1000, 0));
	zassert_false(br_allow_write(&conf, "admin", 0, 0, 0x1000, 0), "node 0 is no node");
	/* write range 1 3-5 2000-20FF */
	zassert_true(br_allow_write(&conf, "range", 1, 3, 0x2000, 0));
	zassert_true(br_allow_write(&conf, "range", 1, 5, 0x20FF, 0xFF));
	zassert_false(br_allow_write(&conf, "range", 1, 6, 0x2000, 0));
	zassert_false(br_allow_write(&conf, "range", 1, 4, 0x2100, 0));

	/* nmt ops 0 1 preop,start */
	zassert_true(br_allow_nmt(&conf, "ops", 0, 1, BR_CMD_PREOP));
	zassert_false(br_allow_nmt(&conf, "ops", 0, 1, BR_CMD_STOP));
	zassert_false(br_allow_nmt(&conf, "ops", 0, 2, BR_CMD_START));
	zassert_false(br_allow_nmt(&conf, "ops", 1, 1, BR_CMD_START));
	/* nmt admin* * * *: each node, so the broadcast too */
	zassert_true(br_allow_nmt(&conf, "admin", 3, 0, BR_CMD_RESET));
	zassert_true(br_allow_nmt(&conf, "admin", 3, 127, BR_CMD_RESET_COMM));
	zassert_false(br_allow_nmt(&conf, "guest", 0, 1, BR_CMD_START));
	/* Writes and NMT are separate rules. */
	zassert_false(br_allow_nmt(&conf, "range", 1, 3, BR_CMD_START));
	zassert_false(br_allow_write(&conf, "ops", 0, 1, 0x2001, 0));
}

/* "all" is every node: the broadcast (and a request object's sub-index 80h) is allowed only
 * where each node 1..127 is, whichever rules allow them. */
ZTEST(bridge_conf, test_a_request_for_all_nodes_needs_each_node_allowed)
{
	zassert_equal(br_allow_load(&conf, CONF_TEST_DIR "/good_allow.conf"), 0);

	/* nmt ops 0 1 ...: node 1 alone is not everybody. */
	zassert_true(br_allow_nmt(&conf, "ops", 0, 1, BR_CMD_START));
	zassert_false(br_allow_nmt(&conf, "ops", 0, 0, BR_CMD_START));
	/* nmt split 0 1-63 start,stop + nmt split 0 64-127 start: two rules cover 1..127 for
	 * start, not for stop. */
	zassert_true(br_allow_nmt(&conf, "split", 0, 0, BR_CMD_START));
	zassert_true(br_allow_nmt(&conf, "split", 0, 5, BR_CMD_STOP));
	zassert_false(br_allow_nmt(&conf, "split", 0, 0, BR_CMD_STOP), "64..127 may not stop");
	zassert_false(br_allow_nmt(&conf, "split", 1, 0, BR_CMD_START), "another line");
	for (uint8_t bit = BR_CMD_START; bit <= BR_CMD_RESET_COMM && bit != 0U; bit <<= 1) {
		zassert_true(br_allow_nmt(&conf, "admin", 0, 0, bit), "admin: every command");
		zassert_false(br_allow_nmt(&conf, "ops", 0, 0, bit));
	}

	/* write admin* * * *: every sub-index, 80h (all nodes) with them. */
	zassert_true(br_allow_write(&conf, "admin", 0, 1, 0x1F82, 0x80));
	/* write mgr5 0 1 1F82:05,1F82:80,...: 80h named, but not each node. */
	zassert_true(br_allow_write(&conf, "mgr5", 0, 1, 0x1F82, 0x05));
	zassert_false(br_allow_write(&conf, "mgr5", 0, 1, 0x1F82, 0x80), "request NMT, all");
	zassert_false(br_allow_write(&conf, "mgr5", 0, 1, 0x1F83, 0x80), "request guarding");
	zassert_false(br_allow_write(&conf, "mgr5", 0, 1, 0x1F25, 0x80), "configuration request");
	zassert_true(br_allow_write(&conf, "admin", 0, 1, 0x1F83, 0x80));
	/* Sub-index 80h of another object is only itself. */
	zassert_true(br_allow_write(&conf, "range", 1, 3, 0x2000, 0x80));
	zassert_true(br_allow_is_for_all_nodes(0x1F82, 0x80));
	zassert_false(br_allow_is_for_all_nodes(0x1F82, 0x7F));
	zassert_false(br_allow_is_for_all_nodes(0x1F81, 0x80));
}

ZTEST(bridge_conf, test_no_allow_list_is_read_only)
{
	zassert_false(br_allow_write(&conf, "admin", 0, 1, 0x2000, 0));
	zassert_false(br_allow_nmt(&conf, "admin", 0, 1, BR_CMD_START));
}

ZTEST(bridge_conf, test_client_name_and_commands)
{
	char name[16];

	br_client_name("ops@host:123", name, sizeof(name));
	zassert_str_equal(name, "ops");
	br_client_name("plain", name, sizeof(name));
	zassert_str_equal(name, "plain");
	br_client_name("a-rather-long-client-name@h", name, sizeof(name));
	zassert_str_equal(name, "a-rather-long-c", "cut to the buffer");
	zassert_equal(br_cmd_bit(0x01), BR_CMD_START);
	zassert_equal(br_cmd_bit(0x02), BR_CMD_STOP);
	zassert_equal(br_cmd_bit(0x80), BR_CMD_PREOP);
	zassert_equal(br_cmd_bit(0x81), BR_CMD_RESET);
	zassert_equal(br_cmd_bit(0x82), BR_CMD_RESET_COMM);
	zassert_equal(br_cmd_bit(0x03), 0);
}

/* bad_cases.txt: "conf|directive|message" or "allow|directive|message". */
ZTEST(bridge_conf, test_every_error_names_file_line_and_reason)
{
	FILE *f = fopen(CONF_TEST_DIR "/bad_cases.txt", "r");
	char line[256];
	int cases = 0;

	zassert_not_null(f);
	while (fgets(line, sizeof(line), f) != NULL) {
		char *kind = strtok(line, "|");
		char *directive = strtok(NULL, "|");
		char *message = strtok(NULL, "|\n");
		char log[2048];
		char path[512];
		char where[600];
		int err;

		zassert_not_null(message, "bad_cases.txt line %d", cases + 1);
		err = load_line(strcmp(kind, "allow") == 0, directive, log, sizeof(log), path,
				sizeof(path));
		(void)unlink(path);
		zassert_true(err == -EINVAL || err == -ENOENT, "'%s' accepted (%d)", directive,
			     err);
		(void)snprintf(where, sizeof(where), "%s:2: ", path);
		zassert_not_null(strstr(log, where), "'%s': no '%s' in: %s", directive, where, log);
		zassert_not_null(strstr(log, message), "'%s': no '%s' in: %s", directive, message,
				 log);
		cases++;
	}
	(void)fclose(f);
	zassert_true(cases >= 18, "%d cases", cases);
}

ZTEST(bridge_conf, test_limits_rules_and_objects)
{
	char log[1024];
	char path[512];
	FILE *f;

	(void)snprintf(path, sizeof(path), "/tmp/bridge_limits_%d.conf", getpid());
	f = fopen(path, "w");
	zassert_not_null(f);
	for (int i = 0; i < CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES + 1; i++) {
		(void)fprintf(f, "write c%d 0 1 2000\n", i);
	}
	(void)fclose(f);
	zassert_equal(captured(br_allow_load, path, log, sizeof(log)), -EINVAL);
	zassert_not_null(strstr(log, "more than CONFIG_CANOPEN_BRIDGE_DDS_ALLOW_RULES (8) rules"),
			 "%s", log);
	zassert_false(conf.allow, "a list with an error allows nothing");

	before(NULL);
	f = fopen(path, "w");
	zassert_not_null(f);
	for (int i = 0; i < CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS + 1; i++) {
		(void)fprintf(f, "object 0 1 %04x:00 100\n", 0x2000 + i);
	}
	(void)fclose(f);
	zassert_equal(captured(br_conf_load, path, log, sizeof(log)), -EINVAL);
	zassert_not_null(strstr(log, "more than CONFIG_CANOPEN_BRIDGE_DDS_OBJECTS (4) objects"),
			 "%s", log);
	(void)unlink(path);

	zassert_equal(captured(br_conf_load, "/nonexistent/bridge.conf", log, sizeof(log)),
		      -ENOENT);
	zassert_not_null(strstr(log, "/nonexistent/bridge.conf: cannot read"), "%s", log);
}
