"""Discovery of scenarios and the test plan: scenario x platform instances, static filters.

The runtime `filter:` (needs the built .config) is applied later by the runner.
"""

import os
from dataclasses import dataclass
from pathlib import Path

from . import statuses as st
from .boards import Platform
from .config import TESTSUITE_FILENAMES, ConfigError, Scenario, load_testsuite_file
from .instance import TestInstance
from .scan import scan_sources

# A folder holding this file is not searched (unless it is a -T root itself). The runner's own
# fixture trees (tests/scripts/twister/trees) carry one.
IGNORE_MARKER = ".twister-ignore"


class PlanError(Exception):
    """A command-line selection that cannot be satisfied (unknown platform, unknown -s)."""


def display_path(path: Path, repo_root: Path) -> str:
    path = Path(path)
    try:
        return path.resolve().relative_to(repo_root).as_posix()
    except ValueError:
        return str(path)


def find_testsuite_files(root: Path):
    """Yield testcase.yaml/sample.yaml/tests.yaml files under root, in sorted order."""
    root = Path(root)
    if root.is_file():
        if root.name in TESTSUITE_FILENAMES:
            yield root
        return
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        if here != root and IGNORE_MARKER in filenames:
            dirnames[:] = []
            continue
        if "CMakeCache.txt" in filenames:  # a build directory
            dirnames[:] = []
            continue
        dirnames[:] = sorted(
            d for d in dirnames if not d.startswith(".") and not d.startswith("twister-out") and d != "__pycache__"
        )
        for name in TESTSUITE_FILENAMES:
            if name in filenames:
                yield here / name


def _relpath(folder: Path, root: Path, repo_root: Path) -> str:
    folder = folder.resolve()
    try:
        return folder.relative_to(repo_root).as_posix()
    except ValueError:
        root = root.resolve()
        base = root if root.is_dir() else root.parent
        rel = folder.relative_to(base)
        return (Path(base.name) / rel).as_posix()


def discover(roots: list[Path], repo_root: Path):
    """Load every scenario under the roots. Returns (scenarios, [ConfigError])."""
    scenarios: list[Scenario] = []
    errors: list[ConfigError] = []
    seen_files = set()
    by_id: dict[str, Scenario] = {}
    for root in roots:
        for path in find_testsuite_files(root):
            real = path.resolve()
            if real in seen_files:
                continue
            seen_files.add(real)
            disp = display_path(path, repo_root)
            found, errs = load_testsuite_file(path, disp, _relpath(path.parent, Path(root), repo_root))
            errors.extend(errs)
            cache = None
            for sc in found:
                if sc.id in by_id:
                    other = display_path(by_id[sc.id].yaml_path, repo_root)
                    errors.append(ConfigError(disp, f"tests/{sc.id}", f"duplicate scenario id (also in {other})"))
                    continue
                by_id[sc.id] = sc
                if sc.harness == "ztest":
                    if sc.keys["testcases"]:
                        sc.cases = list(sc.keys["testcases"])
                    else:
                        if cache is None:
                            cache = scan_sources(sc.source_dir)[1]
                        sc.cases = list(cache)
                scenarios.append(sc)
    return scenarios, errors


def select_scenarios(scenarios: list[Scenario], names: list[str]) -> list[Scenario]:
    """-s: keep the named scenarios ("id" or "relpath/id"); unknown names are an error."""
    if not names:
        return scenarios
    wanted = set(names)
    chosen = [s for s in scenarios if s.id in wanted or f"{s.relpath}/{s.id}" in wanted]
    known = {s.id for s in scenarios} | {f"{s.relpath}/{s.id}" for s in scenarios}
    missing = [n for n in names if n not in known]
    if missing:
        raise PlanError(f"no scenario named {', '.join(missing)} (see --list-tests)")
    return chosen


@dataclass
class Selection:
    """The command-line choices the static plan depends on."""

    platforms: list[str]  # -p
    all_platforms: bool = False  # -l
    integration: bool = False  # -G
    tags: list[str] = None  # -t
    exclude_tags: list[str] = None  # -e
    enable_slow: bool = False  # -S
    build_only: bool = False  # -b
    sanitizers: list = None  # --enable-asan/-ubsan/-tsan: "ASAN", "UBSAN", "TSAN"
    extra_args: list = None  # -x values


