"""scripts/twister end to end on real images: the SafeLine build system, the kernel and ztest.

Skipped (with the reason) only while those pieces are missing from the tree. One twister run
builds the few small fixture images under trees/real and every test checks one aspect of it.
"""

import xml.etree.ElementTree as ET

import pytest
from twister_testlib import REPO, TREES, run_twister

REAL = TREES / "real"
BAD = TREES / "bad_yaml"


def missing_pieces() -> list[str]:
    missing = []
    if not (REPO / "cmake" / "SafeLineConfig.cmake").is_file():
        missing.append("cmake/SafeLineConfig.cmake (build system)")
    ztest_h = [REPO / "include" / "zephyr" / "ztest.h", *REPO.glob("subsys/testsuite/**/zephyr/ztest.h")]
    if not any(p.is_file() for p in ztest_h):
        missing.append("zephyr/ztest.h (ztest)")
    return missing


pytestmark = pytest.mark.skipif(bool(missing_pieces()), reason=f"needs {', '.join(missing_pieces())}")


@pytest.fixture(scope="module")
def real(tmp_path_factory):
    out = tmp_path_factory.mktemp("real") / "twister-out"
    return run_twister(["-T", REAL, "-T", BAD, "-j", "2", "-v"], out, timeout=900)


def test_exit_code_and_last_line(real):
    assert real.returncode == 1, real.stdout
    # passing: adds passed, skips skipped; fixture: its 2 cases skipped; failing: good passed,
    # bad failed; hanging: first passed, forever failed; build_error: 1 case blocked (failed);
    # console: 1 passed; the 2 bad YAML files: 2 failed.
    assert real.lines[-1] == "4 passed, 5 failed, 3 skipped", real.stdout


def test_passing(real):
    s = real.suite("twister.e2e.passing")
    assert s["status"] == "passed", s.get("log")
    assert {k: v["status"] for k, v in real.cases("twister.e2e.passing").items()} == {
        "twister.e2e.passing.twister_pass.adds": "passed",
        "twister.e2e.passing.twister_pass.skips": "skipped",
    }
    build = real.outdir / "native_posix" / s["path"] / "twister.e2e.passing"
    assert (build / "zephyr" / "zephyr.exe").is_file()
    assert "PROJECT EXECUTION SUCCESSFUL" in (build / "handler.log").read_text()
    assert (build / "build.log").is_file()


def test_filter_on_the_real_config(real):
    s = real.suite("twister.e2e.passing.filtered")
    assert (s["status"], s["reason"]) == ("filtered", "filter: not CONFIG_ZTEST")


def test_fixture_skip(real):
    s = real.suite("twister.e2e.passing.fixture")
    assert (s["status"], s["reason"]) == ("skipped", "fixture twister_e2e_absent_fixture not available")


def test_failing(real):
    s = real.suite("twister.e2e.failing")
    assert (s["status"], s["reason"]) == ("failed", "testsuite failed")
    cases = real.cases("twister.e2e.failing")
    assert cases["twister.e2e.failing.twister_fail.good"]["status"] == "passed"
    bad = cases["twister.e2e.failing.twister_fail.bad"]
    assert bad["status"] == "failed"
    assert "Assertion failed at" in bad["reason"]


def test_hanging(real):
    s = real.suite("twister.e2e.hanging")
    assert (s["status"], s["reason"]) == ("failed", "timeout")
    assert 2.9 < float(s["execution_time"]) < 10
    cases = real.cases("twister.e2e.hanging")
    assert cases["twister.e2e.hanging.twister_hang.first"]["status"] == "passed"
    assert cases["twister.e2e.hanging.twister_hang.forever"]["status"] == "failed"


def test_build_error(real):
    s = real.suite("twister.e2e.build_error")
    assert (s["status"], s["reason"]) == ("failed", "build failure")
    assert "error" in s["log"].lower()


def test_console(real):
    s = real.suite("twister.e2e.console")
    assert s["status"] == "passed", s.get("log")
    assert float(s["execution_time"]) < 10


def test_bad_yaml(real):
    assert any(
        line.startswith("ERROR   - tests/scripts/twister/trees/bad_yaml/broken/testcase.yaml: tests/bad.yaml.scenario/")
        for line in real.lines
    )


def test_reports(real):
    root = ET.parse(real.outdir / "twister.xml").getroot()
    suites = {s.get("name"): s for s in root.findall("testsuite")}
    np = suites["native_posix"]
    cases = {c.get("name"): c for c in np.findall("testcase")}
    assert cases["twister.e2e.hanging.twister_hang.forever"].find("failure").get("message") == "timeout"
    assert cases["twister.e2e.passing.twister_pass.skips"].find("skipped") is not None
    assert cases["twister.e2e.console"].find("failure") is None
    assert (real.outdir / "testplan.json").is_file()
    assert real.json["environment"]["toolchain"] == "host"
