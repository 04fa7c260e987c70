#!/usr/bin/env python3
# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Writes io401.eds: a large CiA 401 generic I/O module used by the eds2od and OD tests.

The EDS is test data kept in the repository; this script documents how it was made and
rewrites it identically (python3 make_io401.py > io401.eds).
"""

import sys

out = []
lists = {0: [], 1: [], 2: []}
sections = {0: [], 1: [], 2: []}


def which(idx):
    if idx in (0x1000, 0x1001, 0x1018):
        return 0
    return 2 if 0x2000 <= idx <= 0x5FFF else 1


def var(idx, name, dt, acc, default=None, pdo=0, low=None, high=None, sub=None, extra=()):
    sec = f"{idx:04X}" if sub is None else f"{idx:04X}sub{sub:X}"
    lines = [f"[{sec}]", f"ParameterName={name}", "ObjectType=0x7", f"DataType=0x{dt:04X}",
             f"AccessType={acc}"]
    if default is not None:
        lines.append(f"DefaultValue={default}")
    lines.append(f"PDOMapping={pdo}")
    if low is not None:
        lines.append(f"LowLimit={low}")
    if high is not None:
        lines.append(f"HighLimit={high}")
    lines.extend(extra)
    return lines + [""]


def obj_var(idx, *a, **k):
    lists[which(idx)].append(idx)
    sections[which(idx)].append(var(idx, *a, **k))


def obj_multi(idx, name, code, subs):
    """subs: list of (name, dt, acc, default, pdo, low, high)."""
    lists[which(idx)].append(idx)
    lines = [f"[{idx:04X}]", f"ParameterName={name}", f"ObjectType=0x{code:X}",
             f"SubNumber=0x{len(subs):X}", ""]
    for i, s in enumerate(subs):
        n, dt, acc, d = s[:4]
        pdo = s[4] if len(s) > 4 else 0
        low = s[5] if len(s) > 5 else None
        high = s[6] if len(s) > 6 else None
        lines += var(idx, n, dt, acc, d, pdo, low, high, sub=i)
    sections[which(idx)].append(lines)


def array(idx, name, n, elem_name, dt, acc, default, pdo=0, low=None, high=None, sub0acc="ro"):
    subs = [("Highest sub-index supported", 0x5, sub0acc, n)]
    subs += [(f"{elem_name} {i}", dt, acc, default, pdo, low, high) for i in range(1, n + 1)]
    obj_multi(idx, name, 0x8, subs)


U8, U16, U32, I16, I32, BOOL, VS, R32 = 0x5, 0x6, 0x7, 0x3, 0x4, 0x1, 0x9, 0x8
NRPDO = NTPDO = 32

# --- communication profile
obj_var(0x1000, "Device type", U32, "ro", "0x000F0191")
obj_var(0x1001, "Error register", U8, "ro", "0", pdo=1)
array(0x1003, "Pre-defined error field", 8, "Standard error field", U32, "ro", "0", sub0acc="rw")
obj_var(0x1005, "COB-ID SYNC", U32, "rw", "0x00000080")
obj_var(0x1006, "Communication cycle period", U32, "rw", "0")
obj_var(0x1007, "Synchronous window length", U32, "rw", "0")
obj_var(0x1008, "Manufacturer device name", VS, "const", "SafeLine IO-401")
obj_var(0x1009, "Manufacturer hardware version", VS, "const", "1.0")
obj_var(0x100A, "Manufacturer software version", VS, "const", "0.1.0")
obj_var(0x100C, "Guard time", U16, "rw", "0")
obj_var(0x100D, "Life time factor", U8, "rw", "0")
for idx, what in ((0x1010, "Save"), (0x1011, "Restore default")):
    obj_multi(idx, "Store parameters" if idx == 0x1010 else "Restore default parameters", 0x8,
              [("Highest sub-index supported", U8, "ro", 4)] +
              [(f"{what} {g} parameters", U32, "rw", 1) for g in
               ("all", "communication", "application", "manufacturer")])
obj_var(0x1012, "COB-ID time stamp object", U32, "rw", "0x00000100")
obj_var(0x1014, "COB-ID EMCY", U32, "rw", "$NODEID+0x80")
obj_var(0x1015, "Inhibit time EMCY", U16, "rw", "0")
array(0x1016, "Consumer heartbeat time", 8, "Consumer heartbeat time", U32, "rw", "0")
obj_var(0x1017, "Producer heartbeat time", U16, "rw", "0")
obj_multi(0x1018, "Identity object", 0x9, [
    ("Highest sub-index supported", U8, "const", 4),
    ("Vendor-ID", U32, "ro", "0x00000ABC"), ("Product code", U32, "ro", "0x00000401"),
    ("Revision number", U32, "ro", "0x00010000"), ("Serial number", U32, "ro", "0")])
obj_var(0x1019, "Synchronous counter overflow value", U8, "rw", "0")
array(0x1020, "Verify configuration", 2, "Configuration", U32, "rw", "0")
array(0x1029, "Error behavior", 2, "Error class", U8, "rw", "0")
obj_multi(0x1200, "SDO server parameter", 0x9, [
    ("Highest sub-index supported", U8, "const", 2),
    ("COB-ID client to server", U32, "ro", "$NODEID+0x600"),
    ("COB-ID server to client", U32, "ro", "$NODEID+0x580")])
for n in range(NRPDO):
    cob = f"$NODEID+0x{0x200 + 0x100 * n:X}" if n < 4 else f"0x{0x80000000:X}"
    obj_multi(0x1400 + n, f"RPDO communication parameter {n + 1}", 0x9, [
        ("Highest sub-index supported", U8, "const", 5),
        ("COB-ID used by RPDO", U32, "rw", cob), ("Transmission type", U8, "rw", 255),
        ("Inhibit time", U16, "rw", 0), ("Compatibility entry", U8, "rw", 0),
        ("Event timer", U16, "rw", 0)])
for n in range(NRPDO):
    obj_multi(0x1600 + n, f"RPDO mapping parameter {n + 1}", 0x9,
              [("Number of mapped objects", U8, "rw", 0, 0, 0, 64)] +
              [(f"Mapping entry {i}", U32, "rw", 0) for i in range(1, 9)])
for n in range(NTPDO):
    cob = f"$NODEID+0x{0x180 + 0x100 * n:X}" if n < 4 else f"0x{0xC0000000:X}"
    obj_multi(0x1800 + n, f"TPDO communication parameter {n + 1}", 0x9, [
        ("Highest sub-index supported", U8, "const", 6),
        ("COB-ID used by TPDO", U32, "rw", cob), ("Transmission type", U8, "rw", 255),
        ("Inhibit time", U16, "rw", 0), ("Reserved", U8, "rw", 0),
        ("Event timer", U16, "rw", 0), ("SYNC start value", U8, "rw", 0)])
for n in range(NTPDO):
    obj_multi(0x1A00 + n, f"TPDO mapping parameter {n + 1}", 0x9,
              [("Number of mapped objects", U8, "rw", 0, 0, 0, 64)] +
              [(f"Mapping entry {i}", U32, "rw", 0) for i in range(1, 9)])
obj_var(0x1F80, "NMT startup", U32, "rw", "0")

# --- manufacturer: one configuration record per channel
for ch in range(64):
    obj_multi(0x2100 + ch, f"Channel {ch} configuration", 0x9, [
        ("Highest sub-index supported", U8, "const", 5),
        ("Mode", U8, "rw", 0, 0, 0, 3), ("Debounce time", U16, "rw", 10, 0, 0, 1000),
        # REAL32 1.0, -100.0, 100.0 as IEEE 754 bit patterns (the form lely's dcfchk reads)
        ("Scale", R32, "rw", "0x3F800000", 0, "0xC2C80000", "0x42C80000"),
        ("Label", VS, "rw", f"CH{ch}"),
        ("Enabled", BOOL, "rw", 1)])
obj_var(0x2000, "Operating hours", U32, "ro", "0", pdo=1)
obj_var(0x2001, "Board temperature", I16, "ro", "0", pdo=1)

# --- CiA 401 device profile
array(0x6000, "Read input 8-bit", 8, "Read input", U8, "ro", "0", pdo=1)
array(0x6002, "Polarity input 8-bit", 8, "Polarity input", U8, "rw", "0")
array(0x6003, "Filter constant input 8-bit", 8, "Filter constant input", U8, "rw", "0")
obj_var(0x6005, "Global interrupt enable digital", BOOL, "rw", "1")
array(0x6006, "Interrupt mask any change 8-bit", 8, "Interrupt mask any change", U8, "rw",
      "0xFF")
array(0x6007, "Interrupt mask low-to-high 8-bit", 8, "Interrupt mask low-to-high", U8, "rw",
      "0")
array(0x6008, "Interrupt mask high-to-low 8-bit", 8, "Interrupt mask high-to-low", U8, "rw",
      "0")
array(0x6100, "Read input 16-bit", 4, "Read input", U16, "ro", "0", pdo=1)
array(0x6120, "Read input 32-bit", 2, "Read input", U32, "ro", "0", pdo=1)
array(0x6200, "Write output 8-bit", 8, "Write output", U8, "rww", "0", pdo=1)
array(0x6202, "Change polarity output 8-bit", 8, "Change polarity output", U8, "rw", "0")
array(0x6206, "Error mode output 8-bit", 8, "Error mode output", U8, "rw", "0xFF")
array(0x6207, "Error value output 8-bit", 8, "Error value output", U8, "rw", "0")
array(0x6208, "Filter mask output 8-bit", 8, "Filter mask output", U8, "rw", "0xFF")
array(0x6300, "Write output 16-bit", 4, "Write output", U16, "rww", "0", pdo=1)
array(0x6401, "Read analogue input 16-bit", 16, "Analogue input", I16, "ro", "0", pdo=1)
array(0x6411, "Write analogue output 16-bit", 8, "Analogue output", I16, "rww", "0", pdo=1)
array(0x6421, "Analogue input interrupt trigger selection", 16, "Trigger selection", U8, "rw",
      "0x07")
array(0x6422, "Analogue input interrupt source", 4, "Interrupt source bank", U32, "ro", "0",
      pdo=1)
obj_var(0x6423, "Analogue input global interrupt enable", BOOL, "rw", "0")
array(0x6424, "Analogue input interrupt upper limit integer", 16, "Upper limit", I32, "rw",
      "32767", low="-32768", high="32767")
array(0x6425, "Analogue input interrupt lower limit integer", 16, "Lower limit", I32, "rw",
      "-32768", low="-32768", high="32767")
array(0x6426, "Analogue input interrupt delta unsigned", 16, "Delta", U32, "rw", "0")
array(0x6443, "Analogue output error mode", 8, "Error mode", U8, "rw", "1")
array(0x6444, "Analogue output error value integer", 8, "Error value", I32, "rw", "0")

hdr = """[FileInfo]
FileName=io401.eds
FileVersion=1
FileRevision=0
EDSVersion=4.0
Description=SafeLine CiA 401 generic I/O module (test data)
CreationTime=09:00AM
CreationDate=02-01-2024
CreatedBy=SafeLine

