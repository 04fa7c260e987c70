# SPDX-License-Identifier: Apache-2.0
"""scripts/safeline-dds without a bridge: the types against the IDL, values, arguments, the
loopback configuration and its refusals, the output of every command on canned data, and the
errors (no bridge, refused, aborted, timeout) with their exit codes.

The DDS tests against real bridges are tests/canopen/bridge (twister); the few here that start
a participant run it in a network namespace of their own (unshare -rn), or are skipped."""

import io
import json
import os
import re
import shutil
import subprocess
import sys
import typing

import pytest

BASE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))

from safeline_dds import cli, config, values as V  # noqa: E402

cyclonedds = pytest.importorskip("cyclonedds")
from safeline_dds import types as T  # noqa: E402

IDL = os.path.join(BASE, "subsys", "canopen", "bridge", "dds", "idl", "safeline_canopen.idl")
SCRIPT = os.path.join(BASE, "scripts", "safeline-dds")


# --- the types are the IDL's ------------------------------------------------------------------

def parse_idl(text):
    """{struct: [(name, type, key)]} and {const: value} of our IDL (its own simple shape)."""
    text = re.sub(r"//.*", "", text)
    structs = {}
    for name, body in re.findall(r"struct\s+(\w+)\s*\{(.*?)\};", text, re.S):
        members = []
        for m in re.finditer(r"(@key\s+)?([\w]+(?:<[^>]*>)?)\s+(\w+)(?:\[(\d+)\])?\s*;", body):
            key, typ, field, arr = m.groups()
            typ = typ.replace(" ", "")
            if arr:
                typ = f"array[{typ},{arr}]"
            typ = re.sub(r"^string<(\d+)>$", r"bounded_str[\1]", typ)
            typ = re.sub(r"^sequence<(\w+)(?:,(\d+))?>$",
                         lambda mm: f"sequence[{mm.group(1)}"
                         + (f",{mm.group(2)}" if mm.group(2) else "") + "]", typ)
            members.append((field, "bool" if typ == "boolean" else typ, bool(key)))
        structs[name] = members
    consts = {n: int(v) for n, v in re.findall(r"const\s+uint8\s+(\w+)\s*=\s*(\d+);", text)}
    return structs, consts


def py_members(cls):
    keys = getattr(cls, "__idl_field_annotations__", {})
    out = []
    for name, ann in typing.get_type_hints(cls, include_extras=True).items():
        if ann is bool:
            typ = "bool"
        else:
            meta = typing.get_args(ann)[1]
            typ = meta if isinstance(meta, str) else repr(meta).replace(" ", "")
        out.append((name, typ, keys.get(name, {}).get("key", False)))
    return out


def test_python_types_mirror_the_idl_member_by_member():
    structs, _ = parse_idl(open(IDL).read())
    types_of = {cls.__name__: cls for cls in T.TOPICS.values()}
    assert set(structs) == set(types_of)
    for name, members in structs.items():
        cls = types_of[name]
        assert py_members(cls) == members, name
        assert cls.__idl__.idl_transformed_typename == f"safeline::canopen::v1::{name}"
        assert cls.__idl_annotations__.get("extensibility") == "final", name


def test_constants_mirror_the_idl():
    _, consts = parse_idl(open(IDL).read())
    assert consts, "the IDL has constants"
    for name, value in consts.items():
        assert getattr(T, name) == value, name
    assert set(T.STATUS_NAMES) == {v for k, v in consts.items() if k.startswith("STATUS_")}


def test_every_topic_has_a_type_and_round_trips():
    for name, cls in T.TOPICS.items():
        keys = {k: 1 for k, _, key in py_members(cls) if key}
        sample = cls(**{k: ("x" if k in ("client_id", "bridge") else v) for k, v in keys.items()})
        assert cls.deserialize(sample.serialize()).serialize() == sample.serialize(), name


# --- values -----------------------------------------------------------------------------------

