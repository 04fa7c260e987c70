# SPDX-License-Identifier: Apache-2.0
"""The stack's file dependencies, read from this build's objects by scripts/depgraph: the
node core is in no circle (services reach it, it reaches them only through the list of
canopen/services.h, i.e. core/services.c)."""

import os
import pathlib
import re
import subprocess
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
BASE = pathlib.Path(os.environ.get("SAFELINE_BASE") or HERE.parents[4])


@pytest.fixture(scope="session")
def build_dir(tmp_path_factory):
    image = os.environ.get("SAFELINE_IMAGE")
    if image:
        # <build>/zephyr/zephyr.exe
        return pathlib.Path(image).parents[1]
    build = tmp_path_factory.mktemp("build") / "deps"
    env = dict(os.environ, SAFELINE_BASE=str(BASE))
    subprocess.run(["cmake", "-G", "Ninja", "-S", str(HERE.parent), "-B", str(build)],
                   check=True, env=env, stdout=subprocess.DEVNULL)
    subprocess.run(["ninja", "-C", str(build)], check=True, env=env, stdout=subprocess.DEVNULL)
    return build


def depgraph(build_dir, *args):
    return subprocess.run([sys.executable, str(BASE / "scripts" / "depgraph"), str(build_dir),
                           *args], capture_output=True, text=True)


def test_every_service_is_in_the_graph(build_dir):
    out = depgraph(build_dir).stdout
    for f in ("core/node.c", "core/services.c", "nmt/errctl.c", "emcy/emcy.c", "sync/sync.c",
              "time/time.c", "pdo/pdo.c", "sdo/sdo_srv.c", "sdo/sdo_cli.c", "mgr/mgr.c",
              "mgr/cfg.c"):
        assert f in out, f"{f} missing from the graph:\n{out}"


def test_no_circle_through_the_node_core(build_dir):
    r = depgraph(build_dir, "--fail-on-cycle-through", "core/node.c",
                 "--fail-on-cycle-through", "core/services.c")
    assert r.returncode == 0, r.stdout + r.stderr


def test_services_do_not_call_each_other_in_circles(build_dir):
    """A circle may stay inside one service's folder (e.g. pdo/), never across folders."""
    out = depgraph(build_dir).stdout
    for line in out.splitlines():
        m = re.match(r"circle: (.*)", line)
        if m:
            folders = {p.split("/")[0] for p in m.group(1).split(" -> ")}
            assert len(folders) == 1, line


def test_the_core_calls_no_service(build_dir):
    out = depgraph(build_dir).stdout
    for line in out.splitlines():
        m = re.match(r"\s*(core/node\.c) -> (\S+)", line)
        if m:
            assert m.group(2).startswith(("core/", "od/")), line
