"""Running child processes: a log file, a timeout, and the whole process group killed.

Every child starts in its own session (its own process group), so a terminal's Ctrl-C reaches
only twister, which then kills each group it started (`REGISTRY.kill_all()`); a timed-out image
is killed with everything it forked.
"""

import os
import signal
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

# What a line callback may ask for.
STOP = "stop"  # the harness has what it needs: stop the process now
GRACE = "grace"  # the verdict is printed: the process should exit soon, wait only a little

TERM_GRACE_S = 2.0  # between SIGTERM and SIGKILL
EXIT_GRACE_S = 10.0  # after GRACE, how long the process may take to exit


class ProcessRegistry:
    """The children alive right now, so that an interrupt can kill them all."""

    def __init__(self):
        self._lock = threading.Lock()
        self._procs: dict[subprocess.Popen, float] = {}  # process -> SIGTERM grace (s)
        self.interrupted = threading.Event()

    def add(self, proc: subprocess.Popen, grace: float = 0.5) -> None:
        with self._lock:
            self._procs[proc] = grace
        if self.interrupted.is_set():
            terminate_group(proc, grace)

    def remove(self, proc: subprocess.Popen) -> None:
        with self._lock:
            self._procs.pop(proc, None)

    def kill_all(self) -> None:
        self.interrupted.set()
        with self._lock:
            procs = list(self._procs.items())
        for proc, grace in procs:
            terminate_group(proc, grace)


REGISTRY = ProcessRegistry()


def _signal_group(proc: subprocess.Popen, sig: int) -> None:
    try:
        os.killpg(proc.pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def kill_group(proc: subprocess.Popen) -> None:
    _signal_group(proc, signal.SIGKILL)


def terminate_group(proc: subprocess.Popen, grace: float = TERM_GRACE_S) -> None:
    """SIGTERM the group, then SIGKILL it if the leader is still there after `grace` s."""
    if proc.poll() is None:
        _signal_group(proc, signal.SIGTERM)
        try:
            proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            pass
    # Whatever the leader did, its helpers in the group go too.
    kill_group(proc)


@dataclass
class ProcResult:
    returncode: int | None
    duration: float
    timed_out: bool = False
    stopped: bool = False  # stopped on the harness's request (STOP)
    exit_grace_expired: bool = False  # printed its verdict but did not exit


def popen(cmd, term_grace: float = 0.5, **kwargs) -> subprocess.Popen:
    """subprocess.Popen in a new session, registered for Ctrl-C.

    `term_grace`: on Ctrl-C, how long the process may clean up after SIGTERM before SIGKILL.
    """
    proc = subprocess.Popen(cmd, start_new_session=True, **kwargs)
    REGISTRY.add(proc, term_grace)
    return proc


def run(
    cmd: list[str],
    *,
    cwd: Path | str | None,
    env: dict | None,
    timeout: float | None,
    log_path: Path,
    on_line: Callable[[str], str | None] | None = None,
    log_mode: str = "wb",
    echo: Callable[[str], None] | None = None,
) -> ProcResult:
    """Run `cmd` with stdout and stderr merged into `log_path`, line by line.

    `on_line(line)` sees each line (without the newline) and may return STOP or GRACE.
    On timeout the process group is terminated and `timed_out` is set.
    """
    start = time.monotonic()
    deadline = start + timeout if timeout else None
    with open(log_path, log_mode) as log:
        try:
            proc = popen(
                cmd, cwd=cwd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT
            )
        except OSError as e:
            log.write(f"cannot run {cmd[0]}: {e}\n".encode())
            return ProcResult(returncode=127, duration=0.0)
        request = {"action": None}
        wake = threading.Event()

        def reader():
            for raw in iter(proc.stdout.readline, b""):
                try:
                    log.write(raw)
                    log.flush()
                except ValueError:  # log closed: run() gave up waiting for the pipe
                    break
                line = raw.decode("utf-8", "replace").rstrip("\r\n")
                if echo:
                    echo(line)
                if on_line:
                    action = on_line(line)
                    if action == STOP or (action == GRACE and request["action"] is None):
                        request["action"] = action
                        wake.set()
            wake.set()

        thread = threading.Thread(target=reader, daemon=True)
        thread.start()
        result = ProcResult(returncode=None, duration=0.0)
        grace_deadline = None
        try:
            while proc.poll() is None:
                now = time.monotonic()
                if request["action"] == STOP:
                    result.stopped = True
                    break
                if request["action"] == GRACE and grace_deadline is None:
                    grace_deadline = now + EXIT_GRACE_S
                if deadline and now >= deadline:
                    result.timed_out = True
                    break
                if grace_deadline and now >= grace_deadline:
                    result.exit_grace_expired = True
                    break
                limit = min(d for d in (deadline, grace_deadline, now + 0.2) if d)
                wake.wait(max(0.0, min(0.2, limit - now)))
                wake.clear()
        finally:
            # Also on success: a helper the image forked must not outlive it (nor hold the pipe).
            terminate_group(proc)
            result.returncode = proc.wait()
            thread.join(timeout=5.0)
            proc.stdout.close()
            REGISTRY.remove(proc)
        result.duration = time.monotonic() - start
    return result
