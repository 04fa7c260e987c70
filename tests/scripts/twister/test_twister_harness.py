"""Output parsers: ztest on recorded console logs, console regexes, pytest's JUnit XML."""

from pathlib import Path

import pytest
from twisterlib import statuses as st
from twisterlib.handler import GRACE, STOP, ProcResult
from twisterlib.harness import ConsoleHarness, PytestHarness, ZtestHarness, exit_reason

LOGS = Path(__file__).resolve().parent / "logs"


def feed(harness, text):
    actions = [harness.feed(line) for line in text.splitlines()]
    return [a for a in actions if a]


def ztest(logname, expected, returncode=0, **res):
    h = ZtestHarness("scn", expected)
    actions = feed(h, (LOGS / logname).read_text())
    status, reason, cases = h.finalize(ProcResult(returncode=returncode, duration=1.0, **res))
    return status, reason, {c.identifier: c for c in cases}, actions


def states(cases):
    return {k: v.status for k, v in cases.items()}


def test_passing_log():
    status, reason, cases, actions = ztest("ztest_pass.log", ["co_line.register", "co_line.timers", "co_sdo.expedited"])
    assert (status, reason) == (st.PASSED, None)
    assert states(cases) == {
        "scn.co_line.register": st.PASSED,
        "scn.co_line.timers": st.PASSED,
        "scn.co_sdo.expedited": st.PASSED,
    }
    assert cases["scn.co_line.timers"].duration == pytest.approx(0.010)
    assert actions == [GRACE]  # the verdict: the image should now exit


def test_verdict_needs_the_exit_code_too():
    status, reason, _, _ = ztest("ztest_pass.log", [], returncode=1)
    assert (status, reason) == (st.FAILED, "exited with code 1")
    status, reason, _, _ = ztest("ztest_pass.log", [], returncode=-11)
    assert (status, reason) == (st.FAILED, "killed by SIGSEGV")


def test_exit_code_zero_without_verdict_fails():
    status, reason, cases, _ = ztest("ztest_truncated.log", ["co_sync.producer", "co_sync.window"], returncode=0)
    assert (status, reason) == (st.FAILED, "no PROJECT EXECUTION verdict")


def test_failing_log_keeps_the_assertion():
    status, reason, cases, _ = ztest("ztest_fail.log", ["co_line.register", "co_line.timers", "co_line.wrap"], returncode=1)
    assert (status, reason) == (st.FAILED, "testsuite failed")
    assert states(cases) == {
        "scn.co_line.register": st.PASSED,
        "scn.co_line.timers": st.FAILED,
        "scn.co_line.wrap": st.PASSED,
    }
    assert cases["scn.co_line.timers"].reason == (
        "Assertion failed at tests/canopen/core/line/src/main.c:120: co_line_test_timers: (next == 1000 is false)"
        ": next deadline wrong"
    )
    assert cases["scn.co_line.wrap"].reason is None


def test_skipped_log():
    status, _, cases, _ = ztest("ztest_skip.log", ["needs_vcan.send", "needs_vcan.receive"])
    assert status == st.PASSED
    assert set(states(cases).values()) == {st.SKIPPED}


def test_fault_fails_the_running_case_and_blocks_the_rest():
    h = ZtestHarness("scn", ["co_nmt.boot", "co_nmt.null_deref", "co_nmt.later"])
    actions = feed(h, (LOGS / "ztest_fault.log").read_text())
    assert actions == [GRACE]  # after a fault, only a short wait for the exit
    status, reason, cases = h.finalize(ProcResult(returncode=134, duration=1.0))
    cases = {c.identifier: c for c in cases}
    assert (status, reason) == (st.FAILED, "fatal error")
    assert states(cases) == {"scn.co_nmt.boot": st.PASSED, "scn.co_nmt.null_deref": st.FAILED, "scn.co_nmt.later": st.BLOCKED}


def test_fault_with_ignore_faults_is_judged_by_the_rest():
    h = ZtestHarness("scn", [], ignore_faults=True)
    feed(h, (LOGS / "ztest_fault.log").read_text())
    status, reason, _ = h.finalize(ProcResult(returncode=0, duration=1.0))
    assert (status, reason) == (st.FAILED, "no PROJECT EXECUTION verdict")


