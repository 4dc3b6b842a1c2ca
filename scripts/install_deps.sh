#!/usr/bin/env bash
# Installs the Debian 12 packages the build, the tests and the demo need.
# Idempotent and quiet when everything is already there.
set -euo pipefail

PACKAGES=(
  build-essential cmake catkin
  ros-message-generation ros-message-runtime libroscpp-dev libroslib-dev
  libnodeletlib-dev libnodeletlib-tools
  libimage-transport-dev image-transport-tools libcv-bridge-dev
  libdiagnostic-updater-dev ros-diagnostic-msgs python3-diagnostic-msgs
  librostest-dev python3-rostest libgtest-dev
  python3-roslaunch python3-rosmaster python3-rostopic rosbash
  librosbag-dev python3-rosbag
  ros-std-msgs ros-sensor-msgs python3-sensor-msgs
  libgeometry-msgs-dev ros-geometry-msgs libtf2-msgs-dev ros-tf2-msgs python3-tf2-msgs
  libtf2-dev libtf2-ros-dev python3-tf2-ros libvisualization-msgs-dev ros-visualization-msgs
  python3-geometry-msgs python3-visualization-msgs
  libyaml-cpp-dev libopencv-dev libopencv-contrib-dev libeigen3-dev libboost-program-options-dev
  libimage-geometry-dev
  libstd-srvs-dev python3-std-srvs python3-rosservice
  # image_proc/resize (launch files' resize_scale): Debian puts its nodelet plugin
  # description and the library link pluginlib loads in the -dev package; with
  # ros-image-proc alone the resize cannot load and every nodelet manager logs a
  # pluginlib ERROR about image_proc's nodelet_plugins.xml.
  ros-image-proc libimage-proc-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
)

# ROS from packages.ros.org (Ubuntu 20.04 / Noetic in /opt/ros): its package names are not
# Debian's; rosdep maps package.xml's dependencies to them (after `rosdep init; rosdep update`).
if compgen -G "/opt/ros/*/setup.bash" >/dev/null; then
  repo="$(cd "$(dirname "$0")/.." && pwd)"
  if command -v rosdep >/dev/null && rosdep install --from-paths "$repo" --ignore-src -y -q -r; then
    exit 0
  fi
  echo "install_deps: ROS in /opt/ros: install package.xml's dependencies with" \
       "'rosdep install --from-paths . --ignore-src -y' (the list: README.md, Build notes)" >&2
  exit 0
fi

PACKAGES+=("$@")  # extra packages a target needs (make demo RVIZ=1: rviz)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install_deps: installing ${#missing[@]} package(s): ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
