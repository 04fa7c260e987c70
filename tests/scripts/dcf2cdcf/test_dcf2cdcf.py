# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""scripts/dcf2cdcf: entry choice and order, golden outputs, file:line errors, decoding,
and agreement with lely's dcfgen (dcf-tools) where both describe the same configuration."""

import os
import random
import shutil
import struct
import subprocess

import pytest

from dcf2cdcf_testlib import GOLDEN, SLAVE, edit, run

from cdcf import cdcf


def keys(entries):
    return [(e.index, e.sub) if isinstance(e, cdcf.Entry) else e[:2] for e in entries]


def by_key(entries):
    return {(e.index, e.sub): e.data for e in entries}


# --------------------------------------------------------------------------------------
# Golden outputs


def test_golden_outputs(tmp_path):
    """.bin, .c/.h and the listing equal the reviewed ones (UPDATE_GOLDEN=1 rewrites them)."""
    r = run(SLAVE, "-o", tmp_path / "slave.bin", "--c-dir", tmp_path, "--name", "slave")
    assert r.returncode == 0, r.stderr
    lst = run(SLAVE, "--list")
    assert lst.returncode == 0, lst.stderr
    (tmp_path / "slave.list").write_text(lst.stdout)
    files = ["slave.bin", "slave_cdcf.c", "slave_cdcf.h", "slave.list"]
    if os.environ.get("UPDATE_GOLDEN"):
        os.makedirs(GOLDEN, exist_ok=True)
        for f in files:
            shutil.copyfile(tmp_path / f, os.path.join(GOLDEN, f + ".golden"))
    for f in files:
        with open(os.path.join(GOLDEN, f + ".golden"), "rb") as g:
            assert (tmp_path / f).read_bytes() == g.read(), f"{f} differs from the golden"


def test_c_output_compiles_and_holds_the_stream(tmp_path):
    """The generated C array is the .bin byte for byte (compiled and dumped on the host)."""
    if shutil.which("gcc") is None:
        pytest.skip("no gcc")
    r = run(SLAVE, "-o", tmp_path / "s.bin", "--c-dir", tmp_path, "--name", "s")
    assert r.returncode == 0, r.stderr
    main = tmp_path / "dump.c"
    main.write_text('#include <stdio.h>\n#include "s_cdcf.h"\n'
                    "int main(void) { fwrite(s_cdcf, 1, S_CDCF_SIZE, stdout); return 0; }\n")
    exe = tmp_path / "dump"
    c = subprocess.run(["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-I", str(tmp_path),
                        str(main), str(tmp_path / "s_cdcf.c"), "-o", str(exe)],
                       capture_output=True, text=True)
    assert c.returncode == 0, c.stderr
    out = subprocess.run([str(exe)], capture_output=True, check=True).stdout
    assert out == (tmp_path / "s.bin").read_bytes()


# --------------------------------------------------------------------------------------
# Which entries, in which order


def test_entries_and_layout_of_the_stream():
    """Writable objects with a ParameterValue only; CiA 302 §6.2 layout, little endian."""
    entries = cdcf.generate(SLAVE)
    blob = cdcf.encode(entries)
    n, = struct.unpack_from("<I", blob, 0)
    assert n == len(entries)
    # First entry by hand: 1017h:00, 2 bytes, 100 ms.
    assert blob[4:4 + 9] == bytes([0x17, 0x10, 0x00, 2, 0, 0, 0, 0x64, 0x00])
    d = by_key(entries)
    assert d[(0x2000, 0)] == (0x12345678).to_bytes(4, "little")
    assert d[(0x2001, 0)] == b"configured by the manager"
    assert d[(0x2003, 0)] == (-1234).to_bytes(2, "little", signed=True)
    # $NODEID resolved with the DCF's NodeID (0x22).
    assert d[(0x1400, 1)] == (0x222).to_bytes(4, "little")
    # Read-only objects and those without ParameterValue are left out.
    assert (0x1000, 0) not in d and (0x1018, 1) not in d and (0x2004, 0) not in d
    assert (0x1800, 4) not in d
    assert len(blob) == 4 + sum(7 + len(e.data) for e in entries)


