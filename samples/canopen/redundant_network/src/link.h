/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#ifndef REDUNDANT_NETWORK_LINK_H_
#define REDUNDANT_NETWORK_LINK_H_

#include <stdbool.h>

/*
 * Bring Linux network interface @p ifname up or down, as `ip link set <if> up|down` does
 * (in-process: exec'ing ip takes ~100 ms inside the VM, too vague a cut time). Needs
 * CAP_NET_ADMIN. Returns 0 or a negative errno.
 */
int link_set(const char *ifname, bool up);

#endif /* REDUNDANT_NETWORK_LINK_H_ */
