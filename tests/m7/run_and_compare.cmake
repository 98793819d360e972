# SPDX-License-Identifier: MIT
# Runs the fixed-point suite (RUN: the command as a list), prints its output,
# and fails unless it exits 0 and its digest equals the one in DIGEST_FILE,
# so the host and the Cortex-M7 must produce the same bits.
execute_process(COMMAND ${RUN} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fixed-point suite failed (exit status ${rc})")
endif()
string(REGEX MATCH "digest: ([0-9a-f]+)" m "${out}${err}")
if(NOT m)
  message(FATAL_ERROR "fixed-point suite printed no digest")
endif()
set(got ${CMAKE_MATCH_1})
file(READ ${DIGEST_FILE} expected)
string(STRIP "${expected}" expected)
if(NOT got STREQUAL expected)
  message(FATAL_ERROR "digest ${got} differs from ${expected} in ${DIGEST_FILE}: "
    "the outputs are not the same bits as on the reference platform")
endif()
message("digest ${got} matches ${DIGEST_FILE}")
