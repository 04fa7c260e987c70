# SPDX-License-Identifier: Apache-2.0
"""The CMake package and Kconfig merge: order of fragments, Kconfig's own errors, targets.

These tests configure (and where needed build) small applications written into a temporary
folder, exactly as a sample would be built.
"""

import os
import re
import subprocess
import textwrap

import pytest

BASE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CMAKELISTS = """\
cmake_minimum_required(VERSION 3.20.0)
find_package(SafeLine REQUIRED HINTS $ENV{SAFELINE_BASE})
project(build_test)
target_sources(app PRIVATE src/main.c)
"""

# An application Kconfig with symbols only these tests use.
KCONFIG = """\
config TEST_A
	int "A"
	range 0 100
	default 1

config TEST_B
	int "B"
	range 0 100
	default 1

config TEST_C
	int "C"
	range 0 100
	default 1

config TEST_D
	int "D"
	range 0 100
	default 1

config TEST_NEEDS_TSAN
	bool "only with TSAN"
	depends on TSAN

source "Kconfig.safeline"
"""


def make_app(tmp_path, prj="", board_conf=None, extra=None, main=None):
    app = tmp_path / "app"
    (app / "src").mkdir(parents=True)
    (app / "CMakeLists.txt").write_text(CMAKELISTS)
    (app / "Kconfig").write_text(KCONFIG)
    (app / "prj.conf").write_text(textwrap.dedent(prj))
    (app / "src" / "main.c").write_text(main or "int main(void)\n{\n\treturn 0;\n}\n")
    if board_conf is not None:
        (app / "boards").mkdir()
        (app / "boards" / "native_posix.conf").write_text(textwrap.dedent(board_conf))
    if extra is not None:
        (app / "extra.conf").write_text(textwrap.dedent(extra))
    return app


def configure(app, build, *defs):
    env = dict(os.environ, SAFELINE_BASE=BASE)
    return subprocess.run(["cmake", "-G", "Ninja", "-S", str(app), "-B", str(build)] + list(defs),
                          env=env, capture_output=True, text=True)


def dotconfig(build):
    values = {}
    for line in (build / "zephyr" / ".config").read_text().splitlines():
        if line.startswith("CONFIG_"):
            k, v = line.split("=", 1)
            values[k] = v
    return values


def test_fragments_merge_in_zephyr_order(tmp_path):
    app = make_app(tmp_path,
                   prj="CONFIG_TEST_A=10\nCONFIG_TEST_B=10\nCONFIG_TEST_C=10\nCONFIG_TEST_D=10\n",
                   board_conf="CONFIG_TEST_B=20\nCONFIG_TEST_C=20\nCONFIG_TEST_D=20\n",
                   extra="CONFIG_TEST_C=30\nCONFIG_TEST_D=30\n")
    build = tmp_path / "build"
    r = configure(app, build, f"-DEXTRA_CONF_FILE={app / 'extra.conf'}", "-DCONFIG_TEST_D=40")
    assert r.returncode == 0, r.stderr
    cfg = dotconfig(build)
    assert (cfg["CONFIG_TEST_A"], cfg["CONFIG_TEST_B"], cfg["CONFIG_TEST_C"],
            cfg["CONFIG_TEST_D"]) == ("10", "20", "30", "40")
    # The board defconfig is the first fragment.
    assert cfg["CONFIG_BOARD_NATIVE_POSIX"] == "y"
    assert cfg["CONFIG_BOARD"] == '"native_posix"'
    autoconf = (build / "zephyr/include/generated/zephyr/autoconf.h").read_text()
    assert "#define CONFIG_TEST_D 40" in autoconf


