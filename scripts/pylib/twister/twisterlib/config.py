"""testcase.yaml / sample.yaml / tests.yaml: loading, validation and the `common:` merge.

Errors are reported as `<file>: <key path>: <message> (line N)`, where the key path names the
offending key from the top of the file, e.g.

    tests/kernel/mutex/testcase.yaml: tests/kernel.mutex/timout: unknown key (did you mean 'timeout'?) (line 7)
"""

import difflib
import functools
import re
from dataclasses import dataclass, field
from pathlib import Path

import jsonschema
import yaml

from . import expr

SCHEMA_DIR = Path(__file__).resolve().parent.parent / "schemas"

TESTSUITE_FILENAMES = ("testcase.yaml", "sample.yaml", "tests.yaml")

# Keys holding lists. A space-separated string is accepted for them and split (Zephyr's
# deprecated form). In the `common:` merge they concatenate, common first.
LIST_KEYS = frozenset(
    {
        "tags",
        "platform_allow",
        "platform_exclude",
        "integration_platforms",
        "platform_type",
        "arch_allow",
        "arch_exclude",
        "toolchain_allow",
        "toolchain_exclude",
        "depends_on",
        "extra_configs",
        "extra_conf_files",
        "extra_args",
        "testcases",
        "levels",
    }
)

DEFAULTS = {
    "harness": "test",
    "timeout": 60,
    "type": "integration",
    "build_only": False,
    "skip": False,
    "slow": False,
    "ignore_faults": False,
    "harness_config": {},
}

_CONSOLE_ONLY = ("type", "regex", "ordered", "record")
_PYTEST_ONLY = ("pytest_root", "pytest_args")
_CONFIG_ASSIGN_RE = re.compile(r"^CONFIG_[A-Za-z0-9_]+=.*$")


@dataclass
class ConfigError:
    """One problem in one YAML file."""

    file: str
    key: str
    message: str
    line: int | None = None

    def __str__(self) -> str:
        where = f" (line {self.line})" if self.line else ""
        return f"{self.file}: {self.key}: {self.message}{where}"


@functools.cache
def load_schema(name: str) -> dict:
    with open(SCHEMA_DIR / name, encoding="utf-8") as f:
        return yaml.safe_load(f)


# --- YAML with line numbers -------------------------------------------------------------------


def _key_text(node) -> str:
    return str(node.value) if isinstance(node, yaml.ScalarNode) else "?"


def _walk(node, path, lines, problems):
    if isinstance(node, yaml.MappingNode):
        seen = {}
        for knode, vnode in node.value:
            key = _key_text(knode)
            here = path + (key,)
            line = knode.start_mark.line + 1
            if key in seen and key != "<<":
                problems.append((here, f"duplicate key (first at line {seen[key]})", line))
            seen.setdefault(key, line)
            lines.setdefault(here, line)
            _walk(vnode, here, lines, problems)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            here = path + (i,)
            lines.setdefault(here, item.start_mark.line + 1)
            _walk(item, here, lines, problems)


def load_yaml_with_lines(text: str):
    """Parse YAML; return (data, {key path: line}, [(path, message, line)] for duplicate keys).

    Raises yaml.YAMLError on syntax errors.
    """
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, {}, []
        lines: dict = {}
        problems: list = []
        _walk(node, (), lines, problems)
        data = loader.construct_document(node)
    finally:
        loader.dispose()
    return data, lines, problems


def format_path(path) -> str:
    return "/".join(str(p) for p in path) if path else "(top level)"


def _line_for(lines: dict, path: tuple) -> int | None:
    path = tuple(path)
    while path:
        if path in lines:
            return lines[path]
        path = path[:-1]
    return None


# --- schema errors in words -------------------------------------------------------------------

_TYPE_WORDS = {
    "object": "a mapping",
    "array": "a list",
    "string": "a string",
    "integer": "an integer",
    "number": "a number",
    "boolean": "true or false",
    "null": "nothing",
}


def _yaml_type(value) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "list"
    if isinstance(value, dict):
        return "mapping"
    return type(value).__name__


