# SPDX-License-Identifier: Apache-2.0
#
# CMake toolchain file for the boards whose image is a Linux program for another CPU
# (native_posix_arm32, native_posix_ppc32): the board's board.cmake sets SAFELINE_CROSS_COMPILE
# (the compiler's prefix, e.g. arm-linux-gnueabihf-) and SAFELINE_CROSS_PROCESSOR, then points
# CMAKE_TOOLCHAIN_FILE here before project() runs. CMake reads this file again in its compiler
# checks, which see the two variables through CMAKE_TRY_COMPILE_PLATFORM_VARIABLES.

set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR ${SAFELINE_CROSS_PROCESSOR})
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SAFELINE_CROSS_COMPILE SAFELINE_CROSS_PROCESSOR)

find_program(SAFELINE_CROSS_GCC ${SAFELINE_CROSS_COMPILE}gcc)
if(NOT SAFELINE_CROSS_GCC)
  message(FATAL_ERROR
    "${SAFELINE_CROSS_COMPILE}gcc not found: board ${BOARD} is built with Debian's cross "
    "compiler (scripts/setup installs it)")
endif()
set(CMAKE_C_COMPILER ${SAFELINE_CROSS_GCC})

# Headers and libraries from the cross C library only; programs (python, ninja) from the host.
string(REGEX REPLACE "-$" "" triple "${SAFELINE_CROSS_COMPILE}")
set(CMAKE_FIND_ROOT_PATH /usr/${triple})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
