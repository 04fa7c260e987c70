"""Command line of scripts/twister (Zephyr twister's option spelling)."""

import argparse
import shutil
import signal
import sys
import time
import uuid
from pathlib import Path

from . import handler, log, report, vm
from . import statuses as st
from .boards import load_platforms
from .build import BuildOptions
from .instance import TestInstance
from .plan import (
    PlanError,
    Selection,
    command_line_sanitizers,
    discover,
    display_path,
    make_plan,
    sanitizer_conflict,
    select_scenarios,
)
from .runner import RunOptions, Runner, default_jobs

REPO_ROOT = Path(__file__).resolve().parents[4]

EPILOG = """\
Arguments after `--` are passed to every image (ztest/console harness).
Exit status: 0 when nothing failed, 1 when an instance failed, errored or timed out (or a
YAML file is invalid), 2 on usage errors, 130 when interrupted.
The last line printed is `N passed, N failed[, N skipped]` (see doc/twister.md for how it counts).
"""


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="twister",
        description="Build and run SafeLine test scenarios (testcase.yaml/sample.yaml) on the boards.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sel = p.add_argument_group("selection")
    sel.add_argument("-T", "--testsuite-root", action="append", default=[], metavar="DIR",
                     help="search for scenarios under DIR (repeatable; default: tests/ and samples/)")
    sel.add_argument("-p", "--platform", action="append", default=[],
                     help="platform to run on (repeatable; default: boards with testing: default: true)")
    sel.add_argument("-l", "--all", action="store_true", help="use every platform, not only the default ones")
    sel.add_argument("-G", "--integration", action="store_true",
                     help="run each scenario on its integration_platforms where it lists them")
    sel.add_argument("-s", "--test", "--scenario", dest="scenario", action="append", default=[],
                     metavar="SCENARIO", help="run only this scenario (id, or path/id; repeatable)")
    sel.add_argument("-t", "--tag", action="append", default=[], help="run only scenarios with this tag (repeatable)")
    sel.add_argument("-e", "--exclude-tag", action="append", default=[],
                     help="skip scenarios with this tag (repeatable)")
    sel.add_argument("-S", "--enable-slow", action="store_true", help="also run scenarios marked slow")
    sel.add_argument("-X", "--fixture", action="append", default=[],
                     help="a fixture this machine provides, e.g. -X vcan (repeatable)")
    sel.add_argument("-A", "--board-root", action="append", default=[], metavar="DIR",
                     help="where board folders are (default: boards/ of the repo)")

    bld = p.add_argument_group("build and run")
    bld.add_argument("-b", "--build-only", action="store_true", help="build, do not run")
    bld.add_argument("--test-only", action="store_true", help="run what a previous -b built in the output dir")
    bld.add_argument("-x", "--extra-args", action="append", default=[], metavar="VAR=VALUE",
                     help="add -DVAR=VALUE to every CMake call, e.g. -x=CONFIG_FOO=y (repeatable)")
    bld.add_argument("--enable-asan", action="store_true", help="build with CONFIG_ASAN=y")
    bld.add_argument("--enable-ubsan", action="store_true", help="build with CONFIG_UBSAN=y")
    bld.add_argument("--enable-tsan", action="store_true", help="build with CONFIG_TSAN=y")
    bld.add_argument("-j", "--jobs", type=int, default=default_jobs(),
                     help="instances built and run in parallel (default: number of CPUs)")
    bld.add_argument("--timeout-multiplier", type=float, default=1.0, metavar="F",
                     help="multiply every scenario's timeout by F")
    bld.add_argument("--seed", type=int, help="pass --seed=N to every image")
    bld.add_argument("--retry-failed", type=int, default=0, metavar="N",
                     help="run failed instances (not build failures) again, up to N times")
    bld.add_argument("--vcan-vm", type=Path, default=REPO_ROOT / "scripts" / "vcan-vm", metavar="PATH",
                     help="the VM runner for the vcan fixture (default: scripts/vcan-vm)")

    out = p.add_argument_group("output")
    out.add_argument("-O", "--outdir", type=Path, default=Path("twister-out"),
                     help="output folder (default: twister-out; an existing one becomes twister-out.N)")
    out.add_argument("-o", "--report-dir", type=Path, help="where twister.json/twister.xml go (default: the outdir)")
    out.add_argument("-c", "--clobber-output", action="store_true",
                     help="delete an existing output folder instead of renaming it")
    out.add_argument("-n", "--no-clean", action="store_true",
                     help="reuse an existing output folder (incremental builds)")
    out.add_argument("-v", "--verbose", action="count", default=0, help="more output (-vv: debug)")
    out.add_argument("-i", "--inline-logs", action="store_true", help="print the log of each failure")
    out.add_argument("--list-tests", action="store_true", help="list the test cases of the selected scenarios and exit")
    out.add_argument("--list-tags", action="store_true", help="list the tags of the discovered scenarios and exit")
    out.add_argument("-y", "--dry-run", action="store_true", help="write testplan.json, build nothing")

    p.add_argument("--run-plan", metavar="PLAN", help=argparse.SUPPRESS)  # inside the vcan VM
    return p


def split_image_args(argv: list[str]) -> tuple[list[str], list[str]]:
    if "--" in argv:
        i = argv.index("--")
        return argv[:i], argv[i + 1 :]
    return argv, []


def _is_twister_outdir(path: Path) -> bool:
    return any((path / f).exists() for f in ("twister.json", "testplan.json", "twister.xml")) or not any(path.iterdir())


