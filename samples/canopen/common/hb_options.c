/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

#include <stdio.h>

#include "cmdline.h"
#include "hb_options.h"

struct hb_options hb_opt;

void hb_options_hb_found(char *argv, int offset)
{
	hb_opt.hb_ms = (uint32_t)cmd_read_uint_option("hb", &argv[offset], 1U, 65535U);
}

void hb_options_consumer_found(char *argv, int offset)
{
	hb_opt.consumer_ms =
		(uint32_t)cmd_read_uint_option("hb-consumer", &argv[offset], 1U, 65535U);
}

void hb_options_check(uint32_t hb_dflt, uint32_t consumer_dflt)
{
	char value[16];

	if (hb_opt.hb_ms == 0U) {
		hb_opt.hb_ms = hb_dflt;
	}
	if (hb_opt.consumer_ms == 0U) {
		hb_opt.consumer_ms = consumer_dflt;
	}
	if (hb_opt.hb_ms != 0U && hb_opt.consumer_ms != 0U && hb_opt.consumer_ms <= hb_opt.hb_ms) {
		(void)snprintf(value, sizeof(value), "%u", hb_opt.consumer_ms);
		cmd_option_error("hb-consumer", value, "must be longer than the heartbeat (%u ms)",
				 hb_opt.hb_ms);
	}
}
