# Copyright (c) 2024 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Shared helpers for the eds2od tests (a plain module: conftest.py names clash across
folders)."""

import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DATA = os.path.join(HERE, "data")
GOLDEN = os.path.join(HERE, "golden")
EDS2OD = os.path.join(BASE, "scripts", "eds2od")

sys.path.insert(0, os.path.join(BASE, "scripts", "pylib"))


def run_eds2od(path, outdir=None, name=None, extra=()):
    cmd = [sys.executable, EDS2OD, str(path)]
    if name:
        cmd += ["--name", name]
    if outdir:
        cmd += ["-o", str(outdir)]
    else:
        cmd += ["--lint-only"]
    cmd += list(extra)
    return subprocess.run(cmd, capture_output=True, text=True)


def compile_dump(outdir, name, tmp_path):
    """Build the host program that prints the firmware's EDS for one generated OD."""
    exe = tmp_path / f"dump_{name}"
    cmd = ["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-O1",
           "-DCONFIG_CANOPEN_OD_NAMES=1", "-DCONFIG_CANOPEN_OD_SCRATCH_SIZE=1024",
           f"-DOD_NAME={name}", f'-DOD_HEADER="{name}_od.h"',
           "-I", os.path.join(BASE, "include"),
           "-I", os.path.join(BASE, "subsys", "canopen", "od"),
           "-I", os.path.join(BASE, "subsys", "canopen", "core"), "-I", str(outdir),
           os.path.join(HERE, "host", "eds_dump.c"),
           os.path.join(BASE, "subsys", "canopen", "od", "od.c"),
           os.path.join(BASE, "subsys", "canopen", "od", "od_eds.c"),
           os.path.join(str(outdir), f"{name}_od.c"), "-o", str(exe)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return exe

