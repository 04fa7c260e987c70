# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""scripts/fuzz: the list of harnesses, a replay that passes, a broken invariant that fails
(SAFELINE_FUZZ_BREAK=1 makes Operational an invalid NMT state), bad arguments, and the
eds2od harness's verdicts."""

import glob
import os
import re
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
FUZZ = os.path.join(BASE, "scripts", "fuzz")
EDS_HARNESS_DIR = os.path.join(BASE, "tests", "fuzz", "eds2od")

NAMES = ["nmt", "errctl", "sdo_server", "pdo", "sync", "time", "emcy", "sdo_client", "mgr",
         "lss", "srdo", "cdcf", "dcf", "eds2od"]

needs_clang = pytest.mark.skipif(
    subprocess.run(["sh", "-c", "command -v clang"], capture_output=True).returncode != 0,
    reason="clang (libFuzzer) not installed: scripts/setup")


def fuzz(*args, env=None):
    e = dict(os.environ, SAFELINE_BASE=BASE)
    e.pop("SAFELINE_FUZZ_BREAK", None)
    e.update(env or {})
    return subprocess.run([sys.executable, FUZZ, *args], capture_output=True, text=True,
                          env=e, cwd=BASE, timeout=900)


@needs_clang
def test_list_names_every_harness():
    r = fuzz("--list")
    assert r.returncode == 0, r.stderr
    listed = [line.split()[0] for line in r.stdout.splitlines() if line.strip()]
    assert listed == NAMES


@needs_clang
def test_replay_of_the_corpus_passes():
    r = fuzz("nmt", "--replay-only")
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1] == "fuzz: 1 passed, 0 failed"


@needs_clang
def test_a_broken_invariant_fails_the_run_and_names_it():
    reg = os.path.join(BASE, "tests", "fuzz", "nmt", "regressions")
    before = sorted(os.listdir(reg)) if os.path.isdir(reg) else []
    r = fuzz("nmt", "--time", "30", "--no-save", env={"SAFELINE_FUZZ_BREAK": "1"})
    assert r.returncode == 1, r.stdout + r.stderr
    assert "INVARIANT: nmt: Operational (SAFELINE_FUZZ_BREAK is set)" in r.stdout
    assert r.stdout.splitlines()[-1] == "fuzz: 0 passed, 1 failed"
    after = sorted(os.listdir(reg)) if os.path.isdir(reg) else []
    assert after == before, "--no-save leaves the regression inputs alone"


@needs_clang
def test_a_counted_run_fuzzes_that_many_inputs_with_the_seed():
    r = fuzz("nmt", "--runs", "300", "--seed", "1", "--no-save")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "300 inputs each, seed 1" in r.stdout.splitlines()[0]
    assert re.search(r"^nmt +ok +300 executions from \d+ inputs$", r.stdout, re.M), r.stdout


@needs_clang
def test_a_counted_run_starts_from_the_committed_seeds_only():
    seeds = len(os.listdir(os.path.join(BASE, "tests", "fuzz", "nmt", "corpus")))
    found = os.path.join(BASE, "build", "fuzz", "corpus", "nmt")
    os.makedirs(found, exist_ok=True)
    extra = os.path.join(found, "test-counted-run-ignores-me")
    with open(extra, "wb") as f:
        f.write(b"\x01\x02\x03 an input an earlier timed run found")
    try:
        counted = fuzz("nmt", "--runs", "300", "--seed", "1", "--no-save")
        timed = fuzz("nmt", "--time", "1", "--no-save")
    finally:
        os.remove(extra)
    assert counted.returncode == 0, counted.stdout + counted.stderr
    assert re.search(rf"^nmt +ok +300 executions from {seeds} inputs$", counted.stdout,
                     re.M), counted.stdout
    # A timed run reads the earlier finds too: at least the extra file more.
    m = re.search(r"^nmt +ok +\d+ executions from (\d+) inputs$", timed.stdout, re.M)
    assert m and int(m.group(1)) > seeds, timed.stdout


