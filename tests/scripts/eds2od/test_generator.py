# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Golden outputs, the data-type table, DCF handling and the generated layout."""

import os
import re
import shutil
import subprocess

import pytest

from eds2od_testlib import BASE, DATA, GOLDEN, run_eds2od, srdo_comm, srdo_map

GOLDEN_CASES = [("alltypes.eds", "alltypes"), ("device.dcf", "device"), ("minimal.eds", "minimal")]


@pytest.mark.parametrize("eds,name", GOLDEN_CASES)
def test_golden_output(eds, name, tmp_path):
    """Generated files equal the reviewed ones (UPDATE_GOLDEN=1 rewrites them)."""
    out = tmp_path / "gen"
    r = run_eds2od(os.path.join(DATA, eds), out, name)
    assert r.returncode == 0, r.stderr
    gdir = os.path.join(GOLDEN, name)
    files = sorted(os.listdir(out))
    assert files == sorted([f"{name}_od.c", f"{name}_od.h", f"{name}.eds"])
    # Stored as <file>.golden: expected output, not sources (no compiler or formatter
    # should pick them up).
    if os.environ.get("UPDATE_GOLDEN"):
        shutil.rmtree(gdir, ignore_errors=True)
        os.makedirs(gdir)
        for f in files:
            shutil.copyfile(out / f, os.path.join(gdir, f + ".golden"))
    for f in files:
        with open(os.path.join(gdir, f + ".golden"), "rb") as g:
            assert (out / f).read_bytes() == g.read(), f"{f} differs from {gdir}"


def test_dtype_table_matches_types_h():
    """The generator's type table is the X-macro table of include/canopen/types.h."""
    from eds2od import dtypes

    with open(os.path.join(BASE, "include", "canopen", "types.h")) as f:
        text = f.read()
    rows = re.findall(r"X\((\w+), (0x[0-9A-F]{4}), (\d+), (\w+), ([\w ]+)\)", text)
    c_table = [(n, int(c, 16), int(s), k, t) for n, c, s, k, t in rows]
    py_table = [(t.name, t.code, t.size, t.cls, t.ctype) for t in dtypes.TABLE]
    assert c_table == py_table


def test_dcf_values_and_commissioning(tmp_path):
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "device.dcf"), out, "device").returncode == 0
    h = (out / "device_od.h").read_text()
    c = (out / "device_od.c").read_text()
    assert "#define DEVICE_OD_NODE_ID 10U" in h
    assert "#define DEVICE_OD_BITRATE_KBPS 500U" in h
    # ParameterValue wins over DefaultValue; $NODEID uses the DCF node-ID in the template.
    assert ".x1017_producer_heartbeat_time = 0xFAU" in c
    assert ".cob_id_used_by_tpdo = 0x28AU" in c
    assert "{0U, 0x1800U, 640}" not in c and re.search(r"\{\d+U, 0x1800U, 640\}", c)
    assert ".x2000_setpoint = 0x5DCU" in c


def test_dcf_compact_values(tmp_path):
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "device.dcf"), out, "device").returncode == 0
    c = (out / "device_od.c").read_text()
    assert ".x2001_offsets = {.sub0 = 0x3U, .elem[0] = -5, .elem[1] = 0, .elem[2] = 7}" in c


def test_storage_groups_and_rom(tmp_path):
    out = tmp_path / "gen"
    assert run_eds2od(os.path.join(DATA, "alltypes.eds"), out, "alltypes").returncode == 0
    h = (out / "alltypes_od.h").read_text()
    ram = h[h.index("struct alltypes_od_ram {"):h.index("struct alltypes_od_rom {")]
    rom = h[h.index("struct alltypes_od_rom {"):]
    groups = re.findall(r"^\t\} (\w+);$", ram, re.M)
    assert groups == ["comm", "comm_vol", "manuf", "manuf_vol", "app"]

    bodies = dict((g, b) for b, g in
                  re.findall(r"^\tstruct \{\n(.*?)^\t\} (\w+);$", ram, re.M | re.S))

    def group_of(field):
        found = [g for g, b in bodies.items() if field in b]
        return found[0] if len(found) == 1 else None

    assert group_of("x1017_producer_heartbeat_time") == "comm"   # rw comm parameter
    assert group_of("x1001_error_register") == "comm_vol"        # device-written
    assert group_of("x1010_store_parameters") == "comm_vol"      # command object
    assert group_of("x2003_integer_array") == "manuf"
    assert group_of("x2005_volatile_counter") == "manuf_vol"
    assert group_of("x6000_all_types") == "app"
    assert "x1008_manufacturer_device_name" in rom               # const: flash
    assert "x2004_const_real" in rom


