# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""scripts/srdo-sign: the signatures it writes, the lines it touches (and only those), --check,
every refusal with its file:line, the command line, and lely's dcfchk on a signed DCF."""

import difflib
import os
import shutil
import subprocess

import pytest

from srdo_sign_testlib import (app_array, device, key_line, run, section_line, srdo_comm,
                               srdo_map, srdo_signatures, srdo_valid, values)

# The published vectors (test_signature.py) as SRDOs: SRDO 1 is a producer of node 1 on the
# default COB-IDs (vector A, 0xB218), SRDO 2 the safety scanner's example on 111h/112h
# (0x4370); SRDO 3 is disabled and keeps whatever 13FFh:3 holds.
WANT = {1: 0xB218, 2: 0x4370}
APP = (app_array(0x6010, 2) + app_array(0x6011, 2) + app_array(0x6200, 1) +
       app_array(0x6201, 1))
DISABLED_SIG = 0x1234


def body(key="ParameterValue", sig_key=None, valid_key=None, sig=None, valid=None,
         comm1=None):
    """The SRDOs with their values under `key` (DefaultValue, or ParameterValue for a DCF),
    13FFh and 13FEh under sig_key/valid_key (default: `key`)."""
    b = comm1 if comm1 is not None else srdo_comm(1, 1, 25, 20, 254, 0xFF, 0x100, key=key)
    b += srdo_map(1, [0x62000108, 0x62010108], key=key)
    b += srdo_comm(2, 2, 50, 20, 254, 0x111, 0x112, key=key)
    b += srdo_map(2, [0x60100108, 0x60110108, 0x60100208, 0x60110208], key=key)
    b += srdo_comm(3, 0, 0, 0, 0, 0, 0, key=key) + srdo_map(3, [], key=key)
    b += sig if sig is not None else srdo_signatures(3, {3: DISABLED_SIG}, key=sig_key or key)
    b += valid if valid is not None else srdo_valid(key=valid_key or key)
    return b + APP


def vector_b(key="ParameterValue", cob1=0x103, cob2=0x104):
    """Only vector B: SRDO 1 consumes 6200h:1/6201h:1 (16 bits) of node 2 on 103h/104h."""
    b = srdo_comm(1, 2, 50, 20, 254, cob1, cob2, key=key)
    b += srdo_map(1, [0x62000110, 0x62010110], key=key)
    b += srdo_signatures(1, key=key) + srdo_valid(key=key)
    return b + app_array(0x6200, 1, "0x0006") + app_array(0x6201, 1, "0x0006")


def write(tmp_path, text, name="dev.dcf", newline="\n"):
    p = tmp_path / name
    p.write_bytes(text.replace("\n", newline).encode("utf-8"))
    return p


def changed_lines(old: bytes, new: bytes):
    """[(tag, old lines, new lines)] of the differences, line ends included."""
    a, b = old.decode().splitlines(True), new.decode().splitlines(True)
    sm = difflib.SequenceMatcher(a=a, b=b, autojunk=False)
    return [(tag, a[i1:i2], b[j1:j2]) for tag, i1, i2, j1, j2 in sm.get_opcodes()
            if tag != "equal"]


def assert_refused(r, path, line, message, before: bytes):
    assert r.returncode == 1, r.stdout + r.stderr
    assert f"{path}:{line}: " in r.stderr and message in r.stderr, \
        f"want {path}:{line}: ... {message}, got:\n{r.stderr}"
    line_of_msg = next(ln for ln in r.stderr.splitlines() if message in ln)
    assert line_of_msg.startswith(f"{path}:{line}: "), line_of_msg
    assert "nothing written" in r.stderr
    assert path.read_bytes() == before


# --------------------------------------------------------------------------------------
# What is written


def test_dcf_signatures(tmp_path):
    p = write(tmp_path, device(body(), node_id=1))
    r = run(p)
    assert r.returncode == 0, r.stderr
    sig = values(p, 0x13FF)
    assert {n: sig[n] for n in WANT} == WANT
    assert sig[3] == DISABLED_SIG
    assert values(p, 0x13FE)[0] == 0xA5
    assert "13FFh:1 = 0xB218" in r.stdout and "13FEh = 0xA5" in r.stdout


