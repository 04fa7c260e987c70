"""Sanitizers that cannot share an image: --enable-tsan over ASan variants (and the reverse)
leaves those instances out as `filtered`, with the reason, instead of failing their builds.

The fake cmake refuses CONFIG_ASAN=y with CONFIG_TSAN=y the way Kconfig does (TSAN depends on
!ASAN), so an instance that slipped through would show up as a build failure here."""

import json
import textwrap
from pathlib import Path

import pytest
from twisterlib import statuses as st
from twisterlib.boards import Platform
from twisterlib.plan import Selection, discover, make_plan
from twister_testlib import REPO, TREES, run_twister

FAKE = TREES / "fake"

CONFLICT = "TSan and ASan cannot be combined"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture
def tree(tmp_path):
    """Scenarios that turn sanitizers on in each way a build can: extra_configs, extra_args,
    a Kconfig fragment of extra_conf_files, prj.conf, and none at all."""
    root = tmp_path / "tree"
    for folder, prj in (("plain", "CONFIG_ZTEST=y\n"), ("prj_asan", "CONFIG_ZTEST=y\nCONFIG_ASAN=y\n")):
        d = root / folder
        write(d / "src" / "main.c", (FAKE / "ztest_pass" / "src" / "main.c").read_text())
        write(d / "image.py", (FAKE / "ztest_pass" / "image.py").read_text())
        write(d / "prj.conf", prj)
    write(root / "plain" / "asan.conf", "CONFIG_ASAN=y\n")
    write(root / "plain" / "testcase.yaml", """
        common:
          tags: [san]
        tests:
          san.plain: {}
          san.asan_ubsan:
            extra_configs: [CONFIG_ASAN=y, CONFIG_UBSAN=y]
          san.asan_args:
            extra_args: [CONFIG_ASAN=y]
          san.asan_fragment:
            extra_conf_files: [asan.conf]
          san.asan_then_off:
            extra_configs: [CONFIG_ASAN=y, CONFIG_ASAN=n]
          san.tsan:
            extra_configs: [CONFIG_TSAN=y]
          san.ubsan:
            extra_configs: [CONFIG_UBSAN=y]
        """)
    write(root / "prj_asan" / "testcase.yaml", "tests: {san.prj_asan: {}}\n")
    return root


def planned(tree, **sel):
    boards = {"native_posix": Platform("native_posix", "posix", type="native", default=True)}
    scenarios, errors = discover([tree], REPO)
    assert errors == []
    insts = make_plan(scenarios, boards, Selection(platforms=[], **sel), tree.parent / "out")
    return {i.scenario.id: i for i in insts}


def filtered(insts):
    return {k: i.reason for k, i in insts.items() if i.status == st.FILTERED}


def test_tsan_run_filters_every_asan_variant(tree):
    got = planned(tree, sanitizers=["TSAN"])
    assert filtered(got) == {
        "san.asan_ubsan": f"{CONFLICT} (CONFIG_ASAN=y from extra_configs, CONFIG_TSAN=y from --enable-tsan)",
        "san.asan_args": f"{CONFLICT} (CONFIG_ASAN=y from extra_args, CONFIG_TSAN=y from --enable-tsan)",
        "san.asan_fragment": f"{CONFLICT} (CONFIG_ASAN=y from asan.conf, CONFIG_TSAN=y from --enable-tsan)",
        "san.prj_asan": f"{CONFLICT} (CONFIG_ASAN=y from prj.conf, CONFIG_TSAN=y from --enable-tsan)",
    }
    # every case of a filtered instance is filtered too, with the same reason
    assert {tc.status for tc in got["san.asan_ubsan"].testcases} == {st.FILTERED}
    assert got["san.asan_ubsan"].testcases[0].reason.startswith(CONFLICT)


def test_asan_run_filters_the_tsan_variant(tree):
    assert filtered(planned(tree, sanitizers=["ASAN", "UBSAN"])) == {
        "san.tsan": f"{CONFLICT} (CONFIG_ASAN=y from --enable-asan, CONFIG_TSAN=y from extra_configs)",
    }


def test_no_conflict_without_sanitizer_options_or_when_overridden(tree):
    assert filtered(planned(tree)) == {}
    assert filtered(planned(tree, sanitizers=["UBSAN"])) == {}
    # -x comes last on the CMake command line: it wins over the scenario's CONFIG_ASAN=y
    assert filtered(planned(tree, sanitizers=["TSAN"], extra_args=["CONFIG_ASAN=n"])) == {}
    got = planned(tree, extra_args=["CONFIG_TSAN=y"])
    assert set(filtered(got)) == {"san.asan_ubsan", "san.asan_args", "san.asan_fragment", "san.prj_asan"}
    assert got["san.prj_asan"].reason.endswith("CONFIG_TSAN=y from -x)")


def test_enable_tsan_end_to_end(tree, tmp_path):
    out = tmp_path / "o"
    run = run_twister(["-T", tree, "--enable-tsan", "-j", "2"], out, fake=True)
    assert run.returncode == 0, run.stdout
    statuses = {s["name"]: (s["status"], s.get("reason")) for s in run.json["testsuites"]}
    for name in ("san.asan_ubsan", "san.asan_args", "san.asan_fragment", "san.prj_asan"):
        status, reason = statuses[name]
        assert status == "filtered" and reason.startswith(CONFLICT), (name, status, reason)
        # never built: no build folder at all
        assert not (out / "native_posix" / run.suite(name)["path"] / name).exists()
    for name in ("san.plain", "san.asan_then_off", "san.tsan", "san.ubsan"):
        assert statuses[name][0] == "passed", (name, statuses[name])
    plan = {s["name"]: s for s in json.loads((out / "testplan.json").read_text())["testsuites"]}
    assert plan["san.asan_ubsan"]["status"] == "filtered"
    # summary: the 4 conflicting instances are counted as filtered, their cases not at all
    assert "INFO    - 8 scenario(s), 8 instance(s): 4 to build and run, 4 filtered or skipped" in run.lines
    tally = next(line for line in run.lines if " instance(s): " in line and "filtered;" in line)
    assert tally.startswith("INFO    - 4 instance(s): 4 passed, 0 failed, 0 error, 0 skipped; 4 filtered;"), tally
    assert run.lines[-1] == "4 passed, 0 failed, 4 skipped"
    assert not any("build failure" in line for line in run.lines)


def test_enable_asan_end_to_end(tree, tmp_path):
    run = run_twister(["-T", tree, "--enable-asan", "-j", "2"], tmp_path / "o", fake=True)
    assert run.returncode == 0, run.stdout
    s = run.suite("san.tsan")
    assert s["status"] == "filtered"
    assert s["reason"] == f"{CONFLICT} (CONFIG_ASAN=y from --enable-asan, CONFIG_TSAN=y from extra_configs)"
    assert [x["name"] for x in run.json["testsuites"] if x["status"] == "filtered"] == ["san.tsan"]


def test_both_on_the_command_line_is_a_usage_error(tree, tmp_path):
    run = run_twister(["-T", tree, "--enable-asan", "--enable-tsan"], tmp_path / "o", fake=True)
    assert run.returncode == 2
    assert (
        f"ERROR   - {CONFLICT} (CONFIG_ASAN=y from --enable-asan, CONFIG_TSAN=y from --enable-tsan): "
        "the command line asks for both" in run.lines
    )
    assert not (tmp_path / "o").exists()
