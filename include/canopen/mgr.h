/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen manager: NMT master (CiA 302 §5, CiA 302-2 §3-§4, §6).
 *
 * The NMT master sends NMT module control with the inhibit time 102Ah, supervises every
 * assigned slave (1F81h) by heartbeat (1016h) or node guarding (1F81h guard bytes, 1F83h)
 * and runs the CiA 302-2 boot-up: NMT startup (1F80h), boot NMT slave (identity 1F84h-1F88h,
 * keep-alive, software version 1F52h-1F54h, configuration 1020h vs 1F26h/1F27h, restore
 * 1F8Ah, concise DCF through the configuration manager, start error control, start), the
 * error handler and the boot-up handler, request NMT 1F82h and request guarding 1F83h.
 *
 * All slaves boot in parallel: slave slot i uses SDO client i of the node
 * (CONFIG_CANOPEN_SDO_CLIENTS >= CONFIG_CANOPEN_MGR_SLAVES); clients above the slots are
 * left to the application and to 1F25h requests of the configuration manager. Slaves that
 * reach the configuration download while all CONFIG_CANOPEN_CFG_JOBS are running wait for a
 * job (no boot fails for lack of one).
 *
 * Indications run in the node's line thread with the node's mutex held; they must not block.
 *
 * @defgroup co_mgr NMT master
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_MGR_H_
#define SAFELINE_INCLUDE_CANOPEN_MGR_H_

#include <stdbool.h>
#include <stdint.h>

#include <canopen/event.h>
#include <canopen/line.h>
#include <canopen/nmt.h>
#include <canopen/sdo_cli.h>
#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
#include <canopen/mgr_lss.h>
#endif
#if defined(CONFIG_CANOPEN_MGR_PGM)
#include <canopen/pgm.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** Boot result codes: 0 = OK, 'A'..'O' the error status of CiA 302-2 §3.8 Table 1. */
enum co_mgr_status {
	CO_MGR_ST_OK = 0,
	/** Node not in the network list 1F81h. */
	CO_MGR_ST_A = 'A',
	/** No response to the 1000h upload. */
	CO_MGR_ST_B = 'B',
	/** 1000h differs from 1F84h. */
	CO_MGR_ST_C = 'C',
	/** 1018h:01 differs from 1F85h. */
	CO_MGR_ST_D = 'D',
	/** Check NMT state: no heartbeat. */
	CO_MGR_ST_E = 'E',
	/** Check NMT state: no node guarding reply. */
	CO_MGR_ST_F = 'F',
	/** Software check requested but 1F53h/1F54h not configured. */
	CO_MGR_ST_G = 'G',
	/** Software update needed but not allowed (1F81h bit 6 = 0). */
	CO_MGR_ST_H = 'H',
	/** Software update needed but the download failed. */
	CO_MGR_ST_I = 'I',
	/** Configuration download failed. */
	CO_MGR_ST_J = 'J',
	/** No heartbeat in start error control. */
	CO_MGR_ST_K = 'K',
	/** Slave was already Operational (keep-alive): success with a warning. */
	CO_MGR_ST_L = 'L',
	/** 1018h:02 differs from 1F86h. */
	CO_MGR_ST_M = 'M',
	/** 1018h:03 does not fit 1F87h (major equal, minor greater or equal). */
	CO_MGR_ST_N = 'N',
	/** 1018h:04 differs from 1F88h. */
	CO_MGR_ST_O = 'O',
	/** Boot not run yet. */
	CO_MGR_ST_NONE = 0xff,
};

