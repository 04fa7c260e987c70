# SPDX-License-Identifier: Apache-2.0
"""scripts/bench: figure lines, discovery, the callgrind total, the configurations of the PDO
benchmark, the scale runs and the table (targets, "missed", "missing"), without building
anything but Kconfig merges."""

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


def test_callgrind_toggles_the_collected_function_and_each_excluded_one(monkeypatch):
    cmds = []

    def fake_run(cmd, timeout):
        cmds.append(cmd)
        out = next(a for a in cmd if a.startswith("--callgrind-out-file="))
        with open(out.split("=", 1)[1], "w") as f:
            f.write("summary: 10\n")
        return 0, ""

    monkeypatch.setattr(bench, "run", fake_run)
    assert bench.callgrind_ir("img", ["--x"], "loop", 10, ["can_send"]) == 10
    assert [a for a in cmds[0] if a.startswith("--toggle")] == [
        "--toggle-collect=loop", "--toggle-collect=can_send"]
    assert cmds[0][-2:] == ["img", "--x"]


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
        {"name": "pdo.native.rpdo_rx", "ns_per_op": 500.0, "instr_per_op": 981.0, "bench": "x"},
        {"name": "sdo.block_download", "efficiency_pct": 98.1, "efficiency_no_stall_pct": 99.0,
         "bytes_per_s": 59000},
        {"name": "sdo.block_upload", "efficiency_pct": 90.0, "efficiency_no_stall_pct": 97.5,
         "bytes_per_s": 54000},
        {"name": "scale.lines_255", "rss_mb": 10.0, "hwm_mb": 70.5,
         "cpu_us_per_line_per_s": 1500.0},
    ]
    doc = bench.assemble(figs, FOOTPRINT, {"callgrind": True})
    rpdo = rows_of(doc, "pdo.native.rpdo_rx", "instr_per_op")[0]
    assert (rpdo["value"], rpdo["target"], rpdo["status"]) == (981.0, "<= 300", "missed")
    assert rpdo["canopennode"].startswith("325") and rpdo["what"].endswith("(native)")
    assert rows_of(doc, "pdo.native.rpdo_rx", "ns_per_op")[0]["status"] == ""
    assert rows_of(doc, "sdo.block_download", "efficiency_pct")[0]["status"] == "ok"
    up = rows_of(doc, "sdo.block_upload", "efficiency_pct")[0]
    assert up["status"] == "missed" and up["what"].startswith("block upload")
    assert rows_of(doc, "scale.lines_255", "rss_mb")[0]["status"] == "ok"
    assert rows_of(doc, "scale.lines_255", "hwm_mb")[0]["status"] == "missed"
    # Footprint rows come from scripts/footprint's JSON, with the targets.
    code = rows_of(doc, "footprint.minimal", "code")[0]
    assert (code["target"], code["status"], code["canopennode"]) == ("<= 12288", "missed",
                                                                     "11 308")
    ram = rows_of(doc, "footprint.minimal", "ram")[0]
    assert (ram["target"], ram["status"], ram["canopennode"]) == ("<= 4364", "ok", "4 364")
    assert rows_of(doc, "footprint.full", "code")[0]["status"] == ""
    assert doc["missed"] == ["footprint.minimal:code", "pdo.native.rpdo_rx:instr_per_op",
                             "scale.lines_255:hwm_mb", "sdo.block_upload:efficiency_pct"]
    assert doc["missing"] == []
    # Every figure as measured, the footprint and where it was measured are kept.
    assert doc["figures"] == figs and doc["footprint"] == FOOTPRINT
    assert doc["callgrind"] is True and doc["machine"]["cores"] >= 1 and doc["date"]


def test_a_figure_no_headline_knows_still_gets_a_row():
    doc = bench.assemble([{"name": "lss.fastscan_new", "ops": 3, "scan_us": 812.5, "x": "y"}])
    assert [(r["figure"], r["key"], r["value"], r["status"]) for r in doc["summary"]] == [
        ("lss.fastscan_new", "scan_us", 812.5, "")]
    assert "footprint" not in doc and doc["missed"] == []


def test_table_has_one_row_per_summary_row_with_target_and_missed():
    doc = bench.assemble([{"name": "pdo.minimal.sync_3tpdo", "instr_per_op": 1200.0,
                           "ns_per_op": 900.5}])
    text = bench.format_table(doc["summary"])
    lines = text.splitlines()
    assert lines[0].split()[:3] == ["what", "value", "unit"]
    assert set(lines[1]) <= {"-", " "}
    assert len(lines) == 2 + len(doc["summary"]) == 4
    row = next(line for line in lines if "instructions per SYNC" in line)
    assert "1,200" in row and "<= 900" in row and "missed" in row and "984" in row
    assert "(minimal)" in row


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


