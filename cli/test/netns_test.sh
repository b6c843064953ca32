#!/usr/bin/env bash
# Two computers on this machine (issue 34): two network namespaces made by this test, joined by a
# veth pair and nothing else (no route out of either). A component host runs in one, the executor
# in the other, over DDS on the named interface: the test cell's components, then a simulated
# cell's gripper and perception in lockstep, whose trial must be the same as in one process. A
# host on loopback (the default) in one namespace is not seen from the other.
# Needs root (ip netns); otherwise it is skipped (exit 77) saying why.
# Usage: netns_test.sh PATH/TO/costar   (run from the repository root)
set -u
costar="$1"
if [[ $(id -u) -ne 0 ]]; then
  echo "SKIP: making network namespaces needs root (ip netns add); this is uid $(id -u)"; exit 77
fi
a="costar-a-$$" b="costar-b-$$" va="cva$$" vb="cvb$$"
if ! ip netns add "$a" 2>/dev/null; then
  echo "SKIP: ip netns add is not permitted here"; exit 77
fi
tmp=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null; done
  ip netns del "$a" 2>/dev/null
  ip netns del "$b" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
export XDG_STATE_HOME="$tmp/state"
ip netns add "$b" || { echo "FAIL: ip netns add $b"; exit 1; }
ip link add "$va" type veth peer name "$vb" || { echo "FAIL: ip link add veth"; exit 1; }
ip link set "$va" netns "$a" && ip link set "$vb" netns "$b" || { echo "FAIL: moving the veth ends"; exit 1; }
ip -n "$a" addr add 10.251.34.1/30 dev "$va" && ip -n "$b" addr add 10.251.34.2/30 dev "$vb" &&
  ip -n "$a" link set "$va" up && ip -n "$b" link set "$vb" up && ip -n "$a" link set lo up &&
  ip -n "$b" link set lo up || { echo "FAIL: setting up the veth pair"; exit 1; }

failures=0
# check NAME EXPECTED_EXIT REGEX -- COMMAND...: runs COMMAND, checks its exit code and output.
check() {
  local name="$1" expected="$2" regex="$3"
  shift 4
  local out code
  out=$("$@" 2>&1)
  code=$?
  if [[ $code -ne $expected ]] || ! grep -qE -- "$regex" <<<"$out"; then
    echo "FAIL $name: exit $code (expected $expected), output:"; echo "$out" | tail -20
    failures=$((failures + 1))
  else
    echo "ok   $name"
  fi
}
# start_host NAMESPACE LOG ARGS...: a host in NAMESPACE, ready when it says it serves.
start_host() {
  local ns="$1" log="$2"
  shift 2
  ip netns exec "$ns" "$costar" host "$@" 2>"$log" &
  pids+=($!)
  for _ in $(seq 600); do
    grep -q "costar host: serving" "$log" 2>/dev/null && return 0
    sleep 0.1
  done
  echo "FAIL: the host in $ns did not start: $(cat "$log")"; exit 1
}

cat >"$tmp/plan.xml" <<'XML'
<root BTCPP_format="4"><BehaviorTree ID="main"><Sequence>
  <TestAction polls="3"/><TestCount counter="parts"/>
</Sequence></BehaviorTree></root>
XML
printf '{"partition": "netns-%s", "interface": "%s", "components": ["test_actions", "test_counter"]}' $$ "$vb" \
  >"$tmp/remote.json"
start_host "$a" "$tmp/host.log" test_actions test_counter -w test --partition "netns-$$" --interface "$va"
check "netns: test cell across the veth" 0 '^SUCCESS' -- \
  ip netns exec "$b" "$costar" run "$tmp/plan.xml" -w test --remote "$tmp/remote.json"

# A simulated cell's gripper and perception in the other namespace, in lockstep: the same trial.
printf '{"domain": 73, "partition": "netns-sim-%s", "interface": "%s", "components": ["gripper", "perception"]}' \
  $$ "$vb" >"$tmp/sim_remote.json"
start_host "$a" "$tmp/sim_host.log" gripper perception -w ur5-sim --domain 73 --partition "netns-sim-$$" \
  --interface "$va"
trial_args=(trials examples/ur5/pick_up_node.xml --judge lift -n 1 --seed 41 -j 1)
check "netns: sim trial in one process" 0 '^1 of 1 trials succeeded' -- \
  ip netns exec "$b" "$costar" "${trial_args[@]}" --json "$tmp/local.json"
check "netns: sim trial across the veth" 0 '^1 of 1 trials succeeded' -- \
  ip netns exec "$b" "$costar" "${trial_args[@]}" --remote "$tmp/sim_remote.json" --json "$tmp/remote_trials.json"
check "netns: the same" 0 '^same: 1 trials$' -- python3 -c '
import json, sys
def trials(file):
    return [(t["seed"], t["success"], t["cycle_time_s"], t["judged"]) for t in json.load(open(file))["results"]]
a, b = trials(sys.argv[1]), trials(sys.argv[2])
print(f"same: {len(a)} trials" if a == b and a else f"differ: {a} vs {b}")' "$tmp/local.json" "$tmp/remote_trials.json"

# Loopback (the default) stays in its namespace: a host there is not seen from the other.
printf '{"partition": "netns-lo-%s", "components": ["test_actions"]}' $$ >"$tmp/lo.json"
start_host "$a" "$tmp/lo_host.log" test_actions -w test --partition "netns-lo-$$"
check "netns: loopback stays on its computer" 2 "component 'test_actions': no host serves it on DDS domain 0, partition 'netns-lo-" -- \
  ip netns exec "$b" "$costar" run "$tmp/plan.xml" -w test --remote "$tmp/lo.json"

[[ $failures -eq 0 ]] || exit 1
