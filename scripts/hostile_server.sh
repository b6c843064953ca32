#!/usr/bin/env bash
# A stranger's attacks on `costar serve` (issue 27) on every simulated cell: for each, runs
# server/bench/hostile_serve.py (a fresh store with a 120,000-transition run log, the arm moving
# throughout; classes of hostile requests, SIGTERM, kill -9 during saves) and prints its table
# by class. Exit 0 when no class found anything.
#
# Usage: scripts/hostile_server.sh [BUILD_DIR] [CELL...]
#   BUILD_DIR defaults to build (it needs the costar and costar-robot targets); the cells
#   default to every cell in workcells/. HOSTILE_ARGS passes options to the script
#   (e.g. HOSTILE_ARGS="--transitions 20000 --kills 2" for a quick run).
set -uo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
shift || true
cells=("$@")
if [[ ${#cells[@]} -eq 0 ]]; then
  for file in workcells/*.json; do cells+=("$(basename "$file" .json)"); done
fi
read -r -a extra <<<"${HOSTILE_ARGS:-}"
status=0
for cell in "${cells[@]}"; do
  echo "== $cell"
  python3 server/bench/hostile_serve.py "$build/cli/costar" --workcell "$cell" "${extra[@]}" || status=1
done
exit "$status"