# --- The configurations of the PDO benchmark ----------------------------------------------------

def test_the_footprint_configurations_become_cortex_m4_fragments(tmp_path):
    configs = bench.pdo_configurations(str(tmp_path))
    assert [c["name"] for c in configs] == ["native", "minimal", "default"]
    native, minimal, default = configs
    assert native["fragment"] is None and native["m4"] is None
    assert minimal["source"] == "scripts/footprint.d/minimal.conf"
    assert default["source"] == "samples/canopen/hello_node/prj.conf"
    for cfg in (minimal, default):
        assert "error" not in cfg
        with open(cfg["fragment"]) as f:
            lines = f.read().splitlines()
        # Every CONFIG_CANOPEN_* a fragment can set, as the Cortex-M4 merge resolved it ...
        for line in lines:
            if line.startswith("CONFIG_CANOPEN_") and "LOCK_CHECK" not in line:
                name, value = line.split("=", 1)
                assert cfg["m4"][name] == value.strip('"')
        # ... then the production settings, last.
        assert lines[-2:] == ["CONFIG_LOG=n", "CONFIG_CANOPEN_LOCK_CHECK=n"]
    # The minimal slave's queue sizes stay as its fragment has them; the default slave's are
    # the Cortex-M4 defaults, not the native board's.
    with open(minimal["fragment"]) as f:
        text = f.read()
    assert "CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE=8\n" in text
    assert "CONFIG_CANOPEN_LINE_TX_QUEUE_SIZE=8\n" in text
    assert default["m4"]["CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE"] == "16"
    with open(default["fragment"]) as f:
        assert "CONFIG_CANOPEN_LINE_RX_QUEUE_SIZE=16\n" in f.read()


def test_a_fragment_leaves_out_what_no_fragment_can_set():
    text = bench.fragment_text({"CONFIG_CANOPEN_A": "y", "CONFIG_CANOPEN_B": "n",
                                "CONFIG_CANOPEN_C": "12", "CONFIG_CANOPEN_D": "name",
                                "CONFIG_CANOPEN_HIDDEN": "y", "CONFIG_OTHER": "y",
                                "CONFIG_CANOPEN_LOCK_CHECK": "y"},
                               {"CANOPEN_A", "CANOPEN_B", "CANOPEN_C", "CANOPEN_D",
                                "CANOPEN_LOCK_CHECK", "OTHER"}, "title")
    body = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert body == ["CONFIG_CANOPEN_A=y", "CONFIG_CANOPEN_B=n", "CONFIG_CANOPEN_C=12",
                    'CONFIG_CANOPEN_D="name"', "CONFIG_LOG=n", "CONFIG_CANOPEN_LOCK_CHECK=n"]


def test_a_host_build_that_differs_from_the_cortex_m4_is_said_so():
    m4 = {"CONFIG_CANOPEN_X": "y", "CONFIG_CANOPEN_N": "16", "CONFIG_CANOPEN_LOCK_CHECK": "n",
          "CONFIG_CANOPEN_OFF": "n"}
    built = {"CONFIG_CANOPEN_X": "y", "CONFIG_CANOPEN_N": "160",
             "CONFIG_CANOPEN_LOCK_CHECK": "n"}
    assert bench.differences(m4, built) == ["CONFIG_CANOPEN_N: 16 -> 160"]
    text = bench.describe_configurations([
        {"name": "native", "title": "the native board's defaults", "source": "prj.conf",
         "kconfig": None},
        {"name": "minimal", "title": "the footprint's minimal slave", "source": "min.conf",
         "kconfig": m4, "differences": ["CONFIG_CANOPEN_N: 16 -> 160"]},
        {"name": "default", "title": "the footprint's default slave", "source": "def.conf",
         "kconfig": m4, "error": "building failed"}])
    assert "CONFIG_LOG=n, CONFIG_CANOPEN_LOCK_CHECK=n" in text
    assert "differs from the Cortex-M4 build: CONFIG_CANOPEN_N: 16 -> 160" in text
    assert "not measured: building failed" in text


COST_OUTPUT = "\n".join([
    'BENCH {"name": "pdo.rpdo_rx", "ops": 1, "ns_per_op": 10.0, "collect": "r", '
    '"total_ops": 100}',
    'BENCH {"name": "pdo.rpdo_rx_masked", "ops": 1, "ns_per_op": 11.0, "collect": "m", '
    '"total_ops": 100}',
    '{40}',
    'BENCH {"name": "pdo.sync_3tpdo", "ops": 1, "ns_per_op": 30.0, "collect": "s", '
    '"collect_exclude": ["can_send"], "total_ops": 100}',
])
MORE_OK = ('BENCH {"name": "pdo.rpdo_rx_40_more", "ops": 1, "ns_per_op": 10.0, "collect": "x", '
           '"total_ops": 100}')
