#!/usr/bin/env bash
# The core tests under AddressSanitizer and UndefinedBehaviorSanitizer (issue 15, item 7): builds
# test_core, test_feature_extractor and test_tools (with the tools test_tools runs: act_replay,
# act_make_scenarios, act_eval, act_calibrate, act_lut) in a workspace of their own, RelWithDebInfo
# with -fsanitize=address,undefined, runs them with leak detection and halt on the first error, and
# exits non-zero on any finding or failed test. Reports go to files (the tools' stderr is often
# hidden by the tests that run them) and are printed at the end; the last line is a summary.
#   scripts/sanitize.sh          test_core, test_feature_extractor, test_tools
#   scripts/sanitize.sh --all    and test_sim (slow; its timing test is left out)
#   scripts/sanitize.sh --ros    the core tests, then every rostest (test/ros) with the nodelets,
#                                the test nodes and the tools instrumented; the nodelet manager
#                                (a system binary) gets the ASan runtime preloaded. Leak detection
#                                is off there: roscpp's and Python's own allocations at exit are
#                                not ours to fix; every other finding halts the process.
# ACT_SANITIZE_WS chooses the workspace (default: ws-sanitize-* beside the normal one).
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
tests=(test_core test_feature_extractor test_tools)
ros=0
targets=()
case "${1:-}" in
  "") ;;
  --all) tests+=(test_sim) ;;
  --ros) ros=1; targets=(tests) ;;
  *) echo "usage: $0 [--all | --ros]" >&2; exit 2 ;;
esac
start=$(date +%s)
ACT_WS=${ACT_SANITIZE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/act_color/ws-sanitize-$(echo "$ACT_ROOT" | md5sum | cut -c1-8)}
export ACT_WS
act_install_deps

# act_build puts its own -DCMAKE_BUILD_TYPE=Release after the caller's arguments, and CMake keeps
# the last: the same steps here, with the sanitizers' build type and flags.
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
# GCC's manual: sanitizers raise the rate of false -Wmaybe-uninitialized warnings (here in
# libstdc++'s <regex>); -Werror stays on for everything else.
cxx_flags="$flags -Wno-error=maybe-uninitialized"
mkdir -p "$ACT_WS/src"
ln -sfn "$ACT_ROOT" "$ACT_WS/src/act_color"
log="$ACT_WS/build.log"
echo "act_color: building ${tests[*]} with $flags in $ACT_WS"
if ! catkin_make -C "$ACT_WS" -j"$(nproc)" "${tests[@]}" "${targets[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS=$cxx_flags" "-DCMAKE_EXE_LINKER_FLAGS=$flags" "-DCMAKE_SHARED_LINKER_FLAGS=$flags" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >"$log" 2>&1; then
  tail -n 80 "$log"
  echo "act_color: sanitizer build failed (full log: $log)" >&2
  exit 1
fi
built=$(date +%s)
act_source_workspace

reports="$ACT_WS/sanitizer-reports"
rm -rf "$reports"
mkdir -p "$reports"
# halt_on_error: the first finding ends the process with a non-zero status; log_path: one file
# per process (pid appended), also for the tools the tests run.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:log_path=$reports/asan"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$reports/ubsan"
# Timing tests measure the instrumented code (2-3x slower), not the package: left out.
timing_tests="Renderer.RendersAFrameWellUnder100Milliseconds"
failed=()
summary=()
cd "$ACT_ROOT"
for t in "${tests[@]}"; do
  t0=$(date +%s)
  echo "act_color: running $t under ASan+UBSan"
  if "$ACT_WS/devel/lib/act_color/$t" --gtest_color=no --gtest_filter="-$timing_tests" >"$reports/$t.out" 2>&1; then
    status=ok
  else
    status="exit $?"
    failed+=("$t")
  fi
  summary+=("$t $status $(($(date +%s) - t0))s")
  grep -E '^\[  (PASSED|FAILED) ' "$reports/$t.out" | sed 's/^/  /' || true
done

if [ $ros = 1 ]; then
  # The rostests as CTest runs them (their arguments, e.g. the test bags), every process under
  # the sanitizers: the instrumented libraries need the ASan runtime first in the process.
  t0=$(date +%s)
  echo "act_color: running the rostests under ASan+UBSan"
  asan_runtime=$(gcc -print-file-name=libasan.so)
  # The replays start their bag after a delay in which the instrumented nodelets (slower to load)
  # and the test must connect, and an image waits ~tf_timeout for its pose: run apart, with more
  # time for both, and the bag at a quarter of its rate (the instrumented code is 2-3x slower, not
  # wrong: at rate 1 the start-up training's 100 cycles outlasted the trainer's queue of 5 images
  # and 3 or 7 of the 48 frames were dropped).
  bag="$ACT_WS/build/act_color/test_bags/driving_small.bag"
  if (cd "$ACT_WS/build" && export LD_PRELOAD="$asan_runtime" \
      ASAN_OPTIONS="detect_leaks=0:halt_on_error=1:log_path=$reports/asan" &&
      ctest -R '^_ctest_act_color_rostest_' -E '_rostest_replay' --output-on-failure &&
      rostest act_color replay.test bag:="$bag" delay:=15 tf_timeout:=0.5 rate:=0.25 &&
      rostest act_color replay_tf.test bag:="$bag" delay:=15 tf_timeout:=0.5 rate:=0.25) >"$reports/rostests.out" 2>&1; then
    status=ok
  else
    status="exit $?"
    failed+=(rostests)
  fi
  tests+=(rostests)
  summary+=("rostests $status $(($(date +%s) - t0))s")
  grep -E 'tests passed|Passed|Failed|RESULT' "$reports/rostests.out" | sed 's/^/  /' || true
fi

shopt -s nullglob
files=("$reports"/asan.* "$reports"/ubsan.*)
for f in "${files[@]}"; do
  echo
  echo "== $f"
  head -n 60 "$f"
done
for t in "${failed[@]}"; do
  echo
  echo "== $t (full output: $reports/$t.out)"
  grep -E -B2 -A12 'Failure|ERROR: |runtime error' "$reports/$t.out" | head -n 80 || tail -n 40 "$reports/$t.out"
done
end=$(date +%s)
echo "sanitize: ${#files[@]} sanitizer reports, ${#failed[@]} of ${#tests[@]} test binaries failed" \
  "(${summary[*]}; build $(((built - start) / 60)) min, total $(((end - start) / 60)) min; reports in $reports)"
[ ${#files[@]} -eq 0 ] && [ ${#failed[@]} -eq 0 ]
