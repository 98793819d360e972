# SPDX-License-Identifier: MIT
# hrg_callgrind_count(<out_var> <tag> <function> <args...>)
# Runs ${BENCH} <args...> under callgrind with collection switched on only
# inside <function> and returns its total instruction count (deterministic for
# a given binary and input). Used by the benchmark scripts (cmake -P) that get
# VALGRIND, BENCH and WORK_DIR from the command line.
function(hrg_callgrind_count out_var tag fn)
  set(out_file ${WORK_DIR}/callgrind.${tag})
  execute_process(COMMAND ${VALGRIND} --tool=callgrind --callgrind-out-file=${out_file}
      --toggle-collect=${fn} ${BENCH} ${ARGN}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "callgrind run of ${BENCH} ${ARGN} failed (${rc})")
  endif()
  file(STRINGS ${out_file} totals REGEX "^(summary|totals):")
  list(GET totals 0 line)
  string(REGEX MATCH "[0-9]+" ir "${line}")
  set(${out_var} ${ir} PARENT_SCOPE)
endfunction()
