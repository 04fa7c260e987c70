# SPDX-License-Identifier: Apache-2.0
"""The DDS bridge on the test network (../src/main.c), driven through the image's stdin.

Line 0: gateway 1 (bridged, SDO client) and device 7; line 1: gateway 1 and device 9. The
bridge's configuration and allow-list are ../dds/."""

import re
import time

import pytest

from bridge_fixtures import SCRIPT  # noqa: F401
from safeline_dds import types as T
from safeline_dds.client import NMT_PREOP, NMT_START


def until(fn, timeout=10.0, what="condition"):
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


def up(c):
    n = nodes_of(c)
    return all(k in n and n[k].nmt_state == 5 and (n[k].local or n[k].heartbeat == T.HB_ACTIVE)
               for k in ((0, 1), (0, 7), (1, 1), (1, 9))) and n


@pytest.fixture
def net(firmware, client):
    fw = firmware(dds=False, stdin=True)
    fw.wait_log(r"^ready$")
    c = client("test")
    c.open_state()
    c.wait_bridge(10)
    until(lambda: up(c), 10, "both lines up")
    return fw, c


def test_two_lines_their_gateways_and_devices(net):
    fw, c = net
    b = until(lambda: c.wait_bridge(1).lines == 2 and c.wait_bridge(1), 3, "bridge state")
    assert (b.bridge, b.lines, b.nodes, b.queue_size) == ("testnet", 2, 2, 64)
    assert [(ln.line, ln.name, ln.can_state, ln.nodes) for ln in c.lines()] == \
        [(0, "gw0", 0, 1), (1, "gw1", 0, 1)]
    n = up(c)
    assert sorted(n) == [(0, 1), (0, 7), (1, 1), (1, 9)]
    for line in (0, 1):
        gw = n[(line, 1)]
        assert (gw.name, gw.local, gw.identity_mask) == ("gateway", True, 0x1F)
        assert (gw.vendor_id, gw.product_code, gw.revision, gw.serial) == \
            (0x539, 0x42, 0x10002, 7)
    for key in ((0, 7), (1, 9)):
        d = n[key]
        assert (d.name, d.local, d.heartbeat, d.boot_status) == ("bridge_test", False,
                                                                 T.HB_ACTIVE, T.BOOT_NONE)
        assert time.time_ns() - d.heartbeat_ns < 1e9, "a heartbeat every 100 ms"


def test_heartbeat_lost_and_back(net):
    fw, c = net
    fw.send("cut 0")
    d = until(lambda: nodes_of(c)[(0, 7)].heartbeat == T.HB_LOST and nodes_of(c)[(0, 7)],
              3, "device 7's heartbeat lost")
    time.sleep(0.6)
    d2 = nodes_of(c)[(0, 7)]
    assert d2.heartbeat_ns == d.heartbeat_ns, "no heartbeat since"
    assert nodes_of(c)[(1, 9)].heartbeat == T.HB_ACTIVE, "the other line is fine"
    fw.send("restore 0")
    until(lambda: nodes_of(c)[(0, 7)].heartbeat == T.HB_ACTIVE and
          nodes_of(c)[(0, 7)].heartbeat_ns > d.heartbeat_ns, 3, "device 7 back")


def test_emcy_received_with_history_for_late_joiners(net, cli):
    fw, c = net
    fw.send("emcy 0 0x5000")
    fw.send("clear 0 0x5000")
    fw.send("emcy 1 0x4200")
    until(lambda: len([e for e in c.emcys() if e.node_id in (7, 9)]) == 3, 5, "3 EMCY")
    e7 = [e for e in c.emcys() if (e.line, e.node_id) == (0, 7)]
    assert [(e.code, e.error_register, e.own, e.cob_id, e.seq) for e in e7] == \
        [(0x5000, 0x01, False, 0x87, 1), (0x0000, 0x00, False, 0x87, 2)]
    until(lambda: nodes_of(c)[(0, 7)].emcy_count == 2, 3, "emcy_count")
    rc, late, err = cli("emcy")
    assert rc == 0, err
    got = [(e["line"], e["node"], e["code_hex"], e["seq"]) for e in late if e["node"] != 1]
    assert sorted(got) == [(0, 7, "0000", 2), (0, 7, "5000", 1), (1, 9, "4200", 1)]