/** Steps of "boot NMT slave" (CiA 302-2 §3.4, our table order). */
enum co_mgr_step {
	CO_MGR_STEP_IDLE,
	CO_MGR_STEP_ASSIGNED,
	/** Wait for the boot-up after the master reset the slave (at most BOOTUP_WAIT). */
	CO_MGR_STEP_BOOTUP,
	CO_MGR_STEP_BOOT_ALLOWED,
	CO_MGR_STEP_DEVTYPE,
	CO_MGR_STEP_VENDOR,
	CO_MGR_STEP_PRODUCT,
	CO_MGR_STEP_REVISION,
	CO_MGR_STEP_SERIAL,
	CO_MGR_STEP_KEEP_ALIVE,
	CO_MGR_STEP_KEEP_ALIVE_RESET,
	CO_MGR_STEP_SW_DATE,
	CO_MGR_STEP_SW_TIME,
	/** Program download (CONFIG_CANOPEN_MGR_PGM, mgr_pgm.c): 1F51h:01 = 0. */
	CO_MGR_STEP_PGM_STOP,
	/** 1F50h:01 = the image, block SDO. */
	CO_MGR_STEP_PGM_DOWNLOAD,
	/** 1F51h:01 = 1. */
	CO_MGR_STEP_PGM_START,
	/** Wait for the boot-up of the slave restarting with the new image. */
	CO_MGR_STEP_PGM_RESTART,
	/** 1F52h:01/02 read again. */
	CO_MGR_STEP_PGM_DATE,
	CO_MGR_STEP_PGM_TIME,
	/** The download failed: 1F51h:01 = 1 so the old program runs again, then I. */
	CO_MGR_STEP_PGM_RESUME,
	CO_MGR_STEP_CFG_DATE,
	CO_MGR_STEP_CFG_TIME,
	CO_MGR_STEP_RESTORE,
	CO_MGR_STEP_RESTORE_RESET,
	CO_MGR_STEP_DOWNLOAD,
	CO_MGR_STEP_START_EC,
	CO_MGR_STEP_START,
	CO_MGR_STEP_COUNT,
};

/** Why a boot of one slave failed: which slave, step, object, expected and actual value. */
struct co_mgr_boot_error {
	uint8_t node_id;
	/** enum co_mgr_status letter. */
	uint8_t status;
	enum co_mgr_step step;
	/** Object concerned (slave object, e.g. 1018h:02), 0 if none. */
	uint16_t index;
	uint8_t sub;
	/** Expected value (from the manager's 1F84h..., 1016h time ...). */
	uint32_t expected;
	/** Value found (0 if nothing was received). */
	uint32_t actual;
	/** SDO abort code of the failing transfer, 0 if none. */
	uint32_t abort_code;
};

/**
 * @brief Whether @p e reports a comparison (expected and actual both meaningful).
 *
 * True for the letters that compare a value read from the slave with the manager's (C, D, M,
 * N, O, H) when the value was read (no SDO abort). Otherwise (B, J, E, K, ... or an aborted
 * upload) only the object and the abort code say what happened.
 */
static inline bool co_mgr_error_compared(const struct co_mgr_boot_error *e)
{
	return e->abort_code == 0U && (e->status == 'C' || e->status == 'D' || e->status == 'M' ||
				       e->status == 'N' || e->status == 'O' || e->status == 'H');
}

/** One line of the boot table (co_mgr_get_boot()). */
struct co_mgr_boot_info {
	uint8_t node_id;
	/** 1F81h bit 0. */
	bool assigned;
	/** 1F81h bit 3. */
	bool mandatory;
	/** A boot process is running. */
	bool booting;
	/**
	 * enum co_mgr_status of the last finished boot attempt (CO_MGR_ST_NONE: none yet). An
	 * attempt in progress (booting) does not change it, nor device_type, identity,
	 * read_mask and error: they all describe that last finished attempt.
	 */
	uint8_t status;
	/** Identity read by the last finished attempt: 1000h, 1018h:01..04, which (bit i). */
	uint32_t device_type;
	uint32_t identity[4];
	uint8_t read_mask;
	/** Attempts since the boot process started. */
	uint16_t attempts;
	/** Start of the boot process and end of the last attempt [µs, line time]. */
	uint64_t started_us;
	uint64_t finished_us;
	/**
	 * The master's view of the slave's NMT state (1F82h read value: 0, 1, 4, 5, 7Fh): the
	 * state it commanded last, or reported last, whichever came later.
	 */
	uint8_t nmt_state;
	/** Last error (valid when status is an error letter). */
	struct co_mgr_boot_error error;
};

