# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Shared helpers for the dcf2cdcf tests (a plain module: conftest.py names clash across
folders)."""

import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DATA = os.path.join(HERE, "data")
GOLDEN = os.path.join(HERE, "golden")
DCF2CDCF = os.path.join(BASE, "scripts", "dcf2cdcf")
SLAVE = os.path.join(DATA, "slave.dcf")

sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))


def run(*args):
    return subprocess.run([sys.executable, DCF2CDCF, *map(str, args)], capture_output=True,
                          text=True)


def edit(tmp_path, changes, name="v.dcf", src=SLAVE):
    """Copy of `src` with keys changed: changes = [(section, key, value or None to delete)].

    A key missing from its section is added right after the header. Returns (path, lines):
    lines[(section, key)] is the 1-based line of that key in the new file.
    """
    with open(src, encoding="utf-8") as f:
        rows = f.read().split("\n")
    for sec, key, value in changes:
        head = rows.index(f"[{sec}]")
        end = head + 1
        while end < len(rows) and not rows[end].startswith("["):
            end += 1
        at = next((i for i in range(head + 1, end) if rows[i].split("=")[0] == key), None)
        if value is None:
            assert at is not None, (sec, key)
            del rows[at]
        elif at is None:
            rows.insert(head + 1, f"{key}={value}")
        else:
            rows[at] = f"{key}={value}"
    lines = {}
    for sec, key, value in changes:
        if value is None:
            continue
        head = rows.index(f"[{sec}]")
        at = next(i for i in range(head + 1, len(rows)) if rows[i].split("=")[0] == key)
        lines[(sec, key)] = at + 1
    p = tmp_path / name
    p.write_text("\n".join(rows), encoding="utf-8")
    return p, lines
