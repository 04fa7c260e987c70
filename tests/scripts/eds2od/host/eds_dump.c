/*
 * Copyright (c) 2024 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Host helper for the eds2od tests: builds with one generated dictionary (OD_NAME) and
 * prints the EDS that the firmware's co_od_eds_write() produces.
 */

#include <stdio.h>

#include OD_HEADER

#define CAT2(a, b) a##b
#define CAT(a, b)  CAT2(a, b)

static int sink(const char *s, size_t len, void *user)
{
	return fwrite(s, 1, len, (FILE *)user) == len ? 0 : -5;
}

int main(void)
{
	static struct co_od od;
	static struct CAT(OD_NAME, _od_ram) ram;

	if (co_od_init(&od, &CAT(OD_NAME, _od_def), &ram, CAT(OD_NAME, _od_def).node_id) != 0) {
		return 2;
	}
	return co_od_eds_write(&od, sink, stdout) == 0 ? 0 : 1;
}
