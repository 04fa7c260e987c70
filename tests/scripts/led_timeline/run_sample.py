# SPDX-License-Identifier: Apache-2.0
"""Run by twister for sample.canopen.indicators.timeline (SAFELINE_IMAGE is the built
sample): the recorded LEDs must show the patterns they were meant to, and led-timeline must
draw them. Not collected by the plain pytest run (its name is not test_*)."""

import os
import subprocess
import sys

BASE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def test_indicators_run_matches_its_patterns_and_is_drawn(tmp_path):
    image = os.environ["SAFELINE_IMAGE"]
    run = subprocess.run([image], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "indicators: done" in run.stdout
    log = tmp_path / "run.log"
    log.write_text(run.stdout)
    png = tmp_path / "leds.png"
    r = subprocess.run([sys.executable, os.path.join(BASE, "scripts", "led-timeline"),
                        str(log), "-o", str(png), "--min-agreement", "97"],
                       capture_output=True, text=True)
    print(r.stdout)
    assert r.returncode == 0, r.stdout + r.stderr
    assert len([l for l in r.stdout.splitlines() if l.startswith("node ")]) == 4
    assert png.stat().st_size > 10_000
