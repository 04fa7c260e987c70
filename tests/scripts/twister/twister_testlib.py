"""Helpers shared by the runner's tests (imported by name; conftest.py sets up sys.path)."""

import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
TWISTER = REPO / "scripts" / "twister"
TREES = HERE / "trees"
FAKE_BIN = HERE / "fake_toolchain"


class TwisterRun:
    def __init__(self, proc: subprocess.CompletedProcess, outdir: Path):
        self.proc = proc
        self.outdir = outdir
        self.returncode = proc.returncode
        self.stdout = proc.stdout
        self.lines = proc.stdout.splitlines()

    @property
    def json(self) -> dict:
        return json.loads((self.outdir / "twister.json").read_text())

    def suite(self, name: str, platform: str = "native_posix") -> dict:
        for s in self.json["testsuites"]:
            if s["name"] == name and s.get("platform", "") == platform:
                return s
        raise KeyError(f"{name} on {platform} not in twister.json")

    def cases(self, name: str) -> dict:
        return {c["identifier"]: c for c in self.suite(name)["testcases"]}


def run_twister(args, outdir: Path, fake=False, env=None, timeout=300) -> TwisterRun:
    e = dict(os.environ)
    if fake:
        e["PATH"] = f"{FAKE_BIN}{os.pathsep}{e['PATH']}"
    e.update(env or {})
    cmd = [sys.executable, str(TWISTER), "-O", str(outdir), *[str(a) for a in args]]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=e, timeout=timeout)
    return TwisterRun(proc, outdir)

