# SPDX-License-Identifier: Apache-2.0
#
# Boilerplate run by find_package(SafeLine): board, Kconfig, toolchain flags, the `app` library
# and the image `zephyr/zephyr.exe`. Order follows Zephyr's: configuration first (so CMake sees
# every CONFIG_* as a variable), then the kernel, drivers and subsystems.

cmake_minimum_required(VERSION 3.20.0)

if(CMAKE_SOURCE_DIR STREQUAL CMAKE_BINARY_DIR)
  message(FATAL_ERROR
    "In-source builds are not supported: give a build directory, e.g.\n"
    "  cmake -G Ninja -S ${CMAKE_SOURCE_DIR} -B build")
endif()

set(APPLICATION_SOURCE_DIR ${CMAKE_SOURCE_DIR} CACHE PATH "Application source directory")
set(APPLICATION_BINARY_DIR ${CMAKE_BINARY_DIR} CACHE PATH "Application build directory")
# Zephyr's layout: everything the kernel side generates lives under <build>/zephyr.
set(SAFELINE_BINARY_DIR ${CMAKE_BINARY_DIR}/zephyr)
set(SAFELINE_GENERATED_DIR ${SAFELINE_BINARY_DIR}/include/generated)
file(MAKE_DIRECTORY ${SAFELINE_GENERATED_DIR}/zephyr)

find_package(Python3 3.8 REQUIRED COMPONENTS Interpreter)
set(PYTHON_EXECUTABLE ${Python3_EXECUTABLE})

include(${SAFELINE_BASE}/cmake/extensions.cmake)

# --- Board -------------------------------------------------------------------------------------
if(NOT DEFINED BOARD)
  if(DEFINED ENV{BOARD})
    set(BOARD $ENV{BOARD})
  else()
    set(BOARD native_posix)
  endif()
endif()
set(BOARD ${BOARD} CACHE STRING "Board the image is built for")
file(GLOB board_dirs LIST_DIRECTORIES true ${SAFELINE_BASE}/boards/*/${BOARD})
if(NOT board_dirs)
  file(GLOB known RELATIVE ${SAFELINE_BASE}/boards ${SAFELINE_BASE}/boards/*/*/*.yaml)
  message(FATAL_ERROR "No board named '${BOARD}'. Boards: ${known}")
endif()
list(GET board_dirs 0 BOARD_DIR)
include(${BOARD_DIR}/board.cmake OPTIONAL)

# --- Kconfig -----------------------------------------------------------------------------------
include(${SAFELINE_BASE}/cmake/kconfig.cmake)

# --- Toolchain and global flags ----------------------------------------------------------------
# C only; project() of the application enables nothing more.
project(SafeLine-Kernel VERSION 0.1 LANGUAGES C)
set(CMAKE_C_STANDARD 11)
set(CMAKE_C_EXTENSIONS ON)
set(CMAKE_C_STANDARD_REQUIRED ON)
set(CMAKE_EXPORT_COMPILE_COMMANDS ON)

add_library(zephyr_interface INTERFACE)
target_include_directories(zephyr_interface INTERFACE
  ${SAFELINE_BASE}/include
  ${SAFELINE_GENERATED_DIR})
target_compile_options(zephyr_interface INTERFACE
  -imacros ${AUTOCONF_H}
  -Wall -Wextra -Wno-unused-parameter -Wno-missing-field-initializers
  -Werror=implicit-function-declaration -Wshadow=local
  -fno-strict-aliasing -ffunction-sections -fdata-sections -g)
target_compile_definitions(zephyr_interface INTERFACE _GNU_SOURCE)

if(CONFIG_ASAN OR CONFIG_UBSAN OR CONFIG_TSAN)
  # Sanitized images keep frames for readable reports.
  target_compile_options(zephyr_interface INTERFACE -O1 -fno-omit-frame-pointer)
else()
  target_compile_options(zephyr_interface INTERFACE -O2)
endif()
set(sanitizers "")
if(CONFIG_ASAN)
  list(APPEND sanitizers address)
endif()
if(CONFIG_UBSAN)
  list(APPEND sanitizers undefined)
  target_compile_options(zephyr_interface INTERFACE -fno-sanitize-recover=all)
endif()
if(CONFIG_TSAN)
  list(APPEND sanitizers thread)
endif()
if(sanitizers)
  list(JOIN sanitizers "," sanitizers)
  target_compile_options(zephyr_interface INTERFACE -fsanitize=${sanitizers})
  target_link_options(zephyr_interface INTERFACE -fsanitize=${sanitizers})
endif()

# Core library for zephyr_sources(); the application's own library.
zephyr_library_named(zephyr)
add_library(app STATIC "")
target_link_libraries(app PUBLIC zephyr_interface)
set_property(GLOBAL APPEND PROPERTY SAFELINE_LIBS app)

# Helper functions of the areas (e.g. canopen_od_generate()).
file(GLOB safeline_modules ${SAFELINE_BASE}/cmake/modules/*.cmake)
foreach(module ${safeline_modules})
  include(${module})
endforeach()

add_subdirectory(${SAFELINE_BASE} ${SAFELINE_BINARY_DIR}/safeline)

# --- The image ---------------------------------------------------------------------------------
# Linked once the application's CMakeLists.txt has run, so libraries it adds are included too.
add_executable(zephyr_final ${SAFELINE_BASE}/cmake/empty.c)
set_target_properties(zephyr_final PROPERTIES
  OUTPUT_NAME zephyr.exe
  SUFFIX ""
  RUNTIME_OUTPUT_DIRECTORY ${SAFELINE_BINARY_DIR})
find_package(Threads REQUIRED)

function(safeline_link_image)
  get_property(libs GLOBAL PROPERTY SAFELINE_LIBS)
  foreach(lib ${libs})
    # A library whose sources are all disabled by Kconfig still has to be a valid target.
    get_target_property(srcs ${lib} SOURCES)
    if(NOT srcs)
      target_sources(${lib} PRIVATE ${SAFELINE_BASE}/cmake/empty.c)
    endif()
  endforeach()
  list(JOIN libs "," joined)
  target_link_libraries(zephyr_final PRIVATE
    "$<LINK_LIBRARY:WHOLE_ARCHIVE,${joined}>" zephyr_interface Threads::Threads m)
endfunction()
cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL safeline_link_image)

add_custom_target(run
  COMMAND ${SAFELINE_BINARY_DIR}/zephyr.exe
  DEPENDS zephyr_final
  WORKING_DIRECTORY ${APPLICATION_BINARY_DIR}
  USES_TERMINAL
  COMMENT "Running zephyr.exe")
