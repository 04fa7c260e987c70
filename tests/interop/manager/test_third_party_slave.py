# SPDX-License-Identifier: Apache-2.0
"""The manager sample serves a network it only knows from a DCF written here (--dcf): two
python-canopen LocalNodes whose dictionary is a third-party EDS (python-canopen's CiA 402
example drive, tests/scripts/eds_corpus/third_party/python-canopen_e35.eds), at node-IDs the
bundled network does not use. Node 35 is mandatory, checked against the EDS's identity and
configured from the concise DCF its 1F22h entry names; node 36 ignores every NMT command, so
it stays Pre-operational after the manager's start, and the sample must show it so.
"""

import pathlib
import struct
import threading
import time

import canopen

from conftest import MANAGER_ID, wait_output
from safeline_interop import Device

EDS = (pathlib.Path(__file__).resolve().parents[2] / "scripts" / "eds_corpus" / "third_party" /
       "python-canopen_e35.eds")
GOOD, STUCK = 35, 36
NMT = 0x000


def network_dcf(tmp_path):
    # The identity python-canopen reads from the EDS: device type 00020192h (CiA 402 drive),
    # vendor FFh, product 1, revision 1.
    od = canopen.import_od(str(EDS), GOOD)
    ident = [od[0x1018][s].default for s in (1, 2, 3)]
    # CiA 306's mandatory objects first: the manager reads a DCF with scripts/eds2od's rules.
    lines = ["[1000]", "ParameterValue=0", "", "[1001]", "ParameterValue=0", "", "[1018]",
             "SubNumber=1", "", "[DeviceComissioning]", "NodeID=0x01", "", "[1F80]",
             "ParameterValue=0x00000001", "", "[1F89]", "ParameterValue=5000", ""]
    for index, values in (("1F81", {GOOD: 0x0D, STUCK: 0x05}),
                          ("1F84", {n: od[0x1000].default for n in (GOOD, STUCK)}),
                          ("1F85", {n: ident[0] for n in (GOOD, STUCK)}),
                          ("1F86", {n: ident[1] for n in (GOOD, STUCK)}),
                          ("1F87", {n: ident[2] for n in (GOOD, STUCK)})):
        lines += [f"[{index}]", "ObjectType=0x8", "CompactSubObj=127", "DataType=0x0007",
                  "DefaultValue=0", "", f"[{index}Value]", f"NrOfEntries={len(values)}"]
        lines += [f"0x{n:X}=0x{v:08X}" for n, v in values.items()] + [""]
    lines += ["[1016]", "SubNumber=9", "", "[1016sub1]", f"ParameterValue=0x00{GOOD:02X}012C",
              "", "[1016sub2]", f"ParameterValue=0x00{STUCK:02X}012C", ""]
    lines += ["[1F22]", "ObjectType=0x8", "SubNumber=128", "",
              f"[1F22sub{GOOD:X}]", "DataType=0x000F", "UploadFile=e35.bin", ""]
    # The concise DCF: heartbeat 100 ms, modes of operation (6060h, INTEGER8) = 3.
    cdcf = struct.pack("<I", 2)
    cdcf += struct.pack("<HBIH", 0x1017, 0, 2, 100)
    cdcf += struct.pack("<HBIb", 0x6060, 0, 1, 3)
    (tmp_path / "e35.bin").write_bytes(cdcf)
    path = tmp_path / "network.dcf"
    path.write_text("\n".join(lines) + "\n")
    return path, ident


def test_manager_boots_a_third_party_slave_from_its_dcf(image, iface, network, eds, tmp_path):
    dcf, ident = network_dcf(tmp_path)
    good = canopen.LocalNode(GOOD, str(EDS))
    stuck = canopen.LocalNode(STUCK, str(EDS))
    network.add_node(good)
    network.add_node(stuck)
    # Node 36 hears no NMT command: it never leaves Pre-operational.
    network.unsubscribe(NMT, stuck.nmt.on_command)
    writes = {}
    good.add_write_callback(lambda index, subindex, od, data:
                            writes.__setitem__((index, subindex), bytes(data)))

    def reboot(node):
        time.sleep(0.05)
        node.nmt.send_command(0x81)   # boot-up
        node.nmt.send_command(0x80)   # Pre-operational
        node.nmt.start_heartbeat(100)

    def on_nmt(can_id, data, timestamp):
        if data[0] in (0x81, 0x82):
            for node in (good, stuck):
                if data[1] in (0, node.id):
                    threading.Thread(target=reboot, args=(node,), daemon=True).start()

    network.subscribe(NMT, on_nmt)
    reboot(good)
    reboot(stuck)

    mgr = Device(image, iface, network, eds, MANAGER_ID, "manager: node 1 on",
                 [f"--dcf={dcf}", "--slaves=0", "--cycle=0", "--cut=0"])
    mgr.start()
    try:
        assert wait_output(mgr, "NMT startup DONE", 30), "".join(mgr.lines[-30:])
        out = "".join(mgr.lines)
        assert "waiting for nodes 35, 36 on the bus" in out, out
        row = f"    35  mandatory  {ident[0]:08X}  {ident[1]:08X}  {ident[2]:08X}  OK "
        assert row in out, out
        # The concise DCF named in 1F22h:23h reached the slave.
        assert struct.unpack("<H", writes[(0x1017, 0)])[0] == 100
        assert struct.unpack("<b", writes[(0x6060, 0)])[0] == 3
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and good.nmt.state != "OPERATIONAL":
            time.sleep(0.05)
        assert good.nmt.state == "OPERATIONAL", "the manager started node 35"
        assert wait_output(mgr, "node  35  OPERATIONAL", 5), "".join(mgr.lines[-30:])
        # Node 36 booted (identity right) but stayed Pre-operational: the sample says so.
        time.sleep(1.5)
        out = "".join(mgr.lines)
        assert "node  36  PRE-OPERATIONAL" in out, out
        assert "node  36  OPERATIONAL" not in out, out
        assert stuck.nmt.state == "PRE-OPERATIONAL"
    finally:
        mgr.stop()
        good.nmt.stop_heartbeat()
        stuck.nmt.stop_heartbeat()
