#!/usr/bin/env bash
# ROS 2 (DDS) integration tests: safecass_dds_node, the example's JR3 driver and /diagnostics
# reader as processes, each case in its own loopback-only network namespace when possible (else
# on 127.0.0.1, in a domain of its own), stopped by PID.
# Usage: dds_test.sh CASE BIN_DIR (from the source root).
set -euo pipefail
case_name=$1
bin=$(realpath "$2")
source scripts/ros-lib.sh
ros_in_netns "$0" "$@"

dir=$(dirname "$bin")/dds-test/$case_name
rm -rf "$dir"
mkdir -p "$dir"
ROS_DIR=$dir
# Outside a namespace, a domain per case keeps concurrent cases apart.
export ROS_DOMAIN_ID=$((100 + $(cksum <<<"$case_name" | cut -d' ' -f1) % 100))
finish() {
  local rc=$?
  ros_stop_all
  if [ $rc -ne 0 ]; then
    for f in "$dir"/*.log; do echo "---- $f"; tail -25 "$f"; done
  fi
  exit $rc
}
trap finish EXIT
step() { echo "-- $*"; }
# wait_line FILE REGEX SECONDS: until a line of FILE matches.
wait_line() {
  local i
  for ((i = 0; i < $3 * 10; i++)); do
    if grep -Eq -- "$2" "$1" 2>/dev/null; then return 0; fi
    sleep 0.1
  done
  echo "no line matching '$2' in $1 within $3 s"
  return 1
}
# after_line FILE FIRST THEN: a line matching THEN comes after one matching FIRST.
after_line() {
  awk -v a="$2" -v b="$3" '$0 ~ a { seen = 1 } seen && $0 ~ b { found = 1 } END { exit !found }' "$1" ||
    { echo "no line matching '$3' after one matching '$2' in $1"; return 1; }
}
# wait_after FILE FIRST THEN SECONDS: until a line matching THEN comes after one matching FIRST.
wait_after() {
  local i
  for ((i = 0; i < $4 * 10; i++)); do
    if after_line "$1" "$2" "$3" >/dev/null 2>&1; then return 0; fi
    sleep 0.1
  done
  after_line "$1" "$2" "$3"
}
node() { ros_start node "$bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping examples/dds_robodoc/mapping.json "$@"; }
echo_diagnostics() { ros_start echo "$bin/dds_diagnostics_echo" --prefix "safecass: "; }

case $case_name in
demo_force_fault_shows_on_ros2_diagnostics_with_its_cause_and_clears)
  out=$dir/demo.txt
  ./scripts/ros2-demo.sh "$(dirname "$bin")" >"$out" 2>&1 || { cat "$out"; exit 1; }
  cat "$out"
  step "JR3 Normal at 5 N, ERROR with its cause above 30 N, Normal again at 5 N; CONTROL fails through the connection"
  grep -Eq 'OK +safecass: JR3: Normal' "$out"
  after_line "$out" 'OK +safecass: JR3: Normal' \
    'ERROR safecass: JR3: Error: EVT_FORCE_ERROR \(cause JR3.s_A:EVT_FORCE_ERROR, force_limit judged JR3.ForceNorm = 3[0-9.]*'
  after_line "$out" 'ERROR safecass: JR3: Error: EVT_FORCE_ERROR' 'OK +safecass: JR3: Normal'
  after_line "$out" 'OK +safecass: CONTROL: Normal' 'ERROR safecass: CONTROL: Error: .*cause JR3.s_A:EVT_FORCE_ERROR'
  ;;
a_driver_killed_turns_its_view_to_error_and_back_when_it_returns)
  node
  echo_diagnostics
  ros_start jr3 "$bin/dds_robodoc_jr3" --fz 5
  wait_line "$dir/echo.log" 'OK +safecass: JR3.s_F: Normal' 20
  step "kill -9 the driver: its topic stops and its participant goes"
  kill -KILL "$pid_jr3"
  wait_line "$dir/echo.log" 'ERROR safecass: JR3.s_F: Error: EVT_(WRENCH_TOPIC|FORCE)_STALE' 10
  wait_line "$dir/echo.log" 'ERROR safecass: JR3.s_P.ForceData: Error: EVT_ROS_GRAPH_MISSING .*nobody publishes /jr3/wrench' 10
  step "a new driver: everything clears"
  ros_start jr3b "$bin/dds_robodoc_jr3" --fz 5
  wait_after "$dir/echo.log" 'ERROR safecass: JR3.s_P.ForceData' 'OK +safecass: JR3.s_P.ForceData: Normal' 10
  wait_after "$dir/echo.log" 'ERROR safecass: JR3.s_F' 'OK +safecass: JR3.s_F: Normal' 10
  ;;
node_records_its_inputs_and_their_replay_reaches_the_same_force_fault)
  node --record "$dir/h.jsonl"
  echo_diagnostics
  ros_start jr3 "$bin/dds_robodoc_jr3" --profile 0:5,1.5:5,2:40,3.5:40,4:5
  wait_line "$dir/echo.log" 'ERROR safecass: JR3.s_A: Error: EVT_FORCE_ERROR' 20
  wait_after "$dir/echo.log" 'ERROR safecass: JR3.s_A' 'OK +safecass: JR3.s_A: Normal' 20
  ros_stop "$pid_node"
  step "the node's history has the fault; its inputs replay to the same"
  [ -s "$dir/h.inputs" ] || { echo "no inputs recorded next to the history"; exit 1; }
  grep -q '"machine":"JR3.s_A","event":"EVT_FORCE_ERROR".*"to":"Error"' "$dir/h.jsonl" || { echo "no force error in the history"; exit 1; }
  "$bin/safecass" replay examples/robodoc/robodoc.json --input "$dir/h.inputs" >"$dir/replay.txt" 2>"$dir/replay.err" ||
    { echo "replay failed: $(cat "$dir/replay.err")"; exit 1; }
  grep -Eq "JR3.s_A +(Normal|Warning) -> Error .*EVT_FORCE_ERROR" "$dir/replay.txt" ||
    { echo "the replay has no force error:"; cat "$dir/replay.txt"; exit 1; }
  ;;
node_refuses_bad_arguments_and_mappings_with_where_and_what)
  set +e
  "$bin/safecass_dds_node" examples/robodoc/robodoc.json >"$dir/a.txt" 2>&1
  [ $? -eq 2 ] && grep -q -- "--mapping FILE is required" "$dir/a.txt" || { cat "$dir/a.txt"; exit 1; }
  "$bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping examples/dds_robodoc/mapping.json --domain 300 >"$dir/b.txt" 2>&1
  [ $? -eq 2 ] && grep -q "domain takes an integer in \[0, 232\]" "$dir/b.txt" || { cat "$dir/b.txt"; exit 1; }
  "$bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping examples/dds_robodoc/mapping.json --record "$dir/h.jsonl" \
    --max-bytes 10M >"$dir/e.txt" 2>&1
  [ $? -eq 2 ] && grep -q -- "--max-bytes takes a number of bytes" "$dir/e.txt" || { cat "$dir/e.txt"; exit 1; }
  sed 's/"wrench.force.z"/"wrench.force.q"/' examples/dds_robodoc/mapping.json >"$dir/bad.json"
  "$bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping "$dir/bad.json" >"$dir/c.txt" 2>&1
  [ $? -eq 2 ] && grep -Eq "bad.json:[0-9]+:[0-9]+: error: field path 'wrench.force.q'" "$dir/c.txt" || { cat "$dir/c.txt"; exit 1; }
  ROS_DOMAIN_ID=x "$bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping examples/dds_robodoc/mapping.json >"$dir/d.txt" 2>&1
  [ $? -eq 3 ] && grep -q "ROS_DOMAIN_ID='x'" "$dir/d.txt" || { cat "$dir/d.txt"; exit 1; }
  set -e
  ;;
*)
  echo "unknown case $case_name" >&2
  exit 2
  ;;
esac
echo "PASS $case_name"
