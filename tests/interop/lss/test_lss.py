# SPDX-License-Identifier: Apache-2.0
"""python-canopen's LSS master (canopen.lss.LssMaster) against our LSS slave on a real vcan.

The slave is samples/canopen/lss_node: no node-ID (FFh), LSS address 539h / 105h / 10000h /
serial (--serial). What python-canopen 2.4.1's master does, read in its source, and what the
tests therefore expect:
- every request that has an answer waits LssMaster.RESPONSE_TIMEOUT (0.5 s); no answer raises
  LssError, also for a selective switch that no slave takes (it never returns False);
- a selective switch and identify remote slave sleep 0.2 s after each of their frames;
- identify remote slave and identify non-configured do not wait for the answers: the tests
  read them from the bus;
- inquire node-ID gives our FFh for a node without node-ID;
- fast_scan() probes (BitCheck 80h), then for each part sends BitCheck 31..0 with LSSNext =
  LSSSub (the previous part's LSSNext) and sets a bit when nobody answers, then a verify with
  BitCheck 0 and LSSNext = the next part; the last verify (LSSNext 0 < LSSSub 3) selects the
  node with the lowest LSS address, which enters configuration. A step nobody answers costs
  the full timeout, so a scan takes about 0.5 s per 1 bit of the address.
"""

import time

import pytest
from canopen.lss import (CS_INQUIRE_NODE_ID, CS_INQUIRE_PRODUCT_CODE,
                         CS_INQUIRE_REVISION_NUMBER, CS_INQUIRE_SERIAL_NUMBER,
                         CS_INQUIRE_VENDOR_ID, LssError)

VENDOR = 0x539
PRODUCT = 0x105
REVISION = 0x10000
UNCONFIGURED = 0xFF


def frames(log, cob_id, first_byte=None):
    return [m for m in list(log)
            if m.arbitration_id == cob_id and (first_byte is None or m.data[0] == first_byte)]


