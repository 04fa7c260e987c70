# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The signature of one SRDO (CiA 304): a CRC-16 over its parameters, kept in 13FFh:n.

CRC-16/XMODEM: polynomial 1021h, initial value 0, bits most significant first, no final XOR
("123456789" gives 31C3h). binascii.crc_hqx computes exactly this CRC.

Bytes covered, multi-byte values little-endian as they are in the dictionary and on CAN:
direction (1301h+:1, 1 byte), refresh time/SCT (:2, 2 bytes), SRVT (:3, 1 byte), COB-ID 1
(:5, 4 bytes), COB-ID 2 (:6, 4 bytes), the number of mapping entries N (1381h+:0, 1 byte),
then for k = 1..N the byte k followed by entry k (4 bytes). Sub-index 0 and the transmission
type (:4) are not covered, nor are 13FEh and 13FFh. The COB-IDs enter with their real values:
SRDO 1's bare defaults 0xFF/0x100 are first turned into 0xFF + 2 x node-ID / 0x100 + 2 x node-ID.
"""

from __future__ import annotations

import binascii
import struct

HEAD = struct.Struct("<BHBIIB")
ENTRY = struct.Struct("<BI")


def crc16(data: bytes, crc: int = 0) -> int:
    """CRC-16/XMODEM of data, continuing from crc."""
    return binascii.crc_hqx(data, crc)


def stream(direction: int, cycle: int, srvt: int, cob1: int, cob2: int, entries) -> bytes:
    """The bytes the signature covers; entries are the mapping entries 1..N."""
    out = bytearray(HEAD.pack(direction, cycle, srvt, cob1, cob2, len(entries)))
    for k, e in enumerate(entries, start=1):
        out += ENTRY.pack(k, e)
    return bytes(out)


def signature(direction: int, cycle: int, srvt: int, cob1: int, cob2: int, entries) -> int:
    """13FFh:n for SRDO n with these parameters (COB-IDs with the node-ID applied)."""
    return crc16(stream(direction, cycle, srvt, cob1, cob2, entries))
