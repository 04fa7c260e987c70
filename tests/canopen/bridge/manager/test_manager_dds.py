# SPDX-License-Identifier: Apache-2.0
"""The DDS bridge of the manager sample (--dds) with the Python client, on the virtual bus.

Run by twister as sample.canopen.manager.dds (SAFELINE_IMAGE is the manager sample). Each
test starts the firmware on a DDS domain of its own, inside this process's network namespace.
"""

import glob
import json
import os
import pty
import re
import select
import signal
import subprocess
import sys
import threading
import time

import pytest

from bridge_fixtures import BASE, ISOLATED, NETNS, SCRIPT
from safeline_dds import testing
from safeline_dds import types as T
from safeline_dds.client import (NMT_PREOP, NMT_RESET, NMT_START, NMT_STOP, QOS_EMCY,
                                 QOS_RPC, QOS_STATE, RequestTimeout)

QUIET = ("--cut=0", "--cycle=0")  # the network without the demo's power cycle and cut


def until(fn, timeout=15.0, what="condition"):
    end = time.monotonic() + timeout
    last = None
    while time.monotonic() < end:
        last = fn()
        if last:
            return last
        time.sleep(0.05)
    raise AssertionError(f"{what} not reached within {timeout} s (last: {last!r})")


def nodes_of(c):
    return {(n.line, n.node_id): n for n in c.nodes()}


def settled(c):
    """The demo network after its startup: 2..4 booted and OPERATIONAL, 5 failed with M."""
    n = nodes_of(c)
    ok = all((0, i) in n and n[(0, i)].nmt_state == 5 and n[(0, i)].boot_status == 0
             for i in (2, 3, 4))
    return ok and (0, 5) in n and n[(0, 5)].boot_status == ord("M") and \
        n[(0, 5)].nmt_state == 127 and n


def start_settled(firmware, client, *args, name="test"):
    fw = firmware(*args)
    c = client(name)
    c.open_state()
    c.wait_bridge(15)
    until(lambda: settled(c), 15, "the network settled")
    return fw, c


# --- topics and keys ------------------------------------------------------------------------------

def test_every_topic_appears_with_its_keys(firmware, client):
    fw, c = start_settled(firmware, client, *QUIET)
    b = until(lambda: c.wait_bridge(1).events > 0 and c.wait_bridge(1), 3, "counters")
    assert (b.bridge, b.version, b.lines, b.nodes, b.read_only) == \
        ("manager", "safeline-dds 1.0", 1, 1, False)
    assert b.events > 0 and b.events_lost == 0 and b.queue_size == 1024

    lines = c.lines()
    assert [(ln.line, ln.name, ln.can_state, ln.nodes) for ln in lines] == [(0, "line0", 0, 1)]
    assert lines[0].rx_frames > 0 and lines[0].tx_frames > 0 and lines[0].events_lost == 0

    nodes = settled(c)
    assert sorted(nodes) == [(0, 1), (0, 2), (0, 3), (0, 4), (0, 5)]
    m = nodes[(0, 1)]
    assert (m.name, m.local, m.nmt_state, m.boot_status) == ("manager", True, 5, T.BOOT_NONE)
    assert m.identity_mask == 0x1F and m.vendor_id == 0x539
    for i in (2, 3, 4):
        n = nodes[(0, i)]
        assert (n.name, n.local, n.heartbeat, n.identity_mask) == ("hello_node", False,
                                                                   T.HB_ACTIVE, 0x0F)
        assert (n.vendor_id, n.product_code, n.revision) == (0x539, 1, 0x10000)
        assert n.heartbeat_ns > 0 and time.time_ns() - n.heartbeat_ns < 2e9
    five = nodes[(0, 5)]
    assert five.identity_mask == 0x07 and five.product_code == 1, "read up to the mismatch"

    # EMCY: the manager has no EMCY producer (no 1014h), so its heartbeat errors (8130h, for
    # node 5 whose heartbeat is slower than 1016h wants) come as emergencies with COB-ID 0.
    emcys = until(lambda: c.emcys(), 10, "an emergency")
    assert {(e.line, e.node_id) for e in emcys} == {(0, 1)}
    e = emcys[-1]
    assert e.own and e.cob_id == 0 and e.code in (0x8130, 0) and e.msef[0] == 5

    values = until(lambda: len(c.values()) == 4 and c.values(), 10, "four object values")
    assert sorted(values) == [(0, 1, 0x1001, 0), (0, 2, 0x2001, 0), (0, 3, 0x2001, 0),
                              (0, 4, 0x2001, 0)]
    for key in [(0, 2, 0x2001, 0), (0, 3, 0x2001, 0), (0, 4, 0x2001, 0)]:
        v, alive = values[key]
        assert alive and v.abort_code == 0 and bytes(v.data) == b"\xf4\x01" and \
            v.data_type == 6, "setpoint 500, UNSIGNED16 from the EDS"
    assert c.srdos() == {}, "the manager's network has no SRDO (tests/canopen/bridge/network)"

    # Request and reply topics, keyed by the client.
    r = c.sdo_read(2, 0x1018, 1)
    assert (r.client_id, r.status, bytes(r.data)) == (c.client_id, T.STATUS_OK,
                                                      (0x539).to_bytes(4, "little"))
    assert (r.data_type, r.access, r.name) == (7, 0, "Vendor-ID")
    r = c.nmt(4, NMT_START)
    assert (r.client_id, r.status) == (c.client_id, T.STATUS_OK)
    assert fw.proc.poll() is None


