# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""CiA 301 basic data types; must match CO_DTYPE_TABLE in include/canopen/types.h."""

from dataclasses import dataclass


@dataclass(frozen=True)
class DType:
    name: str
    code: int
    size: int  # wire size in bytes, 0 = variable
    cls: str  # BOOL INT UINT REAL VSTR OSTR USTR TIME DOMAIN
    ctype: str


TABLE = [
    DType("BOOLEAN", 0x0001, 1, "BOOL", "uint8_t"),
    DType("INTEGER8", 0x0002, 1, "INT", "int8_t"),
    DType("INTEGER16", 0x0003, 2, "INT", "int16_t"),
    DType("INTEGER32", 0x0004, 4, "INT", "int32_t"),
    DType("UNSIGNED8", 0x0005, 1, "UINT", "uint8_t"),
    DType("UNSIGNED16", 0x0006, 2, "UINT", "uint16_t"),
    DType("UNSIGNED32", 0x0007, 4, "UINT", "uint32_t"),
    DType("REAL32", 0x0008, 4, "REAL", "float"),
    DType("VISIBLE_STRING", 0x0009, 0, "VSTR", "char"),
    DType("OCTET_STRING", 0x000A, 0, "OSTR", "uint8_t"),
    DType("UNICODE_STRING", 0x000B, 0, "USTR", "uint16_t"),
    DType("TIME_OF_DAY", 0x000C, 6, "TIME", "struct co_time"),
    DType("TIME_DIFFERENCE", 0x000D, 6, "TIME", "struct co_time"),
    DType("DOMAIN", 0x000F, 0, "DOMAIN", "uint8_t"),
    DType("INTEGER24", 0x0010, 3, "INT", "int32_t"),
    DType("REAL64", 0x0011, 8, "REAL", "double"),
    DType("INTEGER40", 0x0012, 5, "INT", "int64_t"),
    DType("INTEGER48", 0x0013, 6, "INT", "int64_t"),
    DType("INTEGER56", 0x0014, 7, "INT", "int64_t"),
    DType("INTEGER64", 0x0015, 8, "INT", "int64_t"),
    DType("UNSIGNED24", 0x0016, 3, "UINT", "uint32_t"),
    DType("UNSIGNED40", 0x0018, 5, "UINT", "uint64_t"),
    DType("UNSIGNED48", 0x0019, 6, "UINT", "uint64_t"),
    DType("UNSIGNED56", 0x001A, 7, "UINT", "uint64_t"),
    DType("UNSIGNED64", 0x001B, 8, "UINT", "uint64_t"),
]

BY_CODE = {t.code: t for t in TABLE}

NUMERIC = ("BOOL", "INT", "UINT", "REAL", "TIME")


def int_range(t: DType):
    """(min, max) of an integer-like type."""
    bits = t.size * 8
    if t.cls == "INT":
        return -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    if t.cls == "BOOL":
        return 0, 1
    return 0, (1 << bits) - 1


def csize(t: DType) -> int:
    """Size of the C storage type of a fixed-size type."""
    return {"int8_t": 1, "uint8_t": 1, "int16_t": 2, "uint16_t": 2, "int32_t": 4,
            "uint32_t": 4, "int64_t": 8, "uint64_t": 8, "float": 4, "double": 8,
            "struct co_time": 8}[t.ctype]
