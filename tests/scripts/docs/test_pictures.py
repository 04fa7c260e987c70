# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The documentation's pictures are what their layouts give (scripts/pictures), and the
generator refuses a layout it cannot draw with the line and the reason."""

import os
import subprocess
import sys

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
TOOL = os.path.join(BASE, "scripts", "pictures")


def run(*args):
    return subprocess.run([sys.executable, TOOL] + list(args), capture_output=True, text=True)


def test_every_committed_picture_is_current():
    r = run("--check")
    assert r.returncode == 0, r.stderr


def test_the_readme_shows_the_architecture_picture():
    with open(os.path.join(BASE, "README.md"), encoding="utf-8") as f:
        assert "](doc/architecture.svg)" in f.read()
    assert os.path.isfile(os.path.join(BASE, "doc", "architecture.layout"))


def test_a_changed_layout_makes_the_check_fail(tmp_path):
    layout = tmp_path / "pic.layout"
    layout.write_text("size 200 100\nbox a 10 10 150 40 plain | one box\n")
    assert run(str(layout)).returncode == 0
    assert run("--check", str(layout)).returncode == 0
    layout.write_text("size 200 100\nbox a 10 10 150 40 plain | another box\n")
    r = run("--check", str(layout))
    assert r.returncode == 1 and "pic.svg is not what its layout gives" in r.stderr


def test_the_same_layout_gives_the_same_bytes(tmp_path):
    layout = tmp_path / "pic.layout"
    layout.write_text("size 300 120\nbox a 10 10 120 40 thread | a | b\n"
                      "box b 170 10 120 40 plain | c\narrow a.e b.w call | <x\n"
                      "text 10 100 | legend\n")
    run(str(layout))
    first = (tmp_path / "pic.svg").read_bytes()
    run(str(layout))
    assert (tmp_path / "pic.svg").read_bytes() == first
    assert b'stroke-dasharray="5,3"' in first and b"legend" in first


def test_bad_layouts_are_refused_with_the_line_and_the_reason(tmp_path):
    cases = {
        "box a 10 10 40 40 plain | a text far too long for forty pixels\n":
            "too long for box a",
        "box a 10 10 100 20 plain | one | two | three\n": "3 lines do not fit box a",
        "box a 10 10 100 40 fancy | a\n": "unknown box style 'fancy'",
        "box a 10 10 100 40 plain | a\narrow a.s b.n solid\n": "no box 'b'",
        "box a 10 10 100 40 plain | a\narrow a.x a.n solid\n": "the side must be n, s, e or w",
        "box a 10 ten 100 40 plain | a\n": "coordinates must be whole numbers",
        "box a 10 10 100 40 plain | a\nbox a 10 60 100 40 plain | b\n": "box a defined twice",
        "circle 1 2 3\n": "cannot read",
    }
    for body, reason in cases.items():
        layout = tmp_path / "bad.layout"
        layout.write_text("size 300 200\n" + body)
        r = run(str(layout))
        assert r.returncode == 2, body
        assert reason in r.stderr and "bad.layout:" in r.stderr, (body, r.stderr)
        assert not (tmp_path / "bad.svg").exists()
    (tmp_path / "nosize.layout").write_text("box a 10 10 100 40 plain | a\n")
    r = run(str(tmp_path / "nosize.layout"))
    assert r.returncode == 2 and "no 'size W H' line" in r.stderr
