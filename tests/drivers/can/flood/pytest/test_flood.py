"""The SocketCAN driver under a receive flood, on a real vcan inside the VM.

The image (../src/main.c) sends 701h every 100 ms with can_send(K_NO_WAIT) and a callback, as
a CANopen line sends its heartbeat, and receives only the identifiers given to it. cangen
writes 100 000 frames of 0F0h back to back (vcan has no arbitration: the flood loads the
receive paths at full speed). A python-can socket whose kernel filter takes only 701h records
the periodic frames with the kernel's receive stamps.

Run by the test runner (scenario drivers.can.flood.socketcan, fixture vcan). By hand:

    scripts/vcan-vm --ifaces vcan0 -- env SAFELINE_IMAGE=<build>/zephyr/zephyr.exe \\
        SAFELINE_CAN_IFACES=vcan0 python3 -m pytest tests/drivers/can/flood/pytest
"""

import os
import subprocess
import sys
import threading
import time

import can

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "lib"))

from socketcan_peer import WAIT_S, Lines, cansend, iface, image  # noqa: E402,F401

PERIODIC_ID = 0x701
RT_PRIORITY = 20
PERIOD_S = 0.100
FLOOD_ID = "0F0"
FLOOD_FRAMES = 100000
QUIET_S = 5.0  # the quiet stretch after the flood whose period is printed for comparison


class Periodic:
    """The image's periodic frames as the bus saw them: (kernel stamp, sequence number)."""

    def __init__(self, iface):
        self.bus = can.Bus(interface="socketcan", channel=iface,
                           can_filters=[{"can_id": PERIODIC_ID, "can_mask": 0x7FF}])
        self.frames = []
        self.running = True
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        while self.running:
            m = self.bus.recv(timeout=0.2)
            if m is not None and m.arbitration_id == PERIODIC_ID and m.dlc == 4:
                self.frames.append((m.timestamp, int.from_bytes(m.data[:4], "little")))

    def wait_for(self, n, timeout=WAIT_S):
        end = time.monotonic() + timeout
        while len(self.frames) < n:
            assert time.monotonic() < end, f"only {len(self.frames)} periodic frames"
            time.sleep(0.05)

    def between(self, t0, t1):
        return [f for f in self.frames if t0 <= f[0] <= t1]

    def stop(self):
        self.running = False
        self.thread.join(timeout=5)
        self.bus.shutdown()


def start_image(image, iface, used=(), realtime=False):
    argv = [image, f"--can-if=0:{iface}"]
    if realtime:
        argv = ["chrt", "-f", str(RT_PRIORITY), *argv]
    if used:
        argv += ["--testargs", *used]
    dut = Lines(argv)
    dut.wait_for(lambda line: line == "READY")
    return dut


def stats(dut, iface):
    """The image's counters and the driver's statistics, as of now."""
    cansend(iface, "7FE#")
    line = dut.wait_for(lambda line: line.startswith("STATS "))
    return {k: int(v) for k, v in (kv.split("=") for kv in line.split()[1:])}


def finish(dut, iface):
    cansend(iface, "7FF#")
    dut.wait_for(lambda line: line == "QUIT")
    assert dut.proc.wait(timeout=WAIT_S) == 0, dut.seen


def flood(iface):
    """cangen's 100 000 frames; returns the wall-clock instants (the kernel stamps' clock) at
    which the flood began and ended."""
    t0 = time.time()
    subprocess.run(["cangen", iface, "-I", FLOOD_ID, "-L", "8", "-D", "i", "-g", "0",
                    "-n", str(FLOOD_FRAMES)], check=True, timeout=300)
    t1 = time.time()
    print(f"flood: {FLOOD_FRAMES} frames in {t1 - t0:.1f} s ({FLOOD_FRAMES / (t1 - t0):.0f}/s)")
    return t0, t1


def intervals_ms(frames):
    return [round((b[0] - a[0]) * 1000, 1) for a, b in zip(frames, frames[1:])]


