/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What the files of the NMT master (doc/mgr.md) share. One concern per file:
 *
 * - mgr.c          init, reset communication, NMT state changes, slave slots, public API
 * - mgr_nmt.c      the NMT command queue (102Ah inhibit time, "including self")
 * - mgr_ec.c       error control of the slaves: heartbeat (1016h), node guarding (1F81h,
 *                  1F83h), the error handler and the boot-up handler
 * - mgr_boot.c     "boot NMT slave" (the const step table) and the boot process of one slave
 * - mgr_startup.c  the NMT startup: reset, boot all, 1F89h, halt, start all / individual
 * - mgr_od.c       the hooks on 1F80h-1F83h and the 1F82h read value
 * - mgr_fm.c       flying master (1F90h) and NMT master detection (1F91h)
 * - mgr_sdom.c     SDO manager: 6E0h registration, 1F00h-1F06h (dynamic SDO connections)
 *
 * Every function here runs with the node's mutex held.
 */

#ifndef SAFELINE_SUBSYS_CANOPEN_MGR_MGR_INTERNAL_H_
#define SAFELINE_SUBSYS_CANOPEN_MGR_MGR_INTERNAL_H_

#include <stdbool.h>
#include <stdint.h>

#include <zephyr/sys/util.h>

#include <canopen/mgr.h>
#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/sdo_cli.h>

#include "node_internal.h"

#define IDX_DEVTYPE     0x1000U
#define IDX_HB_CONSUMER 0x1016U
#define IDX_IDENTITY    0x1018U
#define IDX_CFG_STAMP   0x1020U
#define IDX_RESTORE     0x1011U
#define IDX_INHIBIT     0x102AU
#define IDX_SW_VERIFY   0x1F52U
#define IDX_SW_DATE     0x1F53U
#define IDX_SW_TIME     0x1F54U
#define IDX_CFG_DATE    0x1F26U
#define IDX_CFG_TIME    0x1F27U
#define IDX_STARTUP     0x1F80U
#define IDX_ASSIGN      0x1F81U
#define IDX_REQ_NMT     0x1F82U
#define IDX_REQ_GUARD   0x1F83U
#define IDX_EXP_DEVTYPE 0x1F84U
#define IDX_EXP_VENDOR  0x1F85U
#define IDX_BOOT_TIME   0x1F89U
#define IDX_RESTORE_SUB 0x1F8AU

/* 1F80h bits. */
#define SU_MASTER     BIT(0)
#define SU_START_ALL  BIT(1)
#define SU_NO_SELF_OP BIT(2)
#define SU_NO_START   BIT(3)
#define SU_RESET_ALL  BIT(4)
#define SU_FLYING     BIT(5)
#define SU_STOP_ALL   BIT(6)
#define SU_SELF_START 0x08U

/* 1F81h bits. */
#define AS_SLAVE      BIT(0)
#define AS_BOOT       BIT(2)
#define AS_MANDATORY  BIT(3)
#define AS_KEEP_ALIVE BIT(4)
#define AS_SW_CHECK   BIT(5)
#define AS_SW_UPDATE  BIT(6)
#define AS_RESTORE    BIT(7)

/* 1F82h/1F83h sub-index that addresses every node. */
#define ALL_NODES 0x80U

/* Internal startup phases (co_mgr.phase). */
enum {
	PH_NONE,
	PH_BEGIN,
	PH_RESETTING,
	PH_BOOT,
	PH_BOOTING,
};

#define MS_US(ms) ((uint64_t)(ms) * 1000U)

/* --- Shared helpers ------------------------------------------------------------------------ */

/* The manager's time (its node's); its frames go on the default line. */
static inline uint64_t co_mgr_now(struct co_mgr *m)
{
	return co_node_time(m->node);
}

/* The manager's objects are read when needed, so a write takes effect at the next use;
 * absent objects read as 0.
 */
static inline uint32_t co_mgr_od(struct co_mgr *m, uint16_t index, uint8_t sub)
{
	return co_od_uint(&m->node->od, index, sub, 0U);
}

static inline uint32_t co_mgr_startup_obj(struct co_mgr *m)
{
	return co_mgr_od(m, IDX_STARTUP, 0);
}

static inline uint32_t co_mgr_assign(struct co_mgr *m, uint8_t id)
{
	return co_mgr_od(m, IDX_ASSIGN, id);
}

/* Slave slot i boots over SDO client i. */
static inline struct co_sdo_cli *co_mgr_cli(struct co_mgr_slave *s)
{
	return co_sdo_cli_get(s->mgr->node, s->slot);
}