def test_late_joiner_sees_current_state_and_recent_emcy(firmware, cli):
    fw = firmware()
    # The demo story: node 4 power-cycled at 1 s, node 3 cut off at 2 s and back at 3 s.
    # The sample prints the boot's events too: wait for node 3's second boot, after the cut.
    fw.wait_log(r"node +3  back on the bus[\s\S]*node +3  booted OK", 20)
    rc, nodes, err = cli("nodes")
    assert rc == 0, err
    by_id = {n["node"]: n for n in nodes}
    assert sorted(by_id) == [1, 2, 3, 4, 5]
    for i in (2, 3, 4):
        assert (by_id[i]["nmt"], by_id[i]["boot"], by_id[i]["heartbeat"]) == \
            ("OPERATIONAL", "OK", "ok"), by_id[i]
    assert by_id[5]["boot"] == "M" and by_id[1]["local"] and by_id[1]["nmt"] == "OPERATIONAL"
    rc, emcys, err = cli("emcy")
    assert rc == 0, err
    assert 2 <= len(emcys) <= 16, "the recent history, at most 16 per producer"
    seqs = [e["seq"] for e in emcys]
    assert seqs == sorted(seqs) and len(set(seqs)) == len(seqs)
    assert seqs[-1] >= by_id[1]["emcy_count"], "up to the latest (more may have come since)"
    assert {e["code_hex"] for e in emcys} <= {"8130", "0000"}
    # A second late joiner gets the same history.
    rc, again, _ = cli("emcy")
    assert [e["seq"] for e in again][:len(seqs)] == seqs[:len(again)] or \
        again[0]["seq"] >= seqs[0]


# --- SDO ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("mode", [T.MODE_AUTO, T.MODE_SEGMENTED, T.MODE_BLOCK])
def test_sdo_round_trips_from_1_byte_to_100_kB(firmware, client, mode):
    fw, c = start_settled(firmware, client, *QUIET)
    sizes = [1, 2, 3, 4, 5, 7, 8, 9, 127, 128, 889, 890, 4096, 100_000]
    if mode != T.MODE_AUTO:
        sizes = [1, 5, 889, 100_000]
    for size in sizes:
        data = os.urandom(size)
        w = c.sdo_write(2, 0x2100, 0, data, mode=mode, timeout_ms=30000)
        assert (w.status, w.message) == (T.STATUS_OK, "ok"), size
        r = c.sdo_read(2, 0x2100, 0, mode=mode, timeout_ms=30000)
        assert r.status == T.STATUS_OK, (size, r.message)
        assert bytes(r.data) == data, size
        assert (r.data_type, r.name) == (0x0F, "Data buffer")
    # The other slaves' buffers are their own.
    assert c.sdo_read(3, 0x2100, 0).data == []