def test_truncated_log_after_timeout():
    status, reason, cases, _ = ztest(
        "ztest_truncated.log", ["co_sync.producer", "co_sync.window", "co_sync.counter"], returncode=-15, timed_out=True
    )
    assert (status, reason) == (st.FAILED, "timeout")
    assert states(cases) == {
        "scn.co_sync.producer": st.PASSED,
        "scn.co_sync.window": st.FAILED,
        "scn.co_sync.counter": st.BLOCKED,
    }
    assert cases["scn.co_sync.window"].reason == "timeout"


def test_cases_seen_only_in_the_summary_are_recovered():
    status, _, cases, _ = ztest("ztest_summary_only.log", [])
    assert status == st.PASSED
    assert states(cases) == {"scn.quiet.a": st.PASSED, "scn.quiet.b": st.PASSED}


def test_expected_case_never_reported_in_a_passing_run_is_skipped():
    status, _, cases, _ = ztest("ztest_pass.log", ["co_line.register", "co_line.compiled_out"])
    assert status == st.PASSED
    assert cases["scn.co_line.compiled_out"].status == st.SKIPPED
    assert cases["scn.co_sdo.expedited"].status == st.PASSED  # reported but not scanned: added


def test_sanitizer_report_fails_even_with_a_good_verdict():
    h = ZtestHarness("scn", [])
    text = (LOGS / "ztest_pass.log").read_text().replace(
        "TESTSUITE co_sdo succeeded", "src/main.c:12:7: runtime error: signed integer overflow\nTESTSUITE co_sdo succeeded"
    )
    feed(h, text)
    status, reason, _ = h.finalize(ProcResult(returncode=0, duration=1.0))
    assert status == st.FAILED and reason.startswith("sanitizer: src/main.c:12:7: runtime error")


def test_verdict_but_no_exit():
    status, reason, _, _ = ztest("ztest_pass.log", [], returncode=-15, exit_grace_expired=True)
    assert (status, reason) == (st.FAILED, "did not exit after PROJECT EXECUTION")


def test_start_is_not_matched_inside_other_words():
    h = ZtestHarness("scn", ["s.a"])
    feed(h, "Running TESTSUITE s\nRESTART - a\n")
    assert h.cases["s.a"].status is None


def test_exit_reason():
    assert exit_reason(3) == "exited with code 3"
    assert exit_reason(-9) == "killed by SIGKILL"


# --- console --------------------------------------------------------------------------------

OUTPUT = ["boot", "Hello from native_posix", "tick 1", "node 5 OPERATIONAL", "tick 2"]


def console(cfg, lines=OUTPUT):
    h = ConsoleHarness("sample.x", cfg)
    actions = []
    for line in lines:
        actions.append(h.feed(line))
    return h, actions


def test_one_line_stops_at_the_first_match():
    h, actions = console({"type": "one_line", "regex": [r"Hello from (\w+)"]})
    assert actions[:2] == [None, STOP]
    status, reason, cases = h.finalize(ProcResult(returncode=-15, duration=0.5, stopped=True))
    assert (status, reason) == (st.PASSED, None)
    assert [(c.identifier, c.status) for c in cases] == [("sample.x", st.PASSED)]


def test_multi_line_ordered_needs_the_order():
    h, actions = console({"type": "multi_line", "regex": ["Hello", "OPERATIONAL", "tick 2"]})
    assert actions.index(STOP) == 4 and h.done
    h, actions = console({"type": "multi_line", "regex": ["OPERATIONAL", "Hello"]})
    assert STOP not in actions and not h.done
    status, reason, _ = h.finalize(ProcResult(returncode=0, duration=0.5))
    assert (status, reason) == (st.FAILED, "console output did not match 'Hello'")


def test_multi_line_unordered():
    h, actions = console({"type": "multi_line", "ordered": False, "regex": ["OPERATIONAL", "Hello"]})
    assert actions.index(STOP) == 3


def test_console_failures():
    h, _ = console({"type": "one_line", "regex": ["never"]})
    assert h.finalize(ProcResult(returncode=None, duration=3, timed_out=True))[:2] == (st.FAILED, "timeout")
    assert h.finalize(ProcResult(returncode=2, duration=1))[:2] == (st.FAILED, "exited with code 2")
    # Matched, but the sample exited non-zero on its own before it could be stopped.
    h, _ = console({"type": "one_line", "regex": ["Hello"]})
    assert h.finalize(ProcResult(returncode=1, duration=1))[:2] == (st.FAILED, "exited with code 1")
    assert h.finalize(ProcResult(returncode=0, duration=1))[:2] == (st.PASSED, None)


