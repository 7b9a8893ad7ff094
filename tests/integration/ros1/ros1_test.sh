#!/usr/bin/env bash
# ROS 1 integration tests. Usage: ros1_test.sh CASE BIN_DIR (from the source root).
# Exit 77 (skipped) only when ROS 1 is not installed.
set -euo pipefail
case_name=$1
bin=$(realpath "$2")
if ! command -v roscore >/dev/null || [ ! -x /usr/lib/diagnostic_aggregator/aggregator_node ]; then
  echo "SKIPPED: ROS 1 is not installed (roscore, diagnostic_aggregator: scripts/install-deps.sh installs them)"
  exit 77
fi
source scripts/ros-lib.sh
ros_in_netns "$0" "$@"

dir=$(dirname "$bin")/ros1-test/$case_name
rm -rf "$dir"
ros_env 11711 "$dir"
finish() {
  local rc=$?
  ros_stop_all
  if [ $rc -ne 0 ]; then
    for f in "$dir"/*.log; do echo "---- $f"; tail -25 "$f"; done
  fi
  exit $rc
}
trap finish EXIT
probe() { "$bin/ros1_probe" "$@"; }
step() { echo "-- $*"; }

case $case_name in
force_fault_shows_in_diagnostics_agg_with_its_cause_and_clears)
  ros_master 11711
  ros_aggregator "$dir/ament" examples/ros_robodoc/analyzers.yaml
  ros_start control "$bin/ros_robodoc_control" examples/ros_robodoc/mapping.json
  ros_start jr3 "$bin/ros_robodoc_jr3" --fz 5
  step "all Normal at 5 N"
  probe wait /diagnostics_agg "safecass: JR3" 0 Normal 20
  probe wait /diagnostics_agg "safecass: CONTROL" 0 Normal 5
  step "40 N: JR3's force limit fires; CONTROL and SERVO fail through the connections"
  probe float /jr3_sim/set_fz 40
  probe wait /diagnostics_agg "safecass: JR3.s_A" 2 "EVT_FORCE_ERROR (cause JR3.s_A:EVT_FORCE_ERROR, force_limit judged JR3.ForceNorm" 10
  probe wait /diagnostics_agg "safecass: CONTROL" 2 "EVT_SERVICE_FAILURE (cause JR3.s_A:EVT_FORCE_ERROR" 5
  probe wait /diagnostics_agg "safecass: SERVO" 2 "cause JR3.s_A:EVT_FORCE_ERROR" 5
  step "the sensor's own WARN on /diagnostics became an event on JR3.s_F"
  probe wait /diagnostics_agg "safecass: JR3.s_F" 1 "EVT_ROS_DIAG_WARN (cause JR3.s_F:EVT_ROS_DIAG_WARN, ros:diagnostics judged jr3_sim: saturation = 1)" 5
  probe wait /diagnostics_agg "jr3_sim: saturation" 1 "near the end" 5
  step "back to 5 N: everything clears"
  probe float /jr3_sim/set_fz 5
  probe wait /diagnostics_agg "safecass: CONTROL" 0 Normal 10
  probe wait /diagnostics_agg "safecass: JR3" 0 Normal 10
  probe wait /diagnostics_agg "safecass: SERVO" 0 Normal 5
  ;;
missing_node_missing_topic_and_bad_messages_are_reported)
  ros_master 11711
  ros_start safecass "$bin/safecass_ros1_node" tests/integration/ros1/graph_mapping.json
  ros_start jr3 "$bin/ros_robodoc_jr3" --fz 5
  step "a mapped node that is not running: BMM.s_F"
  probe wait /diagnostics "safecass: BMM.s_F" 2 "EVT_ROS_GRAPH_MISSING (cause BMM.s_F:EVT_ROS_GRAPH_MISSING, ros:graph judged node /bmm_sim of BMM is not running)" 15
  step "a declared topic that nobody publishes: JR3.s_P.ForceData"
  probe wait /diagnostics "safecass: JR3.s_P.ForceData" 2 "ros:graph judged node /jr3_sim does not publish /jr3/temperature" 5
  step "JointState with 3 positions for a 6-element signal: rejected, counted, nothing else changes"
  probe wait /diagnostics "safecass: SERVO.s_F" 0 Normal 5
  probe wait /diagnostics "safecass: bridge" 0 ", 0 rejected" 5
  probe joints /servo/joints 3
  probe wait /diagnostics "safecass: bridge" 1 ", 1 rejected" 5
  probe wait /diagnostics "safecass: SERVO.s_F" 0 Normal 5
  probe wait /diagnostics "safecass: SERVO.s_A" 0 Normal 5
  probe joints /servo/joints 6
  step "other nodes' statuses: ERROR, then STALE, then a level that is not one, then OK, on BMM.s_A"
  probe status /diagnostics "probe: motor" 2
  probe wait /diagnostics "safecass: BMM.s_A" 2 "EVT_ROS_DIAG_ERROR (cause BMM.s_A:EVT_ROS_DIAG_ERROR, ros:diagnostics judged probe: motor = 2)" 5
  probe status /diagnostics "probe: motor" 3
  probe wait /diagnostics "safecass: BMM.s_A" 2 "EVT_STALE (cause BMM.s_A:EVT_STALE" 5
  probe status /diagnostics "probe: motor" 7
  probe wait /diagnostics "safecass: bridge" 1 ", 2 rejected" 5
  probe wait /diagnostics "safecass: BMM.s_A" 2 "EVT_STALE (cause BMM.s_A:EVT_STALE" 5
  probe status /diagnostics "probe: motor" 0
  probe wait /diagnostics "safecass: BMM.s_A" 0 Normal 5
  step "the force sensor stops: its node is missing, then comes back"
  probe wait /diagnostics "safecass: JR3.s_F" 0 Normal 5
  ros_stop "$pid_jr3"
  probe wait /diagnostics "safecass: JR3.s_F" 2 "EVT_ROS_GRAPH_MISSING (cause JR3.s_F:EVT_ROS_GRAPH_MISSING, ros:graph judged node /jr3_sim of JR3 is not running" 10
  ros_start jr3 "$bin/ros_robodoc_jr3" --fz 5
  probe wait /diagnostics "safecass: JR3.s_F" 0 Normal 10
  ;;
timing_checks_fire_when_a_topic_stops_and_when_it_slows_down)
  ros_master 11711
  ros_start safecass "$bin/safecass_ros1_node" tests/integration/ros1/timing_mapping.json
  ros_start jr3 "$bin/ros_robodoc_jr3" --rate 200 --fz 5
  step "200 Hz: JR3.s_F Normal (after a second, when the start-up is over)"
  probe wait /diagnostics "safecass: bridge" 0 "" 15
  sleep 1
  probe wait /diagnostics "safecass: JR3.s_F" 0 Normal 5
  step "the publisher stops: the watchdog on the topic's arrivals raises EVT_WRENCH_TOPIC_STALE"
  ros_stop "$pid_jr3"
  probe wait /diagnostics "safecass: JR3.s_F" 2 "EVT_WRENCH_TOPIC_STALE (cause JR3.s_F:EVT_WRENCH_TOPIC_STALE, ros/jr3/wrench:watchdog" 10
  step "it comes back at 30 Hz, under min_rate 50: the watchdogs clear, the frequency check warns"
  ros_start jr3 "$bin/ros_robodoc_jr3" --rate 30 --fz 5
  probe wait /diagnostics "safecass: JR3.s_F" 1 "EVT_ROS_TOPIC_RATE (cause JR3.s_F:EVT_ROS_TOPIC_RATE, ros/jr3/wrench:frequency" 10
  step "back at 200 Hz: Normal again"
  ros_stop "$pid_jr3"
  ros_start jr3 "$bin/ros_robodoc_jr3" --rate 200 --fz 5
  probe wait /diagnostics "safecass: JR3.s_F" 0 Normal 10
  ;;
node_records_its_inputs_and_their_replay_reaches_the_same_force_fault)
  ros_master 11711
  ros_start safecass "$bin/safecass_ros1_node" examples/ros_robodoc/mapping.json --record "$dir/h.jsonl"
  ros_start jr3 "$bin/ros_robodoc_jr3" --fz 5
  step "5 N, then 40 N (JR3's force limit fires), then 5 N again, recorded"
  probe wait /diagnostics "safecass: JR3.s_A" 0 Normal 20
  probe float /jr3_sim/set_fz 40
  probe wait /diagnostics "safecass: JR3.s_A" 2 "EVT_FORCE_ERROR (cause JR3.s_A:EVT_FORCE_ERROR" 10
  probe float /jr3_sim/set_fz 5
  probe wait /diagnostics "safecass: JR3.s_A" 0 Normal 10
  ros_stop "$pid_safecass"
  step "the node's history has the fault and its clearing; its inputs replay to the same"
  [ -s "$dir/h.inputs" ] || { echo "no inputs recorded next to the history"; exit 1; }
  grep -q '"kind":"transition","component":"JR3","machine":"JR3.s_A","event":"EVT_FORCE_ERROR".*"to":"Error"' "$dir/h.jsonl" || { echo "no force error in the history"; exit 1; }
  "$bin/safecass" replay examples/robodoc/robodoc.json --input "$dir/h.inputs" >"$dir/replay.txt" 2>"$dir/replay.err" ||
    { echo "replay failed: $(cat "$dir/replay.err")"; exit 1; }
  grep -Eq "JR3.s_A +(Normal|Warning) -> Error .*EVT_FORCE_ERROR" "$dir/replay.txt" ||
    { echo "the replay has no force error:"; cat "$dir/replay.txt"; exit 1; }
  grep -Eq "JR3.s_A +Error -> (Normal|Warning)" "$dir/replay.txt" ||
    { echo "the replay's force error does not clear:"; cat "$dir/replay.txt"; exit 1; }
  ;;
*)
  echo "unknown case $case_name" >&2
  exit 2
  ;;
esac
echo "PASS $case_name"
