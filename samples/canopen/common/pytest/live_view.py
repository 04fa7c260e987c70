# SPDX-License-Identifier: Apache-2.0
"""Run by twister for sample.canopen.indicators.live and sample.canopen.commissioning.live
(SAFELINE_IMAGE is the built sample): with --live the sample draws its LED view in place
(common/led_view.c), and each row's glyphs agree with the patterns the row names. Not
collected by the plain pytest run (its name is not test_*)."""

import os
import re
import subprocess

GREEN_ON = "\x1b[1;32m\u25cf\x1b[0m"
RED_ON = "\x1b[1;31m\u25cf\x1b[0m"
OFF = "\x1b[2m\u25cb\x1b[0m"
ROW = re.compile(r"^  (?P<label>.*?) RUN (?P<green>\S+)  ERR (?P<red>\S+)   (?P<detail>.*)$")
DEVICES = 4


def test_live_view_is_redrawn_in_place_and_its_glyphs_match_the_patterns():
    image = os.environ["SAFELINE_IMAGE"]
    run = subprocess.run([image, "--live"], capture_output=True, timeout=90)
    out = run.stdout.decode("utf-8", errors="replace")
    assert run.returncode == 0, out[-2000:] + run.stderr.decode(errors="replace")
    up = f"\x1b[{DEVICES + 1}A"
    tables = out.split(up)
    assert len(tables) > 50, "redrawn in place many times (cursor up over status and rows)"
    # One line per change is the mode without --live.
    assert not re.search(r"^(indicators: node \d|commissioning: serial \S+ node)", out, re.M)
    last = [ln for ln in tables[-1].split("\n") if ln.startswith("\r\x1b[K")][:DEVICES + 1]
    rows = [ROW.match(ln[len("\r\x1b[K"):]) for ln in last[1:]]
    assert all(rows), last
    for m in rows:
        assert m["green"] in (GREEN_ON, OFF) and m["red"] in (RED_ON, OFF), m.group(0)
        run_pat = re.search(r"RUN (\S+)", m["detail"])[1]
        err_pat = re.search(r"ERR (\S+)", m["detail"])[1]
        # A steady pattern shows as the glyph; a blinking one may be caught either way.
        if run_pat in ("on", "off"):
            assert (m["green"] == GREEN_ON) == (run_pat == "on"), m.group(0)
        if err_pat in ("on", "off"):
            assert (m["red"] == RED_ON) == (err_pat == "on"), m.group(0)
    if "commissioning" in image:
        assert "all 4 devices Operational" in last[0]
        for i, m in enumerate(rows):
            assert m["label"] == f"serial A00{i + 1}  node {i + 2:<3}", m["label"]
            assert re.search(r"OPERATIONAL\s+RUN on\s+ERR off", m["detail"]), m["detail"]
    else:
        assert last[0] == "\r\x1b[Kend"
        for i, m in enumerate(rows):
            assert m["label"] == f"node {i + 2} ", m["label"]
        # At the end: node 2 started again, node 3 still stopped.
        assert re.search(r"OPERATIONAL\s+RUN on", rows[0]["detail"]), rows[0]["detail"]
        assert re.search(r"STOPPED\s+RUN 1 flash", rows[1]["detail"]), rows[1]["detail"]
