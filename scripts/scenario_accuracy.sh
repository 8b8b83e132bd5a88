#!/usr/bin/env bash
# The README's tables "Accuracy on the simulated scenarios": renders the five small scenarios for
# both simulated cameras (scenario seed 1), replays each with act_replay for ACT seeds 1..N and
# prints one markdown row per scenario: recall/precision after adaptation for ACT seed 1, the range
# over the seeds, and the largest number of cycles each class needed to settle after the
# darkening.
#   scripts/scenario_accuracy.sh [--seeds N]
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
seeds=6
case "${1:-}" in
  "") ;;
  --seeds) seeds=$2 ;;
  *) echo "usage: $0 [--seeds N]" >&2; exit 2 ;;
esac
act_install_deps
act_build
act_source_workspace
for camera in msl_2007_580 msl_2007_640x480; do
  calibration="$ACT_ROOT/config/calibration/$camera.yaml"
  dir="$ACT_WS/scenario_accuracy/$camera"
  mkdir -p "$dir/out"
  [ -f "$dir/static_darkening_small.bag" ] ||
    rosrun act_color act_make_scenarios --calibration "$calibration" --scenario all --length small \
      --output-dir "$dir" >/dev/null
  echo
  echo "$camera.yaml:"
  echo
  echo "| scenario | green | white | yellow | blue | black | settle after the darkening |"
  echo "|---|---|---|---|---|---|---|"
  for scenario in static_darkening wrong_pose driving spotlights sudden_brightening; do
    for seed in $(seq "$seeds"); do
      rosrun act_color act_replay --bag "$dir/${scenario}_small.bag" --calibration "$calibration" \
        --output "$dir/out/$scenario.$seed.bag" --brief --no-progress --seed "$seed" >"$dir/out/$scenario.$seed.txt"
    done
    python3 - "$dir/out" "$scenario" "$seeds" <<'PY'
import re, sys
out, scenario, seeds = sys.argv[1], sys.argv[2], int(sys.argv[3])
classes = ["green", "white", "yellow", "blue", "black"]
runs, settle = [], {}
for seed in range(1, seeds + 1):
    text = open(f"{out}/{scenario}.{seed}.txt").read()
    row = {}
    for k in classes:
        m = re.search(rf"^\s+{k}\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)", text, re.M)
        row[k] = (float(m.group(2)), float(m.group(4))) if m else None
    runs.append(row)
    m = re.search(r"after 'darken'.*?:(.*)$", text, re.M)
    if m:
        for k, n in re.findall(r"(\w+) (\d+)", m.group(1)):
            settle[k] = max(settle.get(k, 0), int(n))
cells = []
for k in classes:
    vals = [r[k] for r in runs if r[k]]
    if not vals:
        cells.append("-")
        continue
    rec = [v[0] for v in vals]; prec = [v[1] for v in vals]
    cells.append(f"{vals[0][0]:.2f}/{vals[0][1]:.2f} ({min(rec):.2f}-{max(rec):.2f} / {min(prec):.2f}-{max(prec):.2f})")
s = ", ".join(f"{k} {settle[k]}" for k in classes if k in settle)
print(f"| {scenario} | " + " | ".join(cells) + f" | {s} |")
PY
  done
done
