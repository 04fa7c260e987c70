# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the manager sample on a real vcan interface, watched by python-canopen.

Run by twister's pytest harness (scenario sample.canopen.manager.interop, fixture vcan).
Every line of the image (the manager on line 0, in-process hello_node slaves on lines 1..)
is a SocketCAN socket on the same vcan, so python-canopen sees every frame of the boot.
"""

import os
import sys
import time

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, BusLog, Device, bus_log, eds, iface, image, network)

MANAGER_ID = 1


@pytest.fixture(scope="session")
def sample():
    return {"node_id": MANAGER_ID, "od_name": "manager", "up_marker": "manager: node 1 on"}


@pytest.fixture(scope="session")
def slave_eds():
    from safeline_interop import regenerated_eds
    return regenerated_eds("hello_node")


@pytest.fixture
def run_manager(image, iface, network, eds):
    """Start the manager with `slaves` hello_node slaves in the process (nodes 2..)."""
    started = []

    def start(slaves):
        args = [f"--can-if={n}:{iface}" for n in range(1, slaves + 1)]
        args += [f"--slaves={slaves}", "--cycle=0", "--cut=0"]
        d = Device(image, iface, network, eds, MANAGER_ID, "manager: node 1 on", args)
        started.append(d)
        d.start()
        return d

    yield start
    for d in started:
        d.stop()


def wait_output(device, text, timeout):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if any(text in line for line in list(device.lines)):
            return True
        time.sleep(0.05)
    return False
