/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Circular doubly-linked list, as Zephyr's sys/dlist.h.
 *
 * The list head is itself a node: an empty list points to itself, so insertion and removal
 * anywhere are O(1) and need no special cases. Not thread-safe: callers lock.
 */

#ifndef ZEPHYR_INCLUDE_SYS_DLIST_H_
#define ZEPHYR_INCLUDE_SYS_DLIST_H_

#include <stdbool.h>
#include <stddef.h>

#include <zephyr/sys/util.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A node (and a list head). */
struct _dnode {
	union {
		struct _dnode *head; /* when used as a list: the first node */
		struct _dnode *next; /* when used as a node: the next one */
	};
	union {
		struct _dnode *tail; /* when used as a list: the last node */
		struct _dnode *prev; /* when used as a node: the previous one */
	};
};

/** Doubly-linked list structure. */
typedef struct _dnode sys_dlist_t;
/** Doubly-linked list node structure. */
typedef struct _dnode sys_dnode_t;

/** Static initializer of an empty list at address @p ptr_to_list. */
#define SYS_DLIST_STATIC_INIT(ptr_to_list)                                                         \
	{                                                                                          \
		{(ptr_to_list)},                                                                   \
		{                                                                                  \
			(ptr_to_list)                                                              \
		}                                                                                  \
	}

/** Iterate over every node; the body must not remove @p __dn. */
#define SYS_DLIST_FOR_EACH_NODE(__dl, __dn)                                                        \
	for ((__dn) = sys_dlist_peek_head(__dl); (__dn) != NULL;                                   \
	     (__dn) = sys_dlist_peek_next(__dl, __dn))

/** Iterate over every node; the body may remove @p __dn (@p __dns holds the next one). */
#define SYS_DLIST_FOR_EACH_NODE_SAFE(__dl, __dn, __dns)                                            \
	for ((__dn) = sys_dlist_peek_head(__dl),                                                   \
	    (__dns) = ((__dn) != NULL) ? sys_dlist_peek_next(__dl, __dn) : NULL;                   \
	     (__dn) != NULL; (__dn) = (__dns),                                                     \
	    (__dns) = ((__dn) != NULL) ? sys_dlist_peek_next(__dl, __dn) : NULL)

/** The element of type of @p __cn containing node @p __dn (NULL-safe). */
#define SYS_DLIST_CONTAINER(__dn, __cn, __n)                                                       \
	(((__dn) != NULL) ? CONTAINER_OF(__dn, __typeof__(*(__cn)), __n) : NULL)

/** The element at the head of @p __dl, or NULL. */
#define SYS_DLIST_PEEK_HEAD_CONTAINER(__dl, __cn, __n)                                             \
	SYS_DLIST_CONTAINER(sys_dlist_peek_head(__dl), __cn, __n)

/** The element after @p __cn, or NULL. */
#define SYS_DLIST_PEEK_NEXT_CONTAINER(__dl, __cn, __n)                                             \
	(((__cn) != NULL)                                                                          \
		 ? SYS_DLIST_CONTAINER(sys_dlist_peek_next(__dl, &((__cn)->__n)), __cn, __n)       \
		 : NULL)

/** Iterate over every element; the body must not remove @p __cn. */
#define SYS_DLIST_FOR_EACH_CONTAINER(__dl, __cn, __n)                                              \
	for ((__cn) = SYS_DLIST_PEEK_HEAD_CONTAINER(__dl, __cn, __n); (__cn) != NULL;              \
	     (__cn) = SYS_DLIST_PEEK_NEXT_CONTAINER(__dl, __cn, __n))

/** Iterate over every element; the body may remove @p __cn (@p __cns holds the next). */
#define SYS_DLIST_FOR_EACH_CONTAINER_SAFE(__dl, __cn, __cns, __n)                                  \
	for ((__cn) = SYS_DLIST_PEEK_HEAD_CONTAINER(__dl, __cn, __n),                              \
	    (__cns) = SYS_DLIST_PEEK_NEXT_CONTAINER(__dl, __cn, __n);                              \
	     (__cn) != NULL;                                                                       \
	     (__cn) = (__cns), (__cns) = SYS_DLIST_PEEK_NEXT_CONTAINER(__dl, __cn, __n))

/** Initialize @p list as empty. */
static inline void sys_dlist_init(sys_dlist_t *list)
{
	list->head = (sys_dnode_t *)list;
	list->tail = (sys_dnode_t *)list;
}

/** Initialize @p node as not linked. */
static inline void sys_dnode_init(sys_dnode_t *node)
{
	node->next = NULL;
	node->prev = NULL;
}