def test_typed_write_and_read_from_the_command_line(firmware, cli, client):
    start_settled(firmware, client, *QUIET)
    rc, doc, err = cli("write", 5, "0x1017", 0, 500)
    assert rc == 0, err
    assert doc == {"node": 5, "index": "1017", "sub": "00", "name": "Producer heartbeat time",
                   "type": "UNSIGNED16", "size": 2, "status": "ok"}
    rc, doc, err = cli("read", 5, "0x1017", 0)
    assert rc == 0 and doc["value"] == 500 and doc["type"] == "UNSIGNED16", err
    rc, doc, _ = cli("read", 1, "1F81", 5)
    assert rc == 0 and doc["value"] == 5, "the manager's own dictionary (1F81h:05 = 5)"
    rc, doc, _ = cli("info", 2, "2001", 0)
    assert rc == 0 and doc == {"node": 2, "index": "2001", "sub": "00", "name": "Setpoint",
                               "type": "UNSIGNED16", "data_type": 6, "access": "rw"}
    rc, doc, err = cli("read", 2, "6000", 0)
    assert rc == 1 and doc["status"] == "aborted" and doc["abort_code"] == 0x06020000, err
    assert "Object does not exist" in doc["abort_text"]


def test_a_node_that_does_not_answer_times_out(firmware, client, cli):
    fw, c = start_settled(firmware, client, *QUIET)
    assert c.nmt(4, NMT_STOP).status == T.STATUS_OK
    until(lambda: nodes_of(c)[(0, 4)].nmt_state == 4, 5, "node 4 STOPPED")
    # A stopped node does not answer SDO: the bridge's whole-transfer limit first ...
    t0 = time.monotonic()
    rc, doc, err = cli("--timeout", "0.3", "read", 4, "1017", 0)
    assert rc == 4 and doc["status"] == "timeout", err
    assert "no complete answer within 300 ms" in doc["error"]
    # ... or the client's protocol timeout (1 s) within a longer limit.
    r = c.sdo_read(4, 0x1017, 0, timeout_ms=5000)
    assert (r.status, r.abort_code) == (T.STATUS_ABORTED, 0x05040000)
    assert c.nmt(4, NMT_START).status == T.STATUS_OK


# --- refusals -------------------------------------------------------------------------------------

def test_allow_list_refusals_change_nothing(firmware, client, cli):
    fw, c = start_settled(firmware, client, *QUIET)
    before = c.sdo_read(2, 0x2001, 0).data
    cases = [
        (1, 0x1017, 0, b"\xe8\x03", "client 'test' may not write 1017h:00 of node 1"),
        (2, 0x1018, 1, b"\0\0\0\0", "may not write 1018h:01 of node 2"),
        (2, 0x2001, 1, b"\0\0", "may not write 2001h:01 of node 2"),
    ]
    for node, index, sub, data, msg in cases:
        r = c.sdo_write(node, index, sub, data)
        assert r.status == T.STATUS_REFUSED and msg in r.message, r.message
        assert r.message.startswith("not in the allow-list")
    assert c.sdo_read(2, 0x2001, 0).data == before
    assert c.sdo_read(1, 0x1017, 0).data == [0xF4, 0x01], "the manager's 1017h is 500"
    r = c.nmt(1, NMT_STOP)
    assert r.status == T.STATUS_REFUSED and "may not send stop to node 1" in r.message
    time.sleep(0.3)
    assert nodes_of(c)[(0, 1)].nmt_state == 5, "the manager stays OPERATIONAL"
    until(lambda: c.wait_bridge(1).refused == 4, 3, "four refusals counted")
    # A broadcast reaches the manager as well: refused, since node 1 may not be commanded.
    for cmd in (NMT_STOP, NMT_PREOP, NMT_RESET, NMT_START):
        r = c.nmt(0, cmd)
        assert r.status == T.STATUS_REFUSED, r.message
        assert "to all nodes (not to node 1) on line 0" in r.message, r.message
    time.sleep(0.3)
    assert all(n.nmt_state == 5 for n in c.nodes() if n.node_id != 5), "nobody moved"
    until(lambda: c.wait_bridge(1).refused == 8, 3, "eight refusals counted")
    # The allowed ones (demo allow-list: 1017h, 2001h, 2100h of 2..5) go through.
    assert c.sdo_write(2, 0x2001, 0, b"\x58\x02").status == T.STATUS_OK
    rc, doc, err = cli("write", 1, "1017", 0, 1000)
    assert rc == 1 and doc["status"] == "refused", err


