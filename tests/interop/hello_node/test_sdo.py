# SPDX-License-Identifier: Apache-2.0
"""SDO server of hello_node against python-canopen's SDO client on real vcan: expedited,
segmented and block transfers of 0..100 kB with and without CRC, refusals with the right abort
code, and clients that abort in the middle of a transfer."""

import os
import struct
import time

import canopen
import pytest
from canopen.sdo.exceptions import SdoAbortedError

from conftest import NODE_ID, SDO_TIMEOUT

DATA = 0x2100  # DOMAIN, up to 128 KiB, provider-backed
SDO_TX = 0x580 + NODE_ID


def pattern(n, seed=1):
    return bytes(((i * 7 + seed) & 0xFF) for i in range(n))


def upload_block(node, index, crc):
    with node.sdo.open(index, 0, "rb", block_transfer=True, request_crc_support=crc) as f:
        return f.read()


def download_block(node, index, data, crc):
    with node.sdo.open(index, 0, "wb", size=len(data), block_transfer=True,
                       request_crc_support=crc) as f:
        f.write(data)


def test_expedited_upload_of_mandatory_objects(dut):
    assert struct.unpack("<I", dut.sdo.upload(0x1000, 0))[0] == 0
    assert dut.sdo.upload(0x1001, 0) == b"\x00"
    assert struct.unpack("<I", dut.sdo.upload(0x1018, 1))[0] == 0x539


def test_segmented_upload_of_a_string(dut):
    assert dut.sdo.upload(0x1008, 0).rstrip(b"\x00") == b"SafeLine hello_node"


def test_expedited_download_and_read_back(dut):
    dut.sdo.download(0x2001, 0, struct.pack("<H", 500))
    assert struct.unpack("<H", dut.sdo.upload(0x2001, 0))[0] == 500


# Every segment is a round trip, slow inside the VM: 10 000 bytes already span many windows of
# the server's 889-byte buffer; block transfers below go to 100 000.
@pytest.mark.parametrize("size", [0, 1, 4, 5, 7, 8, 14, 100, 889, 890, 4096, 10_000])
def test_segmented_download_and_upload(dut, size):
    data = pattern(size, seed=size)
    dut.sdo.download(DATA, 0, data, force_segment=True)
    assert dut.sdo.upload(DATA, 0) == data


@pytest.mark.parametrize("crc", [True, False], ids=["crc", "nocrc"])
@pytest.mark.parametrize("size", [1, 7, 8, 127 * 7, 127 * 7 + 1, 10_000, 100_000])
def test_block_download_and_upload(dut, size, crc):
    data = pattern(size, seed=size + crc)
    download_block(dut, DATA, data, crc)
    assert upload_block(dut, DATA, crc) == data
    if size <= 1000:
        assert dut.sdo.upload(DATA, 0) == data, "the same value over a segmented upload"


@pytest.mark.parametrize("crc", [True, False], ids=["crc", "nocrc"])
def test_block_upload_of_a_four_byte_object(dut, crc):
    # python-canopen asks with protocol switch threshold 0, so the block protocol is used even
    # for 4 bytes: one segment, the end frame says 3 bytes of it are padding.
    assert upload_block(dut, 0x1000, crc) == dut.sdo.upload(0x1000, 0)


@pytest.mark.parametrize("index,sub,code", [
    (0x3000, 0, 0x06020000),  # object does not exist
    (0x1018, 7, 0x06090011),  # sub-index does not exist
    (0x2002, 0, 0x06010001),  # write-only object
])
def test_upload_refusals(dut, index, sub, code):
    with pytest.raises(SdoAbortedError) as e:
        dut.sdo.upload(index, sub)
    assert e.value.code == code


@pytest.mark.parametrize("index,sub,data,code", [
    (0x1000, 0, b"\x01\x00\x00\x00", 0x06010002),  # read-only object
    (0x1016, 1, b"\x01\x00", 0x06070013),          # too short for UNSIGNED32
    (0x1017, 0, b"\x01\x00\x00\x00", 0x06070012),  # too long for UNSIGNED16
    (0x2001, 0, struct.pack("<H", 1001), 0x06090031),  # above HighLimit
    (0x3000, 0, b"\x01", 0x06020000),
    (0x1018, 9, b"\x01", 0x06090011),
])
def test_download_refusals(dut, index, sub, data, code):
    with pytest.raises(SdoAbortedError) as e:
        dut.sdo.download(index, sub, data)
    assert e.value.code == code


