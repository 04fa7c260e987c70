# SPDX-License-Identifier: Apache-2.0
"""The native_posix command line, exit codes and process end (doc/boards/native_posix.md)."""

import signal
import subprocess
import time

BOARD_OPTIONS = ["--help", "--stop-at=<time>", "--seed=<r_seed>", "--testargs <arg>..."]
APP_OPTIONS = ["--node-id=<n>", "--exit=<code>", "--fatal=<kind>"]


def test_help_lists_every_option_and_exits_0(run):
    result = run("--help")
    assert result.returncode == 0
    for option in BOARD_OPTIONS + APP_OPTIONS:
        assert option in result.stdout
    assert "CANopen node-ID" in result.stdout
    assert "running" not in result.stdout, "--help must not boot the firmware"


def test_unknown_option_prints_usage_and_exits_1(run):
    result = run("--no-such-option")
    assert result.returncode == 1
    assert result.stdout.startswith("Usage:")
    for option in BOARD_OPTIONS + APP_OPTIONS:
        assert option in result.stdout
    assert "--no-such-option" in result.stderr
    assert "Booting" not in result.stdout


def test_malformed_value_exits_1(run):
    for bad in ("--node-id=abc", "--node-id=-1", "--seed=0x1g", "--stop-at=soon", "--node-id"):
        result = run(bad)
        assert result.returncode == 1, bad
        assert "Booting" not in result.stdout, bad


def test_options_reach_the_application(run):
    for args in (["--node-id=5"], ["-node-id=5"], ["--node-id:5"], ["--node-id=0x5"]):
        result = run(*args, "--exit=0")
        assert result.returncode == 0
        assert "node_id=5 " in result.stdout, args


def test_main_return_value_is_the_exit_code(run):
    result = run("--exit=3")
    assert result.returncode == 3
    assert "on_exit hook ran" in result.stdout


def test_seed_makes_random_numbers_repeatable(run):
    first = run("--seed=1234", "--exit=0")
    second = run("--seed=1234", "--exit=0")
    other = run("--seed=1235", "--exit=0")
    default = run("--exit=0")

    def rand_line(result):
        return next(line for line in result.stdout.splitlines() if line.startswith("rand="))

    assert "seed=1234" in first.stdout
    assert rand_line(first) == rand_line(second)
    assert rand_line(first) != rand_line(other)
    assert "seed=22136" in default.stdout, "default seed 0x5678"


def test_testargs_are_left_to_the_application(run):
    result = run("--exit=0", "--testargs", "alpha", "--beta")
    assert result.returncode == 0, "arguments after --testargs are not parsed as options"
    assert "testargs=2 alpha --beta" in result.stdout


def test_stop_at_ends_a_running_image_with_0(run):
    start = time.monotonic()
    result = run("--stop-at=0.5")
    elapsed = time.monotonic() - start
    assert result.returncode == 0
    assert "running" in result.stdout
    assert "Stopped at 0.500s" in result.stdout
    assert "on_exit hook ran" in result.stdout
    assert elapsed >= 0.5
    assert elapsed < 30


