"""The `vcan` fixture: instances that need real SocketCAN run inside scripts/vcan-vm.

The host has no AF_CAN, so after every instance is built on the host, all `fixture: vcan`
instances of the run go to ONE VM:

    scripts/vcan-vm [-v] --ifaces vcan0,...,vcanN --share <outdir> --timeout S -- \\
        python3 scripts/twister --run-plan <outdir>/vcan-plan.json

The plan is a JSON list of RunSpecs (execution.py). Each instance gets interfaces of its own
(`can_lines` of them, default 1): images get `--can-if=<line>:<iface>`, pytest scenarios
SAFELINE_CAN_IFACES. Inside the VM, `--run-plan` runs the instances one after the other (timing
in the VM is noisy enough without them competing), writes each result into its build folder and
prints a marker line that the host turns into a progress line at once.

If the VM cannot start (exit 75, or scripts/vcan-vm missing), every instance of the batch is
"skipped" with the VM's reason; an instance the VM did not finish is an "error".
"""

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from . import handler, log
from . import statuses as st
from .execution import RESULT_FILE, RunResult, RunSpec, execute

EX_CANNOT_START = 75
RESULT_MARK = "@@twister-result "
TWISTER_SCRIPT = Path(__file__).resolve().parents[3] / "twister"
BOOT_ALLOWANCE_S = 120  # boot and shutdown, on top of the instances' own timeouts
VM_TERM_GRACE_S = 15.0


def assign_ifaces(can_lines: list[int]) -> list[list[str]]:
    """vcan0.. handed out in order: [1, 2, 1] -> [[vcan0], [vcan1, vcan2], [vcan3]]."""
    out, n = [], 0
    for count in can_lines:
        out.append([f"vcan{n + k}" for k in range(count)])
        n += count
    return out


def shares_needed(outdir: Path, specs: list[RunSpec]) -> list[Path]:
    """Folders the VM must see besides the project root (which vcan-vm always shares): the
    output folder, and scenario folders outside the project (pytest reads its tests there)."""
    root = TWISTER_SCRIPT.parents[1]
    shares = [Path(outdir)]
    for spec in specs:
        src = Path(spec.source_dir)
        if not src.is_relative_to(root) and not any(src.is_relative_to(s) for s in shares):
            shares.append(src)
    return shares


def write_plan(path: Path, specs: list[RunSpec]) -> None:
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"version": 1, "instances": [s.to_dict() for s in specs]}, f, indent=1)


def run_plan(plan_path: str) -> int:
    """Inside the VM: run every instance of the plan, report each as it finishes."""
    with open(plan_path, encoding="utf-8") as f:
        plan = json.load(f)
    for d in plan["instances"]:
        spec = RunSpec.from_dict(d)
        log.info(f"VM: running {spec.name} (ifaces {spec.env.get('SAFELINE_CAN_IFACES', '-')})")
        try:
            result = execute(spec)
        except Exception as e:  # one broken instance must not lose the others' results
            result = RunResult(st.ERROR, f"runner error in the VM: {e}", 0.0)
        data = result.to_dict()
        (Path(spec.build_dir) / RESULT_FILE).write_text(json.dumps(data), encoding="utf-8")
        sys.stdout.write(RESULT_MARK + json.dumps({"name": spec.name, "result": data}) + "\n")
        sys.stdout.flush()
    return 0


def _cannot_start_reason(stderr_lines: list[str], rc: int) -> str:
    for line in stderr_lines:
        if "cannot start VM" in line:
            return line.strip()
    tail = stderr_lines[-1].strip() if stderr_lines else f"exit {rc}"
    return f"vcan-vm: cannot start VM: {tail}"