MORE_FULL = 'BENCH {"name": "pdo.rpdo_rx_40_more", "error": "-28 after 7 of 40", "registered": 7}'


def fake_pdo(monkeypatch, tmp_path, more_fits):
    """pdo_bench() with the builds, runs and callgrind replaced: returns the builds made."""
    frag = tmp_path / "minimal.conf"
    frag.write_text("CONFIG_CANOPEN_LINE_RX_SLOTS=16\nCONFIG_LOG=n\n")
    configs = [{"name": "native", "title": "n", "source": "prj.conf", "fragment": None,
                "m4": None},
               {"name": "minimal", "title": "m", "source": "min.conf", "fragment": str(frag),
                "m4": {"CONFIG_CANOPEN_LINE_RX_SLOTS": "16"}},
               {"name": "default", "title": "d", "source": "def.conf",
                "error": "Kconfig failed", "fragment": None, "m4": None}]
    builds = []
    monkeypatch.setattr(bench, "pdo_configurations", lambda outdir: configs)

    def fake_build(src, out, extra_conf=None):
        builds.append((os.path.basename(out), extra_conf))
        os.makedirs(os.path.join(out, "zephyr"), exist_ok=True)
        slots = "64" if extra_conf and "_rx64" in extra_conf else "16"
        with open(os.path.join(out, "zephyr", ".config"), "w") as f:
            f.write(f"CONFIG_CANOPEN_LINE_RX_SLOTS={slots}\n")
        return os.path.join(out, slots)

    def fake_image(image, args, timeout, rel):
        fits = more_fits or image.endswith("64")
        return COST_OUTPUT.replace("{40}", MORE_OK if fits else MORE_FULL)

    # Instructions: r 200, m 212 (RPDO, masked), x 205 or 230 with 64 slots, s 700.
    cost = {"r": 20000, "m": 21200, "x": 20500, "s": 70000}

    def fake_cg(image, args, function, timeout, exclude=()):
        if function == "x" and image.endswith("64"):
            return 23000
        if function == "r" and image.endswith("64"):
            return 22000
        return cost[function]

    monkeypatch.setattr(bench, "build", fake_build)
    monkeypatch.setattr(bench, "run_image", fake_image)
    monkeypatch.setattr(bench, "callgrind_ir", fake_cg)
    return builds


def test_each_configuration_is_built_with_its_fragment_and_named_in_its_figures(
        monkeypatch, tmp_path):
    builds = fake_pdo(monkeypatch, tmp_path, more_fits=True)
    figs, configs = bench.pdo_bench("src", str(tmp_path), True, 10, log=lambda s: None)
    assert builds == [("pdo_native", None), ("pdo_minimal", str(tmp_path / "minimal.conf"))]
    by = {f["name"]: f for f in figs}
    assert set(by) == {f"pdo.{c}.{n}" for c in ("native", "minimal")
                       for n in ("rpdo_rx", "rpdo_rx_masked", "rpdo_rx_40_more", "sync_3tpdo")}
    assert by["pdo.minimal.rpdo_rx"]["instr_per_op"] == 200.0
    assert by["pdo.minimal.rpdo_rx_masked"]["extra_instr_per_op"] == 12.0
    assert by["pdo.minimal.rpdo_rx_40_more"]["extra_instr_per_op"] == 5.0
    assert by["pdo.native.sync_3tpdo"]["configuration"] == "native"
    assert [c["name"] for c in configs] == ["native", "minimal", "default"]
    assert configs[2]["error"] == "Kconfig failed" and "m4" not in configs[1]
    # A configuration that failed is reported missing, not left out of the table.
    doc = bench.assemble(figs, expected=bench.expected_figures(
        pdo_configs=[c["name"] for c in configs]))
    assert doc["missing"] == [f"pdo.default.{n}" for n in (
        "rpdo_rx:instr_per_op", "sync_3tpdo:instr_per_op",
        "rpdo_rx_40_more:extra_instr_per_op", "rpdo_rx_masked:extra_instr_per_op")]
    assert doc["missed"] == ["pdo.minimal.rpdo_rx_masked:extra_instr_per_op",
                             "pdo.native.rpdo_rx_masked:extra_instr_per_op"]


