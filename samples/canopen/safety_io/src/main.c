/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * safety_io: a safety sensor and a safety controller talking CiA 304 SRDOs.
 *
 * - The sensor (node 5, line 1) produces SRDO 1 every 20 ms on its default COB-IDs 109h/10Ah:
 *   a two-channel input, channel A in 6000h (emergency stop pressed, input counter) and
 *   channel B, its bitwise complement, in 6001h. The application writes both channels under
 *   the node's mutex; the stack samples them into the normal and the inverted frame.
 * - The controller (node 1, line 0) consumes SRDO 1 (SCT 50 ms, SRVT 10 ms) into its own
 *   6000h/6001h and drives its output 2000h only while co_srdo_may_leave_safe_state() is true
 *   and the emergency stop is released on both channels. It is also a minimal NMT master: it
 *   starts the sensor, then itself.
 * - Faults are injected into the virtual bus (can_virtual.h) right after a valid pair reached
 *   the controller, so they hit the next pair: drop or corrupt a frame, delay the inverted
 *   frame, or make the producer go silent. The controller prints each transition of its SRDO
 *   with the reason and the time since the fault, then recovers by going through
 *   Pre-operational back to Operational.
 *
 * With --can-if only the nodes whose line is on SocketCAN run (both: they talk over the
 * interface), and no fault is injected: a foreign producer or consumer plays the other side.
 *
 * Everything the line threads report reaches the main thread through a message queue, so
 * nothing is printed from a line thread with a node's mutex held.
 */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zephyr/device.h>
#include <zephyr/kernel.h>
#include <zephyr/logging/log.h>

#include <can_virtual.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/node.h>
#include <canopen/srdo.h>

#include "cmdline.h"
#include "controller_od.h"
#include "posix_native_task.h"
#include "sample_common.h"
#include "sensor_od.h"

LOG_MODULE_REGISTER(safety_io, LOG_LEVEL_INF);

#define CONTROLLER_ID 1U
#define SENSOR_ID     5U
#define SRDO_NO       1U
/* SRDO 1's default COB-IDs of the sensor: FFh/100h + 2 x node-ID (CiA 304). */
#define COB_NORMAL    (CO_SRDO_COB1_BASE + 2U * SENSOR_ID)
#define COB_INVERTED  (CO_SRDO_COB2_BASE + 2U * SENSOR_ID)
#define FRAME_BYTES   2U /* per frame: emergency stop, counter */

#define IDX_CHAN_A 0x6000U
#define IDX_CHAN_B 0x6001U
#define IDX_OUTPUT 0x2000U

#define LOOP_MS         10
#define COUNT_EVERY_MS  100  /* the input counter's step */
#define ESTOP_PERIOD_MS 8000 /* the emergency stop is pressed ... */
#define ESTOP_HELD_MS   1000 /* ... for the last second of every period */
#define MASTER_WAIT_MS  100  /* between starting the sensor and the controller */
#define TOLERATE_MS     500  /* a fault not detected within this was tolerated */
#define PAIR_WAIT_MS    200  /* for the valid pair a fault is injected after */

enum fault {
	F_NONE,
	F_DROP_NORMAL,
	F_DROP_INVERTED,
	F_CORRUPT_NORMAL,
	F_CORRUPT_INVERTED,
	F_DELAY_INVERTED,
	F_STOP_PRODUCER,
	F_COUNT,
};

static const char *const fault_names[F_COUNT] = {
	"none",           "drop-normal",   "drop-inverted", "corrupt-normal", "corrupt-inverted",
	"delay-inverted", "stop-producer",
};

/* --- Options -------------------------------------------------------------------------------- */

#define MAX_FAULTS 16

/* Checked while the command line is parsed (usage, error, exit code 1 before the boot). */
static struct {
	uint8_t faults[MAX_FAULTS];
	uint8_t n_faults;
	bool faults_given;
	double fault_at_s;
	double recover_s;
	uint32_t count;
	uint32_t byte;
	uint32_t bit;
	uint32_t delay_ms;
} opt = {
	.fault_at_s = 1.0,
	.recover_s = 1.0,
	.count = 1U,
	.byte = 0U,
	.bit = 0U,
	.delay_ms = 15U,
};

