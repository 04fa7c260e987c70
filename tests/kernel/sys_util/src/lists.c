/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* sys/slist.h and sys/dlist.h: every operation, checked against the expected order. */

#include <zephyr/sys/dlist.h>
#include <zephyr/sys/slist.h>
#include <zephyr/ztest.h>

ZTEST_SUITE(lists, NULL, NULL, NULL, NULL, NULL);

struct item {
	int value;
	sys_snode_t snode;
	sys_dnode_t dnode;
};

static struct item items[6];

static void init_items(void)
{
	for (int i = 0; i < (int)ARRAY_SIZE(items); i++) {
		items[i].value = i;
	}
}

/* The values of the list in order, as digits, e.g. "0213". */
static const char *slist_str(sys_slist_t *list)
{
	static char buf[16];
	struct item *it;
	size_t n = 0;

	SYS_SLIST_FOR_EACH_CONTAINER(list, it, snode) {
		buf[n++] = (char)('0' + it->value);
	}
	buf[n] = '\0';

	return buf;
}

static const char *dlist_str(sys_dlist_t *list)
{
	static char buf[16];
	struct item *it;
	size_t n = 0;

	SYS_DLIST_FOR_EACH_CONTAINER(list, it, dnode) {
		buf[n++] = (char)('0' + it->value);
	}
	buf[n] = '\0';

	return buf;
}

ZTEST(lists, test_slist_basic)
{
	sys_slist_t list;
	sys_slist_t static_list = SYS_SLIST_STATIC_INIT(&static_list);

	init_items();
	sys_slist_init(&list);
	zassert_true(sys_slist_is_empty(&list));
	zassert_true(sys_slist_is_empty(&static_list));
	zassert_is_null(sys_slist_peek_head(&list));
	zassert_is_null(sys_slist_get(&list));

	sys_slist_append(&list, &items[1].snode);
	sys_slist_append(&list, &items[2].snode);
	sys_slist_prepend(&list, &items[0].snode);
	zassert_str_equal(slist_str(&list), "012");
	zassert_equal_ptr(sys_slist_peek_head(&list), &items[0].snode);
	zassert_equal_ptr(sys_slist_peek_tail(&list), &items[2].snode);
	zassert_equal_ptr(sys_slist_peek_next(&items[0].snode), &items[1].snode);
	zassert_is_null(sys_slist_peek_next(&items[2].snode));
	zassert_is_null(sys_slist_peek_next(NULL));
	zassert_equal(sys_slist_len(&list), 3);

	sys_slist_insert(&list, &items[0].snode, &items[3].snode);
	zassert_str_equal(slist_str(&list), "0312");
	sys_slist_insert(&list, &items[2].snode, &items[4].snode);
	zassert_str_equal(slist_str(&list), "03124");
	zassert_equal_ptr(sys_slist_peek_tail(&list), &items[4].snode, "insert after tail");
	sys_slist_insert(&list, NULL, &items[5].snode);
	zassert_str_equal(slist_str(&list), "503124");

	zassert_equal_ptr(sys_slist_get(&list), &items[5].snode);
	zassert_equal_ptr(sys_slist_get_not_empty(&list), &items[0].snode);
	zassert_str_equal(slist_str(&list), "3124");
}

ZTEST(lists, test_slist_remove_and_find)
{
	sys_slist_t list;
	sys_snode_t *prev;

	init_items();
	sys_slist_init(&list);
	for (int i = 0; i < 4; i++) {
		sys_slist_append(&list, &items[i].snode);
	}

	zassert_true(sys_slist_find(&list, &items[2].snode, &prev));
	zassert_equal_ptr(prev, &items[1].snode);
	zassert_true(sys_slist_find(&list, &items[0].snode, &prev));
	zassert_is_null(prev, "the head has no previous node");
	zassert_false(sys_slist_find(&list, &items[5].snode, NULL));

	sys_slist_remove(&list, &items[2].snode, &items[3].snode);
	zassert_str_equal(slist_str(&list), "012");
	zassert_equal_ptr(sys_slist_peek_tail(&list), &items[2].snode, "tail updated");

	zassert_true(sys_slist_find_and_remove(&list, &items[0].snode));
	zassert_str_equal(slist_str(&list), "12");
	zassert_false(sys_slist_find_and_remove(&list, &items[0].snode), "already gone");
	zassert_true(sys_slist_find_and_remove(&list, &items[2].snode));
	zassert_true(sys_slist_find_and_remove(&list, &items[1].snode));
	zassert_true(sys_slist_is_empty(&list));
	zassert_is_null(sys_slist_peek_tail(&list));
}

