/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * manager: a CiA 302 manager boots the network its DCF describes.
 *
 * The network comes from a DCF read at run time (--dcf FILE, default the bundled
 * objdict/manager.dcf; src/network.c): the manager's node-ID ([DeviceComissioning] NodeID),
 * the slaves assigned in 1F81h, their expected identity in 1F84h-1F88h, the boot time 1F89h,
 * heartbeat consumer entries in 1016h, 1F26h/1F27h, and each slave's concise DCF, the file its
 * 1F22h sub-index names. Its values are written into the manager's dictionary at every Reset
 * Communication, as stored parameters would be. The bundled network: hello_node slaves 2..5
 * (2 and 3 mandatory), each configured by slave.bin (scripts/dcf2cdcf of objdict/slave.dcf:
 * heartbeat 100 ms, setpoint 500, 1020h); node 5 is expected with another product code than
 * the one hello_node reports, so its boot ends with error M and the sample shows the report.
 *
 * By default hello_node slaves run in this process for the first assigned node-IDs (at most
 * four), each on its own line thread: the manager on line 0, the i-th slave on line i
 * (can_virtual0..4, one virtual bus; or SocketCAN with --can-if). --slaves=0 runs the manager
 * alone, for slaves in other processes.
 *
 * Output: one line per event as it happens (boot-ups, boot results, reported NMT states,
 * heartbeat losses), also during the boot, and the boot table when the NMT startup finishes.
 * Events reach the main thread through a message queue, so nothing is printed from a line
 * thread with a node lock held.
 *
 * --dds starts the Cyclone DDS bridge (doc/dds-bridge.md) on the manager's line: a second
 * terminal watches the network with scripts/safeline-dds watch.
 */

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <can_virtual.h>
#include <canopen/bridge_dds.h>
#include <canopen/cfg.h>
#include <canopen/line.h>
#include <canopen/mgr.h>
#include <canopen/node.h>

#include "cmdline.h"
#include "hello_node_od.h"
#include "manager_od.h"
#include "network.h"
#include "posix_native_task.h"
#include "sample_common.h"

LOG_MODULE_REGISTER(manager, LOG_LEVEL_INF);

#define MANAGER_ID 1U
#define MAX_SLAVES 4U
/* Options not given. */
#define NOT_GIVEN  UINT32_MAX

/*
 * The options, with their defaults. Each value is checked while the command line is parsed,
 * so that a bad one ends the process (usage, error, exit code 1) before the boot.
 */
static uint32_t slaves_arg = NOT_GIVEN;
static uint32_t cycle_arg = NOT_GIVEN;
static uint32_t cut_arg = NOT_GIVEN;
static char *dcf_arg;
static bool dds_arg;
static char *dds_config_arg;
static char *dds_allow_arg;
static uint32_t dds_domain_arg = CO_BRIDGE_DDS_DOMAIN_DEFAULT;
static char *dds_domain_text;

static void slaves_found(char *argv, int offset)
{
	slaves_arg = (uint32_t)cmd_read_uint_option("slaves", &argv[offset], 0U, MAX_SLAVES);
}

static void cycle_found(char *argv, int offset)
{
	cycle_arg = (uint32_t)cmd_read_uint_option("cycle", &argv[offset], 0U, 127U);
}

static void cut_found(char *argv, int offset)
{
	cut_arg = (uint32_t)cmd_read_uint_option("cut", &argv[offset], 0U, 127U);
}

static void dds_found(char *argv, int offset)
{
	dds_arg = true;
}

