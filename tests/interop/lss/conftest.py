# SPDX-License-Identifier: Apache-2.0
"""Fixtures: lss_node images (no node-ID) on a real vcan interface, commissioned by
python-canopen's LSS master (canopen.lss.LssMaster, network.lss).

Run by twister's pytest harness (scenario sample.canopen.lss_node.interop, fixture vcan).
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    BusLog, Device, bus_log, iface, image, network)

# A node-ID no test gives: the RemoteNode that Device adds to the network stays unused.
PLACEHOLDER_ID = 0x7E


@pytest.fixture(scope="session")
def sample():
    return {"node_id": PLACEHOLDER_ID, "od_name": "lss_node", "up_marker": "lss_node: serial"}


class LssDevice(Device):
    """lss_node with a serial number and, optionally, an LSS medium; no --node-id."""

    def __init__(self, image, iface, network, serial, lss_file=None):
        super().__init__(image, iface, network, None, PLACEHOLDER_ID, "lss_node: serial")
        self.cmd = [image, f"--can-if=0:{iface}", f"--serial={serial}"]
        if lss_file is not None:
            self.cmd.append(f"--lss-file={lss_file}")

    def start(self, wait_bootup=False):
        super().start(wait_bootup=wait_bootup)


@pytest.fixture
def lss_device(image, iface, network):
    """Start lss_node images: lss_device(serial, lss_file=None), stopped at the end."""
    started = []

    def start(serial, lss_file=None):
        d = LssDevice(image, iface, network, serial, lss_file)
        started.append(d)
        d.start()
        return d

    yield start
    for d in started:
        d.stop()


@pytest.fixture
def lss(network):
    """python-canopen's LSS master of the network, every node back in waiting afterwards."""
    master = network.lss
    yield master
    master.send_switch_state_global(master.WAITING_STATE)