def test_40_more_receivers_that_do_not_fit_are_measured_with_more_slots(monkeypatch, tmp_path):
    builds = fake_pdo(monkeypatch, tmp_path, more_fits=False)
    figs, configs = bench.pdo_bench("src", str(tmp_path), True, 10, log=lambda s: None)
    assert [b[0] for b in builds] == ["pdo_native", "pdo_minimal", "pdo_minimal_rx64"]
    with open(builds[2][1]) as f:
        text = f.read()
    assert text.count("CONFIG_CANOPEN_LINE_RX_SLOTS") == 1
    assert "CONFIG_CANOPEN_LINE_RX_SLOTS=64\n" in text and "CONFIG_LOG=n\n" in text
    by = {f["name"]: f for f in figs}
    more = by["pdo.minimal.rpdo_rx_40_more"]
    # Over the RPDO of the build with 64 slots (220), not of the configuration's own (200).
    assert (more["instr_per_op"], more["extra_instr_per_op"], more["rx_slots"]) == (
        230.0, 10.0, 64)
    assert by["pdo.minimal.rpdo_rx"]["instr_per_op"] == 200.0
    # The native build has no fragment to add slots to: its figure stays an error.
    assert "error" in by["pdo.native.rpdo_rx_40_more"]
    doc = bench.assemble(figs, expected=bench.expected_figures(pdo_configs=["native"]))
    assert "pdo.native.rpdo_rx_40_more:extra_instr_per_op" in doc["missing"]
    row = rows_of(doc, "pdo.native.rpdo_rx_40_more", "extra_instr_per_op")[0]
    assert row["value"] is None and row["target"] == "<= 5"
    line = next(ln for ln in bench.format_table(doc["summary"]).splitlines()
                if "more than without them (native)" in ln)
    assert " - " in line and "missing" in line


def test_build_passes_the_fragment_as_extra_conf_file(monkeypatch, tmp_path):
    cmds = []

    class Done:
        returncode = 0
        stdout = ""

    monkeypatch.setattr(bench.subprocess, "run", lambda cmd, **kw: (cmds.append(cmd), Done)[1])
    assert bench.build("src", str(tmp_path), "/x/bench.conf").endswith("zephyr.exe")
    assert "-DEXTRA_CONF_FILE=/x/bench.conf" in cmds[0] and "-DBOARD=native_posix" in cmds[0]
    bench.build("src", str(tmp_path))
    assert not any(a.startswith("-DEXTRA_CONF_FILE") for a in cmds[2])


# --- The scale benchmark --------------------------------------------------------------------------

def test_scale_runs_16_64_and_255_lines_and_prints_the_ratio(monkeypatch, tmp_path):
    runs = []
    monkeypatch.setattr(bench, "build", lambda src, out, extra_conf=None: "img")

    def fake_image(image, args, timeout, rel):
        runs.append(args)
        n = int(args[0].split("=")[1])
        return (f'BENCH {{"name": "scale.lines_{n}", "lines": {n}, "rss_mb": {n / 4}, '
                f'"cpu_us_per_line_per_s": {100.0 + n * 2}}}\n')

    monkeypatch.setattr(bench, "run_image", fake_image)
    figs = bench.scale_bench("src", str(tmp_path), 10, log=lambda s: None)
    assert runs == [["--lines=16"], ["--lines=64"], ["--lines=255"]]
    ratio = figs[-1]
    assert ratio["name"] == "scale.cpu_per_line_255_vs_16" and ratio["ratio"] == 4.62
    doc = bench.assemble(figs, expected=bench.expected_figures(scale=True))
    assert rows_of(doc, "scale.cpu_per_line_255_vs_16", "ratio")[0]["status"] == "missed"
    assert rows_of(doc, "scale.lines_255", "rss_mb")[0]["status"] == "ok"
    assert rows_of(doc, "scale.lines_16", "rss_mb")[0]["target"] == ""
    assert doc["missing"] == []
    # Without the 16-line run there is no ratio: both are reported missing.
    doc = bench.assemble(figs[1:3] + bench.scale_ratio(figs[1:3]),
                         expected=bench.expected_figures(scale=True))
    assert doc["missing"] == ["scale.lines_16:cpu_us_per_line_per_s", "scale.lines_16:rss_mb",
                              "scale.cpu_per_line_255_vs_16:ratio"]


def test_footprint_figures_are_expected_when_it_runs():
    doc = bench.assemble([], FOOTPRINT, expected=bench.expected_figures(footprint=True))
    assert doc["missing"] == ["footprint.default:code", "footprint.default:ram"]
    row = rows_of(doc, "footprint.default", "code")[0]
    assert (row["target"], row["canopennode"]) == ("<= 15360", "14 594 (+524 guarding)")