def test_console_fault_fails():
    h, actions = console({"type": "one_line", "regex": ["never"]}, ["x", ">>> SAFELINE FATAL ERROR 4: Kernel panic"])
    assert actions == [None, STOP]
    assert h.finalize(ProcResult(returncode=-15, duration=1, stopped=True))[:2] == (st.FAILED, "fatal error")


def test_console_record():
    h, _ = console({"type": "multi_line", "regex": ["tick 2"], "record": {"regex": [r"tick (?P<tick>\d+)"]}})
    assert h.recording == [{"tick": "1"}, {"tick": "2"}]


# --- pytest ---------------------------------------------------------------------------------

JUNIT = """<?xml version="1.0" encoding="utf-8"?>
<testsuites><testsuite name="pytest" errors="0" failures="1" skipped="1" tests="4">
<testcase classname="test_sdo" name="test_upload" time="0.120"/>
<testcase classname="test_sdo" name="test_download[8]" time="0.050">
  <failure message="AssertionError: abort 0x06090011&#10;more">trace</failure></testcase>
<testcase classname="test_nmt" name="test_reset" time="0.001"><skipped message="needs vcan"/></testcase>
<testcase classname="test_nmt" name="test_upload" time="0.010"/>
</testsuite></testsuites>
"""


def test_pytest_junit(tmp_path):
    path = tmp_path / "report.xml"
    path.write_text(JUNIT)
    status, reason, cases = PytestHarness("s.py", path).finalize(ProcResult(returncode=1, duration=2))
    assert (status, reason) == (st.FAILED, "pytest failed: test_download[8]")
    got = {c.identifier: (c.status, c.reason) for c in cases}
    assert got == {
        "s.py.test_upload": (st.PASSED, None),
        "s.py.test_download[8]": (st.FAILED, "AssertionError: abort 0x06090011"),
        "s.py.test_reset": (st.SKIPPED, "needs vcan"),
        "s.py.test_nmt.test_upload": (st.PASSED, None),  # same name twice: the class keeps it unique
    }


def test_pytest_verdicts(tmp_path):
    missing = PytestHarness("s.py", tmp_path / "none.xml")
    assert missing.finalize(ProcResult(returncode=5, duration=1))[:2] == (st.FAILED, "pytest collected no tests")
    assert missing.finalize(ProcResult(returncode=None, duration=1, timed_out=True))[:2] == (st.FAILED, "timeout")
    assert missing.finalize(ProcResult(returncode=4, duration=1))[:2] == (st.FAILED, "pytest exited with code 4")
    assert missing.finalize(ProcResult(returncode=0, duration=1))[:2] == (st.PASSED, None)


# --- logs recorded from real SafeLine images -------------------------------------------------


def test_real_passing_log():
    status, reason, cases, _ = ztest("real_pass.log", ["twister_pass.adds", "twister_pass.skips"])
    assert (status, reason) == (st.PASSED, None)
    assert states(cases) == {"scn.twister_pass.adds": st.PASSED, "scn.twister_pass.skips": st.SKIPPED}


def test_real_failing_log():
    status, reason, cases, _ = ztest("real_fail.log", ["twister_fail.good", "twister_fail.bad"], returncode=1)
    assert (status, reason) == (st.FAILED, "testsuite failed")
    assert states(cases) == {"scn.twister_fail.good": st.PASSED, "scn.twister_fail.bad": st.FAILED}
    assert cases["scn.twister_fail.bad"].reason.endswith("(sum not equal to 3): deliberately wrong")


def test_real_timeout_log():
    status, reason, cases, _ = ztest(
        "real_timeout.log", ["twister_hang.first", "twister_hang.forever"], returncode=-15, timed_out=True
    )
    assert (status, reason) == (st.FAILED, "timeout")
    assert states(cases) == {"scn.twister_hang.first": st.PASSED, "scn.twister_hang.forever": st.FAILED}


def test_real_fault_log():
    expected = ["twister_crash.a_first", "twister_crash.b_oops", "twister_crash.c_after"]
    status, reason, cases, actions = ztest("real_fault.log", expected, returncode=1)
    assert (status, reason) == (st.FAILED, "fatal error")
    assert actions == [GRACE]
    assert states(cases) == {
        "scn.twister_crash.a_first": st.PASSED,
        "scn.twister_crash.b_oops": st.FAILED,
        "scn.twister_crash.c_after": st.BLOCKED,
    }


def test_real_console_log():
    h, actions = console(
        {"type": "multi_line", "regex": ["Hello from native_posix", "tick 3"]},
        (LOGS / "real_console.log").read_text().splitlines(),
    )
    assert STOP in actions and h.done
