# native_posix_arm32: a 32-bit little-endian ARM (armhf) Linux program, built by Debian's cross compiler
# (cmake/toolchain/linux-cross.cmake) and run under qemu-arm-static.
set(SAFELINE_BOARD_ARCH posix)
set(SAFELINE_CROSS_COMPILE arm-linux-gnueabihf-)
set(SAFELINE_CROSS_PROCESSOR arm)
set(CMAKE_TOOLCHAIN_FILE ${SAFELINE_BASE}/cmake/toolchain/linux-cross.cmake)
