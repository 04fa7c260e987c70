# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Shared helpers for the eds2od tests (a plain module: conftest.py names clash across
folders)."""

import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DATA = os.path.join(HERE, "data")
GOLDEN = os.path.join(HERE, "golden")
EDS2OD = os.path.join(BASE, "scripts", "eds2od")

sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))


def run_eds2od(path, outdir=None, name=None, extra=()):
    cmd = [sys.executable, EDS2OD, str(path)]
    if name:
        cmd += ["--name", name]
    if outdir:
        cmd += ["-o", str(outdir)]
    else:
        cmd += ["--lint-only"]
    cmd += list(extra)
    return subprocess.run(cmd, capture_output=True, text=True)


def compile_dump(outdir, name, tmp_path):
    """Build the host program that prints the firmware's EDS for one generated OD."""
    exe = tmp_path / f"dump_{name}"
    cmd = ["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-O1",
           "-DCONFIG_CANOPEN_OD_NAMES=1", "-DCONFIG_CANOPEN_OD_SCRATCH_SIZE=1024",
           f"-DOD_NAME={name}", f'-DOD_HEADER="{name}_od.h"',
           "-I", os.path.join(BASE, "include"),
           "-I", os.path.join(BASE, "subsys", "canopen", "od"),
           "-I", os.path.join(BASE, "subsys", "canopen", "core"), "-I", str(outdir),
           os.path.join(HERE, "host", "eds_dump.c"),
           os.path.join(BASE, "subsys", "canopen", "od", "od.c"),
           os.path.join(BASE, "subsys", "canopen", "od", "od_eds.c"),
           os.path.join(str(outdir), f"{name}_od.c"), "-o", str(exe)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return exe



# --------------------------------------------------------------------------------------
# SRDO objects as EDS/DCF text (CiA 304), for the lint tests and tests/scripts/srdo_sign


def section(name, keys):
    """[name] with keys in order; keys whose value is None are left out."""
    return f"[{name}]\n" + "".join(f"{k}={v}\n" for k, v in keys.items() if v is not None) + "\n"


def value_keys(value, key):
    """DefaultValue=value, or for key "ParameterValue" a DCF's DefaultValue=0 and the value."""
    if value is None:
        return {}
    if key == "ParameterValue":
        return {"DefaultValue": "0", "ParameterValue": value}
    return {"DefaultValue": value}


def record(idx, name, subs, objtype=0x9):
    """An ARRAY/RECORD: subs = [(name, DataType, AccessType, value keys, PDOMapping)] for
    sub-index 0, 1, ... (a None item leaves that sub-index out)."""
    n = sum(1 for s in subs if s is not None)
    out = section(f"{idx:04X}", {"ParameterName": name, "ObjectType": f"0x{objtype:X}",
                                 "SubNumber": f"0x{n:X}"})
    for k, s in enumerate(subs):
        if s is None:
            continue
        sname, dt, acc, vals, pdo = s
        out += section(f"{idx:04X}sub{k:X}", {"ParameterName": sname, "ObjectType": "0x7",
                                              "DataType": dt, "AccessType": acc, **vals,
                                              "PDOMapping": pdo})
    return out


def srdo_comm(n, direction=1, cycle=25, srvt=20, tt=254, cob1=0x101, cob2=0x102,
              key="DefaultValue", types=None, sub0=6):
    """1300h + n with its seven sub-indexes; `types` overrides DataTypes by sub-index."""
    t = {0: "0x0005", 1: "0x0005", 2: "0x0006", 3: "0x0005", 4: "0x0005", 5: "0x0007",
         6: "0x0007", **(types or {})}

    def v(x):
        return x if isinstance(x, str) or x is None else f"0x{x:X}"

    subs = [("Highest sub-index supported", t[0], "const", {"DefaultValue": v(sub0)}, "0")]
    for k, (name, val) in enumerate((("Information direction", direction),
                                     ("Refresh time or SCT", cycle), ("SRVT", srvt),
                                     ("Transmission type", tt), ("COB-ID 1", cob1),
                                     ("COB-ID 2", cob2)), start=1):
        subs.append((name, t[k], "rw", value_keys(v(val), key), "0"))
    return record(0x1300 + n, f"SRDO {n} communication parameter", subs)


def srdo_map(n, entries, count=None, key="DefaultValue", size=None):
    """1380h + n: `count` (default len(entries)) and the entries; `size` sub-indexes 1..size
    (default len(entries))."""
    count = len(entries) if count is None else count
    size = len(entries) if size is None else size
    subs = [("Number of mapped objects", "0x0005", "rw", value_keys(f"{count}", key), "0")]
    for k in range(1, size + 1):
        e = entries[k - 1] if k <= len(entries) else 0
        subs.append((f"Mapping entry {k}", "0x0007", "rw", value_keys(f"0x{e:08X}", key), "0"))
    return record(0x1380 + n, f"SRDO {n} mapping parameter", subs)


def srdo_signatures(count, values=None, key="DefaultValue"):
    """13FFh, ARRAY of UNSIGNED16 with sub-indexes 1..count."""
    values = values or {}
    subs = [("Number of entries", "0x0005", "const", {"DefaultValue": f"{count}"}, "0")]
    for k in range(1, count + 1):
        subs.append((f"SRDO {k} signature", "0x0006", "rw",
                     value_keys(f"0x{values.get(k, 0):04X}", key), "0"))
    return record(0x13FF, "Safety configuration signature", subs, objtype=0x8)


def srdo_valid(value=0, key="DefaultValue", dtype="0x0005"):
    """13FEh, configuration valid."""
    return section("13FE", {"ParameterName": "Configuration valid", "ObjectType": "0x7",
                            "DataType": dtype, "AccessType": "rw",
                            **value_keys(f"0x{value:02X}", key), "PDOMapping": "0"})


def app_array(idx, n, dtype="0x0005", pdo="1", access="rw"):
    """An application ARRAY (e.g. 6200h) of n mappable values."""
    subs = [("Number of entries", "0x0005", "const", {"DefaultValue": f"{n}"}, "0")]
    for k in range(1, n + 1):
        subs.append((f"Value {k}", dtype, access, {"DefaultValue": "0"}, pdo))
    return record(idx, f"Object {idx:04X}h", subs, objtype=0x8)