static void fault_found(char *argv, int offset)
{
	const char *value = &argv[offset];
	int f;

	for (f = 0; f < F_COUNT && strcmp(value, fault_names[f]) != 0; f++) {
	}
	if (f == F_COUNT) {
		cmd_option_error("fault", value,
				 "expected none, drop-normal, drop-inverted, corrupt-normal, "
				 "corrupt-inverted, delay-inverted or stop-producer");
	}
	if (f != F_NONE && opt.n_faults == MAX_FAULTS) {
		cmd_option_error("fault", value, "at most %d faults per run", MAX_FAULTS);
	}
	opt.faults_given = true;
	if (f != F_NONE) {
		opt.faults[opt.n_faults++] = (uint8_t)f;
	}
}

static void fault_at_found(char *argv, int offset)
{
	opt.fault_at_s = cmd_read_double_option("fault-at", &argv[offset], 0.0, 3600.0);
}

static void recover_found(char *argv, int offset)
{
	opt.recover_s = cmd_read_double_option("recover-after", &argv[offset], 0.0, 3600.0);
}

static void count_found(char *argv, int offset)
{
	opt.count = (uint32_t)cmd_read_uint_option("count", &argv[offset], 1U, 1000U);
}

static void byte_found(char *argv, int offset)
{
	opt.byte = (uint32_t)cmd_read_uint_option("byte", &argv[offset], 0U, FRAME_BYTES - 1U);
}

static void bit_found(char *argv, int offset)
{
	opt.bit = (uint32_t)cmd_read_uint_option("bit", &argv[offset], 0U, 7U);
}

static void delay_found(char *argv, int offset)
{
	opt.delay_ms = (uint32_t)cmd_read_uint_option("delay", &argv[offset], 1U, 1000U);
}

static void add_options(void)
{
	static struct args_struct_t opts[] = {
		{
			.option = "fault",
			.name = "kind",
			.type = 's',
			.call_when_found = fault_found,
			.descript = "inject this fault on the virtual bus (repeatable, in order): "
				    "drop-normal, drop-inverted, corrupt-normal, corrupt-inverted, "
				    "delay-inverted, stop-producer, or none. Default: each once",
		},
		{
			.option = "fault-at",
			.name = "seconds",
			.type = 'd',
			.call_when_found = fault_at_found,
			.descript = "inject each fault this long after the SRDO is valid "
				    "(default 1)",
		},
		{
			.option = "recover-after",
			.name = "seconds",
			.type = 'd',
			.call_when_found = recover_found,
			.descript = "this long after a detected fault the controller goes "
				    "Pre-operational, then Operational (default 1; 0: it stays in "
				    "the safe state and the run injects no further fault)",
		},
		{
			.option = "count",
			.name = "frames",
			.type = 'u',
			.call_when_found = count_found,
			.descript = "frames each drop, corruption or delay affects (1..1000, "
				    "default 1)",
		},
		{
			.option = "byte",
			.name = "0..1",
			.type = 'u',
			.call_when_found = byte_found,
			.descript = "byte a corruption flips a bit of (default 0)",
		},
		{
			.option = "bit",
			.name = "0..7",
			.type = 'u',
			.call_when_found = bit_found,
			.descript = "bit a corruption flips (default 0)",
		},
		{
			.option = "delay",
			.name = "ms",
			.type = 'u',
			.call_when_found = delay_found,
			.descript = "how late delay-inverted delivers the inverted frame (1..1000, "
				    "default 15; the SRVT is 10)",
		},
		ARG_TABLE_ENDMARKER,
	};

	native_add_command_line_opts(opts);
}
NATIVE_TASK(add_options, PRE_BOOT_1, 21);