def test_custom_allow_list_by_client_name(firmware, client, tmp_path):
    allow = tmp_path / "allow.conf"
    allow.write_text("write  ops  0  2  2001:00\n"
                     "nmt    ops  0  4  stop,start\n")
    fw, ops = start_settled(firmware, client, *QUIET, f"--dds-allow={allow}", name="ops")
    guest = client("guest")
    assert ops.sdo_write(2, 0x2001, 0, b"\x58\x02").status == T.STATUS_OK
    assert ops.sdo_read(2, 0x2001, 0).data == [0x58, 0x02]
    r = guest.sdo_write(2, 0x2001, 0, b"\x00\x00")
    assert r.status == T.STATUS_REFUSED and "client 'guest'" in r.message
    assert ops.sdo_read(2, 0x2001, 0).data == [0x58, 0x02]
    assert ops.sdo_write(3, 0x2001, 0, b"\0\0").status == T.STATUS_REFUSED
    assert guest.nmt(4, NMT_STOP).status == T.STATUS_REFUSED
    assert ops.nmt(0, NMT_STOP).status == T.STATUS_REFUSED, "no broadcast for ops"
    assert ops.nmt(4, NMT_PREOP).status == T.STATUS_REFUSED, "stop and start only"
    assert ops.nmt(4, NMT_STOP).status == T.STATUS_OK
    until(lambda: nodes_of(ops)[(0, 4)].nmt_state == 4, 5, "node 4 STOPPED")
    assert ops.nmt(4, NMT_START).status == T.STATUS_OK


def test_a_request_for_all_nodes_needs_every_node_allowed(firmware, client, cli, tmp_path):
    """NMT "all" and the manager's request objects' sub-index 80h (1F82h request NMT, 1F83h
    request guarding) reach every node: allowed only where each node is."""
    allow = tmp_path / "allow.conf"
    allow.write_text("nmt    ops  0  2-127  stop,start\n"
                     "nmt    ops  0  1      start\n"
                     "write  ops  0  1      1F82:02,1F82:80,1F83:80\n")
    fw, ops = start_settled(firmware, client, *QUIET, f"--dds-allow={allow}", name="ops")
    r = ops.nmt(0, NMT_STOP)
    assert r.status == T.STATUS_REFUSED, r.message
    assert r.message == ("not in the allow-list: client 'ops' may not send stop to all nodes "
                         "(not to node 1) on line 0"), r.message
    rc, doc, err = cli("nmt", "stop", "all", client="ops")
    assert rc == 1 and doc["status"] == "refused" and "(not to node 1)" in doc["error"], err
    for index in (0x1F82, 0x1F83):
        r = ops.sdo_write(1, index, 0x80, b"\x04")
        assert r.status == T.STATUS_REFUSED, r.message
        assert f"may not write {index:04X}h:80 of node 1 on line 0 (not {index:04X}h:01)" \
            in r.message, r.message
    time.sleep(0.3)
    n = nodes_of(ops)
    assert n[(0, 1)].nmt_state == 5 and all(n[(0, i)].nmt_state == 5 for i in (2, 3, 4)), \
        "nobody stopped"
    # One node through the manager's 1F82h: only that node.
    assert ops.sdo_write(1, 0x1F82, 0x02, b"\x04").status == T.STATUS_OK
    until(lambda: nodes_of(ops)[(0, 2)].nmt_state == 4, 5, "node 2 STOPPED")
    # start is allowed for every node: the broadcast goes out, the manager included.
    r = ops.nmt(0, NMT_START)
    assert r.status == T.STATUS_OK, r.message
    until(lambda: nodes_of(ops)[(0, 2)].nmt_state == 5, 5, "node 2 OPERATIONAL again")


