#!/usr/bin/env bash
# The paper's experiments (section 3) on the package's simulator, as CSV and PNG in results/:
#   fig1_zeta.csv, fig1_xi.csv, fig1_{zeta,xi}_{ours,paper}.png     fitness (eq. 6) vs zeta and xi
#   fig23_darkening.csv, fig23_darkening_{ours,paper}.png           50% darkening, recall per cycle
#   fig4_wrong_pose.csv, fig4_wrong_pose_{ours,paper}.png           wrong pose vs right pose
#   summary.md                                                      tables against the paper's numbers
# Each with our defaults and with the paper's algorithm (act_replay --paper), and a static table
# (trained once, then frozen) for contrast. Installs what is missing and builds first.
#   scripts/reproduce.sh [--only fig1|fig23|fig4]
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
act_install_deps
act_build
act_source_workspace
mkdir -p "$ACT_ROOT/results"
"$ACT_WS/devel/lib/act_color/act_reproduce" --calibration "$ACT_ROOT/config/calibration/msl_2007_580.yaml" \
  --output-dir "$ACT_ROOT/results" "$@"