def _short(value, limit: int = 40) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _schema_messages(err) -> list[tuple[tuple, str]]:
    """Turn one jsonschema error into [(key path, message)]."""
    path = tuple(err.absolute_path)
    v = err.validator
    if v in ("anyOf", "oneOf"):
        # Drop the "wrong type for this branch" errors; what remains is the branch that the
        # value was meant for. If nothing remains the value has a type no branch accepts.
        inner = [c for c in err.context if not (c.validator == "type" and not c.relative_path)]
        if inner:
            out = []
            for c in inner:
                out.extend(_schema_messages(c))
            return out
        wanted = []
        for sub in err.validator_value:
            t = sub.get("type") if isinstance(sub, dict) else None
            if t is None and isinstance(sub, dict) and "$ref" in sub:
                t = "object"
            if isinstance(t, str):
                wanted.append(_TYPE_WORDS.get(t, t))
        return [(path, f"expected {' or '.join(wanted)}, got {_yaml_type(err.instance)}")]
    if v == "type":
        types = err.validator_value if isinstance(err.validator_value, list) else [err.validator_value]
        words = " or ".join(_TYPE_WORDS.get(t, t) for t in types)
        got = _yaml_type(err.instance)
        shown = f" {_short(err.instance)}" if got not in ("mapping", "list", "nothing") else ""
        return [(path, f"expected {words}, got {got}{shown}")]
    if v == "additionalProperties":
        allowed = sorted(err.schema.get("properties", {}))
        out = []
        for key in err.instance:
            if key in allowed:
                continue
            msg = "unknown key"
            close = difflib.get_close_matches(str(key), allowed, n=1)
            if close:
                msg += f" (did you mean '{close[0]}'?)"
            out.append((path + (key,), msg))
        return out
    if v == "required":
        return [
            (path + (key,), "missing required key")
            for key in err.validator_value
            if isinstance(err.instance, dict) and key not in err.instance
        ]
    if v == "enum":
        choices = ", ".join(str(c) for c in err.validator_value)
        return [(path, f"{_short(err.instance)} is not one of: {choices}")]
    if v == "pattern" and "propertyNames" in err.schema_path:
        return [(path + (err.instance,), "invalid scenario id (use letters, digits and . _ - +)")]
    if v == "minProperties":
        return [(path, "must not be empty")]
    if v == "minItems":
        return [(path, f"needs at least {err.validator_value} item(s)")]
    return [(path, err.message)]


def schema_errors(data, schema_name: str) -> list[tuple[tuple, str]]:
    schema = load_schema(schema_name)
    validator = jsonschema.Draft202012Validator(schema)
    out = []
    for err in validator.iter_errors(data):
        out.extend(_schema_messages(err))
    out.sort(key=lambda pm: [str(p) for p in pm[0]])
    return out