def test_pdo_remap_order():
    """Disable (bit 31), parameters, count 0, entries, count n, enable (CiA 302 §6.2)."""
    k = keys(cdcf.generate(SLAVE))
    d = cdcf.generate(SLAVE)
    tpdo = [e for e in d if e.index in (0x1800, 0x1A00)]
    assert keys(tpdo) == [(0x1800, 1), (0x1800, 2), (0x1800, 3), (0x1800, 5), (0x1A00, 0),
                          (0x1A00, 1), (0x1A00, 2), (0x1A00, 0), (0x1800, 1)]
    assert tpdo[0].data == (0x800001A2).to_bytes(4, "little")
    assert tpdo[4].data == b"\x00"
    assert tpdo[7].data == b"\x02"
    assert tpdo[-1].data == (0x1A2).to_bytes(4, "little")
    rpdo = [x for x in k if x[0] in (0x1400, 0x1600)]
    assert rpdo == [(0x1400, 1), (0x1400, 2), (0x1600, 0), (0x1600, 1), (0x1600, 2),
                    (0x1600, 0), (0x1400, 1)]
    # Objects in index order around the PDO blocks.
    assert k.index((0x1020, 2)) < k.index((0x1400, 1)) < k.index((0x1800, 1)) \
        < k.index((0x2000, 0))


def test_mapping_alone_still_disables_the_pdo(tmp_path):
    """A remap without a new COB-ID disables and re-enables with the DCF's COB-ID."""
    p, _ = edit(tmp_path, [("1800sub1", "ParameterValue", None),
                           ("1800sub2", "ParameterValue", None),
                           ("1800sub3", "ParameterValue", None),
                           ("1800sub5", "ParameterValue", None)])
    tpdo = [e for e in cdcf.generate(p) if e.index in (0x1800, 0x1A00)]
    assert keys(tpdo)[0] == (0x1800, 1) and keys(tpdo)[-1] == (0x1800, 1)
    assert tpdo[0].data == (0x800001A2).to_bytes(4, "little")  # DefaultValue $NODEID+0x180
    assert tpdo[-1].data == (0x1A2).to_bytes(4, "little")


def test_disabled_pdo_is_written_once(tmp_path):
    """A COB-ID configured invalid is the first write and is not re-enabled."""
    p, _ = edit(tmp_path, [("1800sub1", "ParameterValue", "0x800001A2")])
    tpdo = [e for e in cdcf.generate(p) if e.index in (0x1800, 0x1A00)]
    cob = [e for e in tpdo if (e.index, e.sub) == (0x1800, 1)]
    assert len(cob) == 1 and keys(tpdo)[0] == (0x1800, 1)


def test_defaults_option_adds_writable_defaults(tmp_path):
    without = by_key(cdcf.generate(SLAVE))
    with_d = by_key(cdcf.generate(SLAVE, defaults=True))
    # 1800h:04 (rw, DefaultValue only) joins; read-only objects still do not.
    assert (0x1800, 4) not in without and with_d[(0x1800, 4)] == b"\x00"
    assert (0x2004, 0) not in with_d and (0x1018, 1) not in with_d
    r = run(SLAVE, "--defaults", "--list")
    assert r.returncode == 0 and "1800:04" in r.stdout


def test_save_option_and_node_id_override():
    e = cdcf.generate(SLAVE, node_id=5, save=True)
    assert keys(e)[-1] == (0x1010, 1) and e[-1].data == b"save"
    assert by_key(e)[(0x1400, 1)] == (0x205).to_bytes(4, "little")


