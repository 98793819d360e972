# SPDX-License-Identifier: MIT
# Instructions per chain block of the switch-off step check
# (fw::PumpEdgeCheck::add_row), counted by callgrind (deterministic): rows
# with the pump on only, and the standard window plan's cycle (1000 rows on,
# 1000 off: one edge's fits per 2000 rows).
include(${CMAKE_CURRENT_LIST_DIR}/../../tools/cmake/CallgrindCount.cmake)
set(rows 100000)
foreach(mode on cycle)
  hrg_callgrind_count(ir pump_edge.${mode} hrg_bench_pump_edge ${mode} ${rows})
  math(EXPR per_row_x100 "${ir} * 100 / ${rows}")
  math(EXPR whole "${per_row_x100} / 100")
  math(EXPR frac "${per_row_x100} % 100")
  if(frac LESS 10)
    set(frac "0${frac}")
  endif()
  message("${mode}: ${ir} instructions for ${rows} rows = ${whole}.${frac} per block")
endforeach()
