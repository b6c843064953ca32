#!/usr/bin/env bash
# End-to-end checks of the costar executable: exit codes, messages, trace file.
# Usage: cli_test.sh PATH/TO/costar   (run from the repository root)
set -u
costar="$1"
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

check "run succeeds"        0 '^SUCCESS in 0\.380 s simulated' -- "$costar" run examples/test_workcell/demo.xml -w test
check "run fails with path" 1 'FAILURE at main/Sequence\[1\]/RetryUntilSuccessful\[2\]/TestAction "grasp link": no reachable candidate' \
  -- "$costar" run examples/test_workcell/fails.xml -w test
check "invalid plan"        2 'cli/test/fixtures/invalid.xml:6: parameter .num_cycles. of Repeat: .twice. is not an integer' \
  -- "$costar" run cli/test/fixtures/invalid.xml -w test
check "invalid: every problem" 2 'invalid.xml:8: unknown node .Mvoe. \(did you mean .Move.\?\)' \
  -- "$costar" validate cli/test/fixtures/invalid.xml -w test
check "validate ok"         0 'valid for workcell .test.' -- "$costar" validate examples/test_workcell/demo.xml -w test
check "unknown workcell"    2 "unknown workcell 'moon'" -- "$costar" run examples/test_workcell/demo.xml -w moon
check "missing file"        2 'File does not exist' -- "$costar" run nope.xml
check "nodes model"         0 '<Action ID="Move">' -- "$costar" nodes -w test
check "nodes json"          0 '"category": "knowledge"' -- "$costar" nodes -w test --format json
check "help"                0 'Exit code: 0 SUCCESS' -- "$costar" run --help
check "time limit"          1 'exceeded its time limit' -- "$costar" run examples/test_workcell/demo.xml -w test --time-limit 0.1
check "inject: bad spec"    2 "fault 'melt:arm@t=1': unknown kind 'melt'" \
  -- "$costar" run examples/test_workcell/demo.xml -w test --inject melt:arm@t=1
check "inject: no target"   2 "this workcell has no 'arm-driver'" \
  -- "$costar" run examples/test_workcell/demo.xml -w test --inject nan:arm-driver@t=1
check "inject: dies"        1 "FAILURE at .*: the cell stopped: component 'test_counter' failed: .*is gone" \
  -- "$costar" run examples/test_workcell/demo.xml -w test --inject die:test_counter@t=0.1s
check "inject: throws"      1 'FAILURE at .*"go home": could not start: the operation threw' \
  -- "$costar" run examples/test_workcell/demo.xml -w test --inject throw:test_arm@op=1

# Teaching: jog, teach, move back, rename; waypoints persist in the file.
printf 'jog z 0.05\nteach up\nhome\nmove up\nrename up lifted\nmove nowhere\nquit\n' |
  "$costar" teach --scene sim/scenes/one_node.json --waypoints "$tmp/waypoints.json" >"$tmp/teach.out" 2>&1
if [[ $(grep -c '^ok' "$tmp/teach.out") -eq 5 ]] && grep -q "failed: unknown waypoint 'nowhere' (known: lifted)" "$tmp/teach.out" &&
   grep -q '"name": "lifted"' "$tmp/waypoints.json"; then
  echo "ok   teach"
else
  echo "FAIL teach"; cat "$tmp/teach.out"; failures=$((failures + 1))
fi

# The blind pick-and-place on the simulated UR5.
check "blind pick and place" 0 '^SUCCESS in' -- "$costar" run examples/ur5/blind_pick_place.xml -q \
  --scene sim/scenes/one_node.json --waypoints examples/ur5/blind_waypoints.json

# The trace has one JSON object per transition, with reasons on failures.
"$costar" run examples/test_workcell/fails.xml -w test -q --trace "$tmp/trace.jsonl" >/dev/null
if python3 - "$tmp/trace.jsonl" <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
assert all({"t", "uid", "path", "node", "from", "to"} <= l.keys() for l in lines), "missing keys"
fails = [l for l in lines if l["to"] == "FAILURE"]
assert fails and fails[-1]["reason"] == "no reachable candidate", fails
assert fails[-1]["origin"].endswith('TestAction "grasp link"'), fails[-1]
PY
then echo "ok   trace"; else echo "FAIL trace"; failures=$((failures + 1)); fi

# Ctrl-C stops the run, cancels the operation and exits 130.
cat > "$tmp/long.xml" <<'XML'
<root BTCPP_format="4"><BehaviorTree ID="m"><Repeat num_cycles="-1"><Sleep msec="10"/></Repeat></BehaviorTree></root>
XML
# The handler is installed just before the first tick, so wait until the trace shows ticks (a loaded
# machine may take seconds to start the binary) rather than sleeping a fixed time.
"$costar" run "$tmp/long.xml" -w none -q --trace "$tmp/long.jsonl" >"$tmp/out" 2>&1 &
pid=$!
for _ in $(seq 300); do
  [[ -s "$tmp/long.jsonl" ]] && break
  sleep 0.1
done
kill -INT $pid
wait $pid
code=$?
if [[ $code -eq 130 ]] && grep -q STOPPED "$tmp/out"; then echo "ok   ctrl-c"; else echo "FAIL ctrl-c: exit $code"; cat "$tmp/out"; failures=$((failures + 1)); fi

exit $((failures > 0))
