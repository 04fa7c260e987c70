"""pytest setup for the runner's tests: the twisterlib package on sys.path, fixture trees not
collected (they hold pytest files of their own, which twister runs as pytest-harness scenarios)."""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[2] / "scripts" / "pylib" / "twister"))

collect_ignore = ["trees", "fake_toolchain", "logs"]
