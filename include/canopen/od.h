/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief CANopen object dictionary (CiA 301 §7.4, CiA 306).
 *
 * The dictionary of a node has two parts:
 *  - a generated, const description (struct co_od_def): entries sorted by index, their
 *    sub-index descriptors, limits, the RAM default template and the ROM values;
 *  - a per-node instance (struct co_od) that points at the description and at the node's own
 *    RAM value block, and holds the node's hooks, object providers and staging buffer.
 *
 * Every access goes through this layer: lookup, access rights of the writer, size, limits,
 * the validate hooks (which may refuse with an abort code before anything changes), the
 * commit, then the notify hooks. A refused write of any size leaves the old value intact.
 *
 * Locking: the object dictionary does not lock. It is owned by its node and every call
 * must be made with the node's mutex held (co_node_lock()), as the services do from the
 * line thread. Hooks run in the caller's context with that mutex held and must not block.
 *
 * Generated code: scripts/eds2od turns an EDS/DCF into NAME_od.h / NAME_od.c declaring
 * `extern const struct co_od_def NAME_od_def;` and `struct NAME_od_ram`, the RAM block type.
 */

#ifndef SAFELINE_INCLUDE_CANOPEN_OD_H_
#define SAFELINE_INCLUDE_CANOPEN_OD_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <canopen/sdo_abort.h>
#include <canopen/types.h>

