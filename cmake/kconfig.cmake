# SPDX-License-Identifier: Apache-2.0
#
# Kconfig merge, Zephyr's order: board defconfig, CONF_FILE (default prj.conf), the application's
# boards/<board>.conf, EXTRA_CONF_FILE, then CONFIG_* given with -D. scripts/kconfig/kconfig.py
# runs kconfiglib, stops on any error with Kconfig's own message, and writes .config and
# autoconf.h. Every CONFIG_* of the result becomes a CMake variable.

set(DOTCONFIG ${SAFELINE_BINARY_DIR}/.config)
set(AUTOCONF_H ${SAFELINE_GENERATED_DIR}/zephyr/autoconf.h)

if(EXISTS ${APPLICATION_SOURCE_DIR}/Kconfig)
  set(KCONFIG_ROOT ${APPLICATION_SOURCE_DIR}/Kconfig)
else()
  set(KCONFIG_ROOT ${SAFELINE_BASE}/Kconfig)
endif()

if(NOT DEFINED CONF_FILE AND DEFINED ENV{CONF_FILE})
  set(CONF_FILE $ENV{CONF_FILE})
endif()
if(DEFINED CONF_FILE)
  set(CONF_FILE ${CONF_FILE} CACHE STRING "Application Kconfig fragments (default: prj.conf)")
  string(REPLACE " " ";" conf_files "${CONF_FILE}")
elseif(EXISTS ${APPLICATION_SOURCE_DIR}/prj_${BOARD}.conf)
  set(conf_files ${APPLICATION_SOURCE_DIR}/prj_${BOARD}.conf)
elseif(EXISTS ${APPLICATION_SOURCE_DIR}/prj.conf)
  set(conf_files ${APPLICATION_SOURCE_DIR}/prj.conf)
else()
  set(conf_files "")
endif()

set(kconfig_fragments ${BOARD_DIR}/${BOARD}_defconfig)
foreach(f ${conf_files})
  get_filename_component(f ${f} ABSOLUTE BASE_DIR ${APPLICATION_SOURCE_DIR})
  list(APPEND kconfig_fragments ${f})
endforeach()
if(EXISTS ${APPLICATION_SOURCE_DIR}/boards/${BOARD}.conf)
  list(APPEND kconfig_fragments ${APPLICATION_SOURCE_DIR}/boards/${BOARD}.conf)
endif()

if(NOT DEFINED EXTRA_CONF_FILE AND DEFINED ENV{EXTRA_CONF_FILE})
  set(EXTRA_CONF_FILE $ENV{EXTRA_CONF_FILE})
endif()
if(DEFINED EXTRA_CONF_FILE)
  set(EXTRA_CONF_FILE ${EXTRA_CONF_FILE} CACHE STRING "Extra Kconfig fragments, merged last")
  string(REPLACE " " ";" extra_files "${EXTRA_CONF_FILE}")
  foreach(f ${extra_files})
    get_filename_component(f ${f} ABSOLUTE BASE_DIR ${APPLICATION_SOURCE_DIR})
    list(APPEND kconfig_fragments ${f})
  endforeach()
endif()

foreach(f ${kconfig_fragments})
  if(NOT EXISTS ${f})
    message(FATAL_ERROR "Kconfig fragment not found: ${f}")
  endif()
endforeach()

# -DCONFIG_X=v from the command line or the cache become the last fragment.
set(cli_fragment ${SAFELINE_BINARY_DIR}/misc/generated/extra_kconfig_options.conf)
set(cli_text "")
get_cmake_property(cache_vars CACHE_VARIABLES)
foreach(var ${cache_vars})
  if(var MATCHES "^CONFIG_")
    # As given, like Zephyr: string values need their quotes, -DCONFIG_X=\"text\".
    string(APPEND cli_text "${var}=${${var}}\n")
  endif()
endforeach()
file(CONFIGURE OUTPUT ${cli_fragment} CONTENT "${cli_text}")
list(APPEND kconfig_fragments ${cli_fragment})

set(kconfig_env
  srctree=${SAFELINE_BASE}
  SAFELINE_BASE=${SAFELINE_BASE}
  BOARD=${BOARD}
  BOARD_DIR=${BOARD_DIR}
  KCONFIG_CONFIG=${DOTCONFIG}
  APPLICATION_SOURCE_DIR=${APPLICATION_SOURCE_DIR})

execute_process(
  COMMAND ${CMAKE_COMMAND} -E env ${kconfig_env}
    ${PYTHON_EXECUTABLE} ${SAFELINE_BASE}/scripts/kconfig/kconfig.py
    --kconfig ${KCONFIG_ROOT}
    --config ${DOTCONFIG}
    --autoconf ${AUTOCONF_H}
    --sources ${SAFELINE_BINARY_DIR}/misc/generated/kconfig_sources.txt
    ${kconfig_fragments}
  WORKING_DIRECTORY ${APPLICATION_SOURCE_DIR}
  RESULT_VARIABLE kconfig_result)
if(NOT kconfig_result EQUAL 0)
  message(FATAL_ERROR "Kconfig failed: see the messages above")
endif()

# Re-run CMake when a fragment, a Kconfig file or the .config (menuconfig) changes.
file(STRINGS ${SAFELINE_BINARY_DIR}/misc/generated/kconfig_sources.txt kconfig_sources)
set_property(DIRECTORY ${APPLICATION_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
  ${kconfig_fragments} ${kconfig_sources} ${DOTCONFIG})

# CONFIG_* become CMake variables (y -> y, strings without quotes).
file(STRINGS ${DOTCONFIG} dotconfig_lines REGEX "^CONFIG_")
foreach(line ${dotconfig_lines})
  if(line MATCHES "^(CONFIG_[A-Za-z0-9_]+)=\"?([^\"]*)\"?$")
    set(${CMAKE_MATCH_1} "${CMAKE_MATCH_2}")
  endif()
endforeach()

foreach(tool menuconfig guiconfig)
  add_custom_target(${tool}
    COMMAND ${CMAKE_COMMAND} -E env ${kconfig_env}
      ${PYTHON_EXECUTABLE} -m ${tool} ${KCONFIG_ROOT}
    WORKING_DIRECTORY ${APPLICATION_SOURCE_DIR}
    USES_TERMINAL
    COMMENT "Kconfig ${tool}: saved changes to ${DOTCONFIG} apply at the next build")
endforeach()
