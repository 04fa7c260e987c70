/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * A manager that updates one slave's program (CiA 302-3): the configuration it restores
 * (NMT master, the slave to be booted with its software checked and updated, the date and
 * time 1F53h/1F54h expect) and the image source it hands to co_mgr_set_pgm_source(). Shared
 * by the firmware_update sample and the pgm tests that run the update through a manager;
 * header-only so that a test needs no more than this folder on its include path.
 */

#ifndef SAFELINE_SAMPLES_CANOPEN_COMMON_PGM_OFFER_H_
#define SAFELINE_SAMPLES_CANOPEN_COMMON_PGM_OFFER_H_

#include <errno.h>
#include <stddef.h>
#include <stdint.h>

#include <zephyr/sys/byteorder.h>
#include <zephyr/sys/util.h>

#include <canopen/node.h>
#include <canopen/od.h>
#include <canopen/pgm.h>

/* The program the manager offers to one slave. Change it under the manager's lock. */
struct pgm_offer {
	uint8_t slave;
	const uint8_t *image; /* header and body, as pgm_offer_make_image() makes them */
	size_t len;
	uint32_t date; /* 1F53h: the date the slave's program must have */
	uint32_t time; /* 1F54h */
};

/* A program: a header (pgm.h) and @p body_len bytes from @p seed that stand for machine code. */
static inline void pgm_offer_make_image(uint8_t *img, uint32_t body_len, uint32_t date,
					uint32_t time, uint8_t seed)
{
	for (uint32_t i = 0; i < body_len; i++) {
		img[CO_PGM_HDR_SIZE + i] = (uint8_t)(seed * 31U + i * 13U + (i >> 8));
	}
	co_pgm_image_header(img, img + CO_PGM_HDR_SIZE, body_len, date, time);
}

/*
 * The manager's restore callback (co_od_set_restore_cb(), user_data: the struct pgm_offer):
 * written as a stored configuration would be, so that it survives every reset.
 */
static inline void pgm_offer_restore(struct co_od *od, uint32_t group_mask, void *user_data)
{
	const struct pgm_offer *o = user_data;
	const struct {
		uint16_t index;
		uint8_t sub;
		uint32_t value;
	} cfg[] = {
		{0x1F80, 0, 0x01},        /* NMT master */
		{0x1F81, o->slave, 0x65}, /* slave, boot, check software (5), update allowed (6) */
		{0x1F53, o->slave, o->date},
		{0x1F54, o->slave, o->time},
	};

	if ((group_mask & CO_OD_GROUP_BIT(CO_OD_GROUP_COMM)) == 0U) {
		return;
	}
	for (size_t i = 0; i < ARRAY_SIZE(cfg); i++) {
		uint8_t buf[4];

		sys_put_le32(cfg[i].value, buf);
		(void)co_od_write(od, cfg[i].index, cfg[i].sub, buf, 4, CO_OD_WRITER_STORAGE);
	}
}

/* The manager's image source (co_mgr_set_pgm_source(), user_data: the struct pgm_offer). */
static inline int pgm_offer_source(struct co_node *node, uint8_t id, const void **image,
				   size_t *len, void *user_data)
{
	const struct pgm_offer *o = user_data;

	ARG_UNUSED(node);
	if (id != o->slave) {
		return -ENOENT;
	}
	*image = o->image;
	*len = o->len;
	return 0;
}

#endif /* SAFELINE_SAMPLES_CANOPEN_COMMON_PGM_OFFER_H_ */