def test_without_allow_list_the_bridge_is_read_only(firmware, client):
    fw, c = start_settled(firmware, client, *QUIET, "--dds-allow=none")
    assert c.wait_bridge(1).read_only
    r = c.sdo_write(2, 0x2001, 0, b"\0\0")
    assert r.status == T.STATUS_REFUSED
    assert r.message.startswith("the bridge is read-only: client 'test' may not write")
    r = c.nmt(0, NMT_STOP)
    assert r.status == T.STATUS_REFUSED and "may not send stop to all nodes" in r.message
    assert c.sdo_read(2, 0x2001, 0).status == T.STATUS_OK, "reads always work"


def test_a_bad_allow_list_stops_the_firmware(firmware, tmp_path):
    allow = tmp_path / "bad.conf"
    allow.write_text("# fine\nnmt ops 0 2-5,all stop\n")
    fw = firmware(f"--dds-allow={allow}")
    assert fw.proc.wait(15) == 1
    text = fw.text()
    assert f"{allow}:2: 'all' names no node: a request for all nodes is allowed where each " \
        "node 1..127 is (NODES *)" in text
    assert "DDS bridge failed to start (-22)" in text


# --- malformed requests ---------------------------------------------------------------------------

def raw_sdo(c, **fields):
    def make(rid, bridge):
        return T.SdoRequest(client_id=c.client_id, request_id=rid, bridge=bridge, **fields)
    return c._call("sdo", make, 10, 10)


def raw_nmt(c, **fields):
    def make(rid, bridge):
        return T.NmtRequest(client_id=c.client_id, request_id=rid, bridge=bridge, **fields)
    return c._call("nmt", make, 10, 10)


@pytest.mark.parametrize("fields,status,message", [
    (dict(op=9, node_id=2, index=0x1000), T.STATUS_MALFORMED, "op 9: 0 read, 1 write or 2 info"),
    (dict(op=0, mode=7, node_id=2, index=0x1000), T.STATUS_MALFORMED, "mode 7"),
    (dict(op=0, node_id=0, index=0x1000), T.STATUS_MALFORMED, "node 0: 1..127"),
    (dict(op=0, node_id=200, index=0x1000), T.STATUS_MALFORMED, "node 200: 1..127"),
    (dict(op=0, node_id=2, timeout_ms=700000), T.STATUS_MALFORMED, "timeout_ms 700000"),
    (dict(op=1, node_id=2, index=0x2001), T.STATUS_MALFORMED, "a write needs data"),
    (dict(op=0, node_id=2, index=0x2001, data=b"\x01"), T.STATUS_MALFORMED,
     "only a write carries data"),
    (dict(op=0, line=3, node_id=2, index=0x1000), T.STATUS_UNKNOWN_LINE,
     "line 3 is not bridged"),
    (dict(op=0, node_id=99, index=0x1000), T.STATUS_UNKNOWN_NODE,
     "node 99 is unknown on line 0"),
    (dict(op=1, node_id=99, index=0x2001, data=b"\0\0"), T.STATUS_UNKNOWN_NODE,
     "node 99 is unknown"),
    (dict(op=2, node_id=2, index=0x6000), T.STATUS_NOT_FOUND,
     "6000h:00 is not in the EDS of node 2"),
])
def test_malformed_sdo_requests_get_a_reply_that_says_why(firmware, client, fields, status,
                                                           message):
    fw, c = start_settled(firmware, client, *QUIET)
    before = c.wait_bridge(1).malformed
    r = raw_sdo(c, **fields)
    assert (r.status, r.data) == (status, []), r.message
    assert message in r.message
    if status in (T.STATUS_MALFORMED, T.STATUS_UNKNOWN_LINE, T.STATUS_UNKNOWN_NODE):
        until(lambda: c.wait_bridge(1).malformed == before + 1, 3, "malformed counted")
    assert c.sdo_read(2, 0x1018, 1).status == T.STATUS_OK, "and it serves the next one"


