"""Building an instance: CMake (configure) and Ninja, both logged to <build_dir>/build.log."""

import os
import shlex
import time
from dataclasses import dataclass
from pathlib import Path

from . import handler
from .instance import TestInstance

# A build step that takes longer is stuck (a custom command waiting on something): give up.
BUILD_TIMEOUT_S = 1800


@dataclass
class BuildOptions:
    base: Path  # repo root, exported as SAFELINE_BASE
    extra_args: list  # -x values, "CONFIG_FOO=y" (→ -DCONFIG_FOO=y)
    sanitizers: list  # "ASAN", "UBSAN", "TSAN"
    ninja_jobs: int | None = None
    cmake: str = "cmake"
    ninja: str = "ninja"


def _dflag(arg: str) -> str:
    return arg if arg.startswith("-D") else f"-D{arg}"


def cmake_command(inst: TestInstance, opts: BuildOptions) -> list[str]:
    sc = inst.scenario
    cmd = [
        opts.cmake,
        "-G",
        "Ninja",
        "-S",
        str(sc.source_dir.resolve()),
        "-B",
        str(inst.build_dir),
        f"-DBOARD={inst.platform.identifier}",
    ]
    if sc.get("extra_conf_files"):
        # Relative names are resolved against the application folder by the build system.
        cmd.append("-DEXTRA_CONF_FILE=" + ";".join(sc.get("extra_conf_files")))
    for arg in sc.get("extra_args"):
        cmd.append(_dflag(arg))
    for cfg in sc.get("extra_configs"):
        cmd.append(f"-D{cfg}")
    for san in opts.sanitizers:
        cmd.append(f"-DCONFIG_{san}=y")
    for arg in opts.extra_args:
        cmd.append(_dflag(arg))
    return cmd


def ninja_command(inst: TestInstance, opts: BuildOptions) -> list[str]:
    cmd = [opts.ninja, "-C", str(inst.build_dir)]
    if opts.ninja_jobs:
        cmd += ["-j", str(opts.ninja_jobs)]
    return cmd


def _env(opts: BuildOptions) -> dict:
    env = dict(os.environ)
    env["SAFELINE_BASE"] = str(opts.base)
    return env


def _step(cmd: list[str], opts: BuildOptions, log_path: Path, first: bool) -> bool:
    with open(log_path, "wb" if first else "ab") as log:
        log.write(f"$ {shlex.join(cmd)}\n".encode())
    res = handler.run(cmd, cwd=None, env=_env(opts), timeout=BUILD_TIMEOUT_S, log_path=log_path, log_mode="ab")
    if res.timed_out:
        with open(log_path, "ab") as log:
            log.write(f"twister: {cmd[0]} stopped after {BUILD_TIMEOUT_S} s\n".encode())
    return res.returncode == 0 and not res.timed_out


def configure(inst: TestInstance, opts: BuildOptions) -> bool:
    """Run CMake; True on success."""
    inst.build_dir.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    ok = _step(cmake_command(inst, opts), opts, inst.build_dir / "build.log", first=True)
    inst.build_time += time.monotonic() - start
    return ok


def build(inst: TestInstance, opts: BuildOptions) -> bool:
    """Run Ninja; True on success."""
    start = time.monotonic()
    ok = _step(ninja_command(inst, opts), opts, inst.build_dir / "build.log", first=False)
    inst.build_time += time.monotonic() - start
    return ok


def dotconfig_path(build_dir: Path) -> Path:
    return Path(build_dir) / "zephyr" / ".config"


def read_dotconfig(path: Path) -> dict[str, str]:
    """CONFIG_* values from a Kconfig .config, string quotes removed; unset symbols absent."""
    values: dict[str, str] = {}
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            line = line.strip()
            if not line.startswith("CONFIG_") or "=" not in line:
                continue
            name, value = line.split("=", 1)
            if len(value) >= 2 and value[0] == value[-1] == '"':
                value = value[1:-1].replace('\\"', '"').replace("\\\\", "\\")
            values[name] = value
    return values


def failure_excerpt(log_path: Path, lines: int = 40) -> str:
    """The first error lines of a build log, or its tail."""
    try:
        text = Path(log_path).read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:
        return ""
    for i, line in enumerate(text):
        if "error" in line.lower() and not line.startswith("$ "):
            return "\n".join(text[i : i + lines])
    return "\n".join(text[-lines:])

