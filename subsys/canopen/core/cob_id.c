/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/* COB-ID rules shared by the services (canopen/cob_id.h): one copy for all of them. */

#include <canopen/cob_id.h>

bool co_cob_id_restricted(uint32_t can_id)
{
	return (can_id <= 0x07FU) || ((can_id >= 0x101U) && (can_id <= 0x180U)) ||
	       ((can_id >= 0x581U) && (can_id <= 0x5FFU)) ||
	       ((can_id >= 0x601U) && (can_id <= 0x67FU)) ||
	       ((can_id >= 0x6E0U) && (can_id <= 0x6FFU)) || (can_id >= 0x701U);
}
