# SPDX-License-Identifier: Apache-2.0
"""scripts/bench: figure lines, discovery and the callgrind total, without building anything."""

import importlib.machinery
import importlib.util
import os
import stat

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def load():
    path = os.path.join(BASE, "scripts", "bench")
    loader = importlib.machinery.SourceFileLoader("safeline_bench", path)
    spec = importlib.util.spec_from_loader("safeline_bench", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


bench = load()


def test_only_bench_lines_become_figures():
    out = "\n".join([
        "*** Booting SafeLine on native_posix ***",
        'BENCH {"name": "a.b", "ops": 10, "ns_per_op": 1.5}',
        "BENCH not json",
        'noise BENCH {"name": "x"}',
        'BENCH {"name": "c.d", "p50_us": 3}  ',
    ])
    assert bench.figures(out) == [{"name": "a.b", "ops": 10, "ns_per_op": 1.5},
                                  {"name": "c.d", "p50_us": 3}]


def test_discovery_finds_the_pdo_benchmark_and_refuses_unknown_folders():
    found = [os.path.relpath(d, BASE) for d in bench.discover([])]
    assert os.path.join("tests", "canopen", "pdo", "bench") in found
    assert bench.discover(["tests/canopen/pdo"]) == [os.path.join(BASE, "tests", "canopen",
                                                                  "pdo", "bench")]
    with pytest.raises(SystemExit, match="no benchmark under tests/nowhere"):
        bench.discover(["tests/nowhere"])


def test_callgrind_total_is_read_from_the_output_file(tmp_path, monkeypatch):
    # A stand-in for valgrind that writes a callgrind file with a known total.
    fake = tmp_path / "valgrind"
    fake.write_text("#!/bin/sh\nfor a; do case $a in --callgrind-out-file=*) "
                    "f=${a#--callgrind-out-file=};; esac; done\n"
                    "printf 'events: Ir\\nsummary: 123456\\n' > \"$f\"\n")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PATH", f"{tmp_path}:{os.environ['PATH']}")
    assert bench.callgrind_ir("/bin/true", [], "f", 10) == 123456
