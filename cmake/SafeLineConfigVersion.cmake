# SPDX-License-Identifier: Apache-2.0
# Any requested version is accepted: the tree is used as it is checked out.
file(READ "${CMAKE_CURRENT_LIST_DIR}/../VERSION" PACKAGE_VERSION)
string(STRIP "${PACKAGE_VERSION}" PACKAGE_VERSION)
set(PACKAGE_VERSION_COMPATIBLE TRUE)
if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
  set(PACKAGE_VERSION_EXACT TRUE)
endif()