@needs_clang
def test_unknown_harness_is_refused():
    r = fuzz("nosuch", "--time", "1")
    assert r.returncode == 2
    assert "unknown harness nosuch" in r.stderr


def test_time_below_one_is_refused():
    r = fuzz("--time", "0")
    assert r.returncode == 2
    assert "--time and --jobs must be at least 1" in r.stderr


def eds_harness(*args):
    return subprocess.run([sys.executable, os.path.join(EDS_HARNESS_DIR, "fuzz_eds2od.py"),
                           *args], capture_output=True, text=True, cwd=BASE, timeout=300)


def test_eds2od_harness_stops_after_its_count_of_mutations():
    replays = len(glob.glob(os.path.join(EDS_HARNESS_DIR, "regressions", "*"))) + \
        len(glob.glob(os.path.join(EDS_HARNESS_DIR, "corpus", "*")))
    r = eds_harness("--runs", "40", "--time", "600")
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1] == f"executions: {replays + 40}"


def test_eds2od_harness_accepts_its_corpus_and_regressions():
    r = eds_harness("--replay-only")
    assert r.returncode == 0, r.stdout
    assert "executions: " in r.stdout


def test_eds2od_harness_flags_a_message_without_the_file(tmp_path, monkeypatch):
    sys.path.insert(0, EDS_HARNESS_DIR)
    import fuzz_eds2od

    def noisy(argv):
        print("something went wrong", file=sys.stderr)
        return 1

    monkeypatch.setattr(fuzz_eds2od, "eds2od_main", noisy)
    seed = os.path.join(EDS_HARNESS_DIR, "corpus", "lss.eds")
    assert fuzz_eds2od.check(seed, str(tmp_path)) == \
        "message without FILE[:LINE]: 'something went wrong'"


def test_eds2od_harness_flags_an_exception(tmp_path, monkeypatch):
    sys.path.insert(0, EDS_HARNESS_DIR)
    import fuzz_eds2od

    def broken(argv):
        raise KeyError("x")

    monkeypatch.setattr(fuzz_eds2od, "eds2od_main", broken)
    seed = os.path.join(EDS_HARNESS_DIR, "corpus", "lss.eds")
    assert fuzz_eds2od.check(seed, str(tmp_path)).startswith("Traceback")


@pytest.mark.parametrize("name", ["canopen-log-no-deviceinfo.eds",
                                  "canopen-error-multiline.eds"])
def test_eds2od_names_the_file_on_every_line_of_python_canopen_messages(name, tmp_path):
    """Found by the eds2od harness: python-canopen's log line (no [DeviceInfo]) came out bare,
    and its exception text split one warning over several lines."""
    src = os.path.join(EDS_HARNESS_DIR, "regressions", name)
    path = tmp_path / name
    path.write_bytes(open(src, "rb").read())
    r = subprocess.run([sys.executable, os.path.join(BASE, "scripts", "eds2od"), str(path),
                        "-o", str(tmp_path / "out")], capture_output=True, text=True)
    assert r.returncode in (0, 1)
    lines = r.stderr.splitlines()
    assert any("python-canopen" in line for line in lines), r.stderr
    for line in lines:
        assert line.startswith(f"{path}:") or line.startswith("eds2od: "), line


def test_eds2od_refuses_a_pdo_mapping_count_that_is_not_a_number(tmp_path):
    """Found by the eds2od harness: 1600h sub 0 typed VISIBLE_STRING raised a TypeError in the
    mapping check instead of the error about sub-index 0's type."""
    src = os.path.join(EDS_HARNESS_DIR, "regressions", "pdo-mapping-count-not-a-number.dcf")
    path = tmp_path / "slave.dcf"
    path.write_bytes(open(src, "rb").read())
    r = subprocess.run([sys.executable, os.path.join(BASE, "scripts", "eds2od"), str(path),
                        "-o", str(tmp_path / "out")], capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert f"{path}:213: sub-index 0 of 1600h must be UNSIGNED8" in r.stderr
