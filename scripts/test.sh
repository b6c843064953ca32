#!/usr/bin/env bash
# Quick start 2: set up, build, and run every test: unit and end-to-end tests (CTest), a subset
# of them again under the address + UB sanitizers (SANITIZE=all: every test; SANITIZE=0: none),
# the plan-parser, API and end-to-end server fuzz targets in smoke mode (libFuzzer, clang,
# address + UB sanitizers), and the editor's page (Vitest, then end to end in headless Chromium).
#   FUZZ_RUNS=20000 (default) sets the smoke run's length; FUZZ_RUNS=0 skips it.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
bash scripts/setup.sh
BUILD_DIR="${COSTAR_BUILD_DIR:-build}"
# The tests keep their state (taught waypoints, the editor's runs) in a folder of their own: what a
# user taught in ~/.local/state/costar neither changes what they see nor is written by them.
XDG_STATE_HOME=$(mktemp -d "${TMPDIR:-/tmp}/costar_test_state.XXXXXX")
export XDG_STATE_HOME

echo
echo "test: CTest"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 600

# AddressSanitizer + UndefinedBehaviorSanitizer (clang, -DCOSTAR_SANITIZE=ON, its own build
# folder): the tests labelled "sanitize" (core, world, bt, component, gripper, planning, arm and
# sim: the plan, scene and waypoint parsers, the simulation, rendering on two threads).
# SANITIZE=all builds and runs every test so instead (docs/TESTING.md); SANITIZE=0 skips it.
SANITIZE="${SANITIZE:-subset}"
if [[ "$SANITIZE" != "0" ]]; then
  echo
  echo "test: under AddressSanitizer + UndefinedBehaviorSanitizer ($SANITIZE)"
  sanitize_start=$(date +%s)
  CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR-sanitize" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCOSTAR_SANITIZE=ON -DCOSTAR_BUILD_BENCH=OFF \
    -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache \
    -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
  if [[ "$SANITIZE" == "all" ]]; then
    cmake --build "$BUILD_DIR-sanitize" -j "$(nproc)"
    ctest --test-dir "$BUILD_DIR-sanitize" --output-on-failure -j "$(nproc)" --timeout 3600
  else
    cmake --build "$BUILD_DIR-sanitize" --target sanitize_tests -j "$(nproc)"
    ctest --test-dir "$BUILD_DIR-sanitize" -L sanitize --output-on-failure -j "$(nproc)" --timeout 1800
  fi
  echo "test: sanitizers done in $(( $(date +%s) - sanitize_start )) s"
fi

FUZZ_RUNS="${FUZZ_RUNS:-20000}"
if [[ "$FUZZ_RUNS" -gt 0 ]]; then
  echo
  echo "test: fuzzing the plan parser, $FUZZ_RUNS runs (smoke mode)"
  CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR-fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCOSTAR_BUILD_FUZZ=ON -DCOSTAR_BUILD_TESTS=OFF -DCOSTAR_BUILD_BENCH=OFF \
    -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache \
    -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
  cmake --build "$BUILD_DIR-fuzz" --target plan_parser_fuzz -j "$(nproc)"
  corpus=$(mktemp -d)
  trap 'rm -rf "$corpus"' EXIT
  cp fuzz/corpus/plan_parser/* "$corpus/"
  "$BUILD_DIR-fuzz/fuzz/plan_parser_fuzz" -dict=fuzz/plan.dict -max_len=4096 -seed=1 \
    -runs="$FUZZ_RUNS" -artifact_prefix="$corpus/" "$corpus" 2>&1 | tail -n 3

  echo
  echo "test: fuzzing the editor's API request handling, $FUZZ_RUNS runs (smoke mode)"
  cmake --build "$BUILD_DIR-fuzz" --target api_fuzz -j "$(nproc)"
  api_corpus=$(mktemp -d)
  cp server/fuzz/corpus/* "$api_corpus/"
  "$BUILD_DIR-fuzz/server/api_fuzz" -dict=server/fuzz/api.dict -max_len=4096 -seed=1 \
    -runs="$FUZZ_RUNS" -artifact_prefix="$api_corpus/" "$api_corpus" 2>&1 | tail -n 3
  rm -rf "$api_corpus"

  echo
  echo "test: fuzzing the server end to end (raw bytes as a connection, in memory: HTTP parser, router, handlers, WebSocket), $FUZZ_RUNS runs (smoke mode)"
  cmake --build "$BUILD_DIR-fuzz" --target http_fuzz http_socket_fuzz -j "$(nproc)"
  http_corpus=$(mktemp -d)
  cp server/fuzz/http_corpus/* "$http_corpus/"
  "$BUILD_DIR-fuzz/server/http_fuzz" -dict=server/fuzz/http.dict -max_len=4096 -seed=1 \
    -runs="$FUZZ_RUNS" -artifact_prefix="$http_corpus/" "$http_corpus" 2>&1 | tail -n 3
  # The same over loopback TCP (a socket per run: a tenth of the runs).
  echo "test: fuzzing the server end to end over loopback TCP, $((FUZZ_RUNS / 10)) runs (smoke mode)"
  "$BUILD_DIR-fuzz/server/http_socket_fuzz" -dict=server/fuzz/http.dict -max_len=4096 -seed=1 \
    -runs="$((FUZZ_RUNS / 10))" -artifact_prefix="$http_corpus/" "$http_corpus" 2>&1 | tail -n 3
  rm -rf "$http_corpus"
fi

# The task editor's page (web/): Vitest unit tests, the production build, then the end-to-end
# tests in Debian's Chromium (headless, driven by playwright-core): the paper's three tasks built
# by clicks and keys, every UI action counted, saved, run in the simulated cell and judged from
# the simulator's true state (assemble_by_clicks, paper_tasks); the editor as the cell's control
# panel (control_panel: reload and stop, a second browser, pause, a renamed waypoint, versions,
# Check, Reset scene, disconnection); every cell drawn as it is (cells). Screenshots and the
# figures (action counts, readability, drawn tool against the endpoint) in build/test-artifacts.
# EDITOR_E2E=0 skips the browser tests.
echo
echo "test: the editor's page (npm ci, Vitest, vite build)"
(cd web && npm ci --no-audit --no-fund --loglevel=error && npm test && npm run build)
if [[ "${EDITOR_E2E:-1}" != "0" ]]; then
  if ! dpkg-query -W -f='${Status}' chromium 2>/dev/null | grep -q "install ok installed"; then
    echo "test: installing Debian's chromium for the end-to-end test"
    SUDO=""
    if [[ $(id -u) -ne 0 ]]; then
      SUDO="sudo"
    fi
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends chromium
  fi
  echo
  echo "test: the editor end to end in Chromium (artifacts in $BUILD_DIR/test-artifacts)"
  for e2e in assemble_by_clicks paper_tasks control_panel cells polishing_by_clicks wire_bending_by_clicks teach_by_demonstration collaborative_assembly; do
    node "web/e2e/$e2e.mjs" --costar "$BUILD_DIR/cli/costar" --artifacts "$BUILD_DIR/test-artifacts"
  done
  # Teaching on the 3-finger gripper's cell too (its grasps, its modes).
  node web/e2e/teach_by_demonstration.mjs --costar "$BUILD_DIR/cli/costar" --artifacts "$BUILD_DIR/test-artifacts/iiwa-3f-sim" --cell iiwa-3f-sim
fi
echo
echo "test: all passed in $(( $(date +%s) - start )) s"
rm -rf "$XDG_STATE_HOME"
