# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the flying_master sample on a real vcan interface, as two processes (one per
candidate) with a python-canopen LocalNode as the third slave.

Run by twister's pytest harness (scenario sample.canopen.flying_master.interop, fixture vcan).
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    BusLog, Device, bus_log, eds, iface, image, network, regenerated_eds)


@pytest.fixture(scope="session")
def sample():
    return {"node_id": 3, "od_name": "fm_manager", "up_marker": "flying_master: nodes"}
