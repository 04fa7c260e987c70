# SPDX-License-Identifier: Apache-2.0
"""scripts/led-timeline: the patterns it expects, reading traces, agreement and its CLI."""

import os
import subprocess
import sys

import pytest

BASE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))

from ledtimeline.trace import TraceError, agreement, parse, pattern_on  # noqa: E402

TOOL = os.path.join(BASE, "scripts", "led-timeline")
MS = 1000


def runs(pattern, red, ms=12000):
    """On/off run lengths [ms] of a pattern sampled every 10 ms from t = 0."""
    out, level, length = [], None, 0
    for t in range(0, ms * MS, 10 * MS):
        on = pattern_on(pattern, t, red)
        if on != level and level is not None:
            out.append((level, length))
            length = 0
        level = on
        length += 10
    return out[1:]  # the first run may be cut


@pytest.mark.parametrize("pattern,cycle", [
    ("flicker", [50, 50]),
    ("blink", [200, 200]),
    ("1 flash", [200, 1000]),
    ("2 flashes", [200, 200, 200, 1000]),
    ("3 flashes", [200, 200, 200, 200, 200, 1000]),
    ("4 flashes", [200, 200, 200, 200, 200, 200, 200, 1000]),
])
@pytest.mark.parametrize("red", [False, True])
def test_pattern_timing_of_cia_303_3(pattern, cycle, red):
    r = runs(pattern, red)
    first_on = next(i for i, (lvl, ms) in enumerate(r) if lvl and
                    (i == 0 or r[i - 1][1] == max(cycle)))
    body = r[first_on:first_on + 2 * len(cycle)]
    assert [ms for _, ms in body] == cycle * 2
    assert [lvl for lvl, _ in body] == [i % 2 == 0 for i in range(2 * len(cycle))]


@pytest.mark.parametrize("green,red", [("blink", "1 flash"), ("blink", "2 flashes"),
                                       ("flicker", "flicker"), ("1 flash", "4 flashes")])
def test_green_and_red_never_on_together(green, red):
    for t in range(0, 10_000 * MS, 10 * MS):
        assert not (pattern_on(green, t, False) and pattern_on(red, t, True)), t


def trace_lines(pattern, start_us=0, end_us=3_000_000, shift_us=0, node=2):
    """A run whose green LED follows @pattern, shifted by @shift_us."""
    lines = [f"TRACE pattern {start_us} {node} {pattern} off"]
    level = None
    for t in range(start_us, end_us, 1000):
        on = pattern_on(pattern, t - shift_us, False)
        if on != level:
            lines.append(f"TRACE led {t} {node} 0 {int(on)}")
            level = on
    return lines


def test_agreement_full_for_a_faithful_run():
    good, total = agreement(parse(trace_lines("blink"))[2])
    assert total > 500 and good == total


def test_agreement_drops_for_a_wrong_phase():
    good, total = agreement(parse(trace_lines("blink", shift_us=200_000))[2])
    assert good / total < 0.6


def test_parse_refuses_malformed_lines_with_file_and_line():
    with pytest.raises(TraceError, match=r"run.log:2: malformed TRACE line"):
        parse(["boot", "TRACE led x 2 0 1"], "run.log")
    with pytest.raises(TraceError, match=r"run.log: no TRACE lines"):
        parse(["boot"], "run.log")


def cli(*args, stdin=None):
    return subprocess.run([sys.executable, TOOL, *args], input=stdin, capture_output=True,
                          text=True)


def test_cli_draws_a_png_and_reports_agreement(tmp_path):
    log = tmp_path / "run.log"
    log.write_text("\n".join(["*** Booting", *trace_lines("2 flashes")]) + "\n")
    png = tmp_path / "leds.png"
    r = cli(str(log), "-o", str(png), "--min-agreement", "99")
    assert r.returncode == 0, r.stderr
    assert "node 2:" in r.stdout and "(100.00 %)" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_fails_below_min_agreement(tmp_path):
    log = tmp_path / "run.log"
    log.write_text("\n".join(trace_lines("blink", shift_us=200_000)) + "\n")
    r = cli(str(log), "--min-agreement", "99")
    assert r.returncode == 1
    assert "below 99" in r.stderr


def test_cli_usage_and_unreadable_input(tmp_path):
    assert cli().returncode == 2
    assert cli(str(tmp_path / "missing.log")).returncode == 2
    assert cli("-", "--min-agreement", "150", stdin="").returncode == 2
    r = cli("-", stdin="no trace here\n")
    assert r.returncode == 2 and "no TRACE lines" in r.stderr
