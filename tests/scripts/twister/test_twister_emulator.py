"""Boards whose image runs under an emulator (`simulation: [{name, exec}]` in the board YAML,
doc/twister.md): twister starts `<exec> zephyr.exe <args>`, hands the exec to pytest scenarios,
and skips (after the build) when the exec is not on PATH. With the fake toolchain."""

import json
import os
import textwrap
from pathlib import Path

from twister_testlib import FAKE_BIN, REPO, TREES, run_twister
from twisterlib.boards import load_platforms

FAKE = TREES / "fake"

# Stands in for qemu-user: says it ran, then runs the image with its arguments.
FAKE_QEMU = """\
#!/usr/bin/env python3
import os, sys
print("fake-qemu: " + " ".join(sys.argv[1:]), flush=True)
os.execv(sys.argv[1], sys.argv[1:])
"""


def board_root(tmp_path, exec_name):
    d = tmp_path / "boards" / "posix" / "fake_cross"
    d.mkdir(parents=True)
    (d / "fake_cross.yaml").write_text(textwrap.dedent(f"""\
        identifier: fake_cross
        arch: posix
        type: native
        supported: [can]
        simulation:
          - name: qemu
            exec: {exec_name}
        testing:
          timeout_multiplier: 3
        """))
    return tmp_path / "boards"


def with_fake_qemu(tmp_path):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    qemu = bin_dir / "fake-qemu"
    qemu.write_text(FAKE_QEMU)
    qemu.chmod(0o755)
    # run_twister(fake=True) puts the fake cmake and ninja first; this PATH replaces its own
    return {"PATH": os.pathsep.join((str(bin_dir), str(FAKE_BIN), os.environ["PATH"]))}


def build_dir(run, name):
    return run.outdir / "fake_cross" / run.suite(name, "fake_cross")["path"] / name


def test_the_simulation_exec_is_the_emulator(tmp_path):
    platforms, errors = load_platforms([board_root(tmp_path, "qemu-arm-static")])
    assert errors == []
    assert platforms["fake_cross"].emulator == "qemu-arm-static"


def test_a_board_without_simulation_runs_its_image_itself():
    platforms, errors = load_platforms([REPO / "boards"])
    assert errors == []
    assert platforms["native_posix"].emulator is None


def test_simulation_entries_are_checked(tmp_path):
    d = tmp_path / "posix" / "bad"
    d.mkdir(parents=True)
    (d / "bad.yaml").write_text("identifier: bad\narch: posix\nsimulation:\n  - exec: qemu-arm-static\n")
    _, errors = load_platforms([tmp_path], display=lambda p: Path(p).name)
    assert [str(e) for e in errors] == ["bad.yaml: simulation/0/name: missing required key (line 4)"]


def test_the_image_runs_under_the_emulator_with_its_arguments(tmp_path):
    run = run_twister(
        ["-A", board_root(tmp_path, "fake-qemu"), "-p", "fake_cross", "-T", FAKE, "-s", "fake.pass",
         "--seed", "3", "--", "--extra"],
        tmp_path / "o", fake=True, env=with_fake_qemu(tmp_path),
    )
    assert run.returncode == 0, run.stdout
    log = (build_dir(run, "fake.pass") / "handler.log").read_text().splitlines()
    image = build_dir(run, "fake.pass").resolve() / "zephyr" / "zephyr.exe"
    assert log[0] == f"fake-qemu: {image} --seed=3 --extra"
    assert "argv: --seed=3 --extra" in log
    assert run.suite("fake.pass", "fake_cross")["status"] == "passed"
    assert run.lines[-1] == "1 passed, 0 failed, 1 skipped"


def test_the_board_timeout_multiplier_applies_under_the_emulator(tmp_path):
    # fake.hang hangs: its 2 s timeout x 3 (the board's multiplier) before it is stopped
    run = run_twister(
        ["-A", board_root(tmp_path, "fake-qemu"), "-p", "fake_cross", "-T", FAKE, "-s", "fake.hang"],
        tmp_path / "o", fake=True, env=with_fake_qemu(tmp_path),
    )
    suite = run.suite("fake.hang", "fake_cross")
    assert suite["status"] == "failed" and suite["reason"] == "timeout"
    assert 6.0 <= float(suite["execution_time"]) < 12.0


def test_a_missing_emulator_skips_after_the_build(tmp_path):
    run = run_twister(
        ["-A", board_root(tmp_path, "no-such-qemu-for-twister"), "-p", "fake_cross", "-T", FAKE,
         "-s", "fake.pass"],
        tmp_path / "o", fake=True,
    )
    assert run.returncode == 0, run.stdout
    suite = run.suite("fake.pass", "fake_cross")
    assert suite["status"] == "skipped"
    assert suite["reason"] == "emulator no-such-qemu-for-twister not found"
    assert {c["status"] for c in suite["testcases"]} == {"skipped"}
    # built, so that it cannot rot; never run
    assert (build_dir(run, "fake.pass") / "zephyr" / "zephyr.exe").is_file()
    assert not (build_dir(run, "fake.pass") / "handler.log").exists()
    assert run.lines[-1] == "0 passed, 0 failed, 2 skipped"


def test_pytest_scenarios_are_told_the_emulator(tmp_path):
    tree = tmp_path / "tree" / "emu_pytest"
    (tree / "pytest").mkdir(parents=True)
    (tree / "image.py").write_text("print('image')\n")
    (tree / "testcase.yaml").write_text("tests:\n  fake.emu_pytest:\n    harness: pytest\n")
    (tree / "pytest" / "test_env.py").write_text(textwrap.dedent("""\
        import os
        import subprocess


        def test_the_emulator_is_named():
            assert os.environ["SAFELINE_EMULATOR"] == "fake-qemu"
            out = subprocess.run([os.environ["SAFELINE_EMULATOR"], os.environ["SAFELINE_IMAGE"]],
                                 capture_output=True, text=True, check=True).stdout
            assert out.startswith("fake-qemu: ") and "image" in out
        """))
    run = run_twister(
        ["-A", board_root(tmp_path, "fake-qemu"), "-p", "fake_cross", "-T", tmp_path / "tree"],
        tmp_path / "o", fake=True, env=with_fake_qemu(tmp_path),
    )
    assert run.returncode == 0, run.stdout + (build_dir(run, "fake.emu_pytest") / "handler.log").read_text()
    assert run.lines[-1] == "1 passed, 0 failed"


def test_the_repository_32_bit_boards(tmp_path):
    platforms, errors = load_platforms([REPO / "boards"])
    assert errors == []
    for name, qemu in (("native_posix_arm32", "qemu-arm-static"), ("native_posix_ppc32", "qemu-ppc-static")):
        p = platforms[name]
        # not in a plain `scripts/twister` run: run-tests runs them as a stage of their own
        assert not p.default
        assert p.emulator == qemu and p.timeout_multiplier > 1
        assert "sanitizer" in p.ignore_tags and p.supported == ["can"]
    plan_run = run_twister(["-T", FAKE, "-s", "fake.pass", "-y"], tmp_path / "o", fake=True)
    plan = json.loads((tmp_path / "o" / "testplan.json").read_text())
    assert {s["platform"] for s in plan["testsuites"]} == {"native_posix"}, plan_run.stdout
