# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the interop suites: a SafeLine image on a real vcan interface, driven by
python-canopen.

Run by twister's pytest harness (fixture vcan), which sets SAFELINE_IMAGE, SAFELINE_BUILD_DIR
and SAFELINE_CAN_IFACES inside the VM. A suite's conftest.py imports this module and binds the
sample's name, node-ID and "up" line.
"""

import os
import subprocess
import threading

import can
import canopen
import pytest

SDO_TIMEOUT = 3.0


def env(name):
    value = os.environ.get(name)
    if not value:
        pytest.skip(f"{name} is not set: run through scripts/twister -X vcan")
    return value


def regenerated_eds(od_name):
    """The EDS as the firmware has it, regenerated from the built object dictionary."""
    path = os.path.join(env("SAFELINE_BUILD_DIR"), "canopen_od", od_name, f"{od_name}.eds")
    assert os.path.exists(path), path
    return path


def open_network(iface):
    net = canopen.Network()
    net.connect(interface="socketcan", channel=iface, receive_own_messages=False)
    return net


class BusLog(can.Listener):
    """Every frame on the bus from the time it is added, with python-can's timestamps."""

    def __init__(self):
        self.frames = []

    def on_message_received(self, msg):
        self.frames.append(msg)


class Device:
    """The image as a process; its output goes to image-<n>.log in the build folder."""

    runs = 0

    def __init__(self, image, iface, network, eds, node_id, up_marker, args=()):
        self.node = canopen.RemoteNode(node_id, eds)
        # python-canopen waits 0.3 s for an answer; inside the VM system calls are slow and a
        # 127-segment sub-block can take longer than that to be acknowledged.
        self.node.sdo.RESPONSE_TIMEOUT = SDO_TIMEOUT
        network.add_node(self.node)
        self.cmd = [image, f"--can-if=0:{iface}", f"--node-id={node_id}", *args]
        self.up_marker = up_marker
        self.proc = None
        self.up = threading.Event()
        self.lines = []
        Device.runs += 1
        self.log_path = os.path.join(os.environ.get("SAFELINE_BUILD_DIR", "."),
                                     f"image-{Device.runs}.log")

    def _drain(self):
        # Keep reading so the image never blocks on a full pipe.
        with open(self.log_path, "w") as log:
            for line in self.proc.stdout:
                log.write(line)
                log.flush()
                self.lines.append(line)
                if self.up_marker in line:
                    self.up.set()

    def start(self, wait_bootup=True):
        # Listen for the boot-up before the process exists, so it cannot be missed.
        got = threading.Event()

        def on_hb(state):
            if state == 0:
                got.set()

        self.node.nmt.add_heartbeat_callback(on_hb)
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.drain = threading.Thread(target=self._drain, daemon=True)
        self.drain.start()
        assert self.up.wait(10), f"image did not come up (see {self.log_path})"
        if wait_bootup:
            assert got.wait(10), "no boot-up message"

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self.proc is not None:
            # The whole output, including what the image prints on its way out.
            self.drain.join(timeout=10)


# --- Fixtures. A suite's conftest.py imports these and defines a `sample` fixture returning
# {"node_id": ..., "od_name": ..., "up_marker": ...}.


@pytest.fixture(scope="session")
def iface():
    return env("SAFELINE_CAN_IFACES").split(",")[0]


@pytest.fixture(scope="session")
def image():
    return env("SAFELINE_IMAGE")


@pytest.fixture(scope="session")
def eds(sample):
    return regenerated_eds(sample["od_name"])


@pytest.fixture
def network(iface):
    net = open_network(iface)
    yield net
    net.disconnect()


@pytest.fixture
def bus_log(network):
    """Every frame on the bus from now on, with python-can's receive timestamps."""
    listener = BusLog()
    network.notifier.add_listener(listener)
    yield listener.frames
    network.notifier.remove_listener(listener)


@pytest.fixture
def device(image, iface, network, eds, sample):
    """The device, not yet started (tests that watch the start)."""
    d = Device(image, iface, network, eds, sample["node_id"], sample["up_marker"])
    yield d
    d.stop()


@pytest.fixture
def dut(device):
    """The device, started and past its boot-up message; its python-canopen RemoteNode."""
    device.start()
    return device.node
