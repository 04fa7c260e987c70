# SPDX-License-Identifier: Apache-2.0
"""The CANopen samples' options (samples/canopen/common, the manager's own) and --can-if: a bad
value or an unusable interface ends the process before the node boots, with a non-zero exit code
and a message naming the option or the interface.

The samples are built here (SAFELINE_IMAGE is this folder's image), or taken from
SAFELINE_HELLO_NODE_IMAGE / SAFELINE_MANAGER_IMAGE when set."""

import os
import pathlib
import socket
import struct
import sys
from unittest import mock

import pytest

HERE = pathlib.Path(__file__).resolve().parent
SAMPLES = HERE.parents[3] / "samples" / "canopen"
sys.path.insert(0, str(HERE.parents[1] / "common"))

import safeline_image  # noqa: E402


def _build(name, tmp_path_factory):
    given = os.environ.get(f"SAFELINE_{name.upper()}_IMAGE")
    if given:
        return pathlib.Path(given)
    with mock.patch.dict(os.environ):
        os.environ.pop("SAFELINE_IMAGE", None)
        return safeline_image.image_path(SAMPLES / name, tmp_path_factory.mktemp(name))


@pytest.fixture(scope="session")
def hello_node(tmp_path_factory):
    return _build("hello_node", tmp_path_factory)


@pytest.fixture(scope="session")
def manager(tmp_path_factory):
    return _build("manager", tmp_path_factory)


def _run(image, *args):
    try:
        return safeline_image.run(image, *args, timeout=30)
    except Exception as exc:  # noqa: BLE001 - a hang is a failure like any other
        raise AssertionError(f"{args}: {exc}") from exc


def host_has_af_can():
    try:
        socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW).close()
    except (AttributeError, OSError):
        return False
    return True


def assert_refused(result, option, args):
    assert result.returncode != 0, f"{args}: exit code 0"
    assert result.returncode == 1, f"{args}: exit code {result.returncode}"
    assert "Booting" not in result.stdout, f"{args}: the firmware booted"
    assert " up on " not in result.stdout, f"{args}: the node booted"
    assert result.stdout.startswith("Usage:"), f"{args}: no usage on stdout"
    assert f"--{option}" in result.stderr, f"{args}: the error does not name --{option}"


@pytest.mark.parametrize("value", ["4294967295", " -18446744073709551615", "-18446744073709551615",
                                   "18446744073709551617", "0", "128", "200", "-1", "+16", "16x",
                                   "0x", "", "nan"])
def test_hello_node_refuses_bad_node_id(hello_node, value):
    args = (f"--node-id={value}", "--stop-at=2")
    assert_refused(_run(hello_node, *args), "node-id", args)