def prepare_outdir(outdir: Path, clobber: bool, keep: bool) -> None:
    """Move an old output folder aside (Zephyr: twister-out.1, .2, ...) or delete it (-c)."""
    if outdir.exists() and not keep:
        if not outdir.is_dir() or not _is_twister_outdir(outdir):
            raise PlanError(f"{outdir} exists and is not a twister output folder; choose another -O")
        if clobber:
            shutil.rmtree(outdir)
        else:
            n = 1
            while Path(f"{outdir}.{n}").exists():
                n += 1
            outdir.rename(f"{outdir}.{n}")
    outdir.mkdir(parents=True, exist_ok=True)


def _options_for_report(args) -> dict:
    d = {}
    for key, value in vars(args).items():
        if key == "run_plan":
            continue
        d[key] = str(value) if isinstance(value, Path) else value
    return d


def _sigterm(signum, frame):
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    argv, image_args = split_image_args(argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    log.verbosity = args.verbose

    if args.run_plan:
        return vm.run_plan(args.run_plan)
    if args.jobs < 1:
        parser.error("-j must be at least 1")

    start = time.monotonic()
    roots = [Path(r) for r in args.testsuite_root] or [
        r for r in (REPO_ROOT / "tests", REPO_ROOT / "samples") if r.is_dir()
    ]
    for r in roots:
        if not r.exists():
            log.error(f"-T {r}: no such folder")
            return 2
    board_roots = [Path(b) for b in args.board_root] or [REPO_ROOT / "boards"]
    disp = lambda p: display_path(p, REPO_ROOT)  # noqa: E731

    platforms, errors = load_platforms(board_roots, disp)
    scenarios, scenario_errors = discover(roots, REPO_ROOT)
    errors += scenario_errors
    for err in errors:
        log.error(str(err))

    try:
        scenarios = select_scenarios(scenarios, args.scenario)
    except PlanError as e:
        log.error(str(e))
        return 2

    if args.list_tags:
        tags = sorted({t for sc in scenarios for t in sc.tags})
        log.raw("\n".join(f" - {t}" for t in tags) + f"\n{len(tags)} total.")
        return 1 if errors else 0
    if args.list_tests:
        names = []
        for sc in scenarios:
            if args.tag and not set(sc.tags) & set(args.tag) or set(sc.tags) & set(args.exclude_tag):
                continue
            names += [f"{sc.id}.{c}" for c in sc.cases] if sc.harness == "ztest" and sc.cases else [sc.id]
        log.raw("\n".join(f" - {n}" for n in names) + f"\n{len(names)} total.")
        return 1 if errors else 0

    wanted = (("ASAN", args.enable_asan), ("UBSAN", args.enable_ubsan), ("TSAN", args.enable_tsan))
    sanitizers = [name for name, on in wanted if on]
    conflict = sanitizer_conflict(command_line_sanitizers(sanitizers, args.extra_args))
    if conflict:
        log.error(f"{conflict}: the command line asks for both")
        return 2
    sel = Selection(
        platforms=args.platform,
        all_platforms=args.all,
        integration=args.integration,
        tags=args.tag,
        exclude_tags=args.exclude_tag,
        enable_slow=args.enable_slow,
        build_only=args.build_only,
        sanitizers=sanitizers,
        extra_args=args.extra_args,
    )
    outdir = args.outdir
    try:
        instances = make_plan(scenarios, platforms, sel, outdir.resolve())
        prepare_outdir(outdir, args.clobber_output, keep=args.no_clean or args.test_only or args.dry_run)
    except PlanError as e:
        log.error(str(e))
        return 2
    outdir = outdir.resolve()
    report_dir = (args.report_dir or outdir).resolve()
    report_dir.mkdir(parents=True, exist_ok=True)
    by_file: dict[str, list] = {}
    for err in errors:
        by_file.setdefault(err.file, []).append(err)
    instances = [TestInstance.for_config_errors(errs) for errs in by_file.values()] + instances
    report.write_testplan(report_dir / "testplan.json", instances)

    pipeline = [i for i in instances if i.status is None]
    log.info(
        f"{len(scenarios)} scenario(s), {len(instances) - len(by_file)} instance(s): {len(pipeline)} to build"
        f"{'' if args.build_only else ' and run'}, {len(instances) - len(by_file) - len(pipeline)} filtered or skipped"
    )
    if args.dry_run:
        log.info(f"dry run: {report_dir / 'testplan.json'}")
        return 1 if errors else 0

    opts = RunOptions(
        base=REPO_ROOT,
        outdir=outdir,
        jobs=args.jobs,
        build=BuildOptions(base=REPO_ROOT, extra_args=args.extra_args, sanitizers=sanitizers),
        fixtures={f.split(":", 1)[0] for f in args.fixture},
        timeout_multiplier=args.timeout_multiplier,
        seed=args.seed,
        image_args=image_args,
        test_only=args.test_only,
        inline_logs=args.inline_logs,
        retry_failed=args.retry_failed,
        vcan_vm=args.vcan_vm.resolve(),
        verbose=args.verbose,
    )
    old_term = signal.signal(signal.SIGTERM, _sigterm)
    runner = Runner(instances, opts)
    try:
        runner.run()
    finally:
        signal.signal(signal.SIGTERM, old_term)

    run_id = uuid.uuid4().hex
    env = report.environment(REPO_ROOT, _options_for_report(args))
    report.write_json(report_dir / "twister.json", instances, env, run_id)
    report.write_junit(report_dir / "twister.xml", instances)
    report.print_summary(instances, time.monotonic() - start)
    log.info(f"reports: {report_dir / 'twister.json'}, {report_dir / 'twister.xml'}")
    c = report.count_line(report.counts(instances))
    log.raw(c)
    if runner.interrupted or handler.REGISTRY.interrupted.is_set():
        return 130
    return 1 if any(i.status in st.FAILING for i in instances) else 0
