# SPDX-License-Identifier: MIT
# Shared body of the Linux board toolchains. The including file sets
# HRG_TRIPLE (GNU triple), HRG_PROCESSOR, HRG_QEMU (qemu-user binary) and
# HRG_CROSS_PACKAGE (the Debian package that ships the compiler).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR ${HRG_PROCESSOR})

find_program(HRG_CROSS_CXX ${HRG_TRIPLE}-g++)
find_program(HRG_CROSS_CC ${HRG_TRIPLE}-gcc)
if(NOT HRG_CROSS_CXX OR NOT HRG_CROSS_CC)
  message(FATAL_ERROR
    "${HRG_TRIPLE}-g++ not found: install it with 'apt-get install ${HRG_CROSS_PACKAGE}'")
endif()
set(CMAKE_C_COMPILER ${HRG_CROSS_CC})
set(CMAKE_CXX_COMPILER ${HRG_CROSS_CXX})

# Debian multiarch: target libraries live in /usr/lib/<triple>, the C library
# in /usr/<triple>. Host headers in /usr/include are architecture-neutral.
set(CMAKE_FIND_ROOT_PATH /usr/${HRG_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_LIBRARY_ARCHITECTURE ${HRG_TRIPLE})
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/${HRG_TRIPLE}/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "")

# Unit tests run on the build machine under qemu-user.
find_program(HRG_QEMU_USER ${HRG_QEMU})
if(HRG_QEMU_USER)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${HRG_QEMU_USER};-L;/usr/${HRG_TRIPLE})
else()
  message(WARNING "${HRG_QEMU} not found ('apt-get install qemu-user'): "
                  "cross-built tests cannot run on this machine")
endif()
