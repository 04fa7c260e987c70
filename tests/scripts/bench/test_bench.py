# SPDX-License-Identifier: Apache-2.0
"""scripts/bench: figure lines, discovery and the callgrind total, without building anything."""

import importlib.machinery
import importlib.util
import json
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


# --- The one table and the one JSON file -------------------------------------------------------

def test_judge_says_missed_only_against_a_target():
    assert bench.judge(96.5, (">=", 97)) == "missed"
    assert bench.judge(97.0, (">=", 97)) == "ok"
    assert bench.judge(301, ("<=", 300)) == "missed"
    assert bench.judge(300, ("<=", 300)) == "ok"
    assert bench.judge(5, None) == ""
    assert bench.judge(None, ("<=", 1)) == ""
    assert bench.judge(True, ("<=", 1)) == ""


FOOTPRINT = {"configurations": [
    {"name": "minimal", "title": "minimal slave",
     "stack": {"code": 30000, "ram": 1500, "ram_with_dictionary_and_stacks": 4000}},
    {"name": "full", "title": "full slave",
     "stack": {"code": 54000, "ram": 14000, "ram_with_dictionary_and_stacks": 19000}},
]}


def test_footprint_configurations_become_figures():
    figs = bench.footprint_figures(FOOTPRINT)
    assert [f["name"] for f in figs] == ["footprint.minimal", "footprint.full"]
    assert figs[0]["code"] == 30000 and figs[0]["ram"] == 1500
    assert bench.footprint_figures(None) == []


def rows_of(doc, figure, key):
    return [r for r in doc["summary"] if r["figure"] == figure and r["key"] == key]


def test_assemble_puts_targets_beside_figures_and_lists_the_missed():
    figs = [
        {"name": "pdo.rpdo_rx", "ns_per_op": 500.0, "instr_per_op": 981.0, "bench": "x"},
        {"name": "sdo.block_download", "efficiency_pct": 98.1, "efficiency_no_stall_pct": 99.0,
         "bytes_per_s": 59000},
        {"name": "sdo.block_upload", "efficiency_pct": 90.0, "efficiency_no_stall_pct": 97.5,
         "bytes_per_s": 54000},
        {"name": "scale.lines_255", "rss_mb": 10.0, "hwm_mb": 70.5,
         "cpu_us_per_line_per_s": 1500.0},
    ]
    doc = bench.assemble(figs, FOOTPRINT, {"callgrind": True})
    rpdo = rows_of(doc, "pdo.rpdo_rx", "instr_per_op")[0]
    assert (rpdo["value"], rpdo["target"], rpdo["status"]) == (981.0, "<= 300", "missed")
    assert rpdo["canopennode"].startswith("325")
    assert rows_of(doc, "pdo.rpdo_rx", "ns_per_op")[0]["status"] == ""
    assert rows_of(doc, "sdo.block_download", "efficiency_pct")[0]["status"] == "ok"
    up = rows_of(doc, "sdo.block_upload", "efficiency_pct")[0]
    assert up["status"] == "missed" and up["what"].startswith("block upload")
    assert rows_of(doc, "scale.lines_255", "rss_mb")[0]["status"] == "ok"
    assert rows_of(doc, "scale.lines_255", "hwm_mb")[0]["status"] == "missed"
    # Footprint rows come from scripts/footprint's JSON, with the targets.
    code = rows_of(doc, "footprint.minimal", "code")[0]
    assert (code["target"], code["status"]) == ("<= 12288", "missed")
    assert rows_of(doc, "footprint.minimal", "ram")[0]["status"] == "ok"
    assert rows_of(doc, "footprint.full", "code")[0]["status"] == ""
    assert doc["missed"] == ["footprint.minimal:code", "pdo.rpdo_rx:instr_per_op",
                             "scale.lines_255:hwm_mb", "sdo.block_upload:efficiency_pct"]
    # Every figure as measured, the footprint and where it was measured are kept.
    assert doc["figures"] == figs and doc["footprint"] == FOOTPRINT
    assert doc["callgrind"] is True and doc["machine"]["cores"] >= 1 and doc["date"]


def test_a_figure_no_headline_knows_still_gets_a_row():
    doc = bench.assemble([{"name": "lss.fastscan_new", "ops": 3, "scan_us": 812.5, "x": "y"}])
    assert [(r["figure"], r["key"], r["value"], r["status"]) for r in doc["summary"]] == [
        ("lss.fastscan_new", "scan_us", 812.5, "")]
    assert "footprint" not in doc and doc["missed"] == []


def test_table_has_one_row_per_summary_row_with_target_and_missed():
    doc = bench.assemble([{"name": "pdo.sync_3tpdo", "instr_per_op": 1200.0,
                           "ns_per_op": 900.5}])
    text = bench.format_table(doc["summary"])
    lines = text.splitlines()
    assert lines[0].split()[:3] == ["what", "value", "unit"]
    assert set(lines[1]) <= {"-", " "}
    assert len(lines) == 2 + len(doc["summary"]) == 4
    row = next(line for line in lines if "instructions per SYNC" in line)
    assert "1,200" in row and "<= 900" in row and "missed" in row and "984" in row


def test_table_option_reprints_a_written_file(tmp_path, capsys, monkeypatch):
    doc = bench.assemble([{"name": "sdo.block_download", "efficiency_pct": 96.0}])
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(doc))
    monkeypatch.setattr("sys.argv", ["bench", "--table", str(path)])
    bench.main()
    out = capsys.readouterr().out
    assert "share of the wire bound" in out and "missed" in out


def test_pytest_benchmarks_are_told_apart_and_their_json_is_read(tmp_path, monkeypatch):
    src = tmp_path / "bench"
    src.mkdir()
    (src / "testcase.yaml").write_text("tests:\n  a.bench:\n    harness: pytest\n")
    assert bench.harness(str(src)) == "pytest"
    assert bench.harness(os.path.join(BASE, "tests", "canopen", "pdo", "bench")) == "console"
    out = tmp_path / "out"

    def fake_run(cmd, timeout):
        d = out / "native_posix" / "a.bench"
        d.mkdir(parents=True)
        (d / "handler.log").write_text('BENCH {"name": "b.one", "v": 1}\n')
        (d / "bench-b.json").write_text(json.dumps([{"name": "b.one", "v": 9},
                                                    {"name": "b.two", "v": 2}]))
        return 0, ""

    monkeypatch.setattr(bench, "run", fake_run)
    figs = bench.pytest_bench(str(src), str(out), 10)
    assert figs == [{"name": "b.one", "v": 1}, {"name": "b.two", "v": 2}]


def test_a_vcan_benchmark_runs_in_the_vm_and_others_do_not(tmp_path, monkeypatch):
    cmds = []
    monkeypatch.setattr(bench, "run", lambda cmd, timeout: (cmds.append(cmd), (0, ""))[1])
    for name, fixture in (("plain", ""), ("vm", "    harness_config:\n      fixture: vcan\n")):
        src = tmp_path / name / "bench"
        src.mkdir(parents=True)
        (src / "testcase.yaml").write_text(f"tests:\n  a.bench:\n    harness: pytest\n{fixture}")
        bench.pytest_bench(str(src), str(tmp_path / name / "out"), 10)
    assert "-X" not in cmds[0]
    assert cmds[1][cmds[1].index("-X") + 1] == "vcan"