def test_name_defaults_to_file_name(tmp_path):
    src = tmp_path / "My-Device.eds"
    shutil.copy(os.path.join(DATA, "minimal.eds"), src)
    r = run_eds2od(src, tmp_path / "gen")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "gen" / "my_device_od.h").exists()


def test_cmake_module_declares_the_function():
    with open(os.path.join(BASE, "cmake", "modules", "canopen_od.cmake")) as f:
        text = f.read()
    assert "function(canopen_od_generate target)" in text
    assert "scripts/eds2od" in text


def test_safeline_keys_as_comments(tmp_path):
    """;SafeLineSize=n and ;SafeLineStore=0|1 (the form dcfchk skips) work as the keys do; a
    comment that is no SafeLine key stays a comment."""
    with open(os.path.join(DATA, "minimal.eds")) as f:
        text = f.read()
    text = text.replace("[ManufacturerObjects]\nSupportedObjects=0\n",
                        "[ManufacturerObjects]\nSupportedObjects=1\n1=0x2000\n", 1)
    text += ("\n[2000]\nParameterName=Label\nDataType=0x0009\nAccessType=rw\nDefaultValue=ab\n"
             ";SafeLineSize=32\n; SafeLineStore=0\n;DefaultValue=abcdef\n")
    src = tmp_path / "cmt.eds"
    src.write_text(text)
    out = tmp_path / "gen"
    r = run_eds2od(src, out, "cmt")
    assert r.returncode == 0, r.stderr
    h = (out / "cmt_od.h").read_text()
    assert "char x2000_label[33];" in h
    assert re.search(r"struct \{\n\t\tchar x2000_label\[33\];\n\t\} manuf_vol;", h)
    assert "DefaultValue=ab\n" in (out / "cmt.eds").read_text()


def test_store_override(tmp_path):
    """SafeLineStore=0 keeps a writable parameter out of its group, =1 puts one in."""
    with open(os.path.join(DATA, "minimal.eds")) as f:
        text = f.read()
    text = text.replace("[ManufacturerObjects]\nSupportedObjects=0\n",
                        "[ManufacturerObjects]\nSupportedObjects=2\n1=0x2000\n2=0x2001\n", 1)
    text += ("\n[2000]\nParameterName=Scratch\nDataType=0x0007\nAccessType=rw\nDefaultValue=0\n"
             "SafeLineStore=0\n\n"
             "[2001]\nParameterName=Kept\nDataType=0x0007\nAccessType=rw\nDefaultValue=0\n")
    src = tmp_path / "store.eds"
    src.write_text(text)
    out = tmp_path / "gen"
    r = run_eds2od(src, out, "store")
    assert r.returncode == 0, r.stderr
    h = (out / "store_od.h").read_text()
    assert re.search(r"struct \{\n\t\tuint32_t x2001_kept;\n\t\} manuf;", h)
    assert re.search(r"struct \{\n\t\tuint32_t x2000_scratch;\n\t\} manuf_vol;", h)


def _count(h, name, key):
    m = re.search(rf"#define {name.upper()}_OD_CNT_{key} (\d+)U", h)
    assert m, key
    return int(m.group(1))


def _syntax_check(out, name, defines):
    cmd = ["gcc", "-std=gnu11", "-fsyntax-only", "-I", os.path.join(BASE, "include"),
           "-I", str(out)] + [f"-D{d}" for d in defines] + [str(out / f"{name}_od.c")]
    return subprocess.run(cmd, capture_output=True, text=True)


