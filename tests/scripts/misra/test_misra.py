# SPDX-License-Identifier: Apache-2.0
"""scripts/misra: the MISRA C:2012 check of the stack and the CAN drivers passes with the
deviations of doc/misra.md, an unlisted violation fails it, a deviation row covers it, and
the generated util_macro.h expands Zephyr's Kconfig tests as the compiler does."""

import importlib.machinery
import importlib.util
import os
import shutil
import subprocess
import sys

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPT = os.path.join(BASE, "scripts", "misra")

pytestmark = pytest.mark.skipif(shutil.which("cppcheck") is None,
                                reason="cppcheck not installed (scripts/setup installs it)")


def load():
    loader = importlib.machinery.SourceFileLoader("safeline_misra", SCRIPT)
    spec = importlib.util.spec_from_loader("safeline_misra", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


misra = load()

# 15.6: the body of an if is not a compound statement (required, deviated nowhere).
BAD_C = """#include <stdint.h>

uint32_t misra_probe(uint32_t v);

uint32_t misra_probe(uint32_t v)
{
	uint32_t r = 0U;

	if (v > 3U)
		r = 1U;
	return r;
}
"""


def run(*args, out, cwd=BASE):
    return subprocess.run([sys.executable, SCRIPT, "--out", str(out), *args], cwd=cwd,
                          capture_output=True, text=True)


def test_the_stack_and_the_drivers_pass_with_the_documented_deviations():
    """The check of the test command: everything under subsys/canopen and drivers/can."""
    r = run(out=os.path.join(BASE, "build", "misra"))
    print(r.stdout[-20000:])
    print(r.stderr[-4000:], file=sys.stderr)
    assert r.returncode == 0, "violations not in doc/misra.md, or files not analysed (above)"
    assert " 0 not deviated; 0 analysis errors" in r.stdout
    # Files really analysed: the core's node.c yields violations of deviated rules.
    assert "subsys/canopen/core/node.c" in r.stdout


@pytest.fixture
def probe(tmp_path):
    src = tmp_path / "probe.c"
    src.write_text(BAD_C)
    return src


def test_an_unlisted_violation_fails(probe, tmp_path):
    # From another folder: paths are the project's, not the caller's.
    r = run(str(probe), out=tmp_path / "out", cwd=tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "rule 15.6: 1" in r.stdout
    assert f"{probe}:9:" in r.stdout and "(NOT DEVIATED)" in r.stdout
    assert "1 not deviated" in r.stdout


def test_a_deviation_row_covers_its_rule_and_files_only(probe, tmp_path):
    devs = tmp_path / "devs.md"
    devs.write_text("## Deviations\n\n| rule | where | why |\n|---|---|---|\n"
                    f"| 15.6 | `{tmp_path}/*.c` | the probe |\n")
    r = run("--deviations", str(devs), str(probe), out=tmp_path / "out")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "0 not deviated" in r.stdout

    devs.write_text("## Deviations\n\n| rule | where | why |\n|---|---|---|\n"
                    f"| 15.5, 15.7 | `{tmp_path}/*.c` | other rules |\n"
                    "| 15.6 | `subsys/canopen/*` | another place |\n")
    r = run("--deviations", str(devs), str(probe), out=tmp_path / "out")
    assert r.returncode == 1, r.stdout + r.stderr


def test_a_file_that_does_not_parse_fails(tmp_path):
    src = tmp_path / "broken.c"
    src.write_text("int broken(void)\n{\n\treturn (1;\n}\n")
    r = run(str(src), out=tmp_path / "out")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "ANALYSIS INCOMPLETE" in r.stdout


def test_bad_rows_and_paths_are_usage_errors(tmp_path):
    devs = tmp_path / "devs.md"
    devs.write_text("## Deviations\n| 15.6 | everywhere | no pattern in backticks |\n")
    r = run("--deviations", str(devs), out=tmp_path / "out")
    assert r.returncode == 2 and "names no `file or pattern`" in r.stderr
    r = run(str(tmp_path / "missing.c"), out=tmp_path / "out")
    assert r.returncode == 2 and "no such file or folder" in r.stderr


def test_deviation_rows_are_read_from_the_table(tmp_path):
    devs = tmp_path / "devs.md"
    devs.write_text("## Deviations\n"
                    "text | 1.1 | `a.c` |\n"
                    "| rule | where | why |\n"
                    "| 2.7 | `drivers/can/*`, `x.c` | callbacks |\n"
                    "### Temporary\n"
                    "| 10.1, 10.4 | `subsys/*` | types |\n"
                    "## Fixed in the code\n"
                    "| 15.6 | `subsys/*` | a fix, not a deviation |\n")
    rows = misra.load_deviations(str(devs))
    assert [(sorted(r), g) for r, g, n in rows] == [
        (["2.7"], ["drivers/can/*", "x.c"]), (["10.1", "10.4"], ["subsys/*"])]
    assert misra.deviated("10.4", "subsys/canopen/od/od.c", rows) == 6
    assert misra.deviated("10.3", "subsys/canopen/od/od.c", rows) is None
    assert misra.deviated("15.6", "subsys/canopen/od/od.c", rows) is None
    assert misra.deviated("2.7", "drivers/can/virtual/can_virtual.c", rows) == 4
    assert misra.deviated("2.7", "subsys/canopen/od/od.c", rows) is None


def test_the_generated_util_macro_matches_the_compiler(tmp_path):
    """The shim's IS_ENABLED/IF_ENABLED/IF_DISABLED/COND_CODE_x give, under cppcheck, what
    Zephyr's own macros give under gcc, for set, unset and undefined options, also when the
    option reaches the macro already expanded (inside another macro)."""
    conf = {"A": "y", "B": "n"}
    src = tmp_path / "t.c"
    src.write_text("""#include <zephyr/sys/util_macro.h>
#define CONFIG_A 1
#define LIST(X) IF_ENABLED(CONFIG_A, (X(a))) IF_ENABLED(CONFIG_B, (X(b))) X(c)
#define DECL(n) int n;
int v1 = IS_ENABLED(CONFIG_A) * 10 + IS_ENABLED(CONFIG_B) * 20 + IS_ENABLED(CONFIG_C) * 40;
int v2 IF_ENABLED(CONFIG_A, (= 3)) IF_ENABLED(CONFIG_B, (+ 100));
int v3 IF_DISABLED(CONFIG_B, (= 5)) IF_DISABLED(CONFIG_A, (+ 100));
int v4 = COND_CODE_1(CONFIG_A, (7), (8)) + COND_CODE_1(CONFIG_B, (70), (80));
LIST(DECL)
""")
    out = tmp_path / "out"
    shim = misra.write_shim(str(out), conf, [str(src)])
    inc = os.path.join(BASE, "include")

    def tokens(text):
        keep = [ln for ln in text.splitlines() if ln.startswith(("int", " int"))]
        return " ".join(" ".join(keep).split()).replace(" ;", ";").replace(" = ", "=")

    gcc = subprocess.run(["gcc", "-E", "-P", "-I" + inc, str(src)], capture_output=True,
                         text=True, check=True).stdout
    cpp = subprocess.run(["cppcheck", "-E", "-I" + shim, "-I" + inc, str(src)],
                         capture_output=True, text=True).stdout
    want = "int v1=1 * 10 + 0 * 20 + 0 * 40; int v2=3; int v3=5; int v4=7 + 80; int a; int c;"
    assert tokens(gcc) == want
    assert tokens(cpp) == want


def test_counts_prints_the_violations_per_rule(probe, tmp_path):
    r = run("--counts", str(probe), out=tmp_path / "out")
    assert r.returncode == 1, r.stdout + r.stderr
    rows = [ln.split() for ln in r.stdout.splitlines()]
    assert ["rule", "total", "deviated", "not", "files"] in rows
    assert ["15.6", "1", "0", "1", "1"] in rows
    # The violations not deviated are still listed, one per line; the per-file listing is not.
    assert f"{probe}:9:" in r.stdout and "(NOT DEVIATED)" in r.stdout
    assert "by rule and file" not in r.stdout

    devs = tmp_path / "devs.md"
    devs.write_text("## Deviations\n\n| rule | where | why |\n|---|---|---|\n"
                    f"| 15.6 | `{tmp_path}/*.c` | the probe |\n")
    r = run("--counts", "--deviations", str(devs), str(probe), out=tmp_path / "out")
    assert r.returncode == 0, r.stdout + r.stderr
    assert ["15.6", "1", "1", "0", "1"] in [ln.split() for ln in r.stdout.splitlines()]


def test_a_pattern_that_deviates_nothing_is_reported(probe, tmp_path):
    """A row or one of its patterns that no violation needs is named (to be removed or
    narrowed); it does not fail the check. A partial run names only the patterns whose files
    it checked all."""
    devs = tmp_path / "devs.md"
    devs.write_text("## Deviations\n\n| rule | where | why |\n|---|---|---|\n"
                    f"| 15.6 | `{probe}`, `{tmp_path}/other/*.c` | the probe |\n"
                    f"| 15.5 | `{tmp_path}/probe*.c` | nothing needs it |\n"
                    "| 15.6 | `subsys/canopen/*` | not checked here |\n")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "unchecked.c").write_text("/* no violation here */\n")
    r = run("--deviations", str(devs), str(probe), out=tmp_path / "out")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "deviations no violation needs any more" in r.stdout
    assert f"devs.md:6: rule 15.5 `{tmp_path}/probe*.c` deviates nothing" in r.stdout
    # The used pattern, a pattern with a file not checked, and the stack's rows: not named.
    assert f"`{probe}` deviates nothing" not in r.stdout
    assert "other/*.c` deviates nothing" not in r.stdout
    assert "subsys/canopen/*` deviates nothing" not in r.stdout

    # With every file of the pattern checked, the pattern that deviates nothing is named.
    r = run("--deviations", str(devs), str(probe), str(tmp_path / "other"),
            out=tmp_path / "out")
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"devs.md:5: rule 15.6 `{tmp_path}/other/*.c` deviates nothing" in r.stdout
    assert f"`{probe}` deviates nothing" not in r.stdout


def test_unused_patterns_of_a_full_run():
    rows = [({"10.4"}, ["subsys/a.c", "subsys/b.c"], 3), ({"15.5", "2.7"}, ["subsys/*"], 4)]
    viol = [{"rule": "10.4", "file": "subsys/a.c", "deviation": 3},
            {"rule": "15.5", "file": "subsys/b.c", "deviation": 4}]
    assert misra.unused_patterns(viol, rows) == [(3, {"10.4"}, "subsys/b.c")]
    assert misra.unused_patterns([], rows) == [(3, {"10.4"}, "subsys/a.c"),
                                               (3, {"10.4"}, "subsys/b.c"),
                                               (4, {"15.5", "2.7"}, "subsys/*")]