def run_batch(batch, vcan_vm: Path, outdir: Path, verbose: bool, on_result) -> None:
    """Run [(instance, RunSpec)] in one VM. `on_result(instance, RunResult)` per instance."""
    outdir = Path(outdir).resolve()
    by_name = {spec.name: (inst, spec) for inst, spec in batch}
    pending = dict(by_name)
    for _, spec in batch:
        (Path(spec.build_dir) / RESULT_FILE).unlink(missing_ok=True)

    def finish_all(status: str, reason: str) -> None:
        for name in list(pending):
            inst, spec = pending.pop(name)
            on_result(inst, RunResult(status, reason, 0.0))

    if not (vcan_vm.is_file() and os.access(vcan_vm, os.X_OK)):
        finish_all(st.SKIPPED, f"vcan-vm: cannot start VM: {vcan_vm} not found")
        return

    plan_path = outdir / "vcan-plan.json"
    write_plan(plan_path, [spec for _, spec in batch])
    ifaces = [i for _, spec in batch for i in spec.env["SAFELINE_CAN_IFACES"].split(",")]
    total_timeout = int(sum(spec.timeout + handler.EXIT_GRACE_S for _, spec in batch) + BOOT_ALLOWANCE_S)
    cmd = [str(vcan_vm)]
    if verbose:
        cmd.append("-v")
    cmd += ["--ifaces", ",".join(ifaces)]
    for share in shares_needed(outdir, [spec for _, spec in batch]):
        cmd += ["--share", str(share)]
    cmd += [
        "--timeout",
        str(total_timeout),
        "--",
        sys.executable,
        str(TWISTER_SCRIPT),
        "--run-plan",
        str(plan_path),
    ]
    log.info(f"vcan: running {len(batch)} instance(s) in one VM ({', '.join(ifaces)})")
    log.verbose(f"$ {' '.join(cmd)}")
    vm_log = open(outdir / "vcan-vm.log", "a", encoding="utf-8")
    vm_log.write(f"$ {' '.join(cmd)}\n")
    lock = threading.Lock()
    stderr_lines: list[str] = []
    start = time.monotonic()
    try:
        # vcan-vm's SIGTERM trap tears the VM down (UML runs in a session of its own): let it.
        proc = handler.popen(
            cmd,
            term_grace=VM_TERM_GRACE_S,
            cwd=outdir,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
    except OSError as e:
        vm_log.close()
        finish_all(st.SKIPPED, f"vcan-vm: cannot start VM: {e}")
        return

    def read_stderr():
        for raw in iter(proc.stderr.readline, b""):
            line = raw.decode("utf-8", "replace").rstrip("\n")
            with lock:
                stderr_lines.append(line)
                vm_log.write(f"[stderr] {line}\n")
                vm_log.flush()
            if verbose:  # vcan-vm -v: the boot-to-command time and the run's timings
                log.info(line)

    err_thread = threading.Thread(target=read_stderr, daemon=True)
    err_thread.start()
    # Backstop only: vcan-vm enforces --timeout itself.
    watchdog = threading.Timer(total_timeout + 60, handler.terminate_group, args=(proc, VM_TERM_GRACE_S))
    watchdog.daemon = True
    watchdog.start()
    try:
        for raw in iter(proc.stdout.readline, b""):
            line = raw.decode("utf-8", "replace").rstrip("\r\n")
            with lock:
                vm_log.write(line + "\n")
                vm_log.flush()
            if line.startswith(RESULT_MARK):
                try:
                    msg = json.loads(line[len(RESULT_MARK) :])
                    item = pending.pop(msg["name"], None)
                except (ValueError, KeyError):
                    continue
                if item:
                    on_result(item[0], RunResult.from_dict(msg["result"]))
            elif verbose:
                log.raw(f"    {line}")
        proc.wait()
    finally:
        watchdog.cancel()
        if proc.poll() is None:
            handler.terminate_group(proc, grace=VM_TERM_GRACE_S)
        rc = proc.wait()
        err_thread.join(timeout=5.0)
        handler.REGISTRY.remove(proc)
        vm_log.write(f"exit {rc} after {time.monotonic() - start:.1f} s\n")
        vm_log.close()

    # A marker line lost on the way still left its result file behind.
    for name in list(pending):
        inst, spec = pending[name]
        path = Path(spec.build_dir) / RESULT_FILE
        if path.is_file():
            try:
                result = RunResult.from_dict(json.loads(path.read_text(encoding="utf-8")))
            except (ValueError, KeyError):
                continue
            pending.pop(name)
            on_result(inst, result)
    if not pending:
        return
    if handler.REGISTRY.interrupted.is_set():
        finish_all(st.SKIPPED, "interrupted")
    elif rc == EX_CANNOT_START:
        finish_all(st.SKIPPED, _cannot_start_reason(stderr_lines, rc))
    else:
        last = stderr_lines[-1].strip() if stderr_lines else ""
        finish_all(st.ERROR, f"the VM ended (exit {rc}) before this instance finished{': ' + last if last else ''}")
