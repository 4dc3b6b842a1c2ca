#!/usr/bin/env bash
# make bench: the benchmark suite (tracker and plane stage against baselines, table and
# plot) and the end-to-end latency through the nodelet manager. Figures, never pass/fail.
#   scripts/benchmark.sh RESULTS   (the workspace sourced)
set -euo pipefail
results=$1
mkdir -p "$results"
# Both allocator settings: glibc's defaults, and the ones plane_detection.launch sets.
echo "== glibc malloc defaults"
rosrun mono_plane_detection benchmark_suite --plot "$results/benchmark_default_malloc.png"
echo
echo "== MALLOC_MMAP_THRESHOLD_=64 MiB, MALLOC_TRIM_THRESHOLD_=256 MiB (as plane_detection.launch)"
MALLOC_MMAP_THRESHOLD_=67108864 MALLOC_TRIM_THRESHOLD_=268435456 \
  rosrun mono_plane_detection benchmark_suite --plot "$results/benchmark.png"
echo
bag=$results/latency_sequence.bag
[ -f "$bag" ] || rosrun mono_plane_detection make_sequence --trajectory wheeled --frames 300 \
  --noise 2 --out "$bag" --quiet
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
roslaunch -p "$port" mono_plane_detection plane_detection.launch profile:=wheeled \
  > "$results/latency_pipeline.log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null; wait $launch 2>/dev/null || true' EXIT
rosrun mono_plane_detection benchmark_latency --bag "$bag" --rate 30
