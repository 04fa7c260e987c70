# SPDX-License-Identifier: Apache-2.0
"""Helpers for the DDS tests: a network namespace of their own, and the leak check.

The tests run every DDS participant on the loopback configuration. Where the machine allows
it, they also run inside a network namespace of their own (isolate()): `lo`, plus a veth pair
leak0/leak1 with IPv4 addresses and multicast, the kind of interface Cyclone would pick if a
participant were not pinned to `lo`. IPv6 is off on the pair, so nothing but a participant
that left loopback can make their packet counters move; the tests check them after each test
(leak_counters()). Where no namespace can be made, the tests still run, on the loopback
configuration only, and the namespace checks are skipped with the reason.
"""

import ctypes
import os
import subprocess

CLONE_NEWUSER = 0x10000000
CLONE_NEWNET = 0x40000000
LEAK_IFACES = ("leak0", "leak1")
MARK = "SAFELINE_DDS_NETNS"

_state = {"isolated": False, "reason": "isolate() was not called"}


def _unshare(flags):
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.unshare(flags) != 0:
        err = ctypes.get_errno()
        raise OSError(err, os.strerror(err))


def _write(path, text):
    with open(path, "w") as f:
        f.write(text)


def _ip(*args):
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True)


def isolate():
    """Move this process (and the processes it starts) into a new network namespace.

    Returns (True, description) or (False, why not). Call it before any thread or DDS
    participant exists (a user namespace needs a single-threaded process).
    """
    if _state["isolated"]:
        return True, _state["reason"]
    if os.environ.get(MARK) == "off":
        _state["reason"] = f"{MARK}=off"
        return False, _state["reason"]
    uid, gid = os.geteuid(), os.getegid()
    try:
        if uid == 0:
            _unshare(CLONE_NEWNET)
        else:
            _unshare(CLONE_NEWUSER | CLONE_NEWNET)
            _write("/proc/self/setgroups", "deny")
            _write("/proc/self/uid_map", f"0 {uid} 1")
            _write("/proc/self/gid_map", f"0 {gid} 1")
    except OSError as e:
        _state["reason"] = f"no network namespace on this machine (unshare: {e.strerror})"
        return False, _state["reason"]
    try:
        _ip("link", "set", "lo", "up")
    except (OSError, subprocess.CalledProcessError) as e:
        _state["reason"] = f"namespace made, but lo cannot be brought up ({e})"
        return False, _state["reason"]
    desc = "private network namespace with lo only"
    try:
        _ip("link", "add", LEAK_IFACES[0], "type", "veth", "peer", "name", LEAK_IFACES[1])
        for i, name in enumerate(LEAK_IFACES):
            _write(f"/proc/sys/net/ipv6/conf/{name}/disable_ipv6", "1")
            _ip("addr", "add", f"10.213.0.{i + 1}/24", "dev", name)
            _ip("link", "set", name, "multicast", "on", "up")
        desc = "private network namespace: lo and a veth pair leak0/leak1 (watched)"
    except (OSError, subprocess.CalledProcessError) as e:
        desc += f" (no veth pair: {e})"
    os.environ[MARK] = "1"
    _state.update(isolated=True, reason=desc)
    return True, desc


def isolated():
    return _state["isolated"], _state["reason"]


def _net_dev():
    """{interface: (tx_packets, rx_packets)} of this process's network namespace.

    /proc/net/dev follows the namespace of the reader (/sys/class/net would show the one
    sysfs was mounted in)."""
    out = {}
    with open("/proc/net/dev") as f:
        for line in f.readlines()[2:]:
            name, data = line.split(":", 1)
            fields = data.split()
            out[name.strip()] = (int(fields[9]), int(fields[1]))
    return out


def interfaces():
    return sorted(_net_dev())


def leak_counters():
    """{interface: (tx_packets, rx_packets)} of every interface but lo."""
    return {k: v for k, v in _net_dev().items() if k != "lo"}


def check_no_leak(before, after):
    """None, or a message naming the interfaces whose counters moved."""
    moved = {k: (before.get(k), v) for k, v in after.items() if before.get(k) != v}
    if not moved:
        return None
    return "packets left loopback: " + ", ".join(
        f"{k} tx/rx {b} -> {a}" for k, (b, a) in sorted(moved.items()))