/** Whether @p node is linked into a list. */
static inline bool sys_dnode_is_linked(const sys_dnode_t *node)
{
	return node->next != NULL;
}

/** Whether @p node is the head of @p list. */
static inline bool sys_dlist_is_head(const sys_dlist_t *list, const sys_dnode_t *node)
{
	return list->head == node;
}

/** Whether @p node is the tail of @p list. */
static inline bool sys_dlist_is_tail(const sys_dlist_t *list, const sys_dnode_t *node)
{
	return list->tail == node;
}

/** Whether @p list is empty. */
static inline bool sys_dlist_is_empty(const sys_dlist_t *list)
{
	return list->head == list;
}

/** Whether @p list has more than one node. */
static inline bool sys_dlist_has_multiple_nodes(const sys_dlist_t *list)
{
	return list->head != list->tail;
}

/** The first node of @p list, or NULL. */
static inline sys_dnode_t *sys_dlist_peek_head(const sys_dlist_t *list)
{
	return sys_dlist_is_empty(list) ? NULL : list->head;
}

/** The first node of @p list, which must not be empty. */
static inline sys_dnode_t *sys_dlist_peek_head_not_empty(const sys_dlist_t *list)
{
	return list->head;
}

/** The node after @p node, which must be in @p list; NULL at the tail. */
static inline sys_dnode_t *sys_dlist_peek_next_no_check(const sys_dlist_t *list,
							const sys_dnode_t *node)
{
	return (node == list->tail) ? NULL : node->next;
}

/** The node after @p node, or NULL (also when @p node is NULL). */
static inline sys_dnode_t *sys_dlist_peek_next(const sys_dlist_t *list, const sys_dnode_t *node)
{
	return (node != NULL) ? sys_dlist_peek_next_no_check(list, node) : NULL;
}

/** The node before @p node, or NULL at the head (also when @p node is NULL). */
static inline sys_dnode_t *sys_dlist_peek_prev(const sys_dlist_t *list, const sys_dnode_t *node)
{
	if (node == NULL || node == list->head) {
		return NULL;
	}

	return node->prev;
}

/** The last node of @p list, or NULL. */
static inline sys_dnode_t *sys_dlist_peek_tail(const sys_dlist_t *list)
{
	return sys_dlist_is_empty(list) ? NULL : list->tail;
}

/** Insert @p node at the tail of @p list. */
static inline void sys_dlist_append(sys_dlist_t *list, sys_dnode_t *node)
{
	sys_dnode_t *const tail = list->tail;

	node->next = list;
	node->prev = tail;
	tail->next = node;
	list->tail = node;
}

/** Insert @p node at the head of @p list. */
static inline void sys_dlist_prepend(sys_dlist_t *list, sys_dnode_t *node)
{
	sys_dnode_t *const head = list->head;

	node->next = head;
	node->prev = list;
	head->prev = node;
	list->head = node;
}

/** Insert @p node before @p successor, which is linked in a list. */
static inline void sys_dlist_insert(sys_dnode_t *successor, sys_dnode_t *node)
{
	sys_dnode_t *const prev = successor->prev;

	node->prev = prev;
	node->next = successor;
	prev->next = node;
	successor->prev = node;
}

/**
 * @brief Insert @p node before the first node for which @p cond returns true, else at the tail.
 *
 * Keeps a list ordered when @p cond compares with the node to insert.
 */
static inline void sys_dlist_insert_at(sys_dlist_t *list, sys_dnode_t *node,
				       int (*cond)(sys_dnode_t *node, void *data), void *data)
{
	sys_dnode_t *pos;

	SYS_DLIST_FOR_EACH_NODE(list, pos) {
		if (cond(pos, data) != 0) {
			sys_dlist_insert(pos, node);
			return;
		}
	}
	sys_dlist_append(list, node);
}

/** Unlink @p node from its list and mark it as not linked. */
static inline void sys_dlist_remove(sys_dnode_t *node)
{
	sys_dnode_t *const prev = node->prev;
	sys_dnode_t *const next = node->next;

	prev->next = next;
	next->prev = prev;
	sys_dnode_init(node);
}

/** Remove and return the head of @p list, or NULL if it is empty. */
static inline sys_dnode_t *sys_dlist_get(sys_dlist_t *list)
{
	sys_dnode_t *node = NULL;

	if (!sys_dlist_is_empty(list)) {
		node = list->head;
		sys_dlist_remove(node);
	}

	return node;
}

/** Number of nodes in @p list (O(n)). */
static inline size_t sys_dlist_len(const sys_dlist_t *list)
{
	size_t len = 0;
	sys_dnode_t *node;

	SYS_DLIST_FOR_EACH_NODE(list, node) {
		len++;
	}

	return len;
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_DLIST_H_ */
