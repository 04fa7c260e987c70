# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the hello_node image on a real vcan interface, driven by python-canopen.

Run by twister's pytest harness (scenario sample.canopen.hello_node.interop, fixture vcan).
The fixtures are shared with the other interop suites (../lib/safeline_interop.py).
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, bus_log, device, dut, eds, iface, image, network)

NODE_ID = 0x10


@pytest.fixture(scope="session")
def sample():
    return {"node_id": NODE_ID, "od_name": "hello_node", "up_marker": "hello_node: node"}
