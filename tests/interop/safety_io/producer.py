#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A foreign SRDO producer on a SocketCAN interface, in a process of its own.

    producer.py IFACE NORMAL_ID INVERTED_ID PERIOD

Every PERIOD seconds a pair: the normal frame [emergency stop pressed, counter], then its
bitwise complement on INVERTED_ID. Single-threaded and, where allowed (root in the VM), on a
real-time priority, so that the test's own threads (and their GIL) cannot stretch the gap
between the two frames of a pair. Commands on stdin, one per line; answers on stdout, one
line each, times on CLOCK_MONOTONIC (Python's time.monotonic() in any process):

    good ESTOP [PERIOD_S] pairs every PERIOD (or PERIOD_S), no fault   -> ok
    fault KIND [ARGS]     the next pair carries a fault                -> sent T (when it went out)
        corrupt-normal BYTE BIT, corrupt-inverted BYTE BIT, short-normal, missing-inverted,
        late-inverted DELAY_S
    stop                  no more pairs                                -> stopped T (last good pair)
    slow PERIOD_S         pairs slower from the next one on            -> slowed T (last good pair)
    foreign               frames others sent on the two COB-IDs since  -> foreign N ID...
    quit
"""

import os
import select
import sys
import time

import can


def main():
    iface, cob_n, cob_i, period0 = sys.argv[1], int(sys.argv[2], 0), int(sys.argv[3], 0), \
        float(sys.argv[4])
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
        rt = 1
    except (AttributeError, OSError):
        rt = 0
    # This socket does not get its own frames: whatever arrives here was sent by someone else.
    bus = can.Bus(interface="socketcan", channel=iface, receive_own_messages=False,
                  can_filters=[{"can_id": cob_n, "can_mask": 0x7FF},
                               {"can_id": cob_i, "can_mask": 0x7FF}])

    def say(text):
        sys.stdout.write(text + "\n")
        sys.stdout.flush()

    def send(can_id, data):
        bus.send(can.Message(arbitration_id=can_id, data=bytes(data), is_extended_id=False))
        return time.monotonic()

    running, period, fault, estop, count = False, period0, None, 0, 0
    last_good, slow_reply = 0.0, False
    pending = b""
    nxt = time.monotonic()
    say(f"ready rt={rt}")
    while True:
        timeout = max(0.0, nxt - time.monotonic())
        ready, _, _ = select.select([0], [], [], timeout)
        if ready:
            chunk = os.read(0, 4096)
            if not chunk:
                break
            pending += chunk
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                cmd = line.decode().split()
                if not cmd:
                    continue
                if cmd[0] == "good":
                    if len(cmd) > 2:
                        period0 = float(cmd[2])
                    running, period, fault, estop = True, period0, None, int(cmd[1])
                    say("ok")
                elif cmd[0] == "fault":
                    fault = cmd[1:]
                elif cmd[0] == "stop":
                    running = False
                    say(f"stopped {last_good}")
                elif cmd[0] == "slow":
                    period, slow_reply = float(cmd[1]), True
                elif cmd[0] == "foreign":
                    got = []
                    while (msg := bus.recv(0)) is not None:
                        got.append(f"{msg.arbitration_id:03X}")
                    say(" ".join(["foreign", str(len(got))] + got))
                elif cmd[0] == "quit":
                    bus.shutdown()
                    return
            continue
        # Time for a pair.
        if running:
            kind = fault[0] if fault else None
            normal = bytearray([estop, count & 0xFF])
            inverted = bytearray(b ^ 0xFF for b in normal)
            if kind == "corrupt-normal":
                normal[int(fault[1])] ^= 1 << int(fault[2])
            elif kind == "corrupt-inverted":
                inverted[int(fault[1])] ^= 1 << int(fault[2])
            elif kind == "short-normal":
                normal = normal[:1]
            t_n = send(cob_n, normal)
            t_i = None
            if kind != "missing-inverted":
                if kind == "late-inverted":
                    time.sleep(float(fault[1]))
                t_i = send(cob_i, inverted)
            count += 1
            if kind is None:
                last_good = t_i
                if slow_reply:
                    slow_reply = False
                    say(f"slowed {last_good}")
            else:
                # The frame the fault is judged from: the corrupted one, or the normal frame
                # whose inverted partner is missing or late.
                say(f"sent {t_i if kind == 'corrupt-inverted' else t_n}")
                fault = None
        nxt += period
        if nxt < time.monotonic():
            nxt = time.monotonic()  # after a stall: start afresh, no burst


if __name__ == "__main__":
    main()