/** Error-control events of a slave (co_mgr_ec_ind_t). */
enum co_mgr_ec_event {
	/** A boot-up message (700h+id, 00h) arrived. */
	CO_MGR_EC_BOOTUP,
	/** Heartbeat lost (1016h time elapsed). */
	CO_MGR_EC_HB_LOST,
	/** No node guarding reply within guard time x retry factor. */
	CO_MGR_EC_GUARD_LOST,
	/**
	 * The slave's reported NMT state changed: a heartbeat or node-guarding reply carries
	 * another state than the last one the slave reported (the first report after the start
	 * of supervision or a loss counts; a boot-up reports Pre-operational). States the master
	 * commanded raise it too, when the slave confirms them.
	 */
	CO_MGR_EC_STATE,
};

/** Overall NMT startup state. */
enum co_mgr_startup {
	/** Not a master (1F80h bit 0 = 0) or not started. */
	CO_MGR_STARTUP_IDLE,
	/** Resetting slaves, booting them. */
	CO_MGR_STARTUP_RUNNING,
	/** Startup complete; normal operation. */
	CO_MGR_STARTUP_DONE,
	/** A mandatory slave failed: startup halted (no NMT Start, master stays Pre-op). */
	CO_MGR_STARTUP_HALTED,
};

/**
 * @brief Result of one boot attempt of a slave (OK, L or an error).
 * @param err NULL on success, else the details (also logged).
 */
typedef void (*co_mgr_boot_ind_t)(struct co_node *node, uint8_t id, uint8_t status,
				  const struct co_mgr_boot_error *err, void *user_data);

/** @brief NMT startup finished (DONE) or halted (HALTED, @p err: the mandatory failure). */
typedef void (*co_mgr_startup_ind_t)(struct co_node *node, enum co_mgr_startup result,
				     const struct co_mgr_boot_error *err, void *user_data);

/** @brief Error-control event of slave @p id; @p state the last known state. */
typedef void (*co_mgr_ec_ind_t)(struct co_node *node, uint8_t id, enum co_mgr_ec_event event,
				enum co_nmt_state state, void *user_data);

/**
 * @brief Software version hook (1F81h bits 5 and 6, CiA 302 §4 step 4).
 *
 * Called when slave @p id reports 1F52h date/time different from 1F53h/1F54h and an update is
 * allowed (bit 6). The application updates the program (1F50h/1F51h) itself.
 *
 * @return 0: the software was updated and the boot goes on; otherwise the boot ends with I.
 */
typedef int (*co_mgr_sw_ind_t)(struct co_node *node, uint8_t id, uint32_t exp_date,
			       uint32_t exp_time, uint32_t act_date, uint32_t act_time,
			       void *user_data);

#if defined(CONFIG_CANOPEN_MGR_FLYING)
/**
 * States of the flying master (CiA 302 §5.5, CiA 302-2 §3.7, §5) and of the NMT master
 * detection of a self-starting device (CiA 302-2 §5.1), co_mgr_fm_get().
 */
enum co_mgr_fm_state {
	/** Not a candidate (1F80h bits 0 and 5 not both set) and not self-starting (02h). */
	CO_MGR_FM_OFF,
	/** After the boot-up: waiting 1F90h:02 (negotiation time delay). */
	CO_MGR_FM_DELAY,
	/** 073h sent: waiting 1F90h:01 for an active master's 071h. */
	CO_MGR_FM_DETECT,
	/** 076h sent to a lower-priority active master: waiting for its reset. */
	CO_MGR_FM_FORCED,
	/** Negotiating: waiting priority x 1F90h:04 + node-ID x 1F90h:05 after the last 072h. */
	CO_MGR_FM_NEGOTIATE,
	/** This node is the active NMT master (the manager's functions run). */
	CO_MGR_FM_ACTIVE,
	/** Another node is the active master: this one is a slave and watches its heartbeat. */
	CO_MGR_FM_SLAVE,
	/** Self-starting device: waiting 1F91h:02 after the boot-up. */
	CO_MGR_FM_SS_DELAY,
	/** Self-starting device: 075h sent, waiting 1F91h:01 for a 074h. */
	CO_MGR_FM_SS_ASK,
	/** Self-starting device: nobody answered, waiting node-ID x 1F91h:03. */
	CO_MGR_FM_SS_SLOT,
	/** Self-starting device: the network was started, or a master-capable device exists. */
	CO_MGR_FM_SS_DONE,
	CO_MGR_FM_STATE_COUNT,
};