def test_malformed_nmt_requests_and_requests_for_another_bridge(firmware, client):
    fw, c = start_settled(firmware, client, *QUIET)
    for fields, status, message in [
            (dict(node_id=4, command=7), T.STATUS_MALFORMED, "command 7"),
            (dict(node_id=200, command=1), T.STATUS_MALFORMED, "node 200: 0 (all) or 1..127"),
            (dict(line=9, node_id=4, command=1), T.STATUS_UNKNOWN_LINE, "line 9"),
            (dict(node_id=99, command=2), T.STATUS_UNKNOWN_NODE, "node 99 is unknown")]:
        r = raw_nmt(c, **fields)
        assert r.status == status and message in r.message, r.message
    time.sleep(0.3)
    assert all(n.nmt_state in (5, 127) for n in c.nodes()), "nobody changed state"

    def other(rid, bridge):
        return T.NmtRequest(client_id=c.client_id, request_id=rid, bridge="another",
                            node_id=4, command=NMT_STOP)
    with pytest.raises(RequestTimeout):
        c._call("nmt", other, 1.0, 10)
    time.sleep(0.3)
    assert nodes_of(c)[(0, 4)].nmt_state == 5, "a request for another bridge is not ours"


# --- NMT ------------------------------------------------------------------------------------------

def test_nmt_commands_show_on_node_state(firmware, client, cli):
    fw, c = start_settled(firmware, client, *QUIET)
    rc, doc, err = cli("nmt", "stop", 4)
    assert rc == 0 and doc["message"] == "sent by node 1 (NMT master)", err
    until(lambda: nodes_of(c)[(0, 4)].nmt_state == 4, 5, "node 4 STOPPED")
    rc, doc, err = cli("nmt", "preop", 2)
    assert rc == 0, err
    until(lambda: nodes_of(c)[(0, 2)].nmt_state == 127, 5, "node 2 PRE-OPERATIONAL")
    for node in (2, 4, 5):
        rc, doc, err = cli("nmt", "start", node)
        assert rc == 0, err
    until(lambda: all(nodes_of(c)[(0, i)].nmt_state == 5 for i in (1, 2, 3, 4, 5)), 5,
          "everybody OPERATIONAL")
    boots = nodes_of(c)[(0, 3)].heartbeat_ns
    rc, doc, err = cli("nmt", "reset", 3)
    assert rc == 0, err
    # A slave the application reset stays PRE-OPERATIONAL after its boot-up until started.
    until(lambda: nodes_of(c)[(0, 3)].nmt_state == 127 and
          nodes_of(c)[(0, 3)].heartbeat_ns > boots, 10, "node 3 reset: PRE-OPERATIONAL")
    rc, doc, err = cli("nmt", "start", 3)
    assert rc == 0, err
    until(lambda: nodes_of(c)[(0, 3)].nmt_state == 5, 5, "node 3 OPERATIONAL again")


# --- bridge restart -------------------------------------------------------------------------------

