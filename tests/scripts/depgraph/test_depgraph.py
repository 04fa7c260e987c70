# SPDX-License-Identifier: Apache-2.0
"""scripts/depgraph on small object files compiled here, laid out as CMake lays them out."""

import importlib.machinery
import importlib.util
import os
import shutil
import subprocess
import sys

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPT = os.path.join(BASE, "scripts", "depgraph")

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("nm") is None,
                                reason="needs gcc and nm")


def load():
    loader = importlib.machinery.SourceFileLoader("safeline_depgraph", SCRIPT)
    spec = importlib.util.spec_from_loader("safeline_depgraph", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


depgraph = load()


def compile_into(build, files, tree="subsys/canopen"):
    """Compile {"dir/x.c": source} to <build>/zephyr/<tree>/dir/CMakeFiles/<t>.dir/x.c.o."""
    src_dir = build.parent / (build.name + "-src")
    for rel, text in files.items():
        folder, name = os.path.split(rel)
        src = src_dir / rel
        src.parent.mkdir(parents=True, exist_ok=True)
        src.write_text(text)
        target = "canopen_" + (folder or "top")
        obj_dir = build / "zephyr" / tree / folder / "CMakeFiles" / f"{target}.dir"
        obj_dir.mkdir(parents=True, exist_ok=True)
        subprocess.run(["gcc", "-c", "-O0", "-o", str(obj_dir / (name + ".o")), str(src)],
                       check=True)
    return build


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args)], capture_output=True,
                          text=True)


# a.c calls b, b.c calls c, c.c calls a: one circle. d.c calls a from outside it.
RING = {
    "p/a.c": "int b(void);\nint a(void) { return b() + 1; }\n",
    "q/b.c": "int c(void);\nint b(void) { return c() + 1; }\n",
    "q/c.c": "int a(void);\nint c(void) { return a() + 1; }\n",
    "d.c": "int a(void);\nint d(void) { return a(); }\n",
}

# a.c -> b.c -> c.c, and a.c -> c.c: no circle.
CHAIN = {
    "a.c": "int b(void);\nint c(void);\nint a(void) { return b() + c(); }\n",
    "b.c": "int c(void);\nint b(void) { return c() + 1; }\n",
    "c.c": "int c(void) { return 1; }\n",
}


@pytest.fixture
def ring(tmp_path):
    return compile_into(tmp_path / "ring", RING)


@pytest.fixture
def chain(tmp_path):
    return compile_into(tmp_path / "chain", CHAIN)


def test_ring_edges_and_circle(ring):
    r = run(ring)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == [
        "d.c -> p/a.c",
        "p/a.c -> q/b.c",
        "q/b.c -> q/c.c",
        "q/c.c -> p/a.c",
        "circle: p/a.c -> q/b.c -> q/c.c -> p/a.c",
    ]


def test_symbols_behind_edges(ring):
    r = run(ring, "--symbols")
    assert "p/a.c -> q/b.c: b" in r.stdout.splitlines()


def test_fail_on_any_cycle(ring, chain):
    r = run(ring, "--fail-on-any-cycle")
    assert r.returncode == 1
    assert "1 circle(s)" in r.stderr
    assert run(chain, "--fail-on-any-cycle").returncode == 0


def test_fail_on_cycle_through(ring):
    r = run(ring, "--fail-on-cycle-through", "q/c.c")
    assert r.returncode == 1
    assert "q/c.c is on the circle of p/a.c, q/b.c, q/c.c" in r.stderr
    # d.c depends on the circle but is not on it.
    assert run(ring, "--fail-on-cycle-through", "d.c").returncode == 0
    # Repeatable: one path on a circle is enough.
    assert run(ring, "--fail-on-cycle-through", "d.c",
               "--fail-on-cycle-through", "p/a.c").returncode == 1


def test_unknown_path_is_a_warning(ring):
    r = run(ring, "--fail-on-cycle-through", "core/nodee.c")
    assert r.returncode == 0
    assert "core/nodee.c is not in the graph" in r.stderr


def test_acyclic_graph(chain):
    r = run(chain)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["a.c -> b.c", "a.c -> c.c", "b.c -> c.c"]
    assert run(chain, "--fail-on-cycle-through", "a.c").returncode == 0