ZTEST(lists, test_slist_iterate_and_merge)
{
	sys_slist_t a;
	sys_slist_t b;
	sys_snode_t *node;
	sys_snode_t *next;
	struct item *it;
	struct item *tmp;
	int sum = 0;

	init_items();
	sys_slist_init(&a);
	sys_slist_init(&b);
	for (int i = 0; i < 3; i++) {
		sys_slist_append(&a, &items[i].snode);
		sys_slist_append(&b, &items[i + 3].snode);
	}
	sys_slist_merge_slist(&a, &b);
	zassert_str_equal(slist_str(&a), "012345");
	zassert_true(sys_slist_is_empty(&b));

	SYS_SLIST_FOR_EACH_NODE(&a, node) {
		sum += CONTAINER_OF(node, struct item, snode)->value;
	}
	zassert_equal(sum, 15);

	/* The SAFE variants allow removing the current node. */
	SYS_SLIST_FOR_EACH_NODE_SAFE(&a, node, next) {
		if (CONTAINER_OF(node, struct item, snode)->value % 2 == 0) {
			(void)sys_slist_find_and_remove(&a, node);
		}
	}
	zassert_str_equal(slist_str(&a), "135");
	SYS_SLIST_FOR_EACH_CONTAINER_SAFE(&a, it, tmp, snode) {
		if (it->value == 3) {
			(void)sys_slist_find_and_remove(&a, &it->snode);
		}
	}
	zassert_str_equal(slist_str(&a), "15");
	zassert_equal(SYS_SLIST_PEEK_HEAD_CONTAINER(&a, it, snode)->value, 1);
	zassert_equal(SYS_SLIST_PEEK_TAIL_CONTAINER(&a, it, snode)->value, 5);

	node = &items[1].snode;
	sum = 0;
	SYS_SLIST_ITERATE_FROM_NODE(&a, node) {
		sum += CONTAINER_OF(node, struct item, snode)->value;
	}
	zassert_equal(sum, 5, "iteration starts after the given node");

	sys_slist_init(&b);
	sys_slist_append(&b, &items[0].snode);
	items[2].snode.next = &items[4].snode;
	sys_slist_append_list(&b, &items[2].snode, &items[4].snode);
	zassert_str_equal(slist_str(&b), "024");
}

ZTEST(lists, test_dlist)
{
	sys_dlist_t list = SYS_DLIST_STATIC_INIT(&list);
	sys_dnode_t *node;
	sys_dnode_t *next;

	init_items();
	zassert_true(sys_dlist_is_empty(&list));
	zassert_is_null(sys_dlist_peek_head(&list));
	zassert_is_null(sys_dlist_get(&list));

	for (int i = 0; i < 6; i++) {
		sys_dnode_init(&items[i].dnode);
		zassert_false(sys_dnode_is_linked(&items[i].dnode));
	}
	sys_dlist_append(&list, &items[1].dnode);
	sys_dlist_append(&list, &items[3].dnode);
	sys_dlist_prepend(&list, &items[0].dnode);
	sys_dlist_insert(&items[3].dnode, &items[2].dnode);
	zassert_str_equal(dlist_str(&list), "0123");
	zassert_true(sys_dnode_is_linked(&items[2].dnode));
	zassert_true(sys_dlist_is_head(&list, &items[0].dnode));
	zassert_true(sys_dlist_is_tail(&list, &items[3].dnode));
	zassert_true(sys_dlist_has_multiple_nodes(&list));
	zassert_equal_ptr(sys_dlist_peek_prev(&list, &items[2].dnode), &items[1].dnode);
	zassert_is_null(sys_dlist_peek_prev(&list, &items[0].dnode));
	zassert_is_null(sys_dlist_peek_next(&list, &items[3].dnode));
	zassert_equal(sys_dlist_len(&list), 4);

	sys_dlist_remove(&items[1].dnode);
	zassert_false(sys_dnode_is_linked(&items[1].dnode));
	zassert_str_equal(dlist_str(&list), "023");

	SYS_DLIST_FOR_EACH_NODE_SAFE(&list, node, next) {
		sys_dlist_remove(node);
	}
	zassert_true(sys_dlist_is_empty(&list));

	sys_dlist_append(&list, &items[5].dnode);
	zassert_false(sys_dlist_has_multiple_nodes(&list));
	zassert_equal_ptr(sys_dlist_get(&list), &items[5].dnode);
	zassert_true(sys_dlist_is_empty(&list));
}