/** What a CO_EV_FM event reports (co_event.fm.what). */
enum co_mgr_fm_event {
	/** This node won the negotiation: it is the active master (fm.master_id = own ID). */
	CO_MGR_FM_EV_ACTIVE,
	/** Another node is the active master (its 071h: fm.master_id, fm.priority). */
	CO_MGR_FM_EV_MASTER,
	/** The active master's heartbeat was lost: 000#8200 sent, take-over started. */
	CO_MGR_FM_EV_LOST,
	/** 076h sent to a lower-priority active master (fm.master_id, fm.priority). */
	CO_MGR_FM_EV_FORCE,
	/** As active master, 076h received: network reset, negotiation again. */
	CO_MGR_FM_EV_RESIGN,
	/** Self-starting device: a master-capable device answered 075h (no start sent). */
	CO_MGR_FM_EV_CAPABLE,
	/** Self-starting device: nobody answered 075h, 000#0100 sent (or another's seen). */
	CO_MGR_FM_EV_SELF_START,
};

/** Flying-master view of a node (co_mgr_fm_get()). */
struct co_mgr_fm_info {
	enum co_mgr_fm_state state;
	/** Active master's node-ID (own ID when active), 0 if none is known. */
	uint8_t master_id;
	/** Active master's priority (1F90h:03 of that node, as its 071h said). */
	uint8_t master_prio;
	/** Own priority, 1F90h:03. */
	uint8_t own_prio;
	/** Times this node became the active master since init. */
	uint16_t wins;
	/** When the last master change was seen [µs, node time]. */
	uint64_t changed_us;
};

/** @cond INTERNAL_HIDDEN */
struct co_mgr_fm {
	struct co_timer timer;       /* the state's wait */
	struct co_timer cycle;       /* 076h every 1F90h:06 while active */
	struct co_timer hb_timer;    /* active master's heartbeat */
	struct co_rx rx;             /* 070h..077h */
	struct co_rx hb_rx;          /* 700h + active master */
	struct co_listener listener; /* resets (cold/warm), Operational (self-start) */
	uint64_t changed_us;
	uint16_t hb_ms;
	uint16_t wins;
	uint8_t state;
	uint8_t master_id;
	uint8_t master_prio;
	uint8_t ev_master; /* the master the last CO_EV_FM named (no repeats after resets) */
	uint8_t forced_id; /* lower-priority master we forced (302 §5.5.2: once), or 0 */
	bool warm;         /* the last reset was a Reset Communication */
	bool seen_072;     /* a 072h came since this negotiation round began */
	bool bus_off;      /* our controller is (was) bus-off: restart the round on recovery */
	uint8_t req_val;   /* value of the running request NMT/guarding (co_mgr_request_*()) */
};
/** @endcond */
#endif /* CONFIG_CANOPEN_MGR_FLYING */

#if defined(CONFIG_CANOPEN_MGR_SDOM)
/** @cond INTERNAL_HIDDEN */
/* SDO manager (mgr_sdom.c): one write of an operation, a queued 1F00h/1F01h. */
struct co_mgr_sdom_wr {
	uint32_t val;
	uint16_t index;
	uint8_t sub;
	uint8_t len;
	uint8_t node;
};

struct co_mgr_sdom_req {
	uint32_t val;
	uint16_t kind; /* 1F00h, 1F01h, or an error code to report in the SRD's 1F10h */
};

