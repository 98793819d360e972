# SPDX-License-Identifier: MIT
# Instructions per estimator step, counted by callgrind (deterministic, x86-64
# host build; a Cortex-M7 with a double FPU runs a comparable count).
include(${CMAKE_CURRENT_LIST_DIR}/../../tools/cmake/CallgrindCount.cmake)
function(count op fn count per what)
  hrg_callgrind_count(ir estimator.${op} ${fn} ${op} ${count})
  math(EXPR each "${ir} / ${per}")
  message("estimator ${what}: ${ir} instructions / ${per} = ${each} per call")
endfunction()
# add_sample over 3000-sample windows, 4 repetitions
count(sample hrg_bench_est_sample 4 12000 "add_sample (1 kHz, settled sample)")
count(window hrg_bench_est_window 1 1 "end_window + add_window (once per window)")
count(solve hrg_bench_est_solve 100 100 "solve joint 5x5 (conditioning, LDLT, covariance)")
count(solve_alt hrg_bench_est_solve 20 20 "solve alternating (eqs. 18-19 to convergence)")
count(output hrg_bench_est_output 10000 10000 "DriftCompensator::step (1 kHz drift compensation)")
count(selfcal_sample hrg_bench_selfcal_sample 4 12000 "pickoff self-calibration add_sample (1 kHz, in windows)")
count(selfcal_solve hrg_bench_selfcal_solve 100 100 "pickoff self-calibration solve (5x5, after each window)")
count(selfcal_checks hrg_bench_selfcal_checks 100 100 "readout checks on each solve (damping disagreement + pattern sigmas)")
count(selfcal_weigh hrg_bench_selfcal_weigh 100 100 "self-calibration round's weighing (evidence-weighted map + step)")
count(modelcheck_sample hrg_bench_modelcheck_sample 4 12000 "damping model check add_sample (1 kHz, in windows)")
count(modelcheck_solve hrg_bench_modelcheck_solve 100 100 "damping model check solve (4x4, after each window)")
count(pumpdrift_sample hrg_bench_pumpdrift_sample 60000 60000 "pump drift fit add_sample + d_phi (1 kHz, excitation on; folds every 10 s)")
count(knowngap_step hrg_bench_knowngap_step 10000 10000 "KnownGapDrift::step (1 kHz, known gap's D_Phi)")
