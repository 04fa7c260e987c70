"""testcase.yaml validation (file: key: message) and Zephyr's `common:` merge rules."""

import textwrap
from pathlib import Path

import pytest
from twisterlib import config
from twisterlib.boards import load_platforms


def load(tmp_path, text, name="testcase.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return config.load_testsuite_file(path, f"t/{name}", "t")


def messages(errors):
    return [str(e) for e in errors]


# --- schema ---------------------------------------------------------------------------------


def test_valid_file_gives_scenarios(tmp_path):
    scenarios, errors = load(
        tmp_path,
        """
        common:
          tags: [a]
        tests:
          x.one: {}
          x.two:
          x.three:
            harness: console
            harness_config: {type: one_line, regex: ["hi"]}
        """,
    )
    assert errors == []
    assert [s.id for s in scenarios] == ["x.one", "x.two", "x.three"]
    assert scenarios[1].keys["harness"] == "test"
    assert scenarios[2].harness == "console"
    assert all(s.source_dir == tmp_path for s in scenarios)


def test_unknown_key_names_file_key_line_and_suggestion(tmp_path):
    _, errors = load(tmp_path, "tests:\n  x.one:\n    timout: 5\n")
    assert messages(errors) == ["t/testcase.yaml: tests/x.one/timout: unknown key (did you mean 'timeout'?) (line 3)"]


def test_wrong_type(tmp_path):
    _, errors = load(tmp_path, "tests:\n  x.one:\n    timeout: soon\n    build_only: 1\n")
    assert messages(errors) == [
        "t/testcase.yaml: tests/x.one/build_only: expected true or false, got integer 1 (line 4)",
        "t/testcase.yaml: tests/x.one/timeout: expected an integer, got string 'soon' (line 3)",
    ]


def test_missing_tests_and_empty_file(tmp_path):
    _, errors = load(tmp_path, "common: {tags: [a]}\n")
    assert messages(errors) == ["t/testcase.yaml: tests: missing required key"]
    _, errors = load(tmp_path, "")
    assert messages(errors) == ["t/testcase.yaml: tests: missing required key"]


def test_sample_needs_name(tmp_path):
    _, errors = load(tmp_path, "sample: {description: d}\ntests: {s.a: {}}\n", "sample.yaml")
    assert messages(errors) == ["t/sample.yaml: sample/name: missing required key (line 1)"]


def test_enum_and_bad_scenario_id_and_scenario_not_a_mapping(tmp_path):
    _, errors = load(tmp_path, 'tests:\n  "has space": {}\n  x.h: {harness: robot}\n  x.s: yes\n')
    assert messages(errors) == [
        "t/testcase.yaml: tests/has space: invalid scenario id (use letters, digits and . _ - +) (line 2)",
        "t/testcase.yaml: tests/x.h/harness: 'robot' is not one of: test, ztest, console, pytest (line 3)",
        "t/testcase.yaml: tests/x.s: expected a mapping or nothing, got boolean (line 4)",
    ]


def test_yaml_syntax_error_and_duplicate_key(tmp_path):
    _, errors = load(tmp_path, "tests:\n  x.one: {tags: [a}\n")
    assert len(errors) == 1
    assert str(errors[0]).startswith("t/testcase.yaml: (syntax): invalid YAML: ")
    assert errors[0].line == 2
    _, errors = load(tmp_path, "tests:\n  x.one:\n    tags: [a]\n    tags: [b]\n")
    assert messages(errors) == ["t/testcase.yaml: tests/x.one/tags: duplicate key (first at line 3) (line 4)"]


@pytest.mark.parametrize(
    "scenario, message",
    [
        ("filter: CONFIG_A and", "tests/x.one/filter: expected a symbol, 'not' or '(', found end of expression at column 13"),
        ("extra_configs: [FOO=y]", "tests/x.one/extra_configs/0: expected CONFIG_NAME=value, got 'FOO=y'"),
        ("harness: console", "tests/x.one/harness_config/regex: harness: console needs harness_config regex"),
        (
            "harness: console\n    harness_config: {type: one_line, regex: [a, b]}",
            "tests/x.one/harness_config/regex: type one_line takes exactly one regex (use multi_line)",
        ),
        (
            "harness_config: {type: one_line, regex: [a]}",
            "tests/x.one/harness_config/type: only used with harness: console (this scenario has harness: test)",
        ),
        ("harness_config: {pytest_root: [x]}", "tests/x.one/harness_config/pytest_root: only used with harness: pytest"),
        ("harness_config: {can_lines: 2}", "tests/x.one/harness_config/can_lines: only used with fixture: vcan"),
        (
            "harness: console\n    harness_config: {type: one_line, regex: ['(']}",
            "tests/x.one/harness_config/regex/0: bad regular expression '('",
        ),
    ],
)
def test_checks_beyond_the_schema(tmp_path, scenario, message):
    scenarios, errors = load(tmp_path, f"tests:\n  x.one:\n    {scenario}\n")
    assert scenarios == []
    assert any(message in m for m in messages(errors)), messages(errors)


def test_a_bad_common_filter_is_reported_on_common(tmp_path):
    _, errors = load(tmp_path, "common:\n  filter: 'not'\ntests:\n  x.one: {}\n")
    assert messages(errors)[0].startswith("t/testcase.yaml: common/filter: expected a symbol")


# --- common merge ---------------------------------------------------------------------------


def test_filters_join_with_and():
    merged = config.merge_common({"filter": "CONFIG_A"}, {"filter": "CONFIG_B or CONFIG_C"})
    assert merged["filter"] == "(CONFIG_A) and (CONFIG_B or CONFIG_C)"
    assert config.merge_common({"filter": "CONFIG_A"}, {})["filter"] == "CONFIG_A"
    assert config.merge_common({}, {"filter": "CONFIG_B"})["filter"] == "CONFIG_B"


def test_lists_concatenate_common_first_and_strings_split():
    merged = config.merge_common(
        {"tags": "net can", "extra_configs": ["CONFIG_A=y"], "extra_args": "X=1"},
        {"tags": ["can", "sdo"], "extra_configs": ["CONFIG_B=y"], "extra_args": ["Y=2"]},
    )
    assert merged["tags"] == ["net", "can", "sdo"]  # accumulated, duplicates dropped
    assert merged["extra_configs"] == ["CONFIG_A=y", "CONFIG_B=y"]
    assert merged["extra_args"] == ["X=1", "Y=2"]


def test_scalars_and_strings_are_overridden():
    merged = config.merge_common(
        {"timeout": 10, "harness": "console", "build_only": True, "slow": True},
        {"timeout": 30, "harness": "ztest", "build_only": False},
    )
    assert merged["timeout"] == 30
    assert merged["harness"] == "ztest"
    assert merged["build_only"] is False
    assert merged["slow"] is True  # from common


def test_harness_config_merges_key_by_key():
    merged = config.merge_common(
        {"harness_config": {"type": "one_line", "regex": ["a"], "fixture": "x"}},
        {"harness_config": {"regex": ["b"]}},
    )
    assert merged["harness_config"] == {"type": "one_line", "regex": ["b"], "fixture": "x"}


def test_defaults():
    merged = config.merge_common(None, None)
    assert merged["harness"] == "test"
    assert merged["timeout"] == 60
    assert merged["type"] == "integration"
    assert merged["tags"] == [] and merged["depends_on"] == []
    assert merged["build_only"] is False and merged["skip"] is False and merged["slow"] is False


def test_merged_scenario_from_file(tmp_path):
    scenarios, errors = load(
        tmp_path,
        """
        common:
          tags: [canopen, sdo]
          depends_on: [can]
          filter: CONFIG_CANOPEN
          timeout: 20
          harness_config: {fixture: vcan}
        tests:
          canopen.sdo.server: {}
          canopen.sdo.server.block:
            tags: block
            filter: CONFIG_CANOPEN_SDO_BLOCK
            timeout: 90
            harness_config: {can_lines: 2}
        """,
    )
    assert errors == []
    plain, block = scenarios
    assert plain.tags == ["canopen", "sdo"] and plain.timeout == 20 and plain.filter == "CONFIG_CANOPEN"
    assert block.tags == ["canopen", "sdo", "block"]
    assert block.filter == "(CONFIG_CANOPEN) and (CONFIG_CANOPEN_SDO_BLOCK)"
    assert block.timeout == 90
    assert block.fixture == "vcan" and block.can_lines == 2 and plain.can_lines == 1
    assert block.filter_tree == ("and", ("sym", "CONFIG_CANOPEN"), ("sym", "CONFIG_CANOPEN_SDO_BLOCK"))


# --- boards ---------------------------------------------------------------------------------


def test_board_files(tmp_path):
    d = tmp_path / "posix" / "native_posix"
    d.mkdir(parents=True)
    (d / "native_posix.yaml").write_text(
        "identifier: native_posix\narch: posix\ntype: native\nsupported: [can]\n"
        "testing: {default: true, timeout_multiplier: 2}\n"
    )
    (d / "board.yml").write_text("not: a twister file\n")
    (d / "other.yaml").write_text("ignored: because the name is not the folder's\n")
    bad = tmp_path / "posix" / "broken"
    bad.mkdir()
    (bad / "broken.yaml").write_text("identifier: broken\ntype: native\n")
    platforms, errors = load_platforms([tmp_path], display=lambda p: Path(p).name)
    assert list(platforms) == ["native_posix"]
    p = platforms["native_posix"]
    assert p.arch == "posix" and p.supported == ["can"] and p.default and p.timeout_multiplier == 2.0
    assert [str(e) for e in errors] == ["broken.yaml: arch: missing required key"]


def test_repo_board_is_valid():
    repo_boards = Path(__file__).resolve().parents[3] / "boards"
    platforms, errors = load_platforms([repo_boards])
    assert errors == []
    assert platforms["native_posix"].default
    assert "can" in platforms["native_posix"].supported