def test_vector_b(tmp_path):
    p = write(tmp_path, device(vector_b()))
    r = run(p)
    assert r.returncode == 0, r.stderr
    assert values(p, 0x13FF)[1] == 0x0172


def test_node_id_option_for_default_cobids(tmp_path):
    """Vector B again, now on SRDO 1's default COB-IDs of node 2; --node-id wins over the
    DCF's NodeID."""
    p = write(tmp_path, device(vector_b(cob1=0xFF, cob2=0x100), node_id=5))
    r = run(p, "--node-id", "2")
    assert r.returncode == 0, r.stderr
    assert values(p, 0x13FF)[1] == 0x0172
    assert values(p, 0x1301)[5] == 0xFF, "the bare default stays in the file"


def test_dcf_node_id_for_default_cobids(tmp_path):
    p = write(tmp_path, device(vector_b(cob1=0xFF, cob2=0x100), node_id=2))
    assert run(p).returncode == 0
    assert values(p, 0x13FF)[1] == 0x0172


def test_only_the_value_lines_change(tmp_path):
    """A DCF with ParameterValue: exactly the three value lines are replaced."""
    text = device(body(), node_id=1)
    p = write(tmp_path, text)
    before = p.read_bytes()
    assert run(p).returncode == 0
    diff = changed_lines(before, p.read_bytes())
    assert diff == [
        ("replace", ["ParameterValue=0x0000\n"], ["ParameterValue=0xB218\n"]),
        ("replace", ["ParameterValue=0x0000\n"], ["ParameterValue=0x4370\n"]),
        ("replace", ["ParameterValue=0x00\n"], ["ParameterValue=0xA5\n"]),
    ]
    old, new = before.decode().splitlines(), p.read_bytes().decode().splitlines()
    assert len(old) == len(new)
    changed = [n for n, (a, b) in enumerate(zip(old, new), 1) if a != b]
    assert changed == [key_line(text, "13FFsub1", "ParameterValue"),
                       key_line(text, "13FFsub2", "ParameterValue"),
                       key_line(text, "13FE", "ParameterValue")]


def test_dcf_with_only_default_values_gets_parameter_values(tmp_path):
    """A DCF whose 13FFh/13FEh have only a DefaultValue: a ParameterValue line is added right
    after it; the DefaultValue (the device's default) stays."""
    text = device(body(sig_key="DefaultValue", valid_key="DefaultValue"), node_id=1)
    p = write(tmp_path, text)
    before = p.read_bytes()
    assert run(p).returncode == 0
    new = p.read_bytes().decode().splitlines()
    for sec, want in (("13FFsub1", "0xB218"), ("13FFsub2", "0x4370"), ("13FE", "0xA5")):
        at = key_line(text, sec, "DefaultValue")  # 1-based, in the old file
        shift = sum(1 for s in ("13FFsub1", "13FFsub2", "13FE")
                    if key_line(text, s, "DefaultValue") < at)
        assert new[at - 1 + shift] == text.splitlines()[at - 1]
        assert new[at + shift] == f"ParameterValue={want}"
    assert [tag for tag, _, _ in changed_lines(before, p.read_bytes())] == ["insert"] * 3
    assert values(p, 0x13FF)[1] == 0xB218


def test_eds_gets_default_values(tmp_path):
    """An EDS (no [DeviceComissioning], .eds) has its DefaultValue replaced."""
    text = device(body(key="DefaultValue", comm1=srdo_comm(1, 1, 25, 20, 254, 0x101, 0x102,
                                                           key="DefaultValue")))
    p = write(tmp_path, text, "dev.eds")
    before = p.read_bytes()
    r = run(p)
    assert r.returncode == 0, r.stderr
    assert changed_lines(before, p.read_bytes()) == [
        ("replace", ["DefaultValue=0x0000\n"], ["DefaultValue=0xB218\n"]),
        ("replace", ["DefaultValue=0x0000\n"], ["DefaultValue=0x4370\n"]),
        ("replace", ["DefaultValue=0x00\n"], ["DefaultValue=0xA5\n"]),
    ]


