# SPDX-License-Identifier: Apache-2.0
"""What the logging image prints: Zephyr's line format, filtering, hexdumps, and whole lines
when several threads log at once."""

import re

LINE = re.compile(
    r"^\[(\d{2}):(\d{2}):(\d{2})\.(\d{3}),(\d{3})\] <(err|wrn|inf|dbg)> (\w+): (.*)$")


def log_lines(output):
    return [m for m in (LINE.match(line) for line in output) if m]


def messages(output):
    return [(m.group(6), m.group(7), m.group(8)) for m in log_lines(output)]


def test_zephyr_line_format(output):
    msgs = messages(output)
    assert ("err", "test_logging", "main err 1") in msgs
    assert ("wrn", "test_logging", "main wrn 2") in msgs
    assert ("inf", "test_log_default", "default inf 3") in msgs


def test_timestamps_are_uptime_and_do_not_go_back(output):
    stamps = []
    for m in log_lines(output):
        h, mi, s, ms, us = (int(m.group(i)) for i in range(1, 6))
        assert mi < 60 and s < 60
        if "concurrent" not in m.group(8):
            stamps.append((((h * 60 + mi) * 60 + s) * 1000 + ms) * 1000 + us)
    # Messages logged one after the other by one thread are in time order.
    assert len(stamps) > 10
    assert stamps == sorted(stamps)
    assert stamps[0] < 60 * 1000 * 1000, "uptime starts at boot"


def test_filtered_messages_never_printed(output):
    assert not [line for line in output if "FILTERED" in line]
    levels = {(lvl, mod) for lvl, mod, _ in messages(output)}
    assert ("dbg", "test_log_level") not in levels
    assert ("inf", "test_log_level") not in levels


def test_debug_lines_name_the_function(output):
    assert ("dbg", "test_logging", "log_from_declared_module: declared dbg 4") in messages(output)


def test_hexdump_layout(output):
    title = next(i for i, line in enumerate(output) if line.endswith("<dbg> test_logging: declared hexdump"))
    indent = len(output[title]) - len("declared hexdump")
    first, second = output[title + 1], output[title + 2]
    assert first == " " * indent + (
        "53 61 66 65 4c 69 6e 65  20 68 65 78 64 75 6d 70 |SafeLine  hexdump|")
    assert second == " " * indent + "21 01 02 7f" + " " * 38 + "|!...             |"


def test_concurrent_lines_stay_whole(output):
    concurrent = [m.group(8) for m in log_lines(output) if "concurrent" in m.group(8)]
    assert len(concurrent) == 4 * 50
    pattern = re.compile(r"^concurrent thread=(\d) line=(\d+) payload=0123456789abcdefghijklmnopqrstuvwxyz$")
    seen = set()
    for text in concurrent:
        m = pattern.match(text)
        assert m, f"mangled line: {text!r}"
        seen.add((int(m.group(1)), int(m.group(2))))
    assert seen == {(t, i) for t in range(4) for i in range(50)}
    # No fragments of those lines anywhere else.
    assert sum("payload=" in line for line in output) == 4 * 50
