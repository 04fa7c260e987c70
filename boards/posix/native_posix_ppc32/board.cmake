# native_posix_ppc32: a 32-bit big-endian PowerPC Linux program, built by Debian's cross compiler
# (cmake/toolchain/linux-cross.cmake) and run under qemu-ppc-static.
set(SAFELINE_BOARD_ARCH posix)
set(SAFELINE_CROSS_COMPILE powerpc-linux-gnu-)
set(SAFELINE_CROSS_PROCESSOR powerpc)
set(CMAKE_TOOLCHAIN_FILE ${SAFELINE_BASE}/cmake/toolchain/linux-cross.cmake)
