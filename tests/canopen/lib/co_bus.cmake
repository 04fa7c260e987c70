# SPDX-License-Identifier: Apache-2.0
# The multi-line simulated bus shared by the multi-node tests (co_bus.h).
target_sources(app PRIVATE ${CMAKE_CURRENT_LIST_DIR}/co_bus.c)
target_include_directories(app PRIVATE ${CMAKE_CURRENT_LIST_DIR})
