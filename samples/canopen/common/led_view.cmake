# SPDX-License-Identifier: Apache-2.0
# The live LED view of the indicators and commissioning samples (--live, led_view.h).
target_sources(app PRIVATE ${CMAKE_CURRENT_LIST_DIR}/led_view.c)
target_include_directories(app PRIVATE ${CMAKE_CURRENT_LIST_DIR})