def wait_frame(log, cob_id, first_byte=None, timeout=5.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = frames(log, cob_id, first_byte)
        if found:
            return found[0]
        time.sleep(0.02)
    return None


def wait_line(device, text, timeout=5.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if any(text in line for line in list(device.lines)):
            return True
        time.sleep(0.02)
    return False


def test_switch_global_and_inquire_identity(lss_device, lss, bus_log):
    lss_device(0x1234)
    time.sleep(0.5)
    assert not [m for m in list(bus_log) if 0x701 <= m.arbitration_id <= 0x77F], \
        "a node without node-ID sends no boot-up or heartbeat"
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    assert lss.inquire_lss_address(CS_INQUIRE_VENDOR_ID) == VENDOR
    assert lss.inquire_lss_address(CS_INQUIRE_PRODUCT_CODE) == PRODUCT
    assert lss.inquire_lss_address(CS_INQUIRE_REVISION_NUMBER) == REVISION
    assert lss.inquire_lss_address(CS_INQUIRE_SERIAL_NUMBER) == 0x1234
    assert lss.inquire_node_id() == UNCONFIGURED
    answer = frames(bus_log, 0x7E4, CS_INQUIRE_NODE_ID)[-1]
    assert bytes(answer.data) == bytes([0x5E, 0xFF, 0, 0, 0, 0, 0, 0])

    # Back in waiting, configuration requests are not answered.
    lss.send_switch_state_global(lss.WAITING_STATE)
    with pytest.raises(LssError):
        lss.inquire_node_id()


def test_switch_selective_takes_only_the_matching_address(lss_device, lss):
    lss_device(0x55)
    with pytest.raises(LssError, match="No LSS response"):
        lss.send_switch_state_selective(VENDOR, PRODUCT, REVISION, 0x56)
    with pytest.raises(LssError):
        lss.inquire_node_id()
    assert lss.send_switch_state_selective(VENDOR, PRODUCT, REVISION, 0x55) is True
    assert lss.inquire_node_id() == UNCONFIGURED


def test_configure_node_id_boots_the_node(lss_device, lss, bus_log):
    d = lss_device(0x77)
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    lss.configure_node_id(0x22)
    # Out of range is refused with error 1 (python-canopen raises it).
    with pytest.raises(LssError, match="LSS Error: 1"):
        lss.configure_node_id(0x80)
    # Configured, not yet active: inquire node-ID still answers FFh.
    assert lss.inquire_node_id() == UNCONFIGURED
    lss.send_switch_state_global(lss.WAITING_STATE)
    bootup = wait_frame(bus_log, 0x722, 0x00)
    assert bootup is not None, "boot-up on 722h after the switch to waiting"
    assert wait_frame(bus_log, 0x722, 0x7F) is not None, "heartbeat (Pre-operational) on 722h"
    assert wait_line(d, "lss_node: node-ID 34,")
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    assert lss.inquire_node_id() == 0x22


def test_bit_timing_configure_and_activate(lss_device, lss):
    lss_device(0x78)
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    lss.configure_bit_timing(3)  # 250 kbit/s: the SocketCAN driver takes it
    with pytest.raises(LssError, match="LSS Error: 1"):
        lss.configure_bit_timing(9)  # automatic detection: not supported
    # Silent for two delays, then it answers again (vcan has no rate to change).
    lss.activate_bit_timing(100)
    time.sleep(0.5)
    assert lss.inquire_node_id() == UNCONFIGURED


def test_store_configuration_and_restart(lss_device, lss, bus_log, tmp_path):
    medium = tmp_path / "lss.bin"
    d = lss_device(0x99, str(medium))
    assert wait_line(d, "nothing stored")
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    lss.configure_node_id(0x23)
    lss.store_configuration()
    lss.send_switch_state_global(lss.WAITING_STATE)
    assert wait_frame(bus_log, 0x723, 0x00) is not None
    d.stop()

    # Power cycle: the stored node-ID is the first reset's, no LSS needed.
    bus_log.clear()
    d2 = lss_device(0x99, str(medium))
    assert wait_line(d2, "stored node-ID 35 loaded")
    assert wait_frame(bus_log, 0x723, 0x00) is not None, "boots on 723h by itself"


def test_store_without_medium_is_not_supported(lss_device, lss):
    lss_device(0x9A)
    lss.send_switch_state_global(lss.CONFIGURATION_STATE)
    with pytest.raises(LssError, match="LSS Error: 1"):
        lss.store_configuration()


def test_identify_non_configured_and_remote_slave(lss_device, lss, bus_log):
    lss_device(0x42)
    lss.send_identify_non_configured_remote_slave()
    assert wait_frame(bus_log, 0x7E4, 0x50) is not None
    lss.send_identify_remote_slave(VENDOR, PRODUCT, 0, 0xFFFFFFFF, 0x40, 0x42)
    assert wait_frame(bus_log, 0x7E4, 0x4F) is not None
    n = len(frames(bus_log, 0x7E4, 0x4F))
    lss.send_identify_remote_slave(VENDOR, PRODUCT, 0, 0xFFFFFFFF, 0x43, 0x50)
    time.sleep(0.5)
    assert len(frames(bus_log, 0x7E4, 0x4F)) == n, "serial outside the range: no answer"


def test_fast_scan_finds_and_selects_the_node(lss_device, lss, bus_log, record_property):
    d = lss_device(0x2A)
    t0 = time.monotonic()
    found, address = lss.fast_scan()
    took = time.monotonic() - t0
    assert found, "python-canopen's fastscan found nothing"
    assert address == [VENDOR, PRODUCT, REVISION, 0x2A]
    # Figures for doc/lss.md, in report.xml.
    record_property("fast_scan_s", f"{took:.2f}")
    # Requests: 1 probe + 4 x (32 bit steps + 1 verify) = 133 (our own frames are not logged).
    record_property("fast_scan_answers", len(frames(bus_log, 0x7E4, 0x4F)))
    assert wait_line(d, "lss_node: LSS configuration")
    # Selected: in configuration, it takes a node-ID.
    assert lss.inquire_node_id() == UNCONFIGURED
    lss.configure_node_id(0x24)
    lss.send_switch_state_global(lss.WAITING_STATE)
    assert wait_frame(bus_log, 0x724, 0x00) is not None


def test_fast_scan_finds_two_nodes_one_after_the_other(lss_device, lss, bus_log):
    lss_device(0x31)
    lss_device(0x30)
    found, address = lss.fast_scan()
    assert found and address == [VENDOR, PRODUCT, REVISION, 0x30], "the lower address first"
    lss.configure_node_id(0x40)
    lss.send_switch_state_global(lss.WAITING_STATE)
    assert wait_frame(bus_log, 0x740, 0x00) is not None
    # The configured node no longer answers a fastscan: the other one is found.
    found, address = lss.fast_scan()
    assert found and address == [VENDOR, PRODUCT, REVISION, 0x31]
    lss.configure_node_id(0x41)
    lss.send_switch_state_global(lss.WAITING_STATE)
    assert wait_frame(bus_log, 0x741, 0x00) is not None
    # Nobody left.
    found, _ = lss.fast_scan()
    assert not found
