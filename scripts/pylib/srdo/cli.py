# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Command line of scripts/srdo-sign."""

from __future__ import annotations

import argparse
import os
import shutil
import sys

from eds2od.model import LintError, parse_int

from . import sign


def node_id(s: str) -> int:
    try:
        v = parse_int(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{s}' is not a number") from None
    if not 1 <= v <= 127:
        raise argparse.ArgumentTypeError(f"{v} is not a node-ID (1..127)")
    return v


def write_file(path: str, data: bytes, like: str):
    """Replace path with data atomically (nothing when it already holds them); a new file
    gets the mode of `like`."""
    try:
        with open(path, "rb") as f:
            if f.read() == data:
                return False
    except OSError:
        pass
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    try:
        shutil.copymode(path if os.path.exists(path) else like, tmp)
    except OSError:
        pass
    os.replace(tmp, path)
    return True


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        prog="srdo-sign",
        description="Sign the SRDO configuration of a DCF/EDS (CiA 304): write the CRC "
                    "signature of every SRDO whose direction is not 0 into 13FFh and 0xA5 "
                    "into 13FEh, changing only the lines of those values.")
    ap.add_argument("file", help="DCF or EDS with the SRDO objects")
    ap.add_argument("-o", "--output", help="write the signed file here (default: FILE)")
    ap.add_argument("--node-id", type=node_id,
                    help="node-ID for SRDO 1's default COB-IDs 0xFF/0x100 (default: "
                         "[DeviceComissioning] NodeID)")
    ap.add_argument("--check", action="store_true",
                    help="write nothing; exit 1 unless 13FFh and 13FEh already hold what "
                         "signing would write")
    args = ap.parse_args(argv)
    if args.check and args.output:
        ap.error("--check writes nothing: no -o with it")

    try:
        signer = sign.Signer(args.file, args.node_id)
        if args.check:
            bad = signer.mismatches()
            for t in bad:
                print(f"{args.file}:{t.line}: {t.problem()}", file=sys.stderr)
            if bad:
                print(f"srdo-sign: {args.file} is not signed ({len(bad)} value(s) differ)",
                      file=sys.stderr)
                return 1
            n = len(signer.targets) - 1
            print(f"{args.file}: signed ({n} SRDO signature(s) and 13FEh)")
            return 0
        data = signer.signed()
    except LintError as e:
        for m in e.messages:
            print(m, file=sys.stderr)
        print(f"srdo-sign: {len(e.messages)} error(s) in {args.file}; nothing written",
              file=sys.stderr)
        return 1
    except OSError as e:
        print(f"srdo-sign: {args.file}: {e.strerror}", file=sys.stderr)
        return 2

    out = args.output or args.file
    try:
        changed = write_file(out, data, args.file)
    except OSError as e:
        print(f"srdo-sign: {out}: {e.strerror}", file=sys.stderr)
        return 1
    for t in signer.targets:
        print(f"{t.name} = {t.fmt(t.want)} ({t.what}{'' if t.have != t.want else ', unchanged'})")
    print(f"{out}: {'written' if changed else 'unchanged'}")
    return 0
