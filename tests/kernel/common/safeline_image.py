# SPDX-License-Identifier: Apache-2.0
"""Find (or build) the image of a test folder for its pytest harness.

Under the test runner the image is given: SAFELINE_IMAGE (twister's pytest harness contract).
Run by hand (`python3 -m pytest tests/kernel/cmdline/pytest`), the folder is built once into a
temporary directory with CMake and Ninja, so the tests never silently skip.
"""

import os
import pathlib
import subprocess


def image_path(test_dir: pathlib.Path, build_root: pathlib.Path) -> pathlib.Path:
    given = os.environ.get("SAFELINE_IMAGE")
    if given:
        return pathlib.Path(given)

    base = os.environ.get("SAFELINE_BASE") or str(test_dir.resolve().parents[2])
    build = build_root / test_dir.name
    env = dict(os.environ, SAFELINE_BASE=base)
    subprocess.run(["cmake", "-G", "Ninja", "-S", str(test_dir), "-B", str(build)],
                   check=True, env=env, stdout=subprocess.DEVNULL)
    subprocess.run(["ninja", "-C", str(build)], check=True, env=env, stdout=subprocess.DEVNULL)
    return build / "zephyr" / "zephyr.exe"


def run(image: pathlib.Path, *args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """Run the image to its end; stdout and stderr as text."""
    return subprocess.run([str(image), *args], capture_output=True, text=True, timeout=timeout)
