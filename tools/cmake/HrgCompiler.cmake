# SPDX-License-Identifier: MIT
# Warnings, sanitizers and the compiler cache, applied through one interface
# target so every library of the project is compiled the same way.
add_library(hrg_build_flags INTERFACE)
add_library(hrg::build_flags ALIAS hrg_build_flags)

target_compile_options(hrg_build_flags INTERFACE
  -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion)
if(HRG_WERROR)
  target_compile_options(hrg_build_flags INTERFACE -Werror)
endif()
if(HRG_SANITIZE)
  target_compile_options(hrg_build_flags INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(hrg_build_flags INTERFACE -fsanitize=address,undefined)
endif()
if(HRG_BARE_METAL)
  target_compile_options(hrg_build_flags INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti -fno-threadsafe-statics>)
  target_compile_definitions(hrg_build_flags INTERFACE EIGEN_NO_MALLOC EIGEN_NO_IO
    HRG_BARE_METAL=1)
endif()

find_program(HRG_CCACHE ccache)
if(HRG_CCACHE)
  set(CMAKE_C_COMPILER_LAUNCHER ${HRG_CCACHE})
  set(CMAKE_CXX_COMPILER_LAUNCHER ${HRG_CCACHE})
endif()
