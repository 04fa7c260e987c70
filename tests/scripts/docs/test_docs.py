# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""The documentation holds together: every relative link of the README, doc/ and the samples'
READMEs names a file that exists, and every page of doc/ can be reached from
doc/architecture.md (where a user who clones the repository starts) by following links."""

import glob
import os
import re

import pytest

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
DOC = os.path.join(BASE, "doc")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def pages():
    found = sorted(glob.glob(os.path.join(DOC, "**", "*.md"), recursive=True))
    found += sorted(glob.glob(os.path.join(BASE, "samples", "**", "README.md"), recursive=True))
    return [os.path.join(BASE, "README.md")] + found


def local_links(path):
    """The relative link targets of a page (code blocks and code spans left out), as paths."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    for m in LINK.finditer(text):
        target = m.group(1)
        if re.match(r"[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue
        yield target, os.path.normpath(os.path.join(os.path.dirname(path),
                                                    target.split("#")[0]))


@pytest.mark.parametrize("page", pages(), ids=lambda p: os.path.relpath(p, BASE))
def test_every_relative_link_names_an_existing_file(page):
    missing = [t for t, p in local_links(page) if not os.path.exists(p)]
    assert not missing, f"{os.path.relpath(page, BASE)}: links to nothing: {missing}"


def test_every_doc_page_is_reachable_from_the_architecture_page():
    seen = set()
    todo = [os.path.join(DOC, "architecture.md")]
    while todo:
        p = todo.pop()
        if p in seen or not p.endswith(".md") or not os.path.isfile(p):
            continue
        seen.add(p)
        todo += [target for _, target in local_links(p)]
    every = set(glob.glob(os.path.join(DOC, "**", "*.md"), recursive=True))
    unreached = sorted(os.path.relpath(p, BASE) for p in every - seen)
    assert not unreached, f"no link path from doc/architecture.md to {unreached}"


def test_the_readme_points_to_the_architecture_page():
    targets = {p for _, p in local_links(os.path.join(BASE, "README.md"))}
    assert os.path.join(DOC, "architecture.md") in targets
