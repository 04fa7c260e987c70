# SPDX-License-Identifier: Apache-2.0
# --hb and --hb-consumer, for the samples that have them (hb_options.h).
target_sources(app PRIVATE ${CMAKE_CURRENT_LIST_DIR}/hb_options.c)
target_include_directories(app PRIVATE ${CMAKE_CURRENT_LIST_DIR})