def test_undefined_symbol_stops_the_build_with_kconfig_message(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_NO_SUCH_SYMBOL=y\n")
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert "prj.conf:1: warning: attempt to assign the value 'y' to the undefined symbol " \
           "NO_SUCH_SYMBOL" in r.stderr


def test_malformed_value_is_an_error(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_TEST_A=eleven\n")
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert "the value 'eleven' is invalid for TEST_A" in r.stderr


def test_value_out_of_range_does_not_stick(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_TEST_A=500\n")
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert "TEST_A" in r.stderr and "was assigned the value '500'" in r.stderr
    assert "range is [0, 100]" in r.stderr


def test_unmet_dependency_is_reported(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_TEST_NEEDS_TSAN=y\n")
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert "TEST_NEEDS_TSAN" in r.stderr and "dependencies are not met" in r.stderr


def test_in_source_build_is_refused(tmp_path):
    app = make_app(tmp_path)
    r = configure(app, app)
    assert r.returncode != 0
    assert "In-source builds are not supported" in r.stderr


def test_unknown_board_lists_the_known_ones(tmp_path):
    app = make_app(tmp_path)
    r = configure(app, tmp_path / "build", "-DBOARD=nonesuch")
    assert r.returncode != 0
    assert "No board named 'nonesuch'" in r.stderr and "native_posix" in r.stderr


def test_menuconfig_and_guiconfig_targets_exist(tmp_path):
    app = make_app(tmp_path)
    build = tmp_path / "build"
    assert configure(app, build).returncode == 0
    targets = subprocess.run(["ninja", "-C", str(build), "-t", "targets", "all"],
                             capture_output=True, text=True, check=True).stdout
    names = {line.split(":")[0] for line in targets.splitlines()}
    assert {"menuconfig", "guiconfig", "run"} <= names


def test_saved_config_survives_reconfigure_when_inputs_unchanged(tmp_path):
    # What menuconfig does: it edits .config; the next configure keeps the edit.
    app = make_app(tmp_path, prj="CONFIG_TEST_A=10\n")
    build = tmp_path / "build"
    assert configure(app, build).returncode == 0
    dot = build / "zephyr" / ".config"
    dot.write_text(dot.read_text().replace("CONFIG_TEST_B=1", "CONFIG_TEST_B=77"))
    assert configure(app, build).returncode == 0
    assert dotconfig(build)["CONFIG_TEST_B"] == "77"
    # A changed fragment starts again from the fragments.
    (app / "prj.conf").write_text("CONFIG_TEST_A=11\n")
    assert configure(app, build).returncode == 0
    cfg = dotconfig(build)
    assert (cfg["CONFIG_TEST_A"], cfg["CONFIG_TEST_B"]) == ("11", "1")


def test_sanitizer_option_reaches_the_compiler(tmp_path):
    app = make_app(tmp_path)
    build = tmp_path / "build"
    assert configure(app, build, "-DCONFIG_UBSAN=y").returncode == 0
    commands = (build / "compile_commands.json").read_text()
    assert "-fsanitize=undefined" in commands


def test_later_fragment_may_pick_another_choice_member(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_TEST_CHOICE_A=y\n", extra="CONFIG_TEST_CHOICE_B=y\n")
    kconfig = (app / "Kconfig").read_text().replace('source "Kconfig.safeline"', """\
choice TEST_CHOICE
	prompt "test choice"
	default TEST_CHOICE_A

config TEST_CHOICE_A
	bool "A"

config TEST_CHOICE_B
	bool "B"

endchoice

source "Kconfig.safeline"
""")
    (app / "Kconfig").write_text(kconfig)
    build = tmp_path / "build"
    r = configure(app, build, f"-DEXTRA_CONF_FILE={app / 'extra.conf'}")
    assert r.returncode == 0, r.stderr
    cfg = dotconfig(build)
    assert cfg.get("CONFIG_TEST_CHOICE_B") == "y"
    assert "CONFIG_TEST_CHOICE_A" not in cfg


@pytest.mark.parametrize("prj", ["CONFIG_CAN=n\nCONFIG_CANOPEN=y\n", "CONFIG_CANOPEN=y\n"],
                         ids=["can-off", "can-unset"])
def test_canopen_needs_can(tmp_path, prj):
    # CANOPEN depends on CAN (it does not select it): without CAN the value does not stick.
    app = make_app(tmp_path, prj=prj)
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert re.search(r"^error: CANOPEN \(defined at subsys/canopen/Kconfig:\d+\) was assigned "
                     r"the value 'y' but got the value 'n'\. Its dependencies are not met: "
                     r"CAN \(= n\)\.$", r.stderr, re.M), r.stderr
    assert "nothing was written" in r.stderr
    assert not (tmp_path / "build" / "zephyr" / ".config").exists()


def test_canopen_with_can_always_has_the_object_dictionary(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_CAN=y\nCONFIG_CANOPEN=y\n")
    build = tmp_path / "build"
    r = configure(app, build)
    assert r.returncode == 0, r.stderr
    cfg = dotconfig(build)
    assert cfg["CONFIG_CANOPEN"] == "y" and cfg["CONFIG_CANOPEN_OD"] == "y"
    # CANOPEN_PDO implies CANOPEN_SYNC.
    assert cfg["CONFIG_CANOPEN_PDO"] == "y" and cfg["CONFIG_CANOPEN_SYNC"] == "y"


def test_object_dictionary_cannot_be_turned_off(tmp_path):
    app = make_app(tmp_path, prj="CONFIG_CAN=y\nCONFIG_CANOPEN=y\nCONFIG_CANOPEN_OD=n\n")
    r = configure(app, tmp_path / "build")
    assert r.returncode != 0
    assert re.search(r"^error: CANOPEN_OD \(defined at subsys/canopen/od/Kconfig:\d+\) was "
                     r"assigned the value 'n' but got the value 'y'\.$", r.stderr, re.M), r.stderr
