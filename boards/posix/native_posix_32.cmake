# SPDX-License-Identifier: Apache-2.0
#
# What native_posix_arm32 and native_posix_ppc32 add to the native board's host side.

# A 64-bit time_t, as the C libraries of devices have it (newlib, picolibc), not glibc's
# 32-bit default on these CPUs.
zephyr_compile_definitions(_TIME_BITS=64 _FILE_OFFSET_BITS=64)
# Linked statically, so that qemu-user runs the image without the target's C library folder.
zephyr_link_libraries(-static)
# A 32-bit PowerPC has no 64-bit atomic instructions: gcc calls libatomic for them (the
# board's random generator keeps its state in an atomic 64-bit word).
zephyr_link_libraries(atomic)
# No debug information: nothing reads it under qemu-user (no gdb for these CPUs is installed),
# and builds without it are shorter (the test stage of scripts/run-tests is mostly builds).
zephyr_compile_options(-g0)
