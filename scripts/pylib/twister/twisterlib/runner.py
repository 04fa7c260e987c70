"""The pipeline: build, filter, run and judge every planned instance, -j at a time.

Each worker takes one instance through configure -> runtime filter -> build -> run. Instances
with `fixture: vcan` are built first and stop after the build; as soon as the last of them is
built they run together in one VM (vm.py), in a thread of their own, while the workers go on
with the host instances (the VM's run is mostly waiting on the bus, so the two overlap
well). A progress line is printed as each instance finishes.
"""

import os
import shutil
import signal
import threading
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from . import build, expr, handler, log, vm
from . import statuses as st
from .build import BuildOptions
from .execution import RunResult, RunSpec, execute
from .instance import TestInstance

VCAN_FIXTURE = "vcan"
LOG_EXCERPT_BYTES = 64 * 1024


@dataclass
class RunOptions:
    base: Path
    outdir: Path
    jobs: int
    build: BuildOptions
    fixtures: set = field(default_factory=set)
    timeout_multiplier: float = 1.0
    seed: int | None = None
    image_args: list = field(default_factory=list)
    test_only: bool = False
    inline_logs: bool = False
    retry_failed: int = 0
    vcan_vm: Path | None = None
    verbose: int = 0


def _read_tail(path: Path, limit: int = LOG_EXCERPT_BYTES) -> str:
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - limit))
            data = f.read()
    except OSError:
        return ""
    text = data.decode("utf-8", "replace")
    return text if size <= limit else "[...]\n" + text


