# SPDX-License-Identifier: MIT
# Eigen is header-only and architecture-independent, so every target (host,
# Linux boards, bare metal) uses the Debian copy in /usr/include/eigen3. The
# search ignores the cross sysroot on purpose.
find_path(HRG_EIGEN3_INCLUDE_DIR Eigen/Core
  PATHS /usr/include/eigen3 /usr/local/include/eigen3
  NO_CMAKE_FIND_ROOT_PATH NO_DEFAULT_PATH)
if(NOT HRG_EIGEN3_INCLUDE_DIR)
  message(FATAL_ERROR "Eigen not found: install it with 'apt-get install libeigen3-dev'")
endif()
add_library(hrg_eigen INTERFACE)
add_library(hrg::eigen ALIAS hrg_eigen)
target_include_directories(hrg_eigen SYSTEM INTERFACE ${HRG_EIGEN3_INCLUDE_DIR})
