/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Process data objects (CiA 301 §7.2.2, objects 1400h-1BFFh).
 *
 * Receive PDOs (RPDOs) write their mapped objects through the object dictionary (writer
 * CO_OD_WRITER_PDO, so hooks run); transmit PDOs (TPDOs) read them. Every write to a
 * communication record (1400h/1800h) or a mapping record (1600h/1A00h) is checked and takes
 * effect at once. The mapping is compiled into a table of resolved objects, so a frame costs
 * no dictionary lookup.
 *
 * PDO numbers in this API count from 0: RPDO 0 is 1400h/1600h, TPDO 0 is 1800h/1A00h.
 *
 * @defgroup co_pdo PDO
 * @ingroup canopen
 * @{
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_PDO_H_
#define SAFELINE_INCLUDE_CANOPEN_PDO_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/line.h>
#include <canopen/event.h>
#include <canopen/od.h>
#include <canopen/redundancy.h>

#ifdef __cplusplus
extern "C" {
#endif

struct co_node;

/** @name COB-ID bits of 1400h/1800h sub 1 (CiA 301 §7.5.2.35/37)
 * @{
 */
#define CO_PDO_COB_INVALID BIT(31) /**< 1 = the PDO does not exist (not valid) */
#define CO_PDO_COB_NO_RTR  BIT(30) /**< TPDO: 1 = no remote request allowed */
#define CO_PDO_COB_FRAME   BIT(29) /**< 1 = 29-bit CAN-ID */
/** @} */

/** @name Transmission types (1400h/1800h sub 2)
 * @{
 */
#define CO_PDO_TT_SYNC_ACYCLIC 0U   /**< TPDO: at the next SYNC after an event */
#define CO_PDO_TT_SYNC_MAX     240U /**< 1..240: every n-th SYNC */
#define CO_PDO_TT_RTR_SYNC     252U /**< TPDO: sampled at SYNC, sent on RTR */
#define CO_PDO_TT_RTR_EVENT    253U /**< TPDO: sampled and sent on RTR */
#define CO_PDO_TT_EVENT_MANUF  254U /**< event-driven, manufacturer-specific */
#define CO_PDO_TT_EVENT_PROF   255U /**< event-driven, device/application profile */
/** @} */

/** @name Mapping sub-index 0 values that make a PDO an MPDO (CiA 301 §7.2.3)
 * @{
 */
#define CO_MPDO_SAM 0xFEU /**< source address mode: scanner (TPDO) / dispatcher (RPDO) list */
#define CO_MPDO_DAM 0xFFU /**< destination address mode */
/** @} */

/** @brief Counters of received MPDOs (CONFIG_CANOPEN_MPDO). */
struct co_mpdo_stats {
	uint32_t written; /**< object written */
	uint32_t ignored; /**< other destination, wrong address mode, not in the dispatcher list */
	uint32_t refused; /**< the dictionary refused the write (access, size, limits, a hook) */
	uint32_t missing; /**< DAM: no such object (EMCY 8230h) */
};

/**
 * @brief RPDO indication: the mapped objects of RPDO @p num have just been written.
 *
 * For synchronous RPDOs this happens at the SYNC that commits them. Runs in the line thread
 * with the node's mutex held; must not block.
 *
 * @param node The node.
 * @param num RPDO number (0 = 1400h).
 * @param user_data As registered.
 */
typedef void (*co_rpdo_ind_t)(struct co_node *node, uint16_t num, void *user_data);

/**
 * @brief TPDO indication: TPDO @p num is about to be sampled.
 *
 * Called before the mapped objects are read (at SYNC, on RTR, on the event timer, on a
 * request), so that the application may refresh them. Writes made here do not count as
 * change-of-state events. Runs with the node's mutex held (line thread, or the thread that
 * called co_tpdo_send_req()); must not block.
 *
 * @param node The node.
 * @param num TPDO number (0 = 1800h).
 * @param user_data As registered.
 */
typedef void (*co_tpdo_ind_t)(struct co_node *node, uint16_t num, void *user_data);

/** @cond INTERNAL_HIDDEN */
#ifdef CONFIG_CANOPEN_PDO_MAP_ENTRIES
#define CO_PDO_MAP_ENTRIES CONFIG_CANOPEN_PDO_MAP_ENTRIES
#else
#define CO_PDO_MAP_ENTRIES 8
#endif
#ifdef CONFIG_CANOPEN_RPDOS
#define CO_RPDOS CONFIG_CANOPEN_RPDOS
#else
#define CO_RPDOS 4
#endif
#ifdef CONFIG_CANOPEN_TPDOS
#define CO_TPDOS CONFIG_CANOPEN_TPDOS
#else
#define CO_TPDOS 4
#endif

/* How a frame moves a mapped object (co_pdo_map_ent.move). */
enum co_pdo_move {
	CO_PDO_MOVE_SKIP = 0,    /* a dummy: its bits are skipped */
	CO_PDO_MOVE_COPY,        /* a copy between the frame and the RAM value */
	CO_PDO_MOVE_COPY_NOTIFY, /* an RPDO's copy, then the object's notify hooks */
	CO_PDO_MOVE_COPY_HOOK,   /* an RPDO's copy, then its one hook, a notify hook (hook) */
	CO_PDO_MOVE_ACCESS,      /* through the dictionary's accessors (checks, hooks, bits) */
};

/*
 * One mapped object, resolved once when the mapping is enabled: the object, and how a frame
 * moves it as long as the dictionary's hooks stay as they were (co_pdo_map.hook_gen).
 */
struct co_pdo_map_ent {
	/* The object's descriptor; NULL for a dummy and for a provider's object. */
	const struct co_od_sub *desc;
	uint16_t index; /* object index; a dummy's: its type 0001h-0007h */
	uint16_t entry; /* position of the object's dictionary entry, CO_OD_NO_ENTRY if none */
	uint16_t hook;  /* CO_PDO_MOVE_COPY_HOOK: the hook's position in co_od.hooks */
	uint8_t sub;    /* sub-index (0 for a dummy) */
	uint8_t size;   /* object size on the wire in bytes, 1-8 (a dummy's: its type's) */
	uint8_t bits;   /* mapped length in bits */
	uint8_t move;   /* enum co_pdo_move */
};

/* A compiled mapping: entries in frame order, bit offsets implied by their lengths. */
struct co_pdo_map {
	struct co_pdo_map_ent ent[CO_PDO_MAP_ENTRIES];
	uint32_t hook_gen; /* co_od.hook_gen the moves were resolved at (0: not yet) */
	uint8_t n;         /* entries in use */
	uint8_t bits;      /* total mapped length, 0..64 */
	bool bytewise;     /* every entry is a whole number of bytes */
};

struct co_rpdo {
	struct co_rx rx;
	struct co_timer timer; /* deadline monitor (event timer, 1400h sub 5) */
	struct co_pdo_map map;
	struct co_node *node;
	uint32_t cob_id;
	uint16_t event_ms;
	uint16_t num;
	uint8_t type;
	uint8_t errors; /* active EMCY causes of this RPDO (length, timeout) */
	uint8_t sync_dlc;
	uint8_t sync_data[8]; /* synchronous RPDO held until the next SYNC */
	uint8_t mpdo;         /* 0, or CO_MPDO_SAM/CO_MPDO_DAM (mapping sub 0) */
	bool present;
	bool sync_pending;
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/* The last frames taken, to drop their copies from the other line (redundancy). */
	struct co_rdn_taken taken[CONFIG_CANOPEN_REDUNDANCY_DUP_DEPTH];
	uint8_t taken_next;
#endif
};

struct co_tpdo {
#if defined(CONFIG_CANOPEN_PDO_RTR)
	struct co_rx rx; /* remote requests */
#endif
	struct co_timer inhibit_timer; /* end of the inhibit time */
	struct co_timer event_timer;   /* event timer, 1800h sub 5 */
	struct co_pdo_map map;
	struct co_node *node;
	co_time4_t inhibit_end; /* 4-aligned: no padding before it on a 32-bit target */
	uint32_t cob_id;
	uint32_t inhibit_us;
	uint16_t event_ms;
	uint16_t num;
	uint8_t type;
	uint8_t sync_start;
	uint8_t sync_count;
	uint8_t dlc;
	uint8_t buf[8];  /* the sample of a synchronous TPDO */
	uint8_t n_hooks; /* change-of-state hooks registered for the mapped objects */
	uint8_t mpdo;    /* 0, or CO_MPDO_SAM/CO_MPDO_DAM (mapping sub 0) */
	bool present;
	bool started;  /* cyclic: counting SYNCs (start value reached) */
	bool event;    /* an event waits (type 0: for SYNC; 254/255: for the inhibit time) */
	bool deferred; /* buf waits for the inhibit time (synchronous types) */
	bool sampled;  /* buf holds a sample (type 252) */
	bool sampling; /* the TPDO indication runs: ignore change-of-state */
};

struct co_pdo {
	struct co_rpdo rpdo[CO_RPDOS];
	struct co_tpdo tpdo[CO_TPDOS];
	uint64_t window_end; /* end of the SYNC window of the last SYNC */
	bool window;         /* window_end applies */
	bool operational;
	bool rx_sync_pending; /* an RPDO may hold a frame for the next SYNC (sync_pending) */
	co_rpdo_ind_t rpdo_ind;
	void *rpdo_ind_user_data;
	co_tpdo_ind_t tpdo_ind;
	void *tpdo_ind_user_data;
	uint64_t mpdo_scan; /* bit i: 1FA0h + i is in the dictionary */
	uint64_t mpdo_disp; /* bit i: 1FD0h + i is in the dictionary */
	struct co_mpdo_stats mpdo_stats;
	/* SYNC reaches the PDOs as a node event. */
	struct co_listener sync_listener;
#if defined(CONFIG_CANOPEN_REDUNDANCY)
	/* RPDO frames dropped as the other line's copy of a frame already taken. */
	uint32_t rx_duplicates;
	/* Per line: the supervised nodes whose heartbeat is lost there (CO_EV_REDUNDANCY). */
	uint32_t hb_lost[2][4];
#endif
};
/** @endcond */

/**
 * @brief RPDO frames dropped as copies from the other line (redundancy, CiA 302-6).
 *
 * A node on two lines hears each PDO twice; a frame with the same data as one of the last
 * CONFIG_CANOPEN_REDUNDANCY_DUP_DEPTH frames taken from the other line, within
 * CONFIG_CANOPEN_REDUNDANCY_DUP_WINDOW_US of it, is that frame's copy and is dropped, so the
 * application sees every value once; a copy also ends the wait for the copies of the frames
 * taken before it (a line keeps the order sent). Always 0 without CONFIG_CANOPEN_REDUNDANCY.
 */
uint32_t co_pdo_rx_duplicates(struct co_node *node);

/**
 * @brief Request the transmission of a TPDO (an application event).
 *
 * Event-driven TPDOs (254, 255) are sampled and sent now, or, while the inhibit time runs,
 * once when it ends (requests in between are merged). A type 0 TPDO is sampled and sent at
 * the next SYNC. The caller never has to retry.
 *
 * @param node The node.
 * @param num TPDO number (0 = 1800h).
 * @retval 0 Sent, or scheduled.
 * @retval -EINVAL No such TPDO, or it is not valid (COB-ID bit 31).
 * @retval -ENETDOWN The node is not Operational.
 * @retval -ENOTSUP The transmission type is not triggered by events (1..240, 252, 253).
 */
int co_tpdo_send_req(struct co_node *node, uint16_t num);

/**
 * @brief Send a DAM-MPDO: write @p data into object @p index / @p sub of node @p dest_id.
 *
 * TPDO @p num must be valid with mapping sub 0 = FFh (CO_MPDO_DAM). The frame is sent now,
 * or when the inhibit time of the TPDO ends. Needs CONFIG_CANOPEN_MPDO.
 *
 * @param node The node.
 * @param num TPDO number (0 = 1800h).
 * @param dest_id Destination node-ID 1..127, or 0 for every node.
 * @param index Index of the object in the destination's dictionary.
 * @param sub Sub-index of that object.
 * @param data Value in CANopen (little-endian) order.
 * @param len Length of @p data, 1..4 bytes.
 * @retval 0 Sent, or scheduled for the end of the inhibit time.
 * @retval -EINVAL No such TPDO, not valid, not a DAM-MPDO, or a bad argument.
 * @retval -ENETDOWN The node is not Operational.
 * @retval -EBUSY An MPDO of this TPDO already waits for the end of the inhibit time.
 * @retval -ENOTSUP Built without CONFIG_CANOPEN_MPDO.
 */
int co_mpdo_dam_req(struct co_node *node, uint16_t num, uint8_t dest_id, uint16_t index,
		    uint8_t sub, const void *data, size_t len);

/**
 * @brief Send a SAM-MPDO carrying the present value of local object @p index / @p sub.
 *
 * TPDO @p num must be valid with mapping sub 0 = FEh (CO_MPDO_SAM), and the object must be
 * listed in the object scanner list (1FA0h-1FCFh). The value is read now; the frame is sent
 * now, or when the inhibit time ends. Needs CONFIG_CANOPEN_MPDO.
 *
 * @param node The node.
 * @param num TPDO number (0 = 1800h).
 * @param index Index of the local object.
 * @param sub Sub-index of the local object.
 * @retval 0 Sent, or scheduled for the end of the inhibit time.
 * @retval -EINVAL No such TPDO, not valid, or not a SAM-MPDO.
 * @retval -ENOENT The object is not in the scanner list.
 * @retval -EIO The object cannot be read (missing, not mappable into a TPDO).
 * @retval -ENETDOWN The node is not Operational.
 * @retval -EBUSY An MPDO of this TPDO already waits for the end of the inhibit time.
 * @retval -ENOTSUP Built without CONFIG_CANOPEN_MPDO.
 */
int co_mpdo_sam_req(struct co_node *node, uint16_t num, uint16_t index, uint8_t sub);

/** @brief Copy the MPDO receive counters of the node into @p stats. */
void co_mpdo_get_stats(struct co_node *node, struct co_mpdo_stats *stats);

/** @brief Set the RPDO indication (NULL removes it). */
void co_rpdo_set_ind(struct co_node *node, co_rpdo_ind_t cb, void *user_data);

/** @brief Set the TPDO indication (NULL removes it). */
void co_tpdo_set_ind(struct co_node *node, co_tpdo_ind_t cb, void *user_data);

#ifdef __cplusplus
}
#endif

/** @} */

#endif /* SAFELINE_INCLUDE_CANOPEN_PDO_H_ */
