# SPDX-License-Identifier: MIT
# Instructions of the do-no-harm steps, counted by callgrind (deterministic).
# The switch-off step check (fw::PumpEdgeCheck::add_row) per chain block:
# rows with the pump on only, and the standard window plan's cycle (1000 rows
# on, 1000 off: one edge's fits per 2000 rows). The model check
# (fw::Gyro::check_model) per output frame, with the compensation valid and
# with reasons set: the firmware runs it on every frame to get there too, so
# a run of 0 extra calls is taken off.
include(${CMAKE_CURRENT_LIST_DIR}/../../tools/cmake/CallgrindCount.cmake)
function(per_unit ir n label unit)
  math(EXPR x100 "${ir} * 100 / ${n}")
  math(EXPR whole "${x100} / 100")
  math(EXPR frac "${x100} % 100")
  if(frac LESS 10)
    set(frac "0${frac}")
  endif()
  message("${label}: ${ir} instructions for ${n} ${unit}s = ${whole}.${frac} per ${unit}")
endfunction()
set(rows 100000)
foreach(mode on cycle)
  hrg_callgrind_count(ir pump_edge.${mode} hrg_bench_pump_edge ${mode} ${rows})
  per_unit(${ir} ${rows} ${mode} block)
endforeach()
set(calls 100000)
foreach(mode check_valid check_reasons)
  hrg_callgrind_count(base model.${mode}.0 "hrg::fw::Gyro::check_model()" ${mode} 0)
  hrg_callgrind_count(ir model.${mode} "hrg::fw::Gyro::check_model()" ${mode} ${calls})
  math(EXPR ir "${ir} - ${base}")
  per_unit(${ir} ${calls} "Gyro::check_model, ${mode}" call)
endforeach()
