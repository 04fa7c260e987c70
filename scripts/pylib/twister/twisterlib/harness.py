"""Harnesses: turn an image's output into a verdict and per-case results.

Each harness has `feed(line)` (called for every output line while the process runs; may return
handler.STOP or handler.GRACE) and `finalize(proc_result)` returning (status, reason, cases).
"""

import re
import signal
import xml.etree.ElementTree as ET
from pathlib import Path

from . import statuses as st
from .handler import GRACE, STOP, ProcResult
from .instance import TestCase

# Zephyr's console format (style-anchors §6.3), with Zephyr's regexes.
SUITE_START_RE = re.compile(r"Running TESTSUITE (\w*)")
SUITE_END_RE = re.compile(r"TESTSUITE (\S*)\s+(succeeded|failed)")
CASE_START_RE = re.compile(r"(?<![A-Za-z])START - (test_)?([a-zA-Z0-9_-]+)")
CASE_END_RE = re.compile(r".*(PASS|FAIL|SKIP) - (test_)?(\S*) in (\d*[.,]?\d*) seconds")
SUITE_SUMMARY_RE = re.compile(r"SUITE (\S*) - .* \[(\S*)\]: .* duration = (\d*[.,]?\d*) seconds")
CASE_SUMMARY_RE = re.compile(r".*- (PASS|FAIL|SKIP) - \[([^\.]*).(test_)?(\S*)\] duration = (\d*[.,]?\d*) seconds")
ASSERT_RE = re.compile(r"^\s*(Assertion failed at .*)$")
VERDICT_OK = "PROJECT EXECUTION SUCCESSFUL"
VERDICT_FAILED = "PROJECT EXECUTION FAILED"
# SafeLine's fault marker (the kernel prints it on k_panic/k_oops/fatal signals); Zephyr's too.
FAULT_RE = re.compile(r"(SAFELINE|ZEPHYR) FATAL ERROR")
SANITIZER_RE = re.compile(
    r"(ERROR: (AddressSanitizer|LeakSanitizer)|WARNING: ThreadSanitizer|"
    r"SUMMARY: (AddressSanitizer|UndefinedBehaviorSanitizer|ThreadSanitizer)|: runtime error: )"
)

_RESULT = {"PASS": st.PASSED, "FAIL": st.FAILED, "SKIP": st.SKIPPED}


def exit_reason(returncode: int | None) -> str:
    if returncode is None:
        return "did not exit"
    if returncode < 0:
        try:
            name = signal.Signals(-returncode).name
        except ValueError:
            name = f"signal {-returncode}"
        return f"killed by {name}"
    return f"exited with code {returncode}"


def _seconds(text: str) -> float:
    try:
        return float(text.replace(",", "."))
    except ValueError:
        return 0.0


class _FaultWatch:
    """Fault and sanitizer lines, shared by the ztest and console harnesses."""

    def __init__(self, ignore_faults: bool = False):
        self.ignore_faults = ignore_faults
        self.fault: str | None = None
        self.sanitizer: str | None = None

    def watch(self, line: str) -> bool:
        """True when the line reports a fault that fails the run."""
        if self.fault is None and not self.ignore_faults and FAULT_RE.search(line):
            self.fault = line.strip()
            return True
        if self.sanitizer is None and SANITIZER_RE.search(line):
            self.sanitizer = line.strip()
            return True
        return False

    def failure(self) -> str | None:
        if self.fault:
            return "fatal error"
        if self.sanitizer:
            return f"sanitizer: {self.sanitizer[:160]}"
        return None


