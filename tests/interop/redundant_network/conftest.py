# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the redundant_network sample on two real vcan interfaces, watched by python-can.

Run by twister's pytest harness (scenario sample.canopen.redundant_network.interop, fixture
vcan, two interfaces): SAFELINE_CAN_IFACES names the default and the redundant line.
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import env, image  # noqa: E402,F401


@pytest.fixture(scope="session")
def lines():
    ifaces = env("SAFELINE_CAN_IFACES").split(",")
    if len(ifaces) < 2:
        pytest.skip("needs two interfaces (harness_config: can_lines: 2)")
    return ifaces[:2]