[DeviceInfo]
VendorName=SafeLine
VendorNumber=0x00000ABC
ProductName=IO-401
ProductNumber=0x00000401
RevisionNumber=0x00010000
OrderCode=IO-401-64
BaudRate_10=1
BaudRate_20=1
BaudRate_50=1
BaudRate_125=1
BaudRate_250=1
BaudRate_500=1
BaudRate_800=1
BaudRate_1000=1
SimpleBootUpMaster=0
SimpleBootUpSlave=1
Granularity=8
DynamicChannelsSupported=0
GroupMessaging=0
NrOfRXPDO=32
NrOfTXPDO=32
LSS_Supported=1

[DummyUsage]
Dummy0001=0
Dummy0002=1
Dummy0003=1
Dummy0004=1
Dummy0005=1
Dummy0006=1
Dummy0007=1
"""
out.append(hdr)
for li, title in enumerate(("MandatoryObjects", "OptionalObjects", "ManufacturerObjects")):
    idxs = lists[li]
    out.append(f"[{title}]\nSupportedObjects={len(idxs)}\n" +
               "".join(f"{n}=0x{i:04X}\n" for n, i in enumerate(idxs, 1)) + "\n")
    for lines in sections[li]:
        out.append("\n".join(lines) + "\n")
sys.stdout.write("".join(out))