def test_command_objects_are_never_sent(tmp_path):
    """1010h/1011h signatures in a DCF are not configuration (only --save adds 1010h)."""
    text = open(SLAVE, encoding="utf-8").read()
    extra = ("\n[1010]\nParameterName=Store parameters\nObjectType=0x8\nSubNumber=2\n"
             "\n[1010sub0]\nParameterName=n\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\n"
             "DefaultValue=1\nPDOMapping=0\n"
             "\n[1010sub1]\nParameterName=all\nObjectType=0x7\nDataType=0x0007\n"
             "AccessType=rw\nDefaultValue=1\nParameterValue=0x65766173\nPDOMapping=0\n")
    text = text.replace("[OptionalObjects]\nSupportedObjects=6\n",
                        "[OptionalObjects]\nSupportedObjects=7\n7=0x1010\n") + extra
    p = tmp_path / "cmd.dcf"
    p.write_text(text)
    assert (0x1010, 1) not in by_key(cdcf.generate(p))


# --------------------------------------------------------------------------------------
# Errors as file:line: message


def error_lines(r):
    assert r.returncode == 1
    return [m for m in r.stderr.splitlines() if m]


def test_error_mapping_count_without_entries(tmp_path):
    p, lines = edit(tmp_path, [("1A00sub0", "ParameterValue", "3")])
    errs = error_lines(run(p))
    assert errs == [f"{p}:{lines[('1A00sub0', 'ParameterValue')]}: TPDO 1: 1A00h:0 = 3 but "
                    "1A00h:3 has no ParameterValue"]


def test_error_mapping_of_a_missing_object(tmp_path):
    p, lines = edit(tmp_path, [("1600sub2", "ParameterValue", "0x30000008")])
    errs = error_lines(run(p))
    assert errs == [f"{p}:{lines[('1600sub2', 'ParameterValue')]}: 1600h:2: maps 3000h:0, "
                    "which the DCF does not have"]


def test_error_mapping_length(tmp_path):
    p, lines = edit(tmp_path, [("1A00sub1", "ParameterValue", "0x20030020")])
    errs = error_lines(run(p))
    assert errs == [f"{p}:{lines[('1A00sub1', 'ParameterValue')]}: 1A00h:1: maps 2003h:0 with "
                    "32 bits, but it is INTEGER16 (16 bits)"]


def test_error_nodeid_value_without_node_id(tmp_path):
    p, lines = edit(tmp_path, [("DeviceComissioning", "NodeID", None)])
    errs = error_lines(run(p))
    line = next(i for i, t in enumerate(open(p).read().split("\n"), 1)
                if t == "ParameterValue=$NODEID+0x200")
    assert f"{p}:{line}: 1400h:1: $NODEID value but no node-ID (give [DeviceComissioning] " \
           "NodeID or --node-id)" in errs
    assert run(p, "--node-id", "0x22").returncode == 0


def test_error_from_the_dcf_reader(tmp_path):
    """The eds2od reader's lint errors come through with their lines."""
    p, lines = edit(tmp_path, [("2002", "ParameterValue", "300")])
    errs = error_lines(run(p))
    assert errs == [f"{p}:{lines[('2002', 'ParameterValue')]}: 2002h: ParameterValue 300 out "
                    "of range for UNSIGNED8 (0..255)"]


def test_error_value_above_high_limit(tmp_path):
    p, lines = edit(tmp_path, [("2002", "ParameterValue", "101")])
    errs = error_lines(run(p))
    assert errs == [f"{p}:{lines[('2002', 'ParameterValue')]}: Gain: value 0x65 above "
                    "HighLimit 0x64"]


def test_error_missing_file(tmp_path):
    r = run(tmp_path / "nope.dcf")
    assert r.returncode == 1 and r.stderr.startswith(f"{tmp_path / 'nope.dcf'}: ")


# --------------------------------------------------------------------------------------
# Decoding


def test_round_trip_decode_of_the_generated_stream(tmp_path):
    entries = cdcf.generate(SLAVE)
    assert cdcf.decode(cdcf.encode(entries)) == [(e.index, e.sub, e.data) for e in entries]
    r = run(SLAVE, "-o", tmp_path / "s.bin")
    assert r.returncode == 0
    d = run("--decode", tmp_path / "s.bin")
    assert d.returncode == 0
    assert d.stdout.splitlines()[0] == f"{len(entries)} entries"
    assert d.stdout.splitlines()[1].startswith("1017:00    2 64 00")


