"""Reports: twister.json, twister.xml (JUnit), testplan.json, the summary and the count line.

The count line (the last line twister prints) is `N passed, N failed` plus `, N skipped` when
something was skipped. It counts test cases where a run yields them (ztest, pytest) and one unit
per instance otherwise (console scenarios, build-only instances, bad YAML files):

- a case that passed counts as passed, a skipped one as skipped, and a case that failed or never
  ran because its instance broke (status "blocked") as failed;
- an instance that failed or errored without any failed case (e.g. a crash after the last case,
  a sanitizer report at exit) adds one failed, so a failing run never reads "0 failed";
- "error" counts as failed; "filtered" instances are not counted at all.
"""

import datetime
import json
import os
import platform as host_platform
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

from . import log
from . import statuses as st
from .instance import TestInstance


def counts(instances: list[TestInstance]) -> dict[str, int]:
    c = {"passed": 0, "failed": 0, "skipped": 0}
    for inst in instances:
        if inst.status == st.FILTERED:
            continue
        if inst.counts_cases and inst.testcases:
            failed_cases = 0
            for tc in inst.testcases:
                if tc.status == st.PASSED:
                    c["passed"] += 1
                elif tc.status == st.SKIPPED:
                    c["skipped"] += 1
                elif tc.status == st.FILTERED:
                    continue
                else:
                    c["failed"] += 1
                    failed_cases += 1
            if inst.status in st.FAILING and failed_cases == 0:
                c["failed"] += 1
        elif inst.status == st.PASSED:
            c["passed"] += 1
        elif inst.status == st.SKIPPED:
            c["skipped"] += 1
        else:
            c["failed"] += 1
    return c


def count_line(c: dict[str, int]) -> str:
    line = f"{c['passed']} passed, {c['failed']} failed"
    if c["skipped"]:
        line += f", {c['skipped']} skipped"
    return line


def _fmt_time(seconds: float) -> str:
    return f"{float(seconds):.2f}"


