"""Discovery and the static plan: ignore markers, tags, platforms, depends_on, slow/skip, -s."""

import textwrap
from pathlib import Path

import pytest
from twisterlib import statuses as st
from twisterlib.boards import Platform
from twisterlib.plan import PlanError, Selection, discover, find_testsuite_files, make_plan, select_scenarios

REPO = Path(__file__).resolve().parents[3]


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture
def platforms():
    return {
        "native_posix": Platform("native_posix", "posix", type="native", supported=["can", "can_socketcan"], default=True),
        "other_board": Platform("other_board", "arm", type="mcu", supported=[], default=False, toolchain=["zephyr"]),
    }


def plan(tmp_path, boards, text, **sel):
    write(tmp_path / "t" / "testcase.yaml", text)
    scenarios, errors = discover([tmp_path / "t"], REPO)
    assert errors == []
    selection = Selection(platforms=sel.pop("platforms", []), **sel)
    return {(i.scenario.id, i.platform.identifier): i for i in make_plan(scenarios, boards, selection, tmp_path / "out")}


def test_discovery_skips_ignored_hidden_and_build_folders(tmp_path):
    write(tmp_path / "a" / "testcase.yaml", "tests: {a.a: {}}")
    write(tmp_path / "b" / "sample.yaml", "sample: {name: b}\ntests: {b.b: {}}")
    write(tmp_path / "c" / "tests.yaml", "tests: {c.c: {}}")
    write(tmp_path / "ignored" / ".twister-ignore", "")
    write(tmp_path / "ignored" / "deep" / "testcase.yaml", "tests: {x.x: {}}")
    write(tmp_path / ".hidden" / "testcase.yaml", "tests: {x.y: {}}")
    write(tmp_path / "build" / "CMakeCache.txt", "")
    write(tmp_path / "build" / "sub" / "testcase.yaml", "tests: {x.z: {}}")
    write(tmp_path / "twister-out" / "testcase.yaml", "tests: {x.w: {}}")
    found = sorted(p.relative_to(tmp_path).as_posix() for p in find_testsuite_files(tmp_path))
    assert found == ["a/testcase.yaml", "b/sample.yaml", "c/tests.yaml"]
    # An ignored folder given as -T root itself is searched.
    assert [p.name for p in find_testsuite_files(tmp_path / "ignored")] == ["testcase.yaml"]


def test_default_discovery_does_not_enter_the_runner_fixture_trees():
    assert (REPO / "tests" / "scripts" / "twister" / "trees" / ".twister-ignore").is_file()
    found = list(find_testsuite_files(REPO / "tests"))
    assert not [p for p in found if "tests/scripts/twister/trees" in p.as_posix()]


def test_cases_come_from_the_scan_or_the_testcases_key(tmp_path):
    write(tmp_path / "t" / "src" / "main.c", "ZTEST_SUITE(s, NULL, NULL, NULL, NULL, NULL);\nZTEST(s, test_a) {}\n")
    write(tmp_path / "t" / "testcase.yaml", "tests:\n  t.scan: {}\n  t.listed: {testcases: [s.b, s.c]}\n")
    scenarios, _ = discover([tmp_path / "t"], REPO)
    assert {s.id: s.cases for s in scenarios} == {"t.scan": ["s.a"], "t.listed": ["s.b", "s.c"]}


def test_duplicate_scenario_ids_are_errors(tmp_path):
    write(tmp_path / "a" / "testcase.yaml", "tests: {same.id: {}}")
    write(tmp_path / "b" / "testcase.yaml", "tests: {same.id: {}}")
    scenarios, errors = discover([tmp_path], REPO)
    assert len(scenarios) == 1
    assert len(errors) == 1 and "duplicate scenario id" in errors[0].message


def test_default_platforms_and_build_dir(tmp_path, platforms):
    got = plan(tmp_path, platforms, "tests: {t.a: {}}")
    assert list(got) == [("t.a", "native_posix")]
    inst = got[("t.a", "native_posix")]
    assert inst.status is None
    rel = inst.build_dir.relative_to(tmp_path / "out").as_posix()
    assert rel.startswith("native_posix/") and rel.endswith("/t/t.a")


