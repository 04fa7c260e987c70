# SPDX-License-Identifier: Apache-2.0
"""python-canopen as an SDO requesting device of SafeLine's SDO manager (CiA 302 §7) on vcan.

The python SRD is a LocalNode at 7Fh (the manager scans from 127 down, so it is found
first). It configures the manager's COB-ID pool 1F02h over the manager's default SDO (the
way a tool configures a manager the first time), sets its own 1F10h and sends 6E0h. The
manager writes the SRD's 1280h and 1F10h; from then on the SRD talks to the manager only
over 1280h's COB-IDs, with its own SdoClient, and to the slave (0Ah) over the COB-IDs the
manager wrote into 1281h/1282h.
"""

import struct
import time

import canopen
import pytest
from canopen.sdo import SdoClient

from conftest import SDO_TIMEOUT

SRD_ID = 0x7F
SLAVE_ID = 0x0A
POOL = [0x6C0 + k for k in range(6)]
INVALID = 0x80000000


def req(index, slave):
    return struct.pack("<I", (index << 16) | (SRD_ID << 8) | slave)


def local(srd, index, sub=0):
    """A value of the SRD's own dictionary (what the manager wrote into it)."""
    return srd.sdo[index].raw if sub == 0 else srd.sdo[index][sub].raw


def wait_for(cond, timeout=10.0, what=""):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def client(network, od, c2s, s2c):
    """An SDO client on the COB-IDs of a client entry (client->server, server->client)."""
    c = SdoClient(c2s, s2c, od)
    c.RESPONSE_TIMEOUT = SDO_TIMEOUT
    c.network = network
    network.subscribe(s2c, c.on_response)
    return c


@pytest.fixture
def setup(device, network, srd_eds):
    """The image up, the manager's pool configured, the python SRD on the bus."""
    device.start()
    mgr = device.node
    # The manager's NMT startup resets every node first; let it pass.
    time.sleep(1.0)
    for k, cob in enumerate(POOL):
        mgr.sdo[0x1F02][k + 1].raw = cob
    srd = canopen.LocalNode(SRD_ID, srd_eds)
    network.add_node(srd)
    return mgr, srd


def register(network, srd, value=0x12800001):
    srd.sdo[0x1F10].raw = value
    network.send_message(0x6E0, b"")
    wait_for(lambda: local(srd, 0x1F10) & 1 == 0, what="the manager's answer in 1F10h")


def test_dynamic_channel_read_write_release(setup, network, bus_log, device):
    mgr, srd = setup
    register(network, srd)
    assert local(srd, 0x1F10) == 0x12800002, "Rq 0, state 1, index 1280h"
    c2s, s2c = local(srd, 0x1280, 1), local(srd, 0x1280, 2)
    assert (c2s, s2c) == (POOL[0], POOL[1])
    assert local(srd, 0x1280, 3) == 0x01
    to_mgr = client(network, device.node.object_dictionary, c2s, s2c)

    # A connection to the slave: its default SDO is free, so 1281h gets 60Ah/58Ah.
    to_mgr.download(0x1F00, 0, req(0x1281, SLAVE_ID))
    wait_for(lambda: local(srd, 0x1F10) == 0x12810006, what="1F10h = 12810006h")
    assert (local(srd, 0x1281, 1), local(srd, 0x1281, 2)) == (0x600 + SLAVE_ID, 0x580 + SLAVE_ID)

    # A second one: the default SDO is taken, a pool pair goes into the slave's 1201h.
    to_mgr.download(0x1F00, 0, req(0x1282, SLAVE_ID))
    wait_for(lambda: local(srd, 0x1F10) == 0x12820006, what="1F10h = 12820006h")
    c2s, s2c = local(srd, 0x1282, 1), local(srd, 0x1282, 2)
    assert (c2s, s2c) == (POOL[2], POOL[3])
    assert local(srd, 0x1282, 3) == SLAVE_ID

    # The SRD talks to the slave over the assigned COB-IDs only.
    to_slave = client(network, srd.object_dictionary, c2s, s2c)
    start = len(bus_log)
    value = struct.unpack("<I", to_slave.upload(0x2000, 0))[0]
    assert value == 0x12345678
    to_slave.download(0x2000, 0, struct.pack("<I", 0xCAFEF00D))
    assert struct.unpack("<I", to_slave.upload(0x2000, 0))[0] == 0xCAFEF00D
    # (Our own requests on c2s do not come back to this socket; the slave's answers do.)
    ids = {m.arbitration_id for m in bus_log[start:]}
    assert s2c in ids
    assert 0x580 + SLAVE_ID not in ids, "not over the default SDO"
    # The manager's table (1F03h over its default SDO, as a tool reads it).
    assert mgr.sdo[0x1F03][3].raw == (2 << 24) | (SRD_ID << 16) | (1 << 8) | SLAVE_ID

    # Release everything and de-register (slave 0): the SRD's entries become invalid last.
    to_mgr.download(0x1F01, 0, req(0, 0))
    wait_for(lambda: local(srd, 0x1280, 1) & INVALID, what="1280h invalid")
    for idx in (0x1281, 0x1282):
        assert local(srd, idx, 1) & INVALID and local(srd, idx, 2) & INVALID
    for k in range(1, 4):
        assert mgr.sdo[0x1F03][k].raw == 0
    for k, cob in enumerate(POOL):
        assert mgr.sdo[0x1F02][k + 1].raw == cob, "bit 30 cleared"


def test_heartbeat_loss_releases(setup, network, device):
    mgr, srd = setup
    # The manager consumes the SRD's heartbeat (500 ms); the SRD produces it every 100 ms.
    mgr.sdo[0x1016][1].raw = (SRD_ID << 16) | 500
    # Pre-operational (7Fh): a heartbeat with state 0 would read as a boot-up.
    srd.nmt.state = "PRE-OPERATIONAL"
    srd.nmt.start_heartbeat(100)
    register(network, srd)
    assert local(srd, 0x1F10) == 0x12800002
    to_mgr = client(network, device.node.object_dictionary, local(srd, 0x1280, 1),
                    local(srd, 0x1280, 2))
    to_mgr.download(0x1F00, 0, req(0x1281, SLAVE_ID))
    wait_for(lambda: local(srd, 0x1F10) == 0x12810006, what="1F10h = 12810006h")
    to_mgr.download(0x1F00, 0, req(0x1282, SLAVE_ID))
    wait_for(lambda: local(srd, 0x1F10) == 0x12820006, what="1F10h = 12820006h")
    time.sleep(1.0)
    assert mgr.sdo[0x1F03][3].raw != 0, "kept while the heartbeat runs"

    srd.nmt.stop_heartbeat()
    wait_for(lambda: local(srd, 0x1280, 1) & INVALID, timeout=15, what="release on loss")
    for idx in (0x1281, 0x1282):
        assert local(srd, idx, 1) & INVALID
    # The manager clears its 1F03h entries once the answer to its last write is in, which can
    # come after the SRD's copy of that write (python's server sets the value, then answers).
    wait_for(lambda: all(mgr.sdo[0x1F03][k].raw == 0 for k in range(1, 4)), timeout=5,
             what="1F03h cleared")
    # De-registered: a new 6E0h finds it again.
    register(network, srd)
    assert local(srd, 0x1F10) == 0x12800002