def test_refused_download_leaves_the_old_value(dut):
    dut.sdo.download(0x2001, 0, struct.pack("<H", 42))
    with pytest.raises(SdoAbortedError):
        dut.sdo.download(0x2001, 0, struct.pack("<H", 5000))
    assert struct.unpack("<H", dut.sdo.upload(0x2001, 0))[0] == 42


def quiet_after_abort(dut, bus_log):
    """After the client's abort the server sends nothing more and serves the next request."""
    time.sleep(0.3)
    bus_log.clear()
    time.sleep(0.3)
    assert [m for m in bus_log if m.arbitration_id == SDO_TX] == []
    assert struct.unpack("<I", dut.sdo.upload(0x1000, 0))[0] == 0


def test_client_abort_during_segmented_upload(dut, bus_log):
    dut.sdo.download(DATA, 0, pattern(5000))
    stream = dut.sdo.open(DATA, 0, "rb", buffering=0)
    assert len(stream.read(7)) == 7
    dut.sdo.abort()
    quiet_after_abort(dut, bus_log)


def test_client_abort_during_segmented_download_keeps_the_old_value(dut, bus_log):
    old = pattern(3000, seed=3)
    dut.sdo.download(DATA, 0, old)
    stream = dut.sdo.open(DATA, 0, "wb", size=3000, buffering=0)
    stream.write(pattern(700, seed=9))
    dut.sdo.abort()
    quiet_after_abort(dut, bus_log)
    assert dut.sdo.upload(DATA, 0) == old


def test_client_abort_during_block_download_keeps_the_old_value(dut, bus_log):
    old = pattern(2000, seed=4)
    dut.sdo.download(DATA, 0, old)
    stream = dut.sdo.open(DATA, 0, "wb", size=50_000, block_transfer=True, buffering=0)
    stream.write(pattern(3000, seed=8))
    dut.sdo.abort()
    time.sleep(0.5)
    assert dut.sdo.upload(DATA, 0) == old


def test_client_abort_during_block_upload(dut, bus_log):
    dut.sdo.download(DATA, 0, pattern(20_000))
    stream = dut.sdo.open(DATA, 0, "rb", block_transfer=True, buffering=0)
    assert len(stream.read(7)) > 0
    dut.sdo.abort()
    time.sleep(0.5)
    assert struct.unpack("<I", dut.sdo.upload(0x1000, 0))[0] == 0


def test_sdo_is_silent_in_stopped(dut, bus_log):
    dut.nmt.state = "STOPPED"
    dut.nmt.wait_for_heartbeat(3)
    dut.sdo.RESPONSE_TIMEOUT = 0.5
    with pytest.raises(canopen.SdoCommunicationError):
        dut.sdo.upload(0x1000, 0)
    dut.nmt.state = "PRE-OPERATIONAL"
    dut.nmt.wait_for_heartbeat(3)
    dut.sdo.RESPONSE_TIMEOUT = SDO_TIMEOUT
    assert struct.unpack("<I", dut.sdo.upload(0x1000, 0))[0] == 0


def test_block_upload_survives_a_full_socketcan_tx_queue(device):
    """127-segment sub-blocks against a driver with 16 frames in flight: the line queues what
    the driver cannot take yet and nothing is lost (issue: back-pressure killing block
    transfers in other stacks)."""
    device.start()
    node = device.node
    data = pattern(60_000, seed=11)
    download_block(node, DATA, data, True)
    assert upload_block(node, DATA, True) == data
    device.stop()
    with open(device.log_path) as f:
        stats = [l for l in f if l.startswith("hello_node: line0 ")]
    assert stats, "the image prints its line counters on exit"
    fields = stats[-1].split()
    values = dict(zip(fields[2::2], map(int, fields[3::2])))
    assert values["queued"] > 0, "the driver pushed back during the sub-blocks"
    assert values["queue_max"] > 16
    assert values["dropped"] == 0 and values["errors"] == 0