struct co_mgr_sdom {
	struct co_rx trig_rx; /* 6E0h */
	struct co_timer work; /* runs what waits once a step has ended (mgr_sdom.c) */
	struct co_mgr_sdom_wr wr[8];
	struct co_mgr_sdom_req q[4];
	uint8_t cpool[CONFIG_CANOPEN_MGR_SDOM_CONNS][2]; /* 1F02h subs of each 1F03h entry */
	uint8_t srds[CONFIG_CANOPEN_MGR_SDOM_SRDS];      /* registered SRDs */
	bool all[CONFIG_CANOPEN_MGR_SDOM_SRDS];          /* ... owning all default SDOs */
	uint8_t buf[4];
	uint32_t rel_val; /* the 1F01h value being carried out */
	uint32_t fake_ab; /* a request that could not start: its abort, for the timer */
	uint16_t idx;
	uint8_t n_wr, i_wr, n_q;
	uint8_t op, end, scan_id, srv_num, conn, slave, srd;
	uint8_t pool[2];
	bool rel_active;
	bool trig;                                    /* a 6E0h came: scan when idle */
	bool own_write;                               /* our writes of 1F02h/1F03h pass the hook */
	bool reqec[CONFIG_CANOPEN_MGR_SDOM_SRDS];     /* ... asked for error control of slaves */
	uint8_t stale[CONFIG_CANOPEN_MGR_SDOM_CONNS]; /* release writes refused: 1 SRD, 2 slave */
	bool tried[CONFIG_CANOPEN_MGR_SDOM_CONNS];    /* taken by the running release */
	uint32_t dead[4];  /* node-IDs that did not answer within the running release */
	uint32_t lost[4];  /* node-IDs whose error control failed, still to handle */
	uint8_t fail_side; /* sides of the running release whose writes failed (as stale) */
	bool wait;         /* a step waits for a slave's boot to leave its default SDO */
	uint8_t up_node, up_sub;
	uint16_t up_index; /* the upload that waits */
	uint8_t busy_node; /* node whose default SDO our transfer uses now, 0: none */
	uint32_t ecmap[4]; /* node-IDs supervised because an SRD asked for Req EC */
};
/** @endcond */
#endif /* CONFIG_CANOPEN_MGR_SDOM */

/** @cond INTERNAL_HIDDEN */
struct co_mgr;

struct co_mgr_slave {
	struct co_mgr *mgr;
	struct co_timer timer;    /* boot step timeouts and retries */
	struct co_timer ec_timer; /* heartbeat consumer / node guarding */
	uint64_t started_us;
	uint64_t finished_us;
	uint64_t reset_us; /* the master's last reset of the slave went out */
	uint32_t ident[5]; /* 1000h, 1018h:01..04 as read */
	uint8_t buf[4];    /* upload buffer */
	uint8_t load[4];   /* restore signature "load" */
	uint32_t sw_date;
	uint32_t cfg_date;
	struct co_mgr_boot_error err;
	/* Result of the last finished attempt (co_mgr_get_boot()); the fields above are the
	 * attempt in progress.
	 */
	struct co_mgr_boot_error last_err;
	uint32_t last_ident[5];
	uint32_t cfg_ticket; /* order of the wait for a configuration job */
	uint16_t attempts;
	uint16_t guard_ms;
	uint16_t hb_ms;
	uint16_t xfer_index; /* object of the boot's SDO transfer */
	uint8_t xfer_sub;
	uint8_t id; /* 0: slot free */
	uint8_t slot;
	uint8_t step;
	uint8_t status;
	uint8_t nmt_state; /* 1F82h read value */
	uint8_t read_mask;
	uint8_t last_status;
	uint8_t last_read_mask;
	uint8_t rep_state; /* last state the slave reported (heartbeat, guarding), 0: none */
	uint8_t guard_rf;
	uint8_t guard_missed;
	uint8_t guard_toggle; /* toggle bit expected in the next reply, 0xff: not yet known */
	bool booting;
	bool tried;
	bool sdo_pending;
	bool was_operational;
	bool no_start;  /* 1F81h bit 2 = 0: error control only */
	bool parked;    /* state set through 1F82h: no automatic re-boot */
	bool hb_on;     /* heartbeat monitoring running */
	bool hb_wait;   /* start error control: waiting for the first heartbeat */
	bool guarding;  /* node guarding running */
	bool guard_ans; /* reply seen since the last RTR */
	bool ec_lost;
	bool wait_reboot;    /* after an error-handler reset, waiting for the boot-up */
	bool start_deferred; /* booted while a mandatory slave was still booting */
	bool cfg_wait;       /* DOWNLOAD step waiting for a configuration job slot */
	bool await_bootup;   /* reset by the master, no boot-up seen since */
	bool held;           /* an attempt waits for the master to leave Stopped */
	bool sdo_wait;       /* an SDO step waits for the default SDO (mgr_sdom.c) */
	/* Two lines: BIT(line) whose loss was reported (CO_HB_EV_LINE_LOST). */
	uint8_t line_lost;
	/* Two lines: the last heartbeat on each, or the start of monitoring. */
	uint64_t line_hb_us[2];
#if defined(CONFIG_CANOPEN_MGR_PGM)
	const void *pgm_image; /* the image being downloaded (the application's memory) */
	size_t pgm_len;
	uint32_t pgm_abort; /* abort of the failed download, reported with I */
	uint8_t pgm_ctrl;   /* 1F51h:01 value on the wire */
#endif
};

