# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""What the repository carries holds on any machine: no tracked file names the folder it was
checked out in (a development machine's path in a doc or a test breaks on every other), and
the LICENSE file is the licence every file's SPDX tag names."""

import os
import re
import subprocess

BASE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))

# Parents too general to be a machine's own: their paths appear in docs on purpose
# (/tmp/dg-build), and "/" is in every path.
GENERAL_PARENTS = {"/", "/tmp", "/var/tmp", "/home", "/Users", "/opt", "/srv", "/usr/src"}

# Split so that this line is not a tag itself.
SPDX = re.compile(rb"SPDX-License-" rb"Identifier: ([^\s*]+)")


def git(*args):
    return subprocess.run(["git", "-C", BASE] + list(args), capture_output=True, text=True,
                          check=True).stdout


def tracked_files():
    return [f for f in git("ls-files", "-z").split("\0") if f]


def checkout_paths():
    """The checkout's own folder and its parent, spelt as given and with links resolved; in a
    linked worktree the main checkout's too, whose paths the branch's files came from."""
    roots = {git("rev-parse", "--show-toplevel").strip()}
    common = git("rev-parse", "--path-format=absolute", "--git-common-dir").strip()
    if os.path.basename(common) == ".git":
        roots.add(os.path.dirname(common))
    paths = set()
    for root in roots:
        for p in (root, os.path.realpath(root)):
            paths.add(p)
            parent = os.path.dirname(p)
            if parent not in GENERAL_PARENTS:
                paths.add(parent + "/")
    return sorted(paths, key=len, reverse=True)


def is_binary(data):
    # git's own test: a NUL byte in the first 8000 bytes.
    return b"\0" in data[:8000]


def find_machine_paths(base, files, paths):
    """(file, line number, path) for every line of a text file under base that contains one of
    paths."""
    found = []
    needles = [p.encode() for p in paths]
    for name in files:
        full = os.path.join(base, name)
        if not os.path.isfile(full) or os.path.islink(full):
            continue
        with open(full, "rb") as f:
            data = f.read()
        if is_binary(data) or not any(n in data for n in needles):
            continue
        for no, line in enumerate(data.splitlines(), 1):
            for n in needles:
                if n in line:
                    found.append((name, no, n.decode()))
                    break
    return found


def test_no_tracked_file_contains_the_checkouts_path():
    paths = checkout_paths()
    found = find_machine_paths(BASE, tracked_files(), paths)
    assert not found, "machine paths in tracked files (write $PWD, $SAFELINE_BASE or a " \
        "relative path instead):\n" + "\n".join(f"  {f}:{n}: {p}" for f, n, p in found)


def test_the_path_check_finds_a_path_and_skips_binary_files(tmp_path):
    (tmp_path / "doc.md").write_text("run\ncd /srv/build/safeline && make\n")
    (tmp_path / "parent.txt").write_text("see /srv/build/other\n")
    (tmp_path / "ok.txt").write_text("$S/work and /srv/builder are not it\n")
    (tmp_path / "blob.bin").write_bytes(b"\0/srv/build/safeline")
    files = ["doc.md", "parent.txt", "ok.txt", "blob.bin"]
    paths = ["/srv/build/safeline", "/srv/build/"]
    assert find_machine_paths(str(tmp_path), files, paths) == [
        ("doc.md", 2, "/srv/build/safeline"), ("parent.txt", 1, "/srv/build/")]


def test_the_checkout_and_its_parent_are_searched():
    paths = checkout_paths()
    assert BASE in paths or os.path.realpath(BASE) in paths
    parent = os.path.dirname(BASE)
    if parent not in GENERAL_PARENTS:
        assert parent + "/" in paths


def test_every_spdx_tag_names_the_licence_of_the_license_file():
    tags = {}
    for name in tracked_files():
        full = os.path.join(BASE, name)
        if not os.path.isfile(full):
            continue
        with open(full, "rb") as f:
            data = f.read()
        if is_binary(data):
            continue
        for m in SPDX.finditer(data):
            tags.setdefault(m.group(1).decode(), []).append(name)
    assert "Apache-2.0" in tags
    others = {t: files[:3] for t, files in tags.items() if t != "Apache-2.0"}
    assert not others, f"SPDX tags other than Apache-2.0, which LICENSE holds: {others}"
    with open(os.path.join(BASE, "LICENSE"), encoding="utf-8") as f:
        text = f.read()
    assert "Apache License" in text and "Version 2.0, January 2004" in text
    assert "END OF TERMS AND CONDITIONS" in text
    assert "LICENSE" in tracked_files()
