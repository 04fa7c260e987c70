# SPDX-License-Identifier: Apache-2.0
"""Parameter storage of hello_node (1010h/1011h, CiA 301 §7.5.2.13-14) against python-canopen on
real vcan: without --storage the node has no medium and says so; with --storage=FILE "save"
survives a restart of the process and "load" brings the defaults back."""

import struct

import pytest
from canopen.sdo.exceptions import SdoAbortedError

from conftest import NODE_ID
from safeline_interop import Device

SAVE = struct.pack("<I", 0x65766173)  # "save"
LOAD = struct.pack("<I", 0x64616F6C)  # "load"
HB = 0x1017


def abort_code(fn):
    with pytest.raises(SdoAbortedError) as e:
        fn()
    return e.value.code


def u32(node, index, sub):
    return struct.unpack("<I", node.sdo.upload(index, sub))[0]


def test_without_medium_the_node_says_it_does_not_store(dut):
    for sub in (1, 2, 3, 4):
        assert u32(dut, 0x1010, sub) == 0, f"1010h:{sub}: does not save on command"
        assert u32(dut, 0x1011, sub) == 0, f"1011h:{sub}: does not restore defaults"
        assert abort_code(lambda: dut.sdo.download(0x1010, sub, SAVE)) == 0x08000020
        assert abort_code(lambda: dut.sdo.download(0x1011, sub, LOAD)) == 0x08000020
    # A value other than the signature keeps its own abort code (the same: 08000020h).
    assert abort_code(lambda: dut.sdo.download(0x1010, 1, struct.pack("<I", 5))) == 0x08000020
    assert u32(dut, 0x1010, 1) == 0, "a refused write changes nothing"


def test_with_a_file_medium_save_and_load_survive_a_restart(image, iface, network, eds, sample,
                                                            tmp_path):
    medium = tmp_path / "hello_node.params"

    def start():
        d = Device(image, iface, network, eds, NODE_ID, sample["up_marker"],
                   args=(f"--storage={medium}",))
        d.start()
        return d

    d = start()
    try:
        node = d.node
        assert u32(node, 0x1010, 1) == 1 and u32(node, 0x1011, 1) == 1
        default = node.sdo.upload(HB, 0)
        node.sdo.download(HB, 0, struct.pack("<H", 250))
        assert abort_code(lambda: node.sdo.download(0x1010, 1, struct.pack("<I", 5))) == \
            0x08000020, "a wrong signature"
        node.sdo.download(0x1010, 2, SAVE)  # the communication group
    finally:
        d.stop()
    d = start()
    try:
        node = d.node
        assert struct.unpack("<H", node.sdo.upload(HB, 0))[0] == 250, "restored at boot"
        node.sdo.download(0x1011, 1, LOAD)
        assert struct.unpack("<H", node.sdo.upload(HB, 0))[0] == 250, "until the next reset"
    finally:
        d.stop()
    d = start()
    try:
        assert d.node.sdo.upload(HB, 0) == default, "the defaults after 'load'"
    finally:
        d.stop()
