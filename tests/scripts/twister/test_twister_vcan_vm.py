"""The vcan fixture through the real scripts/vcan-vm (fake images, so no build system needed).

Skipped with the VM's own reason where it cannot boot (`scripts/vcan-vm --check` exits 75).
"""

import subprocess

import pytest
from twister_testlib import REPO, TREES, run_twister

VCAN_VM = REPO / "scripts" / "vcan-vm"


def vm_problem() -> str | None:
    if not VCAN_VM.is_file():
        return "scripts/vcan-vm missing"
    try:
        proc = subprocess.run([str(VCAN_VM), "--check"], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return "scripts/vcan-vm --check did not finish in 120 s"
    if proc.returncode != 0:
        return (proc.stderr.strip().splitlines() or [f"vcan-vm --check exit {proc.returncode}"])[-1]
    return None


@pytest.fixture(scope="module")
def vm_run(tmp_path_factory):
    problem = vm_problem()
    if problem:
        pytest.skip(problem)
    out = tmp_path_factory.mktemp("vm") / "twister-out"
    return run_twister(["-T", TREES / "fake" / "vcan", "-X", "vcan", "-v"], out, fake=True, timeout=600)


def test_instances_pass_inside_the_vm(vm_run):
    assert vm_run.returncode == 0, vm_run.stdout
    assert vm_run.lines[-1] == "2 passed, 0 failed"
    s = vm_run.suite("fake.vcan.pytest")
    proof = vm_run.outdir / "native_posix" / s["path"] / "fake.vcan.pytest" / "vm-proof.txt"
    assert proof.read_text().startswith("VCAN_VM=1 iface=vcan") and proof.read_text().strip().endswith(" up")


def test_boot_time_is_shown_with_v(vm_run):
    assert any(line.startswith("INFO    - vcan-vm: boot to command ") for line in vm_run.lines), vm_run.stdout
    assert (vm_run.outdir / "vcan-vm.log").is_file()
