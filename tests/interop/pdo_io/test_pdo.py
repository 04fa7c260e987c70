# SPDX-License-Identifier: Apache-2.0
"""PDOs of pdo_io seen, remapped and driven by python-canopen on real vcan (CiA 301 §7.2.2).

The sample (samples/canopen/pdo_io) counts input 6000h sub 1 up every 250 ms, echoes output
6200h sub 1 into input 6000h sub 2 and analogue output 6411h sub 1 into analogue input 6401h
sub 2, counts SYNCs in 2011h. Timing inside the VM is slow and noisy: the tests assert order,
counts and lower bounds, never upper bounds of speed.
"""

import struct
import time

import can
import pytest
from canopen.sdo.exceptions import SdoAbortedError

from conftest import NODE_ID, go_operational

TPDO1, TPDO2, TPDO3 = 0x180 + NODE_ID, 0x280 + NODE_ID, 0x380 + NODE_ID
RPDO1, RPDO2 = 0x200 + NODE_ID, 0x300 + NODE_ID
SYNC = 0x080
EMCY = 0x080 + NODE_ID


def frames(log, can_id):
    return [m for m in list(log) if m.arbitration_id == can_id and not m.is_remote_frame]


def wait_for(pred, timeout=3.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if pred():
            return True
        time.sleep(0.02)
    return pred()


def send_syncs(network, n, period=0.1):
    """n SYNCs, `period` apart; returns the time just before each was sent (python-can does not
    log its own frames, and a frame cannot arrive before it was sent)."""
    sent = []
    for _ in range(n):
        sent.append(time.time())
        network.send_message(SYNC, b"")
        time.sleep(period)
    return sent


def test_no_pdo_outside_operational(dut, network, bus_log):
    # Pre-operational after boot-up: inputs change every 250 ms, nothing is sent.
    send_syncs(network, 3)
    time.sleep(0.6)
    assert frames(bus_log, TPDO1) == [] and frames(bus_log, TPDO2) == []


def test_event_driven_tpdo_carries_every_input_change(op, bus_log):
    assert wait_for(lambda: len(frames(bus_log, TPDO1)) >= 6, 5), "TPDO1 every 250 ms"
    got = frames(bus_log, TPDO1)
    assert all(m.dlc == 2 for m in got)
    counts = [m.data[0] for m in got]
    steps = {(b - a) & 0xFF for a, b in zip(counts, counts[1:])}
    # Each change sent once (a change and its event-timer frame never coincide at 250 vs 1000 ms).
    assert steps == {1}, counts


def test_event_timer_sends_without_change(pre, network, bus_log):
    # Map only the echo input (unchanged) with an event timer of 100 ms: frames keep coming
    # with the same value.
    m = pre.tpdo[1]
    m.clear()
    m.add_variable(0x6000, 2)
    m.trans_type = 255
    m.event_timer = 100
    m.inhibit_time = 0
    m.enabled = True
    m.save()
    go_operational(pre)
    bus_log.clear()
    time.sleep(1.2)
    got = frames(bus_log, TPDO1)
    assert len(got) >= 5, len(got)
    assert {bytes(x.data) for x in got} == {b"\x00"}
    gaps = [b.timestamp - a.timestamp for a, b in zip(got, got[1:])]
    assert min(gaps) >= 0.09, gaps


def test_inhibit_time_defers_and_never_loses_the_latest_value(pre, bus_log):
    m = pre.tpdo[1]
    m.inhibit_time = 5000  # 500 ms in 100 µs units, twice the input period
    m.event_timer = 0
    m.save()
    go_operational(pre)
    bus_log.clear()
    assert wait_for(lambda: len(frames(bus_log, TPDO1)) >= 4, 5)
    got = frames(bus_log, TPDO1)
    gaps = [b.timestamp - a.timestamp for a, b in zip(got, got[1:])]
    assert min(gaps) >= 0.45, gaps
    # Deferred, not dropped: each frame carries the newest count, two steps on.
    counts = [x.data[0] for x in got]
    assert all(((b - a) & 0xFF) in (1, 2, 3) for a, b in zip(counts, counts[1:])), counts
    assert any(((b - a) & 0xFF) >= 2 for a, b in zip(counts, counts[1:])), counts


def test_synchronous_tpdo_follows_every_sync(op, network, bus_log):
    syncs = send_syncs(network, 10)
    # Synchronous TPDOs go out while the node handles each SYNC: an SDO answer to a later
    # request means they are all in the log (a fixed wait could miss one under load).
    op.sdo[0x1000].raw
    pdos = frames(bus_log, TPDO2)
    assert len(pdos) == 10, [p.timestamp for p in pdos]
    for s, p, nxt in zip(syncs, pdos, syncs[1:] + [None]):
        assert p.timestamp >= s
        assert nxt is None or p.timestamp <= nxt, "TPDO of SYNC n after SYNC n+1"
    a1, a2, a3, a4 = struct.unpack("<hhhh", bytes(pdos[-1].data))
    assert a4 == -1234


def test_remap_tpdo3_every_second_sync_with_the_sync_count(pre, network, bus_log):
    op = pre
    m = op.tpdo[3]
    m.clear()
    m.add_variable(0x2011)
    m.add_variable(0x6000, 1)
    m.trans_type = 2
    m.enabled = True
    m.save()
    assert op.sdo[0x1A02][0].raw == 2
    assert op.sdo[0x1A02][1].raw == 0x20110020
    assert op.sdo[0x1800 + 2][1].raw & 0x80000000 == 0
    go_operational(op)
    bus_log.clear()
    send_syncs(network, 8)
    op.sdo[0x1000].raw  # every SYNC handled, so its TPDO is in the log
    got = frames(bus_log, TPDO3)
    assert len(got) == 4, len(got)
    counts = [struct.unpack_from("<I", bytes(x.data))[0] for x in got]
    assert all(b - a == 2 for a, b in zip(counts, counts[1:])), counts
    assert all(x.dlc == 5 for x in got)


@pytest.mark.parametrize(
    "index, sub, value, code",
    [
        # Mapping entry written while the PDO is valid.
        (0x1A00, 1, 0x60000108, 0x06090030),
        # Object missing, not mappable, too long: written after making the PDO invalid.
        (0x1A02, 1, 0x7777_0108, 0x06020000),
        (0x1A02, 1, 0x10080008, 0x06040041),
    ],
)
def test_mapping_refusals_carry_the_standard_abort_codes(pre, index, sub, value, code):
    op = pre
    if index == 0x1A02:
        op.sdo[0x1802][1].raw = 0xC0000380 | NODE_ID
        op.sdo[index][0].raw = 0
    with pytest.raises(SdoAbortedError) as e:
        op.sdo[index][sub].raw = value
    assert e.value.code == code, hex(e.value.code)


def test_mapping_in_operational_is_refused_with_08000022(op):
    with pytest.raises(SdoAbortedError) as e:
        op.sdo[0x1A02][0].raw = 0
    assert e.value.code == 0x08000022, hex(e.value.code)


def test_mapping_longer_than_64_bits_is_refused(pre):
    op = pre
    op.sdo[0x1802][1].raw = 0xC0000380 | NODE_ID
    op.sdo[0x1A02][0].raw = 0
    for i in range(1, 5):
        op.sdo[0x1A02][i].raw = 0x64010110
    op.sdo[0x1A02][5].raw = 0x20110020
    with pytest.raises(SdoAbortedError) as e:
        op.sdo[0x1A02][0].raw = 5
    assert e.value.code == 0x06040042, hex(e.value.code)


def test_rpdo_writes_the_dictionary_and_the_echo_comes_back(op, network, bus_log):
    op.rpdo[1][0].raw = 0x5A
    op.rpdo[1][1].raw = 0xA5
    op.rpdo[1].transmit()
    assert wait_for(lambda: op.sdo[0x6200][1].raw == 0x5A)
    assert op.sdo[0x6200][2].raw == 0xA5
    assert wait_for(lambda: any(m.data[1] == 0x5A for m in frames(bus_log, TPDO1)), 3)


def test_synchronous_rpdo_is_committed_at_the_next_sync(op, network):
    before = op.sdo[0x6411][1].raw
    op.rpdo[2][0].raw = before + 111
    op.rpdo[2][1].raw = -5
    op.rpdo[2].transmit()
    time.sleep(0.5)
    assert op.sdo[0x6411][1].raw == before, "a type-1 RPDO waits for the SYNC"
    network.send_message(SYNC, b"")
    assert wait_for(lambda: op.sdo[0x6411][1].raw == before + 111)
    assert op.sdo[0x6411][2].raw == -5


def test_rpdo_too_short_raises_emcy_8210_and_writes_nothing(op, network, bus_log):
    op.rpdo[1][0].raw = 0x33
    op.rpdo[1][1].raw = 0x44
    op.rpdo[1].transmit()
    assert wait_for(lambda: op.sdo[0x6200][1].raw == 0x33)
    network.send_message(RPDO1, b"\x01")
    assert wait_for(lambda: any(m.data[0:2] == b"\x10\x82" for m in frames(bus_log, EMCY)))
    assert op.sdo[0x6200][1].raw == 0x33
    assert op.sdo[0x1003][1].raw & 0xFFFF == 0x8210


def test_rtr_only_tpdo_is_answered_with_the_current_value(pre, network, bus_log):
    op = pre
    m = op.tpdo[3]
    m.clear()
    m.add_variable(0x6000, 1)
    m.trans_type = 253
    m.rtr_allowed = True
    m.enabled = True
    m.save()
    go_operational(op)
    time.sleep(0.6)
    assert frames(bus_log, TPDO3) == [], "type 253 is sent on request only"
    network.bus.send(can.Message(arbitration_id=TPDO3, is_remote_frame=True, dlc=1,
                                 is_extended_id=False))
    assert wait_for(lambda: len(frames(bus_log, TPDO3)) == 1, 3)
    now = op.sdo[0x6000][1].raw
    assert (now - frames(bus_log, TPDO3)[0].data[0]) & 0xFF <= 4
