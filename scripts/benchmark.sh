#!/usr/bin/env bash
# Benchmarks on this machine: builds first, then
#   1. act_benchmark on 580x580, 640x480 and 1280x1024 simulator frames (ACT cycle, full-frame
#      classification, both nodelets' per-frame path through real in-process publishers, and the
#      CMVision-style and cv::inRange baselines), pinned to one core, table on stdout and
#      results/benchmark.json;
#   2. instructions per ACT cycle under callgrind (act_benchmark --callgrind-cycles N).
# A private rosmaster on a free port is started for the published path and stopped afterwards.
#   scripts/benchmark.sh [--samples N] [--cycles N] [--no-callgrind]
set -eo pipefail
ACT_EXTRA_DEB_PACKAGES="${ACT_EXTRA_DEB_PACKAGES:-} valgrind"
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
samples=31
cycles=200
callgrind=1
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples=$2; shift 2 ;;
    --cycles) cycles=$2; shift 2 ;;
    --no-callgrind) callgrind=0; shift ;;
    *) echo "usage: $0 [--samples N] [--cycles N] [--no-callgrind]" >&2; exit 2 ;;
  esac
done
act_install_deps
act_build
act_source_workspace
bin="$ACT_WS/devel/lib/act_color/act_benchmark"
mkdir -p "$ACT_ROOT/results"

echo "act_color: load before the run: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
# A private master so that the nodelet path is timed with real publishers.
port=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://127.0.0.1:$port"
rosmaster --core -p "$port" >/dev/null 2>&1 &
master_pid=$!
trap 'kill "$master_pid" 2>/dev/null || true' EXIT
for _ in $(seq 50); do
  rosnode list >/dev/null 2>&1 && break
  sleep 0.1
done
cpu=$(( $(nproc) - 1 ))
"$bin" --samples "$samples" --cpu "$cpu" --json "$ACT_ROOT/results/benchmark.json" | tee "$ACT_ROOT/results/benchmark.txt"
kill "$master_pid" 2>/dev/null || true
echo "act_color: load after the run: $(cut -d' ' -f1-3 /proc/loadavg)"

if [ "$callgrind" = 1 ]; then
  out=$(mktemp -d)
  valgrind --tool=callgrind --callgrind-out-file="$out/cg.out" --collect-atstart=no \
    --toggle-collect='*runCallgrindCycles*' "$bin" --callgrind-cycles "$cycles" >"$out/log" 2>&1
  total=$(awk '/^summary:|^totals:/ {print $2; exit}' "$out/cg.out")
  per=$((total / cycles))
  echo "callgrind: $total instructions in $cycles ACT cycles (580x580): $per instructions per cycle" |
    tee "$ACT_ROOT/results/callgrind.txt"
  rm -rf "$out"
fi
