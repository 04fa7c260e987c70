import os
import re
from pathlib import Path


def test_own_interface():
    ifaces = os.environ["SAFELINE_CAN_IFACES"].split(",")
    assert len(ifaces) == 1 and re.fullmatch(r"vcan\d+", ifaces[0])
    proof = f"VCAN_VM={os.environ.get('VCAN_VM', '')} iface={ifaces[0]}"
    if os.environ.get("VCAN_VM") == "1":  # really inside scripts/vcan-vm: the interface is up
        flags = int(Path(f"/sys/class/net/{ifaces[0]}/flags").read_text(), 16)
        assert flags & 0x1, "interface is down"
        proof += " up"
    # The working directory is the build folder, shared with the host.
    Path("vm-proof.txt").write_text(proof + "\n")
