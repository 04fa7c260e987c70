# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Command line of scripts/dcf2cdcf."""

import argparse
import os
import re
import sys

from eds2od.model import LintError

from . import cdcf


def write_file(path: str, data):
    """Write only when the content changes, so the build does not redo dependants."""
    mode = "b" if isinstance(data, bytes) else ""
    try:
        with open(path, "r" + mode) as f:
            if f.read() == data:
                return
    except (OSError, UnicodeDecodeError):
        pass
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w" + mode) as f:
        f.write(data)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        prog="dcf2cdcf",
        description="Turn a slave's DCF (CiA 306) into its concise DCF (CiA 302 §6.2): "
                    "the writable objects with a ParameterValue, PDOs in remap order.")
    ap.add_argument("dcf", help="the slave's DCF (or, with --decode, a concise DCF .bin)")
    ap.add_argument("-o", "--output", help="write the binary concise DCF here")
    ap.add_argument("--c-dir", help="write NAME_cdcf.c and NAME_cdcf.h into this folder")
    ap.add_argument("--name", help="C name (default: the DCF's file name)")
    ap.add_argument("--node-id", type=lambda s: int(s, 0),
                    help="node-ID for $NODEID values (default: [DeviceComissioning] NodeID)")
    ap.add_argument("--defaults", action="store_true",
                    help="also send writable objects that only have a DefaultValue")
    ap.add_argument("--save", action="store_true",
                    help="end with 1010h:01 = \"save\" so the slave keeps the configuration")
    ap.add_argument("--list", action="store_true", help="print the entries")
    ap.add_argument("--strict", action="store_true",
                    help="treat the reader's warnings (what CiA 306 allows) as errors")
    ap.add_argument("--decode", action="store_true",
                    help="read a concise DCF .bin and print its entries")
    args = ap.parse_args(argv)

    if args.decode:
        with open(args.dcf, "rb") as f:
            blob = f.read()
        try:
            entries = cdcf.decode(blob)
        except ValueError as e:
            print(f"{args.dcf}: malformed concise DCF: {e}", file=sys.stderr)
            return 1
        sys.stdout.write(cdcf.listing(entries))
        return 0

    warnings = []
    try:
        entries = cdcf.generate(args.dcf, args.node_id, args.defaults, args.save, args.strict,
                                warnings)
    except LintError as e:
        for m in warnings + e.warnings + e.messages:
            print(m, file=sys.stderr)
        return 1
    except OSError as e:
        print(f"{args.dcf}: {e.strerror}", file=sys.stderr)
        return 1
    for m in warnings:
        print(m, file=sys.stderr)
    blob = cdcf.encode(entries)
    if args.output:
        write_file(args.output, blob)
    if args.c_dir:
        name = args.name or re.sub(r"\W", "_", os.path.splitext(os.path.basename(args.dcf))[0])
        name = name.lower()
        if not re.fullmatch(r"[a-z_][a-z0-9_]*", name):
            print(f"{args.dcf}: '{name}' is not a C identifier (use --name)", file=sys.stderr)
            return 1
        c, h = cdcf.c_source(name, blob, os.path.basename(args.dcf))
        write_file(os.path.join(args.c_dir, f"{name}_cdcf.c"), c)
        write_file(os.path.join(args.c_dir, f"{name}_cdcf.h"), h)
    if args.list or not (args.output or args.c_dir):
        sys.stdout.write(cdcf.listing(entries))
    return 0
