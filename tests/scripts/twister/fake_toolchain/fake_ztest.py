"""Prints Zephyr's ztest console format (style-anchors §6.3) for the fake images."""
import sys

RULE = "=" * 67


def out(line=""):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def suite(name, cases):
    """cases: [(case_name, "PASS"|"FAIL"|"SKIP", assertion or None)]. Returns True if none failed."""
    out(f"Running TESTSUITE {name}")
    out(RULE)
    for case, result, why in cases:
        out(f"START - test_{case}")
        if why:
            out(f"    Assertion failed at src/main.c:42: {name}_{case}: {why}")
        out(f" {result} - test_{case} in 0.001 seconds")
        out(RULE)
    failed = any(r == "FAIL" for _, r, _ in cases)
    out(f"TESTSUITE {name} {'failed.' if failed else 'succeeded'}")
    out("")
    out("------ TESTSUITE SUMMARY START ------")
    out("")
    n = {r: sum(1 for _, x, _ in cases if x == r) for r in ("PASS", "FAIL", "SKIP")}
    total = len(cases)
    rate = 100.0 * n["PASS"] / total if total else 0.0
    verdict = "FAIL" if failed else ("SKIP" if n["PASS"] == 0 else "PASS")
    out(f"SUITE {verdict} - {rate:6.2f}% [{name}]: pass = {n['PASS']}, fail = {n['FAIL']}, "
        f"skip = {n['SKIP']}, total = {total} duration = 0.003 seconds")
    for case, result, _ in cases:
        out(f" - {result} - [{name}.test_{case}] duration = 0.001 seconds")
    out("")
    out("------ TESTSUITE SUMMARY END ------")
    out("")
    return not failed


def verdict(ok):
    out(RULE)
    out("PROJECT EXECUTION SUCCESSFUL" if ok else "PROJECT EXECUTION FAILED")
    sys.exit(0 if ok else 1)