class Watcher:
    """scripts/safeline-dds --json watch in a process of its own; the latest snapshot."""

    def __init__(self, domain):
        self.proc = subprocess.Popen(
            [sys.executable, SCRIPT, "--domain", str(domain), "--json", "watch",
             "--interval", "0.2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.snaps = []
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        for line in self.proc.stdout:
            self.snaps.append(json.loads(line))

    def latest(self):
        return self.snaps[-1] if self.snaps else None

    def stop(self):
        self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def watch_shows(w, fn):
    s = w.latest()
    return s is not None and fn(s)


def bridge_up(s, started=None):
    return bool(s["bridges"]) and s["bridges"][0]["alive"] and \
        (started is None or s["bridges"][0]["started_ns"] != started)


def all_operational(s):
    n = {x["node"]: x for x in s["nodes"]}
    return all(i in n and n[i]["alive"] and n[i]["nmt"] == "OPERATIONAL" for i in (1, 2, 3, 4))


def test_bridge_killed_and_restarted_while_clients_run(firmware, client, domain):
    fw, c = start_settled(firmware, client, *QUIET)
    w = Watcher(domain)
    try:
        until(lambda: watch_shows(w, lambda s: bridge_up(s) and all_operational(s)), 15,
              "watch sees the network")
        first = w.latest()["bridges"][0]["started_ns"]
        assert c.sdo_read(2, 0x1018, 1).status == T.STATUS_OK
        fw.kill()  # SIGKILL: no goodbye
        until(lambda: watch_shows(w, lambda s: not s["bridges"][0]["alive"]), 10,
              "watch notices the bridge is gone")
        # After the lease (5 s) the instances have lost their writer: shown stale.
        until(lambda: not any(a for _, (n, a) in c.node_states().items()), 10,
              "node states without writer")

        fw2 = firmware(*QUIET)
        until(lambda: watch_shows(w, lambda s: bridge_up(s, first) and all_operational(s)),
              20, "watch sees the restarted bridge and the network again")
        until(lambda: settled(c), 15, "the library client recovers")
        # The same client's request endpoints match the new bridge by themselves.
        r = c.sdo_read(2, 0x1018, 1, discovery=10)
        assert r.status == T.STATUS_OK and bytes(r.data) == (0x539).to_bytes(4, "little")
        assert c.nmt(4, NMT_START).status == T.STATUS_OK
        assert w.proc.poll() is None, "watch kept running"
        assert fw2.proc.poll() is None
    finally:
        w.stop()


# --- the version trap: C 0.10.2 (bridge) and Python 11.0.1 peers --------------------------------

def test_c_bridge_and_python_11_peers_interoperate(firmware, client):
    """A peer on a newer Cyclone (the PyPI 11.x binding) makes a 0.10 participant look up the
    type objects of the topics it shares, and 0.10 crashes on them, unless its own types carry
    no type information: the bridge's come from idlc -t."""
    import cyclonedds
    from importlib.metadata import version

    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    assert version("cyclonedds") == "11.0.1"
    lib = os.path.realpath(str(cyclonedds.__library__.library_path))
    assert "11.0.1" in lib, lib
    build = os.environ.get("SAFELINE_BUILD_DIR", os.path.dirname(os.path.dirname(
        os.environ["SAFELINE_IMAGE"])))
    gen = glob.glob(os.path.join(build, "**", "gen", "safeline_canopen.c"), recursive=True)
    assert gen, f"no generated types under {build}"
    text = open(gen[0]).read()
    assert text.count(".m_meta = \"\"") == 10, "no type information in any descriptor"
    assert "TYPE_INFO" not in text and "typeinfo" not in text.lower()
    ldd = subprocess.run(["ldd", os.environ["SAFELINE_IMAGE"]], capture_output=True,
                         text=True).stdout
    ddsc = re.search(r"libddsc\.so\S* => (\S+)", ldd)
    assert ddsc and os.path.realpath(ddsc.group(1)).endswith("libddsc.so.0.10.2"), ldd

    fw, c = start_settled(firmware, client, *QUIET)
    # A Python 11.0.1 participant with a reader and a writer on every topic of the bridge,
    # writing on the state topics (line 250: nobody's), so that both sides see each other's
    # types.
    py = client("trap")
    keep = []
    for name, cls in T.TOPICS.items():
        tp = Topic(py.dp, name, cls)
        qos = QOS_RPC if ("request" in name or "reply" in name) else \
            (QOS_EMCY if name == T.TOPIC_EMCY else QOS_STATE)
        rd, wr = DataReader(py.dp, tp, qos=qos), DataWriter(py.dp, tp, qos=qos)
        keep += [tp, rd, wr]
        if "request" not in name and "reply" not in name and name != T.TOPIC_BRIDGE:
            keys = {"line": 250, "node_id": 1, "srdo": 1, "index": 1, "subindex": 0,
                    "bridge": "trap"}
            fields = {k: v for k, v in keys.items() if k in cls.__dataclass_fields__}
            wr.write(cls(**fields))
    time.sleep(2.0)
    assert fw.proc.poll() is None, "the 0.10.2 bridge survived the 11.0.1 peer:\n" + fw.text()
    r = c.sdo_read(3, 0x1018, 2)
    assert r.status == T.STATUS_OK and bytes(r.data) == (1).to_bytes(4, "little")
    # The samples the Python peer wrote reach the other Python client with every field.
    assert any(n.line == 250 for n in c.nodes())
    before = c.wait_bridge(1).time_ns
    until(lambda: c.wait_bridge(1).time_ns > before, 3, "the bridge still refreshing")


# --- watch, live --------------------------------------------------------------------------------

def test_watch_draws_the_network_in_place_in_a_terminal(firmware, client, domain):
    start_settled(firmware, client, *QUIET)
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, SCRIPT, "--domain", str(domain), "watch",
                             "--interval", "0.2"], stdout=slave, stderr=slave, close_fds=True)
    os.close(slave)
    out = b""
    end = time.monotonic() + 6
    try:
        while time.monotonic() < end:
            r, _, _ = select.select([master], [], [], 0.2)
            if r:
                try:
                    out += os.read(master, 65536)
                except OSError:
                    break
            if out.count(b"\x1b[H") >= 6:
                break
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(5)
        os.close(master)
    text = out.decode(errors="replace")
    assert text.startswith("\x1b[?25l\x1b[H\x1b[2J"), text[:40]
    assert text.count("\x1b[H") >= 4, "redrawn in place"
    last = text.split("\x1b[H")[-2]
    assert "bridge manager (safeline-dds 1.0, domain" in last
    for row in (r"0\s+1\s+manager\s+OPERATIONAL\s+local", r"0\s+2\s+hello_node\s+OPERATIONAL"
                r"\s+ok \d\.\ds\s+OK", r"0\s+5\s+hello_node\s+PRE-OPERATIONAL\s+\w+.*\s+M\s"):
        assert re.search(row, last), (row, last)
    assert proc.returncode == 0