def test_dot_output(ring, tmp_path):
    dot = tmp_path / "g.dot"
    r = run(ring, "--dot", dot)
    assert r.returncode == 0, r.stderr
    text = dot.read_text()
    assert text.startswith("//") and "digraph depgraph {" in text
    assert '"p/a.c" -> "q/b.c" [tooltip="b", color=red];' in text
    assert '"d.c" -> "p/a.c" [tooltip="a"];' in text
    assert 'subgraph "cluster_q"' in text
    # The text report is still printed.
    assert "circle: p/a.c -> q/b.c -> q/c.c -> p/a.c" in r.stdout
    r = run(ring, "--dot", "-")
    assert r.stdout.startswith("//") and "circle:" not in r.stdout


def test_static_symbols_and_objects_outside_the_tree_make_no_edges(tmp_path):
    build = compile_into(tmp_path / "build", {
        "a.c": "int helper(void);\nint k_thing(void);\n"
               "int a(void) { return helper() + k_thing(); }\n",
        "b.c": "static int helper(void) { return 2; }\nint b(void) { return helper(); }\n",
        "c.c": "int helper(void) { return 3; }\n",
    })
    # The kernel is not part of the graph, even though a.c uses it.
    compile_into(build, {"k.c": "int k_thing(void) { return 4; }\n"}, tree="kernel/posix")
    r = run(build)
    assert r.stdout.splitlines() == ["a.c -> c.c"]


def test_bad_options():
    r = run("--no-such-option", ".")
    assert r.returncode == 2
    assert "usage: depgraph" in r.stderr and "unrecognized arguments" in r.stderr
    r = run()
    assert r.returncode == 2
    assert "usage: depgraph" in r.stderr and "BUILD_DIR" in r.stderr
    r = run(".", "--fail-on-cycle-through")
    assert r.returncode == 2 and "expected one argument" in r.stderr


def test_missing_or_empty_build_dir(tmp_path):
    r = run(tmp_path / "nonesuch")
    assert r.returncode == 2 and "not a directory" in r.stderr
    r = run(tmp_path)
    assert r.returncode == 2 and "no object files of subsys/canopen" in r.stderr


@pytest.mark.parametrize("obj,src", [
    ("zephyr/safeline/subsys/canopen/core/CMakeFiles/canopen_core.dir/node.c.o", "core/node.c"),
    ("zephyr/safeline/subsys/canopen/CMakeFiles/canopen.dir/x/y.c.o", "x/y.c"),
    ("CMakeFiles/app.dir/path/to/safeline/subsys/canopen/pdo/pdo.c.o", "pdo/pdo.c"),
    ("zephyr/safeline/kernel/posix/CMakeFiles/kernel.dir/sched.c.o", None),
    ("CMakeFiles/app.dir/src/main.c.o", None),
])
def test_object_path_maps_to_source(obj, src):
    assert depgraph.source_of(obj, "subsys/canopen") == src


def test_tarjan_finds_every_component():
    nodes = ["a", "b", "c", "d", "e", "f", "g"]
    edges = {("a", "b"): [], ("b", "a"): [], ("b", "c"): [], ("c", "d"): [], ("d", "e"): [],
             ("e", "c"): [], ("f", "f"): [], ("g", "a"): []}
    adj = depgraph.adjacency(nodes, edges)
    comps = depgraph.strongly_connected(nodes, adj)
    assert comps == [["c", "d", "e"], ["a", "b"], ["f"], ["g"]]
    # A component that is not a simple ring: the walk passes the hub more than once.
    hub = {("h", "x"): [], ("x", "h"): [], ("h", "y"): [], ("y", "h"): []}
    adj = depgraph.adjacency(["h", "x", "y"], hub)
    assert depgraph.closed_walk(adj, ["h", "x", "y"]) == ["h", "x", "h", "y", "h"]


def test_deep_chain_needs_no_recursion():
    n = 5000
    nodes = [f"n{i:05d}" for i in range(n)]
    edges = {(nodes[i], nodes[i + 1]): [] for i in range(n - 1)}
    edges[(nodes[-1], nodes[0])] = []
    comps = depgraph.strongly_connected(nodes, depgraph.adjacency(nodes, edges))
    assert len(comps) == 1 and len(comps[0]) == n
