#!/usr/bin/env bash
# Quick start 1: set up, build, and run the main job headless with a summary.
# Until the simulated UR5 workcell exists this runs the demo plan on the TEST workcell.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR="${COSTAR_BUILD_DIR:-build}"
echo
exec "$BUILD_DIR/cli/costar" run examples/test_workcell/demo.xml --workcell test "$@"
