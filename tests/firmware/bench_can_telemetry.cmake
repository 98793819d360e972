# SPDX-License-Identifier: MIT
# Instructions per base frame of the CAN telemetry encoder
# (fw::can::TelemetryEncoder::tick at the default rates, with and without
# HRG_CAL_READINGS), and per call of the firmware readings' referral to the
# raw pickoffs (fw::residual_at_raw_pickoffs, once per set of readings),
# counted by callgrind (deterministic).
include(${CMAKE_CURRENT_LIST_DIR}/../../tools/cmake/CallgrindCount.cmake)
set(n 100000)
function(per_unit ir label unit)
  math(EXPR x100 "${ir} * 100 / ${n}")
  math(EXPR whole "${x100} / 100")
  math(EXPR frac "${x100} % 100")
  if(frac LESS 10)
    set(frac "0${frac}")
  endif()
  message("${label}: ${ir} instructions for ${n} ${unit}s = ${whole}.${frac} per ${unit}")
endfunction()
hrg_callgrind_count(all can.all hrg_bench_can_tick all ${n})
per_unit(${all} "tick, default rates" frame)
hrg_callgrind_count(without can.no_readings hrg_bench_can_tick no_readings ${n})
per_unit(${without} "tick, without HRG_CAL_READINGS" frame)
math(EXPR diff "${all} - ${without}")
per_unit(${diff} "HRG_CAL_READINGS in the encoder" frame)
hrg_callgrind_count(ref can.referral hrg_bench_referral referral ${n})
per_unit(${ref} "referral to the raw pickoffs" call)