@pytest.mark.parametrize("value,node", [("1", 1), ("127", 127), ("0x7f", 127), ("017", 15)])
def test_hello_node_accepts_good_node_id(hello_node, value, node):
    result = _run(hello_node, f"--node-id={value}", "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert f"hello_node: node {node} up on can_virtual0" in result.stdout


def test_hello_node_default_runs_on_the_virtual_bus(hello_node):
    result = _run(hello_node, "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert "hello_node: node 16 up on can_virtual0" in result.stdout
    assert "Stopped at 0.300s" in result.stdout


@pytest.mark.parametrize("value", ["+0:vcan0", " 0:vcan0", "-0:vcan0", "0x:vcan0", "9:vcan0",
                                   "0:", "0", "vcan0", "0:an-interface-name-too-long"])
def test_can_if_refuses_malformed_values(hello_node, value):
    args = (f"--can-if={value}", "--stop-at=2")
    assert_refused(_run(hello_node, *args), "can-if", args)


def test_can_if_missing_interface_fails_before_the_node_boots(hello_node):
    result = _run(hello_node, "--can-if=0:nonexistent", "--stop-at=2")
    assert result.returncode != 0, "ran on the virtual bus instead"
    assert result.returncode == 1
    assert "nonexistent" in result.stderr, result.stderr
    assert "--can-if" in result.stderr
    assert "Booting" not in result.stdout
    assert " up on " not in result.stdout
    if not host_has_af_can():
        assert "SocketCAN not available on this host" in result.stderr
    else:
        assert "No such device" in result.stderr


@pytest.mark.skipif(host_has_af_can(), reason="the host has AF_CAN (vcan0 may exist)")
def test_can_if_without_af_can_fails_with_the_reason(hello_node):
    result = _run(hello_node, "--can-if=0:vcan0", "--stop-at=2")
    assert result.returncode == 1, "ran on the virtual bus instead"
    assert "vcan0" in result.stderr
    assert "SocketCAN not available on this host" in result.stderr
    assert "Booting" not in result.stdout


@pytest.mark.parametrize("args,option", [
    (("--slaves=5",), "slaves"),
    (("--slaves=4294967295",), "slaves"),
    (("--slaves=-1",), "slaves"),
    (("--slaves= -18446744073709551615",), "slaves"),
    (("--cycle=4294967295",), "cycle"),
    (("--cycle=128",), "cycle"),
    (("--cut=abc",), "cut"),
    (("--cut=4294967295",), "cut"),
    (("--node-id=4294967295",), "node-id"),
    (("--node-id=3",), "node-id"),
])
def test_manager_refuses_bad_options(manager, args, option):
    args = (*args, "--stop-at=2")
    assert_refused(_run(manager, *args), option, args)


def test_manager_good_options(manager):
    result = _run(manager, "--slaves=0", "--cycle=0", "--cut=0", "--node-id=0x7f",
                  "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert "manager: no slaves in this process" in result.stdout
    assert "manager: node 127 on can_virtual0" in result.stdout


# --- The manager's network from a DCF (--dcf) ---------------------------------------------------

def _network_dcf(path, node_id=None, slaves=(), mandatory=(), files=None, boot_time=2000,
                 extra=""):
    """A manager DCF of the network objects alone: hello_node identities for `slaves`, hex keys
    in [xxxxValue] for even node-IDs and decimal keys for odd ones (CiA 306 allows both)."""
    def key(n):
        return f"0x{n:X}" if n % 2 == 0 else str(n)

    # CiA 306's mandatory objects (the manager reads a DCF with scripts/eds2od's rules).
    lines = ["[1000]", "ParameterValue=0", "", "[1001]", "ParameterValue=0", "", "[1018]",
             "SubNumber=1", ""]
    if node_id is not None:
        lines += ["[DeviceComissioning]", f"NodeID=0x{node_id:02X}", ""]
    lines += ["[1F80]", "ParameterValue=0x00000001", "", "[1F89]", f"ParameterValue={boot_time}", ""]
    for index, value in (("1F81", None), ("1F85", 0x539), ("1F86", 1), ("1F87", 0x10000)):
        lines += [f"[{index}]", "ObjectType=0x8", "CompactSubObj=127", "DataType=0x0007",
                  "AccessType=rw", "DefaultValue=0", "", f"[{index}Value]",
                  f"NrOfEntries={len(slaves)}"]
        for n in slaves:
            v = (0x0D if n in mandatory else 0x05) if value is None else value
            lines.append(f"{key(n)}=0x{v:08X}")
        lines.append("")
    lines += ["[1016]", "SubNumber=9", ""]
    for i, n in enumerate(slaves[:8], 1):
        lines += [f"[1016sub{i}]", "DataType=0x0007", f"ParameterValue=0x00{n:02X}012C", ""]
    if files:
        lines += ["[1F22]", "ObjectType=0x8", "SubNumber=128", ""]
    for n, name in (files or {}).items():
        lines += [f"[1F22sub{n:X}]", "DataType=0x000F", f"UploadFile={name}", ""]
    path.write_text(extra + "\n".join(lines) + "\n")
    return path


def _slave_bin(manager):
    # The bundled concise DCF of hello_node (build/network/slave.bin, next to the image's build).
    return (manager.parent.parent / "network" / "slave.bin").read_bytes()


def test_manager_prints_events_during_the_boot(manager):
    result = _run(manager, "--stop-at=0.5", "--cycle=0", "--cut=0")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    table = out.index("  node  role ")
    # The startup's Reset Communication brings a boot-up from every slave before the table.
    for n in (2, 3, 4, 5):
        assert f"node {n:3d}  boot-up" in out[:table], out
    assert "node   5  boot failed: M" in out[:table], out


def test_manager_serves_another_network_from_its_dcf(manager, tmp_path):
    (tmp_path / "hello.bin").write_bytes(_slave_bin(manager))
    dcf = _network_dcf(tmp_path / "net.dcf", node_id=0x20, slaves=(0x30, 0x31, 0x7F),
                       mandatory=(0x30,), files={0x30: "hello.bin", 0x31: "hello.bin",
                                                 0x7F: str(tmp_path / "hello.bin")})
    result = _run(manager, f"--dcf={dcf}", "--stop-at=1", "--cycle=0", "--cut=0")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "manager: node 32 on can_virtual0" in out, out
    for n, line in ((48, 1), (49, 2), (127, 3)):
        assert f"manager: slave {n} (hello_node) on can_virtual{line}" in out, out
    assert "    48  mandatory  00000539  00000001  00010000  OK " in out, out
    assert "    49  optional   00000539  00000001  00010000  OK " in out, out
    assert "   127  optional   00000539  00000001  00010000  OK " in out, out
    assert "manager: NMT startup DONE" in out
    # The concise DCF from the named file set the heartbeat to 100 ms: the slaves report
    # Operational after the start.
    for n in (48, 49, 127):
        assert f"node {n:3d}  OPERATIONAL" in out, out


def test_manager_waits_for_the_dcf_slaves_it_does_not_run(manager, tmp_path):
    dcf = _network_dcf(tmp_path / "net.dcf", slaves=(7, 9), boot_time=300)
    result = _run(manager, f"--dcf={dcf}", "--slaves=1", "--stop-at=0.2")
    assert result.returncode == 0, result.stderr
    assert "manager: slave 7 (hello_node) on can_virtual1" in result.stdout
    assert "waiting for nodes 9 on the bus" in result.stdout, result.stdout
    assert "2..5" not in result.stdout


def test_manager_b_text_names_no_comparison(manager, tmp_path):
    # Mandatory node 64 is absent: B, and the startup halts after 1F89h = 300 ms.
    dcf = _network_dcf(tmp_path / "net.dcf", slaves=(64,), mandatory=(64,), boot_time=300)
    result = _run(manager, f"--dcf={dcf}", "--slaves=0", "--stop-at=1.5")
    assert result.returncode == 0, result.stderr
    halted = [l for l in result.stdout.splitlines() if "NMT startup HALTED" in l]
    assert halted and "node 64 failed with B" in halted[0], result.stdout
    assert "no answer to the 1000h upload" in result.stdout
    assert "expected 00000000 actual 00000000" not in result.stdout, result.stdout
    assert "expected" not in halted[0], halted[0]


def test_manager_j_text_names_the_entry_and_the_abort(manager, tmp_path):
    # A concise DCF that writes an object hello_node does not have: J at that entry.
    (tmp_path / "bad.bin").write_bytes(struct.pack("<IHBIB", 1, 0x5FFF, 0, 1, 7))
    dcf = _network_dcf(tmp_path / "net.dcf", slaves=(2,), files={2: "bad.bin"})
    result = _run(manager, f"--dcf={dcf}", "--stop-at=0.5", "--cycle=0", "--cut=0")
    assert result.returncode == 0, result.stderr
    rows = [l for l in result.stdout.splitlines() if l.startswith("     2  ")]
    assert rows and "  J  " in rows[0], result.stdout
    assert "step DOWNLOAD, 5FFFh:00, SDO abort 06020000" in rows[0], rows[0]
    assert "expected" not in rows[0], rows[0]


@pytest.mark.parametrize("case", ["missing", "key_outside", "bad_number", "nodeid_formula",
                                  "text_cdcf", "bad_cdcf", "missing_cdcf", "manager_is_slave",
                                  "too_many_slaves", "sub_too_high", "value_too_big"])
def test_manager_refuses_a_dcf_it_cannot_serve(manager, tmp_path, case):
    (tmp_path / "hello.bin").write_bytes(_slave_bin(manager))
    path = tmp_path / "net.dcf"
    expect = {"missing": "cannot open", "key_outside": "net.dcf:1: ",
              "bad_number": "is not an unsigned 32-bit number",
              "nodeid_formula": "$NODEID", "text_cdcf": "scripts/dcf2cdcf",
              "bad_cdcf": "is not a concise DCF", "missing_cdcf": "cannot open",
              "manager_is_slave": "net.dcf:25: node 1 is a slave of the network (1F81h "
                                  "assigns 1, 2)",
              "too_many_slaves": "net.dcf:33: 1F81h assigns 10 slaves (2, 3, 4, 5, 6, 7, 8, 9, "
                                 "10, 11); the manager has 8 slave slots",
              "sub_too_high": "[1F84Value]: sub-index 0x80 is not 1..127 (CompactSubObj=127)",
              "value_too_big": "refused by the manager's dictionary"}[case]
    if case == "missing":
        path = tmp_path / "nonexistent.dcf"
    elif case == "key_outside":
        _network_dcf(path, slaves=(2,), extra="NodeID=3\n")
    elif case == "bad_number":
        _network_dcf(path, slaves=(2,), boot_time="5000ms")
    elif case == "nodeid_formula":
        _network_dcf(path, slaves=(2,), boot_time="$NODEID+0x100")
    elif case == "text_cdcf":
        (tmp_path / "slave.dcf").write_text("[FileInfo]\nFileName=slave.dcf\n")
        _network_dcf(path, slaves=(2,), files={2: "slave.dcf"})
    elif case == "bad_cdcf":
        (tmp_path / "short.bin").write_bytes(struct.pack("<IHBI", 2, 0x1017, 0, 2) + b"\x64\x00")
        _network_dcf(path, slaves=(2,), files={2: "short.bin"})
    elif case == "missing_cdcf":
        _network_dcf(path, slaves=(2,), files={2: "absent.bin"})
    elif case == "manager_is_slave":
        _network_dcf(path, slaves=(1, 2))
    elif case == "too_many_slaves":
        _network_dcf(path, slaves=tuple(range(2, 12)))
    elif case == "sub_too_high":
        _network_dcf(path, slaves=(2,), extra="[1F84]\nCompactSubObj=127\n[1F84Value]\n0x80=1\n")
    elif case == "value_too_big":
        # 1F89h is fine, 1016h has 8 entries: a ninth one cannot be written.
        _network_dcf(path, slaves=(2,), extra="[1016sub9]\nParameterValue=0x0002012C\n")
    args = (f"--dcf={path}", "--stop-at=2")
    result = _run(manager, *args)
    assert_refused(result, "dcf", args)
    assert expect in result.stderr, result.stderr


def _edit(path, old, new, count=1):
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, count))


# Each damage the manager once took (issue 29): the rule of scripts/eds2od it breaks, with the
# message eds2od gives, FILE:LINE named.
@pytest.mark.parametrize("case,expect", [
    ("cut_in_a_value", "net.dcf:26: the file ends inside this line (no end of line)"),
    ("fewer_entries", "net.dcf:24: NrOfEntries=4 but [1F81Value] has 2 entries"),
    ("more_entries", "net.dcf:24: NrOfEntries=40 but [1F81Value] has 4 entries"),
    ("bad_nr_of_entries", "net.dcf:24: NrOfEntries=four is not a number"),
    ("duplicate_key", "net.dcf:15: duplicate key 'ParameterValue' in [1F89] (first at line 14)"),
    ("duplicate_section", "duplicate section [1F89] (first at line 13)"),
    ("duplicate_sub_section", "duplicate sub-index 1 of 1016h (first at line"),
    ("sub_given_twice", "net.dcf:27: [1F81Value]: sub-index 3 given twice (first at line 26)"),
    ("sub_not_hex", "[1016subZZ]: 'ZZ' is not a sub-index (one or two hex digits)"),
    ("sub_too_long", "[1016sub1FF]: '1FF' is not a sub-index (one or two hex digits)"),
    ("key_not_a_sub", "net.dcf:25: [1F81Value]: key 'two' is not a sub-index"),
    ("misspelt_section", "[1F85Valeu] is no object section"),
    ("value_without_object", "[1F84Value] has no object [1F84]"),
    ("sub_without_object", "sub-index section [1F22sub2] has no object [1F22]"),
    ("empty", "net.dcf:1: mandatory object 1000h (Device type) is missing; CiA 306 requires "
              "1000h, 1001h and 1018h in every EDS/DCF"),
    ("no_identity", "net.dcf:1: mandatory object 1018h (Identity object) is missing"),
    ("dev_null", "/dev/null: cannot open: not a regular file"),
    ("fifo", "net.dcf: cannot open: not a regular file"),
    ("fifo_upload", "1F22h:02: cannot open"),
])
def test_manager_reads_its_dcf_with_the_rules_of_eds2od(manager, tmp_path, case, expect):
    path = _network_dcf(tmp_path / "net.dcf", slaves=(2, 3, 4, 5), mandatory=(2, 3))
    if case == "cut_in_a_value":
        text = path.read_text()
        path.write_text(text[:text.index("3=0x0000000D") + len("3=0x00")])
    elif case == "fewer_entries":
        _edit(path, "0x4=0x00000005\n5=0x00000005\n", "")
    elif case == "more_entries":
        _edit(path, "NrOfEntries=4", "NrOfEntries=40")
    elif case == "bad_nr_of_entries":
        _edit(path, "NrOfEntries=4", "NrOfEntries=four")
    elif case == "duplicate_key":
        _edit(path, "ParameterValue=2000\n", "ParameterValue=2000\nParameterValue=100\n")
    elif case == "duplicate_section":
        path.write_text(path.read_text() + "[1F89]\nParameterValue=100\n")
    elif case == "duplicate_sub_section":
        path.write_text(path.read_text() + "[1016sub01]\nParameterValue=0\n")
    elif case == "sub_given_twice":
        _edit(path, "0x4=0x00000005\n", "0x3=0x00000005\n")
    elif case == "sub_not_hex":
        _edit(path, "[1016sub1]", "[1016subZZ]")
    elif case == "sub_too_long":
        _edit(path, "[1016sub1]", "[1016sub1FF]")
    elif case == "key_not_a_sub":
        _edit(path, "0x2=0x0000000D", "two=0x0000000D")
    elif case == "misspelt_section":
        _edit(path, "[1F85Value]", "[1F85Valeu]")
    elif case == "value_without_object":
        path.write_text(path.read_text() + "[1F84Value]\nNrOfEntries=0\n")
    elif case == "sub_without_object":
        path.write_text(path.read_text() + "[1F22sub2]\nUploadFile=hello.bin\n")
    elif case == "empty":
        path.write_text("")
    elif case == "no_identity":
        _edit(path, "[1018]\nSubNumber=1\n", "")
    elif case == "dev_null":
        path = pathlib.Path("/dev/null")
    elif case == "fifo":
        path.unlink()
        os.mkfifo(path)
    elif case == "fifo_upload":
        os.mkfifo(tmp_path / "hello.bin")
        _network_dcf(path, slaves=(2,), files={2: "hello.bin"})
    args = (f"--dcf={path}", "--stop-at=2")
    result = _run(manager, *args)
    assert_refused(result, "dcf", args)
    assert expect in result.stderr, result.stderr


@pytest.mark.parametrize("option", ["--dds-allow=none", "--dds-config=x.xml", "--dds-domain=7"])
def test_manager_refuses_dds_options_without_dds(manager, option):
    args = (option, "--stop-at=2")
    result = _run(manager, *args)
    assert_refused(result, option[2:option.index("=")], args)
    assert "needs --dds (the DDS bridge)" in result.stderr


def test_manager_refuses_a_node_id_of_the_dcf_network(manager, tmp_path):
    dcf = _network_dcf(tmp_path / "net.dcf", slaves=(0x30,))
    args = (f"--dcf={dcf}", "--node-id=0x30", "--stop-at=2")
    result = _run(manager, *args)
    assert_refused(result, "node-id", args)
    assert "node 48 is a slave of the network (1F81h assigns 48)" in result.stderr


def test_manager_refuses_demo_nodes_not_in_this_process(manager, tmp_path):
    dcf = _network_dcf(tmp_path / "net.dcf", slaves=(0x30, 0x31))
    for option in ("cycle", "cut"):
        args = (f"--dcf={dcf}", f"--{option}=4", "--stop-at=2")
        assert_refused(_run(manager, *args), option, args)
    args = (f"--dcf={dcf}", "--slaves=3", "--stop-at=2")
    assert_refused(_run(manager, *args), "slaves", args)
