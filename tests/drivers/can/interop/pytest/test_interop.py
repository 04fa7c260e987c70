"""Our SocketCAN driver against can-utils (candump, cansend) and python-can on a real vcan.

Run by the test runner inside the vcan VM (fixture vcan): SAFELINE_IMAGE is the interop image
(src/main.c), SAFELINE_CAN_IFACES the interfaces reserved for this scenario. By hand:

    scripts/vcan-vm --ifaces vcan0 -- env SAFELINE_IMAGE=<build>/zephyr/zephyr.exe \\
        SAFELINE_CAN_IFACES=vcan0 python3 -m pytest tests/drivers/can/interop/pytest
"""

import os
import re
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "lib"))

from socketcan_peer import WAIT_S, Lines, cansend, iface, image  # noqa: E402,F401

GO = "7FD#"
QUIT = "7FF#"
PROBE_ID = 0x7FE


def parse_cansend(text):
    """can-utils frame syntax -> (ext, id, rtr, dlc, data bytes)."""
    ident, _, rest = text.partition("#")
    ext = len(ident) == 8
    if rest.startswith("R"):
        dlc = int(rest[1:] or "0")
        return (ext, int(ident, 16), True, dlc, b"")
    data = bytes.fromhex(rest)
    return (ext, int(ident, 16), False, len(data), data)


CANDUMP_LINE = re.compile(
    r"^\s*(?P<if>\S+)\s+(?P<id>[0-9A-F]{3}|[0-9A-F]{8})\s+\[(?P<dlc>\d)\]\s*(?P<rest>.*)$"
)


def parse_candump(line):
    """candump's default output line -> (ext, id, rtr, dlc, data), or None."""
    m = CANDUMP_LINE.match(line)
    if not m:
        return None
    ident = m.group("id")
    dlc = int(m.group("dlc"))
    rest = m.group("rest").strip()
    if rest == "remote request":
        return (len(ident) == 8, int(ident, 16), True, dlc, b"")
    return (len(ident) == 8, int(ident, 16), False, dlc, bytes.fromhex(rest.replace(" ", "")))


def start_image(image, iface, frames=()):
    argv = [image, f"--can-if=0:{iface}"]
    if frames:
        argv += ["--testargs", *frames]
    dut = Lines(argv)
    dut.wait_for(lambda line: line == "READY")
    return dut


def finish(dut, iface):
    cansend(iface, QUIT)
    dut.wait_for(lambda line: line == "QUIT")
    assert dut.proc.wait(timeout=WAIT_S) == 0, dut.seen


def start_candump(iface):
    """candump, started and proven to be listening (it has printed a probe frame)."""
    dump = Lines(["candump", iface])
    for _ in range(20):
        cansend(iface, f"{PROBE_ID:03X}#01")
        try:
            dump.wait_for(lambda line: (parse_candump(line) or (0, 0))[1] == PROBE_ID, timeout=2)
            return dump
        except AssertionError:
            continue
    dump.stop()
    raise AssertionError("candump did not start")


SENT_FRAMES = [
    "123#DEADBEEF",
    "000#",
    "7EF#0102030405060708",
    "0FF#00FF",
    "1ABCDEF0#112233",
    "00000001#",
    "1FFFFFFF#FFFFFFFFFFFFFFFF",
    "456#R",
    "456#R3",
    "18FF0000#R8",
]


def test_frames_we_send_appear_in_candump_exactly(iface, image):
    import can  # python-can: a second, independent reader

    dut = start_image(image, iface, SENT_FRAMES)
    dump = start_candump(iface)
    bus = can.Bus(interface="socketcan", channel=iface)
    try:
        cansend(iface, GO)
        dut.wait_for(lambda line: line.startswith("SENT "))
        assert f"SENT {len(SENT_FRAMES)}" in dut.seen

        got = []
        while len(got) < len(SENT_FRAMES):
            f = parse_candump(dump.wait_for(lambda line: parse_candump(line) is not None))
            if f[1] not in (PROBE_ID, 0x7FD) or f[0]:
                got.append(f)
        assert got == [parse_cansend(f) for f in SENT_FRAMES]

        seen = []
        end = time.monotonic() + WAIT_S
        while len(seen) < len(SENT_FRAMES) and time.monotonic() < end:
            m = bus.recv(timeout=1.0)
            if m is None or (not m.is_extended_id and m.arbitration_id in (PROBE_ID, 0x7FD)):
                continue
            seen.append(
                (m.is_extended_id, m.arbitration_id, m.is_remote_frame, m.dlc,
                 b"" if m.is_remote_frame else bytes(m.data))
            )
        assert seen == [parse_cansend(f) for f in SENT_FRAMES]
        finish(dut, iface)
    finally:
        bus.shutdown()
        dump.stop()
        dut.stop()


def test_cansend_frames_reach_our_filters(iface, image):
    # filters of the image: std 0x100..0x1FF, ext 0x18DAxxxx
    matching = ["100#01", "1FF#0203", "18DA00F1#AABBCCDD", "18DAFFFF#R2", "155#R5", "180#"]
    other = ["200#", "0FF#11", "18DB00F1#", "00000100#", "600#0102"]
    dut = start_image(image, iface)
    try:
        cansend(iface, GO)
        dut.wait_for(lambda line: line == "SENT 0")
        for a, b in zip(matching, other + [None]):
            cansend(iface, a)
            if b:
                cansend(iface, b)
        finish(dut, iface)
        rx = [parse_cansend(line[3:]) for line in dut.seen if line.startswith("RX ")]
        assert rx == [parse_cansend(f) for f in matching]
    finally:
        dut.stop()


def test_error_frames_reach_the_state_callback(iface, image):
    # (error frame as cansend writes it, expected "STATE <enum can_state>" [, counters])
    steps = [
        ("20000004#0008000000000000", 1, None),  # controller problem: TX warning
        ("20000204#0020000000008880", 2, (0x88, 0x80)),  # TX passive, counters 136/128
        ("20000040#0000000000000000", 3, None),  # bus-off
        ("20000100#0000000000000000", 0, None),  # controller restarted: error-active
    ]
    dut = start_image(image, iface)
    try:
        for frame, state, counters in steps:
            cansend(iface, frame)
            line = dut.wait_for(lambda line: line.startswith("STATE "))
            _, s, tec, rec = line.split()
            assert int(s) == state, (frame, line)
            if counters:
                assert (int(tec), int(rec)) == counters, (frame, line)
        cansend(iface, GO)
        dut.wait_for(lambda line: line == "SENT 0")
        finish(dut, iface)
    finally:
        dut.stop()
