#!/usr/bin/env bash
# Quick start 1: set up, build, and run the main job headless with a summary: a task plan on
# the simulated UR5 workcell (MuJoCo physics, physical grasps), judged by the run's result.
# Today: the blind pick-and-place (taught waypoints, no perception); the structure assembly
# with perception replaces it when SmartMove lands.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR="${COSTAR_BUILD_DIR:-build}"
echo
"$BUILD_DIR/cli/costar" run examples/ur5/blind_pick_place.xml --workcell ur5-sim \
  --scene sim/scenes/one_node.json --waypoints examples/ur5/blind_waypoints.json "$@"
mkdir -p out
"$BUILD_DIR/cli/costar" sim snapshot sim/scenes/assembly.json --out out/assembly_scene.png
