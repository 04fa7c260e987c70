# SPDX-License-Identifier: Apache-2.0
"""Run by twister for sample.canopen.flying_master.options and
sample.canopen.redundant_network.options (SAFELINE_IMAGE is the built sample): --hb and
--hb-consumer (common/hb_options.c). A value outside 1..65535, or a consumer time not longer
than the heartbeat, ends the process before the boot with the usage, an error naming the option
and exit code 1. The flying_master sample compares against its defaults (100 ms, 300 ms);
redundant_network keeps the dictionaries' times for an option not given and compares only two
given ones. Not collected by the plain pytest run (its name is not test_*)."""

import os
import subprocess

import pytest

IMAGE = os.environ.get("SAFELINE_IMAGE", "")
FLYING = "flying_master" in IMAGE


def run(*args):
    return subprocess.run([IMAGE, *args], capture_output=True, text=True, timeout=60)


def assert_refused(args, option, reason=None):
    result = run(*args)
    assert result.returncode == 1, f"{args}: exit code {result.returncode}"
    assert result.stdout.startswith("Usage:"), f"{args}: no usage on stdout"
    assert "Booting" not in result.stdout, f"{args}: the firmware booted"
    assert f"--{option}" in result.stderr, f"{args}: the error does not name --{option}"
    if reason is not None:
        assert reason in result.stderr, f"{args}: {result.stderr!r}"


@pytest.mark.parametrize("option", ["hb", "hb-consumer"])
@pytest.mark.parametrize("value", ["0", "65536", "-1", "10x", ""])
def test_a_time_outside_1_to_65535_is_refused(option, value):
    assert_refused((f"--{option}={value}",), option)


@pytest.mark.parametrize("hb,consumer", [("200", "200"), ("500", "100")])
def test_a_consumer_time_not_longer_than_the_heartbeat_is_refused(hb, consumer):
    assert_refused((f"--hb={hb}", f"--hb-consumer={consumer}"), "hb-consumer",
                   f"must be longer than the heartbeat ({hb} ms)")


def test_an_option_not_given_takes_the_samples_default():
    if FLYING:
        # The default consumer time, 300 ms, is not longer than a 300 ms heartbeat.
        assert_refused(("--hb=300",), "hb-consumer", "must be longer than the heartbeat (300 ms)")
        assert_refused(("--hb-consumer=100",), "hb-consumer",
                       "must be longer than the heartbeat (100 ms)")
    else:
        # The dictionaries' times stay and are not compared with the one given.
        result = run("--hb=300", "--stop-at=0.2")
        assert result.returncode == 0, result.stderr
        assert "Booting" in result.stdout


def test_good_times_boot():
    result = run("--hb=100", "--hb-consumer=400", "--stop-at=0.2")
    assert result.returncode == 0, result.stderr
    assert "Booting" in result.stdout
