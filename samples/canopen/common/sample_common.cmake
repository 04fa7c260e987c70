# SPDX-License-Identifier: Apache-2.0
# What the CANopen samples share (--node-id, line device choice, exit statistics).
target_sources(app PRIVATE ${CMAKE_CURRENT_LIST_DIR}/sample_common.c)
target_include_directories(app PRIVATE ${CMAKE_CURRENT_LIST_DIR})
