# SPDX-License-Identifier: Apache-2.0
# The simulated-time test harness shared by the service tests (co_sim.h).
target_sources(app PRIVATE ${CMAKE_CURRENT_LIST_DIR}/co_sim.c)
target_include_directories(app PRIVATE ${CMAKE_CURRENT_LIST_DIR})
