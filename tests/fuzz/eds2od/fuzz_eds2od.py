#!/usr/bin/env python3
# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Mutation fuzzing of the EDS/DCF generator scripts/eds2od (doc/fuzz.md).

A seeded loop (reproducible with --seed) mutates the seed files of tests/fuzz/eds2od/corpus/
line by line and byte by byte and runs eds2od in-process on each result. Invariants:

- eds2od either generates (exit 0) or refuses (exit 1); it never raises (no traceback);
- every line it prints names the file: `FILE:LINE: message` (warnings included),
  `FILE: message` for what concerns the whole file (the cross-check with python-canopen), or
  its closing `eds2od: N error(s) in FILE`;
- what it generates is accepted again: the EDS "as the firmware has it" passes eds2od.

The regression inputs in tests/fuzz/eds2od/regressions/ are replayed first. On a failure the
input is written to WORK/crash-input.eds|.dcf and its path printed as `crash input: PATH`.
"""

import argparse
import contextlib
import glob
import io
import os
import random
import re
import sys
import tempfile
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))

from eds2od.cli import main as eds2od_main  # noqa: E402

VALUES = ["0", "1", "-1", "0x", "0xFFFFFFFF", "0x100000000", "4294967296", "$NODEID+0x180",
          "$NODEID", "0x7F", "", " ", "abc", "1e3", "0x0007", "0x0009", "0x000F", "0x0020",
          "ro", "rw", "wo", "const", "rww", "rwr", "0x7", "0x8", "0x9", "255", "256", "65535",
          "-2147483648", "9" * 40, "\t", "=", "[", "]", "0b101", "0o7", "1.5", "1e-3"]
KEYS = ["ParameterName", "ObjectType", "DataType", "AccessType", "DefaultValue", "PDOMapping",
        "SubNumber", "LowLimit", "HighLimit", "ParameterValue", "CompactSubObj", "ObjFlags",
        "SupportedObjects", "Denotation", "UploadFile", "DownloadFile", "NrOfEntries"]


def mutate(rng, text):
    lines = text.split("\n")
    for _ in range(rng.randint(1, 4)):
        if not lines:
            lines = [""]
        i = rng.randrange(len(lines))
        op = rng.randrange(12)
        line = lines[i]
        if op == 0:
            del lines[i]
        elif op == 1:
            lines.insert(rng.randrange(len(lines) + 1), line)
        elif op == 2:
            j = rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
        elif op in (3, 4, 5) and "=" in line:
            key = line.split("=", 1)[0]
            lines[i] = f"{key}={rng.choice(VALUES)}"
        elif op == 6 and "=" in line:
            lines[i] = f"{rng.choice(KEYS)}={line.split('=', 1)[1]}"
        elif op == 7 and line.startswith("["):
            sec = line.strip("[]")
            lines[i] = "[" + rng.choice([sec + "sub" + format(rng.randrange(300), "X"),
                                         format(rng.randrange(0x10000), "04X"),
                                         sec[:-1], sec + "x", "", sec.lower()]) + "]"
        elif op == 8 and line:
            k = rng.randrange(len(line) + 1)
            lines[i] = line[:k] + chr(rng.choice([0, 9, 13, 32, 59, 61, 91, 93, 0xE9, 0xFEFF,
                                                  rng.randrange(32, 127)])) + line[k:]
        elif op == 9 and line:
            k = rng.randrange(len(line))
            lines[i] = line[:k] + line[k + 1:]
        elif op == 10:
            del lines[rng.randrange(len(lines)):]
        else:
            src = rng.randrange(len(lines))
            lines.insert(i, f"{lines[src].split('=', 1)[0]}={rng.choice(VALUES)}")
    return "\n".join(lines)


def check(path, tmp):
    """Run eds2od on path; returns None if the invariants hold, else the reason."""
    out = os.path.join(tmp, "out")
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = eds2od_main([path, "--name", "fz", "-o", out])
    except SystemExit as e:
        return f"SystemExit({e.code})\n{err.getvalue()}"
    except Exception:  # noqa: BLE001 - any exception is the finding
        return "Traceback (most recent call last):\n" + traceback.format_exc()
    msg_re = re.compile(rf"^{re.escape(path)}:(\d+:)? \S")
    end_re = re.compile(rf"^eds2od: \d+ error\(s\) in {re.escape(path)}$")
    for line in err.getvalue().splitlines():
        if not (msg_re.match(line) or end_re.match(line)):
            return f"message without FILE[:LINE]: {line!r}"
    if rc not in (0, 1):
        return f"exit {rc}: {err.getvalue()}"
    if rc == 0:
        again = os.path.join(out, "fz.eds")
        err2 = io.StringIO()
        try:
            with contextlib.redirect_stderr(err2), contextlib.redirect_stdout(io.StringIO()):
                rc2 = eds2od_main([again, "--lint-only"])
        except Exception:  # noqa: BLE001
            return "Traceback (most recent call last) on the generated EDS:\n" + \
                traceback.format_exc()
        if rc2 != 0:
            return f"the generated EDS is refused: {err2.getvalue()}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--time", type=float, default=10, help="seconds of mutation")
    ap.add_argument("--seed", type=int, default=20, help="random seed (default 20)")
    ap.add_argument("--runs", type=int, default=0,
                    help="stop after this many mutated inputs (0: only --time bounds the loop)")
    ap.add_argument("--work", default=None, help="where a failing input is written")
    ap.add_argument("--replay-only", action="store_true")
    ap.add_argument("files", nargs="*", help="inputs to check once (instead of fuzzing)")
    args = ap.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="fuzz-eds2od-")
    os.makedirs(work, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="eds2od-", dir=work)
    execs = 0

    def fail(reason, text, ext):
        path = os.path.join(work, "crash-input" + ext)
        with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        print(f"FAIL: {reason}")
        print(f"executions: {execs}")
        print(f"crash input: {path}")
        return 1

    replay = args.files or sorted(glob.glob(os.path.join(HERE, "regressions", "*"))) + \
        sorted(glob.glob(os.path.join(HERE, "corpus", "*")))
    for p in replay:
        execs += 1
        reason = check(os.path.abspath(p), tmp)
        if reason:
            return fail(f"{os.path.relpath(p, BASE)}: {reason}",
                        open(p, encoding="utf-8", errors="surrogateescape").read(),
                        os.path.splitext(p)[1])
    if args.replay_only or args.files:
        print(f"executions: {execs}")
        return 0

    rng = random.Random(args.seed)
    seeds = [(open(p, encoding="utf-8").read(), os.path.splitext(p)[1])
             for p in sorted(glob.glob(os.path.join(HERE, "corpus", "*")))]
    end = time.monotonic() + args.time
    runs = 0
    while time.monotonic() < end and (args.runs == 0 or runs < args.runs):
        runs += 1
        text, ext = rng.choice(seeds)
        text = mutate(rng, text)
        path = os.path.join(tmp, "input" + ext)
        with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        execs += 1
        reason = check(path, tmp)
        if reason:
            return fail(reason, text, ext)
    print(f"executions: {execs}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