struct co_mgr_nmt_cmd {
	uint8_t cs;
	uint8_t id;
	bool self;
};

struct co_mgr {
	struct co_node *node;
	struct co_rx ec_rx;          /* 700h..77Fh: boot-up, heartbeat, guarding replies */
	struct co_listener listener; /* our own NMT changes: abort the boot transfers first */
	struct co_timer nmt_timer;   /* inhibit time 102Ah */
	struct co_timer start_timer; /* deferred startup steps */
	struct co_timer boot_timer;  /* 1F89h */
	struct co_mgr_nmt_cmd nmtq[CONFIG_CANOPEN_MGR_NMT_QUEUE];
	uint64_t nmt_next_us;
	uint16_t nmt_head;
	uint16_t nmt_count;
	uint8_t startup;      /* enum co_mgr_startup */
	uint8_t phase;        /* internal startup phase */
	uint8_t exclude_id;   /* 1F82h 84h..8Fh requester */
	bool boot_pending;    /* Reset communication seen; startup on Pre-operational */
	bool od_update;       /* the manager writes 1F82h/1F83h itself */
	bool nmt_self_busy;   /* applying a command to ourselves */
	uint32_t cfg_tickets; /* waits for a configuration job, in order */
	struct co_mgr_boot_error halt_err;
	struct co_mgr_slave slaves[CONFIG_CANOPEN_MGR_SLAVES];
	co_mgr_boot_ind_t boot_ind;
	void *boot_user_data;
	co_mgr_startup_ind_t startup_ind;
	void *startup_user_data;
	co_mgr_ec_ind_t ec_ind;
	void *ec_user_data;
	co_mgr_sw_ind_t sw_ind;
	void *sw_user_data;
#if defined(CONFIG_CANOPEN_MGR_PGM)
	co_mgr_pgm_source_t pgm_source;
	void *pgm_user_data;
#endif
#if defined(CONFIG_CANOPEN_MGR_FLYING)
	struct co_mgr_fm fm; /* flying master, NMT master detection (mgr_fm.c) */
#endif
#if defined(CONFIG_CANOPEN_MGR_LSS_ASSIGN)
	struct co_mgr_lss lss; /* node-IDs for missing slaves by LSS (mgr_lss.c) */
#endif
#if defined(CONFIG_CANOPEN_MGR_SDOM)
	struct co_mgr_sdom sdom; /* SDO manager (mgr_sdom.c) */
#endif
};
/** @endcond */

/**
 * @brief Send an NMT command to node @p id, or to all nodes (@p id 0) including the master.
 *
 * Commands are queued and sent in order, at least 102Ah apart (never dropped). A broadcast
 * is applied to the master's own NMT state after it is sent (the controller does not receive
 * its own frames), CiA 302 §5.4.
 *
 * @retval 0 Queued (or sent).
 * @retval -EINVAL @p id above 127 or an unknown command.
 * @retval -ENOSPC The queue (CONFIG_CANOPEN_MGR_NMT_QUEUE) is full.
 * @retval -EPERM The node is not an NMT master (1F80h bit 0 = 0).
 */