struct k_mutex;

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @defgroup co_od Object dictionary
 * @{
 */

/** @cond INTERNAL_HIDDEN */
#ifdef CONFIG_CANOPEN_OD_HOOKS_MAX
#define CO_OD_HOOKS_MAX CONFIG_CANOPEN_OD_HOOKS_MAX
#else
#define CO_OD_HOOKS_MAX 32
#endif
#ifdef CONFIG_CANOPEN_OD_HOOK_LINKS
#define CO_OD_HOOK_LINKS CONFIG_CANOPEN_OD_HOOK_LINKS
#else
#define CO_OD_HOOK_LINKS 64
#endif
/* Object providers: on unless a Kconfig build turned CONFIG_CANOPEN_OD_PROVIDERS off. */
#if defined(CONFIG_CANOPEN_OD_PROVIDERS) || !defined(CONFIG_CANOPEN_OD)
#define CO_OD_PROVIDERS 1
#else
#define CO_OD_PROVIDERS 0
#endif
#ifdef CONFIG_CANOPEN_OD_PROVIDERS_MAX
#define CO_OD_PROVIDERS_MAX CONFIG_CANOPEN_OD_PROVIDERS_MAX
#elif CO_OD_PROVIDERS
#define CO_OD_PROVIDERS_MAX 4
#else
#define CO_OD_PROVIDERS_MAX 0
#endif
#ifdef CONFIG_CANOPEN_OD_SCRATCH_SIZE
#define CO_OD_SCRATCH_SIZE CONFIG_CANOPEN_OD_SCRATCH_SIZE
#else
#define CO_OD_SCRATCH_SIZE 256
#endif
/** @endcond */

/** @brief Object codes (CiA 301 §7.4.3; EDS ObjectType). */
enum co_od_objcode {
	CO_OD_OBJ_DOMAIN = 0x2,
	CO_OD_OBJ_DEFTYPE = 0x5,
	CO_OD_OBJ_DEFSTRUCT = 0x6,
	CO_OD_OBJ_VAR = 0x7,
	CO_OD_OBJ_ARRAY = 0x8,
	CO_OD_OBJ_RECORD = 0x9,
};

/** @brief EDS access types (CiA 306 AccessType), kept exactly for EDS regeneration. */
enum co_od_access {
	CO_OD_ACCESS_RO = 0,    /**< read only; the device may change the value */
	CO_OD_ACCESS_WO = 1,    /**< write only */
	CO_OD_ACCESS_RW = 2,    /**< read and write */
	CO_OD_ACCESS_RWR = 3,   /**< read and write; mappable into TPDOs only */
	CO_OD_ACCESS_RWW = 4,   /**< read and write; mappable into RPDOs only */
	CO_OD_ACCESS_CONST = 5, /**< constant; kept in the ROM block */
};

/**
 * @name Sub-index flags (struct co_od_sub.flags, struct co_od_info.flags)
 * @{
 */
/** EDS PDOMapping=1: the object may be mapped (direction from the access type). */
#define CO_OD_F_MAP     0x01U
/** The value lives in the const ROM block. */
#define CO_OD_F_ROM     0x02U
/** The default is "$NODEID + base" and is recomputed at every Reset Communication. */
#define CO_OD_F_NODEID  0x04U
/** limit refers to an entry in the limit table. */
#define CO_OD_F_LIMITS  0x08U
/** The EDS gave a DefaultValue (kept for EDS regeneration). */
#define CO_OD_F_DEFAULT 0x10U
/** Provider objects only: write chunks go straight to the provider, not staged. */
#define CO_OD_F_STREAM  0x20U
/** Saved and restored with the storage group of its object (1010h/1011h). */
#define CO_OD_F_STORE   0x40U
/** @} */

/** @brief Storage groups of CiA 301 1010h/1011h; the sub-index of "all" is 1. */
enum co_od_group {
	CO_OD_GROUP_NONE = 0,  /**< not stored (volatile) */
	CO_OD_GROUP_COMM = 1,  /**< communication parameters, 1000h-1FFFh (1010h sub 2) */
	CO_OD_GROUP_APP = 2,   /**< application parameters, 6000h-9FFFh and up (1010h sub 3) */
	CO_OD_GROUP_MANUF = 3, /**< manufacturer parameters, 2000h-5FFFh (1010h sub 4) */
	CO_OD_GROUP_COUNT,
};

/** @brief Bit of a group in a group mask. */
#define CO_OD_GROUP_BIT(g) (1U << (g))
/** @brief Every stored group. */
#define CO_OD_GROUP_ALL                                                                            \
	(CO_OD_GROUP_BIT(CO_OD_GROUP_COMM) | CO_OD_GROUP_BIT(CO_OD_GROUP_APP) |                    \
	 CO_OD_GROUP_BIT(CO_OD_GROUP_MANUF))

/** @brief Who reads or writes an object; decides access rights and is passed to hooks. */
enum co_od_writer {
	CO_OD_WRITER_SDO = 0, /**< SDO server (needs SDO read/write access) */
	CO_OD_WRITER_PDO,     /**< PDO (needs TPDO/RPDO mappability) */
	CO_OD_WRITER_SRDO,    /**< SRDO (needs TPDO/RPDO mappability) */
	CO_OD_WRITER_MPDO,    /**< MPDO: DAM writes need SDO write access, SAM reads mappability */
	CO_OD_WRITER_APP,     /**< the application: any access except writing ROM */
	CO_OD_WRITER_STORAGE, /**< storage restore at reset: like APP */
	CO_OD_WRITER_COUNT,
};

/** @brief A numeric limit or value, interpreted by the data type's class. */
union co_od_num {
	int64_t i;  /**< INT class */
	uint64_t u; /**< UINT, BOOL and TIME classes */
	double f;   /**< REAL class */
};

/** @brief LowLimit/HighLimit of one sub-index. */
struct co_od_limit {
	union co_od_num lo; /**< lowest allowed value */
	union co_od_num hi; /**< highest allowed value */
	/**
	 * bit 0: lo is $NODEID-relative, bit 1: hi is $NODEID-relative,
	 * bit 2: the EDS gave LowLimit, bit 3: the EDS gave HighLimit
	 */
	uint8_t rel;
};

/** @brief Const descriptor of one sub-index (generated). */
struct co_od_sub {
	uint32_t offset; /**< byte offset of the value in the RAM or ROM block */
	uint32_t size;   /**< size on the wire in bytes; capacity for strings and domains */
	uint16_t limit;  /**< index in co_od_def.limits when CO_OD_F_LIMITS is set */
	uint16_t name;   /**< offset of the ParameterName in co_od_def.names */
	uint8_t sub;     /**< sub-index */
	uint8_t dtype;   /**< enum co_dtype */
	uint8_t access;  /**< enum co_od_access */
	uint8_t flags;   /**< CO_OD_F_* */
};

/** @brief Const descriptor of one index (generated; the table is sorted by index). */
struct co_od_entry {
	uint16_t index;  /**< object index */
	uint16_t first;  /**< position of its first sub-index in co_od_def.subs */
	uint16_t n_subs; /**< number of sub-index descriptors, sorted by sub-index */
	uint16_t name;   /**< offset of the ParameterName in co_od_def.names */
	uint8_t objcode; /**< enum co_od_objcode */
	uint8_t group;   /**< enum co_od_group */
};

/** @brief A $NODEID-relative default: value = base + node-ID (generated). */
struct co_od_nodeid {
	uint32_t sub;   /**< position in co_od_def.subs */
	uint16_t index; /**< index of the object */
	int64_t base;   /**< the formula's constant */
};

/** @brief The whole generated description of one dictionary. */
struct co_od_def {
	const struct co_od_entry *entries; /**< sorted by index */
	const struct co_od_sub *subs;      /**< grouped per entry, sorted by sub-index */
	const struct co_od_limit *limits;
	const struct co_od_nodeid *nodeid;
	const void *ram_defaults; /**< RAM template (defaults with the DCF node-ID) */
	const void *rom;          /**< values of const objects */
	const char *names;        /**< ParameterName pool, NULL if not built in */
	const char *eds_header;   /**< FileInfo/DeviceInfo/... text, NULL if not built */
	uint32_t ram_size;        /**< bytes of values at the start of the RAM block */
	uint32_t comm_end;        /**< RAM [0, comm_end) holds 1000h-1FFFh values */
	/** offset in the RAM block of the node's hook heads, one uint16_t per entry */
	uint32_t hook_heads;
	uint16_t n_entries;
	uint16_t n_nodeid;
	uint32_t n_subs;
	uint32_t max_staged; /**< largest RAM value that can need staging */
	uint8_t node_id;     /**< DCF [DeviceComissioning] NodeID, 0 if none */
};

struct co_od;
struct co_od_provider;

/**
 * @brief Everything an accessor needs to know about one sub-index.
 *
 * Filled by co_od_find() for dictionary and provider objects alike. It stays valid while
 * the dictionary and its providers are unchanged, so services (PDO) may keep it and use the
 * *_info() accessors on their hot paths without a new lookup.
 */
struct co_od_info {
	const struct co_od_sub *desc;      /**< dictionary descriptor, NULL for provider objects */
	const struct co_od_provider *prov; /**< provider, NULL for dictionary objects */
	const struct co_od_limit *limit;   /**< limits or NULL */
	uint32_t size;                     /**< capacity on the wire in bytes */
	uint16_t index;                    /**< object index */
	uint8_t sub;                       /**< sub-index */
	uint8_t dtype;                     /**< enum co_dtype */
	uint8_t access;                    /**< enum co_od_access */
	uint8_t flags;                     /**< CO_OD_F_* */
	uint8_t objcode;                   /**< enum co_od_objcode */
	uint8_t group;                     /**< enum co_od_group */
	/** position of the object's entry in co_od_def.entries; CO_OD_NO_ENTRY if none */
	uint16_t entry;
};

/** @brief co_od_info.entry of a provider's object outside the dictionary. */
#define CO_OD_NO_ENTRY 0xFFFFU

/**
 * @brief Validate return value: the write is a command that the hook carried out.
 *
 * Nothing is stored (the object keeps its value, e.g. 1010h keeps reading 1), the writer
 * is told the write succeeded and the notify hooks still run.
 */
#define CO_OD_HANDLED 0xFFFFFFFFU

/** @brief A write as the hooks see it. */
struct co_od_req {
	const struct co_od_info *info; /**< the object written */
	enum co_od_writer writer;      /**< who writes */
	const uint8_t *data;           /**< new value in CiA wire format (little endian) */
	size_t len;                    /**< length of data in bytes */
};

/**
 * @brief Validate hook: decide whether a write may happen.
 *
 * Runs before anything is written, after the access, size and limit checks passed.
 * Runs in the caller's thread with the node's mutex held; must not block.
 *
 * @param od        dictionary written
 * @param req       the write (each hook gets its own copy of the request; the data is const)
 * @param user_data as registered
 * @retval 0 accept the write
 * @retval CO_OD_HANDLED the hook carried out a command; store nothing, report success
 * @retval abort code refuse it; the value is left unchanged and the code reported
 */
typedef uint32_t (*co_od_validate_cb)(struct co_od *od, struct co_od_req *req, void *user_data);

/**
 * @brief Notify hook: a write has been committed.
 *
 * Runs in the caller's thread with the node's mutex held; must not block.
 *
 * @param od        dictionary written
 * @param req       the write that happened
 * @param user_data as registered
 */
typedef void (*co_od_notify_cb)(struct co_od *od, const struct co_od_req *req, void *user_data);

/**
 * @brief Read-check hook: decide whether a read by an SDO, PDO, SRDO or MPDO reader may
 * happen (application and storage reads are not checked).
 *
 * Runs in the caller's thread with the node's mutex held; must not block.
 *
 * @retval 0 allow the read
 * @retval abort code refuse it (e.g. CO_SDO_AB_NO_DATA for an entry beyond a count)
 */
typedef uint32_t (*co_od_read_check_cb)(const struct co_od *od, const struct co_od_info *info,
					enum co_od_writer reader, void *user_data);

/** Defined when struct co_od_hook has read_check. */
#define CO_OD_HOOK_READ_CHECK 1

/**
 * @brief A hook on a range of indexes and sub-indexes.
 *
 * Either callback may be NULL. Several hooks may cover the same sub-index: every validate
 * hook must accept, and every notify hook is called, in registration order.
 */
struct co_od_hook {
	uint16_t index_first; /**< first index covered */
	uint16_t index_last;  /**< last index covered (>= index_first) */
	uint8_t sub_first;    /**< first sub-index covered */
	uint8_t sub_last;     /**< last sub-index covered (>= sub_first) */
	co_od_validate_cb validate;
	co_od_notify_cb notify;
	void *user_data;
	/** Optional read check (NULL: none); last so that positional initialisers stay valid. */
	co_od_read_check_cb read_check;
};

/** @cond INTERNAL_HIDDEN */
/* A registered hook: the caller's struct co_od_hook and its registration number. */
struct co_od_hook_ent {
	struct co_od_hook hook;
	uint32_t seq; /* registration number: orders the hooks of an object */
};

/*
 * One hook of one entry: the hooks of an entry are a list of links in registration order,
 * headed in the node's RAM block (co_od_def.hook_heads). Links are numbered from 1; 0 ends a
 * list.
 */
struct co_od_hook_link {
	uint16_t hook; /* position in co_od.hooks */
	uint16_t next; /* number of the entry's next link, 0: none */
};
/** @endcond */

/**
 * @brief Callback that restores stored groups (registered by the storage module).
 *
 * @param od         dictionary being reset
 * @param group_mask CO_OD_GROUP_BIT() of each group to restore
 * @param user_data  as registered
 */
typedef void (*co_od_restore_cb)(struct co_od *od, uint32_t group_mask, void *user_data);

/**
 * @brief Operations of an object provider ("virtual objects" the application serves).
 *
 * Called with the node's mutex held, in the caller's thread; must not block.
 */
struct co_od_provider_api {
	/**
	 * @brief Describe (index, sub): fill dtype, access, flags, size, objcode and limit.
	 *
	 * info->index, info->sub and info->prov are set by the caller. For strings and domains
	 * size is the capacity. Return CO_SDO_AB_NO_OBJECT or CO_SDO_AB_NO_SUB if absent.
	 */
	uint32_t (*info)(const struct co_od_provider *p, struct co_od_info *info);
	/**
	 * @brief Current length in bytes of the value (strings, domains), or info->size.
	 */
	uint32_t (*length)(const struct co_od_provider *p, const struct co_od_info *info);
	/** @brief Copy up to @p cap bytes of the wire value from @p offset; set *len. */
	uint32_t (*read)(const struct co_od_provider *p, const struct co_od_info *info,
			 uint32_t offset, void *buf, size_t cap, size_t *len);
	/**
	 * @brief Store @p len wire bytes at @p offset.
	 *
	 * Without CO_OD_F_STREAM this is called once with the whole, validated value
	 * (offset 0, last true), so it is the commit and should not fail. With CO_OD_F_STREAM it
	 * is called per chunk, and the validate hooks only see the last chunk.
	 */
	uint32_t (*write)(const struct co_od_provider *p, const struct co_od_info *info,
			  uint32_t offset, const void *data, size_t len, bool last);
};

/** @brief An object provider serving a range of indexes that are not in the dictionary. */
struct co_od_provider {
	const struct co_od_provider_api *api;
	uint16_t index_first; /**< first index served */
	uint16_t index_last;  /**< last index served */
	void *user_data;      /**< for the provider's own use */
};

/**
 * @brief State of a chunked write (segmented/block SDO, domains); owned by the caller.
 */
struct co_od_xfer {
	struct co_od_info info;   /**< the object */
	enum co_od_writer writer; /**< who writes */
	uint32_t offset;          /**< bytes received so far */
	uint32_t total;           /**< announced size, 0 if unknown */
	uint8_t small[8];         /**< staging for values up to 8 bytes */
	bool active;              /**< between begin and last chunk/abort */
	bool scratch;             /**< holds the dictionary's scratch buffer */
};

/** @brief Per-node dictionary instance. */
struct co_od {
	const struct co_od_def *def; /**< generated description */
	uint8_t *ram;                /**< the node's RAM value block (struct NAME_od_ram) */
	uint8_t node_id;             /**< node-ID used for $NODEID values */
	/** the owning node's mutex, which accessors require (NULL: a dictionary of its own) */
	const struct k_mutex *lock;
	/** each entry's first hook link, in the node's RAM block (co_od_def.hook_heads) */
	uint16_t *hook_heads;
	uint16_t n_hooks; /**< registered hooks */
	uint16_t n_links; /**< hook links in use */
#if CO_OD_PROVIDERS
	uint8_t n_prov;
#endif
	co_od_restore_cb restore;
	void *restore_user_data;
	const struct co_od_xfer *scratch_owner;
	/** the registered hooks in registration order */
	struct co_od_hook_ent hooks[CO_OD_HOOKS_MAX];
	/** links of the entries to the hooks covering them */
	struct co_od_hook_link links[CO_OD_HOOK_LINKS];
	uint32_t hook_next_seq; /**< registration number of the next hook */
	/**
	 * Bumped by every hook registration and removal: a hook loop that called out re-finds
	 * its place when it changed, and a PDO resolves its mapping again when it differs from
	 * the value it resolved it at.
	 */
	uint32_t hook_gen;
#if CO_OD_PROVIDERS
	const struct co_od_provider *prov[CO_OD_PROVIDERS_MAX]; /**< sorted by index_first */
#endif
	/** staging for chunked writes of values over 8 bytes (validate, then commit) */
	uint8_t scratch[CO_OD_SCRATCH_SIZE] __attribute__((aligned(8)));
};

/**
 * @name Data types
 * @{
 */
/** @brief Wire size of a data type in bytes; 0 for variable-length types and unknown ones. */
uint32_t co_dtype_size(uint8_t dtype);
/** @brief Class of a data type (enum co_dtype_class); CO_DTYPE_CLASS_NONE if unknown. */
enum co_dtype_class co_dtype_class(uint8_t dtype);
/** @brief Name of a data type ("UNSIGNED32"), or NULL if unknown. */
const char *co_dtype_name(uint8_t dtype);
/** @} */

/**
 * @name Instance life cycle
 * @{
 */

/**
 * @brief Bind a dictionary instance to its description and RAM block; load all defaults.
 *
 * No stored values are restored here: the NMT reset sequence calls co_od_reset_app() and
 * co_od_reset_comm(), which do.
 *
 * @param od      instance to initialise
 * @param def     generated description (NAME_od_def)
 * @param ram     the node's RAM block, def->ram_size bytes (a struct NAME_od_ram)
 * @param node_id node-ID for $NODEID values, 1..127, or 0/255 (unconfigured: base only)
 * @retval 0 success
 * @retval -EINVAL a NULL argument, or a description whose largest value does not fit
 *         CONFIG_CANOPEN_OD_SCRATCH_SIZE (the generated code also checks this at build time)
 */
int co_od_init(struct co_od *od, const struct co_od_def *def, void *ram, uint8_t node_id);

/**
 * @brief Set the node-ID used for $NODEID values from the next co_od_reset_comm().
 *
 * @retval 0 success
 * @retval -EINVAL node_id is not 1..127 or 255 (unconfigured)
 */
int co_od_set_node_id(struct co_od *od, uint8_t node_id);

/**
 * @brief Reset Communication: reload 1000h-1FFFh (CiA 301 §7.3.2.2.1).
 *
 * Loads the defaults of every object in 1000h-1FFFh, recomputes $NODEID values with the
 * current node-ID, then lets the restore callback (storage) apply the stored communication
 * group through the accessors (writer CO_OD_WRITER_STORAGE). Hooks are not called for the
 * defaults: services re-read their objects when they restart after the reset.
 */
void co_od_reset_comm(struct co_od *od);

/**
 * @brief Reset Application: reload 2000h-FFFFh (manufacturer and profile areas).
 *
 * Loads their defaults, recomputes $NODEID values there, then restores the stored
 * manufacturer and application groups. Reset Node is co_od_reset_app() followed by
 * co_od_reset_comm().
 */
void co_od_reset_app(struct co_od *od);

/**
 * @brief Register the callback that restores stored groups at a reset (storage module).
 *
 * @retval 0 success
 * @retval -EINVAL od is NULL
 */
int co_od_set_restore_cb(struct co_od *od, co_od_restore_cb cb, void *user_data);
/** @} */

/**
 * @name Hooks and providers
 * @{
 */

/**
 * @brief Register a hook (copied into the instance).
 *
 * May be called from inside a hook: the running write still calls every hook that was
 * registered when its hook loop started and is still registered, each once; the new hook
 * takes part from the next write on. co_od_hook_unregister() likewise.
 *
 * @retval 0 success
 * @retval -EINVAL bad ranges or both callbacks (validate, notify) NULL
 * @retval -ENOSPC CONFIG_CANOPEN_OD_HOOKS_MAX hooks are registered, or the links of the
 *         dictionary's entries to their hooks (one per entry a hook covers) would pass
 *         CONFIG_CANOPEN_OD_HOOK_LINKS; nothing is registered then
 */
int co_od_hook_register(struct co_od *od, const struct co_od_hook *hook);

/**
 * @brief Register @p n hooks (a service's table of hooks on its objects).
 * @retval 0 success
 * @retval -EINVAL or -ENOSPC as co_od_hook_register(), for the first hook that failed; none
 *         of the @p n hooks is registered then
 */
int co_od_hooks_register(struct co_od *od, const struct co_od_hook *hooks, size_t n);

/**
 * @brief Remove every hook registered with @p user_data.
 *
 * @return the number of hooks removed
 */
int co_od_hook_unregister(struct co_od *od, const void *user_data);

/**
 * @brief Register an object provider for indexes absent from the dictionary.
 *
 * The dictionary's own objects take precedence; a provider also serves DOMAIN objects of
 * the dictionary that have no RAM (capacity 0) within its range. The provider must outlive
 * the dictionary instance.
 *
 * @retval 0 success
 * @retval -EINVAL bad range or missing operations
 * @retval -EEXIST the range overlaps another provider
 * @retval -ENOSPC CONFIG_CANOPEN_OD_PROVIDERS_MAX providers already registered
 * @retval -ENOTSUP CONFIG_CANOPEN_OD_PROVIDERS is off
 */
int co_od_provider_register(struct co_od *od, const struct co_od_provider *p);
/** @} */

/**
 * @name Access
 * @{
 */

/**
 * @brief Look up (index, sub) in the dictionary, then in the providers. O(log n).
 *
 * @retval 0 found; @p info filled
 * @retval CO_SDO_AB_NO_OBJECT no such index
 * @retval CO_SDO_AB_NO_SUB    the index exists, the sub-index does not
 */
uint32_t co_od_find(const struct co_od *od, uint16_t index, uint8_t sub, struct co_od_info *info);

/**
 * @brief Fill @p info for a dictionary object from its descriptor, as co_od_find() does.
 *
 * For a caller that keeps the descriptor of an object found once (and its entry's position)
 * and needs its info again (a PDO mapping entry calling a notify hook).
 *
 * @param od    dictionary of @p desc
 * @param entry position of the object's entry in co_od_def.entries
 * @param desc  sub-index descriptor of a dictionary object (not a provider's)
 * @param info  filled
 */
void co_od_info_fill(const struct co_od *od, uint16_t entry, const struct co_od_sub *desc,
		     struct co_od_info *info);

/** @cond INTERNAL_HIDDEN */
/* co_od_info_fill() inline, for a hot path (a PDO's notify hooks). */
static inline void co_od_info_fill_inline(const struct co_od *od, uint16_t entry,
					  const struct co_od_sub *desc, struct co_od_info *info)
{
	const struct co_od_entry *e = &od->def->entries[entry];

	info->desc = desc;
	info->prov = NULL;
	info->limit = (desc->flags & CO_OD_F_LIMITS) != 0U ? &od->def->limits[desc->limit] : NULL;
	info->size = desc->size;
	info->index = e->index;
	info->sub = desc->sub;
	info->dtype = desc->dtype;
	info->access = desc->access;
	info->flags = desc->flags;
	info->objcode = e->objcode;
	info->group = e->group;
	info->entry = entry;
}
/** @endcond */

/** @brief Current length in bytes of the value (strings up to the NUL, domains). */
uint32_t co_od_length(const struct co_od *od, const struct co_od_info *info);

/**
 * @brief Read wire bytes of a value from @p offset.
 *
 * @param od     dictionary
 * @param info   object, from co_od_find()
 * @param offset first byte wanted
 * @param buf    destination
 * @param cap    capacity of buf
 * @param len    bytes copied (the rest of the value if it fits)
 * @param reader who reads (access rights)
 * @retval 0 success
 * @retval CO_SDO_AB_WRITEONLY the reader may not read it
 * @retval CO_SDO_AB_NO_MAP    a PDO/SRDO/MPDO reader and the object is not TPDO-mappable
 * @retval other abort codes from a provider
 */
uint32_t co_od_read_info(const struct co_od *od, const struct co_od_info *info, uint32_t offset,
			 void *buf, size_t cap, size_t *len, enum co_od_writer reader);

/** @brief co_od_find() then co_od_read_info(). */
uint32_t co_od_read(const struct co_od *od, uint16_t index, uint8_t sub, uint32_t offset, void *buf,
		    size_t cap, size_t *len, enum co_od_writer reader);

/**
 * @brief Write a whole value in wire format: check, validate, commit, notify.
 *
 * @retval 0 written, or carried out by a hook as a command (CO_OD_HANDLED)
 * @retval CO_SDO_AB_READONLY      the writer may not write it, or it is const
 * @retval CO_SDO_AB_NO_MAP        a PDO/SRDO writer and the object is not RPDO-mappable
 * @retval CO_SDO_AB_DATA_LONG     more bytes than the object holds
 * @retval CO_SDO_AB_DATA_SHORT    fewer bytes than a fixed-size object needs
 * @retval CO_SDO_AB_VALUE_HIGH    above HighLimit
 * @retval CO_SDO_AB_VALUE_LOW     below LowLimit
 * @retval CO_SDO_AB_INVALID_VALUE BOOLEAN other than 0/1
 * @retval other                   the code of a refusing validate hook or provider
 */
uint32_t co_od_write_info(struct co_od *od, const struct co_od_info *info, const void *data,
			  size_t len, enum co_od_writer writer);

/**
 * @name Resolved access for hot paths (PDO, SRDO)
 *
 * A service that keeps an object resolved (a compiled PDO mapping) asks once how a whole
 * value of it moves, co_od_move_of(), and asks again when co_od.hook_gen changed: a plain
 * copy between the frame and the RAM value (with, for a write, the object's notify hooks
 * after it, co_od_notify()), or the accessors co_od_write_info() / co_od_read_info(). Either
 * way the write or read behaves exactly as through the accessors (same checks, hooks and
 * abort codes).
 * @{
 */
/** @brief How a PDO or SRDO moves a whole value of an object (co_od_move_of()). */
enum co_od_move {
	/** through co_od_write_info() / co_od_read_info() */
	CO_OD_MOVE_ACCESS = 0,
	/** a copy of the wire bytes to or from the RAM value (co_od_value_ptr()) */
	CO_OD_MOVE_COPY,
	/** a write: the copy, then co_od_notify() */
	CO_OD_MOVE_COPY_NOTIFY,
};

/**
 * @brief How a whole value of @p info moves for @p who (a PDO or SRDO writer or reader).
 *
 * A copy when the object is a RAM value of a fixed-size type whose C storage is its wire
 * format, @p who may write (@p write) or read it, and nothing else would run: no limits or
 * BOOLEAN check and no validate hook for a write, no read-check hook for a read. The answer
 * stands while co_od.hook_gen is unchanged.
 */
enum co_od_move co_od_move_of(const struct co_od *od, const struct co_od_info *info,
			      enum co_od_writer who, bool write);

/**
 * @brief The notify pass of a write: every notify hook of the object, in registration
 * order, as co_od_write_info() runs it once the value is committed.
 */
void co_od_notify(struct co_od *od, const struct co_od_info *info, const void *data, size_t len,
		  enum co_od_writer writer);

/**
 * @brief The one hook of an object, when it has exactly one and that one is a notify hook
 * only: its position in co_od.hooks (valid while co_od.hook_gen is unchanged), else -1.
 *
 * Its notify pass is then one call of that hook (a hook it registers joins from the next
 * write on), which a PDO resolves once instead of walking the object's hooks per frame.
 */
int co_od_notify_only(const struct co_od *od, const struct co_od_info *info);

/**
 * @brief Copy a value of 1, 2, 4 or 8 bytes with constant lengths (inlined).
 * @return false, with nothing copied, for another length
 */
static inline bool co_od_copy_word(void *dst, const void *src, size_t n)
{
	switch (n) {
	case 1:
		memcpy(dst, src, 1);
		return true;
	case 2:
		memcpy(dst, src, 2);
		return true;
	case 4:
		memcpy(dst, src, 4);
		return true;
	case 8:
		memcpy(dst, src, 8);
		return true;
	default:
		return false;
	}
}
/** @} */

/** @brief co_od_find() then co_od_write_info(). */
uint32_t co_od_write(struct co_od *od, uint16_t index, uint8_t sub, const void *data, size_t len,
		     enum co_od_writer writer);

/**
 * @brief Start a chunked write (segmented or block SDO, streamed domains).
 *
 * Chunks are staged (in the xfer for up to 8 bytes, in the dictionary's scratch buffer
 * above) and the value is checked, validated and committed with the last chunk, so an
 * aborted or refused transfer leaves the old value intact. Streaming provider objects
 * (CO_OD_F_STREAM) receive the chunks directly.
 *
 * @param total announced size in bytes, 0 if unknown
 * @retval 0 started
 * @retval CO_SDO_AB_OUT_OF_MEM the scratch buffer is used by another transfer
 * @retval other the access or size checks of co_od_write_info() that can be made now
 */
uint32_t co_od_write_begin(struct co_od *od, struct co_od_xfer *x, uint16_t index, uint8_t sub,
			   uint32_t total, enum co_od_writer writer);

/**
 * @brief Add a chunk at @p offset (must equal x->offset); commit when @p last.
 *
 * On any non-zero return the transfer is over and the old value is intact.
 *
 * @retval 0 accepted (and committed if last)
 * @retval CO_SDO_AB_GENERAL  offset is not where the previous chunk ended, or no transfer
 * @retval CO_SDO_AB_DATA_LONG the object cannot hold that many bytes
 * @retval other as co_od_write_info()
 */
uint32_t co_od_write_chunk(struct co_od *od, struct co_od_xfer *x, uint32_t offset,
			   const void *data, size_t len, bool last);

/** @brief Drop a chunked write; the old value stays. Safe to call on an idle xfer. */
void co_od_write_abort(struct co_od *od, struct co_od_xfer *x);

/**
 * @brief Pointer to the value in the RAM or ROM block, or NULL for provider objects.
 *
 * The memory holds the C type of the data type (types.h), not the wire format. For direct
 * reads on hot paths with the node's mutex held; writes must go through the accessors.
 */
const void *co_od_value_ptr(const struct co_od *od, const struct co_od_info *info);

/** @brief True if the value currently equals its $NODEID default (base + node-ID). */
bool co_od_is_nodeid_default(const struct co_od *od, const struct co_od_info *info);
/** @} */

/**
 * @name Typed access
 *
 * The C type must be the object's storage type (types.h: UNSIGNED24 is uint32_t, INTEGER40
 * is int64_t, BOOLEAN is bool or uint8_t), else CO_SDO_AB_TYPE_MISMATCH. Getters read as
 * the application (no access check); setters take the writer.
 * @{
 */
#define CO_OD_TYPED_TABLE(X)                                                                       \
	X(u8, uint8_t)                                                                             \
	X(u16, uint16_t)                                                                           \
	X(u32, uint32_t)                                                                           \
	X(u64, uint64_t)                                                                           \
	X(i8, int8_t)                                                                              \
	X(i16, int16_t)                                                                            \
	X(i32, int32_t)                                                                            \
	X(i64, int64_t)                                                                            \
	X(f32, float)                                                                              \
	X(f64, double)                                                                             \
	X(bool, bool)

/** @cond INTERNAL_HIDDEN */
#define CO_OD_TYPED_DECL_(sfx, ctype)                                                              \
	uint32_t co_od_get_##sfx(const struct co_od *od, uint16_t index, uint8_t sub,              \
				 ctype *value);                                                    \
	uint32_t co_od_set_##sfx(struct co_od *od, uint16_t index, uint8_t sub, ctype value,       \
				 enum co_od_writer writer);
