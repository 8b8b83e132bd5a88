#!/usr/bin/env bash
# Packaging test (issue 14): a tiny catkin package of a team (act_color_downstream) in a fresh
# workspace on top of act_color's devel space includes every public header and links the
# libraries with only `find_package(catkin REQUIRED COMPONENTS act_color)`. Usage:
#   run.sh DEVEL_SETUP_BASH WORK_DIR CALIBRATION.yaml
set -eo pipefail
setup=$1 work=$2 calibration=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
rm -rf "$work" && mkdir -p "$work/src"
cp -r "$here/act_color_downstream" "$work/src/"
set +u
# shellcheck disable=SC1090
source "$setup"
export PYENV_VERSION=system
if ! catkin_make -C "$work" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
    >"$work/build.log" 2>&1; then
  tail -n 60 "$work/build.log"
  echo "downstream package: build failed (log: $work/build.log)" >&2
  exit 1
fi
"$work/devel/lib/act_color_downstream/uses_act_color" "$calibration"
