# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Shared helpers for the srdo-sign tests (a plain module: conftest.py names clash across
folders). The SRDO object builders are the eds2od tests' (eds2od_testlib)."""

import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
SRDO_SIGN = os.path.join(BASE, "scripts", "srdo-sign")

sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))
sys.path.insert(0, os.path.join(HERE, "..", "eds2od"))

from eds2od_testlib import (app_array, section, srdo_comm, srdo_map,  # noqa: E402,F401
                            srdo_signatures, srdo_valid)

HEAD = """[FileInfo]
FileName=srdo.dcf
FileVersion=1
FileRevision=0
EDSVersion=4.0
Description=SRDO signing test

[DeviceInfo]
VendorName=SafeLine
ProductName=Safe I/O
"""

BASIC = """[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00000191
PDOMapping=0

[1001]
ParameterName=Error register
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=0
PDOMapping=0

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=0x2

[1018sub0]
ParameterName=Highest sub-index supported
ObjectType=0x7
DataType=0x0005
AccessType=const
DefaultValue=1
PDOMapping=0

[1018sub1]
ParameterName=Vendor-ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00000ABC
PDOMapping=0

"""


def device(body, node_id=None):
    """A whole DCF/EDS around body (object sections); every object listed where it belongs,
    [DeviceComissioning] with NodeID when node_id is given."""
    idxs = sorted(int(h, 16) for h in re.findall(r"^\[([0-9A-F]{4})\]$", body, re.M))
    text = HEAD + "\n"
    if node_id is not None:
        text += f"[DeviceComissioning]\nNodeID={node_id}\nNodeName=safe-io\nBaudrate=500\n\n"
    text += "[MandatoryObjects]\nSupportedObjects=3\n1=0x1000\n2=0x1001\n3=0x1018\n\n"
    for title, sel in (("OptionalObjects", [i for i in idxs if not 0x2000 <= i < 0x6000]),
                       ("ManufacturerObjects", [i for i in idxs if 0x2000 <= i < 0x6000])):
        text += f"[{title}]\nSupportedObjects={len(sel)}\n"
        text += "".join(f"{n}=0x{i:04X}\n" for n, i in enumerate(sel, 1)) + "\n"
    return text + BASIC + body


def run(*args):
    return subprocess.run([sys.executable, SRDO_SIGN, *map(str, args)], capture_output=True,
                          text=True)


def key_line(text, sec, key):
    """1-based line of key= in [sec]."""
    rows = text.splitlines()
    at = rows.index(f"[{sec}]")
    for n in range(at + 1, len(rows)):
        if rows[n].startswith("["):
            break
        if rows[n].split("=")[0].strip() == key:
            return n + 1
    raise AssertionError(f"no {key} in [{sec}]")


def section_line(text, sec):
    return text.splitlines().index(f"[{sec}]") + 1


def values(path, index):
    """{sub: value} of an object as eds2od reads the file (ParameterValue wins)."""
    from eds2od.model import load

    o = load(str(path)).obj(index)
    return {s.sub: (s.default.v if s.default is not None else None) for s in o.subs}
