"""Tests of scripts/vcan-vm: the command's exit code, output, paths and environment cross the VM
boundary; real vcan works inside; a VM that cannot start fails fast with exit 75 and a reason.

The failure-mode tests use fake kernels (VCANVM_KERNEL) and run anywhere. The tests that boot the
real VM are skipped, with the tool's own reason, only where `scripts/vcan-vm --check` says the VM
cannot start (the same rule the test runner applies to vcan scenarios).
"""

import os
import pathlib
import re
import subprocess
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
TOOL = ROOT / "scripts" / "vcan-vm"
EX_TEMPFAIL = 75


def run(args, timeout=240, env=None, cwd=None):
    e = dict(os.environ)
    if env:
        e.update(env)
    return subprocess.run(
        [str(TOOL), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=e,
        cwd=cwd or ROOT,
        stdin=subprocess.DEVNULL,
    )


@pytest.fixture(scope="session")
def vm():
    r = run(["--check"], timeout=180)
    if r.returncode == EX_TEMPFAIL:
        pytest.skip(r.stderr.strip())
    assert r.returncode == 0, r.stderr


def fake_kernel(tmp_path, body):
    """A stand-in for linux.uml that reports the real module version and then runs body."""
    kver = subprocess.run(["/usr/bin/linux.uml", "--version"], capture_output=True, text=True)
    version = kver.stdout.strip() if kver.returncode == 0 else "6.1.176"
    k = tmp_path / "fake-linux.uml"
    k.write_text(
        "#!/bin/sh\n"
        f'if [ "$1" = --version ]; then echo {version}; exit 0; fi\n'
        f"{body}\n"
    )
    k.chmod(0o755)
    return str(k)


def no_leftovers(marker):
    out = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True).stdout
    return [line for line in out.splitlines() if marker in line and "ps -eo" not in line]


needs_uml = pytest.mark.skipif(
    not os.path.exists("/usr/bin/linux.uml"), reason="user-mode-linux not installed"
)


# --- failure modes (no real VM needed) --------------------------------------------------------


def test_missing_kernel_is_exit_75_with_reason():
    r = run(["--", "true"], env={"VCANVM_KERNEL": "/nonexistent/linux.uml"}, timeout=30)
    assert r.returncode == EX_TEMPFAIL
    assert r.stderr.startswith("vcan-vm: cannot start VM: /nonexistent/linux.uml not found")


def test_check_reports_missing_kernel():
    r = run(["--check"], env={"VCANVM_KERNEL": "/nonexistent/linux.uml"}, timeout=30)
    assert r.returncode == EX_TEMPFAIL
    assert "vcan-vm: cannot start VM:" in r.stderr


@needs_uml
def test_kernel_dying_at_boot_is_exit_75_with_its_last_words(tmp_path):
    k = fake_kernel(tmp_path, 'echo "Kernel panic - not syncing: fake"; exit 1')
    r = run(["--", "true"], env={"VCANVM_KERNEL": k}, timeout=30)
    assert r.returncode == EX_TEMPFAIL
    assert "vcan-vm: cannot start VM:" in r.stderr
    assert "Kernel panic - not syncing: fake" in r.stderr


@needs_uml
def test_hanging_boot_is_stopped_by_the_boot_timeout(tmp_path):
    k = fake_kernel(tmp_path, "exec sleep 300 # vcanvm-hang-marker")
    t0 = time.monotonic()
    r = run(["--boot-timeout", "2", "--", "true"], env={"VCANVM_KERNEL": k}, timeout=60)
    elapsed = time.monotonic() - t0
    assert r.returncode == EX_TEMPFAIL
    assert "did not reach the command within 2s" in r.stderr
    assert elapsed < 30
    time.sleep(0.5)
    assert no_leftovers("vcanvm-hang-marker") == []


