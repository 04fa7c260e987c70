# SPDX-License-Identifier: Apache-2.0
#
# canopen_concise_dcf(<target> DCF <slave.dcf> [NAME <c_name>] [NODE_ID <id>] [DEFAULTS] [SAVE])
#
# Runs scripts/dcf2cdcf at build time: checks the slave's DCF (errors as file:line: message)
# and turns it into the concise DCF of CiA 302 §6.2 (the stream the configuration manager
# serves as 1F22h and downloads to the slave). Generates <name>_cdcf.c, <name>_cdcf.h and
# <name>.bin in <build>/canopen_cdcf/<name>/; the source is added to <target> and the folder
# to its include path, so the application includes "<name>_cdcf.h" and registers
# `<name>_cdcf` with co_cfg_set_concise_dcf(). NAME defaults to the file name.
#   NODE_ID   node-ID for $NODEID values (default: the DCF's [DeviceComissioning] NodeID)
#   DEFAULTS  also send writable objects that have only a DefaultValue
#   SAVE      end with 1010h:01 = "save"

function(canopen_concise_dcf target)
  cmake_parse_arguments(ARG "DEFAULTS;SAVE" "DCF;NAME;NODE_ID" "" ${ARGN})
  if(NOT ARG_DCF)
    message(FATAL_ERROR "canopen_concise_dcf(${target} DCF <file>): DCF is required")
  endif()
  get_filename_component(dcf ${ARG_DCF} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARG_NAME)
    set(name ${ARG_NAME})
  else()
    get_filename_component(name ${dcf} NAME_WE)
    string(MAKE_C_IDENTIFIER ${name} name)
    string(TOLOWER ${name} name)
  endif()
  set(opts)
  if(DEFINED ARG_NODE_ID)
    list(APPEND opts --node-id ${ARG_NODE_ID})
  endif()
  if(ARG_DEFAULTS)
    list(APPEND opts --defaults)
  endif()
  if(ARG_SAVE)
    list(APPEND opts --save)
  endif()
  set(outdir ${CMAKE_CURRENT_BINARY_DIR}/canopen_cdcf/${name})
  file(GLOB generator_sources ${SAFELINE_BASE}/scripts/pylib/cdcf/*.py
       ${SAFELINE_BASE}/scripts/pylib/eds2od/*.py)
  add_custom_command(
    OUTPUT ${outdir}/${name}_cdcf.c ${outdir}/${name}_cdcf.h ${outdir}/${name}.bin
    COMMAND ${PYTHON_EXECUTABLE} ${SAFELINE_BASE}/scripts/dcf2cdcf ${dcf} --name ${name}
            --c-dir ${outdir} -o ${outdir}/${name}.bin ${opts}
    DEPENDS ${dcf} ${generator_sources} ${SAFELINE_BASE}/scripts/dcf2cdcf
    COMMENT "dcf2cdcf: concise DCF '${name}' from ${ARG_DCF}"
    VERBATIM)
  target_sources(${target} PRIVATE ${outdir}/${name}_cdcf.c ${outdir}/${name}_cdcf.h)
  target_include_directories(${target} PRIVATE ${outdir})
endfunction()
