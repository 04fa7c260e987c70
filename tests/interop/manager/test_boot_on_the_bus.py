# SPDX-License-Identifier: Apache-2.0
"""The manager sample on a real vcan: every line a socket on one interface, the traffic
checked from another socket (python-can).

Run by twister's pytest harness (scenario sample.canopen.manager.vcan, fixture vcan), which
sets SAFELINE_IMAGE and SAFELINE_CAN_IFACES inside the VM of scripts/vcan-vm.
"""

import os
import re
import subprocess

import can
import pytest

SLAVES = (2, 3, 4, 5)
# What objdict/slave.dcf makes the manager write, in this order (expedited SDO downloads).
CDCF = [
    (0x1017, 0, bytes.fromhex("6400")),
    (0x1020, 1, bytes.fromhex("333d0000")),
    (0x1020, 2, bytes.fromhex("8062ee01")),
    (0x2001, 0, bytes.fromhex("f401")),
]


def env(name):
    value = os.environ.get(name)
    if not value:
        pytest.skip(f"{name} is not set: run through scripts/twister -X vcan")
    return value


@pytest.fixture(scope="module")
def run():
    """One run of the sample (manager and four slaves, lines 0..4 on one interface)."""
    image = env("SAFELINE_IMAGE")
    iface = env("SAFELINE_CAN_IFACES").split(",")[0]
    bus = can.Bus(interface="socketcan", channel=iface, receive_own_messages=False)
    log = can.BufferedReader()
    notifier = can.Notifier(bus, [log])
    try:
        cmd = [image, "--stop-at=6", "--cut=0"] + [f"--can-if={n}:{iface}" for n in range(5)]
        out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             timeout=120)
    finally:
        notifier.stop()
        bus.shutdown()
    frames = []
    while (msg := log.get_message(0)) is not None:
        frames.append(msg)
    build = os.environ.get("SAFELINE_BUILD_DIR", ".")
    with open(os.path.join(build, "manager-vcan.log"), "w") as f:
        f.write(out.stdout)
    return out, frames


def test_boot_table(run):
    out, _ = run
    assert out.returncode == 0, out.stdout
    text = out.stdout
    for node in (2, 3, 4):
        assert re.search(rf"^ +{node}  \w+ +00000539  00000001  00010000  OK ", text, re.M), text
    assert re.search(r"^ +5  optional +00000539  00000001  - +M .*1018h:02 expected 00000002 "
                     r"actual 00000001$", text, re.M), text
    assert "manager: NMT startup DONE" in text
    assert re.search(r"node +4  booted OK", text), text


def nmt(frames, cs, node):
    return [i for i, f in enumerate(frames)
            if f.arbitration_id == 0 and bytes(f.data) == bytes([cs, node])]


def test_bus_order(run):
    _, frames = run
    resets = nmt(frames, 0x82, 0)
    assert resets, "no Reset Communication of all nodes"
    first_sdo = min(i for i, f in enumerate(frames) if 0x602 <= f.arbitration_id <= 0x605)
    assert resets[0] < first_sdo, "SDO to a slave before the startup's reset"
    # Never the manager itself (CiA 302-2 §3.1 d).
    assert not nmt(frames, 0x82, 1) and not nmt(frames, 0x81, 1)
    for node in (2, 3, 4):
        assert nmt(frames, 0x01, node), f"node {node} not started"
    assert not nmt(frames, 0x01, 5), "the mismatched node 5 was started"
    assert not nmt(frames, 0x01, 0), "1F80h bit 1 = 0: no start-all"


def test_identity_and_configuration(run):
    _, frames = run
    for node in SLAVES:
        reqs = [bytes(f.data) for f in frames if f.arbitration_id == 0x600 + node]
        uploads = [(r[1] | r[2] << 8, r[3]) for r in reqs if r[0] == 0x40]
        # 1000h always, then 1018h:01..03 (1F84h and 1F88h are 0); node 5 stops at :02.
        want = [(0x1000, 0), (0x1018, 1), (0x1018, 2)] + ([(0x1018, 3)] if node != 5 else [])
        assert uploads[:len(want)] == want, (node, uploads)
        downloads = [(r[1] | r[2] << 8, r[3], r[4:8 - ((r[0] >> 2) & 3)]) for r in reqs
                     if r[0] & 0xE3 == 0x23]
        if node == 5:
            assert not downloads, "node 5 failed the identity check: nothing to configure"
        else:
            # The first boot downloads the concise DCF in stream order; node 4 gets it once
            # more after its power cycle (1020h is 0 again).
            assert downloads[:len(CDCF)] == CDCF, (node, downloads)
