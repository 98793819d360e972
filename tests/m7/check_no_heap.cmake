# SPDX-License-Identifier: MIT
# Fails when the bare-metal image links a heap or exception machinery: the
# chain and its kernels must run without malloc/new (NM, ELF).
execute_process(COMMAND ${NM} ${ELF} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NM} failed on ${ELF}")
endif()
string(REGEX MATCHALL "[ \t](malloc|calloc|realloc|free|_Znwj|_Znaj|_sbrk|__cxa_throw|__cxa_allocate_exception)\n" bad "${syms}")
if(bad)
  message(FATAL_ERROR "the bare-metal image links heap or exception symbols:${bad}")
endif()
message("no heap and no exception symbols in ${ELF}")