/* Lines named with --can-if (bit n: line n), from the whole command line. */
static uint32_t can_if_lines(void)
{
	uint32_t lines = 0U;
	char **argv;
	int argc;

	native_get_cmd_line_args(&argc, &argv);
	for (int i = 1; i < argc; i++) {
		int offset = cmd_is_option(argv[i], "can-if", 1);

		if (strcmp(argv[i], "--testargs") == 0 || strcmp(argv[i], "-testargs") == 0) {
			break;
		}
		if (offset > 0) {
			/* The SocketCAN driver has checked "<line>:<ifname>" already. */
			lines |= BIT(strtoul(&argv[i][offset], NULL, 10) & 31U);
		}
	}
	return lines;
}

static bool controller_runs(uint32_t lines)
{
	return lines == 0U || (lines & BIT(0)) != 0U;
}

static bool sensor_runs(uint32_t lines)
{
	return lines == 0U || (lines & BIT(1)) != 0U;
}

/* Options against each other, once the command line is parsed, still before the boot. */
static void check_options(void)
{
	uint32_t lines = can_if_lines();
	int id = sample_node_id(CONTROLLER_ID);
	char value[8];

	if (lines != 0U && opt.n_faults > 0U) {
		cmd_option_error("fault", fault_names[opt.faults[0]],
				 "faults are injected into the virtual bus, not with --can-if");
	}
	if (controller_runs(lines) && sensor_runs(lines) && id == (int)SENSOR_ID) {
		(void)snprintf(value, sizeof(value), "%d", id);
		cmd_option_error("node-id", value, "%u is the sensor's node-ID", SENSOR_ID);
	}
	if (!opt.faults_given && lines == 0U) {
		/* The default run: every fault once. */
		for (int f = F_NONE + 1; f < F_COUNT; f++) {
			opt.faults[opt.n_faults++] = (uint8_t)f;
		}
	}
}
NATIVE_TASK(check_options, PRE_BOOT_2, 21);

/* --- Nodes ---------------------------------------------------------------------------------- */

struct unit {
	const char *name;
	struct co_line line;
	struct co_node node;
	struct co_listener listener;
	const struct device *can;
	bool runs;
	/* Under the node's mutex (listener, hook, main thread). */
	uint64_t op_us;        /* Operational entered */
	uint64_t last_pair_us; /* last valid pair received (controller); 0: none since op_us */
	uint64_t fault_us;     /* a fault injected (controller); 0: none pending */
};

static struct unit controller = {.name = "controller"};
static struct unit sensor = {.name = "sensor"};
static struct controller_od_ram controller_ram;
static struct sensor_od_ram sensor_ram;
static K_THREAD_STACK_DEFINE(controller_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);
static K_THREAD_STACK_DEFINE(sensor_stack, CONFIG_CANOPEN_LINE_STACK_SIZE);

/* What a line thread saw, as the main thread prints it. */
struct app_event {
	struct unit *unit;
	enum co_event_type type;
	enum co_nmt_state state;
	uint8_t srdo;
	uint8_t reason;
	bool safe;
	int srdo_state; /* enum co_srdo_state when the event was raised */
	uint64_t time_us;
	uint64_t op_us;
	uint64_t last_pair_us;
	uint64_t fault_us;
};

K_MSGQ_DEFINE(events, sizeof(struct app_event), 64, 8);
static atomic_t events_lost;
/* Given after every valid pair the controller received. */
static K_SEM_DEFINE(pair_sem, 0, 1);

