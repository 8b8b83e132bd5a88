#!/usr/bin/env bash
# Runs every test of the package: core gtests (no master), simulator and tool tests, rostests.
# Installs what is missing and builds first. Exits non-zero when any test fails.
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
act_install_deps
act_build
act_build tests
act_source_workspace
cd "$ACT_WS/build"
# catkin_make run_tests exits 0 on failures; ctest does not.
ctest --output-on-failure -j"${ACT_TEST_JOBS:-1}" "$@"