def _git_commit(base: Path) -> str:
    try:
        out = subprocess.run(
            ["git", "-C", str(base), "describe", "--always", "--dirty", "--abbrev=12"],
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    return out.stdout.strip() if out.returncode == 0 and out.stdout.strip() else "unknown"


def environment(base: Path, options: dict) -> dict:
    version = ""
    try:
        version = (Path(base) / "VERSION").read_text(encoding="utf-8").strip()
    except OSError:
        pass
    return {
        "os": os.name,
        "host": host_platform.platform(),
        "toolchain": "host",
        "commit": _git_commit(base),
        "safeline_version": version,
        "run_date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "options": options,
    }


def _suite_entry(inst: TestInstance, run_id: str) -> dict:
    if inst.scenario is None:
        err = inst.config_error
        return {
            "name": err.file,
            "arch": "",
            "platform": "",
            "path": str(Path(err.file).parent),
            "runnable": False,
            "retries": 0,
            "status": inst.status,
            "reason": inst.reason,
            "log": inst.log,
            "execution_time": _fmt_time(0),
            "build_time": _fmt_time(0),
            "testcases": [],
        }
    sc, plat = inst.scenario, inst.platform
    d = {
        "name": sc.id,
        "arch": plat.arch,
        "platform": plat.identifier,
        "path": sc.relpath,
        "run_id": run_id,
        "runnable": not inst.build_only and inst.status != st.FILTERED,
        "retries": inst.retries,
        "status": inst.status,
    }
    if inst.reason:
        d["reason"] = inst.reason
    if inst.status in st.FAILING and inst.log:
        d["log"] = inst.log
    d["execution_time"] = _fmt_time(inst.execution_time)
    d["build_time"] = _fmt_time(inst.build_time)
    d["harness"] = sc.harness
    if sc.fixture:
        d["fixture"] = sc.fixture
    if inst.recording:
        d["recording"] = inst.recording
    d["testcases"] = []
    for tc in inst.testcases:
        t = {"identifier": tc.identifier, "status": tc.status, "execution_time": _fmt_time(tc.duration)}
        if tc.reason and tc.status != st.PASSED:
            t["reason"] = tc.reason
        d["testcases"].append(t)
    return d


def write_json(path: Path, instances: list[TestInstance], env: dict, run_id: str) -> None:
    data = {"environment": env, "testsuites": [_suite_entry(i, run_id) for i in instances]}
    Path(path).write_text(json.dumps(data, indent=4) + "\n", encoding="utf-8")


def write_testplan(path: Path, instances: list[TestInstance]) -> None:
    suites = []
    for inst in instances:
        if inst.scenario is None:
            err = inst.config_error
            suites.append({"name": err.file, "status": inst.status, "reason": inst.reason, "testcases": []})
            continue
        d = {
            "name": inst.scenario.id,
            "platform": inst.platform.identifier,
            "arch": inst.platform.arch,
            "path": inst.scenario.relpath,
            "build_dir": str(inst.build_dir),
            "harness": inst.scenario.harness,
            "runnable": not inst.build_only,
        }
        if inst.status:
            d["status"] = inst.status
            d["reason"] = inst.reason
        d["testcases"] = [{"identifier": tc.identifier} for tc in inst.testcases]
        suites.append(d)
    Path(path).write_text(json.dumps({"testsuites": suites}, indent=4) + "\n", encoding="utf-8")


# --- JUnit ----------------------------------------------------------------------------------


def _junit_cases(inst: TestInstance):
    """(classname, name, time, status, message) rows, the same units the count line counts."""
    if inst.scenario is None:
        yield ("config", inst.config_error.file, 0.0, inst.status, inst.reason)
        return
    sc = inst.scenario
    if inst.counts_cases and inst.testcases:
        any_failed = False
        for tc in inst.testcases:
            if tc.status == st.FILTERED:
                continue
            any_failed |= tc.status not in (st.PASSED, st.SKIPPED)
            yield (sc.id, tc.identifier, tc.duration, tc.status, tc.reason)
        if inst.status in st.FAILING and not any_failed:
            yield (sc.id, sc.id, inst.execution_time, inst.status, inst.reason)
        return
    seconds = inst.execution_time if not inst.build_only else inst.build_time
    yield (sc.id, sc.id, seconds, inst.status, inst.reason)


def write_junit(path: Path, instances: list[TestInstance]) -> None:
    root = ET.Element("testsuites")
    groups: dict[str, list[TestInstance]] = {}
    for inst in instances:
        if inst.status == st.FILTERED:
            continue
        groups.setdefault(inst.platform_id or "config", []).append(inst)
    for plat, insts in groups.items():
        suite = ET.SubElement(root, "testsuite", name=plat)
        n = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
        total_time = 0.0
        for inst in insts:
            log_given = False
            for classname, name, seconds, status, message in _junit_cases(inst):
                n["tests"] += 1
                total_time += seconds
                case = ET.SubElement(suite, "testcase", classname=classname, name=name, time=f"{seconds:.3f}")
                if status == st.SKIPPED:
                    n["skipped"] += 1
                    ET.SubElement(case, "skipped", message=message or "skipped")
                elif status == st.ERROR:
                    n["errors"] += 1
                    el = ET.SubElement(case, "error", type="error", message=message or "error")
                    if inst.log and not log_given:
                        el.text, log_given = inst.log, True
                elif status != st.PASSED:
                    n["failures"] += 1
                    el = ET.SubElement(case, "failure", type=status or "failure", message=message or "failed")
                    if inst.log and not log_given:
                        el.text, log_given = inst.log, True
        for key, value in n.items():
            suite.set(key, str(value))
        suite.set("time", f"{total_time:.3f}")
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


# --- console summary -----------------------------------------------------------------------


def _cases_text(inst: TestInstance) -> str:
    if not inst.counts_cases or not inst.testcases:
        return "-"
    passed = sum(1 for tc in inst.testcases if tc.status == st.PASSED)
    return f"{passed}/{len(inst.testcases)}"


def print_summary(instances: list[TestInstance], elapsed: float) -> None:
    shown = [i for i in instances if i.status != st.FILTERED and i.scenario is not None]
    bad_files = [i for i in instances if i.scenario is None]
    filtered = sum(1 for i in instances if i.status == st.FILTERED)
    for i in bad_files:
        log.error(i.reason)
    if shown:
        w_sc = max(8, *(len(i.scenario_id) for i in shown))
        w_pl = max(8, *(len(i.platform_id) for i in shown))
        header = f"{'scenario':<{w_sc}}  {'platform':<{w_pl}}  {'status':<8}  {'cases':>7}  {'time':>8}  reason"
        lines = [header, "-" * len(header)]
        order = {st.ERROR: 0, st.FAILED: 1, st.SKIPPED: 2, st.PASSED: 3}
        for i in sorted(shown, key=lambda i: (order.get(i.status, 4), i.scenario_id, i.platform_id)):
            seconds = i.build_time + i.execution_time
            reason = i.reason if i.reason and i.status != st.PASSED else ""
            lines.append(
                f"{i.scenario_id:<{w_sc}}  {i.platform_id:<{w_pl}}  {i.status:<8}  {_cases_text(i):>7}  "
                f"{seconds:>7.2f}s  {reason}".rstrip()
            )
        log.raw("\n".join(lines))
    by = {s: sum(1 for i in shown if i.status == s) for s in (st.PASSED, st.FAILED, st.ERROR, st.SKIPPED)}
    bad = f"; {len(bad_files)} invalid YAML file(s)" if bad_files else ""
    log.info(
        f"{len(shown)} instance(s): {by[st.PASSED]} passed, {by[st.FAILED]} failed, {by[st.ERROR]} error, "
        f"{by[st.SKIPPED]} skipped; {filtered} filtered{bad}; {elapsed:.1f}s"
    )
