#!/usr/bin/env bash
# The main job: the whole pipeline on the package's own simulated omnidirectional camera.
# First the live demo (launch/demo.launch, headless): the simulated camera publishes at 30 Hz
# with changing light, the ACT trainer and the segmentation nodelets run in one manager, and the
# accuracy against the simulator's truth is printed every 2 s (ACT_DEMO_SECONDS, default 30).
# Then it renders the scenario bags (sudden darkening, wrong pose, driving under changing light,
# spotlights and shadows, sudden brightening), runs ACT and the segmentation over each with
# act_replay, and prints per-class recall/precision and the cycles each class needed after every
# light change; the same on a second camera. Last, ACT on a quick subset of the randomized scene
# family's report split (act_eval: defaults, the paper's algorithm and the fixed-table ceiling side
# by side; ACT_EVAL_SCENES, default 10, of the 100; the whole split: act_eval --split report), and
# ACT on the real images of test/data/real (act_real_eval: calibration fitted to each image).
# Installs what is missing and builds first.
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

demo_seconds=${ACT_DEMO_SECONDS:-30}
echo "act_color: live demo, $demo_seconds s: simulated camera -> ACT trainer -> segmentation (one nodelet manager)"
demo_log="$ACT_WS/demo.log"
set +e
(cd "$ACT_WS" && timeout -s INT "$demo_seconds" roslaunch act_color demo.launch scenario:=driving >"$demo_log" 2>&1)
demo_status=$?
set -e
# 124: stopped by the timeout, as intended.
if [ "$demo_status" -ne 124 ] && [ "$demo_status" -ne 0 ]; then
  tail -n 40 "$demo_log"
  echo "act_color: the demo failed (exit $demo_status, log: $demo_log)" >&2
  exit 1
fi
sed -e 's/\x1b\[[0-9;]*m//g' "$demo_log" | grep -E "accuracy( over|:)" | sed -e 's/^\[ INFO\] \[[0-9.]*\]: /  /'
if ! grep -q "accuracy over" "$demo_log"; then
  echo "act_color: the demo printed no accuracy (log: $demo_log)" >&2
  exit 1
fi
echo

# The scenarios on the package's camera, then on a second camera (640x480, off-centre mirror,
# mirrored bearings), which nothing is tuned to.
for camera in msl_2007_580 msl_2007_640x480; do
  calibration="$ACT_ROOT/config/calibration/$camera.yaml"
  if [ "$camera" = msl_2007_580 ]; then
    scenarios="$ACT_WS/scenarios/$length"
  else
    scenarios="$ACT_WS/scenarios/$length-$camera"
  fi
  mkdir -p "$scenarios/out"
  echo
  echo "act_color: rendering the $length scenarios for $camera.yaml into $scenarios"
  rosrun act_color act_make_scenarios --calibration "$calibration" --scenario all --length "$length" \
    --output-dir "$scenarios" --png "$scenarios/png" | sed 's/^/  /'
  for bag in "$scenarios"/*.bag; do
    name=$(basename "$bag" .bag)
    echo
    echo "== $name ($camera)"
    rosrun act_color act_replay --bag "$bag" --calibration "$calibration" \
      --output "$scenarios/out/$name.labels.bag" --csv "$scenarios/out/$name.csv" --brief --no-progress
  done
  echo
  echo "act_color: labels, tables and per-frame CSVs in $scenarios/out, first frames as PNG in $scenarios/png"
done

# Scenes nobody tuned on: the randomized family's report split (issue 11), a quick subset.
eval_scenes=${ACT_EVAL_SCENES:-10}
echo
echo "act_color: the randomized scene family, report split, first $eval_scenes of 100 scenes (act_eval)"
rosrun act_color act_eval --split report --count "$eval_scenes" 2>/dev/null | sed 's/^/  /'

# Real cameras (issue 12): NuBot's lab images, the calibration fitted to each, ACT before and after
# five changes of light, the defaults and the paper side by side.
echo
echo "act_color: real images (test/data/real): calibration from each image, then ACT (act_real_eval)"
rosrun act_color act_real_eval --dir "$ACT_ROOT/test/data/real" 2>/dev/null | sed 's/^/  /'
