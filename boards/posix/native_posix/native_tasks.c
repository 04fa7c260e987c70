/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* NATIVE_TASK() registry (see posix_native_task.h). Host code. */

#include <stddef.h>

#include "posix_native_task.h"

static struct native_task_entry *tasks;

void native_task_register(struct native_task_entry *entry)
{
	struct native_task_entry **pos = &tasks;

	/* Sorted by level, then priority; registration order among equals. */
	while (*pos != NULL && ((*pos)->level < entry->level ||
				((*pos)->level == entry->level && (*pos)->prio <= entry->prio))) {
		pos = &(*pos)->next;
	}
	entry->next = *pos;
	*pos = entry;
}

void run_native_tasks(int level)
{
	for (struct native_task_entry *t = tasks; t != NULL; t = t->next) {
		if (t->level == level) {
			t->fn();
		}
	}
}
