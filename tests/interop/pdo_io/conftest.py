# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the pdo_io image on a real vcan interface, driven by python-canopen.

Run by twister's pytest harness (scenario sample.canopen.pdo_io.interop, fixture vcan).
The fixtures are shared with the other interop suites (../lib/safeline_interop.py).
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, bus_log, device, dut, eds, iface, image, network)

NODE_ID = 0x20


@pytest.fixture(scope="session")
def sample():
    return {"node_id": NODE_ID, "od_name": "pdo_io", "up_marker": "pdo_io: node"}


def go_operational(node):
    node.nmt.state = "OPERATIONAL"
    # A heartbeat already on its way when the command left may still show the old state.
    states = [node.nmt.wait_for_heartbeat(3) for _ in range(2)]
    assert states[-1] == "OPERATIONAL", states


@pytest.fixture
def pre(dut):
    """The device in PRE-OPERATIONAL (where PDOs are remapped, CiA 301 §7.3.3) with its PDO
    configuration read back over SDO."""
    dut.tpdo.read(from_od=False)
    dut.rpdo.read(from_od=False)
    return dut


@pytest.fixture
def op(pre):
    """The device in OPERATIONAL with its PDO configuration read back over SDO."""
    go_operational(pre)
    return pre
