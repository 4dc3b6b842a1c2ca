#!/usr/bin/env bash
# The main job (make demo): renders a sample sequence unless a bag is given, plays it
# through the nodelet pipeline (roslaunch, rosbag play, simulated time) and prints the
# report of demo_report. Called by the Makefile with the workspace sourced.
#   scripts/demo.sh RESULTS PROFILE FRAMES RVIZ [BAG [TRUTH]]
# Environment: DEMO_CAMERA (camera namespace, default camera), DEMO_IMAGE (image topic in
# it, default image_raw), DEMO_FIRST_MESSAGE_TIMEOUT (s, default 60).
# Fails fast (exit 2, before anything is started) on an unknown profile, a missing or
# unreadable bag, or a bag without the camera's image or camera_info topic; exits 1
# when the pipeline sends nothing within the timeout.
set -euo pipefail
results=$1 profile=$2 frames=$3 rviz=$4 bag=${5:-} truth=${6:-}
camera=${DEMO_CAMERA:-camera} image=${DEMO_IMAGE:-image_raw}
camera=${camera#/} camera=${camera%/}
image_topic=/$camera/$image info_topic=/$camera/camera_info
config=$(cd "$(dirname "$0")/../config" && pwd)
die() { echo "demo: $*" >&2; exit 2; }

if [ ! -f "$config/tracker_$profile.yaml" ] || [ ! -f "$config/planes_$profile.yaml" ]; then
  known=$(cd "$config" && ls tracker_*.yaml | sed 's/tracker_\(.*\)\.yaml/\1/' | tr '\n' ' ')
  die "unknown profile '$profile' (no config/tracker_$profile.yaml); profiles: $known"
fi
if [ -n "$bag" ]; then
  [ -f "$bag" ] || die "no bag file $bag"
  [ -r "$bag" ] || die "cannot read the bag $bag"
  topics=$(python3 - "$bag" <<'PYTHON'
import sys
import rosbag
try:
    with rosbag.Bag(sys.argv[1]) as bag:
        print('\n'.join(sorted(bag.get_type_and_topic_info().topics)))
except Exception as e:  # not a bag, truncated, unindexed...
    print('demo: cannot read the bag %s: %s' % (sys.argv[1], e), file=sys.stderr)
    sys.exit(2)
PYTHON
) || exit 2
  for topic in "$image_topic" "$info_topic"; do
    grep -qxF "$topic" <<< "$topics" || die "the bag $bag has no topic $topic (it has: \
$(echo $topics)); choose the camera with CAMERA=namespace IMAGE=image_topic_name"
  done
fi

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
echo "demo: playing $bag through tracker + planes (profile $profile, $image_topic); log in $log"
# Own master on a free port, so a running roscore is left alone.
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
status=0
report_args=(--out "$results" --frames "$frames"
  --first-message-timeout "${DEMO_FIRST_MESSAGE_TIMEOUT:-60}")
[ -z "$truth" ] || report_args+=(--truth "$truth")
# The report first: it waits for the master and subscribes as soon as there is one, so it
# hears the bag from its first image (started after the launch, on a loaded machine it
# subscribed after the bag had begun and reported on 23 of 120 images).
rosrun mono_plane_detection demo_report planes:=/$camera/planes tracks:=/$camera/tracks \
  image_planes:=/$camera/image_planes \
  image:="$image_topic" "${report_args[@]}" &
report=$!
# A generated bag (its ground truth known): its true camera joins the map frame's tree.
ground_truth=false
[ -z "$truth" ] || ground_truth=true
roslaunch -p "$port" mono_plane_detection replay.launch bag:="$bag" profile:="$profile" \
  camera:="$camera" image:="$image" rviz:="$rviz" ground_truth:="$ground_truth" \
  player_required:=false > "$log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null; wait $launch 2>/dev/null || true' EXIT
wait $report || status=$?
grep -E "ERROR|FATAL" "$log" | head -5 || true
[ $status -eq 0 ] || echo "demo: failed (exit $status); the pipeline's log: $log" >&2
exit $status
