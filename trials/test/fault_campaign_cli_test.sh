#!/usr/bin/env bash
# End-to-end checks of fault_campaign's options and outputs (issue 27): a bad number or a
# --jsonl line lacking a field is a clear error, and an output that cannot be written is an
# error, never a "wrote". Usage: campaign_cli_test.sh PATH/TO/fault_campaign (repository root).
set -u
campaign="$1"
failures=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

check() {  # check NAME EXPECTED_EXIT PATTERN -- COMMAND...
  local name="$1" expected="$2" pattern="$3"
  shift 4
  "$@" >"$tmp/out" 2>&1
  local code=$?
  if [[ $code -ne $expected ]]; then
    echo "FAIL $name: exit $code, expected $expected"; cat "$tmp/out"; failures=$((failures + 1)); return
  fi
  if ! grep -qE -- "$pattern" "$tmp/out"; then
    echo "FAIL $name: output lacks /$pattern/"; cat "$tmp/out"; failures=$((failures + 1)); return
  fi
  echo "ok   $name"
}
claims_nothing() {  # claims_nothing NAME: the last check's output says no file was written
  if grep -q '^wrote' "$tmp/out"; then echo "FAIL $1: claims a file written"; failures=$((failures + 1)); fi
}

for bad in nan inf -1 0 1e400 0.5junk; do
  check "--window $bad" 2 "--window: must be a number above 0 s and at most 1e\+09, not $bad" \
    -- "$campaign" -w test --plan examples/test_workcell/demo.xml -n 1 --window "$bad"
done

# One run in the test cell (no simulator) to have a line to break.
test_run=(-w test --plan examples/test_workcell/demo.xml --window 0.38 -n 1 --seed 3)
check "a run, its line" 0 'all' -- "$campaign" "${test_run[@]}" --jsonl "$tmp/good.jsonl" --json "$tmp/good.json"
check "summarize" 0 '^1 runs from' -- "$campaign" --summarize "$tmp/good.jsonl"
python3 - "$tmp/good.jsonl" "$tmp/missing.jsonl" <<'PY'
import json, sys
line = json.loads(open(sys.argv[1]).readline())
del line["outcome"]
with open(sys.argv[2], "w") as out:
    out.write(open(sys.argv[1]).readline() + json.dumps(line) + "\n")
PY
check "summarize: a line lacks a field" 2 "^error: $tmp/missing.jsonl:2: missing field 'outcome'$" \
  -- "$campaign" --summarize "$tmp/missing.jsonl"
printf 'not json\n' >"$tmp/bad.jsonl"
check "summarize: not JSON" 2 "^error: $tmp/bad.jsonl:1: not a JSON object: .*line 1, column 2" \
  -- "$campaign" --summarize "$tmp/bad.jsonl"

check "--json /dev/full" 2 "^error: cannot write '/dev/full': No space left on device" \
  -- "$campaign" "${test_run[@]}" --json /dev/full
claims_nothing "--json /dev/full"
check "--jsonl /dev/full" 2 "^error: cannot write '/dev/full': No space left on device" \
  -- "$campaign" "${test_run[@]}" --jsonl /dev/full
check "--json in a missing folder, before any run" 2 "^error: cannot write --json '$tmp/no/c.json': there is no folder" \
  -- "$campaign" "${test_run[@]}" --json "$tmp/no/c.json"
if grep -q '^\[' "$tmp/out"; then echo "FAIL a run ran before the output was refused"; failures=$((failures + 1)); fi

exit $((failures > 0))