int co_mgr_nmt_req(struct co_node *node, uint8_t id, enum co_nmt_cs cs);

/**
 * @brief Start the boot process of slave @p id (as the boot-up handler would).
 *
 * @retval 0 Started (the result comes through the boot indication).
 * @retval -EINVAL @p id outside 1..127 or the master's own ID.
 * @retval -EALREADY A boot of @p id is running.
 * @retval -ENOSPC No slave slot free.
 */
int co_mgr_boot_req(struct co_node *node, uint8_t id);

/**
 * @brief Read one line of the boot table.
 *
 * @retval 0 Filled.
 * @retval -ENOENT @p id is neither assigned nor ever booted.
 */
int co_mgr_get_boot(struct co_node *node, uint8_t id, struct co_mgr_boot_info *info);

/** @brief Current NMT startup state. */
enum co_mgr_startup co_mgr_get_startup(struct co_node *node);

/**
 * @brief Clear the "set by request NMT" mark of slave @p id (1F82h writes park a slave: the
 * boot-up handler then leaves it alone, CiA 302 §5.4).
 */
void co_mgr_release(struct co_node *node, uint8_t id);

/** @brief Set the boot indication (NULL removes it). */
void co_mgr_set_boot_ind(struct co_node *node, co_mgr_boot_ind_t cb, void *user_data);

/** @brief Set the startup indication (NULL removes it). */
void co_mgr_set_startup_ind(struct co_node *node, co_mgr_startup_ind_t cb, void *user_data);

/** @brief Set the error-control indication (NULL removes it). */
void co_mgr_set_ec_ind(struct co_node *node, co_mgr_ec_ind_t cb, void *user_data);

/** @brief Set the software version hook (NULL: an update that is needed fails with I). */
void co_mgr_set_sw_ind(struct co_node *node, co_mgr_sw_ind_t cb, void *user_data);

#if defined(CONFIG_CANOPEN_MGR_FLYING)
/**
 * @brief The flying-master view of the node: state, active master, priorities.
 * @retval 0 Filled.
 */
int co_mgr_fm_get(struct co_node *node, struct co_mgr_fm_info *info);

/** @brief Name of a flying-master state ("ACTIVE" ...). */
const char *co_mgr_fm_state_str(enum co_mgr_fm_state state);

/**
 * @brief Request NMT from a device that is not the active master (CiA 302 §5.4, 302-2 §6.4).
 *
 * Other devices must not send NMT frames themselves; they write 1F82h:@p id of the active
 * master, which sends the command. This writes @p value to 1F82h:@p id of the active master
 * this node knows (co_mgr_fm_get(): a candidate that is a slave), over SDO client
 * @p cli_num, asynchronously; @p con gets the master's answer (0, or an abort code such as
 * 06090030h for a value it refuses, 08000022h if it is not the master any more).
 *
 * @param value 04h stop, 05h start, 06h reset node, 07h reset communication, 7Fh
 *        pre-operational (@p id 80h: all nodes).
 * @retval 0 Sent; @p con follows.
 * @retval -EINVAL @p id outside 1..80h, another @p value, or no client @p cli_num.
 * @retval -ENOENT No active master known.
 * @retval -EPERM This node is the active master (write its own 1F82h).
 * @retval other As co_sdo_cli_set_server() / co_sdo_cli_download_req() (-EBUSY ...).
 */
int co_mgr_request_nmt(struct co_node *node, uint8_t cli_num, uint8_t id, uint8_t value,
		       co_sdo_cli_con_t con, void *user_data);

/**
 * @brief Request node guarding from the active master: 1F83h:@p id = @p on (1 start, 0 stop).
 * @return As co_mgr_request_nmt().
 */
int co_mgr_request_guarding(struct co_node *node, uint8_t cli_num, uint8_t id, bool on,
			    co_sdo_cli_con_t con, void *user_data);
#endif

/** @brief Name of a boot step ("DEVTYPE" ...). */
const char *co_mgr_step_str(enum co_mgr_step step);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_MGR_H_ */
