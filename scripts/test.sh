#!/usr/bin/env bash
# Quick start 2: set up, build, and run every test: unit and end-to-end tests (CTest), and
# the plan-parser fuzz target in smoke mode (libFuzzer, clang, address + UB sanitizers).
#   FUZZ_RUNS=20000 (default) sets the smoke run's length; FUZZ_RUNS=0 skips it.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
bash scripts/setup.sh
BUILD_DIR="${COSTAR_BUILD_DIR:-build}"

echo
echo "test: CTest"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 600

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
fi
echo
echo "test: all passed in $(( $(date +%s) - start )) s"
