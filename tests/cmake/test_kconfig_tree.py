# SPDX-License-Identifier: Apache-2.0
"""Lint of the Kconfig tree itself, parsed with kconfiglib as the build parses it.

- Every symbol and choice has help text (on at least one of its definitions: a board's
  Kconfig.defconfig only changes a default and needs none).
- No `select` of a symbol that has a prompt: a user-visible option is reached with
  `depends on` (or `imply`), so that it cannot be forced on behind the user's back.

The tree is the root Kconfig for every board, plus every application's own Kconfig file
under tests/ and samples/ (which sources Kconfig.safeline).
"""

import os
from pathlib import Path

import kconfiglib
import pytest

BASE = Path(__file__).resolve().parents[2]

BOARD_DIRS = sorted(p.parent for p in BASE.glob("boards/*/*/Kconfig.board"))

APP_KCONFIGS = sorted(
    p for top in ("tests", "samples") for p in (BASE / top).rglob("Kconfig")
    # The runner's fixture trees are not SafeLine applications.
    if "scripts" not in p.relative_to(BASE).parts)


def load(monkeypatch, root, board_dir):
    """kconfiglib.Kconfig(root) with the environment cmake/kconfig.cmake sets."""
    monkeypatch.setenv("srctree", str(BASE))
    monkeypatch.setenv("SAFELINE_BASE", str(BASE))
    monkeypatch.setenv("BOARD", board_dir.name)
    monkeypatch.setenv("BOARD_DIR", str(board_dir))
    monkeypatch.setenv("APPLICATION_SOURCE_DIR", str(Path(root).parent))
    monkeypatch.delenv("KCONFIG_CONFIG", raising=False)
    kconf = kconfiglib.Kconfig(str(root), warn_to_stderr=False)
    assert kconf.warnings == []
    return kconf


def items(kconf):
    """Every symbol and choice with its definition nodes."""
    found = {}
    for node in kconf.node_iter():
        if isinstance(node.item, (kconfiglib.Symbol, kconfiglib.Choice)):
            found.setdefault(node.item, []).append(node)
    return found


def where(nodes):
    """file:line of each definition, relative to the tree where kconfiglib gives it so."""
    def rel(path):
        return os.path.relpath(path, BASE) if os.path.isabs(path) else path

    return ", ".join(f"{rel(n.filename)}:{n.linenr}" for n in nodes)


def roots():
    params = []
    for board_dir in BOARD_DIRS:
        params.append(pytest.param(BASE / "Kconfig", board_dir, id=f"Kconfig-{board_dir.name}"))
    for app in APP_KCONFIGS:
        params.append(pytest.param(app, BOARD_DIRS[0], id=str(app.relative_to(BASE))))
    return params


ROOTS = roots()


def test_the_tree_has_boards_and_the_stack(monkeypatch):
    assert BOARD_DIRS, "no boards/*/*/Kconfig.board"
    kconf = load(monkeypatch, BASE / "Kconfig", BOARD_DIRS[0])
    for name in ("CAN", "CANOPEN", "CANOPEN_OD", "LOG", "ZTEST", "PRINTK"):
        assert name in kconf.syms and kconf.syms[name].nodes, name


@pytest.mark.parametrize("root,board_dir", ROOTS)
def test_every_symbol_and_choice_has_help(monkeypatch, root, board_dir):
    kconf = load(monkeypatch, root, board_dir)
    missing = []
    for item, nodes in items(kconf).items():
        if not any(n.help and n.help.strip() for n in nodes):
            name = item.name or "<choice " + (nodes[0].prompt[0] if nodes[0].prompt else "?") + ">"
            missing.append(f"{name} ({where(nodes)})")
    assert missing == [], "options without help text:\n  " + "\n  ".join(sorted(missing))


@pytest.mark.parametrize("root,board_dir", ROOTS)
def test_no_select_of_a_prompted_symbol(monkeypatch, root, board_dir):
    kconf = load(monkeypatch, root, board_dir)
    bad = []
    for sym in kconf.unique_defined_syms:
        for target, _cond in sym.selects:
            prompted = [n for n in target.nodes if n.prompt]
            if prompted:
                bad.append(f"{sym.name} ({where(sym.nodes)}) selects {target.name}, which has a "
                           f"prompt ({where(prompted)}): use 'depends on' or 'imply'")
    assert bad == [], "\n".join(bad)
