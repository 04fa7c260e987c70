# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""doc/architecture.md's list of direct calls between services ("Dependencies") is true of
the sources: each listed function is called in the caller's file and defined in the
callee's. (That no unlisted call exists is read from object files, scripts/depgraph.)"""

import os
import re

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
TREE = os.path.join(BASE, "subsys", "canopen")
PAGE = os.path.join(BASE, "doc", "architecture.md")
ROW = re.compile(r"^\| `([a-z_/]+\.c)` \| `([a-z_/]+\.c)` \| ((?:`co_\w+`(?:, )?)+) \|")


def calls_table():
    with open(PAGE, encoding="utf-8") as f:
        text = f.read()
    section = text.split("## Dependencies", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in section.splitlines():
        m = ROW.match(line)
        if m:
            rows.append((m.group(1), m.group(2), re.findall(r"`(co_\w+)`", m.group(3))))
    return rows


def source(rel):
    with open(os.path.join(TREE, rel), encoding="utf-8") as f:
        # Comments out: a function named in a comment is no call.
        return re.sub(r"/\*.*?\*/|//[^\n]*", "", f.read(), flags=re.S)


def caller_source(rel):
    """The caller's file and its folder's own headers, whose inline helpers it compiles in
    (mgr/mgr_internal.h's co_mgr_cli() calls co_sdo_cli_get())."""
    folder = os.path.dirname(os.path.join(TREE, rel))
    headers = sorted(h for h in os.listdir(folder) if h.endswith(".h"))
    return source(rel) + "".join(source(os.path.join(os.path.dirname(rel), h)) for h in headers)


def defines(text, fn):
    """A definition starts at the line's start (return type first) and is no declaration."""
    return re.search(r"^[A-Za-z_][\w \*]*\b" + fn + r"\([^;]*?\)\s*\{", text, re.M) is not None


def test_the_table_lists_the_calls_between_services():
    rows = calls_table()
    assert len(rows) >= 10, "the table under 'Dependencies' is gone or unreadable"
    callers = {r[0].split("/")[0] for r in rows}
    assert {"emcy", "pdo", "redundancy", "mgr", "bridge"} <= callers


@pytest.mark.parametrize("caller,callee,fns", calls_table(),
                         ids=lambda v: v if isinstance(v, str) else ",".join(v))
def test_each_listed_call_is_in_the_sources(caller, callee, fns):
    assert caller.split("/")[0] != callee.split("/")[0], "a call inside one folder"
    caller_text, callee_text = caller_source(caller), source(callee)
    for fn in fns:
        assert re.search(r"\b" + fn + r"\(", caller_text), f"{caller} does not call {fn}()"
        assert defines(callee_text, fn), f"{callee} does not define {fn}()"


def test_the_definition_check_tells_a_definition_from_a_declaration():
    text = "int f(int a);\nstatic bool g(void)\n{\n}\nvoid co_x(struct a *b,\n\t  int c)\n{\n}\n"
    assert not defines(text, "f") and defines(text, "g") and defines(text, "co_x")