static int on_event(struct co_node *node, const struct co_event *ev, void *user_data)
{
	struct unit *u = user_data;
	struct app_event e = {.unit = u, .type = ev->type};

	if (ev->type == CO_EV_NMT_STATE) {
		e.state = ev->nmt.to;
		e.time_us = co_node_time(node);
		if (ev->nmt.to == CO_NMT_OPERATIONAL) {
			u->op_us = e.time_us;
			u->last_pair_us = 0U;
		}
	} else {
		e.srdo = ev->srdo.srdo;
		e.reason = ev->srdo.reason;
		e.safe = ev->srdo.safe;
		e.srdo_state = ev->srdo.srdo != 0U ? co_srdo_get_state(node, ev->srdo.srdo, NULL)
						   : -EINVAL;
		e.time_us = ev->srdo.time_us;
	}
	e.op_us = u->op_us;
	e.last_pair_us = u->last_pair_us;
	e.fault_us = u->fault_us;
	if (k_msgq_put(&events, &e, K_NO_WAIT) != 0) {
		atomic_inc(&events_lost);
	}
	/* A deleted SRDO reports no events: say so when Operational starts without it. */
	if (ev->type == CO_EV_NMT_STATE && ev->nmt.to == CO_NMT_OPERATIONAL &&
	    co_srdo_get_state(node, SRDO_NO, NULL) == CO_SRDO_STATE_DELETED) {
		e.type = CO_EV_SRDO;
		e.srdo = SRDO_NO;
		e.safe = false;
		e.reason = CO_SRDO_R_NONE;
		e.srdo_state = CO_SRDO_STATE_DELETED;
		if (k_msgq_put(&events, &e, K_NO_WAIT) != 0) {
			atomic_inc(&events_lost);
		}
	}
	return 0;
}

/* The controller's SRDO consumer wrote its objects: a valid pair arrived. */
static void pair_notify(struct co_od *od, const struct co_od_req *req, void *user_data)
{
	struct unit *u = user_data;

	if (req->writer == CO_OD_WRITER_SRDO) {
		u->last_pair_us = co_node_time(&u->node);
		k_sem_give(&pair_sem);
	}
}

static int unit_start(struct unit *u, const struct co_od_def *def, void *ram, uint8_t id,
		      k_thread_stack_t *stack, size_t stack_size)
{
	int err = co_line_init(&u->line, u->name, u->can);

	if (err == 0) {
		err = co_node_init(&u->node, u->name, &u->line, def, ram, id);
	}
	if (err == 0) {
		co_listener_init(&u->listener, u->name,
				 CO_EV_BIT(CO_EV_NMT_STATE) | CO_EV_BIT(CO_EV_SRDO), on_event, u);
		err = co_node_listener_add(&u->node, &u->listener);
	}
	if (err == 0 && u == &controller) {
		const struct co_od_hook hook = {
			.index_first = IDX_CHAN_A,
			.index_last = IDX_CHAN_B,
			.sub_first = 1,
			.sub_last = 2,
			.notify = pair_notify,
			.user_data = u,
		};

		co_node_lock(&u->node);
		err = co_od_hook_register(co_node_od(&u->node), &hook);
		co_node_unlock(&u->node);
	}
	if (err == 0) {
		err = co_line_start(&u->line, stack, stack_size,
				    CONFIG_CANOPEN_LINE_THREAD_PRIORITY);
	}
	if (err == 0) {
		err = co_node_start(&u->node);
	}
	if (err != 0) {
		LOG_ERR("%s: start failed (%d)", u->name, err);
	}
	return err;
}

/* --- Printing ------------------------------------------------------------------------------- */

static const char *reason_word(uint8_t reason)
{
	static const char *const words[] = {
		[CO_SRDO_R_NONE] = "NONE",
		[CO_SRDO_R_NOT_OPERATIONAL] = "NOT_OPERATIONAL",
		[CO_SRDO_R_STARTING] = "STARTING",
		[CO_SRDO_R_CONFIG] = "CONFIG",
		[CO_SRDO_R_SCT] = "SCT",
		[CO_SRDO_R_SRVT] = "SRVT",
		[CO_SRDO_R_NOT_INVERTED] = "NOT_INVERTED",
		[CO_SRDO_R_SHORT] = "SHORT",
		[CO_SRDO_R_TX_FAIL] = "TX_FAIL",
		[CO_SRDO_R_GFC] = "GFC",
	};

	return reason < ARRAY_SIZE(words) && words[reason] != NULL ? words[reason] : "?";
}

/* A fault of the SRDO itself, as opposed to the node's state or configuration. */
static bool is_fault(uint8_t reason)
{
	return reason == CO_SRDO_R_SCT || reason == CO_SRDO_R_SRVT ||
	       reason == CO_SRDO_R_NOT_INVERTED || reason == CO_SRDO_R_SHORT ||
	       reason == CO_SRDO_R_TX_FAIL;
}

