# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The SRDO signature: CRC-16/XMODEM over the byte stream of CiA 304, on published vectors."""

import random

import pytest

import srdo_sign_testlib  # noqa: F401  (puts scripts/pylib on the path)

from srdo import crc16, signature, stream

# (parameters, the byte stream, the signature); the first is the worked example of a safety
# scanner's manual (an SRDO it consumes), the others are a producer of node 1 and a consumer
# of node 2.
VECTORS = [
    ((2, 50, 20, 0x111, 0x112, [0x60100108, 0x60110108, 0x60100208, 0x60110208]),
     "02 32 00 14 11 01 00 00 12 01 00 00 04 01 08 01 10 60 02 08 01 11 60 03 08 02 10 60 "
     "04 08 02 11 60", 0x4370),
    ((1, 25, 20, 0x101, 0x102, [0x62000108, 0x62010108]),
     "01 19 00 14 01 01 00 00 02 01 00 00 02 01 08 01 00 62 02 08 01 01 62", 0xB218),
    ((2, 50, 20, 0x103, 0x104, [0x62000110, 0x62010110]),
     "02 32 00 14 03 01 00 00 04 01 00 00 02 01 10 01 00 62 02 10 01 01 62", 0x0172),
]


def crc_bitwise(data, crc=0):
    """CRC-16/XMODEM the long way: polynomial 1021h, most significant bit first."""
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021 if crc & 0x8000 else crc << 1) & 0xFFFF
    return crc


def test_check_value():
    assert crc16(b"123456789") == 0x31C3
    assert crc16(b"") == 0


def test_same_as_bitwise_crc():
    rnd = random.Random(304)
    for n in range(200):
        data = bytes(rnd.randrange(256) for _ in range(n))
        assert crc16(data) == crc_bitwise(data)


def test_continues_from_a_crc():
    assert crc16(b"56789", crc16(b"1234")) == crc16(b"123456789")


@pytest.mark.parametrize("params,hexbytes,crc", VECTORS)
def test_vector_stream(params, hexbytes, crc):
    assert stream(*params) == bytes.fromhex(hexbytes)


@pytest.mark.parametrize("params,hexbytes,crc", VECTORS)
def test_vector_signature(params, hexbytes, crc):
    assert signature(*params) == crc
    assert crc_bitwise(stream(*params)) == crc