def _with_client_sdo(eds, tmp_path):
    """io401.eds plus one client SDO parameter record, 1280h (io401 has none)."""
    text = open(eds, encoding="utf-8").read()
    m = re.search(r"\[OptionalObjects\]\nSupportedObjects=(\d+)\n", text)
    n = int(m.group(1)) + 1
    text = text.replace(m.group(0), f"[OptionalObjects]\nSupportedObjects={n}\n{n}=0x1280\n")
    subs = [("Highest sub-index supported", "0x0005", "const", "3"),
            ("COB-ID client to server", "0x0007", "rw", "0x80000000"),
            ("COB-ID server to client", "0x0007", "rw", "0x80000000"),
            ("Node-ID of the SDO server", "0x0005", "rw", "0")]
    rec = "\n[1280]\nParameterName=SDO client parameter\nObjectType=0x9\nSubNumber=0x4\n"
    for i, (pn, dt, acc, dv) in enumerate(subs):
        rec += (f"\n[1280sub{i}]\nParameterName={pn}\nObjectType=0x7\nDataType={dt}\n"
                f"AccessType={acc}\nDefaultValue={dv}\nPDOMapping=0\n")
    text = text.replace("\n[1400]\n", rec + "\n[1400]\n", 1)
    path = tmp_path / "io_cli.eds"
    path.write_text(text, encoding="utf-8")
    return path


def _with_srdos(eds, tmp_path, numbers=(1, 2)):
    """io401.eds plus disabled SRDOs (1300h + n with 1380h + n; io401 has none)."""
    text = open(eds, encoding="utf-8").read()
    m = re.search(r"\[OptionalObjects\]\nSupportedObjects=(\d+)\n", text)
    n = int(m.group(1))
    idxs = [0x1300 + k for k in numbers] + [0x1380 + k for k in numbers]
    text = text.replace(m.group(0), f"[OptionalObjects]\nSupportedObjects={n + len(idxs)}\n" +
                        "".join(f"{n + 1 + i}=0x{x:04X}\n" for i, x in enumerate(idxs)))
    srdos = "".join(srdo_comm(k, 0, 0, 0, 0, 0, 0) + srdo_map(k, [0, 0], count=0)
                    for k in numbers)
    text = text.replace("\n[1400]\n", "\n" + srdos + "[1400]\n", 1)
    path = tmp_path / "io_srdo.eds"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("key,sym,guard", [
    ("RPDO", "CONFIG_CANOPEN_RPDOS", "CONFIG_CANOPEN_PDO"),
    ("TPDO", "CONFIG_CANOPEN_TPDOS", "CONFIG_CANOPEN_PDO"),
    ("SRDO", "CONFIG_CANOPEN_SRDOS", "CONFIG_CANOPEN_SRDO"),
    ("EM_HIST", "CONFIG_CANOPEN_EMCY_HISTORY", "CONFIG_CANOPEN_EMCY"),
    ("SDO_CLI", "CONFIG_CANOPEN_SDO_CLIENTS", "CONFIG_CANOPEN_SDO_CLIENT"),
])
def test_counts_checked_against_kconfig_only_with_the_service(tmp_path, key, sym, guard):
    """A dictionary with more objects than the service's Kconfig limit does not build, but
    only when the service is enabled."""
    out = tmp_path / "gen"
    eds = os.path.join(DATA, "io401.eds")
    if key == "SDO_CLI":
        eds = _with_client_sdo(eds, tmp_path)
    if key == "SRDO":
        eds = _with_srdos(eds, tmp_path)
    r = run_eds2od(eds, out, "io")
    assert r.returncode == 0, r.stderr
    n = _count((out / "io_od.h").read_text(), "io", key)
    assert n > 0, f"io401.eds should have {key} objects"
    assert _syntax_check(out, "io", [f"{guard}=1", f"{sym}={n}"]).returncode == 0
    r = _syntax_check(out, "io", [f"{guard}=1", f"{sym}={n - 1}"])
    assert r.returncode != 0
    assert f"more {key} objects than {sym}" in r.stderr
    assert _syntax_check(out, "io", [f"{sym}={n - 1}"]).returncode == 0, "service off"


def test_srdo_count_is_the_highest_srdo_number(tmp_path):
    """The stack keeps instances for SRDOs 1..n: a dictionary with only SRDO 3 needs three."""
    out = tmp_path / "gen"
    r = run_eds2od(_with_srdos(os.path.join(DATA, "io401.eds"), tmp_path, (3,)), out, "io")
    assert r.returncode == 0, r.stderr
    assert _count((out / "io_od.h").read_text(), "io", "SRDO") == 3
    guard = "CONFIG_CANOPEN_SRDO=1"
    assert _syntax_check(out, "io", [guard, "CONFIG_CANOPEN_SRDOS=3"]).returncode == 0
    r = _syntax_check(out, "io", [guard, "CONFIG_CANOPEN_SRDOS=2"])
    assert r.returncode != 0 and "more SRDO objects than CONFIG_CANOPEN_SRDOS" in r.stderr