def test_round_trip_random_streams():
    rnd = random.Random(302)
    for _ in range(200):
        ents = [(rnd.randrange(0x10000), rnd.randrange(0x100),
                 bytes(rnd.randrange(256) for _ in range(rnd.choice([0, 1, 2, 4, 7, 30]))))
                for _ in range(rnd.randrange(12))]
        assert cdcf.decode(cdcf.encode(ents)) == ents


@pytest.mark.parametrize("cut,msg", [
    (lambda b: b[:3], "shorter than its 4-byte count"),
    (lambda b: b[:-1], "data bytes"),
    (lambda b: b[:4 + 5], "header truncated"),
    (lambda b: b + b"\x00", "1 bytes after the last"),
    (lambda b: struct.pack("<I", struct.unpack_from("<I", b)[0] + 1) + b[4:], "header truncated"),
])
def test_decode_rejects_malformed_streams(cut, msg, tmp_path):
    blob = cut(cdcf.encode(cdcf.generate(SLAVE)))
    with pytest.raises(ValueError, match=msg):
        cdcf.decode(blob)
    (tmp_path / "bad.bin").write_bytes(blob)
    r = run("--decode", tmp_path / "bad.bin")
    assert r.returncode == 1 and "malformed concise DCF" in r.stderr


# --------------------------------------------------------------------------------------
# Agreement with lely's dcfgen (dcf-tools)

DCFGEN_YAML = """\
master:
  node_id: 1
slave:
  dcf: slave.eds
  node_id: 0x22
  heartbeat_producer: 100
  rpdo:
    1:
      cob_id: 0x222
      transmission: 1
      mapping:
        - {index: 0x2000, sub_index: 0}
        - {index: 0x2003, sub_index: 0}
  tpdo:
    1:
      cob_id: 0x1A2
      transmission: 254
      inhibit_time: 50
      event_timer: 500
      mapping:
        - {index: 0x2003, sub_index: 0}
        - {index: 0x2000, sub_index: 0}
  sdo:
    - {index: 0x1020, sub_index: 1, value: 15000}
    - {index: 0x1020, sub_index: 2, value: 3600000}
    - {index: 0x2000, sub_index: 0, value: 0x12345678}
    - {index: 0x2002, sub_index: 0, value: 42}
    - {index: 0x2003, sub_index: 0, value: -1234}
"""


def test_same_stream_as_lely_dcfgen(tmp_path):
    """dcfgen, told in YAML what slave.dcf says with ParameterValue, emits the same entries;
    the PDO blocks byte for byte in the same order."""
    dcfgen = shutil.which("dcfgen")
    if dcfgen is None:
        pytest.skip("dcf-tools (dcfgen) is not installed")
    # dcfgen reads the slave's EDS (its current values) and the wanted values from YAML.
    rows = [r for r in open(SLAVE, encoding="utf-8").read().split("\n")
            if not r.startswith("ParameterValue=")]
    (tmp_path / "slave.eds").write_text("\n".join(rows))
    (tmp_path / "cfg.yml").write_text(DCFGEN_YAML)
    (tmp_path / "out").mkdir()
    # -S: SafeLineSize (our key) is unknown to lely's linter.
    r = subprocess.run([dcfgen, "-S", "-d", "out", "cfg.yml"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    theirs = cdcf.decode((tmp_path / "out" / "slave.bin").read_bytes())
    ours = [(e.index, e.sub, e.data) for e in cdcf.generate(SLAVE)]
    # dcfgen's YAML has no strings: 2001h is ours alone.
    ours = [e for e in ours if e[0] != 0x2001]

    def pdo(s):
        return [e for e in s if 0x1400 <= e[0] <= 0x1BFF]

    assert pdo(ours) == pdo(theirs)
    assert sorted(ours) == sorted(theirs)
