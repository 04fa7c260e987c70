/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* Nothing runs: the scenario is about the objects of the stack this build compiles. */

int main(void)
{
	return 0;
}
