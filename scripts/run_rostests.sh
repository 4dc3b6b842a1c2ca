#!/usr/bin/env bash
# make test's rostests and launch checks, JOBS at a time, the longest first (the run's wall
# time is otherwise the longest test's, left alone at the end). Each rostest replays images
# in real time through its own manager and master (rostest takes a free port): one uses
# about half a core, so two side by side still keep up on two cores. Each runs through
# catkin's own target, which writes its result file; all output goes to stdout.
# Usage: scripts/run_rostests.sh CATKIN_BUILD_DIR [JOBS]
set -u
build=$1 jobs=${2:-2}
prefix=run_tests_mono_plane_detection_
targets=$(make -C "$build" help | grep -o "${prefix}\(rostest_\|roslaunch-check_\)[^ ]*" | sort -u)
[ -n "$targets" ] || { echo "rostests: no rostest targets in $build"; exit 1; }
# Seconds each took alone (CI, 2026-12): the order to start them in; unknown ones last.
declare -A seconds=([plane_nodelet]=66 [tracker_nodelet]=45 [two_cameras]=32
  [plane_accuracy_humanoid_camera_height]=23 [plane_accuracy_wheeled_auto]=20
  [plane_accuracy_wheeled_camera_height]=20 [plane_accuracy_humanoid_odometry]=19
  [plane_accuracy_wheeled_odometry]=14 [tf_tree]=13 [plane_accuracy_humanoid]=13
  [plane_accuracy_furnished_humanoid]=18 [plane_accuracy_furnished_wheeled]=17
  [plane_accuracy_furnished_wheeled_odometry]=17 [plane_accuracy_wheeled]=12
  [plane_accuracy_humanoid_aruco]=12
  [plane_accuracy_wheeled_aruco]=12 [tf_localiser]=9 [demo_cli]=6 [sequence_playback]=5)
ordered=$(for t in $targets; do
  name=${t##*_test_}; name=${name#nodelets_}; name=${name#ros_}; name=${name#tools_}
  name=${name#sim_}; name=${name%.test}
  echo "${seconds[$name]:-0} $t"
done | sort -rn | cut -d' ' -f2)
# Every test runs even when one fails (xargs goes on, exits non-zero at the end);
# scripts/summarize_tests.sh reports them all.
printf '%s\n' $ordered | xargs -P "$jobs" -I{} make --no-print-directory -C "$build" {}
