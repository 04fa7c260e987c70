# SPDX-License-Identifier: Apache-2.0
"""scripts/footprint: the sources it takes from the CMakeLists, the link map it reads, and a
real run of the three configurations (skipped without arm-none-eabi-gcc)."""

import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPT = os.path.join(BASE, "scripts", "footprint")


def load():
    loader = importlib.machinery.SourceFileLoader("safeline_footprint", SCRIPT)
    spec = importlib.util.spec_from_loader("safeline_footprint", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


fp = load()


def rel(paths):
    return sorted(os.path.relpath(p, BASE) for p in paths)


def test_sources_follow_the_cmakelists_conditions():
    base = {"CONFIG_CANOPEN_OD": "y", "CONFIG_CANOPEN_PDO": "y", "CONFIG_CANOPEN_SYNC": "y"}
    got = rel(fp.canopen_sources(base))
    assert "subsys/canopen/core/line.c" in got
    assert "subsys/canopen/core/lock_check.c" not in got
    assert "subsys/canopen/pdo/pdo.c" in got and "subsys/canopen/pdo/mpdo.c" not in got
    assert "subsys/canopen/sdo/sdo_srv.c" not in got
    assert not any(p.startswith("subsys/canopen/bridge") for p in got), "native-only folders"

    more = dict(base, CONFIG_CANOPEN_MPDO="y", CONFIG_CANOPEN_SDO_SERVER="y",
                CONFIG_CANOPEN_LOCK_CHECK="y", CONFIG_CANOPEN_STORAGE="y",
                CONFIG_CANOPEN_CFG="y")
    got = rel(fp.canopen_sources(more))
    assert "subsys/canopen/pdo/mpdo.c" in got
    assert "subsys/canopen/sdo/sdo_srv.c" in got
    assert "subsys/canopen/core/lock_check.c" in got
    assert "subsys/canopen/storage/storage.c" in got
    assert "subsys/canopen/storage/storage_file.c" not in got, "host file backend"
    assert "subsys/canopen/mgr/cfg.c" in got and "subsys/canopen/mgr/mgr.c" not in got


def test_conditions_and_what_is_not_understood():
    conf = {"CONFIG_A": "y", "CONFIG_B": "n"}
    assert fp._cond("CONFIG_A OR CONFIG_B", conf)
    assert not fp._cond("CONFIG_A AND CONFIG_B", conf)
    assert fp._cond("CONFIG_B OR (CONFIG_A AND NOT CONFIG_B)", conf)
    assert not fp._cond("NOT ( CONFIG_A )", conf)
    with pytest.raises(fp.FootprintError, match="not understood"):
        fp._cond("CONFIG_A STREQUAL x", conf)


def test_map_sections_are_summed_per_file(tmp_path):
    m = tmp_path / "f.map"
    m.write_text("\n".join([
        "Discarded input sections",
        " .text.gone     0x00000000       0x40 /o/a.o",
        "",
        "Linker script and memory map",
        ".text           0x00000000      0x100",
        " .text.f        0x00000000       0x20 /o/a.o",
        " .text.a_very_long_function_name",
        "                0x00000020       0x10 /o/a.o",
        " .rodata.s      0x00000030        0x8 /o/b.o",
        " *fill*         0x00000038        0x8 ",
        ".data           0x20000000        0x4 load address 0x00000100",
        " .data.x        0x20000000        0x4 /o/b.o",
        ".bss            0x20000004       0x30",
        " .bss.y         0x20000004       0x30 /o/a.o",
        " COMMON         0x20000034        0x4 /o/c.o",
    ]) + "\n")
    got = fp.parse_map(str(m))
    assert got["/o/a.o"] == {"text": 0x30, "data": 0, "bss": 0x30}, "discarded ones left out"
    assert got["/o/b.o"] == {"text": 8, "data": 4, "bss": 0}
    assert got["/o/c.o"] == {"text": 0, "data": 0, "bss": 4}


@pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None,
                    reason="arm-none-eabi-gcc not installed (scripts/setup installs it)")
def test_three_configurations_measured(tmp_path):
    out = tmp_path / "footprint.json"
    r = subprocess.run([sys.executable, SCRIPT, "-O", str(tmp_path / "build"), "-o", str(out)],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stdout[-3000:]
    for title in ("minimal slave", "default slave", "full slave"):
        assert title in r.stdout
    assert "target <= 12.0 kB" in r.stdout and "target <= 5.5 kB" in r.stdout
    assert "compiler warnings" not in r.stdout

    doc = json.loads(out.read_text())
    assert doc["target"].startswith("Cortex-M4")
    configs = {c["name"]: c for c in doc["configurations"]}
    assert list(configs) == ["minimal", "default", "full"]
    for c in configs.values():
        files = {f["file"]: f for f in c["files"] if f["kind"] == "stack"}
        assert "subsys/canopen/core/line.c" in files
        assert c["stack"]["code"] == c["totals"]["stack"]["text"] + c["totals"]["stack"]["data"]
        assert c["stack"]["code"] > 10000
        assert c["ram"]["per_line"] > 0 and c["ram"]["per_node"] > 0
        assert "stubs.c" not in " ".join(files), "the stubs are not the stack's"
        # Embedded defaults: a target's receive table (32 entries), not the native board's.
        assert c["kconfig"]["CONFIG_CANOPEN_LINE_RX_SLOTS"] in ("16", "32"), "embedded defaults"
    assert "per_rpdo" in configs["minimal"]["ram"] and "per_sdo_srv" in configs["minimal"]["ram"]
    assert "subsys/canopen/pdo/mpdo.c" not in {f["file"] for f in configs["minimal"]["files"]}
    # The minimal slave leaves out the OD's providers; the others keep the default.
    assert configs["minimal"]["kconfig"]["CONFIG_CANOPEN_OD_PROVIDERS"] == "n"
    assert configs["full"]["kconfig"]["CONFIG_CANOPEN_OD_PROVIDERS"] == "y"
    assert "subsys/canopen/srdo/srdo.c" in {f["file"] for f in configs["full"]["files"]}
    assert configs["full"]["lines"] == 2, "redundancy: a second line"
    assert configs["minimal"]["target"] == {"code": 12 * 1024, "ram": 2 * 1024}
    assert configs["full"]["target"] is None
    assert configs["full"]["stack"]["code"] > configs["minimal"]["stack"]["code"]
