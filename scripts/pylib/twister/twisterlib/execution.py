"""One run of one built instance: the image (or pytest) under its harness.

A RunSpec holds everything a run needs and nothing else, as plain data, so the same code runs
an instance on the host and inside the vcan VM (where the spec arrives as JSON, see vm.py).
"""

import os
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

from . import handler
from . import statuses as st
from .harness import ConsoleHarness, PytestHarness, ZtestHarness
from .instance import TestCase

RESULT_FILE = "twister-result.json"


@dataclass
class RunSpec:
    name: str  # instance name, for messages
    scenario: str
    source_dir: str
    build_dir: str
    harness: str  # ztest | console | pytest
    harness_config: dict
    timeout: float  # seconds, multipliers applied
    expected_cases: list = field(default_factory=list)  # "suite.case"
    image_args: list = field(default_factory=list)  # extra arguments for zephyr.exe
    env: dict = field(default_factory=dict)  # added to the environment
    ignore_faults: bool = False
    base: str = ""  # the repo root (SAFELINE_BASE)
    emulator: str = ""  # the board's `simulation` exec the image runs under; "" for the host

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "RunSpec":
        return cls(**d)

    @property
    def image(self) -> Path:
        return Path(self.build_dir) / "zephyr" / "zephyr.exe"


@dataclass
class RunResult:
    status: str
    reason: str | None
    execution_time: float
    testcases: list = field(default_factory=list)  # of TestCase
    recording: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return {
            "status": self.status,
            "reason": self.reason,
            "execution_time": self.execution_time,
            "testcases": [tc.to_dict() for tc in self.testcases],
            "recording": self.recording,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "RunResult":
        return cls(
            d["status"],
            d.get("reason"),
            float(d.get("execution_time", 0.0)),
            [TestCase.from_dict(t) for t in d.get("testcases", [])],
            d.get("recording", []),
        )


def pytest_command(spec: RunSpec) -> list[str]:
    roots = spec.harness_config.get("pytest_root") or ["pytest"]
    junit = Path(spec.build_dir) / "report.xml"
    return [
        sys.executable,
        "-m",
        "pytest",
        *[str(Path(spec.source_dir) / r) for r in roots],
        f"--junitxml={junit}",
        "-o",
        "junit_family=xunit2",
        "-p",
        "no:cacheprovider",  # nothing written into the source tree
        "-q",
        # The slowest cases in the log: where an interop scenario's time goes.
        "--durations=8",
        *spec.harness_config.get("pytest_args", []),
    ]


def execute(spec: RunSpec, echo=None) -> RunResult:
    """Run one built instance and judge it. Output goes to <build_dir>/handler.log."""
    build_dir = Path(spec.build_dir)
    log_path = build_dir / "handler.log"
    env = dict(os.environ)
    env.update(spec.env)
    env["SAFELINE_BASE"] = spec.base
    env["SAFELINE_BUILD_DIR"] = str(build_dir)
    env["SAFELINE_IMAGE"] = str(spec.image)
    if spec.emulator:
        # For pytest scenarios that start the image themselves.
        env["SAFELINE_EMULATOR"] = spec.emulator

    if spec.harness == "pytest":
        junit = build_dir / "report.xml"
        junit.unlink(missing_ok=True)
        harness = PytestHarness(spec.scenario, junit)
        cmd = pytest_command(spec)
        cwd = str(build_dir)  # files the tests write land in the build folder
    else:
        if not spec.image.is_file():
            log_path.write_text(f"image not found: {spec.image}\n")
            return RunResult(st.ERROR, "image not found", 0.0)
        if spec.harness == "console":
            harness = ConsoleHarness(spec.scenario, spec.harness_config, spec.ignore_faults)
        else:
            harness = ZtestHarness(spec.scenario, spec.expected_cases, spec.ignore_faults)
        cmd = [str(spec.image), *spec.image_args]
        if spec.emulator:
            cmd.insert(0, spec.emulator)
        cwd = str(build_dir)

    res = handler.run(cmd, cwd=cwd, env=env, timeout=spec.timeout, log_path=log_path, on_line=harness.feed, echo=echo)
    status, reason, cases = harness.finalize(res)
    if handler.REGISTRY.interrupted.is_set():
        # Killed by Ctrl-C, not by its own doing: nothing it did not finish counts as failed.
        status, reason = st.SKIPPED, "interrupted"
        for tc in cases:
            if tc.status not in (st.PASSED, st.SKIPPED):
                tc.status, tc.reason = st.SKIPPED, reason
    recording = getattr(harness, "recording", [])
    return RunResult(status, reason, res.duration, cases, recording)
