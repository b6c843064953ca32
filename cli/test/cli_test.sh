#!/usr/bin/env bash
# End-to-end checks of the costar executable: exit codes, messages, trace file.
# Usage: cli_test.sh PATH/TO/costar   (run from the repository root)
set -u
costar="$1"
failures=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A state folder of its own (taught waypoints): the user's ~/.local/state/costar is not this test's.
export XDG_STATE_HOME="$tmp/state"

check() {  # check NAME EXPECTED_EXIT PATTERN -- COMMAND...
  local name="$1" expected="$2" pattern="$3"
  shift 4
  "$@" >"$tmp/out" 2>&1
  local code=$?
  if [[ $code -ne $expected ]]; then
    echo "FAIL $name: exit $code, expected $expected"; cat "$tmp/out"; failures=$((failures + 1)); return
  fi
  if ! grep -aqE -- "$pattern" "$tmp/out"; then
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
check "workcells: iiwa"     0 '^iiwa-sim ' -- "$costar" workcells
check "validate on iiwa"    0 'valid for workcell .iiwa-sim.' -- "$costar" validate examples/ur5/assemble_structure.xml -w iiwa-sim
check "nodes of iiwa"       0 '<Action ID="SmartGrasp">' -- "$costar" nodes -w iiwa-sim
# Hostile plans (issue 27): a chain of 12,000 SubTrees (~950 KB) is refused with its line (it
# overflowed the stack); a name that is not UTF-8, or a reference to a surrogate, is refused at load.
{
  echo '<root BTCPP_format="4" main_tree_to_execute="T0">'
  for ((i = 0; i < 11999; ++i)); do
    echo "<BehaviorTree ID=\"T$i\"><Inverter><SubTree ID=\"T$((i + 1))\"/></Inverter></BehaviorTree>"
  done
  echo '<BehaviorTree ID="T11999"><Inverter><AlwaysSuccess/></Inverter></BehaviorTree></root>'
} >"$tmp/deep.xml"
check "deep subtrees: validate" 2 'deep\.xml:502: the plan nests deeper than 1000 levels once its subtrees are instantiated' \
  -- "$costar" validate "$tmp/deep.xml" -w none
check "deep subtrees: run"      2 'deep\.xml:502: the plan nests deeper than 1000 levels' -- "$costar" run "$tmp/deep.xml" -w test
check "deep subtrees: ur5-sim"  2 'deep\.xml:502: the plan nests deeper than 1000 levels' -- "$costar" validate "$tmp/deep.xml"
printf '<root BTCPP_format="4"><BehaviorTree ID="m">\n<AlwaysSuccess name="ok \xff"/></BehaviorTree></root>\n' >"$tmp/bytes.xml"
check "name not UTF-8"          2 'bytes\.xml:2: column 25: invalid UTF-8 \(bytes FF\): plan files are UTF-8 text' \
  -- "$costar" validate "$tmp/bytes.xml" -w none
printf '<root BTCPP_format="4"><BehaviorTree ID="m">\n<AlwaysSuccess name="a&#xD800;b"/></BehaviorTree></root>\n' >"$tmp/surrogate.xml"
check "surrogate reference"     2 "surrogate\.xml:2: column 23: the character reference '&#xD800;' is not a character XML allows" \
  -- "$costar" run "$tmp/surrogate.xml" -w none
check "calibrate: bad cell" 2 "unknown workcell .nosuch." -- "$costar" calibrate -w nosuch
check "host: unknown component" 2 "workcell .test. has no component .gripper. \(it has: test_logger, test_actions" \
  -- "$costar" host gripper -w test
# Components served by `costar host` in another process, over DDS on loopback, in a partition
# of this test's own.
cat >"$tmp/remote.xml" <<'XML'
<root BTCPP_format="4"><BehaviorTree ID="main"><Sequence>
  <TestLog message="remote"/><TestAction polls="3"/><TestCount counter="parts"/>
  <Fallback><TestAction result="failure" reason="jammed" polls="2"/><TestAction polls="1"/></Fallback>
</Sequence></BehaviorTree></root>
XML
cat >"$tmp/remote_fails.xml" <<'XML'
<root BTCPP_format="4"><BehaviorTree ID="main"><TestAction result="failure" reason="remote jam" polls="2"/></BehaviorTree></root>
XML
partition="cli-test-$$"
printf '{"partition": "%s", "components": ["test_actions", "test_counter"]}' "$partition" >"$tmp/remote.json"
"$costar" host test_actions test_counter -w test --partition "$partition" 2>"$tmp/host.log" &
host_pid=$!
check "remote: run"         0 '^SUCCESS' -- "$costar" run "$tmp/remote.xml" -w test --remote "$tmp/remote.json"
check "remote: failure"     1 'FAILURE at .*remote jam' -- "$costar" run "$tmp/remote_fails.xml" -w test --remote "$tmp/remote.json"
kill "$host_pid"; wait "$host_pid"
check "remote: host ended"  0 'serving test_actions test_counter of test on DDS domain 0' -- cat "$tmp/host.log"
check "remote: no host"     2 "component 'test_actions': no host serves it on DDS domain 0, partition 'cli-test-" \
  -- "$costar" run "$tmp/remote.xml" -w test --remote "$tmp/remote.json"
printf '{"partition": "%s", "components": ["gripper"]}' "$partition" >"$tmp/remote_bad.json"
check "remote: unknown"     2 "remote_bad.json: components: the test cell has no component 'gripper'" \
  -- "$costar" run "$tmp/remote.xml" -w test --remote "$tmp/remote_bad.json"
check "remote: sim cell"    2 "remote.json: components: 'test_actions' of ur5-sim cannot run in a host \(gripper and perception can" \
  -- "$costar" run "$tmp/remote.xml" -w ur5-sim --remote "$tmp/remote.json"
# A simulated cell's gripper and perception in a host, in lockstep with the executor's simulation
# (rt/clock, dds/lockstep.h): the same trials, to the bit, as with every component in one process.
printf '{"domain": 71, "partition": "%s", "components": ["gripper", "perception"]}' "$partition" >"$tmp/sim_remote.json"
"$costar" host gripper perception -w ur5-sim --domain 71 --partition "$partition" 2>"$tmp/sim_host.log" &
sim_host_pid=$!
trial_args=(trials examples/ur5/pick_up_node.xml --judge lift -n 2 --seed 41 -j 1)
check "remote sim: one process" 0 '^2 of 2 trials succeeded' -- "$costar" "${trial_args[@]}" --json "$tmp/local_trials.json"
check "remote sim: trials"      0 '^2 of 2 trials succeeded' -- "$costar" "${trial_args[@]}" --remote "$tmp/sim_remote.json" \
  --json "$tmp/remote_trials.json"
check "remote sim: the same"    0 '^same: 2 trials$' -- python3 -c '
import json, sys
def trials(file):
    return [(t["seed"], t["success"], t["cycle_time_s"], t["judged"]) for t in json.load(open(file))["results"]]
a, b = trials(sys.argv[1]), trials(sys.argv[2])
print(f"same: {len(a)} trials" if a == b and a else f"differ: {a} vs {b}")' "$tmp/local_trials.json" "$tmp/remote_trials.json"
check "remote sim: -j 2"        2 'a host serves one run at a time' \
  -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift -n 2 --seed 41 -j 2 --remote "$tmp/sim_remote.json"
kill "$sim_host_pid"; wait "$sim_host_pid"
check "remote sim: host ended"  0 'serving gripper perception of ur5-sim in lockstep' -- cat "$tmp/sim_host.log"
# The 3-finger adaptive gripper in a host (its fingers and modes through the executor's simulator).
printf '{"domain": 71, "partition": "%s-3f", "components": ["gripper"]}' "$partition" >"$tmp/sim_remote_3f.json"
"$costar" host gripper -w iiwa-3f-sim --domain 71 --partition "$partition-3f" 2>"$tmp/sim_host_3f.log" &
sim_host_pid=$!
trial_args=(trials examples/ur5/pick_up_node.xml -w iiwa-3f-sim --judge lift -n 1 --seed 41 -j 1)
check "remote 3f: one process" 0 '^1 of 1 trials succeeded' -- "$costar" "${trial_args[@]}" --json "$tmp/local_3f.json"
check "remote 3f: trials"      0 '^1 of 1 trials succeeded' -- "$costar" "${trial_args[@]}" --remote "$tmp/sim_remote_3f.json" \
  --json "$tmp/remote_3f.json"
check "remote 3f: the same"    0 '^same: 1 trials$' -- python3 -c '
import json, sys
def trials(file):
    return [(t["seed"], t["success"], t["cycle_time_s"], t["judged"]) for t in json.load(open(file))["results"]]
a, b = trials(sys.argv[1]), trials(sys.argv[2])
print(f"same: {len(a)} trials" if a == b and a else f"differ: {a} vs {b}")' "$tmp/local_3f.json" "$tmp/remote_3f.json"
kill "$sim_host_pid"; wait "$sim_host_pid"
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

# Trials spread over machines: shards' JSON results merge into one summary (no simulation here:
# two hand-written shard files of a 3-trial batch).
shard_json() {  # shard_json INDEX RESULTS
  printf '{"plan": "p.xml", "scene": "s.json", "judge": "lift", "seed": 5, "count": 3, "trials": 3, "shard": {"index": %s, "count": 2}, "results": [%s]}' "$1" "$2"
}
shard_json 0 '{"index": 0, "seed": 5, "success": true, "cycle_time_s": 6.0}, {"index": 2, "seed": 7, "success": false, "cycle_time_s": 9.0, "failure_path": "main/SmartGrasp", "reason": "no feasible node"}' >"$tmp/s0.json"
shard_json 1 '{"index": 1, "seed": 6, "success": true, "cycle_time_s": 7.0}' >"$tmp/s1.json"
check "trials merge"        0 '^2 of 3 trials succeeded' -- "$costar" trials merge "$tmp/s0.json" "$tmp/s1.json" --json "$tmp/merged.json"
check "trials merge: missing" 2 '1 of 3 trials are missing \(a shard not merged\?\): 1' -- "$costar" trials merge "$tmp/s0.json"
check "trials merge: twice" 2 'trial 1 appears twice' -- "$costar" trials merge "$tmp/s0.json" "$tmp/s1.json" "$tmp/s1.json"
check "trials: bad shard"   2 "needs 0 <= I < N" -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift --shard 4/4

# An output never replaces what the command reads (a hostile tester's --trace P.xml replaced the plan,
# --trace W.json every taught waypoint, trials --json P.xml the plan).
cp examples/test_workcell/demo.xml "$tmp/own.xml"
printf '{"waypoints": [{"name": "kept", "joints": [0, 0, 0, 0, 0, 0]}]}' >"$tmp/kept.json"
check "run: --trace is the plan" 2 "cannot write --trace '$tmp/own.xml': it is the plan, which this command reads" \
  -- "$costar" run "$tmp/own.xml" -w test --trace "$tmp/own.xml"
check "run: --trace is the waypoints" 2 "cannot write --trace '$tmp/./kept.json': it is the waypoint file, which this command reads" \
  -- "$costar" run "$tmp/own.xml" -w test --waypoints "$tmp/kept.json" --trace "$tmp/./kept.json"
check "trials: --json is the plan" 2 "cannot write --json '$tmp/own.xml': it is the plan, which this command reads" \
  -- "$costar" trials "$tmp/own.xml" --judge lift --json "$tmp/own.xml"
check "trials: --json is --plot" 2 "--json and --plot name the same file" \
  -- "$costar" trials "$tmp/own.xml" --judge lift --json "$tmp/r.png" --plot "$tmp/r.png"
if cmp -s examples/test_workcell/demo.xml "$tmp/own.xml" && grep -q '"kept"' "$tmp/kept.json"; then
  echo "ok   outputs: the plan and the waypoints are as they were"
else
  echo "FAIL outputs: an input was written"; failures=$((failures + 1))
fi

# Calibration (issue 14): bad options are refused before any cell is built.
check "calibrate: bad move"   2 "'5cm' should be DISTANCE_M,ANGLE_DEG" -- "$costar" calibrate --camera-move 5cm
check "calibrate: bad method" 2 "--method: nope not in" -- "$costar" calibrate marker --method nope
check "calibrate eval: 0"     2 "--setups: Value 0 not in range" -- "$costar" calibrate eval --setups 0
# The simulated cells are the files of workcells/, in name order.
sim_cells=$(for f in workcells/*.json; do basename "$f" .json; done | LC_ALL=C sort | paste -sd, | sed 's/,/, /g')
check "calibrate eval: bad cell" 2 "unknown workcell 'nosuch' for calibrate eval \(simulated cells: $sim_cells\)" \
  -- "$costar" calibrate eval -w nosuch --setups 1
check "calibrate eval: no sim"  2 "unknown workcell 'test' for calibrate eval" -- "$costar" calibrate eval -w test --setups 1
check "trials: bad move"      2 "--camera-move: '1,1' should be DISTANCE_M,ANGLE_DEG, numbers from 0 to 0.5 m and 45 degrees" \
  -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift --camera-move 1,1

# Issue 27: numbers are read strictly and checked against the clock's range; messages print them
# short. No cell is built for any of these.
for bad in nan,5 0.05junk,5 inf,0 0.05,nan 1e400,1; do
  check "trials --camera-move $bad" 2 "--camera-move: '$bad' should be DISTANCE_M,ANGLE_DEG" \
    -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift --camera-move "$bad"
done
for bad in nan inf -1 1e10 5junk; do
  check "run --time-limit $bad" 2 "--time-limit: must be a number from 0 s and at most 1e\+09, not $bad" \
    -- "$costar" run examples/test_workcell/demo.xml -w test --time-limit "$bad"
done
for bad in -1 18446744073709551616 1.5; do
  check "run --seed $bad" 2 "--seed: must be a whole number from 0 to 18446744073709551615, not $bad" \
    -- "$costar" run examples/test_workcell/demo.xml -w test --seed "$bad"
done
check "run --rate nan"        2 "--rate: must be a number from 0.1 Hz and at most 10000, not nan" \
  -- "$costar" run examples/test_workcell/demo.xml -w test --rate nan
check "inject at t=1e10s"     2 "fault 'nan:arm-driver@t=1e10s': t= needs a time in seconds from 0 to 1e9" \
  -- "$costar" run examples/ur5/pick_up_node.xml --inject nan:arm-driver@t=1e10s
check "calibrate eval --methods bogus" 2 "--methods: unknown hand-eye method 'bogus' \(known: daniilidis, " \
  -- "$costar" calibrate eval --setups 1 --methods daniilidis,bogus
check "perception eval --min-found nan" 2 "--min-found: must be a number from 0 and at most 1, not nan" \
  -- "$costar" perception eval --scenes 1 --min-found nan
if grep -qE '[0-9]{40}' "$tmp/out"; then echo "FAIL a number of 40 digits in a message"; failures=$((failures + 1)); fi

# Issue 27: unchecked writes reported success. Every output is checked: an error naming the path
# and the system's words, exit 2, no "wrote".
claims_nothing() {  # claims_nothing NAME: the last check's output claims no file written
  if grep -q '^wrote' "$tmp/out"; then echo "FAIL $1: claims a file written"; failures=$((failures + 1)); fi
}
check "nodes -o /dev/full" 2 "^error: cannot write '/dev/full': No space left on device" \
  -- "$costar" nodes -w test -o /dev/full
claims_nothing "nodes -o /dev/full"
check "nodes > /dev/full" 2 "^error: cannot write the standard output: No space left on device" \
  -- bash -c "'$costar' nodes -w test > /dev/full"
check "run --trace /dev/full" 2 "^error: cannot write '/dev/full': No space left on device" \
  -- "$costar" run examples/test_workcell/demo.xml -w test -q --trace /dev/full
check "run --trace in a missing folder" 2 "^error: cannot write '$tmp/no/t.jsonl': No such file or directory" \
  -- "$costar" run examples/test_workcell/demo.xml -w test -q --trace "$tmp/no/t.jsonl"
mkfifo "$tmp/nobody_reads"
check "run --trace to a pipe nobody reads" 2 "^error: cannot write '$tmp/nobody_reads': No such device or address" \
  -- timeout 20 "$costar" run examples/test_workcell/demo.xml -w test -q --trace "$tmp/nobody_reads"
check "nodes -o a pipe nobody reads" 2 "^error: cannot write '$tmp/nobody_reads': No such device or address" \
  -- timeout 20 "$costar" nodes -w test -o "$tmp/nobody_reads"
rm "$tmp/nobody_reads"
check "calibrate --json in a missing folder" 2 "^error: cannot write --json '$tmp/no/c.json': there is no folder" \
  -- "$costar" calibrate --json "$tmp/no/c.json"
check "calibrate --calibration in a missing folder" 2 \
  "^error: cannot write --calibration '$tmp/no/c.json': there is no folder" \
  -- "$costar" calibrate --calibration "$tmp/no/c.json"
check "perception eval --json /dev/full is written to" 2 "error: cannot write --json '$tmp/no/e.json': there is no folder" \
  -- "$costar" perception eval --scenes 1 --json "$tmp/no/e.json"
check "sim snapshot to /dev/full" 2 "cannot write '/dev/full': No space left on device" \
  -- "$costar" sim snapshot sim/scenes/one_node.json --out /dev/full --width 16 --height 16
claims_nothing "sim snapshot to /dev/full"
if grep -q 'libpng' "$tmp/out"; then echo "FAIL sim snapshot to /dev/full: libpng's own message"; failures=$((failures + 1)); fi
mkfifo "$tmp/nobody_reads"
check "sim snapshot to a pipe nobody reads" 2 "cannot write '$tmp/nobody_reads': No such device or address" \
  -- timeout 20 "$costar" sim snapshot sim/scenes/one_node.json --out "$tmp/nobody_reads" --width 16 --height 16
rm "$tmp/nobody_reads"
check "sim snapshot after a plan in a cell" 0 \
  '^wire: 2[45][0-9]\.[0-9] mm out of the clamp, E 1[12][0-9] GPa, yield strength [6-9][0-9] MPa; bends -?0\.[0-9] \(drawing 90, .*held 0, let go 0, pulled out 0 times' \
  -- "$costar" sim snapshot sim/scenes/wire_bending.json -w iiwa-3f-sim --plan cli/test/fixtures/pinch_open.xml \
  --settle 0.1 --camera jig --width 64 --height 48 --out "$tmp/jig.png"
if ! grep -q '^ran cli/test/fixtures/pinch_open.xml: SUCCESS after' "$tmp/out" || [[ ! -s "$tmp/jig.png" ]]; then
  echo "FAIL sim snapshot after a plan: no SUCCESS line or no picture"; cat "$tmp/out"; failures=$((failures + 1))
fi
check "sim snapshot in a cell without a simulator" 2 "workcell 'test' is not simulated: nothing to picture" \
  -- "$costar" sim snapshot sim/scenes/one_node.json -w test --out "$tmp/x.png"

# Teaching: jog, teach, move back, rename; waypoints persist in the file.
printf 'jog z 0.05\nteach up\nhome\nmove up\nrename up lifted\nmove nowhere\nquit\n' |
  "$costar" teach --scene sim/scenes/one_node.json --waypoints "$tmp/waypoints.json" >"$tmp/teach.out" 2>&1
if [[ $(grep -c '^ok' "$tmp/teach.out") -eq 5 ]] && grep -q "failed: unknown waypoint 'nowhere' (known: lifted)" "$tmp/teach.out" &&
   grep -q '"name": "lifted"' "$tmp/waypoints.json"; then
  echo "ok   teach"
else
  echo "FAIL teach"; cat "$tmp/teach.out"; failures=$((failures + 1))
fi

# Free-drive (docs/TEACHING.md): a push moves the tool, recorded and replayed; the table stops it.
printf 'drag 0 20 0 1 translation record swipe\ntrajectories\nreplay swipe\nreplay nothing\ndrag 0 0 -40 3 lock x\nquit\n' |
  "$costar" teach --scene sim/scenes/one_node.json --waypoints "$tmp/waypoints.json" >"$tmp/drag.out" 2>&1
if grep -Eq "^the tool moved [-0-9.]* 0\.(09[5-9]|1[0-9])[0-9]* " "$tmp/drag.out" && grep -q "^  swipe  *in world: " "$tmp/drag.out" &&
  grep -q "failed: FollowTrajectory: unknown trajectory 'nothing'" "$tmp/drag.out" &&
  grep -q "held back: fingers would touch table" "$tmp/drag.out" && grep -q '"trajectories"' "$tmp/waypoints.json"; then
  echo "ok   teach: drag, record, replay"
else
  echo "FAIL teach: drag, record, replay"; cat "$tmp/drag.out"; failures=$((failures + 1))
fi

# A hand pushes with at most 60 N and turns with 3 N m, as in the editor (200 N moved the tool 0.8 m
# in 1.1 s, 1e308 made MuJoCo unstable).
printf 'drag 200 0 0 1\ndrag 0 0 0 1 turn 0 0 5\nquit\n' |
  "$costar" teach --scene sim/scenes/one_node.json --waypoints "$tmp/waypoints.json" >"$tmp/hard.out" 2>&1
if grep -q "^error: a hand pushes the tool with at most 60 N; the force asked is 200 N (nothing was done)" "$tmp/hard.out" &&
   grep -q "^error: a hand turns the tool with at most 3 N m; the torque asked is 5 N m (nothing was done)" "$tmp/hard.out" &&
   ! grep -q "the tool moved" "$tmp/hard.out"; then
  echo "ok   teach: a drag harder than a hand is refused"
else
  echo "FAIL teach: a drag harder than a hand is refused"; cat "$tmp/hard.out"; failures=$((failures + 1))
fi

# Issue 27: a name that is not UTF-8 is refused where it is typed, the waypoint file untouched.
printf 'teach a\xffb\nquit\n' |
  "$costar" teach --scene sim/scenes/one_node.json --waypoints "$tmp/waypoints.json" >"$tmp/teach.out" 2>&1
if grep -q "^error: the command is not UTF-8 text (byte 8 of the line, 0xFF): names are UTF-8" "$tmp/teach.out" &&
   python3 -c 'import json, sys; assert [w["name"] for w in json.load(open(sys.argv[1]))["waypoints"]] == ["lifted"]' \
     "$tmp/waypoints.json"; then
  echo "ok   teach: a name that is not UTF-8"
else
  echo "FAIL teach: a name that is not UTF-8"; cat "$tmp/teach.out"; failures=$((failures + 1))
fi
check "smartmove teach: a name that is not UTF-8" 2 "p' is not UTF-8 text: names are UTF-8$" \
  -- "$costar" smartmove teach node "to$(printf '\xff')p" --at lifted --waypoints "$tmp/waypoints.json"

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

# Trials: options, scene and waypoint files and output paths are checked before the first trial
# (issue 10); the errors name the option or the file and the field. No trial runs in these.
trials=(trials examples/ur5/blind_pick_place.xml --judge blind_place --scene sim/scenes/one_node.json
        --waypoints examples/ur5/blind_waypoints.json -n 1)
no_trial() {  # no_trial NAME: the last check's output shows no trial ran
  if grep -qE '^\[ *1/1\]' "$tmp/out"; then echo "FAIL $1: a trial ran"; failures=$((failures + 1)); fi
}
for bad in nan 0 -5 inf; do
  check "trials --time-limit $bad" 2 "--time-limit: must be a number above 0 s and at most 1e\+06, not $bad" \
    -- "$costar" "${trials[@]}" --time-limit "$bad"
  no_trial "trials --time-limit $bad"
done
check "trials --require nan" 2 '--require: must be a number from 0 and at most 1, not nan' \
  -- "$costar" "${trials[@]}" --require nan
check "trials --plot in a missing folder" 2 "error: cannot write --plot '/nonexistent/p.png': there is no folder '/nonexistent'" \
  -- "$costar" "${trials[@]}" --plot /nonexistent/p.png
no_trial "trials --plot in a missing folder"
check "trials --json to a folder" 2 "error: cannot write --json '$tmp': it is a folder" \
  -- "$costar" "${trials[@]}" --json "$tmp"
no_trial "trials --json to a folder"
check "trials --json in a missing folder" 2 "error: cannot write --json '$tmp/no/r.json': there is no folder '$tmp/no'" \
  -- "$costar" "${trials[@]}" --json "$tmp/no/r.json"
mkdir -p "$tmp/blocked/trial_1.jsonl"
check "trials --trace where the first trial's file is a folder" 2 \
  "error: cannot write --trace '$tmp/blocked/trial_1.jsonl': it is a folder" -- "$costar" "${trials[@]}" --trace "$tmp/blocked"
no_trial "trials --trace where the first trial's file is a folder"
printf '{"parts": [{"class": "node", "count": 4294967297}]}\n' >"$tmp/count.json"
check "trials: scene count out of range" 2 \
  "error: scene '$tmp/count.json': parts\[0\]\.count: must be a whole number from 1 to 100, not 4294967297" \
  -- "$costar" trials examples/ur5/blind_pick_place.xml --judge blind_place --scene "$tmp/count.json" -n 1
no_trial "trials: scene count out of range"
printf '{"waypoints": [{"name": "pick", "position": [0.45, -0.25, 0.03], "orientation": [0, 0, 0, 0]}]}\n' >"$tmp/zero.json"
check "run: zero quaternion in a waypoint" 2 \
  "waypoint file '$tmp/zero.json': waypoints\[0\]\.orientation: must be a unit quaternion \[w, x, y, z\], not \[0,0,0,0\]" \
  -- "$costar" run examples/ur5/blind_pick_place.xml -q --scene sim/scenes/one_node.json --waypoints "$tmp/zero.json"

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
if [[ $code -eq 130 ]] && grep -q 'STOPPED by SIGINT (Ctrl-C)' "$tmp/out"; then echo "ok   ctrl-c"; else echo "FAIL ctrl-c: exit $code"; cat "$tmp/out"; failures=$((failures + 1)); fi

# Issue 27: SIGTERM (a batch scheduler's time limit) stops a run like Ctrl-C, with its trace
# complete; SIGKILL keeps every tick's lines but the last tick's (the trace is written as it goes).
trace_ok() {  # trace_ok FILE ENDED: every line a transition; ENDED=1: the run's halt is the last
  python3 - "$1" "$2" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
assert text and text.endswith("\n"), "empty, or a line cut short"
lines = [json.loads(l) for l in text.splitlines()]
assert all({"t", "uid", "path", "node", "from", "to"} <= l.keys() for l in lines), "missing keys"
if sys.argv[2] == "1":
    # the root (the first node made: the smallest uid) is the last to be halted
    assert lines[-1]["uid"] == min(l["uid"] for l in lines) and lines[-1]["to"] == "IDLE", lines[-1]
PY
}
wait_for_trace() {  # wait_for_trace FILE: until the run has ticked
  for _ in $(seq 300); do
    [[ -s "$1" ]] && break
    sleep 0.1
  done
}
"$costar" run "$tmp/long.xml" -w none -q --trace "$tmp/term.jsonl" >"$tmp/out" 2>&1 &
pid=$!
wait_for_trace "$tmp/term.jsonl"
kill -TERM $pid
wait $pid
code=$?
if [[ $code -eq 143 ]] && grep -q 'STOPPED by SIGTERM' "$tmp/out" && trace_ok "$tmp/term.jsonl" 1; then
  echo "ok   sigterm: exit 143, trace complete"
else
  echo "FAIL sigterm: exit $code"; cat "$tmp/out"; failures=$((failures + 1))
fi
# SIGHUP (the terminal or the ssh session closed) stops it the same way; it ended the process.
"$costar" run "$tmp/long.xml" -w none -q --trace "$tmp/hup.jsonl" >"$tmp/out" 2>&1 &
pid=$!
wait_for_trace "$tmp/hup.jsonl"
kill -HUP $pid
wait $pid
code=$?
if [[ $code -eq 129 ]] && grep -q 'STOPPED by SIGHUP (the terminal closed)' "$tmp/out" && trace_ok "$tmp/hup.jsonl" 1; then
  echo "ok   sighup: exit 129, trace complete"
else
  echo "FAIL sighup: exit $code"; cat "$tmp/out"; failures=$((failures + 1))
fi
"$costar" run "$tmp/long.xml" -w none -q --trace "$tmp/kill.jsonl" >"$tmp/out" 2>&1 &
pid=$!
wait_for_trace "$tmp/kill.jsonl"
sleep 0.3
kill -KILL $pid
wait $pid 2>/dev/null
if trace_ok "$tmp/kill.jsonl" 0 && [[ $(wc -l <"$tmp/kill.jsonl") -gt 2 ]]; then
  echo "ok   sigkill: the trace holds $(wc -l <"$tmp/kill.jsonl") whole lines"
else
  echo "FAIL sigkill: trace"; failures=$((failures + 1))
fi

# Issue 27: `costar trials` on SIGTERM starts no further trial, cancels the running one, and writes
# --json for the trials that finished, marked interrupted; no empty trace file is left.
mkdir -p "$tmp/traces"
"$costar" trials examples/ur5/blind_pick_place.xml --judge blind_place --scene sim/scenes/one_node.json \
  --waypoints examples/ur5/blind_waypoints.json -n 20 -j 1 --json "$tmp/int.json" --trace "$tmp/traces" >"$tmp/out" 2>&1 &
pid=$!
for _ in $(seq 600); do
  grep -qE '^\[ *1/20\]' "$tmp/out" && break
  sleep 0.1
done
kill -TERM $pid
wait $pid
code=$?
if [[ $code -eq 143 ]] && grep -q 'costar trials: stopped by SIGTERM: [0-9]* of 20 trials finished' "$tmp/out" &&
   python3 - "$tmp/int.json" "$tmp/traces" <<'PY'
import json, os, sys
summary = json.load(open(sys.argv[1]))
assert summary["interrupted"] is True and summary["planned"] == 20, summary
assert 1 <= len(summary["results"]) < 20, len(summary["results"])
for name in os.listdir(sys.argv[2]):
    assert os.path.getsize(os.path.join(sys.argv[2], name)) > 0, name + " is empty"
PY
then
  echo "ok   trials: sigterm keeps the finished trials"
else
  echo "FAIL trials: sigterm: exit $code"; cat "$tmp/out"; failures=$((failures + 1))
fi
# A standard output nobody reads any more (| head -1) no longer ends the batch before --json.
"$costar" trials examples/ur5/blind_pick_place.xml --judge blind_place --scene sim/scenes/one_node.json \
  --waypoints examples/ur5/blind_waypoints.json -n 3 --json "$tmp/piped.json" | head -1 >/dev/null
code=${PIPESTATUS[0]}
if [[ $code -eq 0 ]] && python3 -c 'import json, sys; assert len(json.load(open(sys.argv[1]))["results"]) == 3' "$tmp/piped.json"; then
  echo "ok   trials | head -1: the batch finishes, --json written"
else
  echo "FAIL trials | head -1: exit $code"; failures=$((failures + 1))
fi
check "trials merge refuses an interrupted shard" 2 "are of an interrupted run" -- "$costar" trials merge "$tmp/int.json"

# Issue 27: the default scene of `costar trials` is the workcell's wherever the command runs.
repo=$PWD
check "trials outside the repository" 0 "on scene $repo/sim/scenes/assembly.json" \
  -- bash -c "cd '$tmp' && '$(realpath "$costar")' trials '$repo/examples/ur5/blind_pick_place.xml' --judge blind_place -n 1 --time-limit 0.5"

# The light costar links no robot library; costar-robot (beside it) runs the commands that do.
robot="$(dirname "$costar")/costar-robot"
if ldd "$costar" | grep -qE 'libpcl|libvtk|libQt|libopencv|libmujoco|libompl|libfcl|liborocos|libEGL'; then
  echo "FAIL light executable links robot libraries:"; ldd "$costar" | grep -E 'libpcl|libvtk|libQt|libopencv|libmujoco|libompl|libfcl|liborocos|libEGL' | head; failures=$((failures + 1))
else
  echo "ok   light executable ($(ldd "$costar" | wc -l) shared libraries)"
fi
# Both list the same commands, options and exit codes.
"$costar" --help | sed "s|$costar|COSTAR|" >"$tmp/help.light"
"$robot" --help | sed "s|$robot|COSTAR|" >"$tmp/help.robot"
if diff -u "$tmp/help.robot" "$tmp/help.light" >"$tmp/help.diff"; then echo "ok   same help"; else echo "FAIL help differs"; cat "$tmp/help.diff"; failures=$((failures + 1)); fi
check "misspelt command"    2 'subcommand is required' -- "$costar" rnu examples/test_workcell/demo.xml
check "version"             0 '^costar 0\.1\.0' -- "$costar" --version
# Validating against the UR5 cell's stored description gives what the cell itself gives, word
# for word (exit code, every problem, the summary line), with and without taught waypoints.
same() {  # same NAME ARGS...: costar and costar-robot print the same and exit the same
  local name="$1"
  shift
  "$costar" "$@" >"$tmp/light.out" 2>&1
  local light=$?
  "$robot" "$@" >"$tmp/robot.out" 2>&1
  local heavy=$?
  if [[ $light -eq $heavy ]] && diff -u "$tmp/robot.out" "$tmp/light.out" >"$tmp/same.diff"; then
    echo "ok   $name (exit $light)"
  else
    echo "FAIL $name: exit $light, costar-robot $heavy"; cat "$tmp/same.diff"; failures=$((failures + 1))
  fi
}
for plan in examples/ur5/*.xml cli/test/fixtures/ur5_predicates.xml; do
  same "validate $plan as costar-robot does" validate "$plan" --waypoints "$tmp/none.json"
done
same "validate with waypoints as costar-robot does" validate cli/test/fixtures/ur5_predicates.xml \
  --waypoints examples/ur5/blind_waypoints.json
# A force at or above its max_force: the constraint is in the stored description (less_than).
same "validate forces against max_force as costar-robot does" validate cli/test/fixtures/force_limits.xml \
  -w iiwa-3f-sim --waypoints examples/iiwa/polishing_waypoints.json
check "force at max_force refused" 2 'force_limits.xml:8: .*force \(40\) must be below max_force \(40\)' \
  -- "$costar" validate cli/test/fixtures/force_limits.xml -w iiwa-3f-sim --waypoints examples/iiwa/polishing_waypoints.json
check "force above max_force refused" 2 'force_limits.xml:9: .*force \(20\) must be below max_force \(15\)' \
  -- "$costar" validate cli/test/fixtures/force_limits.xml -w iiwa-3f-sim --waypoints examples/iiwa/polishing_waypoints.json
same "nodes model as costar-robot writes it" nodes --waypoints "$tmp/none.json"
same "nodes json as costar-robot writes it" nodes --format json --waypoints "$tmp/none.json"
check "predicate problems named" 2 'ur5_predicates.xml:11: .*unknown reference frame .node_1.' \
  -- "$costar" validate cli/test/fixtures/ur5_predicates.xml --waypoints examples/ur5/blind_waypoints.json
# Without costar-robot beside it: a clear error for what needs it, the rest still works.
mkdir -p "$tmp/alone"
cp "$costar" "$tmp/alone/costar"
check "no costar-robot: robot command" 2 "'costar sim' needs the robot libraries .*costar-robot.*cannot be started" \
  -- "$tmp/alone/costar" sim snapshot sim/scenes/one_node.json --out "$tmp/x.png"
check "no costar-robot: run on ur5-sim" 2 "needs the robot libraries" \
  -- "$tmp/alone/costar" run examples/ur5/pick_up_node.xml
check "no costar-robot: run -w none" 0 '^SUCCESS' -- "$tmp/alone/costar" run bench/plans/reference_1000_leaves.xml -w none -q

# A hostile tester's findings, the second part: each refused with a clear message before anything
# runs (they ran silently, ran nothing and exited 0, or showed a library's internal text).
check "an empty --trace is refused" 2 "^--trace: needs a file name, not ''" \
  -- "$costar" run examples/test_workcell/demo.xml -w test --trace ''
check "a shard without trials is refused" 2 '^error: --shard: slice 5 of 2 trial\(s\) has none' \
  -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift -n 2 --shard 5/10
check "trials on a cell without a simulation" 2 "^error: costar trials judges a simulated world, and the 'none' workcell has none" \
  -- "$costar" trials examples/ur5/pick_up_node.xml --judge lift -n 1 -w none
check "a scene for a cell without a simulation" 2 "the 'none' workcell has no simulation: a scene \(--scene\) applies" \
  -- "$costar" run bench/plans/reference_1000_leaves.xml -w none --scene sim/scenes/one_node.json
check "perception detect on a cell that is not simulated" 2 "'none' is not a simulated workcell \(those are: .*ur5-sim" \
  -- "$costar" perception detect sim/scenes/one_node.json -w none
check "cross-validation folds" 2 '^--folds: must be 0 \(none\) or a whole number from 2 to 100, not -1' \
  -- "$costar" perception train --folds -1
check "a marker id beyond the dictionary" 2 '^--id: Value -1 not in range 0 to 49' -- "$costar" perception marker --id -1
check "JSON syntax errors without the library's prefix" 2 "scene '.*bad_scene.json': line 2, column 1[0-9]: syntax error" \
  -- bash -c "printf '{\"parts\": [\n {\"class\": ,}]}' > '$tmp/bad_scene.json' && '$costar' run examples/ur5/pick_up_node.xml --scene '$tmp/bad_scene.json'"
printf '{"waypoints": [{"name": "seven", "joints": [0, -1.57, 1.57, -1.57, -1.57, 0, 0]}]}\n' >"$tmp/seven.json"
check "validate reads joint waypoints as run does" 2 'waypoints\[0\]\.joints: must be 6 angles' \
  -- "$costar" validate examples/ur5/pick_up_node.xml --waypoints "$tmp/seven.json"

exit $((failures > 0))
