# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the pdo_io image on a real vcan interface, faults made with the host's tools.

Run by twister's pytest harness (scenario sample.canopen.pdo_io.faults, fixture vcan): the
rows of doc/faults.md that vcan can express. The fixtures are shared with the other interop
suites (../lib/safeline_interop.py), plus `joined`: the image on the second interface, joined
to the tester's by can-gw, so that its line can be cut while the tester's socket lives on.
"""

import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, Device, bus_log, device, dut, eds, env, iface, image, network)

NODE_ID = 0x20


@pytest.fixture(scope="session")
def sample():
    return {"node_id": NODE_ID, "od_name": "pdo_io", "up_marker": "pdo_io: node"}


def cangw(*args):
    subprocess.run(["cangw", *args], check=True, timeout=30)


def join(a, b):
    """Frames written on either interface appear on the other (can-gw, both ways). The route
    from @p b (the node's) goes first: once the node hears @p a it may answer at once."""
    cangw("-A", "-s", b, "-d", a, "-e")
    cangw("-A", "-s", a, "-d", b, "-e")


@pytest.fixture
def dut_iface():
    ifaces = env("SAFELINE_CAN_IFACES").split(",")
    if len(ifaces) < 2:
        pytest.skip("needs two vcan interfaces")
    return ifaces[1]


@pytest.fixture
def joined(image, iface, dut_iface, network, eds, sample):
    """The device on the second interface, joined to the tester's; started."""
    join(iface, dut_iface)
    d = Device(image, dut_iface, network, eds, sample["node_id"], sample["up_marker"])
    try:
        d.start()
        yield d
    finally:
        d.stop()
        cangw("-F")
        subprocess.run(["ip", "link", "set", dut_iface, "up"], check=True, timeout=30)
