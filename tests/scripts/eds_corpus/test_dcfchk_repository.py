# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""lely's dcfchk (dcf-tools) accepts every EDS/DCF of the repository, without a warning.

A DCF is checked with its own NodeID, an EDS with node-ID 1 (dcfchk needs one to evaluate
$NODEID COB-IDs of PDOs). Left out: tests/scripts/eds_corpus/, whose files are quirks on
purpose or other projects' files (third_party/SOURCES.md), and the fuzzer's regression inputs
(tests/fuzz/eds2od/regressions/, malformed on purpose). SafeLine's own keys are written as
comments there (";SafeLineSize=64"), which dcfchk skips and eds2od reads (doc/eds2od.md).
"""

import os
import re
import shutil
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DCFCHK = shutil.which("dcfchk")


def repository_files():
    r = subprocess.run(["git", "ls-files", "*.eds", "*.dcf"], cwd=BASE, capture_output=True,
                       text=True)
    if r.returncode != 0:  # not a git checkout: every file on disk
        files = []
        for root, _, names in os.walk(BASE):
            files += [os.path.relpath(os.path.join(root, n), BASE) for n in names
                      if n.endswith((".eds", ".dcf"))]
    else:
        files = r.stdout.split()
    skip = ("tests/scripts/eds_corpus/", "tests/fuzz/eds2od/regressions/", "build/")
    return sorted(f for f in files if not f.startswith(skip))


FILES = repository_files()


def test_there_are_files():
    assert len(FILES) >= 30


@pytest.mark.skipif(DCFCHK is None, reason="dcf-tools (dcfchk) not installed: scripts/setup")
@pytest.mark.parametrize("rel", FILES)
def test_dcfchk_accepts(rel):
    path = os.path.join(BASE, rel)
    m = re.search(r"(?mi)^NodeID=(\S+)", open(path, encoding="utf-8").read())
    node_id = int(m.group(1), 0) if m else 1
    r = subprocess.run([DCFCHK, "-n", str(node_id), path], capture_output=True, text=True)
    assert r.returncode == 0 and not r.stderr.strip(), r.stderr
