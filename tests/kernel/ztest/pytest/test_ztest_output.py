# SPDX-License-Identifier: Apache-2.0
"""The ztest console output, parsed with the regexes of Zephyr's twister (its harness.py)."""

import re

RULE = "=" * 67
SUITE_START = re.compile(r"Running TESTSUITE (\w*)")
SUITE_END = re.compile(r"TESTSUITE (\S*)\s+(succeeded|failed)")
CASE_START = re.compile(r"START - (test_)?([a-zA-Z0-9_-]+)")
CASE_END = re.compile(r".*(PASS|FAIL|SKIP) - (test_)?(\S*) in (\d*[.,]?\d*) seconds")
SUITE_SUMMARY = re.compile(r"SUITE (\S*) - .* \[(\S*)\]: .* duration = (\d*[.,]?\d*) seconds")
CASE_SUMMARY = re.compile(r".*- (PASS|FAIL|SKIP) - \[([^\.]*).(test_)?(\S*)\] duration = (\d*[.,]?\d*) seconds")


def test_exit_code_and_verdict(result):
    assert result.returncode == 0, result.stdout
    lines = result.stdout.splitlines()
    assert lines[-1] == "PROJECT EXECUTION SUCCESSFUL"
    assert lines[-2] == RULE


def test_suites_in_name_order(result):
    started = [m.group(1) for m in map(SUITE_START.match, result.stdout.splitlines()) if m]
    assert started == ["a_fixture", "b_endings", "d_asserts"], "c_rejected is not run"
    ended = {m.group(1): m.group(2) for m in map(SUITE_END.match, result.stdout.splitlines()) if m}
    assert ended == {"a_fixture": "succeeded", "b_endings": "succeeded", "d_asserts": "succeeded"}


def test_case_lines(result):
    lines = result.stdout.splitlines()
    ends = [m for m in map(CASE_END.match, lines) if m]
    starts = [m for m in map(CASE_START.match, lines) if m]
    assert len(starts) == len(ends) == 3 + 7 + 1
    for m in ends:
        assert m.group(1) == "PASS", m.group(0)
        assert re.fullmatch(r"\d+\.\d{3}", m.group(4)), "three decimals"
    # The result line starts with a space and is followed by the rule.
    for i, line in enumerate(lines):
        if CASE_END.match(line):
            assert line.startswith(" PASS - ")
            assert lines[i + 1] == RULE


def test_failure_report_format(result):
    assert re.search(
        r"\n\n    Assertion failed at tests/kernel/ztest/src/main\.c:\d+: "
        r"b_endings_test_1_assert_ends_test: \(1 not equal to 2\)\ndeliberate: 42\n",
        result.stdout)
    assert "    Expectation failed at tests/kernel/ztest/src/main.c:" in result.stdout
    assert "    Assumption failed at tests/kernel/ztest/src/main.c:" in result.stdout
    assert "TC_PRINT reaches the console" in result.stdout


def test_summary(result):
    lines = result.stdout.splitlines()
    start = lines.index("------ TESTSUITE SUMMARY START ------")
    end = lines.index("------ TESTSUITE SUMMARY END ------")
    assert lines[start - 1] == "" and lines[start + 1] == ""
    summary = lines[start + 1:end]
    suites = {m.group(2): m for m in map(SUITE_SUMMARY.match, summary) if m}
    assert set(suites) == {"a_fixture", "b_endings", "c_rejected", "d_asserts"}
    assert "SUITE PASS - 100.00% [a_fixture]: pass = 3, fail = 0, skip = 0, total = 3" in summary[1]
    assert any(line.startswith("SUITE SKIP -   0.00% [c_rejected]: pass = 0, fail = 0, skip = 1, "
                               "total = 1 duration = 0.000 seconds") for line in summary)
    cases = [m for m in map(CASE_SUMMARY.match, summary) if m]
    assert len(cases) == 3 + 7 + 1 + 1
    assert ("SKIP", "c_rejected", "never_runs") in [(m.group(1), m.group(2), m.group(4)) for m in cases]
    assert lines[end + 1] == ""