# --- loopback only ----------------------------------------------------------------------------------

def test_the_bridge_ignores_cyclonedds_uri(firmware, client, tmp_path, domain):
    """CYCLONEDDS_URI naming a configuration on another interface changes nothing: the bridge
    passes its own loopback configuration (and the leak check after the test sees no packet)."""
    elsewhere = tmp_path / "elsewhere.xml"
    elsewhere.write_text('<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">'
                         '<General><Interfaces><NetworkInterface name="leak0" '
                         'multicast="true"/></Interfaces><AllowMulticast>true</AllowMulticast>'
                         '</General></Domain></CycloneDDS>')
    os.environ["CYCLONEDDS_URI"] = f"file://{elsewhere}"
    try:
        fw, c = start_settled(firmware, client, *QUIET)
        assert c.sdo_read(2, 0x1018, 1).status == T.STATUS_OK
    finally:
        del os.environ["CYCLONEDDS_URI"]


@pytest.mark.leaks
def test_the_leak_check_sees_a_participant_off_loopback(tmp_path):
    """The check itself: a participant on Cyclone's defaults (not pinned to lo) in this
    namespace sends on the veth pair, and the counters show it."""
    if not ISOLATED:
        pytest.skip(NETNS)
    if "leak0" not in testing.interfaces():
        pytest.skip(f"no veth pair to watch ({NETNS})")
    before = testing.leak_counters()
    code = ("from cyclonedds.domain import Domain, DomainParticipant; import time; "
            "d = Domain(99, '<CycloneDDS/>'); p = DomainParticipant(99); time.sleep(1.5)")
    env = {k: v for k, v in os.environ.items() if k != "CYCLONEDDS_URI"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       timeout=30)
    assert r.returncode == 0, r.stderr
    problem = testing.check_no_leak(before, testing.leak_counters())
    assert problem is not None and "leak" in problem, problem


def test_the_namespace(request):
    """Where the machine allows it, these tests run in a namespace of their own."""
    if not ISOLATED:
        pytest.skip(NETNS)
    assert os.environ.get(testing.MARK) == "1"
    assert set(testing.interfaces()) <= {"lo", "leak0", "leak1"}, testing.interfaces()
