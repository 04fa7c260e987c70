# SPDX-License-Identifier: Apache-2.0
#
# canopen_od_generate(<target> EDS <file.eds|file.dcf> [NAME <c_name>])
#
# Runs scripts/eds2od at build time: lints the EDS/DCF (errors as file:line: message) and
# generates <name>_od.c, <name>_od.h and <name>.eds (the EDS as the firmware has it) in
# <build>/canopen_od/<name>/. The source is added to <target> and the folder to its include
# path, so the application includes "<name>_od.h". NAME defaults to the file name.

function(canopen_od_generate target)
  cmake_parse_arguments(ARG "" "EDS;NAME" "" ${ARGN})
  if(NOT ARG_EDS)
    message(FATAL_ERROR "canopen_od_generate(${target} EDS <file>): EDS is required")
  endif()
  get_filename_component(eds ${ARG_EDS} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARG_NAME)
    set(name ${ARG_NAME})
  else()
    get_filename_component(name ${eds} NAME_WE)
    string(MAKE_C_IDENTIFIER ${name} name)
    string(TOLOWER ${name} name)
  endif()
  set(outdir ${CMAKE_CURRENT_BINARY_DIR}/canopen_od/${name})
  file(GLOB generator_sources ${SAFELINE_BASE}/scripts/pylib/eds2od/*.py)
  add_custom_command(
    OUTPUT ${outdir}/${name}_od.c ${outdir}/${name}_od.h ${outdir}/${name}.eds
    COMMAND ${PYTHON_EXECUTABLE} ${SAFELINE_BASE}/scripts/eds2od ${eds} --name ${name}
            -o ${outdir}
    DEPENDS ${eds} ${generator_sources} ${SAFELINE_BASE}/scripts/eds2od
    COMMENT "eds2od: object dictionary '${name}' from ${ARG_EDS}"
    VERBATIM)
  target_sources(${target} PRIVATE ${outdir}/${name}_od.c ${outdir}/${name}_od.h)
  target_include_directories(${target} PRIVATE ${outdir})
endfunction()
