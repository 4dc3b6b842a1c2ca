#!/usr/bin/env bash
# make bench: the benchmark suite (tracker and plane stage against baselines, table and
# plot), the plane stage on the AdelaideRMF dev scenes against sequential MAGSAC, the
# tracker against the floor on generated and real frames (table and plot),
# and the end-to-end latency and resident memory of the nodelet manager (table and
# plot). Figures, never pass/fail.
#   scripts/benchmark.sh RESULTS [DATA]   (the workspace sourced; DATA: the folder with
#   euroc_stereo/, tum_office_frames/ and adelaidermf_dev/, default ../shared/data next to
#   the repository)
set -euo pipefail
results=$1
data=${2:-$(cd "$(dirname "$0")/.." && pwd)/../shared/data}
mkdir -p "$results"
# Both allocator settings: glibc's defaults, and the ones plane_detection.launch sets.
launch_malloc=(MALLOC_MMAP_THRESHOLD_=67108864 MALLOC_TRIM_THRESHOLD_=268435456)
echo "== glibc malloc defaults"
rosrun mono_plane_detection benchmark_suite --plot "$results/benchmark_default_malloc.png"
echo
echo "== MALLOC_MMAP_THRESHOLD_=64 MiB, MALLOC_TRIM_THRESHOLD_=256 MiB (as plane_detection.launch)"
env "${launch_malloc[@]}" rosrun mono_plane_detection benchmark_suite --plot "$results/benchmark.png"
echo
# Real textures: the first EuRoC left image and the first TUM office frame, when there.
real=()
euroc=$(ls "$data"/euroc_stereo/cam0/*.png 2>/dev/null | head -1 || true)
tum=$(ls "$data"/tum_office_frames/*.png 2>/dev/null | head -1 || true)
[ -n "$euroc" ] && real+=(--euroc "$euroc") || echo "(no EuRoC images under $data/euroc_stereo: generated rows only)"
[ -n "$tum" ] && real+=(--tum "$tum") || echo "(no TUM frames under $data/tum_office_frames: generated rows only)"
# The plane stage on real image pairs: the AdelaideRMF dev scenes against sequential MAGSAC.
if ls "$data"/adelaidermf_dev/*.labels > /dev/null 2>&1; then
  echo "== plane stage on real pairs (AdelaideRMF dev scenes) against sequential MAGSAC"
  rosrun mono_plane_detection eval_two_view "$data/adelaidermf_dev" --seeds 5
  echo
else
  echo "(no AdelaideRMF scenes under $data/adelaidermf_dev: no real-pair plane rows)"
fi
echo "== tracker against the floor (glibc malloc defaults)"
rosrun mono_plane_detection benchmark_tracker_floor "${real[@]}" \
  --plot "$results/benchmark_tracker_floor.png"
echo
echo "== the same with the allocator settings plane_detection.launch sets (what the nodelets get)"
env "${launch_malloc[@]}" rosrun mono_plane_detection benchmark_tracker_floor "${real[@]}" \
  --plot "$results/benchmark_tracker_floor_launch_malloc.png"
echo
echo "== the same with the search spread over 5 images (off by default: docs/benchmarks.md, tenth round)"
rosrun mono_plane_detection benchmark_tracker_floor "${real[@]}" --spread 5 \
  --plot "$results/benchmark_tracker_floor_spread.png"
echo
echo "== the same with predict_motion (off by default: docs/benchmarks.md, eighth round)"
rosrun mono_plane_detection benchmark_tracker_floor "${real[@]}" --predict-motion 1 \
  --plot "$results/benchmark_tracker_floor_predict_motion.png"
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
# The manager's process id, for its resident memory: roslaunch names it when it starts.
pid=0
for _ in $(seq 60); do
  # (in the camera's namespace: process[camera/plane_detection_manager-2])
  pid=$(sed -n 's/.*process\[\([^]]*\/\)\{0,1\}plane_detection_manager-[0-9]*\]: started with pid \[\([0-9]*\)\].*/\2/p' \
    "$results/latency_pipeline.log" | head -1)
  [ -n "$pid" ] && break
  pid=0
  sleep 0.5
done
[ "$pid" != 0 ] || echo "benchmark: the manager's process id not found in" \
  "$results/latency_pipeline.log: no resident memory figures" >&2
rosrun mono_plane_detection benchmark_latency --bag "$bag" --rate 30 --pid "$pid" \
  --plot "$results/benchmark_latency.png"
