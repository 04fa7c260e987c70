# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the safety_io controller alone on a real vcan, fed by a foreign SRDO producer.

Run by twister's pytest harness (scenario sample.canopen.safety_io.interop, fixture vcan).
The image runs with --can-if=0:<vcan> only, so just the controller (node 1) starts; python-can
(producer.py, a process of its own) plays the sensor (node 5): pairs on 109h (normal) and 10Ah
(bitwise inverted) every 20 ms, or every 60 ms once the fault campaign has widened the
controller's timing over SDO. python-canopen (../lib/safeline_interop.py) is the NMT master
that resets the controller between faults, the SDO client and the EMCY consumer.
"""

import json
import os
import queue
import re
import subprocess
import sys
import threading
import time

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))

from safeline_interop import (  # noqa: E402
    BusLog, Device, env, open_network, regenerated_eds)

# The signature as scripts/srdo-sign computes it (scripts/pylib/srdo/signature.py).
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts", "pylib"))

from srdo.signature import signature  # noqa: E402

CONTROLLER_ID = 1
SENSOR_ID = 5
COB_NORMAL = 0xFF + 2 * SENSOR_ID  # 109h: SRDO 1's default COB-IDs of node 5
COB_INVERTED = 0x100 + 2 * SENSOR_ID  # 10Ah
EMCY = 0x80 + CONTROLLER_ID
# The sample's timing: the sensor's refresh time, the controller's SCT and SRVT (1301h sub 2,
# sub 3 of its signed dictionary).
SAMPLE_TIMING = {"period_ms": 20, "sct_ms": 50, "srvt_ms": 10}
# The timing the fault campaign sets over SDO (and signs): three times as wide, so that the
# VM's hiccups on the controller's receive path (10-20 ms under load, see the README) do not
# fake SRVT faults on good pairs.
WIDE_TIMING = {"period_ms": 60, "sct_ms": 150, "srvt_ms": 30}
PERIOD = SAMPLE_TIMING["period_ms"] / 1000
UP_MARKER = f"safety_io: controller node {CONTROLLER_ID} up"
# The controller's own measurement runs on its clock, but its line thread runs in a slow VM:
# the time it takes to get to a deadline or a frame is allowed on top of the protocol's bound.
VM_ALLOWANCE_MS = 100


class Controller(Device):
    """The image; keeps each console line with the host time it was read."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.timed = []

    def _drain(self):
        with open(self.log_path, "w") as log:
            for line in self.proc.stdout:
                log.write(line)
                log.flush()
                self.timed.append((time.monotonic(), line))
                self.lines.append(line)
                if self.up_marker in line:
                    self.up.set()

    def mark(self):
        return len(self.timed)

    def wait_line(self, pattern, since, timeout=5.0):
        """The first line from index `since` on that matches `pattern`: (host time, match)."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + timeout
        while True:
            for t, line in list(self.timed[since:]):
                m = rx.search(line)
                if m:
                    return t, m
            if time.monotonic() > deadline:
                tail = "".join(line for _, line in self.timed[since:][-20:])
                pytest.fail(f"no line matching {pattern!r} within {timeout} s; "
                            f"the controller printed:\n{tail}")
            time.sleep(0.01)

    def nmt_state(self):
        """The controller's NMT state as it last printed it."""
        for _, line in reversed(list(self.timed)):
            m = re.search(rf"controller: node {CONTROLLER_ID} ([A-Z-]+)", line)
            if m:
                return m.group(1)
        return None

    def lines_since(self, since):
        return [line for _, line in list(self.timed[since:])]