def test_srdo_safe_state(net, cli):
    fw, c = net
    fw.send("srdo 0 1 1 4")
    s = until(lambda: c.srdos().get((0, 1, 1)), 3, "SRDO 1")[0]
    assert (s.safe, s.reason, s.reason_text, s.transitions) == (True, 4, "SCT", 1)
    rc, nodes, err = cli("nodes")
    gw = next(n for n in nodes if (n["line"], n["node"]) == (0, 1))
    assert gw["safe_state"] and gw["srdo"] == [{"srdo": 1, "safe": True, "reason": "SCT"}]
    fw.send("srdo 0 1 0 0")
    until(lambda: not c.srdos()[(0, 1, 1)][0].safe, 3, "SRDO 1 valid")
    assert c.srdos()[(0, 1, 1)][0].transitions == 2
    fw.send("srdo 1 0 1 9")
    g = until(lambda: c.srdos().get((1, 1, 0)), 3, "the GFC")[0]
    assert (g.safe, g.reason_text) == (True, "GFC")
    assert sorted(c.srdos()) == [(0, 1, 1), (1, 1, 0)]


def test_can_controller_state(net):
    fw, c = net
    fw.send("canstate 0 2")
    ln = until(lambda: c.lines()[0].can_state == 2 and c.lines()[0], 3, "error-passive")
    assert ln.tx_err_cnt >= 128, "the controller's counter with the state"
    assert c.lines()[1].can_state == 0
    fw.send("canstate 0 0")
    until(lambda: c.lines()[0].can_state == 0, 3, "error-active again")


def test_active_line_follows_the_redundancy_switch(net, client):
    fw, c = net
    assert [ln.active_line for ln in c.lines()] == [0, 0]
    fw.send("switch 0 1")
    until(lambda: c.lines()[0].active_line == 1, 3, "line 0: redundant line active")
    assert c.lines()[1].active_line == 0, "the other gateway did not switch"
    fw.send("switch 0 0")
    until(lambda: c.lines()[0].active_line == 0, 3, "line 0: default line active again")
    # A reset picks the default line without a switch event: an NMT state change re-reads
    # the node's own view (this gateway has one line, so the default).
    fw.send("switch 0 1")
    until(lambda: c.lines()[0].active_line == 1, 3, "switched again")
    ops = client("ops")
    assert ops.nmt(1, NMT_PREOP).status == T.STATUS_OK
    until(lambda: c.lines()[0].active_line == 0, 3, "the node's own active line after NMT")
    assert ops.nmt(1, NMT_START).status == T.STATUS_OK


def stats(fw):
    """The bridge's counters as the image prints them (exact, at once)."""
    n = len(re.findall(r"^stats ", fw.text(), re.M))
    fw.send("stats")
    line = re.findall(r"^stats (.*)$", fw.text(), re.M)[n]
    words = line.split()
    return {words[i]: int(words[i + 1]) for i in range(0, len(words), 2)}


def test_a_full_queue_loses_events_counted_and_published(net):
    fw, c = net
    s0 = stats(fw)
    fw.send("burst 5000")
    s1 = stats(fw)
    lost = s1["lost"] - s0["lost"]
    assert lost > 0, "a burst of 5000 into a queue of 64"
    assert s1["events"] + s1["lost"] - s0["events"] - s0["lost"] == 5000, "each one counted"
    assert s1["queue_max"] == 64
    b = until(lambda: c.wait_bridge(1).events_lost == s1["lost"] and c.wait_bridge(1), 3,
              "the loss published in canopen/bridge_state")
    assert b.events >= s1["events"] and b.queue_max == 64
    until(lambda: c.lines()[0].events_lost == s1["lost"], 3, "and in line 0's state")
    assert c.lines()[1].events_lost == 0
    fw.wait_log(r"<wrn> canopen_bridge_dds: \d+ events lost so far: the queue \(64\) was full")
    # The bridge goes on.
    assert c.sdo_read(7, 0x2001, 0).status == T.STATUS_OK