class ZtestHarness:
    """Zephyr ztest console output. Verdict: exit code 0 and PROJECT EXECUTION SUCCESSFUL."""

    def __init__(self, scenario_id: str, expected: list[str], ignore_faults: bool = False):
        self.scenario_id = scenario_id
        self.cases: dict[str, TestCase] = {}
        for name in expected:
            self._case(name)
        self.suite: str | None = None
        self.current: TestCase | None = None
        self.verdict: str | None = None
        self.faults = _FaultWatch(ignore_faults)
        self.lines = 0
        self.assert_case: TestCase | None = None  # its message is on the next line

    def _case(self, name: str) -> TestCase:
        if name not in self.cases:
            self.cases[name] = TestCase(f"{self.scenario_id}.{name}")
        return self.cases[name]

    def _case_named(self, case: str) -> TestCase:
        if self.suite:
            return self._case(f"{self.suite}.{case}")
        # No suite header seen: the first expected case of that name.
        for name, tc in self.cases.items():
            if name.split(".", 1)[-1] == case:
                return tc
        return self._case(f"unknown.{case}")

    def feed(self, line: str):
        self.lines += 1
        if self.faults.watch(line):
            return GRACE
        if self.assert_case is not None:
            tc, self.assert_case = self.assert_case, None
            msg = line.strip()
            if msg and not CASE_END_RE.match(line) and not CASE_START_RE.search(line):
                tc.reason = f"{tc.reason}: {msg}"[:300]
                return None
        m = CASE_SUMMARY_RE.match(line)
        if m:
            suite, case = m.group(2), m.group(4)
            tc = self._case(f"{suite}.{case}")
            if tc.status in (None, st.STARTED):
                tc.status = _RESULT[m.group(1)]
                tc.duration = _seconds(m.group(5))
            return None
        m = SUITE_START_RE.search(line)
        if m:
            self.suite = m.group(1)
            return None
        m = CASE_START_RE.search(line)
        if m:
            tc = self._case_named(m.group(2))
            tc.status = st.STARTED
            tc.reason = None
            self.current = tc
            return None
        m = ASSERT_RE.match(line)
        if m and self.current is not None and self.current.reason is None:
            self.current.reason = m.group(1).strip()
            self.assert_case = self.current
            return None
        m = CASE_END_RE.match(line)
        if m:
            tc = self._case_named(m.group(3))
            tc.status = _RESULT[m.group(1)]
            tc.duration = _seconds(m.group(4))
            if tc.status != st.FAILED:
                tc.reason = None
            elif tc.reason is None:
                tc.reason = "failed"
            self.current = None
            return None
        if SUITE_END_RE.search(line):
            self.suite = None
            return None
        if VERDICT_OK in line:
            self.verdict = st.PASSED
            return GRACE
        if VERDICT_FAILED in line:
            self.verdict = st.FAILED
            return GRACE
        return None

    def finalize(self, res: ProcResult):
        failure = self.faults.failure()
        if failure:
            status, reason = st.FAILED, failure
        elif res.timed_out:
            status, reason = st.FAILED, "timeout"
        elif res.exit_grace_expired:
            status, reason = st.FAILED, "did not exit after PROJECT EXECUTION"
        elif self.verdict == st.FAILED:
            status, reason = st.FAILED, "testsuite failed"
        elif res.returncode != 0:
            status, reason = st.FAILED, exit_reason(res.returncode)
        elif self.verdict is None:
            status, reason = st.FAILED, "no PROJECT EXECUTION verdict"
        elif any(tc.status == st.FAILED for tc in self.cases.values()):
            status, reason = st.FAILED, "a test case failed"
        else:
            status, reason = st.PASSED, None

        for tc in self.cases.values():
            if tc.status == st.STARTED:
                tc.status, tc.reason = st.FAILED, reason or "did not finish"
            elif tc.status is None:
                if status == st.PASSED:
                    tc.status, tc.reason = st.SKIPPED, "not reported by the image"
                else:
                    tc.status, tc.reason = st.BLOCKED, f"not run: {reason}"
        return status, reason, list(self.cases.values())