CO_OD_TYPED_TABLE(CO_OD_TYPED_DECL_)
#undef CO_OD_TYPED_DECL_
/** @endcond */

/**
 * @brief Read a TIME_OF_DAY or TIME_DIFFERENCE.
 * @retval 0 success
 * @retval CO_SDO_AB_TYPE_MISMATCH not a time type
 */
uint32_t co_od_get_time(const struct co_od *od, uint16_t index, uint8_t sub, struct co_time *t);
/** @brief Write a TIME_OF_DAY or TIME_DIFFERENCE; see co_od_write_info() for the codes. */
uint32_t co_od_set_time(struct co_od *od, uint16_t index, uint8_t sub, const struct co_time *t,
			enum co_od_writer writer);

/**
 * @brief The value of an integer object as unsigned, or @p dflt if it cannot be read.
 *
 * For services reading their configuration objects, whose integer type may differ between
 * dictionaries (where co_od_get_u32() and the like would refuse a type mismatch). Reads as
 * the application, like the getters. The wire value of any size is taken as unsigned little
 * endian; values wider than 32 bits give their low 32 bits.
 *
 * @param od   dictionary
 * @param index object index
 * @param sub  sub-index
 * @param dflt returned when the object is absent, unreadable or empty
 * @return the value, or @p dflt
 */
