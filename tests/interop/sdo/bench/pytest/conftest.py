# SPDX-License-Identifier: Apache-2.0
"""The hello_node image on a real vcan, python-canopen as the SDO client (../../../lib)."""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, device, dut, eds, iface, image, network)

NODE_ID = 0x10


@pytest.fixture(scope="session")
def sample():
    return {"node_id": NODE_ID, "od_name": "hello_node", "up_marker": "hello_node: node"}