def test_sdo_through_the_gateway_and_in_its_own_dictionary(net, client, cli):
    fw, c = net
    r = c.sdo_read(7, 0x2001, 0)
    assert (r.status, bytes(r.data), r.name, r.data_type) == (T.STATUS_OK, b"\xf4\x01",
                                                             "Setpoint", 6)
    rc, doc, err = cli("write", 7, "2002", 0, "--", "-12", client="ops")
    assert rc == 0 and doc["type"] == "INTEGER16", err
    rc, doc, err = cli("read", 7, "2002", 0, client="ops")
    assert rc == 0 and doc["value"] == -12, err
    rc, doc, err = cli("--line", 1, "read", 9, "1018", 2)
    assert rc == 0 and doc["value"] == 0x42, err
    # The gateway itself: its dictionary, with an SDO server's access rights.
    admin = client("admin")
    assert admin.sdo_write(1, 0x2000, 0, b"\x07\0\0\0").status == T.STATUS_OK
    assert bytes(admin.sdo_read(1, 0x2000, 0).data) == b"\x07\0\0\0"
    r = admin.sdo_write(1, 0x1018, 1, b"\0\0\0\0")
    assert (r.status, r.abort_code) == (T.STATUS_ABORTED, 0x06010002)
    r = admin.sdo_read(1, 0x6000, 0)
    assert (r.status, r.abort_code) == (T.STATUS_ABORTED, 0x06020000)
    # The allow-list by object range and client.
    test = client("test")
    assert test.sdo_write(9, 0x2001, 0, b"\x01\x00", line=1).status == T.STATUS_OK
    assert test.sdo_write(9, 0x1017, 0, b"\x01\x00", line=1).status == T.STATUS_REFUSED
    assert c.sdo_write(7, 0x2001, 0, b"\x01\x00").status == T.STATUS_OK, "test: 2000-20FF"


def test_nmt_without_a_master(net, client):
    fw, c = net
    admin = client("admin")
    r = admin.nmt(7, NMT_START)
    assert (r.status, r.message) == (T.STATUS_FAILED,
                                     "no NMT master among the bridged nodes of this line")
    ops = client("ops")
    r = ops.nmt(1, NMT_PREOP)
    assert (r.status, r.message) == (T.STATUS_OK, "applied to node 1 of the bridge's process")
    until(lambda: nodes_of(c)[(0, 1)].nmt_state == 127, 3, "gateway 0 PRE-OPERATIONAL")
    assert nodes_of(c)[(1, 1)].nmt_state == 5, "the other gateway is another node"
    assert ops.nmt(1, NMT_START).status == T.STATUS_OK
    until(lambda: nodes_of(c)[(0, 1)].nmt_state == 5, 3, "gateway 0 OPERATIONAL")


def test_object_values_local_and_remote(net, client):
    fw, c = net
    v = until(lambda: c.values().get((1, 9, 0x2002, 0)), 3, "device 9's temperature")[0]
    assert (bytes(v.data), v.data_type, v.size) == (b"\xfb\xff", 3, 2), "-5, INTEGER16"
    fw.send("count 0 42")
    until(lambda: bytes(c.values()[(0, 1, 0x2000, 0)][0].data) == b"\x2a\0\0\0", 1,
          "the gateway's counter within its 50 ms")
    changes = c.values()[(0, 7, 0x2001, 0)][0].changes
    assert client("admin").sdo_write(7, 0x2001, 0, b"\x58\x02").status == T.STATUS_OK
    v = until(lambda: bytes(c.values()[(0, 7, 0x2001, 0)][0].data) == b"\x58\x02" and
              c.values()[(0, 7, 0x2001, 0)][0], 2, "device 7's setpoint 600")
    assert v.changes == changes + 1, "published once per change"
    time.sleep(0.5)
    assert c.values()[(0, 7, 0x2001, 0)][0].changes == changes + 1, "not again unchanged"