@pytest.mark.parametrize("text,dtype,wire", [
    ("500", V.UNSIGNED16, b"\xf4\x01"),
    ("0x1F4", V.UNSIGNED16, b"\xf4\x01"),
    ("255", V.UNSIGNED8, b"\xff"),
    ("-12", V.INTEGER16, b"\xf4\xff"),
    ("-1", V.INTEGER32, b"\xff\xff\xff\xff"),
    ("0x12345678", V.UNSIGNED32, b"\x78\x56\x34\x12"),
    ("16777215", V.UNSIGNED24, b"\xff\xff\xff"),
    ("18446744073709551615", V.UNSIGNED64, b"\xff" * 8),
    ("true", V.BOOLEAN, b"\x01"),
    ("0", V.BOOLEAN, b"\x00"),
    ("1.5", V.REAL32, b"\x00\x00\xc0\x3f"),
    ("hello", V.VISIBLE_STRING, b"hello"),
    ("0a 1b 2c", V.OCTET_STRING, b"\x0a\x1b\x2c"),
    ("0xdeadbeef", V.DOMAIN, b"\xde\xad\xbe\xef"),
])
def test_encode_and_decode_round_trip(text, dtype, wire):
    assert V.encode(text, dtype) == wire
    value, shown = V.decode(wire, dtype)
    assert shown


