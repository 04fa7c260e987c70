# SPDX-License-Identifier: Apache-2.0
"""Reading a run's TRACE lines and the patterns of CiA 303-3 as the stack shows them.

A run prints (samples/canopen/indicators does, at its end):

    TRACE pattern <time_us> <node> <run pattern> <err pattern>
    TRACE led <time_us> <node> <0 green | 1 red> <0 | 1>

Pattern names are those of the sample: off, on, flicker, blink, "1 flash" .. "4 flashes".
The patterns run in 50 ms ticks from time 0 on the node's clock; green uses the even slots,
red the odd ones (antiphase), as doc/leds.md says.
"""

import re
from dataclasses import dataclass, field

TICK_US = 50_000
SLOT_TICKS = 4
OFF_SLOTS = 5

PATTERNS = ("off", "on", "flicker", "blink", "1 flash", "2 flashes", "3 flashes", "4 flashes")

_PATTERN = re.compile(r"TRACE pattern (\d+) (\d+) (.+?) (off|on|flicker|blink|\d flash(?:es)?)\s*$")
_LED = re.compile(r"TRACE led (\d+) (\d+) ([01]) ([01])\s*$")


class TraceError(Exception):
    """A trace that cannot be drawn; the message says why."""


@dataclass
class Node:
    """What one node's LEDs did and were meant to do."""
    node_id: int
    # (time_us, run pattern, err pattern), in time order
    patterns: list = field(default_factory=list)
    # colour (0 green, 1 red) -> [(time_us, on)], in time order
    changes: dict = field(default_factory=lambda: {0: [], 1: []})


def parse(lines, source="<input>"):
    """Nodes by ID from TRACE lines; other lines are ignored. Raises TraceError."""
    nodes = {}
    for n, line in enumerate(lines, 1):
        if not line.startswith("TRACE "):
            continue
        m = _PATTERN.match(line)
        if m:
            t, node_id, run, err = int(m[1]), int(m[2]), m[3], m[4]
            if run not in PATTERNS:
                raise TraceError(f"{source}:{n}: unknown RUN pattern '{run}'")
            nodes.setdefault(node_id, Node(node_id)).patterns.append((t, run, err))
            continue
        m = _LED.match(line)
        if m:
            t, node_id, colour, on = int(m[1]), int(m[2]), int(m[3]), m[4] == "1"
            nodes.setdefault(node_id, Node(node_id)).changes[colour].append((t, on))
            continue
        raise TraceError(f"{source}:{n}: malformed TRACE line: {line.strip()}")
    if not nodes:
        raise TraceError(f"{source}: no TRACE lines (run the sample to its end)")
    for node in nodes.values():
        node.patterns.sort()
        for c in node.changes.values():
            c.sort()
    return nodes


def pattern_on(pattern, t_us, red):
    """Whether an LED showing @pattern is on at @t_us (red: the odd half of every cycle)."""
    tick = t_us // TICK_US
    slot = tick // SLOT_TICKS
    phase = 1 if red else 0
    if pattern == "off":
        return False
    if pattern == "on":
        return True
    if pattern == "flicker":
        return tick % 2 == phase
    if pattern == "blink":
        return slot % 2 == phase
    flashes = int(pattern[0])
    pos = slot % (2 * flashes - 1 + OFF_SLOTS)
    return pos % 2 == phase and pos <= 2 * flashes - 2 + phase


def expected(node, t_us, colour, bicolour=False):
    """What the patterns say the LED shows at @t_us (None before the first pattern)."""
    current = None
    for t, run, err in node.patterns:
        if t > t_us:
            break
        current = (run, err)
    if current is None:
        return None
    red = pattern_on(current[1], t_us, True)
    if colour == 1:
        return red
    return pattern_on(current[0], t_us, False) and not (bicolour and red)


def recorded(node, t_us, colour):
    """What the LED showed at @t_us (off before its first change)."""
    state = False
    for t, on in node.changes[colour]:
        if t > t_us:
            break
        state = on
    return state


def agreement(node, step_us=10_000, guard_us=40_000):
    """Share of sample instants where the recorded LEDs show the expected pattern.

    Samples every @step_us from the first pattern to the last event, skipping @guard_us on
    either side of each pattern change (the run notes a change when it polls, a little after
    the LEDs changed). Returns (agreeing, compared).
    """
    if not node.patterns:
        return 0, 0
    start = node.patterns[0][0]
    ends = [node.patterns[-1][0]] + [c[-1][0] for c in node.changes.values() if c]
    end = max(ends)
    changes = [t for t, _, _ in node.patterns]
    good = total = 0
    t = start + guard_us + step_us // 2
    while t < end:
        if all(abs(t - c) >= guard_us for c in changes):
            for colour in (0, 1):
                want = expected(node, t, colour)
                if want is not None:
                    total += 1
                    good += recorded(node, t, colour) == want
        t += step_us
    return good, total
