# SPDX-License-Identifier: Apache-2.0
"""The CANopen samples' options (samples/canopen/common, the manager's own) and --can-if: a bad
value or an unusable interface ends the process before the node boots, with a non-zero exit code
and a message naming the option or the interface.

The samples are built here (SAFELINE_IMAGE is this folder's image), or taken from
SAFELINE_HELLO_NODE_IMAGE / SAFELINE_MANAGER_IMAGE when set."""

import os
import pathlib
import socket
import sys
from unittest import mock

import pytest

HERE = pathlib.Path(__file__).resolve().parent
SAMPLES = HERE.parents[3] / "samples" / "canopen"
sys.path.insert(0, str(HERE.parents[1] / "common"))

import safeline_image  # noqa: E402


def _build(name, tmp_path_factory):
    given = os.environ.get(f"SAFELINE_{name.upper()}_IMAGE")
    if given:
        return pathlib.Path(given)
    with mock.patch.dict(os.environ):
        os.environ.pop("SAFELINE_IMAGE", None)
        return safeline_image.image_path(SAMPLES / name, tmp_path_factory.mktemp(name))


@pytest.fixture(scope="session")
def hello_node(tmp_path_factory):
    return _build("hello_node", tmp_path_factory)


@pytest.fixture(scope="session")
def manager(tmp_path_factory):
    return _build("manager", tmp_path_factory)


def _run(image, *args):
    try:
        return safeline_image.run(image, *args, timeout=30)
    except Exception as exc:  # noqa: BLE001 - a hang is a failure like any other
        raise AssertionError(f"{args}: {exc}") from exc


def host_has_af_can():
    try:
        socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW).close()
    except (AttributeError, OSError):
        return False
    return True


def assert_refused(result, option, args):
    assert result.returncode != 0, f"{args}: exit code 0"
    assert result.returncode == 1, f"{args}: exit code {result.returncode}"
    assert "Booting" not in result.stdout, f"{args}: the firmware booted"
    assert " up on " not in result.stdout, f"{args}: the node booted"
    assert result.stdout.startswith("Usage:"), f"{args}: no usage on stdout"
    assert f"--{option}" in result.stderr, f"{args}: the error does not name --{option}"


@pytest.mark.parametrize("value", ["4294967295", " -18446744073709551615", "-18446744073709551615",
                                   "18446744073709551617", "0", "128", "200", "-1", "+16", "16x",
                                   "0x", "", "nan"])
def test_hello_node_refuses_bad_node_id(hello_node, value):
    args = (f"--node-id={value}", "--stop-at=2")
    assert_refused(_run(hello_node, *args), "node-id", args)


@pytest.mark.parametrize("value,node", [("1", 1), ("127", 127), ("0x7f", 127), ("017", 15)])
def test_hello_node_accepts_good_node_id(hello_node, value, node):
    result = _run(hello_node, f"--node-id={value}", "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert f"hello_node: node {node} up on can_virtual0" in result.stdout


def test_hello_node_default_runs_on_the_virtual_bus(hello_node):
    result = _run(hello_node, "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert "hello_node: node 16 up on can_virtual0" in result.stdout
    assert "Stopped at 0.300s" in result.stdout


@pytest.mark.parametrize("value", ["+0:vcan0", " 0:vcan0", "-0:vcan0", "0x:vcan0", "9:vcan0",
                                   "0:", "0", "vcan0", "0:an-interface-name-too-long"])
def test_can_if_refuses_malformed_values(hello_node, value):
    args = (f"--can-if={value}", "--stop-at=2")
    assert_refused(_run(hello_node, *args), "can-if", args)


def test_can_if_missing_interface_fails_before_the_node_boots(hello_node):
    result = _run(hello_node, "--can-if=0:nonexistent", "--stop-at=2")
    assert result.returncode != 0, "ran on the virtual bus instead"
    assert result.returncode == 1
    assert "nonexistent" in result.stderr, result.stderr
    assert "--can-if" in result.stderr
    assert "Booting" not in result.stdout
    assert " up on " not in result.stdout
    if not host_has_af_can():
        assert "SocketCAN not available on this host" in result.stderr
    else:
        assert "No such device" in result.stderr


@pytest.mark.skipif(host_has_af_can(), reason="the host has AF_CAN (vcan0 may exist)")
def test_can_if_without_af_can_fails_with_the_reason(hello_node):
    result = _run(hello_node, "--can-if=0:vcan0", "--stop-at=2")
    assert result.returncode == 1, "ran on the virtual bus instead"
    assert "vcan0" in result.stderr
    assert "SocketCAN not available on this host" in result.stderr
    assert "Booting" not in result.stdout


@pytest.mark.parametrize("args,option", [
    (("--slaves=5",), "slaves"),
    (("--slaves=4294967295",), "slaves"),
    (("--slaves=-1",), "slaves"),
    (("--slaves= -18446744073709551615",), "slaves"),
    (("--cycle=4294967295",), "cycle"),
    (("--cycle=128",), "cycle"),
    (("--cut=abc",), "cut"),
    (("--cut=4294967295",), "cut"),
    (("--node-id=4294967295",), "node-id"),
    (("--node-id=3",), "node-id"),
])
def test_manager_refuses_bad_options(manager, args, option):
    args = (*args, "--stop-at=2")
    assert_refused(_run(manager, *args), option, args)


def test_manager_good_options(manager):
    result = _run(manager, "--slaves=0", "--cycle=0", "--cut=0", "--node-id=0x7f",
                  "--stop-at=0.3")
    assert result.returncode == 0, result.stderr
    assert "manager: no slaves in this process" in result.stdout
    assert "manager: node 127 on can_virtual0" in result.stdout
