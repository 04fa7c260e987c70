# SPDX-License-Identifier: Apache-2.0
"""The 32-bit boards (doc/boards/native_posix_32.md): built by Debian's cross compilers through
cmake/toolchain/linux-cross.cmake, run under qemu-user, with the stack's embedded defaults."""

import os
import shutil
import subprocess

import pytest

from test_build_system import configure, dotconfig, make_app

BOARDS = {
    # board: (compiler prefix, qemu-user, byte order)
    "native_posix_arm32": ("arm-linux-gnueabihf-", "qemu-arm-static", "little"),
    "native_posix_ppc32": ("powerpc-linux-gnu-", "qemu-ppc-static", "big"),
}

# What the stack's layouts depend on, printed by the image itself.
MAIN = r"""
#include <stdint.h>
#include <stdio.h>
#include <time.h>

int main(void)
{
	const uint32_t word = 0x01020304U;

	printf("sizes: pointer %u long %u size_t %u time_t %u\n", (unsigned)sizeof(void *),
	       (unsigned)sizeof(long), (unsigned)sizeof(size_t), (unsigned)sizeof(time_t));
	printf("byte order: %s\n", (*(const uint8_t *)&word == 0x04U) ? "little" : "big");
	return 0;
}
"""


def need(*programs):
    missing = [p for p in programs if shutil.which(p) is None]
    if missing:
        pytest.skip(f"{', '.join(missing)} not installed (scripts/setup installs it)")


@pytest.mark.parametrize("board", sorted(BOARDS))
def test_the_image_is_32_bit_with_the_board_byte_order(tmp_path, board):
    prefix, qemu, order = BOARDS[board]
    need(prefix + "gcc", qemu)
    app = make_app(tmp_path, main=MAIN)
    build = tmp_path / "build"
    r = configure(app, build, f"-DBOARD={board}")
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"/usr/bin/{prefix}gcc " in (build / "compile_commands.json").read_text()
    subprocess.run(["ninja", "-C", str(build)], capture_output=True, text=True, check=True)
    image = build / "zephyr" / "zephyr.exe"
    # Statically linked: qemu-user needs no folder of the target's C library.
    out = subprocess.run([qemu, str(image)], capture_output=True, text=True, timeout=60, check=True)
    lines = out.stdout.splitlines()
    assert lines[0] == f"*** Booting SafeLine on {board} ***"
    # time_t has 64 bits as on devices' C libraries, not glibc's 32-bit default on these CPUs
    assert "sizes: pointer 4 long 4 size_t 4 time_t 8" in lines
    assert f"byte order: {order}" in lines


@pytest.mark.parametrize("board", sorted(BOARDS))
def test_the_stack_gets_its_embedded_defaults(tmp_path, board):
    app = make_app(tmp_path, prj="CONFIG_CAN=y\nCONFIG_CANOPEN=y\n")
    native, cross = tmp_path / "native", tmp_path / "cross"
    assert configure(app, native).returncode == 0
    # Kconfig runs before the compiler is looked for: no cross compiler needed here.
    configure(app, cross, f"-DBOARD={board}")
    n, c = dotconfig(native), dotconfig(cross)
    assert c[f"CONFIG_BOARD_{board.upper()}"] == "y" and c["CONFIG_ARCH_POSIX"] == "y"
    assert "CONFIG_BOARD_NATIVE_POSIX" not in c
    # a size whose default is the native board's own (subsys/canopen/*/Kconfig), and the lock
    # check the native board's defconfig turns on (a check, not a feature: no bool default of
    # the stack is keyed on the board)
    assert (n["CONFIG_CANOPEN_OD_SCRATCH_SIZE"], c["CONFIG_CANOPEN_OD_SCRATCH_SIZE"]) == ("256", "32")
    assert n["CONFIG_CANOPEN_LOCK_CHECK"] == "y"
    assert "CONFIG_CANOPEN_LOCK_CHECK" not in c
    # and the kernel's own default tick rate, not the native board's
    assert (n["CONFIG_SYS_CLOCK_TICKS_PER_SEC"], c["CONFIG_SYS_CLOCK_TICKS_PER_SEC"]) == ("100000", "10000")


def test_a_missing_cross_compiler_is_named(tmp_path):
    # A PATH with the host tools CMake needs here, and no cross compiler.
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("python3", "ninja"):
        os.symlink(shutil.which(tool), bin_dir / tool)
    app = make_app(tmp_path)
    r = subprocess.run([shutil.which("cmake"), "-G", "Ninja", "-S", str(app), "-B", str(tmp_path / "b"),
                        "-DBOARD=native_posix_arm32"],
                       env=dict(os.environ, PATH=str(bin_dir),
                                SAFELINE_BASE=str(os.path.dirname(os.path.dirname(
                                    os.path.dirname(os.path.abspath(__file__)))))),
                       capture_output=True, text=True)
    assert r.returncode != 0
    message = " ".join(r.stderr.split())  # CMake wraps its messages
    assert ("arm-linux-gnueabihf-gcc not found: board native_posix_arm32 is built with Debian's "
            "cross compiler (scripts/setup installs it)") in message
