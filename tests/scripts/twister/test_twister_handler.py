"""Running a process: log, timeout, process-group kill, harness requests."""

import os
import sys
import time

from twisterlib import handler


def py(code):
    return [sys.executable, "-c", code]


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie is dead for our purpose.
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def test_output_goes_to_the_log_and_the_callback(tmp_path):
    seen = []
    res = handler.run(
        py("import sys; print('one'); print('two', file=sys.stderr); sys.exit(3)"),
        cwd=tmp_path, env=None, timeout=30, log_path=tmp_path / "h.log", on_line=seen.append,
    )
    assert res.returncode == 3 and not res.timed_out
    assert sorted(seen) == ["one", "two"]
    assert sorted((tmp_path / "h.log").read_text().split()) == ["one", "two"]


def test_timeout_kills_the_whole_process_group(tmp_path):
    code = (
        "import subprocess, time;"
        "p = subprocess.Popen(['sleep', '300']);"
        "open('child.pid', 'w').write(str(p.pid));"
        "print('started', flush=True);"
        "time.sleep(300)"
    )
    start = time.monotonic()
    res = handler.run(py(code), cwd=tmp_path, env=None, timeout=1.5, log_path=tmp_path / "h.log")
    took = time.monotonic() - start
    assert res.timed_out
    assert res.returncode < 0
    assert 1.4 < took < 10
    child = int((tmp_path / "child.pid").read_text())
    time.sleep(0.2)
    assert not alive(child)


def test_stop_request_ends_the_process(tmp_path):
    code = "import time\nfor i in range(1000):\n    print(f'tick {i}', flush=True); time.sleep(0.02)"
    res = handler.run(
        py(code), cwd=tmp_path, env=None, timeout=30, log_path=tmp_path / "h.log",
        on_line=lambda line: handler.STOP if line == "tick 5" else None,
    )
    assert res.stopped and not res.timed_out
    assert res.duration < 10
    assert "tick 5" in (tmp_path / "h.log").read_text()


def test_grace_bounds_the_wait_after_a_verdict(tmp_path, monkeypatch):
    monkeypatch.setattr(handler, "EXIT_GRACE_S", 0.5)
    code = "import time; print('PROJECT EXECUTION SUCCESSFUL', flush=True); time.sleep(60)"
    res = handler.run(
        py(code), cwd=tmp_path, env=None, timeout=30, log_path=tmp_path / "h.log",
        on_line=lambda line: handler.GRACE if "PROJECT" in line else None,
    )
    assert res.exit_grace_expired and not res.timed_out
    assert res.duration < 5


def test_missing_program(tmp_path):
    res = handler.run([str(tmp_path / "nope")], cwd=tmp_path, env=None, timeout=5, log_path=tmp_path / "h.log")
    assert res.returncode == 127
    assert "cannot run" in (tmp_path / "h.log").read_text()