# Sanitizers that cannot share an image (Kconfig: TSAN depends on !ASAN; GCC and Clang refuse
# -fsanitize=address,thread). UBSan goes with either.
SANITIZER_CONFLICTS = (("TSAN", "ASAN"),)
_SANITIZER_NAMES = {"ASAN": "ASan", "UBSAN": "UBSan", "TSAN": "TSan"}


def _cache_assignment(arg: str) -> tuple[str, str] | None:
    """"VAR=value", "-DVAR=value" or "-DVAR:TYPE=value" -> (VAR, value)."""
    arg = arg[2:] if arg.startswith("-D") else arg
    if "=" not in arg:
        return None
    name, value = arg.split("=", 1)
    return name.split(":", 1)[0], value


def _read_fragment(path: Path) -> dict[str, str]:
    """CONFIG_* assignments of a Kconfig fragment ("# CONFIG_X is not set" reads n)."""
    values: dict[str, str] = {}
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return values
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("# CONFIG_") and line.endswith(" is not set"):
            values[line[2:-len(" is not set")]] = "n"
        elif line.startswith("CONFIG_") and "=" in line:
            name, value = line.split("=", 1)
            values[name.strip()] = value.strip().strip('"')
    return values


def sanitizer_settings(sc: Scenario, plat: Platform, sel: Selection) -> dict[str, str]:
    """The sanitizers an instance's build would enable: {"ASAN": "where it comes from"}.

    Follows the Kconfig merge of cmake/kconfig.cmake (board defconfig, CONF_FILE or
    prj[_<board>].conf, boards/<board>.conf, EXTRA_CONF_FILE, then the -DCONFIG_* values, the
    last assignment winning) over the -D arguments that build.cmake_command() passes, in its
    order: extra_conf_files, extra_args, extra_configs, --enable-*, -x.
    """
    cache: dict[str, tuple[str, str]] = {}  # -D variable -> (value, origin)
    if sc.get("extra_conf_files"):
        cache["EXTRA_CONF_FILE"] = (";".join(sc.get("extra_conf_files")), "extra_conf_files")
    assignments = [("extra_args", a) for a in sc.get("extra_args") or []]
    assignments += [("extra_configs", a) for a in sc.get("extra_configs") or []]
    assignments += [(f"--enable-{s.lower()}", f"CONFIG_{s}=y") for s in sel.sanitizers or []]
    assignments += [("-x", a) for a in sel.extra_args or []]
    for origin, arg in assignments:
        kv = _cache_assignment(arg)
        if kv:
            cache[kv[0]] = (kv[1], origin)

    def files(var: str) -> list[Path] | None:
        value = cache[var][0] if var in cache else os.environ.get(var)
        if value is None:
            return None
        return [sc.source_dir / f for f in value.replace(";", " ").split()]

    fragments = []
    if plat.path is not None:
        fragments.append(plat.path.parent / f"{plat.identifier}_defconfig")
    conf = files("CONF_FILE")
    if conf is None:
        board_prj = sc.source_dir / f"prj_{plat.identifier}.conf"
        conf = [board_prj if board_prj.exists() else sc.source_dir / "prj.conf"]
    fragments += conf
    fragments.append(sc.source_dir / "boards" / f"{plat.identifier}.conf")
    fragments += files("EXTRA_CONF_FILE") or []

    config: dict[str, tuple[str, str]] = {}
    for frag in fragments:
        for name, value in _read_fragment(frag).items():
            config[name] = (value, frag.name)
    for name, (value, origin) in cache.items():
        if name.startswith("CONFIG_"):
            config[name] = (value, origin)
    return {
        s: config[f"CONFIG_{s}"][1]
        for s in _SANITIZER_NAMES
        if config.get(f"CONFIG_{s}", ("n", ""))[0] == "y"
    }


def command_line_sanitizers(sanitizers: list, extra_args: list) -> dict[str, str]:
    """The sanitizers the command line alone enables (--enable-*, then -x CONFIG_*SAN=...)."""
    enabled = {s: f"--enable-{s.lower()}" for s in sanitizers or []}
    for arg in extra_args or []:
        kv = _cache_assignment(arg)
        if kv and kv[0].startswith("CONFIG_") and kv[0][len("CONFIG_"):] in _SANITIZER_NAMES:
            name = kv[0][len("CONFIG_"):]
            if kv[1] == "y":
                enabled[name] = "-x"
            else:
                enabled.pop(name, None)
    return enabled


