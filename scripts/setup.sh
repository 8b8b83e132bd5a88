#!/usr/bin/env bash
# Sourced by main.sh and test.sh: installs the Debian packages the package needs (only the
# missing ones) and builds it in a catkin workspace outside the sources (one per checkout, under
# ~/.cache/act_color; ACT_WS overrides), whose src/act_color links to this checkout.
# Quiet when everything is already there; the build log is printed only when the build fails.

ACT_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ACT_WS=${ACT_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/act_color/ws-$(basename "$ACT_ROOT")-$(echo "$ACT_ROOT" | md5sum | cut -c1-8)}
export ACT_ROOT ACT_WS
# pyenv's python3 lacks the ROS modules (see shared/ROS_ON_DEBIAN.md).
export PYENV_VERSION=system

ACT_DEB_PACKAGES=(
  build-essential cmake catkin libroscpp-dev libnodeletlib-dev libnodelet-dev libnodeletlib-tools
  pluginlib-dev libimage-transport-dev libcv-bridge-dev libtf2-ros-dev libtf2-geometry-msgs-dev
  libtf2-eigen-dev libsensor-msgs-dev libgeometry-msgs-dev libstd-msgs-dev ros-sensor-msgs
  ros-std-msgs ros-geometry-msgs ros-message-generation ros-message-runtime python3-gencpp
  python3-genmsg python3-genpy librostest-dev python3-rostest python3-roslaunch python3-rosmaster
  rosout python3-rosbag librosbag-dev python3-rostopic python3-rosnode python3-rosparam
  python3-rosservice
  rospack-tools libopencv-dev libeigen3-dev libgtest-dev rosbash python3-rosmsg
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libdiagnostic-updater-dev ros-diagnostic-msgs libbenchmark-dev libvisualization-msgs-dev ros-visualization-msgs catkin-lint
  libdiagnostic-aggregator-tools libdiagnostic-aggregator-dev python3-geometry-msgs python3-sensor-msgs python3-diagnostic-msgs
)

act_install_deps() {
  local missing=() p
  for p in "${ACT_DEB_PACKAGES[@]}" ${ACT_EXTRA_DEB_PACKAGES:-}; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "act_color: installing ${#missing[@]} Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq >/dev/null
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" \
    >"$ACT_ROOT/.apt.log" 2>&1 || { cat "$ACT_ROOT/.apt.log"; return 1; }
}

act_build() {
  mkdir -p "$ACT_WS/src"
  ln -sfn "$ACT_ROOT" "$ACT_WS/src/act_color"
  local log="$ACT_WS/build.log"
  if ! catkin_make -C "$ACT_WS" -j"$(nproc)" "$@" -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >"$log" 2>&1; then
    tail -n 80 "$log"
    echo "act_color: build failed (full log: $log)" >&2
    return 1
  fi
}

act_source_workspace() {
  # devel/setup.bash reads unset variables (ROS_DISTRO): not under set -u.
  set +u
  # shellcheck disable=SC1091
  source "$ACT_WS/devel/setup.bash"
}
