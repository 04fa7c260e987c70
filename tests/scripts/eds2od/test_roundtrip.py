# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""EDS -> C -> EDS written by the firmware -> python-canopen reads the same dictionary."""

import os
import re
import struct
import subprocess

import canopen
import pytest

from eds2od_testlib import BASE, DATA, compile_dump, run_eds2od

CASES = [("alltypes.eds", "alltypes"), ("io401.eds", "io401"), ("device.dcf", "device")]


def flatten(od):
    out = {}
    for obj in od.values():
        if isinstance(obj, canopen.objectdictionary.ODVariable):
            vs = [obj]
        else:
            vs = list(obj.subindices.values())
        for v in vs:
            out[(v.index, v.subindex)] = (obj, v)
    return out


def same_value(data_type, a, b):
    if data_type == canopen.objectdictionary.REAL32 and a is not None and b is not None:
        return struct.pack("<f", a) == struct.pack("<f", b)
    return a == b


def decimal_reals(path, tmp_path):
    """A copy of the EDS with REAL values written as IEEE 754 bit patterns (the form lely's
    dcfchk needs) turned into decimals, the only form python-canopen reads (whole numbers
    without a point: it reads REAL limits with int())."""

    def dec(fmt, ifmt, text):
        f = struct.unpack(fmt, struct.pack(ifmt, int(text, 16)))[0]
        return str(int(f)) if f.is_integer() else repr(f)

    sections = re.split(r"(?m)^(?=\[)", open(path, encoding="utf-8").read())
    for i, sec in enumerate(sections):
        m = re.search(r"(?m)^DataType=0x00(08|11)$", sec)
        if not m:
            continue
        fmt, ifmt = ("<f", "<I") if m.group(1) == "08" else ("<d", "<Q")
        sections[i] = re.sub(
            r"(?m)^(DefaultValue|ParameterValue|LowLimit|HighLimit)=(0x[0-9A-Fa-f]+)$",
            lambda k: f"{k.group(1)}={dec(fmt, ifmt, k.group(2))}", sec)
    out = tmp_path / ("decimal_" + os.path.basename(path))
    out.write_text("".join(sections), encoding="utf-8")
    return str(out)


def expected_default(v):
    # A DCF's ParameterValue is what the firmware holds as its default.
    return v.value if getattr(v, "value", None) is not None else v.default


@pytest.mark.parametrize("eds,name", CASES)
def test_firmware_eds_equals_generator_eds(eds, name, tmp_path):
    out = tmp_path / "gen"
    r = run_eds2od(os.path.join(DATA, eds), out, name)
    assert r.returncode == 0, r.stderr
    exe = compile_dump(out, name, tmp_path)
    fw = subprocess.run([str(exe)], capture_output=True, check=True).stdout
    assert fw == (out / f"{name}.eds").read_bytes()


@pytest.mark.parametrize("eds,name", CASES)
def test_python_canopen_reads_the_same_objects(eds, name, tmp_path):
    out = tmp_path / "gen"
    r = run_eds2od(os.path.join(DATA, eds), out, name)
    assert r.returncode == 0, r.stderr
    exe = compile_dump(out, name, tmp_path)
    regen = tmp_path / "firmware.eds"
    regen.write_bytes(subprocess.run([str(exe)], capture_output=True, check=True).stdout)

    src = canopen.import_od(decimal_reals(os.path.join(DATA, eds), tmp_path), node_id=5)
    fw = canopen.import_od(str(regen), node_id=5)
    a, b = flatten(src), flatten(fw)
    compact = {o.index for o in src.values()
               if isinstance(o, canopen.objectdictionary.ODArray) and 0 in o.subindices
               and o.subindices[0].name == "Number of entries"}
    checked = 0
    for key, (obj, v) in a.items():
        assert key in b, f"{key[0]:04X}h:{key[1]} missing in the firmware's EDS"
        fobj, w = b[key]
        if key[0] in compact and key[1] == 0:
            # python-canopen invents sub 0 of CompactSubObj arrays (rw, no value); the
            # firmware has the CiA 306 meaning (ro, the number of entries).
            assert w.access_type == "ro" and w.default == len(fobj.subindices) - 1
            continue
        assert type(obj) is type(fobj), key
        assert (w.data_type, w.access_type, w.pdo_mappable) == \
            (v.data_type, v.access_type, v.pdo_mappable), key
        if key[0] in compact:
            # python-canopen reads neither [xxxxValue] nor default names of CompactSubObj
            # entries (test_dcf_compact_values checks them).
            continue
        assert w.name == v.name, key
        assert same_value(v.data_type, w.default, expected_default(v)), \
            (key, w.default, expected_default(v))
        assert same_value(v.data_type, w.min, v.min) and same_value(v.data_type, w.max, v.max), key
        checked += 1
    # python-canopen only expands CompactSubObj through a Name section; the firmware's EDS
    # lists every sub-index, so it may only have more.
    extra = set(b) - set(a)
    assert all(k[0] in compact for k in extra), sorted(extra)
    assert checked == len(a) - sum(1 for k in a if k[0] in compact)


def test_every_type_and_object_code_is_covered():
    od = canopen.import_od(os.path.join(DATA, "alltypes.eds"))
    types = {v.data_type for _, v in flatten(od).values()}
    from eds2od import dtypes
    assert {t.code for t in dtypes.TABLE} <= types
    with open(os.path.join(DATA, "alltypes.eds")) as f:
        text = f.read()
    for code in ("0x7", "0x8", "0x9", "0x2"):
        assert f"ObjectType={code}\n" in text


def test_generated_c_compiles_strictly(tmp_path):
    """The build contract: generated C compiles with -std=gnu11 -Wall -Wextra, no warning."""
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "io401.eds"), out, "io401").returncode == 0
    for defs in ([], ["-DCONFIG_CANOPEN_OD_NAMES=1", "-DCONFIG_CANOPEN_OD_SCRATCH_SIZE=64"]):
        r = subprocess.run(["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", *defs, "-c",
                            "-I", os.path.join(BASE, "include"), str(out / "io401_od.c"),
                            "-o", str(tmp_path / "x.o")], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr


def test_scratch_size_is_checked_at_build_time(tmp_path):
    """A Kconfig staging buffer smaller than the OD's largest value fails the build."""
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "alltypes.eds"), out, "alltypes").returncode == 0
    r = subprocess.run(["gcc", "-std=gnu11", "-c", "-DCONFIG_CANOPEN_OD_SCRATCH_SIZE=16",
                        "-I", os.path.join(BASE, "include"), str(out / "alltypes_od.c"),
                        "-o", str(tmp_path / "x.o")], capture_output=True, text=True)
    assert r.returncode != 0 and "CONFIG_CANOPEN_OD_SCRATCH_SIZE" in r.stderr


def test_service_limits_are_checked_at_build_time(tmp_path):
    """More SDO server objects than CONFIG_CANOPEN_SDO_SERVERS fails the build."""
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "io401.eds"), out, "io401").returncode == 0
    cmd = ["gcc", "-std=gnu11", "-c", "-I", os.path.join(BASE, "include"),
           str(out / "io401_od.c"), "-o", str(tmp_path / "x.o")]
    ok = subprocess.run(cmd + ["-DCONFIG_CANOPEN_SDO_SERVERS=1"], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    bad = subprocess.run(cmd + ["-DCONFIG_CANOPEN_SDO_SERVERS=0"], capture_output=True, text=True)
    assert bad.returncode != 0 and "CONFIG_CANOPEN_SDO_SERVERS" in bad.stderr
