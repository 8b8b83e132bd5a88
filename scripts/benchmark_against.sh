#!/usr/bin/env bash
# The ACT cycle of this checkout against another revision's, measured in one run: builds REV
# (default: the last commit before issue 11's work, eece390) in its own workspace, then runs both
# act_benchmark binaries in turn (580x580, one core, three rounds) and prints the medians and
# their ratio (issue 11: at most 1.3x), also for this checkout without issue 13's ball stage.
#   scripts/benchmark_against.sh [REV] [--rounds N]
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
rev=eece390
rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds=$2; shift 2 ;;
    -*) echo "usage: $0 [REV] [--rounds N]" >&2; exit 2 ;;
    *) rev=$1; shift ;;
  esac
done
act_install_deps
act_build
ours="$ACT_WS/devel/lib/act_color/act_benchmark"
base_src="$ACT_WS/baseline-$rev/src"
base_ws="$ACT_WS/baseline-$rev/ws"
if [ ! -x "$base_ws/devel/lib/act_color/act_benchmark" ]; then
  rm -rf "$base_src"
  mkdir -p "$base_src"
  git -C "$ACT_ROOT" archive "$rev" | tar -x -C "$base_src"
  (ACT_ROOT="$base_src" ACT_WS="$base_ws" && export ACT_ROOT ACT_WS && mkdir -p "$ACT_WS/src" &&
    ln -sfn "$ACT_ROOT" "$ACT_WS/src/act_color" &&
    catkin_make -C "$ACT_WS" -j"$(nproc)" act_benchmark -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >"$ACT_WS.log" 2>&1) ||
    { tail -n 40 "$base_ws.log"; echo "act_color: could not build $rev" >&2; exit 1; }
fi
base="$base_ws/devel/lib/act_color/act_benchmark"
cpu=$(( $(nproc) - 1 ))
echo "act_color: ACT cycle at 580x580, $rev vs this checkout, $rounds rounds (load $(cut -d' ' -f1-3 /proc/loadavg))"
declare -a b o n
for _ in $(seq "$rounds"); do
  b+=("$("$base" --no-ros --sizes 580x580 --samples 15 --cpu "$cpu" | awk '$2 == "act_cycle" {print $3}')")
  run=$("$ours" --no-ros --sizes 580x580 --samples 15 --cpu "$cpu")
  o+=("$(awk '$2 == "act_cycle" {print $3}' <<<"$run")")
  n+=("$(awk '$2 == "act_cycle_no_ball" {print $3}' <<<"$run")")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
mb=$(median "${b[@]}")
mo=$(median "${o[@]}")
mn=$(median "${n[@]}")
echo "  $rev: ${b[*]} ms (median $mb)"
echo "  this checkout: ${o[*]} ms (median $mo)"
awk -v b="$mb" -v o="$mo" 'BEGIN {printf "  ratio (this / %s): %.2fx\n", "'"$rev"'", o / b}'
if [ -n "$mn" ]; then
  echo "  this checkout without the ball stage: ${n[*]} ms (median $mn)"
  awk -v b="$mb" -v o="$mn" 'BEGIN {printf "  ratio (this without the ball stage / %s): %.2fx\n", "'"$rev"'", o / b}'
fi
# Instructions per ACT cycle under callgrind: repeatable whatever else the machine does.
if command -v valgrind >/dev/null; then
  cycles=200
  # Instructions per ACT cycle of BIN [ARGS...] under callgrind.
  instructions() {
    local bin=$1 out total
    shift
    out=$(mktemp)
    valgrind --tool=callgrind --callgrind-out-file="$out" --collect-atstart=no \
      --toggle-collect='*runCallgrindCycles*' "$bin" --callgrind-cycles "$cycles" "$@" >/dev/null 2>&1
    total=$(awk '/^summary:|^totals:/ {print $2; exit}' "$out")
    rm -f "$out"
    echo $((total / cycles))
  }
  ins_base=$(instructions "$base")
  ins_ours=$(instructions "$ours")
  # And this checkout without issue 13's ball stage, which came after issue 11's budget was set.
  ins_no_ball=$(instructions "$ours" --no-ball)
  awk -v b="$ins_base" -v o="$ins_ours" -v n="$ins_no_ball" -v r="$rev" \
    'BEGIN {printf "  callgrind: %d instructions per cycle (%s), %d (this checkout): %.3fx; without the ball stage %d: %.3fx\n", b, r, o, o / b, n, n / b}'
fi