class ConsoleHarness:
    """Regexes over the console. The process is stopped as soon as everything matched."""

    def __init__(self, scenario_id: str, config: dict, ignore_faults: bool = False):
        self.scenario_id = scenario_id
        self.type = config.get("type", "one_line")
        regexes = config.get("regex") or []
        if self.type == "one_line":
            regexes = regexes[:1]
        self.patterns = [re.compile(r) for r in regexes]
        self.ordered = bool(config.get("ordered", True))
        self.matched = [False] * len(self.patterns)
        self.next = 0
        rec = (config.get("record") or {}).get("regex") or []
        self.record_patterns = [re.compile(r) for r in ([rec] if isinstance(rec, str) else rec)]
        self.recording: list[dict] = []
        self.faults = _FaultWatch(ignore_faults)
        self.start_time = None

    @property
    def done(self) -> bool:
        return all(self.matched)

    def feed(self, line: str):
        for rp in self.record_patterns:
            m = rp.search(line)
            if m and m.groupdict():
                self.recording.append(m.groupdict())
        if self.faults.watch(line):
            return STOP
        if self.done:
            return STOP
        if self.ordered:
            if self.patterns[self.next].search(line):
                self.matched[self.next] = True
                self.next += 1
        else:
            for i, p in enumerate(self.patterns):
                if not self.matched[i] and p.search(line):
                    self.matched[i] = True
        return STOP if self.done else None

    def finalize(self, res: ProcResult):
        failure = self.faults.failure()
        if failure:
            status, reason = st.FAILED, failure
        elif self.done:
            if res.stopped or res.returncode == 0:
                status, reason = st.PASSED, None
            else:
                status, reason = st.FAILED, exit_reason(res.returncode)
        elif res.timed_out:
            status, reason = st.FAILED, "timeout"
        elif res.returncode != 0:
            status, reason = st.FAILED, exit_reason(res.returncode)
        else:
            missing = [p.pattern for p, ok in zip(self.patterns, self.matched) if not ok]
            status, reason = st.FAILED, f"console output did not match {missing[0]!r}"
        tc = TestCase(self.scenario_id, status, reason, res.duration)
        return status, reason, [tc]


def parse_junit(path: Path, scenario_id: str) -> list[TestCase]:
    """Test cases from the JUnit XML that pytest writes with --junitxml."""
    root = ET.parse(path).getroot()
    cases: list[TestCase] = []
    seen: set[str] = set()
    for el in root.iter("testcase"):
        name = el.get("name", "?")
        ident = f"{scenario_id}.{name}"
        if ident in seen:
            ident = f"{scenario_id}.{el.get('classname', '')}.{name}"
        seen.add(ident)
        bad = el.find("failure")
        if bad is None:
            bad = el.find("error")
        skipped = el.find("skipped")
        if bad is not None:
            status, reason = st.FAILED, (bad.get("message") or "failed").splitlines()[0][:200]
        elif skipped is not None:
            status, reason = st.SKIPPED, (skipped.get("message") or "skipped").splitlines()[0][:200]
        else:
            status, reason = st.PASSED, None
        cases.append(TestCase(ident, status, reason, _seconds(el.get("time", "0") or "0")))
    return cases


class PytestHarness:
    """Host-side pytest driving the image; the verdict is pytest's, the cases its JUnit XML."""

    def __init__(self, scenario_id: str, junit_path: Path):
        self.scenario_id = scenario_id
        self.junit_path = Path(junit_path)

    def feed(self, line: str):
        return None

    def finalize(self, res: ProcResult):
        cases: list[TestCase] = []
        junit_error = None
        if self.junit_path.is_file():
            try:
                cases = parse_junit(self.junit_path, self.scenario_id)
            except ET.ParseError as e:
                junit_error = f"unreadable JUnit XML: {e}"
        if res.timed_out:
            status, reason = st.FAILED, "timeout"
        elif res.returncode == 0:
            status, reason = (st.PASSED, None) if junit_error is None else (st.ERROR, junit_error)
        elif res.returncode == 5:
            status, reason = st.FAILED, "pytest collected no tests"
        else:
            failed = [tc.identifier.rsplit(".", 1)[-1] for tc in cases if tc.status == st.FAILED]
            if failed:
                more = f" (+{len(failed) - 3})" if len(failed) > 3 else ""
                status, reason = st.FAILED, f"pytest failed: {', '.join(failed[:3])}{more}"
            else:
                status, reason = st.FAILED, f"pytest {exit_reason(res.returncode)}"
        return status, reason, cases