/* "12.3" for a time span in µs (negative spans, which cannot happen, read 0.0). */
static const char *ms(char *buf, size_t size, uint64_t from_us, uint64_t to_us)
{
	uint64_t d = co_time_before_eq(from_us, to_us) ? to_us - from_us : 0U;

	(void)snprintf(buf, size, "%u.%u", (unsigned int)(d / 1000U),
		       (unsigned int)(d % 1000U / 100U));
	return buf;
}

static void print_event(const struct app_event *e)
{
	char a[16];

	if (e->type == CO_EV_NMT_STATE) {
		printk("%s: node %u %s\n", e->unit->name, co_node_id(&e->unit->node),
		       co_nmt_state_str(e->state));
		return;
	}
	if (e->srdo == 0U) {
		printk("%s: GFC received\n", e->unit->name);
	} else if (!e->safe && e->srdo_state == CO_SRDO_STATE_DELETED) {
		printk("%s: SRDO %u DELETED (direction 0): no safety data\n", e->unit->name,
		       e->srdo);
	} else if (!e->safe) {
		printk("%s: SRDO %u VALID (first pair %s %s ms after Operational)\n", e->unit->name,
		       e->srdo, e->unit == &controller ? "received" : "sent",
		       ms(a, sizeof(a), e->op_us, e->time_us));
	} else if (!is_fault(e->reason)) {
		printk("%s: SRDO %u SAFE (%s)\n", e->unit->name, e->srdo, reason_word(e->reason));
	} else if (e->unit != &controller) {
		printk("%s: SRDO %u SAFE (%s)\n", e->unit->name, e->srdo, reason_word(e->reason));
	} else if (e->last_pair_us == 0U) {
		printk("%s: SRDO %u SAFE (%s) %s ms after Operational, no valid pair yet\n",
		       e->unit->name, e->srdo, reason_word(e->reason),
		       ms(a, sizeof(a), e->op_us, e->time_us));
	} else if (e->fault_us != 0U) {
		printk("%s: SRDO %u SAFE (%s) %s ms after the fault\n", e->unit->name, e->srdo,
		       reason_word(e->reason), ms(a, sizeof(a), e->fault_us, e->time_us));
	} else {
		printk("%s: SRDO %u SAFE (%s) %s ms after the last valid pair\n", e->unit->name,
		       e->srdo, reason_word(e->reason),
		       ms(a, sizeof(a), e->last_pair_us, e->time_us));
	}
}

/* --- Application: the sensor's input, the controller's output ------------------------------- */

static int64_t start_ms;

/* The simulated input, both channels written at once under the node's mutex. */
static void sensor_step(void)
{
	static int pressed_before = -1;
	int64_t t = k_uptime_get() - start_ms;
	uint8_t pressed = (t % ESTOP_PERIOD_MS) >= ESTOP_PERIOD_MS - ESTOP_HELD_MS ? 1U : 0U;
	uint8_t count = (uint8_t)(t / COUNT_EVERY_MS);
	struct co_od *od = co_node_od(&sensor.node);

	co_node_lock(&sensor.node);
	(void)co_od_set_u8(od, IDX_CHAN_A, 1, pressed, CO_OD_WRITER_APP);
	(void)co_od_set_u8(od, IDX_CHAN_B, 1, (uint8_t)~pressed, CO_OD_WRITER_APP);
	(void)co_od_set_u8(od, IDX_CHAN_A, 2, count, CO_OD_WRITER_APP);
	(void)co_od_set_u8(od, IDX_CHAN_B, 2, (uint8_t)~count, CO_OD_WRITER_APP);
	co_node_unlock(&sensor.node);
	if (pressed != pressed_before) {
		if (pressed_before >= 0) {
			printk("sensor: emergency stop %s\n",
			       pressed != 0U ? "pressed" : "released");
		}
		pressed_before = pressed;
	}
}

