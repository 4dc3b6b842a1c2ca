#!/usr/bin/env bash
# make fuzz: builds the libFuzzer targets of test/fuzz (clang, -fsanitize=fuzzer,address,
# undefined) against the core compiled the same way, runs each for FUZZ_SECONDS
# (default 60) from its seed corpus, and prints executions and crashes per target.
# Crash inputs land in build/fuzz/crashes/; exit code 1 when any target crashed.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$repo/build/fuzz
seconds=${FUZZ_SECONDS:-60}
targets=${FUZZ_TARGETS:-"groups segment_planes correspondence_parser target_detector plane_pipeline"}
mkdir -p "$out/obj" "$out/crashes"
CXX=${CXX_FUZZ:-clang++}
flags=(-std=c++17 -O1 -g -fno-omit-frame-pointer -I"$repo/include" $(pkg-config --cflags opencv4)
       -I/usr/include/eigen3)
libs=($(pkg-config --libs opencv4))

# The core, instrumented for coverage and sanitizers (rebuilt when a source is newer).
objects=()
for src in "$repo"/src/{geometry,tracking,planes,mapping,viz,sim,eval}/*.cpp; do
  obj=$out/obj/$(basename "${src%.cpp}").o
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ -n "$(find "$repo/include" -newer "$obj" -print -quit)" ]; then
    "$CXX" "${flags[@]}" -fsanitize=fuzzer-no-link,address,undefined -c "$src" -o "$obj"
  fi
  objects+=("$obj")
done

status=0
for t in $targets; do
  bin=$out/fuzz_$t
  "$CXX" "${flags[@]}" -fsanitize=fuzzer,address,undefined "$repo/test/fuzz/fuzz_$t.cpp" \
    "${objects[@]}" "${libs[@]}" -o "$bin"
  corpus=$out/corpus_$t
  mkdir -p "$corpus"
  log=$out/fuzz_$t.log
  if "$bin" "$corpus" "$repo/test/fuzz/corpus/$t" -max_total_time="$seconds" -max_len=4096 \
       -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
       -artifact_prefix="$out/crashes/${t}_" > "$log" 2>&1; then
    result=ok
  else
    result="CRASH (see $log)"
    status=1
  fi
  execs=$(grep -m1 "stat::number_of_executed_units" "$log" | awk '{print $2}')
  echo "fuzz $t: ${execs:-?} executions in ${seconds} s, $result"
done
exit $status
