# Copyright (c) 2026 SafeLine contributors
# SPDX-License-Identifier: Apache-2.0
"""Other projects' EDS/DCF files (third_party/, SOURCES.md): the ones CiA 306 allows are
accepted and their generated C compiles; the others are refused for what the stack cannot do
(doc/eds2od.md lists the results)."""

import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
TP = os.path.join(HERE, "third_party")
EDS2OD = os.path.join(BASE, "scripts", "eds2od")

ACCEPTED = ["CANopenNode_DS301_profile.eds", "python-canopen_e35.eds",
            "lely-core_co-nmt-slave.dcf", "lely-core_coapp-fiber-slave.dcf"]
REFUSED = {
    "python-canopen_sample.eds": "2020h: unknown data type 0x40",
    "lely-core_co-pdo-receive.dcf": "1600h:1: maps 2000h:0 with 28 bits, but it is UNSIGNED32",
    "lely-core_co-pdo-transmit.dcf": "1A00h:1: maps 2000h:0 with 28 bits, but it is UNSIGNED32",
    "lely-core_co-sdev.dcf": "200Ch: ParameterValue '365 43200000' is not a valid TIME_OF_DAY",
    # A data type test file, not a device: it lists 1018h only.
    "python-canopen_datatypes.eds": "50: mandatory object 1000h (Device type) is missing",
}


def test_every_file_has_an_expectation():
    files = {f for f in os.listdir(TP) if f.endswith((".eds", ".dcf"))}
    assert files == set(ACCEPTED) | set(REFUSED)


@pytest.mark.parametrize("name", ACCEPTED)
def test_accepted_and_compiles(name, tmp_path):
    r = subprocess.run([sys.executable, EDS2OD, os.path.join(TP, name), "--name", "tp", "-o",
                        str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    c = subprocess.run(["gcc", "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only",
                        "-I", os.path.join(BASE, "include"), "-I", str(tmp_path),
                        str(tmp_path / "tp_od.c")], capture_output=True, text=True)
    assert c.returncode == 0, c.stderr


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_refused(name):
    r = subprocess.run([sys.executable, EDS2OD, os.path.join(TP, name), "--lint-only"],
                       capture_output=True, text=True)
    assert r.returncode == 1 and REFUSED[name] in r.stderr, r.stderr