def test_usage_errors_are_exit_2():
    assert run(["--", ], timeout=30).returncode == 2
    assert run(["--bogus", "--", "true"], timeout=30).returncode == 2
    r = run(["--ifaces", "vcan0,no/slash", "--", "true"], timeout=30)
    assert r.returncode == 2 and "bad interface name" in r.stderr


def test_share_with_comma_is_refused(tmp_path):
    d = tmp_path / "a,b"
    d.mkdir()
    r = run(["--share", str(d), "--", "true"], timeout=30)
    assert r.returncode == EX_TEMPFAIL
    assert "spaces and commas" in r.stderr


# --- the real VM ------------------------------------------------------------------------------


def test_exit_code_output_and_timing(vm):
    r = run(["-v", "--", "bash", "-c", "echo out-line; echo err-line >&2; exit 42"])
    assert r.returncode == 42
    assert r.stdout == "out-line\n"
    assert "err-line\n" in r.stderr
    m = re.search(r"vcan-vm: boot to command (\d+\.\d+) s", r.stderr)
    assert m, r.stderr
    assert 0.0 < float(m.group(1)) < 60.0


def test_cwd_env_python_and_shared_writes(vm, tmp_path):
    probe = tmp_path / "probe.txt"
    script = (
        'import os, sys, pathlib; '
        'pathlib.Path(os.environ["PROBE"]).write_text('
        'os.getcwd() + "|" + os.environ["VCANVM_TEST_VAR"] + "|" + sys.executable); '
        'pathlib.Path("/etc/vcanvm-should-vanish").write_text("x")'
    )
    r = run(
        ["--share", str(tmp_path), "--", "python3", "-c", script],
        env={"PROBE": str(probe), "VCANVM_TEST_VAR": "it survives"},
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    host_python = subprocess.run(
        ["python3", "-c", "import os, sys; print(os.path.realpath(sys.executable))"],
        capture_output=True,
        text=True,
    ).stdout.strip()
    cwd, var, exe = probe.read_text().split("|")
    assert cwd == str(tmp_path.resolve())
    assert var == "it survives"
    assert os.path.realpath(exe) == host_python
    # writes outside the shared directories land in the throw-away overlay
    assert not os.path.exists("/etc/vcanvm-should-vanish")


def test_candump_sees_cansend_on_requested_interfaces(vm):
    cmd = (
        "ip -br link show type vcan | cut -d' ' -f1 | sort | tr '\\n' ' '; echo; "
        "candump -n 1 -T 5000 vcan7 & sleep 0.5; cansend vcan7 123#DEADBEEF; wait"
    )
    r = run(["--ifaces", "vcan3,vcan7", "--", "bash", "-c", cmd])
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].split() == ["vcan3", "vcan7"]
    assert re.search(r"vcan7\s+123\s+\[4\]\s+DE AD BE EF", r.stdout), r.stdout


def test_bad_interface_fails_the_start_not_the_command(vm):
    r = run(["--ifaces", "lo", "--", "true"])
    assert r.returncode == EX_TEMPFAIL
    assert r.stderr.startswith("vcan-vm: cannot start VM: cannot create CAN interface lo")


def test_timeout_ends_the_guest(vm):
    t0 = time.monotonic()
    r = run(["--timeout", "12", "--", "sleep", "600"])
    assert r.returncode == 124
    assert time.monotonic() - t0 < 60
    time.sleep(0.5)
    assert no_leftovers("VCANVM_CTL=") == []


def test_sigterm_ends_the_guest(vm):
    import signal

    p = subprocess.Popen(
        [str(TOOL), "--", "bash", "-c", "echo started; exec sleep 600"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        text=True,
        cwd=ROOT,
    )
    try:
        assert p.stdout.readline() == "started\n"
        p.send_signal(signal.SIGTERM)
        assert p.wait(timeout=60) == 143
    finally:
        if p.poll() is None:
            p.kill()
    time.sleep(0.5)
    assert no_leftovers("VCANVM_CTL=") == []