def period_figures(frames, when):
    """Median interval and the fraction of intervals outside 100 ms +-10 %, printed."""
    steps = sorted(intervals_ms(frames))
    outside = [s for s in steps if not 90.0 <= s <= 110.0]
    median = steps[len(steps) // 2]
    print(f"period {when}: {len(steps)} intervals, median {median} ms, "
          f"{steps[0]}..{steps[-1]} ms, outside +-10 %: {len(outside)} {outside}")
    return steps, median, len(outside) / len(steps)


def test_a_flood_on_an_unused_identifier_never_reaches_the_socket(iface, image):
    """No filter wants 0F0h: the kernel filter drops the flood before the driver's socket,
    which reads nothing of it and loses nothing; every send succeeds and is confirmed by its
    echo, and the periodic frame keeps its period while the flood runs: no frame missing and
    the median interval within 100 ms +-2 %.

    The spread of the intervals is printed, for the flood and for a quiet stretch after it,
    not asserted: on the shared build machines (a load of 10-18 on two cores) the host holds
    the VM up now and then while cangen keeps it busy, by 10-30 ms and once by 270 ms with
    nothing of the flood read by the image, whatever the driver does; what the driver does
    (nothing with the flood) is asserted exactly."""
    periodic = Periodic(iface)
    # At a real-time priority inside the VM, as a node's line thread has on a target: cangen
    # takes all of the VM's one CPU and would otherwise decide when the image runs.
    dut = start_image(image, iface, realtime=True)
    try:
        periodic.wait_for(5)
        before = stats(dut, iface)
        t0, t1 = flood(iface)
        time.sleep(QUIET_S)
        t2 = time.time()
        after = stats(dut, iface)
        finish(dut, iface)
    finally:
        dut.stop()
        periodic.stop()
    print(f"before {before}\nafter {after}")

    during = periodic.between(t0, t1)
    assert len(during) >= int((t1 - t0) / PERIOD_S) - 1, "periodic frames missing"
    seqs = [s for _, s in during]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs))), "a send failed (sequence gap)"
    _, median, outside = period_figures(during, "during the flood")
    _, _, outside_quiet = period_figures(periodic.between(t1 + 0.5, t2), "after it (quiet)")
    print(f"outside +-10 %: {outside:.0%} of the intervals in the flood, "
          f"{outside_quiet:.0%} after it")
    assert 98.0 <= median <= 102.0, f"median interval {median} ms during the flood"

    # The socket read the second report frame and nothing of the flood.
    assert after["rx_frames"] - before["rx_frames"] == 1, (before, after)
    assert after["rx_overflows"] == 0, after
    assert after["eagain"] == 0 and after["failed"] == 0, after
    assert after["tx_timeout"] == 0 and after["tx_other"] == 0, after
    assert after["tx_ok"] == after["tx_confirmed"] >= after["sent"] - 1, after


def test_a_flood_on_a_used_identifier_overflows_the_socket_and_sending_recovers(iface, image):
    """A filter wants 0F0h: the flood reaches the socket, faster than the VM reads it, so its
    buffer overflows and echoes of the periodic frame are lost with flood frames. Their TX
    slots are released (TX callback -ETIMEDOUT) instead of being held for ever: once the flood
    is over, every periodic send succeeds and is confirmed again, at its period."""
    periodic = Periodic(iface)
    dut = start_image(image, iface, used=[FLOOD_ID])
    try:
        periodic.wait_for(5)
        before = stats(dut, iface)
        t0, t1 = flood(iface)
        time.sleep(1.5)  # the driver reads what is still queued
        settled = stats(dut, iface)
        t_settled = time.time()
        time.sleep(1.5)
        after = stats(dut, iface)
        t_after = time.time()
        finish(dut, iface)
    finally:
        dut.stop()
        periodic.stop()
    print(f"before {before}\nsettled {settled}\nafter {after}")

    # What this case is about: flood frames arrived, and the socket overflowed.
    assert settled["rx_used"] - before["rx_used"] > 1000, settled
    assert settled["rx_overflows"] > 0, "the flood did not overflow the socket: nothing tested"
    unconfirmed = settled["tx_echo_timeouts"] + settled["tx_echoes_lost"]
    print(f"during the flood: {unconfirmed} echoes lost or late, "
          f"{settled['eagain'] - before['eagain']} sends refused")
    assert settled["tx_timeout"] == unconfirmed, settled

    # After it: every send is accepted and confirmed, none is refused or released.
    sent = after["sent"] - settled["sent"]
    assert sent >= 10, (settled, after)
    assert after["eagain"] == settled["eagain"], "can_send() still refuses after the flood"
    # (the frame sent last may still wait for its echo)
    assert after["tx_ok"] - settled["tx_ok"] >= sent - 1, (settled, after)
    assert after["tx_timeout"] == settled["tx_timeout"], (settled, after)
    recent = periodic.between(t_settled, t_after)
    assert len(recent) >= 10, recent
    seqs = [s for _, s in recent]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs))), "a send failed after the flood"
