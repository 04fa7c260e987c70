/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * --hb=<ms> (every node's heartbeat period, 1017h) and --hb-consumer=<ms> (the consumer time of
 * the 1016h entries), 1..65535, for the samples that have them: HB_OPTIONS() gives the two
 * entries of the sample's option table, with the sample's own help texts.
 */

#ifndef SAFELINE_SAMPLES_CANOPEN_COMMON_HB_OPTIONS_H_
#define SAFELINE_SAMPLES_CANOPEN_COMMON_HB_OPTIONS_H_

#include <stdint.h>

/* The values given, 0 when not given (hb_options_check() then puts the sample's default). */
struct hb_options {
	uint32_t hb_ms;
	uint32_t consumer_ms;
};

extern struct hb_options hb_opt;

void hb_options_hb_found(char *argv, int offset);
void hb_options_consumer_found(char *argv, int offset);

#define HB_OPTIONS(hb_help, consumer_help)                                                         \
	{                                                                                          \
		.option = "hb",                                                                    \
		.name = "ms",                                                                      \
		.type = 'u',                                                                       \
		.call_when_found = hb_options_hb_found,                                            \
		.descript = (hb_help),                                                             \
	},                                                                                         \
	{                                                                                          \
		.option = "hb-consumer", .name = "ms", .type = 'u',                                \
		.call_when_found = hb_options_consumer_found, .descript = (consumer_help),         \
	}

/*
 * Once the command line is parsed, before the boot: an option not given takes @p hb_dflt or
 * @p consumer_dflt (0: the dictionary's, left as it is and not compared). A consumer time not
 * longer than the heartbeat is refused (usage, error, exit code 1): the consumer would report
 * a heartbeat event for a producer that is alive.
 */
void hb_options_check(uint32_t hb_dflt, uint32_t consumer_dflt);

#endif /* SAFELINE_SAMPLES_CANOPEN_COMMON_HB_OPTIONS_H_ */
