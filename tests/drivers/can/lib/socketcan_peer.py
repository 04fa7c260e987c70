# SPDX-License-Identifier: Apache-2.0
"""Shared by the pytest suites of tests/drivers/can: a test image or a can-utils tool as a
process whose output lines are waited for, and the fixtures the runner's environment gives.

Run by the test runner inside the vcan VM (fixture vcan): SAFELINE_IMAGE is the scenario's
image, SAFELINE_CAN_IFACES the interfaces reserved for it.
"""

import os
import queue
import shutil
import subprocess
import threading
import time

import pytest

WAIT_S = 30  # syscalls are slow inside UML: generous, but a hang still fails


class Lines:
    """A process whose stdout lines are read by a thread, to wait on with a deadline."""

    def __init__(self, argv):
        self.proc = subprocess.Popen(
            argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1
        )
        self.q = queue.Queue()
        self.seen = []
        threading.Thread(target=self._pump, daemon=True).start()

    def _pump(self):
        for line in self.proc.stdout:
            self.q.put(line.rstrip("\n"))
        self.q.put(None)

    def next(self, timeout=WAIT_S):
        line = self.q.get(timeout=timeout)
        if line is not None:
            self.seen.append(line)
        return line

    def wait_for(self, pred, timeout=WAIT_S):
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                raise AssertionError(f"timed out; output so far: {self.seen}")
            try:
                line = self.next(left)
            except queue.Empty:
                continue
            if line is None:
                raise AssertionError(f"process ended; output: {self.seen}")
            if pred(line):
                return line

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


@pytest.fixture(scope="module")
def iface():
    ifaces = os.environ.get("SAFELINE_CAN_IFACES", "")
    if not ifaces:
        pytest.skip("needs the vcan fixture (SAFELINE_CAN_IFACES): run via scripts/twister")
    for tool in ("candump", "cansend", "cangen"):
        assert shutil.which(tool), f"{tool} missing (can-utils: scripts/setup)"
    return ifaces.split(",")[0]


@pytest.fixture(scope="module")
def image():
    path = os.environ.get("SAFELINE_IMAGE")
    assert path and os.path.exists(path), "SAFELINE_IMAGE must name the built zephyr.exe"
    return path


def cansend(iface, frame):
    subprocess.run(["cansend", iface, frame], check=True, timeout=WAIT_S)
