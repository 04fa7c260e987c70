# SPDX-License-Identifier: Apache-2.0
"""The manager's SDO client against a python-canopen LocalNode on a real vcan: python-canopen
plays slave 5, which the manager boots (identity uploads) and configures (concise DCF
downloads), then starts (CiA 302 §4, CiA 302-2 §3, CiA 301 §7.2.4).
"""

import struct
import threading
import time

import canopen

from conftest import wait_output

NMT = 0x000
SDO_RX, SDO_TX = 0x600, 0x580


def sent(log, can_id):
    return [m for m in list(log) if m.arbitration_id == can_id and not m.is_remote_frame]


def sdo_requests(log, node):
    """(ccs, index, sub) of every SDO request to `node`, in order."""
    return [(m.data[0] >> 5, struct.unpack_from("<H", bytes(m.data), 1)[0], m.data[3])
            for m in sent(log, SDO_RX + node) if m.dlc == 8]


def uploads(log, node):
    return [(i, s) for ccs, i, s in sdo_requests(log, node) if ccs == 2]


def test_manager_boots_and_configures_a_python_canopen_local_node(run_manager, network,
                                                                 slave_eds, bus_log):
    # Slave 5 is python-canopen's LocalNode with the hello_node dictionary and the product
    # code the manager expects for node 5 (1F86h sub 5 = 2).
    local = canopen.LocalNode(5, slave_eds)
    network.add_node(local)
    local.sdo[0x1018][2].raw = 2
    writes = {}

    def on_write(index, subindex, od, data):
        writes[(index, subindex)] = bytes(data)

    local.add_write_callback(on_write)

    def reboot():
        # Reset: boot-up, then Pre-operational (python-canopen's NmtSlave does not do this by
        # itself on a reset command).
        time.sleep(0.05)
        local.nmt.send_command(0x81)
        local.nmt.send_command(0x80)

    def on_nmt(can_id, data, timestamp):
        if data[0] in (0x81, 0x82) and data[1] in (0, 5):
            threading.Thread(target=reboot, daemon=True).start()

    network.subscribe(NMT, on_nmt)
    reboot()

    mgr = run_manager(3)
    assert wait_output(mgr, "NMT startup DONE", 20), "".join(mgr.lines[-20:])
    assert wait_output(mgr, "node   5  booted OK", 10) or any(
        line.startswith("     5  ") and " OK " in line for line in mgr.lines), \
        "".join(mgr.lines[-30:])

    # The manager's SDO client read the identity and wrote the concise DCF into the LocalNode.
    assert (0x1018, 2) in uploads(bus_log, 5) and (0x1018, 3) in uploads(bus_log, 5)
    assert struct.unpack("<H", writes[(0x1017, 0)])[0] == 100
    assert struct.unpack("<H", writes[(0x2001, 0)])[0] == 500
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and local.nmt.state != "OPERATIONAL":
        time.sleep(0.05)
    assert local.nmt.state == "OPERATIONAL", "the manager started node 5"
    local.nmt.stop_heartbeat()