def test_sigterm_ends_with_128_plus_signal(image):
    proc = subprocess.Popen([str(image)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().startswith("*** Booting")
        # Wait until main() runs, then stop the image.
        while "running" not in proc.stdout.readline():
            pass
        proc.send_signal(signal.SIGTERM)
        rest = proc.communicate(timeout=30)[0]
    finally:
        proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM
    assert "on_exit hook ran" in rest


def test_fatal_errors(run):
    for kind, reason in (("panic", "4: Kernel panic"), ("oops", "3: Kernel oops")):
        result = run(f"--fatal={kind}")
        assert result.returncode == 1, kind
        assert f">>> SAFELINE FATAL ERROR {reason}" in result.stdout
        assert "Current thread:" in result.stdout and "(main)" in result.stdout
        assert "no fatal error" not in result.stdout

    result = run("--fatal=assert", "--node-id=7")
    assert result.returncode == 1
    assert "ASSERTION FAIL [node_id == 12345]" in result.stdout
    assert "node_id is 7" in result.stdout
    assert ">>> SAFELINE FATAL ERROR 4: Kernel panic" in result.stdout

    result = run("--fatal=assert", "--node-id=12345")
    assert result.returncode == 0, "a true assertion does nothing"
    assert "no fatal error" in result.stdout


# --- Strict values: every bad value is refused before the firmware boots -----------------------

BAD_VALUES = [
    # unsigned 32-bit ('u'): no sign, no space, no wrap, nothing after the number
    ("node-id", " -18446744073709551615"),
    ("node-id", "-18446744073709551615"),
    ("node-id", "18446744073709551617"),
    ("node-id", "4294967296"),
    ("node-id", "+5"),
    ("node-id", " 5"),
    ("node-id", "5 "),
    ("node-id", "5x"),
    ("node-id", "0x"),
    ("node-id", "08"),
    ("node-id", ""),
    ("node-id", "nan"),
    ("seed", " -4294967295"),
    ("seed", " -18446744073709551615"),
    ("seed", "-0"),
    ("seed", "1e3"),
    # signed 32-bit ('i')
    ("exit", "2147483648"),
    ("exit", "-2147483649"),
    ("exit", "--1"),
    ("exit", "+1"),
    ("exit", " 1"),
    ("exit", "9223372036854775808"),
    # --stop-at: a finite, non-negative number of seconds
    ("stop-at", "nan"),
    ("stop-at", "NAN"),
    ("stop-at", "-nan"),
    ("stop-at", "inf"),
    ("stop-at", "infinity"),
    ("stop-at", "-1"),
    ("stop-at", "-0.5"),
    ("stop-at", "1e999"),
    ("stop-at", "1s"),
    ("stop-at", " 1"),
    ("stop-at", "+1"),
    ("stop-at", ""),
]


def assert_refused(result, option, value):
    what = f"--{option}={value!r}"
    assert result.returncode == 1, f"{what}: exit code {result.returncode}"
    assert "Booting" not in result.stdout, f"{what}: the firmware booted"
    assert result.stdout.startswith("Usage:"), f"{what}: no usage on stdout"
    assert f"--{option}" in result.stderr, f"{what}: the error does not name the option"
    assert "Error" in result.stderr, what


def test_bad_values_are_refused_before_boot_with_usage(run):
    for option, value in BAD_VALUES:
        # A value the parser lets through must not hang the test (--stop-at=nan did).
        try:
            result = run(f"--{option}={value}", "--exit=0", timeout=10)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"--{option}={value!r} was accepted and never stopped")
        assert_refused(result, option, value)


def test_bad_stop_at_does_not_run_forever(run):
    for value in ("nan", "inf", "-1", "later"):
        try:
            result = run(f"--stop-at={value}", timeout=10)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"--stop-at={value} never stopped")
        assert_refused(result, "stop-at", value)


def test_full_range_values_are_accepted(run):
    # UINT32_MAX is the table parser's "not given" value: given, it is a value like any other.
    result = run("--node-id=4294967295", "--exit=0")
    assert result.returncode == 0
    assert "node_id=4294967295 " in result.stdout

    result = run("--seed=4294967295", "--exit=0")
    assert result.returncode == 0
    assert "seed=4294967295" in result.stdout, "--seed=UINT32_MAX is not the default seed"

    for value, seed in (("0", 0), ("0xFFFFFFFF", 4294967295), ("017", 15)):
        result = run(f"--seed={value}", "--exit=0")
        assert result.returncode == 0, value
        assert f"seed={seed}" in result.stdout, value

    for value, code in (("-3", 253), ("0x7", 7), ("-0", 0)):
        result = run(f"--exit={value}")
        assert result.returncode == code, value


def test_good_stop_at_values(run):
    for value, shown in (("0.2", "0.200"), ("2e-1", "0.200"), ("0", "0.000")):
        result = run(f"--stop-at={value}", timeout=30)
        assert result.returncode == 0, value
        assert f"Stopped at {shown}s" in result.stdout, value
