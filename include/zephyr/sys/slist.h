/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/**
 * @file
 * @brief Singly-linked list with head and tail pointers, as Zephyr's sys/slist.h.
 *
 * Nodes are embedded in the caller's structs; the list never allocates. Append, prepend and
 * get are O(1); removing an arbitrary node is O(n). Not thread-safe: callers lock.
 */

#ifndef ZEPHYR_INCLUDE_SYS_SLIST_H_
#define ZEPHYR_INCLUDE_SYS_SLIST_H_

#include <stdbool.h>
#include <stddef.h>

#include <zephyr/sys/util.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A list node, embedded in the element. */
struct _snode {
	struct _snode *next;
};

/** Single-linked list node structure. */
typedef struct _snode sys_snode_t;

/** A list: head and tail. */
struct _slist {
	sys_snode_t *head;
	sys_snode_t *tail;
};

/** Single-linked list structure. */
typedef struct _slist sys_slist_t;

/** Static initializer of an empty list. */
#define SYS_SLIST_STATIC_INIT(ptr_to_list) {NULL, NULL}

/**
 * @brief Iterate over every node of @p __sl; the loop body must not remove @p __sn.
 */
#define SYS_SLIST_FOR_EACH_NODE(__sl, __sn)                                                        \
	for ((__sn) = sys_slist_peek_head(__sl); (__sn) != NULL; (__sn) = sys_slist_peek_next(__sn))

/**
 * @brief Iterate from the node after @p __sn (or from the head if @p __sn is NULL).
 */
#define SYS_SLIST_ITERATE_FROM_NODE(__sl, __sn)                                                    \
	for ((__sn) = ((__sn) != NULL) ? sys_slist_peek_next_no_check(__sn)                        \
				       : sys_slist_peek_head(__sl);                                \
	     (__sn) != NULL; (__sn) = sys_slist_peek_next(__sn))

/**
 * @brief Iterate over every node; the body may remove @p __sn (@p __sns holds the next one).
 */
#define SYS_SLIST_FOR_EACH_NODE_SAFE(__sl, __sn, __sns)                                            \
	for ((__sn) = sys_slist_peek_head(__sl), (__sns) = sys_slist_peek_next(__sn);              \
	     (__sn) != NULL; (__sn) = (__sns), (__sns) = sys_slist_peek_next(__sn))

/** The element of type of @p __cn containing node @p __ln (NULL-safe). */
#define SYS_SLIST_CONTAINER(__ln, __cn, __n)                                                       \
	(((__ln) != NULL) ? CONTAINER_OF((__ln), __typeof__(*(__cn)), __n) : NULL)

/** The element at the head of @p __sl, or NULL. */
#define SYS_SLIST_PEEK_HEAD_CONTAINER(__sl, __cn, __n)                                             \
	SYS_SLIST_CONTAINER(sys_slist_peek_head(__sl), __cn, __n)

/** The element at the tail of @p __sl, or NULL. */
#define SYS_SLIST_PEEK_TAIL_CONTAINER(__sl, __cn, __n)                                             \
	SYS_SLIST_CONTAINER(sys_slist_peek_tail(__sl), __cn, __n)

/** The element after @p __cn, or NULL. */
#define SYS_SLIST_PEEK_NEXT_CONTAINER(__cn, __n)                                                   \
	(((__cn) != NULL) ? SYS_SLIST_CONTAINER(sys_slist_peek_next(&((__cn)->__n)), __cn, __n)    \
			  : NULL)

/**
 * @brief Iterate over every element; the body must not remove @p __cn.
 */
#define SYS_SLIST_FOR_EACH_CONTAINER(__sl, __cn, __n)                                              \
	for ((__cn) = SYS_SLIST_PEEK_HEAD_CONTAINER(__sl, __cn, __n); (__cn) != NULL;              \
	     (__cn) = SYS_SLIST_PEEK_NEXT_CONTAINER(__cn, __n))

/**
 * @brief Iterate over every element; the body may remove @p __cn (@p __cns holds the next).
 */
#define SYS_SLIST_FOR_EACH_CONTAINER_SAFE(__sl, __cn, __cns, __n)                                  \
	for ((__cn) = SYS_SLIST_PEEK_HEAD_CONTAINER(__sl, __cn, __n),                              \
	    (__cns) = SYS_SLIST_PEEK_NEXT_CONTAINER(__cn, __n);                                    \
	     (__cn) != NULL; (__cn) = (__cns), (__cns) = SYS_SLIST_PEEK_NEXT_CONTAINER(__cn, __n))

/** Initialize @p list as empty. */
static inline void sys_slist_init(sys_slist_t *list)
{
	list->head = NULL;
	list->tail = NULL;
}

/** Whether @p list is empty. */
static inline bool sys_slist_is_empty(const sys_slist_t *list)
{
	return list->head == NULL;
}

/** The first node of @p list, or NULL. */
static inline sys_snode_t *sys_slist_peek_head(const sys_slist_t *list)
{
	return list->head;
}

