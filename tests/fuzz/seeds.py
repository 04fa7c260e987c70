#!/usr/bin/env python3
# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Write the hand-made seed inputs of the frame harnesses (tests/fuzz/NAME/corpus/seed-*).

A fuzzer rarely builds a whole conversation (a segmented upload, an LSS selective switch, a
slave's boot answers) from random bytes; these seeds give it one of each to mutate. The
record format is doc/fuzz.md's; the identifier byte indexes the harness's table in src/.
Run after changing a table: tests/fuzz/seeds.py
"""

import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
MUX = 0x20     # copy bytes 1-3 of the last frame sent
TOGGLE = 0x40  # copy its SDO toggle bit


def rec(sel, data=b"", dt=1, flags=0, dlc=None):
    data = bytes(data)
    n = len(data) if dlc is None else dlc
    return bytes([sel, (n & 0x0F) | flags]) + data.ljust(8, b"\0")[:8] + bytes([dt])


def ms(n):
    """Time advance byte for n × 10 ms (n <= 127)."""
    return 128 + n


def sdo(cmd, index=0, sub=0, value=b""):
    return bytes([cmd]) + struct.pack("<HB", index, sub) + bytes(value).ljust(4, b"\0")


SEEDS = {}

# nmt: 000h = 0, 605h = 4, 705h = 6 (RTR: guarding).
SEEDS["nmt"] = {
    "states": bytes([0x00]) + rec(0, [0x01, 0x05]) + rec(0, [0x02, 0x00], ms(20)) +
    rec(4, sdo(0x40, 0x1017), 1) + rec(0, [0x80, 0x05], ms(5)) + rec(4, sdo(0x40, 0x1017)) +
    rec(0, [0x01, 0x00]) + rec(0, [0x82, 0x05], ms(3)) + rec(0, [0x81, 0x00], ms(3)),
    "guard-stopped": bytes([0x80]) + rec(0, [0x02, 0x05]) + rec(6, [], ms(10), 0x10, 1) +
    rec(6, [], ms(10), 0x10, 1) + rec(4, sdo(0x2B, 0x1017, 0, b"\x0a\x00"), ms(1)),
}

# errctl: 710h = 0, 711h = 1, 705h = 4 (guarding RTR), 000h = 6.
hb = b"".join(rec(0, [0x05], ms(5)) + rec(1, [0x7F], ms(3)) for _ in range(4))
guard = b"".join(rec(4, [], ms(10), 0x10, 1) for _ in range(4))
SEEDS["errctl"] = {
    "heartbeats-then-silence": bytes([0x80]) + hb + rec(6, [0x80, 0x00], ms(100)),
    "guarding-then-stop": bytes([0x00]) + guard + rec(6, [0x02, 0x05], ms(50)) + guard,
}

# sdo_server: 605h = 0.
SEEDS["sdo_server"] = {
    "expedited": bytes([0x00]) + rec(0, sdo(0x40, 0x1000)) + rec(0, sdo(0x2B, 0x1017, 0,
                                                                        b"\x64\x00")) +
    rec(0, sdo(0x40, 0x1017)) + rec(0, sdo(0x80, 0x1017, 0, b"\0\0\0\x08")),
    "segmented-upload": bytes([0x00]) + rec(0, sdo(0x40, 0x1008)) +
    b"".join(rec(0, [0x60 | (0x10 * (i & 1))], dlc=8) for i in range(4)),
    "segmented-download": bytes([0x80]) + rec(0, sdo(0x21, 0x2007, 0, b"\x08\0\0\0")) +
    rec(0, [0x00, 1, 2, 3, 4, 5, 6, 7]) + rec(0, [0x1D, 8], dlc=8),
    "block-upload": bytes([0x00]) + rec(0, sdo(0xA4, 0x1008, 0, b"\x7f\x00")) +
    rec(0, [0xA3], dlc=8) + rec(0, [0xA2, 0x03, 0x7F], dlc=8) + rec(0, [0xA1], dlc=8),
    "block-download": bytes([0x00]) + rec(0, sdo(0xC6, 0x2007, 0, b"\x08\0\0\0")) +
    rec(0, [0x01, 1, 2, 3, 4, 5, 6, 7]) + rec(0, [0x82, 8], dlc=8) +
    rec(0, [0xD9, 0, 0], dlc=8),
    "timeout": bytes([0x00]) + rec(0, sdo(0x40, 0x1008)) + rec(0, [0x60], ms(120), dlc=8),
}

# pdo: 205h = 0, 305h = 1, 185h = 4 (RTR), 080h = 6, 000h = 7, 321h = 9, 322h = 10.
sync = rec(6, [], ms(1), dlc=0)
SEEDS["pdo"] = {
    "sync-rpdo": bytes([0x80]) + b"".join(sync + rec(0, range(8)) + rec(1, range(8, 16))
                                           for _ in range(3)) + rec(4, [], 1, 0x10, 8),
    "mpdo": bytes([0x81]) + rec(9, [0x05, 0x00, 0x62, 0x01, 0x11, 0, 0, 0]) +
    rec(10, [0x90, 0x00, 0x60, 0x01, 0x22, 0, 0, 0]) + sync + rec(7, [0x80, 0x05]),
}

# sync: 080h = 0, 000h = 3.
SEEDS["sync"] = {
    "counter": bytes([0x80]) + b"".join(rec(0, [c], 100) for c in (1, 2, 3, 4, 1)) +
    rec(0, [], ms(3), dlc=0),
    "producer": bytes([0x81]) + rec(3, [0x02, 0x05], ms(5)) + rec(3, [0x01, 0x05], ms(5)),
}

# time: 100h = 0, 000h = 3.
SEEDS["time"] = {
    "consumer": bytes([0x80]) + rec(0, [0x10, 0x27, 0, 0, 0x5E, 0x39], ms(10)) +
    rec(0, [0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF], ms(10)),
    "producer": bytes([0x81]) + rec(3, [0x01, 0x05], ms(100)),
}

# emcy: 090h = 0, 091h = 1.
SEEDS["emcy"] = {
    "codes": bytes([0x80]) + rec(0, [0x10, 0x23, 0x03, 1, 2, 3, 4, 5]) +
    rec(1, [0x00, 0x00, 0x00, 0, 0, 0, 0, 0], ms(1)) + rec(0, [0x00, 0x81, 0x11], 1),
}

# sdo_client: setup bytes (mode, length), then 590h = 0 (the server's answers).
seg = [rec(0, [0x20], 1, MUX * 0 | TOGGLE, 8) for _ in range(3)]
SEEDS["sdo_client"] = {
    "expedited-download": bytes([0x00, 4, 0]) + rec(0, [0x60], 1, MUX, 8),
    "segmented-download": bytes([0x01, 20, 0]) + rec(0, [0x60], 1, MUX, 8) + b"".join(seg),
    "expedited-upload": bytes([0x04, 8, 0]) + rec(0, [0x43, 0, 0, 0, 1, 2, 3, 4], 1, MUX),
    "segmented-upload": bytes([0x05, 64, 0]) + rec(0, [0x41, 0, 0, 0, 20, 0, 0, 0], 1, MUX) +
    rec(0, [0x00, 1, 2, 3, 4, 5, 6, 7], 1, TOGGLE) + rec(0, [0x00, 1, 2, 3, 4, 5, 6, 7], 1,
                                                         TOGGLE) +
    rec(0, [0x03, 1, 2, 3, 4, 5, 6, 0], 1, TOGGLE),
    "block-download": bytes([0x02, 30, 0]) + rec(0, [0xA4, 0, 0, 0, 0x7F], 1, MUX, 8) +
    rec(0, [0xA2, 5, 0x7F], 5, 0, 8) + rec(0, [0xA1], 1, 0, 8),
    "block-upload": bytes([0x06, 64, 0]) + rec(0, [0xC6, 0, 0, 0, 12, 0, 0, 0], 1, MUX) +
    rec(0, [0x01, 1, 2, 3, 4, 5, 6, 7]) + rec(0, [0x82, 8, 9, 10, 11, 12, 0, 0]) +
    rec(0, [0xC9, 0, 0], 1, 0, 8),
}

# mgr: setup bytes (1F80h, 1F81h:02 bits), then 582h-584h = 0-2, 702h-704h = 6-8, 000h = 9.
answers = b"".join(rec(s, [0x43, 0, 0, 0, 0x92, 0x01, 0x02, 0x00], 2, MUX)
                   for _ in range(6) for s in (0, 1, 2))
SEEDS["mgr"] = {
    "boot": bytes([0x00, 0x00]) + rec(6, [0x00]) + rec(7, [0x00]) + rec(8, [0x00]) + answers,
    "stop-during-boot": bytes([0x00, 0x72]) + rec(9, [0x02, 0x01], 10) + rec(9, [0x01, 0x01]),
    "mandatory-guarding": bytes([0x40, 0x09]) + rec(6, [0x00]) + answers +
    rec(6, [0x7F], ms(20)),
}

# lss: 7E5h = 0, 000h = 6.


def lss(cs, value):
    return rec(0, bytes([cs]) + struct.pack("<I", value), dlc=8)


SEEDS["lss"] = {
    "global-configure": bytes([0x00]) + rec(0, [0x04, 0x01], dlc=8) +
    rec(0, [0x11, 0x0A], dlc=8) + rec(0, [0x13, 0x00, 0x02], dlc=8) + rec(0, [0x17], dlc=8) +
    rec(0, [0x15, 0x0A, 0x00], dlc=8) + rec(0, [0x04, 0x00], ms(10), dlc=8) +
    rec(6, [0x82, 0x00]),
    "selective-inquire": bytes([0x00]) + lss(0x40, 0x12345678) + lss(0x41, 0x42) +
    lss(0x42, 0x20001) + lss(0x43, 0xBEEF) +
    b"".join(rec(0, [cs], dlc=8) for cs in (0x5A, 0x5B, 0x5C, 0x5D, 0x5E)),
    "fastscan": bytes([0x00]) + rec(0, [0x4C], dlc=8) +
    rec(0, [0x51, 0, 0, 0, 0, 0x80, 0, 0], dlc=8) +
    rec(0, b"\x51" + struct.pack("<I", 0x12345678) + bytes([0x1F, 0, 1])),
}

# srdo: 0FFh = 0, 100h = 1, 000h = 9.
pair = rec(0, [0x11, 0x22]) + rec(1, [0xEE, 0xDD], 2)
SEEDS["srdo"] = {
    "pairs": bytes([0x81]) + b"".join(pair + rec(0, [0x11, 0x22], ms(1)) for _ in range(3)) +
    rec(0, [0x11, 0x22], ms(10)),
    "bad-pair": bytes([0x81]) + rec(0, [0x11, 0x22]) + rec(1, [0x11, 0x22]) +
    rec(9, [0x80, 0x05], ms(2)),
}


def cdcf(entries):
    out = struct.pack("<I", len(entries))
    for index, sub, data in entries:
        out += struct.pack("<HBI", index, sub, len(data)) + bytes(data)
    return out


SEEDS["cdcf"] = {
    "two-entries": cdcf([(0x1017, 0, b"\x64\x00"), (0x1008, 0, b"SafeLine device")]),
    "empty": cdcf([]),
    "truncated": cdcf([(0x1017, 0, b"\x64\x00")])[:-1],
}


def dcf(slaves=(2, 3), files=None, cut=None):
    """A network DCF as the manager reads it (--dcf): the mandatory objects, 1F80h, 1F89h,
    1F81h and 1F85h as compact arrays, heartbeat consumers, concise DCFs in 1F22h."""
    lines = ["[1000]", "ParameterValue=0", "[1001]", "ParameterValue=0", "[1018]",
             "SubNumber=1", "[DeviceComissioning]", "NodeID=0x01", "[1F80]",
             "ParameterValue=0x00000001", "[1F89]", "ParameterValue=2000"]
    for index, value in (("1F81", 0x0D), ("1F85", 0x539)):
        lines += [f"[{index}]", "CompactSubObj=127", "DefaultValue=0", f"[{index}Value]",
                  f"NrOfEntries={len(slaves)}"]
        lines += [f"0x{n:X}={value}" if n % 2 == 0 else f"{n}=0x{value:08X}" for n in slaves]
    lines += ["[1016]", "SubNumber=2", "[1016sub1]", f"ParameterValue=0x00{slaves[0]:02X}012C"]
    if files:
        lines += ["[1F22]", "SubNumber=128"]
        for n, name in files.items():
            lines += [f"[1F22sub{n:X}]", f"UploadFile={name}"]
    text = ("\n".join(lines) + "\n").encode()
    return text if cut is None else text[:text.index(cut.encode()) + len(cut)]


SEEDS["dcf"] = {
    "network": dcf(files={2: "slave.bin"}),
    "fifo": dcf(files={2: "fifo.bin"}),
    "cut-in-1F81Value": dcf(slaves=(2, 3, 4, 5), cut="3=0x00"),
    "nr-of-entries": dcf().replace(b"NrOfEntries=2", b"NrOfEntries=4", 1),
    "sub-zz": dcf().replace(b"[1016sub1]", b"[1016subZZ]"),
    "duplicate-key": dcf().replace(b"ParameterValue=2000", b"ParameterValue=2000\n"
                                   b"ParameterValue=100"),
    "empty": b"",
}


def main():
    for name, seeds in SEEDS.items():
        d = os.path.join(HERE, name, "corpus")
        os.makedirs(d, exist_ok=True)
        for seed, data in seeds.items():
            with open(os.path.join(d, f"seed-{seed}"), "wb") as f:
                f.write(data)
    print(f"{sum(len(s) for s in SEEDS.values())} seeds written")


if __name__ == "__main__":
    main()
