# SPDX-License-Identifier: Apache-2.0
"""The SDO manager image on a real vcan; python-canopen is the SDO requesting device
(../../lib for the shared fixtures)."""

import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "lib"))

from safeline_interop import (  # noqa: E402,F401
    SDO_TIMEOUT, Device, bus_log, eds, iface, image, network, regenerated_eds)

MANAGER_ID = 0x01


@pytest.fixture(scope="session")
def sample():
    return {"node_id": MANAGER_ID, "od_name": "sdom_mgr", "up_marker": "sdom: manager"}


@pytest.fixture(scope="session")
def srd_eds():
    """The SRD's dictionary (1F10h, 1F11h, client entries 1280h-1282h) of the simulated suite."""
    return os.path.join(HERE, "..", "..", "..", "canopen", "mgr_sdom", "objdict", "sdom_srd.eds")


@pytest.fixture
def device(image, iface, network, eds, sample):
    """The image, not yet started: the manager on line 0, the slave on line 1, both sockets on
    the same interface."""
    d = Device(image, iface, network, eds, sample["node_id"], sample["up_marker"],
               [f"--can-if=1:{iface}"])
    yield d
    d.stop()