@pytest.mark.parametrize("text,dtype,message", [
    ("256", V.UNSIGNED8, "does not fit UNSIGNED8 (0..255)"),
    ("-1", V.UNSIGNED16, "does not fit UNSIGNED16"),
    ("32768", V.INTEGER16, "does not fit INTEGER16 (-32768..32767)"),
    ("five", V.UNSIGNED32, "is not an integer"),
    ("maybe", V.BOOLEAN, "is not a BOOLEAN"),
    ("x", V.REAL64, "is not a number"),
    ("caf\u00e9", V.VISIBLE_STRING, "ASCII characters only"),
    ("zz", V.OCTET_STRING, "is not hex bytes"),
    ("1", 0, "give --type"),
])
def test_encode_refuses_what_does_not_fit(text, dtype, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        V.encode(text, dtype)


def test_decode_unknown_or_odd_sizes_as_hex():
    assert V.decode(b"\x01\x02\x03", V.UNSIGNED16)[0] == "010203"
    assert V.decode(b"\x01\x02", 0)[1] == "01 02"
    assert V.decode(bytes(100), V.DOMAIN)[1].endswith("... (100 bytes)")
    assert V.decode(b"name\0junk", V.VISIBLE_STRING)[0] == "name"
    assert V.decode(b"\x2a\x00", V.INTEGER16) == (42, "42 (0x002A)")


def test_type_names_and_aliases():
    assert V.parse_type("u16") == V.UNSIGNED16
    assert V.parse_type("UNSIGNED16") == V.UNSIGNED16
    assert V.parse_type("0x0006") == V.UNSIGNED16
    assert V.parse_type("string") == V.VISIBLE_STRING
    with pytest.raises(ValueError, match="unknown data type"):
        V.parse_type("u13")
    assert V.type_name(V.INTEGER64) == "INTEGER64"
    assert V.abort_text(0x06010002) == "Attempt to write a read only object"


# --- arguments --------------------------------------------------------------------------------

def parse(*argv):
    return cli.build_parser().parse_args(list(argv))


def test_index_and_sub_index_are_hex_in_every_spelling():
    for spelling in ("1017", "0x1017", "1017h", "0X1017"):
        a = parse("read", "5", spelling, "0")
        assert a.index == 0x1017
    assert parse("read", "5", "1018", "0a").sub == 0x0A
    assert parse("write", "5", "0x1017", "0", "500").value == "500"
    assert parse("write", "5", "2002", "0", "--", "-12").value == "-12"


@pytest.mark.parametrize("argv", [
    ["read", "0", "1017", "0"], ["read", "128", "1017", "0"], ["read", "5", "10000", "0"],
    ["read", "5", "1017", "100"], ["read", "5", "xyz", "0"], ["nmt", "jump", "5"],
    ["nmt", "start", "200"], ["read", "5", "1017", "0", "--block", "--segmented"],
])
def test_bad_arguments_are_usage_errors(argv, capsys):
    with pytest.raises(SystemExit) as e:
        parse(*argv)
    assert e.value.code == cli.EXIT_USAGE


def test_nmt_all_is_node_0_and_modes():
    assert parse("nmt", "start", "all").node == 0
    assert parse("nmt", "reset-comm", "5").node == 5
    assert parse("read", "5", "2100", "0", "--block").mode == T.MODE_BLOCK
    assert parse("read", "5", "2100", "0").mode == T.MODE_AUTO


# --- the loopback configuration ----------------------------------------------------------------

def test_the_project_configuration_is_loopback_only():
    text, desc = config.load()
    assert desc == "loopback configuration"
    assert config.loopback_problems(text) == []
    assert 'NetworkInterface name="lo" multicast="false"' in text


@pytest.mark.parametrize("edit,problem", [
    (('name="lo"', 'name="eth0"'), "must be exactly lo"),
    (('multicast="false"', 'multicast="true"'), "multicast must be off"),
    (("<AllowMulticast>false", "<AllowMulticast>spdp"), "AllowMulticast must be false"),
    (('Id="any"', 'Id="42"'), 'Domain Id="any"'),
    (('address="127.0.0.1"', 'address="10.0.0.1"'), "only 127.0.0.1"),
])
def test_a_changed_loopback_configuration_is_refused(tmp_path, monkeypatch, edit, problem):
    text = config.LOOPBACK.read_text().replace(*edit)
    bad = tmp_path / "loopback.xml"
    bad.write_text(text)
    monkeypatch.setattr(config, "LOOPBACK", bad)
    with pytest.raises(config.ConfigError, match="refusing to start") as e:
        config.load()
    assert problem in str(e.value)


def test_without_the_loopback_configuration_the_client_refuses(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "LOOPBACK", tmp_path / "missing.xml")
    with pytest.raises(config.ConfigError, match="pass --dds-config FILE"):
        config.load()
    # ... unless the user passes their own, which is then used as given.
    own = tmp_path / "own.xml"
    own.write_text("<CycloneDDS/>")
    assert config.load(str(own)) == ("<CycloneDDS/>", str(own))
    assert config.load(f"file://{own}")[1] == str(own)
    with pytest.raises(config.ConfigError, match="cannot read"):
        config.load(str(tmp_path / "nope.xml"))


@pytest.mark.parametrize("content,reason", [
    ("vm\n", "not a Cyclone DDS configuration: not XML (syntax error: line 1, column 0)"),
    ("", "not a Cyclone DDS configuration: not XML"),
    ("<Domain/>", "the root element is <Domain>, not <CycloneDDS>"),
    ("<CycloneDDS>\u00e9</CycloneDDS>", "Cyclone takes ASCII only"),
    (b"\xff\xfe<", "not UTF-8 text (byte 0)"),
])
def test_a_file_that_is_no_dds_configuration_is_refused_in_one_line(tmp_path, content, reason):
    bad = tmp_path / "hostname"
    if isinstance(content, bytes):
        bad.write_bytes(content)
    else:
        bad.write_text(content)
    with pytest.raises(config.ConfigError) as e:
        config.load(str(bad))
    assert str(e.value).startswith(f"{bad}: ") and reason in str(e.value)
    assert "\n" not in str(e.value)


def test_a_fifo_or_a_directory_as_dds_configuration_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    for path in (fifo, tmp_path):
        with pytest.raises(config.ConfigError, match="not a regular file"):
            config.load(str(path))


def test_dds_config_of_a_plain_text_file_ends_in_one_line_without_traceback(tmp_path):
    """safeline-dds --dds-config /etc/hostname: a usage error in one line, before any DDS."""
    host = tmp_path / "hostname"
    host.write_text("vm\n")
    r = subprocess.run([sys.executable, SCRIPT, "--dds-config", str(host), "nodes"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == cli.EXIT_USAGE
    assert r.stderr == (f"safeline-dds: error: {host}: not a Cyclone DDS configuration: not XML "
                        "(syntax error: line 1, column 0)\n")


def test_client_id_carries_the_name_the_allow_list_matches(monkeypatch):
    monkeypatch.setenv("SAFELINE_DDS_CLIENT", "ops")
    cid = config.client_id()
    assert cid.startswith("ops@") and re.search(rf":{os.getpid()}(\.\d+)?$", cid)
    again = config.client_id("ops")
    assert again.startswith("ops@") and again != cid, "two clients never share an id"
    assert config.client_id("admin").startswith("admin@")
    assert len(config.client_id("x" * 100)) <= 64


# --- commands on canned data ---------------------------------------------------------------------

class Sample:
    """Stands in for a DDS sample: its fields and a sample_info."""

    def __init__(self, cls, **fields):
        self.__dict__.update(cls(**fields).__dict__)


class FakeClient:
    """The client's interface, without DDS; replies given by the test."""

    now = None

    def __init__(self, domain=42, dds_config=None, name=None, bridge=None):
        self.domain_id = domain
        self.name = name
        self.requests = []
        self.closed = False
        now = FakeClient.now
        self.bridge_state = T.BridgeState(bridge="manager", version="safeline-dds 1.0",
                                          domain_id=42, started_ns=now - 10 ** 10,
                                          time_ns=now - 10 ** 8, lines=1, nodes=1, events=10)
        self.line = T.LineState(line=0, name="line0", can_state=0, rx_frames=5)
        self.nodes = {
            (0, 1): (T.NodeState(line=0, node_id=1, name="manager", local=True, nmt_state=5,
                                 identity_mask=0x1F, vendor_id=0x539), True),
            (0, 5): (T.NodeState(line=0, node_id=5, name="hello_node", nmt_state=127,
                                 heartbeat=T.HB_LOST, heartbeat_ns=now - 2 * 10 ** 9,
                                 boot_status=ord("M"), identity_mask=0x7), True),
            (0, 6): (T.NodeState(line=0, node_id=6, nmt_state=4, heartbeat_ns=now - 10 ** 8),
                     False),
        }
        self.emcy = [T.Emcy(line=0, node_id=5, code=0x8130, error_register=0x11, seq=3,
                            time_ns=now - 10 ** 9)]
        self.srdo = {(0, 5, 1): (T.SrdoState(line=0, node_id=5, srdo=1, safe=True, reason=4,
                                             reason_text="SCT"), True)}
        self.reply = None

    # state
    def open_state(self):
        pass

    def wait_bridge(self, timeout):
        return self.bridge_state

    def _latest(self, name, key):
        return {"manager": (self.bridge_state, True)} if name == T.TOPIC_BRIDGE else {}

    def line_states(self):
        return {0: (self.line, True)}

    def node_states(self):
        return self.nodes

    def emcys(self):
        return self.emcy

    def srdos(self):
        return self.srdo

    def values(self):
        return {(0, 2, 0x2001, 0): (T.OdValue(line=0, node_id=2, index=0x2001, subindex=0,
                                              data_type=V.UNSIGNED16, size=2, data=[0xF4, 1],
                                              changes=1), True)}

    # requests
    def sdo_info(self, node, index, sub, **kw):
        self.requests.append(("info", node, index, sub))
        return T.SdoReply(client_id="c", status=T.STATUS_OK, data_type=V.UNSIGNED16,
                          access=2, name="Producer heartbeat time")

    def sdo_read(self, node, index, sub, **kw):
        self.requests.append(("read", node, index, sub))
        return self.reply or T.SdoReply(client_id="c", status=T.STATUS_OK,
                                        data_type=V.UNSIGNED16, name="Producer heartbeat time",
                                        data=[0xE8, 0x03])

    def sdo_write(self, node, index, sub, data, **kw):
        self.requests.append(("write", node, index, sub, bytes(data)))
        return self.reply or T.SdoReply(client_id="c", status=T.STATUS_OK)

    def close(self):
        self.closed = True

    def nmt(self, node, command, **kw):
        self.requests.append(("nmt", node, command))
        return self.reply or T.NmtReply(client_id="c", status=T.STATUS_OK,
                                        message="sent by node 1 (NMT master)")


@pytest.fixture
def fake(monkeypatch):
    import time

    from safeline_dds import client as client_mod

    FakeClient.now = time.time_ns()
    made = []

    def factory(*a, **kw):
        c = FakeClient(*a, **kw)
        if fake.reply is not None:
            c.reply = fake.reply
        made.append(c)
        return c

    fake.reply = None
    fake.made = made
    monkeypatch.setattr(client_mod, "BridgeClient", factory)
    return fake


def run_cli(capsys, *argv):
    rc = cli.main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_nodes_table_and_json(fake, capsys):
    rc, out, _ = run_cli(capsys, "nodes")
    assert rc == 0
    assert "bridge manager (safeline-dds 1.0, domain 42): up" in out
    assert "line 0 line0: error-active" in out
    row1 = next(l for l in out.splitlines() if re.match(r"\s+0\s+1\s", l))
    assert "manager" in row1 and "OPERATIONAL" in row1 and "local" in row1
    row5 = next(l for l in out.splitlines() if re.match(r"\s+0\s+5\s", l))
    assert "PRE-OPERATIONAL" in row5 and re.search(r"LOST 2\.\ds", row5) and " M " in row5
    assert re.search(r"8130h 1\.\ds ago", row5) and "SAFE 1:SCT" in row5
    row6 = next(l for l in out.splitlines() if re.match(r"\s+0\s+6\s", l))
    assert "STOPPED ?" in row6, "an instance without writer is shown stale"
    rc, out, _ = run_cli(capsys, "--json", "nodes")
    nodes = json.loads(out)
    assert [(n["line"], n["node"]) for n in nodes] == [(0, 1), (0, 5), (0, 6)]
    assert nodes[0]["identity"] == {"device_type": 0, "vendor_id": 0x539, "product_code": 0,
                                    "revision": 0, "serial": 0}
    assert nodes[1]["boot"] == "M" and nodes[1]["safe_state"] is True
    assert nodes[1]["last_emcy"]["code_hex"] == "8130"
    assert nodes[2]["alive"] is False


def test_read_decodes_with_the_eds_type(fake, capsys):
    rc, out, _ = run_cli(capsys, "read", "5", "0x1017", "0")
    assert rc == 0
    assert out.strip() == ("node 5 1017:00 Producer heartbeat time = 1000 (0x03E8) "
                           "(UNSIGNED16, 2 bytes)")
    rc, out, _ = run_cli(capsys, "--json", "read", "5", "1017", "0")
    assert json.loads(out) == {"node": 5, "index": "1017", "sub": "00",
                               "name": "Producer heartbeat time", "type": "UNSIGNED16",
                               "value": 1000, "size": 2, "hex": "e803"}


def test_write_is_typed_from_the_eds(fake, capsys):
    rc, out, _ = run_cli(capsys, "write", "5", "0x1017", "0", "500")
    assert rc == 0, out
    assert "node 5 1017:00 Producer heartbeat time := 500 (UNSIGNED16, 2 bytes): ok" in out
    assert fake.made[-1].requests == [("info", 5, 0x1017, 0), ("write", 5, 0x1017, 0,
                                                                b"\xf4\x01")]
    rc, _, err = run_cli(capsys, "write", "5", "0x1017", "0", "70000")
    assert rc == cli.EXIT_USAGE and "does not fit UNSIGNED16" in err
    rc, _, _ = run_cli(capsys, "write", "5", "2000", "0", "7", "--type", "u32")
    assert fake.made[-1].requests == [("write", 5, 0x2000, 0, b"\x07\0\0\0")]


def test_write_from_a_file(fake, capsys, tmp_path):
    f = tmp_path / "blob.bin"
    f.write_bytes(bytes(range(200)))
    rc, out, _ = run_cli(capsys, "write", "2", "2100", "0", "--file", str(f), "--block")
    assert rc == 0 and "200 bytes" in out
    assert fake.made[-1].requests[-1] == ("write", 2, 0x2100, 0, bytes(range(200)))
    rc, _, err = run_cli(capsys, "write", "2", "2100", "0")
    assert rc == cli.EXIT_USAGE and "give a VALUE or --file" in err


@pytest.mark.parametrize("reply,code,text", [
    (T.SdoReply(client_id="c", status=T.STATUS_REFUSED,
                message="not in the allow-list: client 'x' may not write 1018h:01"),
     cli.EXIT_FAILED, "refused: not in the allow-list"),
    (T.SdoReply(client_id="c", status=T.STATUS_ABORTED, abort_code=0x06010002,
                message="SDO abort 06010002h: Attempt to write a read only object"),
     cli.EXIT_FAILED, "aborted: SDO abort 06010002h"),
    (T.SdoReply(client_id="c", status=T.STATUS_TIMEOUT, message="no complete answer"),
     cli.EXIT_TIMEOUT, "timeout: no complete answer"),
    (T.SdoReply(client_id="c", status=T.STATUS_UNKNOWN_NODE, message="node 9 is unknown"),
     cli.EXIT_FAILED, "unknown node: node 9 is unknown"),
])
def test_failed_requests_say_why(fake, capsys, reply, code, text):
    fake.reply = reply
    rc, out, err = run_cli(capsys, "read", "5", "1018", "1")
    assert rc == code
    assert text in err
    rc, out, err = run_cli(capsys, "--json", "read", "5", "1018", "1")
    doc = json.loads(out)
    assert rc == code and text in doc["error"]
    assert doc["status"] == T.STATUS_NAMES[reply.status]
    if reply.status == T.STATUS_ABORTED:
        assert doc["abort_code"] == 0x06010002


def test_nmt_command_and_refusal(fake, capsys):
    rc, out, _ = run_cli(capsys, "nmt", "start", "all")
    assert rc == 0 and "nmt start all nodes: sent by node 1 (NMT master)" in out
    assert fake.made[-1].requests == [("nmt", 0, 1)]
    fake.reply = T.NmtReply(client_id="c", status=T.STATUS_REFUSED, message="read-only")
    rc, _, err = run_cli(capsys, "nmt", "reset", "5")
    assert rc == cli.EXIT_FAILED and "nmt reset node 5: refused: read-only" in err


def test_emcy_values_lines_watch_once(fake, capsys):
    rc, out, _ = run_cli(capsys, "emcy")
    assert rc == 0 and "node   5  8130h  reg 11h" in out and "#3" in out
    rc, out, _ = run_cli(capsys, "--json", "emcy", "7")
    assert json.loads(out) == []
    rc, out, _ = run_cli(capsys, "values")
    assert "node   2 2001:00  500 (0x01F4) (UNSIGNED16)" in out
    rc, out, _ = run_cli(capsys, "lines")
    assert "line 0 line0: error-active" in out
    rc, out, _ = run_cli(capsys, "watch", "--count", "2", "--interval", "0")
    assert out.count("LINE NODE") == 2, "not a terminal: one table per refresh"
    rc, out, _ = run_cli(capsys, "--json", "watch", "--count", "2", "--interval", "0")
    snaps = [json.loads(l) for l in out.splitlines()]
    assert len(snaps) == 2 and snaps[0]["bridges"][0]["bridge"] == "manager"


def test_watch_in_a_terminal_refreshes_in_place(fake, monkeypatch):
    buf = io.StringIO()
    buf.isatty = lambda: True
    monkeypatch.setattr(sys, "stdout", buf)
    assert cli.main(["watch", "--count", "3", "--interval", "0"]) == 0
    text = buf.getvalue()
    assert text.startswith("\x1b[?25l\x1b[H\x1b[2J"), "hide the cursor, clear once"
    assert text.count("\x1b[H") == 4, "then home before each refresh, no scrolling"
    assert text.endswith("\x1b[?25h"), "the cursor comes back"


class _Exited(Exception):
    pass


def run_entry(monkeypatch, *argv):
    """cli.run() as scripts/safeline-dds calls it, its os._exit() caught: the code."""
    def fake_exit(code):
        raise _Exited(code)

    monkeypatch.setattr(cli.os, "_exit", fake_exit)
    with pytest.raises(_Exited) as e:
        cli.run(list(argv))
    return e.value.args[0]


def test_the_entry_closes_the_client_and_skips_the_interpreters_finalization(fake, monkeypatch,
                                                                              capsys):
    assert run_entry(monkeypatch, "watch", "--count", "1", "--interval", "0") == cli.EXIT_OK
    assert fake.made[0].closed, "the participant is deleted before the process ends"
    assert "bridge manager" in capsys.readouterr().out
    fake.reply = T.SdoReply(client_id="c", status=T.STATUS_ABORTED, abort_code=0x06020000,
                            message="SDO abort 06020000h")
    assert run_entry(monkeypatch, "read", "2", "1017", "0") == cli.EXIT_FAILED
    assert fake.made[1].closed, "closed on a failure too"
    # argparse's SystemExit (and SIGTERM's) ends in the same exit.
    assert run_entry(monkeypatch, "nosuchcommand") == cli.EXIT_USAGE
    assert run_entry(monkeypatch, "--help") == cli.EXIT_OK


def test_no_bridge_and_config_errors_have_their_exit_codes(monkeypatch, capsys):
    from safeline_dds import client as client_mod

    def no_bridge(*a, **kw):
        raise client_mod.NoBridge("no bridge found on DDS domain 42 within 5 s")

    monkeypatch.setattr(client_mod, "BridgeClient", no_bridge)
    rc, _, err = run_cli(capsys, "nodes")
    assert rc == cli.EXIT_NO_BRIDGE and "error: no bridge found on DDS domain 42" in err

    def bad_config(*a, **kw):
        raise config.ConfigError("refusing to start: the loopback DDS configuration is missing")

    monkeypatch.setattr(client_mod, "BridgeClient", bad_config)
    rc, out, err = run_cli(capsys, "--json", "nodes")
    assert rc == cli.EXIT_USAGE and json.loads(out)["status"] == "config"


# --- real participants, in a namespace of their own ---------------------------------------------

def netns_run(cmd, env=None, timeout=30):
    if shutil.which("unshare") is None:
        pytest.skip("no unshare on this machine")
    probe = subprocess.run(["unshare", "-rn", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip(f"no network namespace here (unshare -rn: {probe.stderr.decode().strip()})")
    script = "ip link set lo up && exec " + " ".join(f"'{c}'" for c in cmd)
    return subprocess.run(["unshare", "-rn", "sh", "-c", script], capture_output=True,
                          text=True, env=env, timeout=timeout)


def test_no_bridge_found_for_real():
    r = netns_run([sys.executable, SCRIPT, "--timeout", "0.5", "--domain", "77", "nodes"])
    assert r.returncode == cli.EXIT_NO_BRIDGE, r.stderr
    assert "no bridge found on DDS domain 77 within 0.5 s (loopback configuration" in r.stderr


def test_cyclonedds_uri_is_ignored(tmp_path):
    """A configuration in CYCLONEDDS_URI would put the client on another interface; the client
    passes its loopback configuration explicitly, so Cyclone never reads the variable."""
    bad = tmp_path / "elsewhere.xml"
    bad.write_text('<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any"><General>'
                   '<Interfaces><NetworkInterface name="nosuch0"/></Interfaces></General>'
                   '</Domain></CycloneDDS>')
    env = dict(os.environ, CYCLONEDDS_URI=f"file://{bad}")
    r = netns_run([sys.executable, SCRIPT, "--timeout", "0.3", "nodes"], env=env)
    assert r.returncode == cli.EXIT_NO_BRIDGE, r.stderr
    assert "nosuch0" not in r.stderr


def test_a_configuration_cyclone_refuses_is_one_line_with_its_reason(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any"><General>'
                   '<Frobnicate>1</Frobnicate></General></Domain></CycloneDDS>')
    r = netns_run([sys.executable, SCRIPT, "--dds-config", str(bad), "nodes"])
    assert r.returncode == cli.EXIT_USAGE, r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr
    assert r.stderr.startswith(f"safeline-dds: error: {bad}: Cyclone DDS refused the "
                               "configuration (")
    assert "Frobnicate: unknown element" in r.stderr


def test_help_lists_every_command():
    r = subprocess.run([sys.executable, SCRIPT, "--help"], capture_output=True, text=True)
    assert r.returncode == 0
    for cmd in ("watch", "nodes", "emcy", "read", "write", "nmt", "--json"):
        assert cmd in r.stdout
