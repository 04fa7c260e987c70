# SPDX-License-Identifier: Apache-2.0
"""NMT slave, heartbeat and node guarding of hello_node, seen by python-canopen on real vcan."""

import time

import can
import pytest

from conftest import NODE_ID

HB = 0x700 + NODE_ID


def frames_with_id(log, can_id, rtr=False):
    return [m for m in log if m.arbitration_id == can_id and m.is_remote_frame == rtr]


def test_boot_up_is_the_first_frame_and_heartbeat_follows(device, bus_log):
    device.start()
    deadline = time.monotonic() + 3.5
    while time.monotonic() < deadline and len(frames_with_id(bus_log, HB)) < 3:
        time.sleep(0.05)
    own = frames_with_id(bus_log, HB)
    assert own[0].dlc == 1 and own[0].data[0] == 0x00, "boot-up 700h+N: 00"
    assert [m.data[0] for m in own[1:3]] == [0x7F, 0x7F], "heartbeats in PRE-OPERATIONAL"
    # 1017h = 1000 ms; generous bounds inside the VM.
    period = own[2].timestamp - own[1].timestamp
    assert 0.7 < period < 1.5, period


def test_nmt_commands_and_the_states_the_heartbeat_shows(dut):
    dut.nmt.state = "OPERATIONAL"
    assert dut.nmt.wait_for_heartbeat(3) == "OPERATIONAL"
    dut.nmt.state = "STOPPED"
    assert dut.nmt.wait_for_heartbeat(3) == "STOPPED"
    dut.nmt.state = "PRE-OPERATIONAL"
    assert dut.nmt.wait_for_heartbeat(3) == "PRE-OPERATIONAL"


def test_broadcast_and_foreign_node_ids(dut, network):
    network.send_message(0x000, bytes([0x01, NODE_ID + 1]))
    time.sleep(0.3)
    assert dut.nmt.wait_for_heartbeat(3) == "PRE-OPERATIONAL", "command for another node"
    network.send_message(0x000, bytes([0x01, 0x00]))
    assert dut.nmt.wait_for_heartbeat(3) == "OPERATIONAL", "broadcast start"


def test_malformed_nmt_frames_are_ignored(dut, network):
    network.send_message(0x000, bytes([0x01]))
    network.send_message(0x000, bytes([0x01, NODE_ID, 0x00]))
    network.send_message(0x000, bytes([0x03, NODE_ID]))
    time.sleep(0.3)
    assert dut.nmt.wait_for_heartbeat(3) == "PRE-OPERATIONAL"


def test_reset_communication_sends_boot_up_again(dut, bus_log):
    dut.nmt.state = "OPERATIONAL"
    dut.nmt.wait_for_heartbeat(3)
    bus_log.clear()
    dut.nmt.state = "RESET COMMUNICATION"
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and not frames_with_id(bus_log, HB):
        time.sleep(0.02)
    own = frames_with_id(bus_log, HB)
    assert own and own[0].data[0] == 0x00, "boot-up first after the reset"
    assert dut.nmt.wait_for_heartbeat(3) == "PRE-OPERATIONAL"


def test_node_guarding_answers_with_toggle(dut, network, bus_log):
    # A heartbeat producer does not answer guarding; switch it off first (over SDO when the
    # server is there, else through NMT reset would restore it: use SDO).
    dut.sdo[0x1017].raw = 0
    bus_log.clear()
    for _ in range(4):
        network.send_message(HB, b"", remote=True)
        time.sleep(0.1)
    answers = [m.data[0] for m in frames_with_id(bus_log, HB)]
    assert answers == [0x7F, 0xFF, 0x7F, 0xFF]


def test_heartbeat_node_does_not_answer_guarding(dut, network, bus_log):
    dut.sdo[0x1017].raw = 100
    time.sleep(0.05)
    bus_log.clear()
    network.send_message(HB, b"", remote=True)
    time.sleep(0.35)
    answers = [m.data[0] for m in frames_with_id(bus_log, HB)]
    assert all(a == 0x7F for a in answers), "only heartbeats, no toggled answers"
    assert 2 <= len(answers) <= 5, answers