def test_eds_without_values_gets_default_values(tmp_path):
    """rw signatures without any value: a DefaultValue line is added at the section's end."""
    sig = srdo_signatures(3).replace("DefaultValue=0x0000\n", "")
    comm1 = srdo_comm(1, 1, 25, 20, 254, 0x101, 0x102, key="DefaultValue")
    p = write(tmp_path, device(body(key="DefaultValue", sig=sig, comm1=comm1)), "dev.eds")
    r = run(p)
    assert r.returncode == 0, r.stderr
    got = values(p, 0x13FF)
    assert (got[1], got[2], got[3]) == (0xB218, 0x4370, None)
    assert "PDOMapping=0\nDefaultValue=0xB218\n\n[13FFsub2]" in p.read_text()


def test_compact_signatures_get_a_value_section(tmp_path):
    sig = ("[13FF]\nParameterName=Safety configuration signature\nObjectType=0x8\n"
           "DataType=0x0006\nAccessType=rw\nDefaultValue=0\nPDOMapping=0\nCompactSubObj=3\n\n")
    p = write(tmp_path, device(body(sig=sig), node_id=1))
    r = run(p)
    assert r.returncode == 0, r.stderr
    assert ("CompactSubObj=3\n\n[13FFValue]\nNrOfEntries=2\n1=0xB218\n2=0x4370\n\n"
            in p.read_text())
    assert values(p, 0x13FF)[1] == 0xB218
    assert run(p, "--check").returncode == 0


def test_compact_signatures_value_section_updated(tmp_path):
    sig = ("[13FF]\nParameterName=Safety configuration signature\nObjectType=0x8\n"
           "DataType=0x0006\nAccessType=rw\nDefaultValue=0\nPDOMapping=0\nCompactSubObj=3\n\n"
           "[13FFValue]\nNrOfEntries=1\n1=0x0001\n\n")
    p = write(tmp_path, device(body(sig=sig), node_id=1))
    assert run(p).returncode == 0
    assert "[13FFValue]\nNrOfEntries=2\n1=0xB218\n2=0x4370\n\n" in p.read_text()


def test_crlf_comments_and_spacing_kept(tmp_path):
    text = device(body(), node_id=1).replace(
        "[13FFsub1]\nParameterName=SRDO 1 signature\nObjectType=0x7\nDataType=0x0006\n"
        "AccessType=rw\nDefaultValue=0\nParameterValue=0x0000\n",
        "[13FFsub1]\nParameterName=SRDO 1 signature\nObjectType=0x7\nDataType=0x0006\n"
        "AccessType=rw\nDefaultValue=0\nParameterValue = 0x0000   ; signed by srdo-sign\n")
    p = write(tmp_path, text, newline="\r\n")
    before = p.read_bytes()
    assert run(p).returncode == 0
    diff = changed_lines(before, p.read_bytes())
    assert diff[0] == ("replace", ["ParameterValue = 0x0000   ; signed by srdo-sign\r\n"],
                       ["ParameterValue = 0xB218   ; signed by srdo-sign\r\n"])
    assert len(diff) == 3 and b"\r\n" in p.read_bytes() and b"\r\r" not in p.read_bytes()


def test_twice_changes_nothing(tmp_path):
    for key in ("ParameterValue", "DefaultValue"):
        p = write(tmp_path, device(body(sig_key=key, valid_key=key), node_id=1))
        assert run(p).returncode == 0
        once = p.read_bytes()
        r = run(p)
        assert r.returncode == 0, r.stderr
        assert p.read_bytes() == once
        assert f"{p}: unchanged" in r.stdout


def test_output_elsewhere(tmp_path):
    p = write(tmp_path, device(body(), node_id=1))
    before = p.read_bytes()
    out = tmp_path / "signed" / "dev.dcf"
    out.parent.mkdir()
    r = run(p, "-o", out)
    assert r.returncode == 0, r.stderr
    assert p.read_bytes() == before
    assert values(out, 0x13FF)[1] == 0xB218
    assert sorted(os.listdir(tmp_path / "signed")) == ["dev.dcf"]


# --------------------------------------------------------------------------------------
# --check


