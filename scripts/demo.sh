#!/usr/bin/env bash
# The main job (make demo): renders a sample sequence unless a bag is given, plays it
# through the nodelet pipeline (roslaunch, rosbag play, simulated time) and prints the
# report of demo_report. Called by the Makefile with the workspace sourced.
#   scripts/demo.sh RESULTS PROFILE FRAMES RVIZ [BAG [TRUTH]]
set -euo pipefail
results=$1 profile=$2 frames=$3 rviz=$4 bag=${5:-} truth=${6:-}
mkdir -p "$results"
if [ -z "$bag" ]; then
  echo "demo: rendering a $frames-image $profile sequence (room, start-up target, ground truth)"
  rosrun mono_plane_detection make_sequence --trajectory "$profile" --frames "$frames" \
    --noise 2 --out "$results/sequence.bag" --quiet
  bag=$results/sequence.bag truth=$results/sequence.yaml
else
  frames=0  # unknown: the report ends when the bag has been silent for a while
fi
log=$results/pipeline.log
echo "demo: playing $bag through tracker + planes (profile $profile); log in $log"
# Own master on a free port, so a running roscore is left alone.
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
roslaunch -p "$port" mono_plane_detection replay.launch bag:="$bag" profile:="$profile" \
  rviz:="$rviz" player_required:=false > "$log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null; wait $launch 2>/dev/null || true' EXIT
for _ in $(seq 100); do rosparam get /use_sim_time >/dev/null 2>&1 && break; sleep 0.2; done
status=0
rosrun mono_plane_detection demo_report planes:=/camera/planes tracks:=/camera/tracks \
  image:=/camera/image_raw _out:="$results" _truth:="$truth" _frames:="$frames" || status=$?
grep -E "ERROR|FATAL" "$log" | head -5 || true
exit $status