uint32_t co_od_uint(const struct co_od *od, uint16_t index, uint8_t sub, uint32_t dflt);
/** @} */

/**
 * @name Wire helpers for hooks
 * @{
 */
/** @brief Little-endian unsigned of @p len bytes (1..8). */
static inline uint64_t co_od_le_get(const uint8_t *p, size_t len)
{
	uint64_t v = 0;

	for (size_t i = len; i > 0; i--) {
		v = (v << 8) | p[i - 1];
	}
	return v;
}

/** @brief Store @p v as @p len little-endian bytes (1..8). */
static inline void co_od_le_put(uint8_t *p, size_t len, uint64_t v)
{
	for (size_t i = 0; i < len; i++) {
		p[i] = (uint8_t)(v >> (8 * i));
	}
}

/**
 * @brief The new value of an integer write as unsigned (UINT, BOOL, TIME classes).
 *
 * Out of line: every service's validate hooks call it, and a size build would keep a copy
 * in each of them.
 */
uint64_t co_od_req_uint(const struct co_od_req *req);
/** @} */

/**
 * @brief Emit the EDS of the dictionary (CiA 306), the way scripts/eds2od writes it.
 *
 * Needs CONFIG_CANOPEN_OD_NAMES (names and the EDS header built in). Values are the
 * defaults of the description; $NODEID defaults keep their formula.
 *
 * @param od    dictionary
 * @param sink  called with consecutive pieces of the text
 * @param user_data passed to sink
 * @retval 0 success
 * @retval -ENOTSUP names or header not built in
 * @retval negative the first negative value returned by sink
 */
int co_od_eds_write(const struct co_od *od, int (*sink)(const char *s, size_t len, void *user),
		    void *user_data);

/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SAFELINE_INCLUDE_CANOPEN_OD_H_ */
