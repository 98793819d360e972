# SPDX-License-Identifier: MIT
# Instructions per call (one demodulated block) of the pickoff correction and
# the feedthrough removal, and of the chain's whole correction stage
# (dsp::ElectronicsCorrection::apply), counted by callgrind (deterministic).
include(${CMAKE_CURRENT_LIST_DIR}/../../tools/cmake/CallgrindCount.cmake)
set(calls 100000)
foreach(mode pickoff_q31 pickoff_f64 feedthrough_q31 feedthrough_f64 stage_q31 stage_f32)
  hrg_callgrind_count(ir correction.${mode} hrg_bench_${mode} ${mode} ${calls})
  math(EXPR per_call_x100 "${ir} * 100 / ${calls}")
  math(EXPR whole "${per_call_x100} / 100")
  math(EXPR frac "${per_call_x100} % 100")
  if(frac LESS 10)
    set(frac "0${frac}")
  endif()
  message("${mode}: ${ir} instructions for ${calls} calls = ${whole}.${frac} per block")
endforeach()
