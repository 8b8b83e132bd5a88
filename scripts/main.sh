#!/usr/bin/env bash
# The main job: the whole pipeline on the package's own simulated omnidirectional camera.
# Renders the scenario bags (sudden darkening, wrong pose, driving under changing light,
# spotlights and shadows, sudden brightening), runs ACT and the segmentation over each with
# act_replay, and prints per-class recall/precision and the cycles each class needed after every
# light change. Installs what is missing and builds first.
#   scripts/main.sh            small scenarios (a few dozen frames each, about a minute)
#   scripts/main.sh --full     full-length scenarios (hundreds of frames each)
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
length=small
case "${1:-}" in
  "") ;;
  --full) length=full ;;
  *) echo "usage: $0 [--full]" >&2; exit 2 ;;
esac
act_install_deps
act_build
act_source_workspace

calibration="$ACT_ROOT/config/calibration/msl_2007_580.yaml"
scenarios="$ACT_WS/scenarios/$length"
mkdir -p "$scenarios/out"
echo "act_color: rendering the $length scenarios into $scenarios"
rosrun act_color act_make_scenarios --calibration "$calibration" --scenario all --length "$length" \
  --output-dir "$scenarios" --png "$scenarios/png" | sed 's/^/  /'
for bag in "$scenarios"/*.bag; do
  name=$(basename "$bag" .bag)
  echo
  echo "== $name"
  rosrun act_color act_replay --bag "$bag" --calibration "$calibration" \
    --output "$scenarios/out/$name.labels.bag" --csv "$scenarios/out/$name.csv" --brief --no-progress
done
echo
echo "act_color: labels, tables and per-frame CSVs in $scenarios/out, first frames as PNG in $scenarios/png"