/* The output follows the input only while the SRDO is valid and both channels agree. */
static void controller_step(void)
{
	static bool output;
	struct co_od *od = co_node_od(&controller.node);
	uint8_t a = 1U;
	uint8_t b = 0U;
	int state;
	bool valid;
	bool released;
	const char *why;

	co_node_lock(&controller.node);
	/*
	 * co_srdo_may_leave_safe_state() alone is also true when no SRDO exists: an SDO write of
	 * 0 to 1301h sub 1 would then release the output with no safety data at all. The output
	 * needs SRDO 1 itself to be valid too.
	 */
	state = co_srdo_get_state(&controller.node, SRDO_NO, NULL);
	valid = co_srdo_may_leave_safe_state(&controller.node) && state == CO_SRDO_STATE_VALID;
	(void)co_od_get_u8(od, IDX_CHAN_A, 1, &a);
	(void)co_od_get_u8(od, IDX_CHAN_B, 1, &b);
	released = a == 0U && b == 0xFFU;
	if ((valid && released) != output) {
		output = valid && released;
		(void)co_od_set_u8(od, IDX_OUTPUT, 0, output ? 1U : 0U, CO_OD_WRITER_APP);
		why = output                           ? ""
		      : state == CO_SRDO_STATE_DELETED ? " (SRDO 1 deleted)"
		      : !valid                         ? " (SRDO in the safe state)"
						       : " (emergency stop pressed)";
		printk("controller: output %s%s\n", output ? "ON" : "OFF", why);
	}
	co_node_unlock(&controller.node);
}

/* --- Fault campaign (virtual bus only) ------------------------------------------------------ */

enum phase {
	P_WAIT_VALID,   /* for the controller's SRDO to be valid */
	P_WAIT_INJECT,  /* fault-at after it */
	P_WAIT_DETECT,  /* for the controller to notice, or TOLERATE_MS */
	P_WAIT_RECOVER, /* recover-after */
	P_DONE,
};

static struct {
	enum phase phase;
	uint8_t next;    /* index in opt.faults */
	uint8_t current; /* enum fault being shown */
	int64_t at_ms;   /* deadline of the phase */
	bool valid;      /* the controller's SRDO 1 */
	uint32_t injected;
	uint32_t detected;
	uint32_t tolerated;
	int bus;
} run;

static void nmt_send(struct unit *u, uint8_t cs, uint8_t id)
{
	struct can_frame f = {.id = CO_NMT_COB_ID, .dlc = 2, .data = {cs, id}};

	co_node_lock(&u->node);
	(void)co_node_send(&u->node, CO_ROUTE_DEFAULT, &f);
	co_node_unlock(&u->node);
}

static void nmt_local(struct unit *u, enum co_nmt_cs cs)
{
	int err = co_nmt_req(&u->node, cs);

	if (err != 0) {
		printk("%s: NMT command %02x refused by %s (%d)\n", u->name, cs,
		       co_nmt_get_refusal(&u->node, NULL), err);
	}
}

static int inject(enum fault f)
{
	const struct can_filter normal = {.id = COB_NORMAL, .mask = CAN_STD_ID_MASK};
	const struct can_filter inverted = {.id = COB_INVERTED, .mask = CAN_STD_ID_MASK};
	uint8_t xor_mask[CAN_MAX_DLEN] = {0};
	int err = -EINVAL;

	xor_mask[opt.byte] = (uint8_t)BIT(opt.bit);
	switch (f) {
	case F_DROP_NORMAL:
		err = can_virtual_drop_frames(run.bus, &normal, opt.count);
		break;
	case F_DROP_INVERTED:
		err = can_virtual_drop_frames(run.bus, &inverted, opt.count);
		break;
	case F_CORRUPT_NORMAL:
		err = can_virtual_corrupt_frames(run.bus, &normal, opt.count, xor_mask);
		break;
	case F_CORRUPT_INVERTED:
		err = can_virtual_corrupt_frames(run.bus, &inverted, opt.count, xor_mask);
		break;
	case F_DELAY_INVERTED:
		err = can_virtual_delay_frames(run.bus, &inverted, opt.count, opt.delay_ms * 1000U);
		break;
	case F_STOP_PRODUCER:
		/* The sensor goes silent: every frame of its SRDO is lost until the recovery. */
		err = can_virtual_drop_frames(run.bus, &normal, UINT32_MAX);
		if (err == 0) {
			err = can_virtual_drop_frames(run.bus, &inverted, UINT32_MAX);
		}
		break;
	default:
		break;
	}
	return err;
}