class Runner:
    def __init__(self, instances: list[TestInstance], opts: RunOptions):
        self.instances = instances
        self.opts = opts
        self.lock = threading.Lock()
        self.done = 0
        self.total = 0
        self.vcan_queue: list[TestInstance] = []
        # vcan instances still on their way through the build (the VM starts at 0).
        self.vcan_pending = 0
        self.vcan_thread: threading.Thread | None = None
        self.interrupted = False
        # Set by SIGINT/SIGTERM during run(). The handler only sets it: a KeyboardInterrupt
        # raised inside concurrent.futures.wait() can leave a future's lock taken, and the
        # worker that then completes that future blocks forever (so did the run).
        self.stop_requested = threading.Event()

    # --- progress -----------------------------------------------------------------------------

    def _finish(self, inst: TestInstance) -> None:
        """An instance has its final status: print its progress line."""
        if inst.status in st.FAILING and inst.log_file is not None:
            inst.log = _read_tail(inst.log_file)
        with self.lock:
            self.done += 1
            n = self.done
        status = inst.status.upper()
        reason = f" ({inst.reason})" if inst.reason and inst.status != st.PASSED else ""
        seconds = inst.build_time + inst.execution_time
        log.info(f"{n}/{self.total} {inst.platform_id} {inst.scenario_id} {status}{reason} ({seconds:.2f}s)")
        if self.opts.inline_logs and inst.status in st.FAILING and inst.log_file is not None:
            what = inst.log_file.name
            text = _read_tail(inst.log_file, 16 * 1024).rstrip("\n")
            log.raw(f"---- {what} of {inst.name} ----\n{text}\n---- end of {what} ----")

    # --- one instance -------------------------------------------------------------------------

    def make_spec(self, inst: TestInstance, ifaces: list[str] | None = None) -> RunSpec:
        sc, plat = inst.scenario, inst.platform
        timeout = sc.timeout * self.opts.timeout_multiplier * plat.timeout_multiplier
        args, env = [], {}
        seed = self.opts.seed if self.opts.seed is not None else sc.get("seed")
        if seed is not None:
            args.append(f"--seed={seed}")
        if ifaces:
            args += [f"--can-if={line}:{name}" for line, name in enumerate(ifaces)]
            env["SAFELINE_CAN_IFACES"] = ",".join(ifaces)
        args += self.opts.image_args
        return RunSpec(
            name=inst.name,
            scenario=sc.id,
            source_dir=str(sc.source_dir.resolve()),
            build_dir=str(inst.build_dir.resolve()),
            harness=sc.harness,
            harness_config=dict(sc.harness_config),
            timeout=timeout,
            expected_cases=list(sc.cases) if sc.harness == "ztest" else [],
            image_args=args,
            env=env,
            ignore_faults=bool(sc.get("ignore_faults")),
            base=str(self.opts.base),
            emulator=plat.emulator or "",
        )

    def apply_result(self, inst: TestInstance, result: RunResult) -> None:
        inst.set_status(result.status, result.reason)
        inst.execution_time = result.execution_time
        if result.testcases or inst.scenario.harness != "ztest":
            inst.testcases = result.testcases
        inst.recording = result.recording
        inst.log_file = inst.build_dir / "handler.log"
        inst.fill_cases(st.BLOCKED if result.status in st.FAILING else result.status, result.reason)

    def _fail_build(self, inst: TestInstance, what: str) -> None:
        inst.set_status(st.FAILED, "build failure")
        inst.log_file = inst.build_dir / "build.log"
        inst.fill_cases(st.BLOCKED, f"build failure ({what})")

    def _runtime_filter(self, inst: TestInstance) -> bool:
        """Evaluate `filter:` on the .config; False when the instance is done (filtered/error)."""
        sc = inst.scenario
        if sc.filter_tree is None:
            return True
        path = build.dotconfig_path(inst.build_dir)
        try:
            env = build.read_dotconfig(path)
        except OSError:
            inst.set_status(st.ERROR, f"filter needs {path}, which CMake did not write")
            inst.fill_cases(st.BLOCKED, inst.reason)
            return False
        plat = inst.platform
        env.update({"ARCH": plat.arch, "BOARD": plat.identifier, "PLATFORM": plat.identifier})
        try:
            keep = expr.evaluate(sc.filter_tree, env)
        except expr.FilterError as e:
            inst.set_status(st.ERROR, f"filter: {e}")
            return False
        if not keep:
            inst.set_status(st.FILTERED, f"filter: {sc.filter}")
            inst.fill_cases(st.FILTERED, inst.reason)
            return False
        return True

    def process(self, inst: TestInstance) -> None:
        """Take one instance through the pipeline (worker thread)."""
        queued = False
        try:
            queued = not self._process(inst)
        except Exception as e:  # a runner bug must not hang or hide the rest of the run
            inst.set_status(st.ERROR, f"runner error: {e!r}")
        if not queued:
            if handler.REGISTRY.interrupted.is_set() and inst.status not in (st.PASSED,
                                                                             st.FILTERED):
                inst.set_status(st.SKIPPED, "interrupted")
            self._finish(inst)
        if self._wants_vm(inst):
            self._vcan_built()

    def _wants_vm(self, inst: TestInstance) -> bool:
        return inst.scenario.fixture == VCAN_FIXTURE and VCAN_FIXTURE in self.opts.fixtures

    def _vcan_built(self) -> None:
        """One more vcan instance is through its build (queued or done): start the VM batch
        when it was the last."""
        with self.lock:
            self.vcan_pending -= 1
            start = self.vcan_pending == 0 and bool(self.vcan_queue)
            todo = sorted(self.vcan_queue, key=lambda i: i.name) if start else []
        if start and not handler.REGISTRY.interrupted.is_set():
            self.vcan_thread = threading.Thread(target=self._run_vcan, args=(todo,),
                                                name="vcan-vm", daemon=True)
            self.vcan_thread.start()

    def _process(self, inst: TestInstance) -> bool:
        interrupted = handler.REGISTRY.interrupted
        sc = inst.scenario
        if interrupted.is_set():
            inst.set_status(st.SKIPPED, "interrupted")
            return True
        if not self.opts.test_only:
            log.verbose(f"building {inst.name}")
            if not build.configure(inst, self.opts.build):
                self._fail_build(inst, "cmake")
                return True
            if not self._runtime_filter(inst):
                return True
            if not build.build(inst, self.opts.build):
                self._fail_build(inst, "build")
                return True
        elif not self._runtime_filter(inst):
            return True
        if inst.build_only:
            inst.set_status(st.PASSED, "build only")
            inst.fill_cases(st.SKIPPED, "build only")
            return True
        fixture = sc.fixture
        if fixture and fixture not in self.opts.fixtures:
            inst.set_status(st.SKIPPED, f"fixture {fixture} not available")
            inst.fill_cases(st.SKIPPED, inst.reason)
            return True
        emulator = inst.platform.emulator
        if emulator and shutil.which(emulator) is None:
            # Built (so it cannot rot), not run: like a missing fixture, never a failure.
            inst.set_status(st.SKIPPED, f"emulator {emulator} not found")
            inst.fill_cases(st.SKIPPED, inst.reason)
            return True
        if fixture == VCAN_FIXTURE:
            with self.lock:
                self.vcan_queue.append(inst)
            return False
        log.verbose(f"running {inst.name}")
        self.apply_result(inst, execute(self.make_spec(inst)))
        return True

    # --- the whole run ------------------------------------------------------------------------

    def _run_pool(self, todo: list[TestInstance], work) -> None:
        with ThreadPoolExecutor(max_workers=max(1, self.opts.jobs)) as pool:
            futures = {pool.submit(work, inst) for inst in todo}
            while futures:
                if self.stop_requested.is_set():
                    self.interrupt()
                    for f in futures:
                        f.cancel()
                    raise KeyboardInterrupt
                _, futures = wait(futures, timeout=0.5, return_when=FIRST_COMPLETED)

    def _run_vcan(self, todo: list[TestInstance]) -> None:
        lines = [inst.scenario.can_lines for inst in todo]
        batch = [(inst, self.make_spec(inst, ifaces)) for inst, ifaces in zip(todo, vm.assign_ifaces(lines))]

        def on_result(inst, result):
            self.apply_result(inst, result)
            self._finish(inst)

        vm.run_batch(batch, self.opts.vcan_vm, self.opts.outdir, self.opts.verbose > 0, on_result)

    def interrupt(self) -> None:
        if not self.interrupted:
            self.interrupted = True
            log.warning("interrupted: stopping every child process")
        handler.REGISTRY.kill_all()

    def _on_signal(self, signum, frame) -> None:
        self.stop_requested.set()
        # Kill the children from another thread: the main thread may be inside the registry's
        # lock (a vcan retry batch runs on it), which the handler must not take again.
        threading.Thread(target=self.interrupt, name="interrupt", daemon=True).start()

    def run(self) -> None:
        """Run every instance; SIGINT and SIGTERM stop the run (children killed, rest skipped)."""
        old = {sig: signal.signal(sig, self._on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            self._run()
        finally:
            for sig, h in old.items():
                signal.signal(sig, h)

    def _run(self) -> None:
        todo = [i for i in self.instances if i.status is None]
        self.total = len(todo)
        n_cpu = os.cpu_count() or 1
        parallel = max(1, min(self.opts.jobs, len(todo)))
        if self.opts.build.ninja_jobs is None:
            self.opts.build.ninja_jobs = max(1, n_cpu // parallel)
        # The VM's instances first, so their batch can start while the host ones build.
        todo.sort(key=lambda i: not self._wants_vm(i))
        self.vcan_pending = sum(1 for i in todo if self._wants_vm(i))
        try:
            self._run_pool(todo, self.process)
            if self.vcan_thread is not None:
                while self.vcan_thread.is_alive():
                    if self.stop_requested.is_set():
                        raise KeyboardInterrupt
                    self.vcan_thread.join(timeout=0.5)
            for attempt in range(1, self.opts.retry_failed + 1):
                if self.stop_requested.is_set():
                    raise KeyboardInterrupt
                if handler.REGISTRY.interrupted.is_set():
                    break
                again = [i for i in todo if i.status in st.FAILING and i.reason != "build failure"]
                if not again:
                    break
                log.info(f"retry {attempt} of {self.opts.retry_failed}: {len(again)} failed instance(s)")
                self.done, self.total = 0, len(again)
                for inst in again:
                    inst.retries += 1
                    inst.init_cases()
                host = [i for i in again if i.scenario.fixture != VCAN_FIXTURE]
                self.vcan_queue = []
                self._run_pool(host, self._rerun)
                vcan = [i for i in again if i.scenario.fixture == VCAN_FIXTURE]
                if vcan:
                    self._run_vcan(vcan)
        except KeyboardInterrupt:
            self.interrupt()
        for inst in self.instances:
            if inst.status is None:
                inst.set_status(st.SKIPPED, "interrupted")
                inst.fill_cases(st.SKIPPED, "interrupted")

    def _rerun(self, inst: TestInstance) -> None:
        self.apply_result(inst, execute(self.make_spec(inst)))
        self._finish(inst)


def default_jobs() -> int:
    return os.cpu_count() or 1