/* Arm the slave's timer (boot step timeouts, retries) @p ms from now. */
static inline void co_mgr_arm(struct co_mgr_slave *s, uint32_t ms)
{
	co_node_timer_start(s->mgr->node, &s->timer, co_mgr_now(s->mgr) + MS_US(ms));
}

/* Success of a boot: OK, or L (already Operational, a success with a warning). */
static inline bool co_mgr_status_ok(uint8_t st)
{
	return st == CO_MGR_ST_OK || st == CO_MGR_ST_L;
}

/* --- mgr.c: slave slots ---------------------------------------------------------------------- */

/* The slot of node @p id, NULL if it has none. */
struct co_mgr_slave *co_mgr_slot_find(struct co_mgr *m, uint8_t id);
/* The slot of node @p id, taking a free one if needed; NULL (logged) if all are in use. */
struct co_mgr_slave *co_mgr_slot_get(struct co_mgr *m, uint8_t id);

/* --- mgr_nmt.c: NMT command queue ------------------------------------------------------------- */

bool co_mgr_cs_valid(uint8_t cs);
/*
 * Queue NMT command @p cs for node @p id (0: all). @p self: apply it to our own NMT state
 * once sent, for broadcasts "including self". Returns 0 or -ENOSPC.
 */
int co_mgr_nmt_queue(struct co_mgr *m, uint8_t cs, uint8_t id, bool self);
void co_mgr_nmt_timer_handler(struct co_timer *timer, uint64_t now_us);

/* --- mgr_ec.c: error control ------------------------------------------------------------------ */

/* Heartbeat consumer time [ms] for @p id in our 1016h, 0 if none. */
uint16_t co_mgr_hb_time(struct co_mgr *m, uint8_t id);
void co_mgr_send_rtr(struct co_mgr_slave *s);
void co_mgr_ec_stop(struct co_mgr_slave *s);
void co_mgr_guard_start(struct co_mgr_slave *s, uint16_t gt_ms, uint8_t rf);
void co_mgr_hb_start(struct co_mgr_slave *s, uint64_t now);
void co_mgr_ec_timer_handler(struct co_timer *timer, uint64_t now_us);
/* Receiver of 700h..77Fh: boot-ups, heartbeats and guarding replies. */
void co_mgr_ec_rx(struct co_rx *rx, const struct can_frame *frame, uint64_t now_us);

/* --- mgr_boot.c: boot NMT slave and the boot process of one slave ----------------------------- */

/* Start the boot process (302-2 §3.3): attempt counter reset, first attempt now. */
void co_mgr_boot_process_start(struct co_mgr_slave *s);
/* An error-control frame of a booting slave (@p byte 0: boot-up) for the current step. */
void co_mgr_boot_ec(struct co_mgr_slave *s, uint8_t byte);
/* 1F89h expired while @p s had not booted: end its attempt with B, stop its retries. */
void co_mgr_boot_expire(struct co_mgr_slave *s, uint64_t now_us);
/* Retry after B in CONFIG_CANOPEN_MGR_RETRY_TIME; while the master is Stopped, when it runs. */
void co_mgr_boot_retry(struct co_mgr_slave *s);
/* The master is about to leave Pre-operational/Operational: abort the running SDO on the bus. */
void co_mgr_boot_abort_sdo(struct co_mgr_slave *s, uint32_t abort_code);
/* The master entered Stopped: a running attempt ends (B, indicated) and is held. */
void co_mgr_boot_stopped(struct co_mgr_slave *s);
/* The master runs again: start the held attempt (from the line thread). */
void co_mgr_boot_resume(struct co_mgr_slave *s);
/* The SDO manager may have given a default SDO back: boots that wait for one look again now. */
void co_mgr_boot_sdo_recheck(struct co_mgr *m);
/* Boot step timeouts, retries and the wait for a boot-up after the error handler. */
void co_mgr_slave_timer_handler(struct co_timer *timer, uint64_t now_us);

/* --- mgr_startup.c: NMT startup --------------------------------------------------------------- */

/* The resets of S3 are out: boot all slaves (from the line thread). */
void co_mgr_startup_resets_sent(struct co_mgr *m);
/*
 * An attempt of @p s ended and was indicated: retry it, halt the startup, or go on with it.
 * @p mandatory (1F81h bit 3) and @p now are taken when the attempt ended, before the
 * indication, which may change 1F81h.
 */