def test_check_before_and_after_signing(tmp_path):
    text = device(body(), node_id=1)
    p = write(tmp_path, text)
    r = run(p, "--check")
    assert r.returncode == 1
    assert (f"{p}:{key_line(text, '13FFsub1', 'ParameterValue')}: 13FFh:1 holds 0x0000, not "
            "0xB218" in r.stderr)
    assert f"{p}:{key_line(text, '13FE', 'ParameterValue')}: 13FEh holds 0x00, not 0xA5" \
        in r.stderr
    assert "13FFh:3" not in r.stderr, "a disabled SRDO has no signature to check"
    assert p.read_text() == text
    assert run(p).returncode == 0
    signed = p.read_bytes()
    r = run(p, "--check")
    assert r.returncode == 0, r.stderr
    assert p.read_bytes() == signed
    assert sorted(os.listdir(tmp_path)) == ["dev.dcf"]


@pytest.mark.parametrize("sec,old,new,srdo", [
    ("1302sub2", "ParameterValue=0x32", "ParameterValue=0x33", 2),      # SCT
    ("1302sub3", "ParameterValue=0x14", "ParameterValue=0x15", 2),      # SRVT
    ("1301sub1", "ParameterValue=0x1", "ParameterValue=0x2", 1),        # direction
    ("1382sub3", "ParameterValue=0x60100208", "ParameterValue=0x60100108", 2),  # an entry
])
def test_check_fails_after_editing_a_covered_field(tmp_path, sec, old, new, srdo):
    p = write(tmp_path, device(body(), node_id=1))
    assert run(p).returncode == 0
    text = p.read_text()
    at = key_line(text, sec, old.split("=")[0])
    rows = text.split("\n")
    assert rows[at - 1] == old
    rows[at - 1] = new
    p.write_text("\n".join(rows))
    r = run(p, "--check")
    assert r.returncode == 1, r.stderr
    assert f"13FFh:{srdo} holds 0x{WANT[srdo]:04X}, not " in r.stderr
    assert f"{p}:{key_line(text, f'13FFsub{srdo}', 'ParameterValue')}: " in r.stderr


def test_check_fails_after_a_node_id_change(tmp_path):
    """SRDO 1 on the default COB-IDs: another node-ID is another signature."""
    p = write(tmp_path, device(body(), node_id=1))
    assert run(p).returncode == 0
    assert run(p, "--check").returncode == 0
    assert run(p, "--check", "--node-id", "1").returncode == 0
    r = run(p, "--check", "--node-id", "2")
    assert r.returncode == 1 and "13FFh:1 holds 0xB218" in r.stderr
    assert "13FFh:2" not in r.stderr


def test_check_fails_when_13fe_is_cleared(tmp_path):
    p = write(tmp_path, device(body(), node_id=1))
    assert run(p).returncode == 0
    text = p.read_text()
    at = key_line(text, "13FE", "ParameterValue")
    rows = text.split("\n")
    rows[at - 1] = "ParameterValue=0"
    p.write_text("\n".join(rows))
    r = run(p, "--check")
    assert r.returncode == 1
    assert f"{p}:{at}: 13FEh holds 0x00, not 0xA5" in r.stderr


# --------------------------------------------------------------------------------------
# Refusals: file:line: message, exit 1, nothing written


def test_refuses_a_lint_error(tmp_path):
    text = device(body(comm1=srdo_comm(1, 1, 25, 20, 253, 0xFF, 0x100, key="ParameterValue")),
                  node_id=1)
    p = write(tmp_path, text)
    r = run(p)
    assert_refused(r, p, key_line(text, "1301sub4", "ParameterValue"),
                   "SRDO 1 transmission type 253; an SRDO has 254 only", p.read_bytes())


def test_check_refuses_a_lint_error(tmp_path):
    text = device(body(comm1=srdo_comm(1, 1, 25, 20, 254, 0x101, 0x104, key="ParameterValue")))
    p = write(tmp_path, text)
    r = run(p, "--check")
    assert r.returncode == 1
    assert f"{p}:{key_line(text, '1301sub6', 'ParameterValue')}: 1301h:6: SRDO 1 COB-ID 2 " \
           "0x104 must be 0x102" in r.stderr


