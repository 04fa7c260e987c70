# SPDX-License-Identifier: Apache-2.0
#
# Zephyr's CMake verbs, with the same names and meaning, for SafeLine's feature folders.
# Every library registers itself in the global property SAFELINE_LIBS; the image links them all
# with --whole-archive so that SYS_INIT entries and constructors are kept.

# Library name from the folder's path relative to SAFELINE_BASE, as Zephyr does:
# subsys/canopen/od -> subsys__canopen__od.
function(zephyr_library_get_current_dir_lib_name base lib_name)
  file(RELATIVE_PATH rel ${base} ${CMAKE_CURRENT_SOURCE_DIR})
  if(rel MATCHES "^\\.\\./")
    get_filename_component(rel ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  endif()
  string(REPLACE "/" "__" name ${rel})
  set(${lib_name} ${name} PARENT_SCOPE)
endfunction()

macro(zephyr_library)
  zephyr_library_get_current_dir_lib_name(${SAFELINE_BASE} lib_name)
  zephyr_library_named(${lib_name})
endmacro()

macro(zephyr_library_named name)
  set(ZEPHYR_CURRENT_LIBRARY ${name})
  add_library(${name} STATIC "")
  target_link_libraries(${name} PUBLIC zephyr_interface)
  set_property(GLOBAL APPEND PROPERTY SAFELINE_LIBS ${name})
endmacro()

function(zephyr_library_sources source)
  target_sources(${ZEPHYR_CURRENT_LIBRARY} PRIVATE ${source} ${ARGN})
endfunction()

function(zephyr_library_sources_ifdef feature_toggle source)
  if(${${feature_toggle}})
    zephyr_library_sources(${source} ${ARGN})
  endif()
endfunction()

function(zephyr_library_sources_ifndef feature_toggle source)
  if(NOT ${feature_toggle})
    zephyr_library_sources(${source} ${ARGN})
  endif()
endfunction()

# zephyr_library_sources_if_kconfig(foo_bar.c) compiles the file when CONFIG_FOO_BAR=y.
function(zephyr_library_sources_if_kconfig item)
  get_filename_component(item_basename ${item} NAME_WE)
  string(TOUPPER CONFIG_${item_basename} kconfig_name)
  if(${kconfig_name})
    zephyr_library_sources(${item})
  endif()
endfunction()

function(zephyr_library_include_directories)
  target_include_directories(${ZEPHYR_CURRENT_LIBRARY} PRIVATE ${ARGN})
endfunction()

function(zephyr_library_compile_definitions)
  target_compile_definitions(${ZEPHYR_CURRENT_LIBRARY} PRIVATE ${ARGN})
endfunction()

function(zephyr_library_compile_options)
  target_compile_options(${ZEPHYR_CURRENT_LIBRARY} PRIVATE ${ARGN})
endfunction()

function(zephyr_library_link_libraries)
  target_link_libraries(${ZEPHYR_CURRENT_LIBRARY} PUBLIC ${ARGN})
endfunction()

# Global settings: they reach every library and the application.
function(zephyr_include_directories)
  foreach(dir ${ARGN})
    get_filename_component(abs ${dir} ABSOLUTE)
    target_include_directories(zephyr_interface INTERFACE ${abs})
  endforeach()
endfunction()

function(zephyr_compile_definitions)
  target_compile_definitions(zephyr_interface INTERFACE ${ARGN})
endfunction()

function(zephyr_compile_options)
  target_compile_options(zephyr_interface INTERFACE ${ARGN})
endfunction()

function(zephyr_link_libraries)
  target_link_libraries(zephyr_interface INTERFACE ${ARGN})
endfunction()

# Sources of the core library `zephyr`.
function(zephyr_sources)
  target_sources(zephyr PRIVATE ${ARGN})
endfunction()

function(zephyr_sources_ifdef feature_toggle)
  if(${${feature_toggle}})
    zephyr_sources(${ARGN})
  endif()
endfunction()

function(add_subdirectory_ifdef feature_toggle source_dir)
  if(${${feature_toggle}})
    add_subdirectory(${source_dir} ${ARGN})
  endif()
endfunction()

# Adds a folder only once it holds a CMakeLists.txt, so that parents can name every feature
# folder while features are still being written.
function(safeline_add_subdirectory_if_present source_dir)
  get_filename_component(abs ${source_dir} ABSOLUTE)
  if(EXISTS ${abs}/CMakeLists.txt)
    add_subdirectory(${abs} ${ARGN})
  endif()
endfunction()

function(add_subdirectory_if_kconfig dir)
  string(TOUPPER CONFIG_${dir} kconfig_name)
  string(REPLACE "/" "_" kconfig_name ${kconfig_name})
  add_subdirectory_ifdef(${kconfig_name} ${dir})
endfunction()