class Producer:
    """Client of producer.py, a foreign SRDO producer in a process of its own: every PERIOD a
    pair, the normal frame on 109h, then its bitwise complement on 10Ah, carrying
    [emergency stop pressed, counter]. One fault at a time can be put on the next pair; the
    producer can stop or slow down. Times are host CLOCK_MONOTONIC (time.monotonic())."""

    def __init__(self, iface):
        script = os.path.join(os.path.dirname(__file__), "producer.py")
        self.proc = subprocess.Popen(
            [sys.executable, script, iface, hex(COB_NORMAL), hex(COB_INVERTED), str(PERIOD)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        self.replies = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        ready = self._reply("ready", 10)
        self.realtime = ready.endswith("rt=1")

    def _read(self):
        for line in self.proc.stdout:
            self.replies.put(line.strip())

    def _reply(self, word, timeout=2.0):
        try:
            line = self.replies.get(timeout=timeout)
        except queue.Empty:
            pytest.fail(f"the producer did not answer {word!r} within {timeout} s")
        assert line.split()[0] == word, line
        return line

    def _cmd(self, text):
        self.proc.stdin.write(text + "\n")
        self.proc.stdin.flush()

    def good(self, estop=0, period=None):
        """Good pairs from now on (every `period` seconds from now on, if given)."""
        self._cmd(f"good {estop}" + (f" {period}" if period else ""))
        self._reply("ok")

    def inject(self, kind, byte=0, bit=0, delay=0.0):
        """Put a fault on the next pair; returns the time of the frame it is judged from."""
        args = {"corrupt-normal": f" {byte} {bit}", "corrupt-inverted": f" {byte} {bit}",
                "late-inverted": f" {delay}"}.get(kind, "")
        self._cmd(f"fault {kind}{args}")
        return float(self._reply("sent").split()[1])

    def stop_sending(self):
        """No more pairs; returns the time of the last good one."""
        self._cmd("stop")
        return float(self._reply("stopped").split()[1])

    def slow_down(self, period):
        """Pairs every `period` from the next one on; returns the time of the last pair at
        the normal rate."""
        self._cmd(f"slow {period}")
        return float(self._reply("slowed").split()[1])

    def foreign_frames(self):
        """COB-IDs of the frames someone else sent on 109h/10Ah since the last call."""
        self._cmd("foreign")
        return self._reply("foreign").split()[2:]

    def close(self):
        if self.proc.poll() is None:
            self._cmd("quit")
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


class Rig:
    """The controller, its foreign producer, and python-canopen as NMT master."""

    def __init__(self, controller, producer, network, bus_log):
        self.controller = controller
        self.producer = producer
        self.network = network
        self.bus_log = bus_log
        self.node = controller.node
        self.results = []
        self.spurious = []
        self.timing = dict(SAMPLE_TIMING)

    def recover(self, settle=0.3, attempts=3):
        """Good pairs again, then the controller through Pre-operational back to Operational
        (NMT from python-canopen): its SRDO must become valid, its output come on, and both
        stay so for `settle` seconds of good pairs.

        A fault during those seconds is put down to the VM: its SocketCAN receive path can
        hand an in-time inverted frame over after the SRVT deadline, or stamp it late (see the
        sample's README). Such a fault is recorded in `spurious` and the recovery tried again,
        `attempts` times in all."""
        for attempt in range(attempts):
            self.producer.good(period=self.timing["period_ms"] / 1000)
            since = self.controller.mark()
            self.pre_operational()
            self.node.nmt.send_command(0x01)  # start
            self.controller.wait_line(r"controller: SRDO 1 VALID", since)
            self.controller.wait_line(r"controller: output ON", since)
            time.sleep(settle)
            faults = [line.strip() for line in self.controller.lines_since(since)
                      if re.search(r"SAFE \((SCT|SRVT|NOT_INVERTED|SHORT)\)", line)]
            if not faults:
                return since
            self.spurious.extend(faults)
        pytest.fail(f"{attempts} recoveries in a row ended in a fault on good pairs: "
                    f"{self.spurious[-attempts:]}")

    def pre_operational(self):
        """NMT enter Pre-operational (from python-canopen), and wait until the controller is."""
        if self.controller.nmt_state() == "PRE-OPERATIONAL":
            return
        since = self.controller.mark()
        self.node.nmt.send_command(0x80)
        self.controller.wait_line(rf"controller: node {CONTROLLER_ID} PRE-OPERATIONAL", since)

    def srdo_params(self):
        """SRDO 1's covered parameters as the controller holds them, read over SDO."""
        comm, mapping = self.node.sdo[0x1301], self.node.sdo[0x1381]
        n = mapping[0].raw
        return dict(direction=comm[1].raw, cycle=comm[2].raw, srvt=comm[3].raw,
                    cob1=comm[5].raw, cob2=comm[6].raw,
                    entries=[mapping[k].raw for k in range(1, n + 1)])

    def configure(self, sct_ms, srvt_ms):
        """In Pre-operational: SCT and SRVT over SDO, the signature (computed by the Python
        of scripts/srdo-sign) into 13FFh:1, then 13FEh := A5h, which the controller accepts
        only after checking the configuration against the signature."""
        comm = self.node.sdo[0x1301]
        comm[2].raw = sct_ms
        comm[3].raw = srvt_ms
        crc = signature(**self.srdo_params())
        self.node.sdo[0x13FF][1].raw = crc
        self.node.sdo[0x13FE].raw = 0xA5
        return crc

    def emcys(self, since_frames=0):
        return [bytes(m.data) for m in list(self.bus_log)[since_frames:]
                if m.arbitration_id == EMCY]


@pytest.fixture(scope="module")
def wide(rig):
    """The controller reconfigured and signed over SDO for WIDE_TIMING, the producer at its
    period."""
    if rig.timing != WIDE_TIMING:
        rig.pre_operational()
        rig.configure(WIDE_TIMING["sct_ms"], WIDE_TIMING["srvt_ms"])
        rig.timing = dict(WIDE_TIMING)
    return rig


@pytest.fixture(scope="module")
def rig():
    iface = env("SAFELINE_CAN_IFACES").split(",")[0]
    image = env("SAFELINE_IMAGE")
    network = open_network(iface)
    log = BusLog()
    network.notifier.add_listener(log)
    producer = Producer(iface)
    controller = Controller(image, iface, network, regenerated_eds("controller"), CONTROLLER_ID,
                            UP_MARKER)
    r = Rig(controller, producer, network, log.frames)
    try:
        controller.start()
        yield r
    finally:
        controller.stop()
        producer.close()
        network.disconnect()
        path = os.path.join(os.environ.get("SAFELINE_BUILD_DIR", "."), "srdo-detection.json")
        with open(path, "w") as f:
            json.dump({"producer_realtime": producer.realtime, "timing": r.timing,
                       "detections": r.results,
                       "spurious_faults_on_good_pairs": r.spurious}, f, indent=1)
