# SPDX-License-Identifier: Apache-2.0
#
# CMake package entry of SafeLine: `find_package(SafeLine REQUIRED HINTS $ENV{SAFELINE_BASE})`
# in an application's CMakeLists.txt, before project(). Like Zephyr's package, it sets up the
# board, merges Kconfig and defines the `app` library the application adds its sources to.

get_filename_component(SAFELINE_BASE "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(SafeLine_FOUND TRUE)
include(${SAFELINE_BASE}/cmake/safeline.cmake)
