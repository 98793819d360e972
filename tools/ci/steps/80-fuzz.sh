#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# libFuzzer (Debian's clang) with AddressSanitizer and UndefinedBehaviorSanitizer
# on the CAN command decoder, the candump -l log reader, the DBC parser, the
# hrg-recording reader (CSV and gzip) and the scenario (TOML) reader, for a
# bounded time each (HRG_FUZZ_SECONDS, default 30). Fails on any crash,
# sanitizer finding or broken invariant. Seeds are the protocol's own frames
# and files, the shared example recordings (HRG_SHARED_DIR, default ../shared;
# a recording the main job writes when they are absent) and the scenario
# library; findings are kept in build/fuzz/ for reproduction.
set -euo pipefail
seconds=${HRG_FUZZ_SECONDS:-30}
out=${HRG_FUZZ_DIR:-build/fuzz}
mkdir -p "$out"
command -v clang++ >/dev/null || { echo "fuzz: clang++ missing (apt-get install clang)" >&2; exit 1; }
flags=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
  -Ihal/include -Idsp/include -Ifirmware/include -Ifirmware/can/include -Itools)
can_src=(firmware/can/src/signal.cpp firmware/can/src/messages.cpp firmware/can/src/command.cpp
  firmware/can/src/telemetry.cpp)
clang++ "${flags[@]}" tests/fuzz/fuzz_command_decoder.cpp "${can_src[@]}" \
  -o "$out/fuzz_command_decoder" &
clang++ "${flags[@]}" tests/fuzz/fuzz_candump_reader.cpp tools/can/candump_log.cpp \
  -o "$out/fuzz_candump_reader" &
clang++ "${flags[@]}" tests/fuzz/fuzz_dbc_parser.cpp tools/can/dbc.cpp \
  -o "$out/fuzz_dbc_parser" &
wait %1 && wait %2 && wait %3
clang++ "${flags[@]}" -Itools/recording/include tests/fuzz/fuzz_recording_reader.cpp \
  tools/recording/src/recording.cpp tools/recording/src/recording_writer.cpp -lz \
  -o "$out/fuzz_recording_reader" &
# toml++'s own assertions are off behind toml_text/ (upstream
# marzer/tomlplusplus#301); everything else is checked.
clang++ "${flags[@]}" -Isim_target/include -Itoml_text/include -I/usr/include/eigen3 \
  tests/fuzz/fuzz_scenario_reader.cpp sim_target/src/scenario.cpp sim_target/src/profile.cpp \
  toml_text/src/toml_text.cpp -o "$out/fuzz_scenario_reader" &
wait %1 && wait %2

# Seeds.
mkdir -p "$out/seed-command" "$out/seed-candump" "$out/seed-dbc"
# Controller state (operate, 1 V) + STATUS_REQUEST, WINDOW and AGC frames with
# valid CRCs (bit 7 of the length byte asks the harness to seal them).
printf '\x03\x00\x00\x80\x04\x80\x82\x01\x00\x00\x00\x00\x00\x00\x00\x02\x80\x86\x0a\x00\xc8\x00\x02\x00\x00\x00' \
  > "$out/seed-command/status-window"
printf '(0000000001.000000) can0 100#0102030405060708\n(0000000001.000500) can0 090#84103002\n(1.5) can0 20000040#0000000000000000\n(2.0) can1 1ABCDEF0#R\n' \
  > "$out/seed-candump/log"
cp firmware/can/hrg.dbc "$out/seed-dbc/hrg.dbc"
# Recordings: the head of each shared example as CSV, gzip and cut gzip (the
# whole files are larger than -max_len).
mkdir -p "$out/seed-recording" "$out/seed-scenario"
shared=${HRG_SHARED_DIR:-../shared}/examples
examples=("$shared"/*.csv.gz)
if [ ! -e "${examples[0]}" ]; then
  echo "fuzz: no shared examples in $shared; seeding from a main-job recording"
  tools/ci/preset.sh host --no-test --target hrg >/dev/null
  build/host/bin/hrg sim --duration 2 --out "$out/sim-seed" --no-plots --quiet || true
  gzip -c "$out/sim-seed/telemetry.csv" >"$out/sim-seed/telemetry.csv.gz"
  examples=("$out/sim-seed/telemetry.csv.gz")
fi
for f in "${examples[@]}"; do
  n=$(basename "$f" .csv.gz)
  { zcat "$f" || true; } | head -n 30 >"$out/seed-recording/$n.csv"
  gzip -9 -c "$out/seed-recording/$n.csv" >"$out/seed-recording/$n.csv.gz"
  head -c 200 "$out/seed-recording/$n.csv.gz" >"$out/seed-recording/$n-cut.csv.gz"
done
# Scenarios: the library, without the comments' slashes (see the target).
for f in sim_target/scenarios/*.toml; do
  tr -d '/' <"$f" >"$out/seed-scenario/$(basename "$f")"
done

fail=0
run() {  # run NAME SEED_DIR SECONDS
  local name=$1 seeds=$2 t=$3
  mkdir -p "$out/corpus-$name"
  if "$out/$name" -max_total_time="$t" -print_final_stats=1 -artifact_prefix="$out/$name-" \
      -max_len=4096 -timeout=10 "$out/corpus-$name" "$seeds" >"$out/$name.log" 2>&1; then
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$name.log")
    echo "fuzz: $name ok: $execs executions in $t s, no crash, no sanitizer finding"
  else
    echo "fuzz: $name FAILED"
    grep -E 'ERROR|SUMMARY|runtime error|deadly signal' "$out/$name.log" | head -n 20
    return 1
  fi
}
# Each fuzzer is single-threaded: two at a time keep both cores of the CI
# machine busy and halve the step. Each pair's lines print when it ends.
pair() {  # pair "NAME SEEDS SECONDS" ["NAME SEEDS SECONDS"]
  local pids=() logs=() i=0 spec
  for spec in "$@"; do
    # shellcheck disable=SC2086
    ( run $spec ) >"$out/pair-$i.txt" &
    pids+=($!); logs+=("$out/pair-$i.txt"); i=$((i + 1))
  done
  for i in "${!pids[@]}"; do
    wait "${pids[$i]}" || fail=1
    cat "${logs[$i]}"
  done
}
pair "fuzz_command_decoder $out/seed-command $seconds" \
  "fuzz_candump_reader $out/seed-candump $seconds"
pair "fuzz_recording_reader $out/seed-recording $seconds" \
  "fuzz_scenario_reader $out/seed-scenario $seconds"
pair "fuzz_dbc_parser $out/seed-dbc $(( (seconds + 1) / 2 ))"
exit $fail
