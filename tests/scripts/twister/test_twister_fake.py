"""scripts/twister end to end, with a fake toolchain (fake_toolchain/cmake, ninja) whose "images"
are Python scripts printing Zephyr's console format. Fast, and independent of the real build."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ET

import pytest
from twister_testlib import FAKE_BIN, TREES, TWISTER, run_twister

FAKE = TREES / "fake"
BAD = TREES / "bad_yaml"


def pid_alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """One run over every fake scenario and the broken YAML files."""
    out = tmp_path_factory.mktemp("full") / "twister-out"
    return run_twister(["-T", FAKE, "-T", BAD, "-j", "2"], out, fake=True)


def test_exit_code_and_last_line(full):
    assert full.returncode == 1, full.stdout
    # Counted units (doc/twister.md): cases of ztest/pytest instances, one per console,
    # build-only instance and bad YAML file. passed: pass 1, filtered_in 1, fail 1, hang 1,
    # other_tag 1, pytest 2, console 1, build_only 1. failed: fail 1, hang 2 (the hung case and the
    # blocked one), fault 2, build_error 1, console nomatch 1, 2 bad files. skipped: pass 1,
    # filtered_in 1, pytest 1, misc.skip 1, 2 vcan instances without the fixture.
    assert full.lines[-1] == "9 passed, 9 failed, 6 skipped"


def test_progress_line_per_instance(full):
    progress = [line for line in full.lines if line.startswith("INFO    - ") and "/14 native_posix " in line]
    assert len(progress) == 14
    assert [int(line.split()[2].split("/")[0]) for line in progress] == list(range(1, 15))
    hang = next(line for line in progress if " fake.hang " in line)
    assert " FAILED (timeout) (" in hang and hang.endswith("s)")
    assert any(" fake.pass PASSED (" in line for line in progress)


def test_config_errors_are_reported_and_the_rest_still_runs(full):
    assert (
        "ERROR   - tests/scripts/twister/trees/bad_yaml/broken/testcase.yaml: tests/bad.yaml.scenario/timout: "
        "unknown key (did you mean 'timeout'?) (line 5)" in full.lines
    )
    assert (
        "ERROR   - tests/scripts/twister/trees/bad_yaml/broken/testcase.yaml: tests/bad.yaml.scenario/timeout: "
        "expected an integer, got string 'soon' (line 6)" in full.lines
    )
    bad = full.suite("tests/scripts/twister/trees/bad_yaml/bad_filter/testcase.yaml", platform="")
    assert bad["status"] == "error"
    assert "tests/bad.yaml.filter/filter: expected ')'" in bad["reason"]
    assert full.suite("fake.pass")["status"] == "passed"


def test_passing_ztest(full):
    s = full.suite("fake.pass")
    assert (s["status"], s["arch"], s["path"], s["runnable"]) == ("passed", "posix", "tests/scripts/twister/trees/fake/ztest_pass", True)
    assert {k: v["status"] for k, v in full.cases("fake.pass").items()} == {
        "fake.pass.demo.adds": "passed",
        "fake.pass.demo.skips": "skipped",
    }
    assert float(s["build_time"]) >= 0 and float(s["execution_time"]) > 0


def test_failing_ztest(full):
    s = full.suite("fake.fail")
    assert (s["status"], s["reason"]) == ("failed", "testsuite failed")
    cases = full.cases("fake.fail")
    assert cases["fake.fail.arith.good"]["status"] == "passed"
    assert cases["fake.fail.arith.bad"]["status"] == "failed"
    assert "1 + 1 == 3 is false" in cases["fake.fail.arith.bad"]["reason"]
    assert "PROJECT EXECUTION FAILED" in s["log"]


def test_hanging_ztest_is_killed(full):
    s = full.suite("fake.hang")
    assert (s["status"], s["reason"]) == ("failed", "timeout")
    assert 1.9 < float(s["execution_time"]) < 8
    assert {k: v["status"] for k, v in full.cases("fake.hang").items()} == {
        "fake.hang.hang.first": "passed",
        "fake.hang.hang.forever": "failed",
        "fake.hang.hang.never_reached": "blocked",
    }
    helper = full.outdir / "native_posix" / s["path"] / "fake.hang" / "helper.pid"
    assert not pid_alive(int(helper.read_text()))


def test_fault(full):
    s = full.suite("fake.fault")
    assert (s["status"], s["reason"]) == ("failed", "fatal error")


def test_build_failure(full):
    s = full.suite("fake.build_error")
    assert (s["status"], s["reason"]) == ("failed", "build failure")
    assert "error: expected ';'" in s["log"]
    build_log = full.outdir / "native_posix" / s["path"] / "fake.build_error" / "build.log"
    assert "$ ninja -C" in build_log.read_text()


def test_runtime_filter_uses_the_built_config(full):
    out = full.suite("fake.pass.filtered_out")
    assert (out["status"], out["reason"]) == ("filtered", "filter: CONFIG_FAKE_FEATURE and CONFIG_FAKE_LEVEL > 2")
    assert full.suite("fake.pass.filtered_in")["status"] == "passed"


def test_console_sample_is_stopped_once_matched(full):
    s = full.suite("fake.console.forever")
    assert s["status"] == "passed"
    assert s["recording"][:2] == [{"tick": "1"}, {"tick": "2"}]
    assert float(s["execution_time"]) < 8
    nomatch = full.suite("fake.console.nomatch")
    assert (nomatch["status"], nomatch["reason"]) == ("failed", "exited with code 1")


def test_pytest_harness(full):
    s = full.suite("fake.pytest")
    assert s["status"] == "passed", s.get("log")
    assert {k: v["status"] for k, v in full.cases("fake.pytest").items()} == {
        "fake.pytest.test_environment_names_the_build": "passed",
        "fake.pytest.test_image_runs": "passed",
        "fake.pytest.test_skipped": "skipped",
    }
    log = (full.outdir / "native_posix" / s["path"] / "fake.pytest" / "handler.log").read_text()
    assert "slowest 8 durations" in log, "the slowest cases are listed"


def test_fixture_not_given_means_skipped(full):
    for name in ("fake.vcan.ztest", "fake.vcan.pytest"):
        s = full.suite(name)
        assert (s["status"], s["reason"]) == ("skipped", "fixture vcan not available")


def test_static_statuses(full):
    got = {n: (full.suite(n)["status"], full.suite(n).get("reason")) for n in (
        "fake.misc.build_only", "fake.misc.slow", "fake.misc.skip", "fake.misc.other_tag",
        "fake.misc.no_can", "fake.misc.excluded")}
    assert got == {
        "fake.misc.build_only": ("passed", "build only"),
        "fake.misc.slow": ("filtered", "slow scenario (run with -S)"),
        "fake.misc.skip": ("skipped", "skip: true"),
        "fake.misc.other_tag": ("passed", None),
        "fake.misc.no_can": ("filtered", "platform lacks depends_on: flexray"),
        "fake.misc.excluded": ("filtered", "in platform_exclude"),
    }
    assert full.suite("fake.misc.build_only")["runnable"] is False


def test_json_environment(full):
    env = full.json["environment"]
    for key in ("os", "toolchain", "commit", "run_date", "options"):
        assert key in env
    assert env["options"]["jobs"] == 2


def test_junit(full):
    root = ET.parse(full.outdir / "twister.xml").getroot()
    suites = {s.get("name"): s for s in root.findall("testsuite")}
    np = suites["native_posix"]
    cases = {c.get("name"): c for c in np.findall("testcase")}
    assert cases["fake.hang.hang.forever"].find("failure").get("message") == "timeout"
    assert cases["fake.pass.demo.skips"].find("skipped") is not None
    assert cases["fake.console.forever"].find("failure") is None
    assert "fake.misc.slow" not in cases  # filtered instances are left out
    failures = len(np.findall("testcase/failure"))
    assert int(np.get("failures")) == failures == 7
    assert len(suites["config"].findall("testcase/error")) == 2


def test_testplan(full):
    plan = json.loads((full.outdir / "testplan.json").read_text())
    names = {s["name"] for s in plan["testsuites"]}
    assert {"fake.pass", "fake.misc.slow", "fake.vcan.ztest"} <= names


# --- options ----------------------------------------------------------------------------------


def test_extra_args_sanitizers_seed_and_image_args(tmp_path):
    run = run_twister(
        ["-T", FAKE, "-s", "fake.pass", "-x=CONFIG_A=y", "-xCONFIG_B=y", "--extra-args", "CONFIG_C=y",
         "--enable-ubsan", "--enable-tsan", "--seed", "7", "--", "--extra", "arg"],
        tmp_path / "o", fake=True,
    )
    assert run.returncode == 0, run.stdout
    build = tmp_path / "o" / "native_posix" / run.suite("fake.pass")["path"] / "fake.pass"
    cmake = json.loads((build / "fake-cmake-args.json").read_text())
    for flag in ("-DBOARD=native_posix", "-DCONFIG_A=y", "-DCONFIG_B=y", "-DCONFIG_C=y", "-DCONFIG_UBSAN=y",
                 "-DCONFIG_TSAN=y"):
        assert flag in cmake["args"]
    assert cmake["args"][:2] == ["-G", "Ninja"]
    assert cmake["SAFELINE_BASE"] == str(TWISTER.parents[1])
    assert "argv: --seed=7 --extra arg" in (build / "handler.log").read_text()
    assert run.lines[-1] == "1 passed, 0 failed, 1 skipped"
    # --enable-asan cannot go with --enable-tsan (test_twister_sanitizers.py); alone it is passed on
    run = run_twister(["-T", FAKE, "-s", "fake.pass", "--enable-asan", "-b"], tmp_path / "o2", fake=True)
    assert run.returncode == 0, run.stdout
    cmake = json.loads(next((tmp_path / "o2").rglob("fake-cmake-args.json")).read_text())
    assert "-DCONFIG_ASAN=y" in cmake["args"]


def test_extra_conf_files_and_extra_args_from_yaml(tmp_path):
    tree = tmp_path / "tree" / "t"
    (tree / "src").mkdir(parents=True)
    (tree / "image.py").write_text((FAKE / "ztest_pass" / "image.py").read_text())
    (tree / "testcase.yaml").write_text(textwrap.dedent("""
        tests:
          t.confs:
            extra_conf_files: [a.conf, b.conf]
            extra_args: CONF_FILE=prj_x.conf -DFOO=1
            extra_configs: ['CONFIG_S="text"']
        """))
    run = run_twister(["-T", tmp_path / "tree", "-b"], tmp_path / "o", fake=True)
    assert run.returncode == 0, run.stdout
    args = json.loads(next((tmp_path / "o").rglob("fake-cmake-args.json")).read_text())["args"]
    assert "-DEXTRA_CONF_FILE=a.conf;b.conf" in args
    assert "-DCONF_FILE=prj_x.conf" in args and "-DFOO=1" in args
    assert '-DCONFIG_S="text"' in args


def test_build_only_flag(tmp_path):
    run = run_twister(["-T", FAKE / "ztest_pass", "-T", FAKE / "ztest_fail", "-b"], tmp_path / "o", fake=True)
    assert run.returncode == 0, run.stdout
    assert run.suite("fake.fail")["status"] == "passed"  # built, never run
    assert run.suite("fake.fail")["runnable"] is False
    assert not list((tmp_path / "o").rglob("handler.log"))
    # fake.pass, fake.pass.filtered_in, fake.fail: one each; filtered_out is not counted
    assert run.lines[-1] == "3 passed, 0 failed"


def test_tags_and_scenario_selection(tmp_path):
    run = run_twister(["-T", FAKE / "misc", "-t", "other"], tmp_path / "o", fake=True)
    ran = [s["name"] for s in run.json["testsuites"] if s["status"] != "filtered"]
    assert ran == ["fake.misc.other_tag"]
    run = run_twister(["-T", FAKE, "-s", "fake.nope"], tmp_path / "o2", fake=True)
    assert run.returncode == 2
    assert "ERROR   - no scenario named fake.nope (see --list-tests)" in run.lines


def test_list_tests_and_tags(tmp_path):
    run = run_twister(["-T", FAKE, "--list-tests"], tmp_path / "o", fake=True)
    assert run.returncode == 0
    assert " - fake.pass.demo.adds" in run.lines and " - fake.console.forever" in run.lines
    assert " - fake.hang.hang.never_reached" in run.lines
    assert not (tmp_path / "o").exists()
    run = run_twister(["-T", FAKE, "--list-tags"], tmp_path / "o", fake=True)
    assert [line for line in run.lines if line.startswith(" - ")] == [" - demo", " - fake", " - misc", " - other", " - socketcan"]


def test_outdir_is_kept_as_numbered_copy_or_clobbered(tmp_path):
    out = tmp_path / "twister-out"
    for _ in range(2):
        assert run_twister(["-T", FAKE / "misc", "-s", "fake.misc.build_only"], out, fake=True).returncode == 0
    assert (tmp_path / "twister-out.1" / "twister.json").is_file()
    assert run_twister(["-T", FAKE / "misc", "-s", "fake.misc.build_only", "-c"], out, fake=True).returncode == 0
    assert not (tmp_path / "twister-out.2").exists()
    precious = tmp_path / "precious"
    precious.mkdir()
    (precious / "thesis.txt").write_text("keep me")
    run = run_twister(["-T", FAKE / "misc", "-c"], precious, fake=True)
    assert run.returncode == 2 and (precious / "thesis.txt").is_file()


def test_retry_failed(tmp_path):
    run = run_twister(["-T", FAKE / "ztest_fail", "--retry-failed", "2"], tmp_path / "o", fake=True)
    assert run.returncode == 1
    assert run.suite("fake.fail")["retries"] == 2
    assert "INFO    - retry 2 of 2: 1 failed instance(s)" in run.lines


def test_timeout_multiplier(tmp_path):
    run = run_twister(["-T", FAKE / "hang", "--timeout-multiplier", "0.5"], tmp_path / "o", fake=True)
    s = run.suite("fake.hang")
    assert s["reason"] == "timeout" and float(s["execution_time"]) < 1.9


def test_inline_logs(tmp_path):
    run = run_twister(["-T", FAKE / "ztest_fail", "-i"], tmp_path / "o", fake=True)
    start = run.lines.index("---- handler.log of native_posix/tests/scripts/twister/trees/fake/ztest_fail/fake.fail ----")
    assert "PROJECT EXECUTION FAILED" in run.lines[start:]


def test_ctrl_c_kills_children_and_reports(tmp_path):
    out = tmp_path / "o"
    env = dict(os.environ, PATH=f"{FAKE_BIN}{os.pathsep}{os.environ['PATH']}")
    proc = subprocess.Popen(
        [sys.executable, str(TWISTER), "-O", str(out), "-T", str(FAKE / "hang"), "--timeout-multiplier", "60"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
    )
    helper_pid = next(out.rglob("helper.pid"), None) if out.exists() else None
    deadline = time.monotonic() + 30
    while helper_pid is None or not helper_pid.read_text():
        assert time.monotonic() < deadline, "the hanging image never started"
        time.sleep(0.1)
        helper_pid = next(out.rglob("helper.pid"), None) if out.exists() else None
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    stdout, _ = proc.communicate(timeout=30)
    assert proc.returncode == 130, stdout
    assert not pid_alive(int(helper_pid.read_text()))
    data = json.loads((out / "twister.json").read_text())
    hang = next(s for s in data["testsuites"] if s["name"] == "fake.hang")
    assert (hang["status"], hang["reason"]) == ("skipped", "interrupted")
    assert stdout.splitlines()[-1] == "1 passed, 0 failed, 2 skipped"


# --- the vcan fixture with stand-in VMs ------------------------------------------------------

PASSTHROUGH_VM = """#!/bin/sh
# Stand-in for scripts/vcan-vm: records its options, then runs the command on the host.
printf '%s\\n' "$@" > "$VM_ARGS_FILE"
while [ "$1" != "--" ]; do shift; done
shift
echo "vcan-vm: boot to command 0.01 s (stand-in)" >&2
exec "$@"
"""


def make_vm(tmp_path, text):
    vm = tmp_path / "vcan-vm"
    vm.write_text(textwrap.dedent(text))
    vm.chmod(0o755)
    return vm


def test_vcan_instances_run_in_one_vm_with_their_own_interfaces(tmp_path):
    vm = make_vm(tmp_path, PASSTHROUGH_VM)
    args_file = tmp_path / "vm-args.txt"
    run = run_twister(["-T", FAKE / "vcan", "-X", "vcan", "--vcan-vm", vm, "-v"], tmp_path / "o", fake=True,
                      env={"VM_ARGS_FILE": str(args_file)})
    assert run.returncode == 0, run.stdout
    assert run.lines[-1] == "2 passed, 0 failed"
    vm_args = args_file.read_text().splitlines()
    assert vm_args[0] == "-v"
    assert vm_args[vm_args.index("--ifaces") + 1] == "vcan0,vcan1,vcan2"
    assert vm_args[vm_args.index("--") + 2:][-2] == "--run-plan"
    assert "INFO    - vcan-vm: boot to command 0.01 s (stand-in)" in run.lines
    ztest_log = (tmp_path / "o" / "native_posix" / run.suite("fake.vcan.ztest")["path"] / "fake.vcan.ztest" / "handler.log")
    pytest_out = run.suite("fake.vcan.pytest")
    assert pytest_out["status"] == "passed"
    proof = tmp_path / "o" / "native_posix" / pytest_out["path"] / "fake.vcan.pytest" / "vm-proof.txt"
    assert proof.read_text().startswith("VCAN_VM= iface=vcan")  # the stand-in ran it on the host
    lines = [line for line in ztest_log.read_text().splitlines() if line.startswith("can lines:")]
    assert len(lines) == 1 and "--can-if=0:vcan" in lines[0] and "--can-if=1:vcan" in lines[0]


def test_vcan_vm_that_cannot_start_skips_with_its_reason(tmp_path):
    vm = make_vm(tmp_path, """#!/bin/sh
        echo "vcan-vm: cannot start VM: /usr/bin/linux.uml missing" >&2
        exit 75
        """)
    run = run_twister(["-T", FAKE / "vcan", "-X", "vcan", "--vcan-vm", vm], tmp_path / "o", fake=True)
    assert run.returncode == 0, run.stdout
    for name in ("fake.vcan.ztest", "fake.vcan.pytest"):
        s = run.suite(name)
        assert (s["status"], s["reason"]) == ("skipped", "vcan-vm: cannot start VM: /usr/bin/linux.uml missing")
    assert run.lines[-1] == "0 passed, 0 failed, 2 skipped"


def test_missing_vcan_vm_skips(tmp_path):
    run = run_twister(["-T", FAKE / "vcan", "-X", "vcan", "--vcan-vm", tmp_path / "none"], tmp_path / "o", fake=True)
    assert run.suite("fake.vcan.ztest")["status"] == "skipped"
    assert run.suite("fake.vcan.ztest")["reason"].startswith("vcan-vm: cannot start VM: ")


def test_vm_dying_midway_is_an_error(tmp_path):
    vm = make_vm(tmp_path, """#!/bin/sh
        echo "vcan-vm: the guest died while the command ran (status 125)" >&2
        exit 125
        """)
    run = run_twister(["-T", FAKE / "vcan", "-X", "vcan", "--vcan-vm", vm], tmp_path / "o", fake=True)
    assert run.returncode == 1
    s = run.suite("fake.vcan.ztest")
    assert s["status"] == "error" and "exit 125" in s["reason"] and "guest died" in s["reason"]


def test_vm_batch_overlaps_the_host_instances(tmp_path):
    # The vcan instances are built first and their VM batch starts at once, while the host
    # instances still run: here the VM's two results come before the 2 s hang is killed, where
    # a VM run after every host instance would report them last.
    vm = make_vm(tmp_path, PASSTHROUGH_VM)
    run = run_twister(["-T", FAKE / "vcan", "-T", FAKE / "hang", "-X", "vcan", "--vcan-vm", vm,
                       "-j", "1"], tmp_path / "o", fake=True,
                      env={"VM_ARGS_FILE": str(tmp_path / "vm-args.txt")})
    progress = [line for line in run.lines if " native_posix " in line and "/3 " in line]
    order = [next(n for n in ("fake.vcan.ztest", "fake.vcan.pytest", "fake.hang") if n in line)
             for line in progress]
    assert order.index("fake.hang") == 2, progress
    assert run.suite("fake.hang")["reason"] == "timeout"