static void describe(enum fault f, char *buf, size_t size)
{
	const char *cnt = opt.count == 1U ? "the next frame" : "the next frames";

	switch (f) {
	case F_DROP_NORMAL:
	case F_DROP_INVERTED:
		(void)snprintf(buf, size, "%s on %03Xh lost (%u)", cnt,
			       f == F_DROP_NORMAL ? COB_NORMAL : COB_INVERTED, opt.count);
		break;
	case F_CORRUPT_NORMAL:
	case F_CORRUPT_INVERTED:
		(void)snprintf(buf, size, "%s on %03Xh with byte %u bit %u flipped (%u)", cnt,
			       f == F_CORRUPT_NORMAL ? COB_NORMAL : COB_INVERTED, opt.byte, opt.bit,
			       opt.count);
		break;
	case F_DELAY_INVERTED:
		(void)snprintf(buf, size, "%s on %03Xh delivered %u ms late (%u)", cnt,
			       COB_INVERTED, opt.delay_ms, opt.count);
		break;
	case F_STOP_PRODUCER:
		(void)snprintf(buf, size, "every frame on %03Xh/%03Xh lost until the recovery",
			       COB_NORMAL, COB_INVERTED);
		break;
	default:
		buf[0] = '\0';
		break;
	}
}

static void set_fault_time(uint64_t us)
{
	co_node_lock(&controller.node);
	controller.fault_us = us;
	co_node_unlock(&controller.node);
}

static void next_fault(int64_t now)
{
	if (run.next < opt.n_faults) {
		run.phase = run.valid ? P_WAIT_INJECT : P_WAIT_VALID;
		run.at_ms = now + (int64_t)(opt.fault_at_s * 1000.0);
		return;
	}
	run.phase = P_DONE;
	printk("safety_io: %u fault(s) injected: %u detected, %u tolerated\n", run.injected,
	       run.detected, run.tolerated);
}

static void campaign_event(const struct app_event *e)
{
	int64_t now = k_uptime_get();

	if (e->unit != &controller || e->type != CO_EV_SRDO || e->srdo != SRDO_NO) {
		return;
	}
	run.valid = !e->safe && e->srdo_state == CO_SRDO_STATE_VALID;
	if (run.valid && run.phase == P_WAIT_VALID) {
		next_fault(now);
	} else if (e->safe && is_fault(e->reason) && run.phase != P_WAIT_RECOVER &&
		   run.phase != P_DONE) {
		if (run.phase == P_WAIT_DETECT) {
			run.detected++;
		}
		if (opt.recover_s == 0.0) {
			run.phase = P_DONE;
			printk("safety_io: the controller stays in the safe state "
			       "(--recover-after=0)\n");
			return;
		}
		run.phase = P_WAIT_RECOVER;
		run.at_ms = now + (int64_t)(opt.recover_s * 1000.0);
	}
}