def test_refuses_without_signature_object(tmp_path):
    text = device(body(sig=""), node_id=1)
    p = write(tmp_path, text)
    assert_refused(run(p), p, section_line(text, "1301"),
                   "SRDO 1 needs its signature in 13FFh:1, but the file has no object 13FFh",
                   p.read_bytes())


def test_refuses_without_valid_object(tmp_path):
    text = device(body(valid=""), node_id=1)
    p = write(tmp_path, text)
    assert_refused(run(p), p, section_line(text, "1301"),
                   "the file has no object 13FEh (configuration valid, UNSIGNED8)",
                   p.read_bytes())


def test_refuses_default_cobids_without_node_id(tmp_path):
    text = device(body())
    p = write(tmp_path, text)
    assert_refused(run(p), p, key_line(text, "1301sub5", "ParameterValue"),
                   "SRDO 1 uses the default COB-IDs 0xFF/0x100, which follow the node-ID "
                   "(0xFF + 2 x node-ID): give --node-id or [DeviceComissioning] NodeID",
                   p.read_bytes())
    assert "--node-id" in run(p, "--check").stderr


def test_refuses_default_cobids_with_node_id_above_64(tmp_path):
    text = device(body())
    p = write(tmp_path, text)
    assert_refused(run(p, "--node-id", "65"), p, key_line(text, "1301sub5", "ParameterValue"),
                   "which need a node-ID 1..64, not 65", p.read_bytes())


def test_refuses_a_dcf_node_id_above_64_with_default_cobids(tmp_path):
    text = device(body(), node_id=100)
    p = write(tmp_path, text)
    assert_refused(run(p), p, key_line(text, "1301sub5", "ParameterValue"),
                   "must be 1..64; NodeID is 100", p.read_bytes())


def test_refuses_a_file_without_srdo(tmp_path):
    text = device(srdo_signatures(1) + srdo_valid())
    p = write(tmp_path, text)
    assert_refused(run(p), p, 1, "no SRDO (1301h..1340h with its mapping 1381h..13C0h): "
                                 "nothing to sign", p.read_bytes())


def test_refuses_when_the_signed_file_would_not_check(tmp_path):
    """A HighLimit that keeps 13FEh from holding A5h: the result is linted before writing."""
    valid = srdo_valid(key="ParameterValue").replace("PDOMapping=0", "PDOMapping=0\n"
                                                     "HighLimit=0x10")
    text = device(body(valid=valid), node_id=1)
    p = write(tmp_path, text)
    assert_refused(run(p), p, key_line(text, "13FE", "ParameterValue"),
                   "Configuration valid: value 0xa5 above HighLimit 0x10 (in the signed file)",
                   p.read_bytes())


# --------------------------------------------------------------------------------------
# Command line


@pytest.mark.parametrize("args", [[], ["--node-id", "abc", "F.dcf"], ["--node-id", "0", "F.dcf"],
                                  ["--node-id", "128", "F.dcf"], ["--bogus", "F.dcf"],
                                  ["--check", "-o", "out.dcf", "F.dcf"], ["a.dcf", "b.dcf"]])
def test_usage_errors(tmp_path, args):
    r = run(*args)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("usage: srdo-sign")


def test_unreadable_input(tmp_path):
    r = run(tmp_path / "missing.dcf")
    assert r.returncode == 2
    assert f"srdo-sign: {tmp_path / 'missing.dcf'}: No such file or directory" in r.stderr


def test_help():
    r = run("--help")
    assert r.returncode == 0 and "--node-id" in r.stdout and "--check" in r.stdout


def test_script_is_executable():
    from srdo_sign_testlib import SRDO_SIGN

    assert os.access(SRDO_SIGN, os.X_OK)


# --------------------------------------------------------------------------------------
# lely's dcfchk (dcf-tools, scripts/requirements.txt)


def test_lely_dcfchk_accepts_a_signed_dcf(tmp_path):
    dcfchk = shutil.which("dcfchk")
    if dcfchk is None:
        pytest.skip("dcf-tools (dcfchk) is not installed (scripts/setup installs it)")
    p = write(tmp_path, device(body(sig_key="DefaultValue"), node_id=1))
    assert run(p).returncode == 0
    r = subprocess.run([dcfchk, str(p)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stderr == ""