/** The last node of @p list, or NULL. */
static inline sys_snode_t *sys_slist_peek_tail(const sys_slist_t *list)
{
	return list->tail;
}

/** The node after @p node, which must not be NULL. */
static inline sys_snode_t *sys_slist_peek_next_no_check(const sys_snode_t *node)
{
	return node->next;
}

/** The node after @p node, or NULL (also when @p node is NULL). */
static inline sys_snode_t *sys_slist_peek_next(const sys_snode_t *node)
{
	return (node != NULL) ? node->next : NULL;
}

/** Insert @p node at the head of @p list. */
static inline void sys_slist_prepend(sys_slist_t *list, sys_snode_t *node)
{
	node->next = list->head;
	list->head = node;
	if (list->tail == NULL) {
		list->tail = node;
	}
}

/** Insert @p node at the tail of @p list. */
static inline void sys_slist_append(sys_slist_t *list, sys_snode_t *node)
{
	node->next = NULL;
	if (list->tail == NULL) {
		list->head = node;
	} else {
		list->tail->next = node;
	}
	list->tail = node;
}

/**
 * @brief Append the chain of nodes from @p head to @p tail (linked through their first word).
 */
static inline void sys_slist_append_list(sys_slist_t *list, void *head, void *tail)
{
	if (head == NULL || tail == NULL) {
		return;
	}
	if (list->tail == NULL) {
		list->head = (sys_snode_t *)head;
	} else {
		list->tail->next = (sys_snode_t *)head;
	}
	list->tail = (sys_snode_t *)tail;
	list->tail->next = NULL;
}

/** Move every node of @p list_to_append to the end of @p list, leaving it empty. */
static inline void sys_slist_merge_slist(sys_slist_t *list, sys_slist_t *list_to_append)
{
	sys_snode_t *head = list_to_append->head;
	sys_snode_t *tail = list_to_append->tail;

	sys_slist_append_list(list, head, tail);
	sys_slist_init(list_to_append);
}

/** Insert @p node after @p prev; a NULL @p prev means at the head. */
static inline void sys_slist_insert(sys_slist_t *list, sys_snode_t *prev, sys_snode_t *node)
{
	if (prev == NULL) {
		sys_slist_prepend(list, node);
	} else if (prev->next == NULL) {
		sys_slist_append(list, node);
	} else {
		node->next = prev->next;
		prev->next = node;
	}
}

/** Remove and return the head of @p list, which must not be empty. */
static inline sys_snode_t *sys_slist_get_not_empty(sys_slist_t *list)
{
	sys_snode_t *node = list->head;

	list->head = node->next;
	if (list->tail == node) {
		list->tail = list->head;
	}
	node->next = NULL;

	return node;
}

/** Remove and return the head of @p list, or NULL if it is empty. */
static inline sys_snode_t *sys_slist_get(sys_slist_t *list)
{
	return sys_slist_is_empty(list) ? NULL : sys_slist_get_not_empty(list);
}

/**
 * @brief Remove @p node, which follows @p prev_node (NULL if @p node is the head).
 */
static inline void sys_slist_remove(sys_slist_t *list, sys_snode_t *prev_node, sys_snode_t *node)
{
	if (prev_node == NULL) {
		list->head = node->next;
		if (list->tail == node) {
			list->tail = list->head;
		}
	} else {
		prev_node->next = node->next;
		if (list->tail == node) {
			list->tail = prev_node;
		}
	}
	node->next = NULL;
}

/**
 * @brief Find @p node in @p list.
 *
 * @param list The list.
 * @param node The node to look for.
 * @param prev Where to store the node before @p node (NULL if it is the head); may be NULL.
 * @return true if found.
 */
static inline bool sys_slist_find(const sys_slist_t *list, const sys_snode_t *node,
				  sys_snode_t **prev)
{
	sys_snode_t *test;
	sys_snode_t *p = NULL;

	SYS_SLIST_FOR_EACH_NODE(list, test) {
		if (test == node) {
			if (prev != NULL) {
				*prev = p;
			}
			return true;
		}
		p = test;
	}
	if (prev != NULL) {
		*prev = NULL;
	}

	return false;
}

/**
 * @brief Remove @p node from @p list if it is there (O(n)).
 *
 * @return true if the node was found and removed.
 */
static inline bool sys_slist_find_and_remove(sys_slist_t *list, sys_snode_t *node)
{
	sys_snode_t *prev = NULL;

	if (!sys_slist_find(list, node, &prev)) {
		return false;
	}
	sys_slist_remove(list, prev, node);

	return true;
}

/** Number of nodes in @p list (O(n)). */
static inline size_t sys_slist_len(const sys_slist_t *list)
{
	size_t len = 0;
	sys_snode_t *node;

	SYS_SLIST_FOR_EACH_NODE(list, node) {
		len++;
	}

	return len;
}

#ifdef __cplusplus
}
#endif

#endif /* ZEPHYR_INCLUDE_SYS_SLIST_H_ */
