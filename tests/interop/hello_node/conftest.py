# SPDX-License-Identifier: Apache-2.0
"""Fixtures: the hello_node image on a real vcan interface, driven by python-canopen.

Run by twister's pytest harness (scenario sample.canopen.hello_node.interop, fixture vcan),
which sets SAFELINE_IMAGE, SAFELINE_BUILD_DIR and SAFELINE_CAN_IFACES inside the VM.
"""

import os
import subprocess
import time

import can
import canopen
import pytest

NODE_ID = 0x10


def _env(name):
    value = os.environ.get(name)
    if not value:
        pytest.skip(f"{name} is not set: run through scripts/twister -X vcan")
    return value


@pytest.fixture(scope="session")
def iface():
    return _env("SAFELINE_CAN_IFACES").split(",")[0]


@pytest.fixture(scope="session")
def image():
    return _env("SAFELINE_IMAGE")


@pytest.fixture(scope="session")
def eds():
    # The EDS as the firmware has it, regenerated from the built object dictionary.
    path = os.path.join(_env("SAFELINE_BUILD_DIR"), "canopen_od", "hello_node", "hello_node.eds")
    assert os.path.exists(path), path
    return path


@pytest.fixture
def network(iface):
    net = canopen.Network()
    net.connect(interface="socketcan", channel=iface, receive_own_messages=False)
    yield net
    net.disconnect()


@pytest.fixture
def bus_log(network):
    """Every frame on the bus from now on, with python-can's receive timestamps."""
    frames = []

    class Listener(can.Listener):
        def on_message_received(self, msg):
            frames.append(msg)

    listener = Listener()
    network.notifier.add_listener(listener)
    yield frames
    network.notifier.remove_listener(listener)


class Device:
    def __init__(self, image, iface, network, eds, node_id=NODE_ID):
        self.node = canopen.RemoteNode(node_id, eds)
        network.add_node(self.node)
        self.cmd = [image, f"--can-if=0:{iface}", f"--node-id={node_id}"]
        self.proc = None

    def start(self, wait_bootup=True):
        # Listen for the boot-up before the process exists, so it cannot be missed.
        got = {"bootup": False}

        def on_hb(state):
            if state == 0:
                got["bootup"] = True

        self.node.nmt.add_heartbeat_callback(on_hb)
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        line = self.proc.stdout.readline()
        while line and "up on" not in line:
            line = self.proc.stdout.readline()
        assert "hello_node: node" in line, f"image did not come up: {line!r}"
        if wait_bootup:
            end = time.monotonic() + 10
            while not got["bootup"] and time.monotonic() < end:
                time.sleep(0.01)
            assert got["bootup"], "no boot-up message"

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


@pytest.fixture
def dut(image, iface, network, eds):
    d = Device(image, iface, network, eds)
    d.start()
    yield d.node
    d.stop()


@pytest.fixture
def device(image, iface, network, eds):
    """The device, not yet started (tests that watch the start)."""
    d = Device(image, iface, network, eds)
    yield d
    d.stop()
