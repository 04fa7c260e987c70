"""Counting rules of the last line, twister.json and JUnit layout."""

import json
import xml.etree.ElementTree as ET
from pathlib import Path

from twisterlib import report
from twisterlib import statuses as st
from twisterlib.boards import Platform
from twisterlib.config import ConfigError, Scenario, merge_common
from twisterlib.instance import TestCase, TestInstance

PLAT = Platform("native_posix", "posix", default=True)


def inst(sid, status, cases=(), harness="test", build_only=False, reason=None):
    sc = Scenario(sid, Path("t/testcase.yaml"), Path("t"), "t", merge_common({}, {"harness": harness}))
    i = TestInstance(sc, PLAT, Path("/tmp/out") / sid, status=status, reason=reason, build_only=build_only)
    i.testcases = [TestCase(f"{sid}.s.{n}", s) for n, s in cases]
    return i


def test_ztest_instances_count_cases_blocked_as_failed():
    insts = [
        inst("a", st.PASSED, [("x", st.PASSED), ("y", st.PASSED), ("z", st.SKIPPED)]),
        inst("b", st.FAILED, [("x", st.PASSED), ("y", st.FAILED), ("z", st.BLOCKED)], reason="timeout"),
    ]
    assert report.counts(insts) == {"passed": 3, "failed": 2, "skipped": 1}


def test_failed_instance_without_failed_case_adds_one():
    i = inst("a", st.FAILED, [("x", st.PASSED)], reason="exited with code 1")
    assert report.counts([i]) == {"passed": 1, "failed": 1, "skipped": 0}


def test_console_build_only_errors_count_one_each_and_filtered_not_at_all():
    insts = [
        inst("c", st.PASSED, [("c", st.PASSED)], harness="console"),
        inst("b", st.PASSED, [("x", st.SKIPPED), ("y", st.SKIPPED)], build_only=True),
        inst("f", st.FILTERED, [("x", st.FILTERED)]),
        inst("s", st.SKIPPED, [], reason="skip: true"),
        TestInstance.for_config_errors([ConfigError("t/testcase.yaml", "tests", "missing required key")]),
    ]
    assert report.counts(insts) == {"passed": 2, "failed": 1, "skipped": 1}


def test_count_line():
    assert report.count_line({"passed": 3, "failed": 0, "skipped": 0}) == "3 passed, 0 failed"
    assert report.count_line({"passed": 3, "failed": 1, "skipped": 2}) == "3 passed, 1 failed, 2 skipped"


def test_json_and_junit(tmp_path):
    good = inst("a", st.PASSED, [("x", st.PASSED)])
    bad = inst("b", st.FAILED, [("x", st.FAILED), ("y", st.BLOCKED)], reason="timeout")
    bad.log = "START - test_x\n"
    bad.testcases[0].reason = "timeout"
    skipped = inst("c", st.SKIPPED, [("x", st.SKIPPED)], reason="fixture vcan not available")
    filtered = inst("d", st.FILTERED, [], reason="filter: CONFIG_X")
    err = TestInstance.for_config_errors([ConfigError("u/testcase.yaml", "tests/x/timeout", "expected an integer")])
    insts = [err, good, bad, skipped, filtered]

    report.write_json(tmp_path / "twister.json", insts, {"os": "posix"}, "rid")
    data = json.loads((tmp_path / "twister.json").read_text())
    suites = {s["name"]: s for s in data["testsuites"]}
    assert set(suites) == {"u/testcase.yaml", "a", "b", "c", "d"}
    b = suites["b"]
    for key in ("name", "arch", "platform", "path", "run_id", "runnable", "retries", "status", "reason", "log",
                "execution_time", "build_time", "testcases"):
        assert key in b
    assert (b["status"], b["reason"], b["log"]) == ("failed", "timeout", "START - test_x\n")
    assert [(t["identifier"], t["status"]) for t in b["testcases"]] == [("b.s.x", "failed"), ("b.s.y", "blocked")]
    assert "log" not in suites["a"] and "reason" not in suites["a"]
    assert suites["d"]["status"] == "filtered" and suites["d"]["runnable"] is False
    assert suites["u/testcase.yaml"]["status"] == "error"

    report.write_junit(tmp_path / "twister.xml", insts)
    root = ET.parse(tmp_path / "twister.xml").getroot()
    by_name = {s.get("name"): s for s in root.findall("testsuite")}
    assert set(by_name) == {"native_posix", "config"}
    np = by_name["native_posix"]
    assert (np.get("tests"), np.get("failures"), np.get("skipped"), np.get("errors")) == ("4", "2", "1", "0")
    cases = {c.get("name"): c for c in np.findall("testcase")}
    assert set(cases) == {"a.s.x", "b.s.x", "b.s.y", "c.s.x"}  # filtered "d" left out
    assert cases["b.s.x"].find("failure").get("message") == "timeout"
    assert cases["b.s.y"].find("failure").get("type") == "blocked"
    assert cases["b.s.x"].find("failure").text == "START - test_x\n"
    assert cases["c.s.x"].find("skipped") is not None
    assert cases["a.s.x"].get("classname") == "a"
    assert by_name["config"].find("testcase/error") is not None
