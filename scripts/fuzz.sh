#!/usr/bin/env bash
# make fuzz: builds the libFuzzer targets (CMake option MPD_FUZZ, in build/ws_fuzz: the
# whole package compiled by clang with -fsanitize=fuzzer-no-link,address,undefined), runs
# each for FUZZ_SECONDS (default 60) from its seed corpus, and prints executions and
# crashes per target. Crash inputs land in build/fuzz/crashes/; exit code 1 when any
# target crashed. FUZZ_TARGETS picks targets (default: all).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=$repo/build/ws_fuzz
out=$repo/build/fuzz
seconds=${FUZZ_SECONDS:-60}
jobs=${JOBS:-2}
targets=${FUZZ_TARGETS:-"groups segment_planes correspondence_parser target_detector plane_pipeline messages"}
mkdir -p "$ws/src" "$out/crashes"
[ -e "$ws/src/mono_plane_detection" ] || ln -sfn "$repo/build/ws/src/mono_plane_detection" "$ws/src/mono_plane_detection"

flags="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer"
source /opt/ros/noetic/setup.bash 2>/dev/null || true
names=()
for t in $targets; do names+=("fuzz_$t"); done
echo "fuzz: building ${names[*]} (log: $ws/build.log)"
(cd "$ws" && CC=clang CXX=clang++ catkin_make -j"$jobs" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
   -DMPD_FUZZ=ON -DCATKIN_ENABLE_TESTING=OFF -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
   -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
   -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" "${names[@]}") \
  > "$ws/build.log" 2>&1 || { tail -30 "$ws/build.log"; exit 1; }

status=0
for t in $targets; do
  bin=$ws/devel/lib/mono_plane_detection/fuzz_$t
  corpus=$out/corpus_$t
  mkdir -p "$corpus" "$repo/test/fuzz/corpus/$t"
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