def load_validated(path: Path, display: str, schema_name: str):
    """Read and validate one YAML file. Returns (data or None, [ConfigError])."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        return None, [ConfigError(display, "(file)", f"cannot read: {e}")]
    try:
        data, lines, dups = load_yaml_with_lines(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        line = mark.line + 1 if mark else None
        return None, [ConfigError(display, "(syntax)", f"invalid YAML: {problem}", line)]
    errors = [ConfigError(display, format_path(p), m, ln) for p, m, ln in dups]
    if data is None:
        data = {}
    for p, msg in schema_errors(data, schema_name):
        errors.append(ConfigError(display, format_path(p), msg, _line_for(lines, p)))
    if errors:
        return None, errors
    return data, []


# --- the `common:` merge ----------------------------------------------------------------------


def as_list(value) -> list:
    if value is None:
        return []
    if isinstance(value, str):
        return value.split()
    return list(value)


def merge_common(common: dict | None, scenario: dict | None) -> dict:
    """Merge `common:` into one scenario with Zephyr's rules, then apply the defaults.

    - `filter`: joined with `and`: "(common) and (scenario)";
    - list keys (strings are split on spaces): concatenated, common first;
    - `harness_config`: merged key by key, the scenario's keys win;
    - any other key (scalars, strings such as `harness`): the scenario's value wins.
    """
    common = common or {}
    scenario = scenario or {}
    merged: dict = {}
    for key in list(common) + [k for k in scenario if k not in common]:
        in_c, in_s = key in common, key in scenario
        c, s = common.get(key), scenario.get(key)
        if key in LIST_KEYS:
            merged[key] = as_list(c) + as_list(s)
        elif in_c and in_s and key == "filter":
            merged[key] = f"({c}) and ({s})"
        elif in_c and in_s and key == "harness_config":
            merged[key] = {**(c or {}), **(s or {})}
        else:
            merged[key] = s if in_s else c
    if "tags" in merged:
        merged["tags"] = list(dict.fromkeys(merged["tags"]))
    for key, value in DEFAULTS.items():
        if merged.get(key) is None:
            merged[key] = dict(value) if isinstance(value, dict) else value
    for key in LIST_KEYS:
        merged.setdefault(key, [])
    return merged


# --- scenarios --------------------------------------------------------------------------------


@dataclass
class Scenario:
    """One entry of `tests:` with `common:` merged in."""

    id: str
    yaml_path: Path
    source_dir: Path
    relpath: str  # the folder, relative to the repo root (or to its -T root when outside)
    keys: dict
    is_sample: bool = False
    filter_tree: object = None
    cases: list = field(default_factory=list)  # expected "suite.case" names

    @property
    def harness(self) -> str:
        """'ztest' (also for Zephyr's spelling 'test'), 'console' or 'pytest'."""
        h = self.keys["harness"]
        return "ztest" if h in ("test", "ztest") else h

    @property
    def harness_config(self) -> dict:
        return self.keys.get("harness_config") or {}

    @property
    def fixture(self) -> str | None:
        return self.harness_config.get("fixture")

    @property
    def can_lines(self) -> int:
        return int(self.harness_config.get("can_lines", 1))

    @property
    def tags(self) -> list[str]:
        return self.keys["tags"]

    @property
    def timeout(self) -> int:
        return self.keys["timeout"]

    @property
    def filter(self) -> str | None:
        return self.keys.get("filter")

    def get(self, key, default=None):
        return self.keys.get(key, default)


def _semantic_errors(display: str, lines: dict, path: tuple, keys: dict, merged: bool):
    """Checks the schema cannot express. `merged` is True for a scenario after the merge."""
    errors = []

    def err(subpath, msg):
        p = path + subpath
        errors.append(ConfigError(display, format_path(p), msg, _line_for(lines, p)))

    if not merged:
        if keys.get("filter") is not None:
            try:
                expr.parse(keys["filter"])
            except expr.FilterError as e:
                err(("filter",), f"{e} in {keys['filter']!r}")
        for i, item in enumerate(keys.get("extra_configs") or []):
            if not _CONFIG_ASSIGN_RE.match(item):
                err(("extra_configs", i), f"expected CONFIG_NAME=value, got {item!r}")
        hc = keys.get("harness_config") or {}
        rx = hc.get("regex") or []
        rec = (hc.get("record") or {}).get("regex") or []
        for name, lst in (("regex", rx), ("record", as_list(rec) if isinstance(rec, str) else rec)):
            for i, pattern in enumerate(lst):
                try:
                    re.compile(pattern)
                except re.error as e:
                    sub = ("harness_config", name, i) if name == "regex" else ("harness_config", "record", "regex")
                    err(sub, f"bad regular expression {pattern!r}: {e}")
        return errors

    harness = keys["harness"]
    hc = keys.get("harness_config") or {}
    if harness == "console":
        if not hc.get("regex"):
            err(("harness_config", "regex"), "harness: console needs harness_config regex")
        if not hc.get("type"):
            err(("harness_config", "type"), "harness: console needs harness_config type (one_line or multi_line)")
        if hc.get("type") == "one_line" and len(hc.get("regex") or []) > 1:
            err(("harness_config", "regex"), "type one_line takes exactly one regex (use multi_line)")
    else:
        for key in _CONSOLE_ONLY:
            if key in hc:
                err(("harness_config", key), f"only used with harness: console (this scenario has harness: {harness})")
    if harness != "pytest":
        for key in _PYTEST_ONLY:
            if key in hc:
                err(("harness_config", key), f"only used with harness: pytest (this scenario has harness: {harness})")
    if "can_lines" in hc and hc.get("fixture") != "vcan":
        err(("harness_config", "can_lines"), "only used with fixture: vcan")
    return errors


def load_testsuite_file(path: Path, display: str, relpath: str):
    """Load one testcase.yaml/sample.yaml/tests.yaml.

    Returns (scenarios, errors). Any error in the file drops all its scenarios: a file that is
    half right is still wrong, and the run reports it as an error.
    """
    data, errors = load_validated(path, display, "testsuite-schema.yaml")
    if errors:
        return [], errors
    text = Path(path).read_text(encoding="utf-8")
    _, lines, _ = load_yaml_with_lines(text)

    common = data.get("common") or {}
    errors.extend(_semantic_errors(display, lines, ("common",), common, merged=False))
    scenarios = []
    for sid, raw in data["tests"].items():
        raw = raw or {}
        path_s = ("tests", sid)
        errors.extend(_semantic_errors(display, lines, path_s, raw, merged=False))
        keys = merge_common(common, raw)
        errors.extend(_semantic_errors(display, lines, path_s, keys, merged=True))
        tree = None
        if keys.get("filter"):
            try:
                tree = expr.parse(keys["filter"])
            except expr.FilterError:
                pass  # already reported on the key it came from
        scenarios.append(
            Scenario(
                id=str(sid),
                yaml_path=Path(path),
                source_dir=Path(path).parent,
                relpath=relpath,
                keys=keys,
                is_sample="sample" in data,
                filter_tree=tree,
            )
        )
    if errors:
        return [], errors
    return scenarios, []
