# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the DDS bridge tests (manager/, network/pytest/, bench/pytest/); their
conftest.py import everything from here.

Before anything else the test process moves into a network namespace of its own (where the
machine allows it): every participant it starts, the firmware's bridge and the clients, runs
there on the loopback configuration, and after each test the counters of the namespace's
other interfaces must not have moved."""

import itertools
import os
import re
import subprocess
import sys
import time

BASE = os.environ.get("SAFELINE_BASE") or os.path.abspath(
    os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))

from safeline_dds import testing  # noqa: E402

ISOLATED, NETNS = testing.isolate()

import pytest  # noqa: E402

SCRIPT = os.path.join(BASE, "scripts", "safeline-dds")
# Domains 11.. per test. In a namespace of its own a test process has them to itself; without
# one, test processes running at the same time share the host's loopback, so each starts at
# an offset of its own (fewer collisions, not none).
_domains = itertools.count(11 + (0 if ISOLATED else (os.getpid() % 6) * 36))


@pytest.fixture(autouse=True)
def no_dds_packet_leaves_loopback(request):
    if not ISOLATED:
        yield
        return
    before = testing.leak_counters()
    yield
    if request.node.get_closest_marker("leaks"):
        return
    problem = testing.check_no_leak(before, testing.leak_counters())
    assert problem is None, problem


@pytest.fixture
def domain():
    """A DDS domain of the test's own: a killed bridge of an earlier test (its lease lasts
    5 s) is never mistaken for this test's."""
    return next(_domains)


class Firmware:
    def __init__(self, image, args, log_path, stdin=False):
        self.args = args
        self.log_path = log_path
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen([image, *args], stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
                                     text=True)

    def send(self, command, timeout=30.0):
        """A command of an image that reads them (tests/canopen/bridge/network)."""
        pattern = rf"^(ok|error) {re.escape(command)}(: .*)?$"
        seen = len(re.findall(pattern, self.text(), re.M))
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            answers = list(re.finditer(pattern, self.text(), re.M))
            if len(answers) > seen:
                assert answers[seen].group(1) == "ok", answers[seen].group(0)
                return
            time.sleep(0.02)
        raise AssertionError(f"no answer to '{command}':\n{self.text()}")

    def text(self):
        with open(self.log_path) as f:
            return f.read()

    def wait_log(self, pattern, timeout=15.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            m = re.search(pattern, self.text(), re.M)
            if m:
                return m
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise AssertionError(f"no '{pattern}' in the firmware's output:\n{self.text()}")

    def stop(self):
        if self.proc.poll() is None:
            if self.proc.stdin is not None:
                self.proc.stdin.close()
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.log.close()
        return self.proc.returncode

    def kill(self):
        self.proc.kill()
        self.proc.wait()
        self.log.close()


@pytest.fixture
def firmware(tmp_path, domain):
    """start(*args): the manager sample with --dds on the test's domain."""
    image = os.environ.get("SAFELINE_IMAGE")
    if not image:
        pytest.skip("SAFELINE_IMAGE not set (run through twister)")
    started = []

    def start(*args, dds=True, stdin=False):
        argv = list(args)
        if dds:
            argv = ["--dds", f"--dds-domain={domain}", *argv]
        elif domain is not None:
            argv = [f"--dds-domain={domain}", *argv]
        fw = Firmware(image, argv, tmp_path / f"firmware{len(started)}.log", stdin)
        started.append(fw)
        return fw

    yield start
    for fw in started:
        if fw.proc.poll() is None:
            fw.stop()
    for fw in started:
        bad = re.search(r"^.*(Sanitizer|runtime error:|SAFELINE FATAL ERROR).*$", fw.text(), re.M)
        assert bad is None, f"{fw.log_path}: {bad.group(0)}"


@pytest.fixture
def client(domain):
    """A client library object on the test's domain (this process)."""
    from safeline_dds.client import BridgeClient

    made = []

    def make(name="test", **kw):
        c = BridgeClient(domain, name=name, **kw)
        made.append(c)
        return c

    yield make
    for c in made:
        c.close()


@pytest.fixture
def cli(domain):
    """Run scripts/safeline-dds in a process of its own (a late joiner); --json output."""
    import json

    def run(*args, client="test", timeout=60, json_out=True):
        argv = [sys.executable, SCRIPT, "--domain", str(domain), "--client", client]
        if json_out:
            argv.append("--json")
        r = subprocess.run(argv + [str(a) for a in args], capture_output=True, text=True,
                           timeout=timeout)
        doc = None
        if json_out and r.stdout.strip():
            doc = json.loads(r.stdout.strip().splitlines()[-1])
        return r.returncode, doc, r.stderr

    return run