static void campaign_step(void)
{
	int64_t now = k_uptime_get();
	char what[80];

	if ((run.phase != P_WAIT_INJECT && run.phase != P_WAIT_DETECT &&
	     run.phase != P_WAIT_RECOVER) ||
	    now < run.at_ms) {
		return;
	}
	switch (run.phase) {
	case P_WAIT_INJECT:
		/* Right after a valid pair, so that the fault hits the next one. */
		k_sem_reset(&pair_sem);
		(void)k_sem_take(&pair_sem, K_MSEC(PAIR_WAIT_MS));
		run.current = opt.faults[run.next++];
		describe(run.current, what, sizeof(what));
		set_fault_time(co_node_time(&controller.node));
		if (inject(run.current) != 0) {
			printk("safety_io: fault %s could not be injected\n",
			       fault_names[run.current]);
			set_fault_time(0U);
			next_fault(now);
			break;
		}
		run.injected++;
		printk("safety_io: fault %u/%u %s: %s\n", run.next, opt.n_faults,
		       fault_names[run.current], what);
		run.phase = P_WAIT_DETECT;
		run.at_ms = k_uptime_get() + TOLERATE_MS;
		break;
	case P_WAIT_DETECT:
		/* Nothing noticed: within what SCT and SRVT allow (one lost pair, say). */
		run.tolerated++;
		printk("controller: SRDO 1 still valid %d ms after the fault: tolerated\n",
		       TOLERATE_MS);
		(void)can_virtual_clear_faults(run.bus);
		set_fault_time(0U);
		next_fault(now);
		break;
	case P_WAIT_RECOVER:
		(void)can_virtual_clear_faults(run.bus);
		set_fault_time(0U);
		printk("controller: recovery: Pre-operational, then Operational\n");
		nmt_local(&controller, CO_NMT_CS_ENTER_PRE_OPERATIONAL);
		nmt_local(&controller, CO_NMT_CS_START);
		run.phase = P_WAIT_VALID;
		break;
	default:
		break;
	}
}

/* --- main ----------------------------------------------------------------------------------- */

int main(void)
{
	uint32_t lines = can_if_lines();
	int id = sample_node_id(CONTROLLER_ID);
	int64_t tick;

	controller.runs = controller_runs(lines);
	sensor.runs = sensor_runs(lines);
	controller.can = sample_line_device(0);
	sensor.can = sample_line_device(1);
	if ((controller.runs && controller.can == NULL) || (sensor.runs && sensor.can == NULL)) {
		LOG_ERR("no CAN controller");
		return 1;
	}
	if (controller.runs &&
	    unit_start(&controller, &controller_od_def, &controller_ram, (uint8_t)id,
		       controller_stack, K_THREAD_STACK_SIZEOF(controller_stack)) != 0) {
		return 1;
	}
	if (sensor.runs && unit_start(&sensor, &sensor_od_def, &sensor_ram, SENSOR_ID, sensor_stack,
				      K_THREAD_STACK_SIZEOF(sensor_stack)) != 0) {
		return 1;
	}
	if (controller.runs) {
		sample_print_stats_on_exit("controller", &controller.line);
		printk("safety_io: controller node %d up on %s\n", id, controller.can->name);
	}
	if (sensor.runs) {
		printk("safety_io: sensor node %u up on %s\n", SENSOR_ID, sensor.can->name);
	}
	if (sensor.runs && !controller.runs) {
		sample_print_stats_on_exit("sensor", &sensor.line);
		printk("sensor: waiting for an NMT master to start it (000#01%02X)\n", SENSOR_ID);
	}
	start_ms = k_uptime_get();
	run.bus = controller.runs && sensor.runs && lines == 0U
			  ? can_virtual_get_bus(controller.can)
			  : -1;
	run.phase = run.bus >= 0 && opt.n_faults > 0U ? P_WAIT_VALID : P_DONE;

	/* A minimal NMT master: start the sensor, give it time to produce, then start itself. */
	if (controller.runs) {
		printk("controller: NMT start node %u\n", SENSOR_ID);
		nmt_send(&controller, CO_NMT_CS_START, SENSOR_ID);
		k_sleep(K_MSEC(MASTER_WAIT_MS));
		nmt_local(&controller, CO_NMT_CS_START);
	}

	tick = k_uptime_get();
	for (;;) {
		struct app_event e;

		if (k_msgq_get(&events, &e, K_TIMEOUT_ABS_MS(tick)) == 0) {
			print_event(&e);
			campaign_event(&e);
			continue;
		}
		if (atomic_set(&events_lost, 0) != 0) {
			printk("safety_io: events lost (queue full)\n");
		}
		tick += LOOP_MS;
		if (sensor.runs) {
			sensor_step();
		}
		if (controller.runs) {
			controller_step();
			campaign_step();
		}
	}
	return 0;
}
