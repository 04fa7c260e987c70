/*
 * Copyright (c) 2026 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * The network description of the manager sample, read from a DCF (CiA 306) at run time
 * (--dcf FILE): the manager's node-ID ([DeviceComissioning] NodeID), the values of the
 * network objects (1016h, 1017h, 102Ah, 1F26h, 1F27h, 1F80h, 1F81h, 1F84h-1F89h), and for
 * each slave the concise DCF its 1F22h sub-index names (UploadFile= or DownloadFile=, as
 * lely's dcfgen writes it: a binary file made by scripts/dcf2cdcf -o).
 */

#ifndef SAFELINE_SAMPLES_MANAGER_NETWORK_H_
#define SAFELINE_SAMPLES_MANAGER_NETWORK_H_

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <canopen/od.h>

#define NETWORK_MAX_VALUES 1024U

struct network_value {
	uint16_t index;
	uint8_t sub;
	uint32_t value;
	/* Line of the DCF it came from (0: a cleared array entry). */
	uint32_t line;
};

struct network {
	const char *path;
	/* [DeviceComissioning] NodeID, 0 if the DCF has none. */
	uint8_t node_id;
	/* Assigned slaves (1F81h bit 0), ascending. */
	uint8_t slaves[127];
	uint8_t n_slaves;
	/* Values written into the manager's dictionary at every Reset Communication, in order. */
	struct network_value values[NETWORK_MAX_VALUES];
	size_t n_values;
	/* Concise DCF of node n (1F22h:n), NULL if none. */
	uint8_t *cdcf[128];
	uint32_t cdcf_size[128];
};

/*
 * Read @p path into @p net. On failure return a negative errno and put the reason
 * ("FILE:LINE: ...") into @p err.
 */
int network_load(struct network *net, const char *path, char *err, size_t errlen);

/* Free the concise DCFs network_load() read. */
void network_free(struct network *net);

/* Line of the DCF that assigns slave @p id (1F81h), 0 if none. */
uint32_t network_slave_line(const struct network *net, uint8_t id);

/*
 * Write the network's values into @p od (writer CO_OD_WRITER_STORAGE, caller holds the
 * dictionary's lock if it has one). Returns 0, or the first SDO abort code with the value
 * that was refused in *bad.
 */
uint32_t network_apply(const struct network *net, struct co_od *od,
		       const struct network_value **bad);

#endif /* SAFELINE_SAMPLES_MANAGER_NETWORK_H_ */
