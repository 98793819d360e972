# SPDX-License-Identifier: MIT
# `cmake --build --preset cortex-m7 --target size_report` prints the code and
# data size of each freestanding library (text/data/bss, as arm-none-eabi-size).
find_program(HRG_SIZE_TOOL NAMES ${HRG_TOOLCHAIN_PREFIX}size arm-none-eabi-size)
set(_libs)
set(_targets)
foreach(lib IN ITEMS hrg_dsp hrg_estimator hrg_firmware_core hrg_firmware_can
                     hrg_firmware_calibration hrg_firmware_app)
  if(TARGET ${lib})
    list(APPEND _libs $<TARGET_FILE:${lib}>)
    list(APPEND _targets ${lib})
  endif()
endforeach()
add_custom_target(size_report
  COMMAND ${CMAKE_COMMAND} -DSIZE_TOOL=${HRG_SIZE_TOOL} "-DLIBS=${_libs}"
          -P ${CMAKE_SOURCE_DIR}/tools/cmake/print_size.cmake
  DEPENDS ${_targets}
  VERBATIM)
