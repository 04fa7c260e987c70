/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * What the CANopen samples share on native_posix: the --node-id option, the choice of CAN
 * controller for a line (SocketCAN when --can-if named an interface, else the virtual bus) and
 * the line counters printed on the way out.
 */

#ifndef SAFELINE_SAMPLES_CANOPEN_COMMON_SAMPLE_COMMON_H_
#define SAFELINE_SAMPLES_CANOPEN_COMMON_SAMPLE_COMMON_H_

#include <stdint.h>

#include <zephyr/device.h>

#include <canopen/line.h>

/*
 * The node-ID given with --node-id, or @p dflt when the option was not given. The command line
 * refuses a value outside 1..127 before the boot (usage, error, exit code 1).
 */
int sample_node_id(uint8_t dflt);

/*
 * CAN controller @p n: can_socketcan<n> when it has an interface, else can_virtual<n>. An
 * interface named with --can-if that cannot be opened never gets here: the SocketCAN driver
 * ends the process with the reason before the boot.
 */
const struct device *sample_line_device(unsigned int n);

/* Print @p line's counters when the process ends (tests read them). */
void sample_print_stats_on_exit(const char *prefix, struct co_line *line);

#endif /* SAFELINE_SAMPLES_CANOPEN_COMMON_SAMPLE_COMMON_H_ */
