#!/usr/bin/env bash
# Quick start 1: set up, build, and run the main job headless with a summary: the paper's UR5
# structure assembly (a node at the base, a long link on it, a node on top) on the simulated
# workcell (MuJoCo physics, physical grasps, perception from the simulated RGB-D camera).
#   1. one run of examples/ur5/assemble_structure.xml with every node's status as it changes;
#   2. COSTAR_TRIALS (default 10) trials with random part placements and sensor noise, judged
#      from the simulator's true final state: success rate, failure reasons, cycle times
#      (out/assembly_trials.json, out/assembly_trials.png);
#   3. pictures: the scene (out/assembly_scene.png) and what DetectObjects finds in it
#      (out/assembly_detections.png).
# Extra arguments go to the single run (e.g. --seed 7).
# It builds only the two executables (and the models and cell descriptions they read); the tests
# and benchmarks are built by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh costar costar-robot
BUILD_DIR="${COSTAR_BUILD_DIR:-build}"
COSTAR="$BUILD_DIR/cli/costar"
TRIALS="${COSTAR_TRIALS:-10}"
mkdir -p out

echo
echo "== 1/3: the structure assembly, one run"
"$COSTAR" run examples/ur5/assemble_structure.xml --workcell ur5-sim --scene sim/scenes/assembly.json "$@"

echo
echo "== 2/3: $TRIALS trials (random placements, any yaw, sensor noise)"
"$COSTAR" trials examples/ur5/assemble_structure.xml --judge assembly -n "$TRIALS" \
  --json out/assembly_trials.json --plot out/assembly_trials.png

echo
echo "== 3/3: pictures"
"$COSTAR" sim snapshot sim/scenes/assembly.json --out out/assembly_scene.png
"$COSTAR" perception detect sim/scenes/assembly.json --out out/assembly_detections.png
