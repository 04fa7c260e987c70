# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The README's "Your first node" works as it stands: its fenced blocks, taken out of
README.md in order, make a project in a temporary folder (a block whose first line names a
file under my_node/ is that file; a shell block is run), the project builds on native_posix,
and the run prints what the README's output block shows."""

import os
import re
import subprocess

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
README = os.path.join(BASE, "README.md")
FENCE = re.compile(r"^```([\w-]*)\n(.*?)^```$", re.S | re.M)
# The first line of a file block: "# my_node/prj.conf" or "/* my_node/src/main.c */".
FILE_NAME = re.compile(r"^(?:#|/\*) (my_node/[\w./-]+)(?: \*/)?$")
TIMESTAMP = re.compile(r"\[\d\d:\d\d:\d\d\.\d{3},\d{3}\]")


def section(text, title):
    start = text.index(f"\n## {title}\n")
    end = text.find("\n## ", start + 1)
    return text[start:end if end > 0 else len(text)]


def blocks(text):
    """(kind, payload): ("file", (path, content)), ("sh", script) or ("output", lines)."""
    found = []
    for m in FENCE.finditer(text):
        lang, body = m.group(1), m.group(2)
        first, _, rest = body.partition("\n")
        name = FILE_NAME.match(first)
        if name:
            found.append(("file", (name.group(1), rest)))
        elif lang == "sh":
            found.append(("sh", body))
        elif lang == "":
            found.append(("output", [l for l in body.splitlines() if l.strip()]))
        else:
            raise AssertionError(f"a {lang} block without its file name on the first line")
    return found


def matches(expected, actual):
    """Every expected line, in order, among the actual lines; log timestamps may differ."""
    pattern = [re.escape(TIMESTAMP.sub("TS", e)).replace("TS", TIMESTAMP.pattern)
               for e in expected]
    i = 0
    for line in actual:
        if i < len(pattern) and re.fullmatch(pattern[i], line.rstrip()):
            i += 1
    return i == len(pattern)


def test_the_section_holds_a_whole_project():
    with open(README, encoding="utf-8") as f:
        found = blocks(section(f.read(), "Your first node"))
    files = {v[0] for k, v in found if k == "file"}
    assert files == {"my_node/CMakeLists.txt", "my_node/prj.conf", "my_node/src/main.c"}
    assert [k for k, _ in found].count("sh") == 2
    assert found[-1][0] == "output"


def test_matching_ignores_timestamps_only():
    got = ["*** Booting ***", "[00:00:00.001,250] <inf> co_node: a: X -> Y", "", "Stopped"]
    assert matches(["[00:00:00.000,380] <inf> co_node: a: X -> Y", "Stopped"], got)
    assert not matches(["[00:00:00.000,380] <inf> co_node: b: X -> Y"], got)
    assert not matches(["Stopped", "*** Booting ***"], got)


def test_your_first_node_builds_and_boots(tmp_path):
    with open(README, encoding="utf-8") as f:
        found = blocks(section(f.read(), "Your first node"))
    # Two jobs at most: the build machines are shared (cmake --build reads this variable).
    env = dict(os.environ, SAFELINE_BASE=BASE, CMAKE_BUILD_PARALLEL_LEVEL="2")
    out = ""
    for kind, payload in found:
        if kind == "file":
            path, content = payload
            assert (tmp_path / path).parent.is_dir(), f"no folder for {path}: mkdir missing"
            (tmp_path / path).write_text(content)
        elif kind == "sh":
            r = subprocess.run(["bash", "-euo", "pipefail", "-c", payload], cwd=tmp_path,
                               env=env, capture_output=True, text=True, timeout=900)
            out = r.stdout + r.stderr
            assert r.returncode == 0, f"{payload}\nexit {r.returncode}:\n{out[-4000:]}"
        else:
            assert matches(payload, out.splitlines()), \
                "the README shows:\n" + "\n".join(payload) + f"\nthe run printed:\n{out}"
    assert (tmp_path / "my_node" / "build" / "canopen_od" / "my_node" / "my_node_od.h").exists()
