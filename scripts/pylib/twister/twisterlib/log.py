"""Console output with Zephyr twister's level prefixes.

Everything goes to stdout, flushed line by line, so that a person (or CI) watching a long run
sees progress as it happens and the order of messages is the order of events. Worker threads
print through the same lock.
"""

import sys
import threading

_lock = threading.Lock()
verbosity = 0


def _emit(prefix: str, msg: str) -> None:
    with _lock:
        for line in str(msg).splitlines() or [""]:
            sys.stdout.write(f"{prefix}{line}\n")
        sys.stdout.flush()


def raw(msg: str) -> None:
    """Print text as is (tables, listings, the final count line)."""
    with _lock:
        sys.stdout.write(msg if msg.endswith("\n") else msg + "\n")
        sys.stdout.flush()


def info(msg: str) -> None:
    _emit("INFO    - ", msg)


def warning(msg: str) -> None:
    _emit("WARNING - ", msg)


def error(msg: str) -> None:
    _emit("ERROR   - ", msg)


def verbose(msg: str) -> None:
    """Shown with -v."""
    if verbosity >= 1:
        _emit("INFO    - ", msg)


def debug(msg: str) -> None:
    """Shown with -vv."""
    if verbosity >= 2:
        _emit("DEBUG   - ", msg)
