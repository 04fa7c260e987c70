# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The EDS/DCF quirk corpus: one small file per quirk in cases/, its expectation in its
leading comment lines:

    ; tool: eds2od | dcf2cdcf
    ; expect: accept | refuse
    ; warning: LINE: TEXT      accepted with `file:LINE: warning: ...TEXT...` (and refused
                               with --strict)
    ; error: LINE: TEXT        refused with `file:LINE: ...TEXT...`
    ; value: SECTION KEY=VALUE what the generated NAME.eds says

An accepted case is also generated and its C compiled (gcc -Wall -Wextra -Werror). A case
lists every warning it gets. EDS_CORPUS_SCRIPTS=<dir> runs another copy of scripts/ (an
older checkout) against the same expectations: every case failed on the tools before the
corpus was written.
"""

import glob
import os
import re
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
SCRIPTS = os.environ.get("EDS_CORPUS_SCRIPTS", os.path.join(BASE, "scripts"))
CASES = sorted(glob.glob(os.path.join(HERE, "cases", "*.eds")) +
               glob.glob(os.path.join(HERE, "cases", "*.dcf")))

sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))


def spec(path):
    out = {"tool": "eds2od", "expect": None, "warning": [], "error": [], "value": []}
    for ln in open(path, encoding="utf-8"):
        if not ln.startswith(";"):
            break
        m = re.match(r"^; (tool|expect|warning|error|value): (.*)$", ln.rstrip("\n"))
        if not m:
            continue
        k, v = m.groups()
        if k in ("tool", "expect"):
            out[k] = v
        elif k == "value":
            sec, kv = v.split(" ", 1)
            out[k].append((sec, *kv.split("=", 1)))
        else:
            line, text = v.split(": ", 1)
            out[k].append((int(line), text))
    assert out["expect"] in ("accept", "refuse"), path
    return out


def run(tool, path, *args):
    cmd = [sys.executable, os.path.join(SCRIPTS, tool), str(path)] + list(args)
    return subprocess.run(cmd, capture_output=True, text=True, cwd=BASE)


def found(stderr, path, line, text, warning):
    pre = f"{path}:{line}: " + ("warning: " if warning else "")
    return any(ln.startswith(pre) and text in ln for ln in stderr.splitlines())


def own_warnings(stderr, path):
    """file:line: warning: lines (not the note that python-canopen could not read a file)."""
    return [ln for ln in stderr.splitlines()
            if re.match(re.escape(str(path)) + r":\d+: warning: ", ln)]


def test_corpus_is_there():
    assert len(CASES) >= 10


@pytest.mark.parametrize("path", CASES, ids=os.path.basename)
def test_case(path, tmp_path):
    s = spec(path)
    tool = s["tool"]
    if tool == "eds2od":
        name = re.sub(r"\W", "_", os.path.splitext(os.path.basename(path))[0])
        args = ["--name", name, "-o", str(tmp_path)] if s["expect"] == "accept" \
            else ["--lint-only"]
    else:
        args = ["-o", str(tmp_path / "out.bin")]
    r = run(tool, path, *args)
    if s["expect"] == "refuse":
        assert r.returncode == 1, f"{tool} accepted it:\n{r.stderr}"
        for line, text in s["error"]:
            assert found(r.stderr, path, line, text, False), \
                f"want {line}: {text}\ngot:\n{r.stderr}"
        return
    assert r.returncode == 0, r.stderr
    got = own_warnings(r.stderr, path)
    for line, text in s["warning"]:
        assert found(r.stderr, path, line, text, True), f"want {line}: {text}\ngot:\n{r.stderr}"
    assert len(got) == len(s["warning"]), "unexpected warnings:\n" + "\n".join(got)
    if s["warning"]:
        r2 = run(tool, path, "--lint-only", "--strict") if tool == "eds2od" else \
            run(tool, path, "--strict")
        assert r2.returncode == 1, r2.stderr
        for line, text in s["warning"]:
            assert found(r2.stderr, path, line, text, False) and "(--strict)" in r2.stderr, \
                f"--strict: want {line}: {text}\ngot:\n{r2.stderr}"
    if tool != "eds2od":
        return
    from eds2od.model import Reader

    eds = tmp_path / f"{name}.eds"
    rd = Reader(str(eds), eds.read_text(encoding="utf-8"))
    for sec, key, want in s["value"]:
        section = rd.sections.get(sec.lower())
        assert section is not None, f"no [{sec}] in the generated EDS"
        assert section.get(key) == want, f"[{sec}] {key}={section.get(key)}, want {want}"
    cmd = ["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only",
           "-I", os.path.join(BASE, "include"), "-I", str(tmp_path),
           str(tmp_path / f"{name}_od.c")]
    c = subprocess.run(cmd, capture_output=True, text=True)
    assert c.returncode == 0, c.stderr