static void dds_domain_found(char *argv, int offset)
{
	dds_domain_arg = (uint32_t)cmd_read_uint_option("dds-domain", &argv[offset], 0U, 232U);
	dds_domain_text = &argv[offset];
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "dcf",
			.name = "file",
			.type = 's',
			.dest = &dcf_arg,
			.descript = "the network: the manager's DCF (1F81h slaves, 1F84h-1F89h, "
				    "1016h, 1F22h UploadFile= concise DCF per slave; default the "
				    "bundled objdict/manager.dcf)",
		},
		{
			.option = "slaves",
			.name = "0..4",
			.type = 'u',
			.call_when_found = slaves_found,
			.descript =
				"hello_node slaves run in this process for the first node-IDs "
				"the DCF assigns (lines 1..; default all of them, at most 4; 0 = "
				"the manager alone)",
		},
		{
			.option = "cycle",
			.name = "node",
			.type = 'u',
			.call_when_found = cycle_found,
			.descript = "power-cycle this in-process slave 1 s after the startup "
				    "(default the third in-process slave, 0 = none)",
		},
		{
			.option = "cut",
			.name = "node",
			.type = 'u',
			.call_when_found = cut_found,
			.descript =
				"cut this in-process slave off the virtual bus 2 s after the "
				"startup, for 1 s (default the second in-process slave, 0 = none)",
		},
		{
			.is_switch = true,
			.option = "dds",
			.type = 'b',
			.call_when_found = dds_found,
			.descript = "start the DDS bridge on the manager's line (loopback only; "
				    "watch it with scripts/safeline-dds watch)",
		},
		{
			.option = "dds-domain",
			.name = "0..232",
			.type = 'u',
			.call_when_found = dds_domain_found,
			.descript = "DDS domain of the bridge (default 42)",
		},
		{
			.option = "dds-config",
			.name = "file",
			.type = 's',
			.dest = &dds_config_arg,
			.descript =
				"Cyclone DDS configuration of the bridge instead of its loopback "
				"one (a deliberate choice: it may leave the host)",
		},
		{
			.option = "dds-allow",
			.name = "file|none",
			.type = 's',
			.dest = &dds_allow_arg,
			.descript =
				"the bridge's allow-list (default dds/allow.conf of the sample; "
				"none: read-only)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

/* The network (--dcf), the manager's node-ID and the in-process slaves, settled before boot. */
static struct network net;
static uint8_t manager_id;
static unsigned int n_slaves;
static unsigned int cycle_node;
static unsigned int cut_node;

static bool is_slave(uint32_t id)
{
	for (unsigned int i = 0; i < net.n_slaves; i++) {
		if (net.slaves[i] == id) {
			return true;
		}
	}
	return false;
}

static bool in_process(uint32_t id)
{
	for (unsigned int i = 0; i < n_slaves; i++) {
		if (net.slaves[i] == id) {
			return true;
		}
	}
	return false;
}

/* "2, 3, 4, 5": the slaves from the @p first-th on */
static void slave_list(char *buf, size_t len, unsigned int first)
{
	size_t n = 0;

	buf[0] = '\0';
	for (unsigned int i = first; i < net.n_slaves && n < len; i++) {
		int k = snprintf(buf + n, len - n, "%s%u", i == first ? "" : ", ", net.slaves[i]);

		n += k > 0 ? (size_t)k : 0U;
	}
}

static unsigned int demo_node(uint32_t arg, const char *option, unsigned int dflt_index)
{
	char value[16];

	if (arg == NOT_GIVEN) {
		return dflt_index < n_slaves ? net.slaves[dflt_index] : 0U;
	}
	if (arg != 0U && !in_process(arg)) {
		(void)snprintf(value, sizeof(value), "%u", arg);
		cmd_option_error(option, value, "not a slave of this process (--slaves, --dcf)");
	}
	return arg;
}

/*
 * Once the whole command line is parsed, still before the boot: read the DCF and try its
 * values on a scratch copy of the manager's dictionary, so a file the manager cannot serve
 * ends the process with the reason, not the boot.
 */
static void check_options(void)
{
	static struct manager_od_ram scratch_ram;
	static struct co_od scratch;
	const char *path = dcf_arg != NULL ? dcf_arg : MANAGER_DCF;
	const struct network_value *bad;
	char err[512], list[400];
	uint32_t ab;
	int id;

	/* These only configure the bridge: without it they would be silently ignored. */
	if (!dds_arg && dds_allow_arg != NULL) {
		cmd_option_error("dds-allow", dds_allow_arg, "needs --dds (the DDS bridge)");
	}
	if (!dds_arg && dds_config_arg != NULL) {
		cmd_option_error("dds-config", dds_config_arg, "needs --dds (the DDS bridge)");
	}
	if (!dds_arg && dds_domain_text != NULL) {
		cmd_option_error("dds-domain", dds_domain_text, "needs --dds (the DDS bridge)");
	}
	if (network_load(&net, path, err, sizeof(err)) != 0) {
		cmd_option_error("dcf", path, "%s", err);
	}
	id = sample_node_id(net.node_id != 0U ? net.node_id : MANAGER_ID);
	manager_id = (uint8_t)id;
	slave_list(list, sizeof(list), 0U);
	if (is_slave(manager_id)) {
		(void)snprintf(err, sizeof(err), "%d", id);
		cmd_option_error(sample_node_id(0) != 0 ? "node-id" : "dcf",
				 sample_node_id(0) != 0 ? err : path,
				 "%s:%u: node %d is a slave of the network (1F81h assigns %s)",
				 path, network_slave_line(&net, manager_id), id, list);
	}
	if (net.n_slaves > CONFIG_CANOPEN_MGR_SLAVES) {
		/* The line of the first slave that finds no slot. */
		cmd_option_error("dcf", path,
				 "%s:%u: 1F81h assigns %u slaves (%s); the manager has %d slave "
				 "slots (CONFIG_CANOPEN_MGR_SLAVES)",
				 path,
				 network_slave_line(&net, net.slaves[CONFIG_CANOPEN_MGR_SLAVES]),
				 net.n_slaves, list, CONFIG_CANOPEN_MGR_SLAVES);
	}
	if (co_od_init(&scratch, &manager_od_def, &scratch_ram, manager_id) != 0) {
		cmd_option_error("dcf", path, "the manager's dictionary cannot be set up");
	}
	co_od_reset_app(&scratch);
	co_od_reset_comm(&scratch);
	ab = network_apply(&net, &scratch, &bad);
	if (ab != 0U) {
		cmd_option_error("dcf", path,
				 "%s:%u: %04Xh:%02X = 0x%08X: refused by the manager's "
				 "dictionary (SDO abort %08X)",
				 path, bad->line, bad->index, bad->sub, bad->value, ab);
	}
	if (slaves_arg == NOT_GIVEN) {
		n_slaves = MIN(net.n_slaves, MAX_SLAVES);
	} else if (slaves_arg > net.n_slaves) {
		(void)snprintf(err, sizeof(err), "%u", slaves_arg);
		cmd_option_error("slaves", err, "the network has %u slaves (%s)", net.n_slaves,
				 list);
	} else {
		n_slaves = slaves_arg;
	}
	cycle_node = demo_node(cycle_arg, "cycle", 2U);
	cut_node = demo_node(cut_arg, "cut", 1U);
}
NATIVE_TASK(check_options, PRE_BOOT_2, 21);

struct slave {
	struct co_line line;
	struct co_node node;
	struct hello_node_od_ram ram;
	char line_name[8];
	char node_name[12];
};

static struct slave slaves[MAX_SLAVES];
static K_THREAD_STACK_ARRAY_DEFINE(slave_stacks, MAX_SLAVES, CONFIG_CANOPEN_LINE_STACK_SIZE);

static struct co_line mline;
static struct co_node mgr;
static struct manager_od_ram mram;
static struct co_cfg cfg;
static K_THREAD_STACK_DEFINE(mline_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* --- Events: line threads -> main thread ------------------------------------------------- */

enum ev_kind {
	EV_STARTUP,
	EV_BOOT,
	EV_EC,
	EV_OWN_STATE,
	EV_HB,
};

struct event {
	uint64_t t_us;
	struct co_mgr_boot_error err;
	uint8_t kind;
	uint8_t id;
	uint8_t status; /* EV_BOOT: letter; EV_STARTUP: enum co_mgr_startup */
	uint8_t ec;     /* enum co_mgr_ec_event, or enum co_hb_event for EV_HB */
	uint8_t state;  /* enum co_nmt_state */
	bool has_err;
};

K_MSGQ_DEFINE(events, sizeof(struct event), 64, 8);
static atomic_t events_lost;

static void post(struct event *ev)
{
	ev->t_us = co_line_time(&mline);
	if (k_msgq_put(&events, ev, K_NO_WAIT) != 0) {
		atomic_inc(&events_lost);
	}
}

/* Indications: manager line thread, manager lock held; they only queue. */
static void on_boot(struct co_node *node, uint8_t id, uint8_t status,
		    const struct co_mgr_boot_error *err, void *user_data)
{
	struct event ev = {.kind = EV_BOOT, .id = id, .status = status, .has_err = err != NULL};

	if (err != NULL) {
		ev.err = *err;
	}
	post(&ev);
}

static void on_startup(struct co_node *node, enum co_mgr_startup result,
		       const struct co_mgr_boot_error *err, void *user_data)
{
	struct event ev = {.kind = EV_STARTUP, .status = (uint8_t)result, .has_err = err != NULL};

	if (err != NULL) {
		ev.err = *err;
	}
	post(&ev);
}

static void on_ec(struct co_node *node, uint8_t id, enum co_mgr_ec_event event,
		  enum co_nmt_state state, void *user_data)
{
	struct event ev = {.kind = EV_EC, .id = id, .ec = (uint8_t)event, .state = (uint8_t)state};

	post(&ev);
}

/*
 * The CiA 301 heartbeat consumer of the manager (1016h) reports the states the slaves send.
 * The manager's own indication covers boot-ups and losses; its state view also follows the
 * commands it sends, so the states come from here.
 */
static void on_hb(struct co_node *node, uint8_t id, enum co_hb_event event, enum co_nmt_state state,
		  void *user_data)
{
	struct event ev = {.kind = EV_HB, .id = id, .ec = (uint8_t)event, .state = (uint8_t)state};

	/* Losses are the manager's (on_ec). */
	if (event == CO_HB_EV_STARTED || event == CO_HB_EV_STATE || event == CO_HB_EV_RECOVERED) {
		post(&ev);
	}
}

static int on_own_state(struct co_node *node, enum co_nmt_state from, enum co_nmt_state to,
			void *user_data)
{
	struct event ev = {.kind = EV_OWN_STATE, .id = co_node_id(node), .state = (uint8_t)to};

	post(&ev);
	return 0;
}

/* --- Printing ------------------------------------------------------------------------------ */

static const char *status_text(uint8_t st)
{
	switch (st) {
	case CO_MGR_ST_A:
		return "not in the network list 1F81h";
	case CO_MGR_ST_B:
		return "no answer to the 1000h upload";
	case CO_MGR_ST_C:
		return "device type differs (1F84h)";
	case CO_MGR_ST_D:
		return "vendor-ID differs (1F85h)";
	case CO_MGR_ST_E:
		return "no heartbeat (check NMT state)";
	case CO_MGR_ST_F:
		return "no node-guarding reply (check NMT state)";
	case CO_MGR_ST_G:
		return "software version objects not configured";
	case CO_MGR_ST_H:
		return "software update needed, not allowed";
	case CO_MGR_ST_I:
		return "software update failed";
	case CO_MGR_ST_J:
		return "configuration download failed";
	case CO_MGR_ST_K:
		return "no heartbeat in start error control";
	case CO_MGR_ST_L:
		return "was already operational";
	case CO_MGR_ST_M:
		return "product code differs (1F86h)";
	case CO_MGR_ST_N:
		return "revision differs (1F87h)";
	case CO_MGR_ST_O:
		return "serial number differs (1F88h)";
	default:
		return "?";
	}
}

static void result_str(uint8_t st, char *buf, size_t len)
{
	if (st == CO_MGR_ST_OK) {
		snprintf(buf, len, "OK");
	} else if (st == CO_MGR_ST_NONE) {
		snprintf(buf, len, "-");
	} else {
		snprintf(buf, len, "%c", st);
	}
}

/*
 * "product code differs (1F86h), step PRODUCT, 1018h:02 expected ... actual ...": expected and
 * actual only where the manager compared a value it read; B, J, ... name the object alone.
 */
static void error_str(const struct co_mgr_boot_error *e, char *buf, size_t len)
{
	int n = snprintf(buf, len, "%s, step %s", status_text(e->status), co_mgr_step_str(e->step));

	if (e->index != 0U && n > 0 && (size_t)n < len) {
		if (co_mgr_error_compared(e)) {
			n += snprintf(buf + n, len - n, ", %04Xh:%02X expected %08X actual %08X",
				      e->index, e->sub, e->expected, e->actual);
		} else {
			n += snprintf(buf + n, len - n, ", %04Xh:%02X", e->index, e->sub);
		}
	}
	if (e->abort_code != 0U && n > 0 && (size_t)n < len) {
		(void)snprintf(buf + n, len - n, ", SDO abort %08X", e->abort_code);
	}
}

static void ident_str(const struct co_mgr_boot_info *b, int i, char *buf, size_t len)
{
	/* read_mask bit 0: 1000h, bits 1..4: 1018h:01..04 */
	if ((b->read_mask & BIT(i + 1)) != 0U) {
		snprintf(buf, len, "%08X", b->identity[i]);
	} else {
		snprintf(buf, len, "%-8s", "-");
	}
}

static void print_table(void)
{
	static const char rule[] = "  ----  ---------  --------  --------  --------  ------  "
				   "---------  ------------------------------";

	printk("\n  node  role       vendor    product   revision  result  boot time  details\n");
	printk("%s\n", rule);
	/* Row by row (co_mgr_get_boot() locks): no console output with the manager locked. */
	for (unsigned int id = 1; id <= 127U; id++) {
		struct co_mgr_boot_info b;
		char v[12], p[12], r[12], res[4], det[160] = "";
		char ms[16] = "-";

		if (co_mgr_get_boot(&mgr, (uint8_t)id, &b) != 0 || !b.assigned) {
			continue;
		}
		ident_str(&b, 0, v, sizeof(v));
		ident_str(&b, 1, p, sizeof(p));
		ident_str(&b, 2, r, sizeof(r));
		result_str(b.status, res, sizeof(res));
		if (b.status != CO_MGR_ST_NONE && b.finished_us >= b.started_us) {
			snprintf(ms, sizeof(ms), "%.1f ms",
				 (double)(b.finished_us - b.started_us) / 1e3);
		}
		if (b.status != CO_MGR_ST_OK && b.status != CO_MGR_ST_NONE) {
			error_str(&b.error, det, sizeof(det));
		} else if (b.status == CO_MGR_ST_NONE) {
			if (b.booting) {
				snprintf(det, sizeof(det), "booting (attempt %u)", b.attempts);
			} else {
				snprintf(det, sizeof(det), "not booted");
			}
		}
		printk("  %4u  %-9s  %s  %s  %s  %-6s  %9s%s%s\n", id,
		       b.mandatory ? "mandatory" : "optional", v, p, r, res, ms,
		       det[0] != '\0' ? "  " : "", det);
	}
	printk("%s\n\n", rule);
}

static const char *ec_text(uint8_t ec)
{
	switch (ec) {
	case CO_MGR_EC_BOOTUP:
		return "boot-up";
	case CO_MGR_EC_HB_LOST:
		return "heartbeat lost";
	case CO_MGR_EC_GUARD_LOST:
		return "node guarding lost";
	default:
		return "state";
	}
}

static bool booted_ok(uint8_t id)
{
	struct co_mgr_boot_info b;

	return co_mgr_get_boot(&mgr, id, &b) == 0 && b.status == CO_MGR_ST_OK;
}

static void print_event(const struct event *ev, uint64_t start_us)
{
	double t = (double)(ev->t_us - start_us) / 1e6;
	char det[160];

	switch (ev->kind) {
	case EV_BOOT:
		if (ev->status == CO_MGR_ST_OK) {
			printk("[%8.3f s] node %3u  booted OK\n", t, ev->id);
		} else {
			error_str(&ev->err, det, sizeof(det));
			printk("[%8.3f s] node %3u  boot failed: %c, %s\n", t, ev->id, ev->status,
			       det);
		}
		break;
	case EV_EC:
		/* States are printed from the heartbeats (EV_HB). */
		if (ev->ec != CO_MGR_EC_STATE) {
			printk("[%8.3f s] node %3u  %s\n", t, ev->id, ec_text(ev->ec));
		}
		break;
	case EV_HB:
		if (ev->ec != CO_HB_EV_RECOVERED) {
			printk("[%8.3f s] node %3u  %s\n", t, ev->id,
			       co_nmt_state_str((enum co_nmt_state)ev->state));
		} else if (booted_ok(ev->id)) {
			/*
			 * Only for slaves the manager supervises: a slave it did not configure
			 * (node 5) keeps its own heartbeat period, longer than 1016h expects.
			 */
			printk("[%8.3f s] node %3u  heartbeat back (%s)\n", t, ev->id,
			       co_nmt_state_str((enum co_nmt_state)ev->state));
		}
		break;
	case EV_OWN_STATE:
		printk("[%8.3f s] node %3u  %s (manager)\n", t, ev->id,
		       co_nmt_state_str((enum co_nmt_state)ev->state));
		break;
	default:
		break;
	}
}

/* --- Demo: what happens to the network after the startup ------------------------------------ */

enum demo_action {
	DEMO_CYCLE,
	DEMO_CUT,
	DEMO_RESTORE,
	DEMO_COUNT,
};

/* When, in ms after the startup (in this order). */
static const int64_t demo_at_ms[DEMO_COUNT] = {1000, 2000, 3000};

static bool on_virtual_bus(const struct device *dev)
{
	return strncmp(dev->name, "can_virtual", 11) == 0;
}

static struct slave *slave_of(unsigned int id)
{
	for (unsigned int i = 0; i < n_slaves; i++) {
		if (net.slaves[i] == id) {
			return &slaves[i];
		}
	}
	return NULL;
}

static void demo(enum demo_action a, unsigned int cycle, unsigned int cut, uint64_t start_us)
{
	double t = (double)(co_line_time(&mline) - start_us) / 1e6;

	switch (a) {
	case DEMO_CYCLE:
		if (cycle != 0U) {
			/* A slave that loses power and comes back: the boot-up handler boots it. */
			printk("[%8.3f s] node %3u  power-cycled (local Reset node)\n", t, cycle);
			(void)co_nmt_req(&slave_of(cycle)->node, CO_NMT_CS_RESET_NODE);
		}
		break;
	case DEMO_CUT:
		if (cut != 0U) {
			/*
			 * Its heartbeat stops: the error handler resets it (1F81h bit 3, 1F80h bits
			 * 4 and 6 clear) and, without a boot-up, boots it again a while later.
			 */
			printk("[%8.3f s] node %3u  cut off the bus\n", t, cut);
			(void)can_virtual_cut(slave_of(cut)->line.dev);
		}
		break;
	case DEMO_RESTORE:
		if (cut != 0U) {
			printk("[%8.3f s] node %3u  back on the bus\n", t, cut);
			(void)can_virtual_restore(slave_of(cut)->line.dev);
		}
		break;
	default:
		break;
	}
}

/* --- DDS bridge (--dds) --------------------------------------------------------------------- */

/*
 * The SDO client of the manager that serves the bridge's requests: the first above the slave
 * slots (1F25h requests take the highest idle client first, so they use client 9).
 */
#define DDS_SDO_CLIENT CONFIG_CANOPEN_MGR_SLAVES
#define DATA_INDEX     0x2100U
#define DATA_CAPACITY  (128U * 1024U)

/*
 * With --dds the in-process slaves serve hello_node's 2100h data buffer (DOMAIN, up to
 * 128 KiB) as the hello_node sample does, so that large SDO transfers can go through the
 * bridge. Chunks stream into a shadow that becomes the value when the last one arrived.
 */
struct data_buf {
	uint8_t value[DATA_CAPACITY];
	uint8_t shadow[DATA_CAPACITY];
	uint32_t len;
	uint32_t shadow_len;
};

static struct data_buf data_bufs[MAX_SLAVES];

static uint32_t data_info(const struct co_od_provider *p, struct co_od_info *info)
{
	if (info->sub != 0U) {
		return CO_SDO_AB_NO_SUB;
	}
	info->dtype = CO_DTYPE_DOMAIN;
	info->access = CO_OD_ACCESS_RW;
	info->flags = CO_OD_F_STREAM;
	info->objcode = CO_OD_OBJ_VAR;
	info->size = DATA_CAPACITY;
	return 0;
}

static uint32_t data_length(const struct co_od_provider *p, const struct co_od_info *info)
{
	return ((struct data_buf *)p->user_data)->len;
}

static uint32_t data_read(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, void *buf, size_t cap, size_t *len)
{
	struct data_buf *d = p->user_data;
	size_t n = 0;

	if (offset < d->len) {
		n = MIN(cap, (size_t)(d->len - offset));
		memcpy(buf, &d->value[offset], n);
	}
	*len = n;
	return 0;
}

static uint32_t data_write(const struct co_od_provider *p, const struct co_od_info *info,
			   uint32_t offset, const void *data, size_t len, bool last)
{
	struct data_buf *d = p->user_data;

	if (data == NULL) {
		d->shadow_len = 0U;
		return 0;
	}
	if (offset == 0U) {
		d->shadow_len = 0U;
	}
	if (offset != d->shadow_len || len > DATA_CAPACITY - offset) {
		return CO_SDO_AB_DATA_LONG;
	}
	memcpy(&d->shadow[offset], data, len);
	d->shadow_len = offset + (uint32_t)len;
	if (last) {
		memcpy(d->value, d->shadow, d->shadow_len);
		d->len = d->shadow_len;
	}
	return 0;
}

static const struct co_od_provider_api data_api = {
	.info = data_info,
	.length = data_length,
	.read = data_read,
	.write = data_write,
};

static struct co_od_provider data_providers[MAX_SLAVES];

#if defined(CONFIG_CANOPEN_BRIDGE_DDS)
/* The bridge: started before the nodes, so it sees the whole boot. */
static int dds_start(void)
{
	const char *allow = MANAGER_DDS_DIR "/allow.conf";
	struct co_bridge_dds_config cfg = {
		.name = "manager",
		.domain_id = dds_domain_arg,
		.dds_config = dds_config_arg,
		.config_file = MANAGER_DDS_DIR "/bridge.conf",
	};
	int err;

	if (dds_allow_arg != NULL) {
		allow = strcmp(dds_allow_arg, "none") == 0 ? NULL : dds_allow_arg;
	}
	cfg.allow_file = allow;
	err = co_bridge_dds_init(&cfg);
	if (err != 0) {
		LOG_ERR("DDS bridge failed to start (%d)", err);
	}
	return err;
}

/* The manager's line and the manager; the slaves are seen through the manager. */
static int dds_attach(void)
{
	struct co_bridge_dds_node_config ncfg = {.name = "manager", .sdo_client = DDS_SDO_CLIENT};
	int err = co_bridge_dds_add_line(&mline, 0U, "line0");

	if (err == 0) {
		err = co_bridge_dds_add_node(&mgr, &ncfg);
	}
	if (err != 0) {
		LOG_ERR("DDS bridge: cannot follow the manager (%d)", err);
	}
	return err;
}

static void dds_stop(void)
{
	co_bridge_dds_stop();
}
NATIVE_TASK(dds_stop, ON_EXIT, 10);
#else
static int dds_start(void)
{
	LOG_ERR("--dds: built without CONFIG_CANOPEN_BRIDGE_DDS");
	return -ENOTSUP;
}

static int dds_attach(void)
{
	return -ENOTSUP;
}
#endif

/* --- Set-up -------------------------------------------------------------------------------- */

static int start_slave(unsigned int i)
{
	struct slave *s = &slaves[i];
	const struct device *can = sample_line_device(i + 1U);
	int err;

	if (can == NULL) {
		LOG_ERR("no CAN controller for line %u", i + 1U);
		return -ENODEV;
	}
	(void)snprintf(s->line_name, sizeof(s->line_name), "line%u", i + 1U);
	(void)snprintf(s->node_name, sizeof(s->node_name), "slave%u", net.slaves[i]);
	err = co_line_init(&s->line, s->line_name, can);
	if (err == 0) {
		err = co_node_init(&s->node, s->node_name, &s->line, &hello_node_od_def, &s->ram,
				   net.slaves[i]);
	}
	if (err == 0 && dds_arg) {
		data_providers[i] = (struct co_od_provider){
			.api = &data_api,
			.index_first = DATA_INDEX,
			.index_last = DATA_INDEX,
			.user_data = &data_bufs[i],
		};
		err = co_od_provider_register(co_node_od(&s->node), &data_providers[i]);
	}
	if (err == 0) {
		err = co_line_start(&s->line, slave_stacks[i],
				    K_THREAD_STACK_SIZEOF(slave_stacks[i]),
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&s->node);
	}
	return err;
}

/*
 * The DCF's values go into the manager's dictionary at every Reset Communication, after the
 * defaults, as stored parameters would (the sample has no storage of its own).
 */
static void restore_network(struct co_od *od, uint32_t group_mask, void *user_data)
{
	const struct network_value *bad;
	uint32_t ab;

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	ab = network_apply(&net, od, &bad);
	if (ab != 0U) {
		LOG_ERR("%s:%u: %04Xh:%02X refused (%08X)", net.path, bad->line, bad->index,
			bad->sub, ab);
	}
}

static int start_manager(uint8_t id)
{
	const struct device *can = sample_line_device(0);
	int err;

	if (can == NULL) {
		LOG_ERR("no CAN controller for line 0");
		return -ENODEV;
	}
	err = co_line_init(&mline, "line0", can);
	if (err == 0) {
		err = co_node_init(&mgr, "manager", &mline, &manager_od_def, &mram, id);
	}
	if (err == 0) {
		err = co_cfg_init(&cfg, &mgr);
	}
	/* Each slave's concise DCF: the file its 1F22h sub-index names. */
	for (unsigned int n = 1; err == 0 && n <= 127U; n++) {
		if (net.cdcf[n] != NULL) {
			err = co_cfg_set_concise_dcf(&cfg, (uint8_t)n, net.cdcf[n],
						     net.cdcf_size[n]);
		}
	}
	if (err == 0) {
		co_node_lock(&mgr);
		err = co_od_set_restore_cb(co_node_od(&mgr), restore_network, NULL);
		co_node_unlock(&mgr);
	}
	if (err != 0) {
		return err;
	}
	co_mgr_set_boot_ind(&mgr, on_boot, NULL);
	co_mgr_set_startup_ind(&mgr, on_startup, NULL);
	co_mgr_set_ec_ind(&mgr, on_ec, NULL);
	co_hb_set_ind(&mgr, on_hb, NULL);
	co_nmt_set_state_ind(&mgr, on_own_state, NULL);
	if (dds_arg && dds_attach() != 0) {
		return -EIO;
	}
	err = co_line_start(&mline, mline_stack, K_THREAD_STACK_SIZEOF(mline_stack),
			    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	if (err == 0) {
		/* The NMT startup runs by itself from 1F80h in the manager's line thread. */
		err = co_node_start(&mgr);
	}
	printk("manager: node %u on %s\n", id, can->name);
	return err;
}

int main(void)
{
	unsigned int cycle = cycle_node;
	unsigned int cut = cut_node;
	unsigned int next = DEMO_COUNT; /* next demo action; DEMO_COUNT: none pending */
	int64_t done_ms = 0;
	uint64_t start_us;
	struct event ev;
	char list[400];
	int err;

	if (cut != 0U &&
	    !on_virtual_bus(sample_line_device((unsigned int)(slave_of(cut) - slaves) + 1U))) {
		cut = 0U; /* only a slave on the virtual bus can be cut */
	}
	printk("manager: network %s\n", net.path);

	if (dds_arg && dds_start() != 0) {
		return 1;
	}
	/* Slaves first, so they are on the bus when the manager resets them. */
	for (unsigned int i = 0; i < n_slaves; i++) {
		err = start_slave(i);
		if (err != 0) {
			LOG_ERR("slave %u failed to start (%d)", net.slaves[i], err);
			return 1;
		}
		printk("manager: slave %u (hello_node) on %s\n", net.slaves[i],
		       slaves[i].line.dev->name);
	}
	slave_list(list, sizeof(list), n_slaves);
	if (n_slaves < net.n_slaves) {
		printk("manager: %s slaves in this process; waiting for nodes %s on the bus\n",
		       n_slaves == 0U ? "no" : "not all", list);
	}
	start_us = co_line_time(&mline);
	err = start_manager(manager_id);
	if (err != 0) {
		LOG_ERR("manager failed to start (%d)", err);
		return 1;
	}
	sample_print_stats_on_exit("manager", &mline);

	for (;;) {
		k_timeout_t wait = next < DEMO_COUNT ? K_TIMEOUT_ABS_MS(done_ms + demo_at_ms[next])
						     : K_FOREVER;

		if (k_msgq_get(&events, &ev, wait) != 0) {
			demo((enum demo_action)next, cycle, cut, start_us);
			next++;
			continue;
		}
		if (ev.kind == EV_STARTUP) {
			double ms = (double)(ev.t_us - start_us) / 1e3;

			print_table();
			if (ev.status == CO_MGR_STARTUP_DONE) {
				printk("manager: NMT startup DONE in %.1f ms, manager %s\n", ms,
				       co_nmt_state_str(co_nmt_get_state(&mgr)));
			} else {
				char det[160];

				error_str(&ev.err, det, sizeof(det));
				printk("manager: NMT startup HALTED after %.1f ms: node %u failed "
				       "with %c (%s)\n",
				       ms, ev.err.node_id, ev.err.status, det);
			}
			done_ms = k_uptime_get();
			next = 0;
			continue;
		}
		/* Also during the boot: a slave that never reports Operational shows it. */
		print_event(&ev, start_us);
		if (atomic_get(&events_lost) != 0) {
			printk("manager: %ld events lost (queue full)\n",
			       (long)atomic_set(&events_lost, 0));
		}
	}
	return 0;
}
