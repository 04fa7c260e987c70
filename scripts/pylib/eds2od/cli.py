# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Command line: eds2od INPUT.eds|.dcf --name NAME -o OUTDIR."""

from __future__ import annotations

import argparse
import logging
import os
import re
import sys

from . import gen
from .model import LintError, crosscheck, load


def write_file(path: str, text: str):
    # Always rewritten (atomically): the build's dependency check compares times.
    data = text.encode("utf-8")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


class _LogToWarnings(logging.Handler):
    """python-canopen logs what it dislikes; each record becomes a warning naming the file."""

    def __init__(self, path: str, warnings: list):
        super().__init__(logging.WARNING)
        self.path = path
        self.warnings = warnings

    def emit(self, record):
        self.warnings.append(f"{self.path}: warning: python-canopen: {record.getMessage()}")


def crosscheck_quoting_log(model, path: str):
    """crosscheck() with python-canopen's log messages as warnings, every message on one line
    (python-canopen's exceptions quote the file's lines, newlines included)."""
    log = logging.getLogger("canopen")
    handler = _LogToWarnings(path, model.warnings)
    saved = log.propagate
    log.addHandler(handler)
    log.propagate = False
    try:
        problems = crosscheck(model, path)
    finally:
        log.removeHandler(handler)
        log.propagate = saved
    model.warnings = [re.sub(r"\s*\n\s*", " ", m) for m in model.warnings]
    return [re.sub(r"\s*\n\s*", " ", m) for m in problems]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        prog="eds2od",
        description="Lint a CiA 306 EDS/DCF and generate the SafeLine object dictionary: "
                    "NAME_od.h, NAME_od.c and NAME.eds (the EDS as the firmware has it).")
    ap.add_argument("input", help="EDS or DCF file")
    ap.add_argument("--name", help="C name prefix (default: the file name)")
    ap.add_argument("-o", "--outdir", help="output directory (required unless --lint-only)")
    ap.add_argument("--lint-only", action="store_true", help="only check the file")
    ap.add_argument("--no-crosscheck", action="store_true",
                    help="do not compare the reading with python-canopen's")
    ap.add_argument("--strict", action="store_true",
                    help="treat warnings (what CiA 306 allows but is worth a look) as errors")
    args = ap.parse_args(argv)

    name = args.name or os.path.splitext(os.path.basename(args.input))[0]
    name = re.sub(r"[^0-9A-Za-z_]", "_", name).lower()
    if not re.match(r"^[a-z_]", name):
        name = "od_" + name
    try:
        model = load(args.input, args.strict)
    except LintError as e:
        for m in e.warnings + e.messages:
            print(m, file=sys.stderr)
        print(f"eds2od: {len(e.messages)} error(s) in {args.input}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"eds2od: {e}", file=sys.stderr)
        return 2
    if not args.no_crosscheck:
        problems = crosscheck_quoting_log(model, args.input)
        for m in model.warnings:
            print(m, file=sys.stderr)
        if problems:
            for m in problems:
                print(m, file=sys.stderr)
            return 1
    else:
        for m in model.warnings:
            print(m, file=sys.stderr)
    if args.lint_only:
        return 0
    if not args.outdir:
        ap.error("-o OUTDIR is required")
    os.makedirs(args.outdir, exist_ok=True)
    try:
        hdr, src = gen.write_c(model, name)
    except ValueError as e:
        print(f"{args.input}: {e}", file=sys.stderr)
        return 1
    write_file(os.path.join(args.outdir, f"{name}_od.h"), hdr)
    write_file(os.path.join(args.outdir, f"{name}_od.c"), src)
    write_file(os.path.join(args.outdir, f"{name}.eds"), gen.write_eds(model))
    return 0
