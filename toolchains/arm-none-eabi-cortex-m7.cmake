# SPDX-License-Identifier: MIT
# Bare-metal Cortex-M7 with double-precision FPU (STM32H7 / i.MX RT class):
# freestanding static libraries, no OS, no heap, no exceptions, no RTTI.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR cortex-m7)

find_program(HRG_M7_CXX arm-none-eabi-g++)
find_program(HRG_M7_CC arm-none-eabi-gcc)
if(NOT HRG_M7_CXX OR NOT HRG_M7_CC)
  message(FATAL_ERROR "arm-none-eabi-g++ not found: install it with "
    "'apt-get install gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib'")
endif()
set(CMAKE_C_COMPILER ${HRG_M7_CC})
set(CMAKE_CXX_COMPILER ${HRG_M7_CXX})
set(HRG_TOOLCHAIN_PREFIX arm-none-eabi-)
# Static libraries only: the compiler checks must not try to link a program.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(_m7 "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
set(CMAKE_C_FLAGS_INIT "${_m7} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${_m7} -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_m7} -Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(HRG_BARE_METAL ON CACHE BOOL "" FORCE)