def sanitizer_conflict(enabled: dict[str, str]) -> str | None:
    """Why these sanitizers cannot be built together, or None."""
    for a, b in SANITIZER_CONFLICTS:
        if a in enabled and b in enabled:
            return (
                f"{_SANITIZER_NAMES[a]} and {_SANITIZER_NAMES[b]} cannot be combined "
                f"(CONFIG_{b}=y from {enabled[b]}, CONFIG_{a}=y from {enabled[a]})"
            )
    return None


def platforms_for(sc: Scenario, platforms: dict[str, Platform], sel: Selection) -> list[Platform]:
    if sel.platforms:
        return [platforms[p] for p in sel.platforms]
    if sel.all_platforms:
        return list(platforms.values())
    if sel.integration and sc.get("integration_platforms"):
        return [platforms[p] for p in sc.get("integration_platforms") if p in platforms]
    default = [p for p in platforms.values() if p.default]
    allow = sc.get("platform_allow")
    if allow and not any(p.identifier in allow for p in default):
        # Like Zephyr: a scenario meant for specific boards runs there without -p.
        return [platforms[p] for p in allow if p in platforms]
    return default


def static_filter(sc: Scenario, plat: Platform, sel: Selection) -> tuple[str, str] | None:
    """Why this instance does not go through the pipeline: (status, reason), or None."""
    tags = set(sc.tags)
    if sel.tags and not tags & set(sel.tags):
        return st.FILTERED, "command line tag filter (-t)"
    if sel.exclude_tags and tags & set(sel.exclude_tags):
        return st.FILTERED, "command line tag exclusion (-e)"
    allow = sc.get("platform_allow")
    if allow and plat.identifier not in allow:
        return st.FILTERED, "not in platform_allow"
    if plat.identifier in sc.get("platform_exclude"):
        return st.FILTERED, "in platform_exclude"
    if sc.get("platform_type") and plat.type not in sc.get("platform_type"):
        return st.FILTERED, f"platform type {plat.type} not in platform_type"
    if sc.get("arch_allow") and plat.arch not in sc.get("arch_allow"):
        return st.FILTERED, f"arch {plat.arch} not in arch_allow"
    if plat.arch in sc.get("arch_exclude"):
        return st.FILTERED, f"arch {plat.arch} in arch_exclude"
    if sc.get("toolchain_allow") and not set(plat.toolchain) & set(sc.get("toolchain_allow")):
        return st.FILTERED, "no toolchain in toolchain_allow"
    if set(plat.toolchain) & set(sc.get("toolchain_exclude")):
        return st.FILTERED, "toolchain in toolchain_exclude"
    missing = [d for d in sc.get("depends_on") if d not in plat.supported]
    if missing:
        return st.FILTERED, f"platform lacks depends_on: {', '.join(missing)}"
    if plat.only_tags and not tags & set(plat.only_tags):
        return st.FILTERED, "no tag in the platform's testing.only_tags"
    if plat.ignore_tags and tags & set(plat.ignore_tags):
        return st.FILTERED, "tag in the platform's testing.ignore_tags"
    if sc.get("min_ram") and plat.ram and sc.get("min_ram") > plat.ram:
        return st.FILTERED, "not enough RAM (min_ram)"
    if sc.get("min_flash") and plat.flash and sc.get("min_flash") > plat.flash:
        return st.FILTERED, "not enough flash (min_flash)"
    if sc.get("slow") and not sel.enable_slow:
        return st.FILTERED, "slow scenario (run with -S)"
    conflict = sanitizer_conflict(sanitizer_settings(sc, plat, sel))
    if conflict:
        return st.FILTERED, conflict
    if sc.get("skip"):
        return st.SKIPPED, "skip: true"
    return None


def make_plan(scenarios: list[Scenario], platforms: dict[str, Platform], sel: Selection, outdir: Path):
    """Scenario x platform instances, statically filtered; pipeline instances have status None."""
    unknown = [p for p in sel.platforms if p not in platforms]
    if unknown:
        raise PlanError(f"unknown platform {', '.join(unknown)} (known: {', '.join(sorted(platforms)) or 'none'})")
    instances = []
    for sc in scenarios:
        for plat in platforms_for(sc, platforms, sel):
            inst = TestInstance(sc, plat, build_dir=Path(outdir) / plat.identifier / sc.relpath / sc.id)
            inst.build_only = bool(sc.get("build_only") or sel.build_only)
            inst.init_cases()
            verdict = static_filter(sc, plat, sel)
            if verdict:
                inst.set_status(*verdict)
                inst.fill_cases(verdict[0], verdict[1])
            instances.append(inst)
    return instances