void co_mgr_startup_boot_ended(struct co_mgr_slave *s, bool mandatory, uint64_t now);
/*
 * The error handler stops the network ("stop all", 1F80h bit 6) for a mandatory slave whose
 * error control failed (@p guarding: node guarding, else heartbeat): a running startup that
 * still waits for a mandatory slave halts with that slave's error (F or K), since the Stopped
 * master cannot boot it.
 */
void co_mgr_startup_halt_ec(struct co_mgr_slave *s, bool guarding);
/* Whether a mandatory slave has not booted yet (the initial startup may still halt). */
bool co_mgr_mandatory_pending(struct co_mgr *m);
void co_mgr_start_timer_handler(struct co_timer *timer, uint64_t now_us);
void co_mgr_boot_timer_handler(struct co_timer *timer, uint64_t now_us);

/* --- mgr_od.c: the manager's objects --------------------------------------------------------- */

/* Keep the 1F82h read value (the master's view of the slave's state) up to date. */
void co_mgr_set_nmt_view(struct co_mgr_slave *s, uint8_t v);
int co_mgr_od_hooks_register(struct co_mgr *m);

/* --- mgr_fm.c: flying master, NMT master detection ----------------------------------------- */

#if defined(CONFIG_CANOPEN_MGR_FLYING)
int co_mgr_fm_init(struct co_mgr *m);
/* The NMT startup began (after our boot-up): a candidate negotiates, a self-starter asks. */
void co_mgr_fm_begin(struct co_mgr *m);
/* Whether this node won the negotiation (the manager's functions run). */
bool co_mgr_fm_active(struct co_mgr *m);
#endif

/* --- mgr_lss.c: node-IDs for missing slaves by LSS -------------------------------------------- */

/* Follow the boot results: a slave ending with B is searched by fastscan. */
int co_mgr_lss_init(struct co_mgr *m);

/* --- mgr_pgm.c: program download in the software step --------------------------------------- */

/* Boot handler results besides a next step (mgr_boot.c). */
#define CO_MGR_NEXT_WAIT 0xfeU
#define CO_MGR_NEXT_END  0xfdU

/* mgr_boot.c's transfer helpers and result, for the steps of mgr_pgm.c. */
uint8_t co_mgr_boot_fail(struct co_mgr_slave *s, uint8_t status, uint16_t index, uint8_t sub,
			 uint32_t expected, uint32_t actual, uint32_t abort_code);
uint8_t co_mgr_boot_upload(struct co_mgr_slave *s, uint16_t index, uint8_t sub);
void co_mgr_boot_sdo_con(struct co_sdo_cli *cli, uint32_t abort_code, size_t size, void *user_data);

/* Whether the application has an image for the slave (then its download starts). */
bool co_mgr_pgm_has_image(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_stop(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_stop_sdo(struct co_mgr_slave *s, uint32_t ab);
uint8_t co_mgr_pgm_download(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_download_sdo(struct co_mgr_slave *s, uint32_t ab);
uint8_t co_mgr_pgm_start(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_start_sdo(struct co_mgr_slave *s, uint32_t ab);
uint8_t co_mgr_pgm_restart(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_restart_ec(struct co_mgr_slave *s, uint8_t byte);
uint8_t co_mgr_pgm_restart_to(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_date(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_date_sdo(struct co_mgr_slave *s, uint32_t ab);
uint8_t co_mgr_pgm_time(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_time_sdo(struct co_mgr_slave *s, uint32_t ab);
uint8_t co_mgr_pgm_resume(struct co_mgr_slave *s);
uint8_t co_mgr_pgm_resume_sdo(struct co_mgr_slave *s, uint32_t ab);

/* --- mgr_sdom.c: SDO manager ------------------------------------------------------------------ */

#if defined(CONFIG_CANOPEN_MGR_SDOM)
/* Receive 6E0h and hook 1F00h-1F06h. */
int co_mgr_sdom_init(struct co_mgr *m);
/* The error control of node @p id failed (mgr_ec.c): release an SRD's connections, or tell
 * the SRDs that asked for error control that slave @p id failed (1F11h).
 */
void co_mgr_sdom_lost(struct co_mgr *m, uint8_t id);
/* Node @p id sent its boot-up: entries it kept after a failed release are gone. */
void co_mgr_sdom_bootup(struct co_mgr *m, uint8_t id);
/* Whether the boot of @p id must not use its default SDO now: an SRD holds it (a connection
 * over it, or all default SDOs), or our own SDO manager transfer to @p id runs.
 */
bool co_mgr_sdom_default_held(struct co_mgr *m, uint8_t id);
#endif

#endif /* SAFELINE_SUBSYS_CANOPEN_MGR_MGR_INTERNAL_H_ */