def test_platform_selection(tmp_path, platforms):
    assert set(plan(tmp_path, platforms, "tests: {t.a: {}}", all_platforms=True)) == {
        ("t.a", "native_posix"),
        ("t.a", "other_board"),
    }
    assert set(plan(tmp_path, platforms, "tests: {t.a: {}}", platforms=["other_board"])) == {("t.a", "other_board")}
    # A scenario allowed only on a non-default board runs there without -p.
    assert set(plan(tmp_path, platforms, "tests: {t.a: {platform_allow: [other_board]}}")) == {("t.a", "other_board")}
    with pytest.raises(PlanError, match="unknown platform nope"):
        plan(tmp_path, platforms, "tests: {t.a: {}}", platforms=["nope"])


def test_integration_platforms_with_G(tmp_path, platforms):
    text = "tests: {t.a: {integration_platforms: [other_board]}, t.b: {}}"
    got = plan(tmp_path, platforms, text, integration=True)
    assert set(got) == {("t.a", "other_board"), ("t.b", "native_posix")}


def test_tag_filters(tmp_path, platforms):
    text = "common: {tags: [canopen]}\ntests: {t.sdo: {tags: [sdo]}, t.nmt: {tags: [nmt]}}"
    got = plan(tmp_path, platforms, text, tags=["sdo"])
    assert got[("t.sdo", "native_posix")].status is None
    assert got[("t.nmt", "native_posix")].status == st.FILTERED
    assert "tag" in got[("t.nmt", "native_posix")].reason
    got = plan(tmp_path, platforms, text, exclude_tags=["sdo"])
    assert got[("t.sdo", "native_posix")].status == st.FILTERED
    assert got[("t.nmt", "native_posix")].status is None
    got = plan(tmp_path, platforms, text, tags=["canopen"], exclude_tags=["nmt"])
    assert [k for k, i in got.items() if i.status is None] == [("t.sdo", "native_posix")]


@pytest.mark.parametrize(
    "keys, reason",
    [
        ("platform_exclude: [native_posix]", "in platform_exclude"),
        ("platform_allow: [native_posix]", None),
        ("arch_allow: [arm]", "arch posix not in arch_allow"),
        ("arch_exclude: [posix]", "arch posix in arch_exclude"),
        ("arch_allow: [posix, arm]", None),
        ("platform_type: [mcu]", "platform type native not in platform_type"),
        ("depends_on: [can, can_socketcan]", None),
        ("depends_on: [can, flexray, lin]", "platform lacks depends_on: flexray, lin"),
        ("slow: true", "slow scenario (run with -S)"),
        ("toolchain_allow: [zephyr]", "no toolchain in toolchain_allow"),
    ],
)
def test_static_filters(tmp_path, platforms, keys, reason):
    inst = plan(tmp_path, platforms, f"tests:\n  t.a:\n    {keys}\n")[("t.a", "native_posix")]
    if reason is None:
        assert inst.status is None
    else:
        assert (inst.status, inst.reason) == (st.FILTERED, reason)


def test_slow_runs_with_S_and_skip_is_skipped_not_filtered(tmp_path, platforms):
    got = plan(tmp_path, platforms, "tests: {t.slow: {slow: true}, t.skip: {skip: true}}", enable_slow=True)
    assert got[("t.slow", "native_posix")].status is None
    skip = got[("t.skip", "native_posix")]
    assert (skip.status, skip.reason) == (st.SKIPPED, "skip: true")


def test_build_only(tmp_path, platforms):
    got = plan(tmp_path, platforms, "tests: {t.a: {build_only: true}, t.b: {}}")
    assert got[("t.a", "native_posix")].build_only and not got[("t.b", "native_posix")].build_only
    got = plan(tmp_path, platforms, "tests: {t.a: {build_only: true}, t.b: {}}", build_only=True)
    assert all(i.build_only for i in got.values())


def test_select_scenarios_by_id_or_path(tmp_path):
    write(tmp_path / "t" / "testcase.yaml", "tests: {t.a: {}, t.b: {}, t.c: {}}")
    scenarios, _ = discover([tmp_path / "t"], REPO)
    rel = scenarios[0].relpath
    assert [s.id for s in select_scenarios(scenarios, ["t.b", f"{rel}/t.c"])] == ["t.b", "t.c"]
    assert select_scenarios(scenarios, []) == scenarios
    with pytest.raises(PlanError, match="no scenario named t.x"):
        select_scenarios(scenarios, ["t.a", "t.x"])
