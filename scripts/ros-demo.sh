#!/usr/bin/env bash
# `make ros-demo`: ROBODOC on ROS 1. Starts a roscore on 127.0.0.1 (in a private network namespace
# when possible), diagnostic_aggregator, the CONTROL node with SAFECASS and a simulated JR3 whose
# force ramps through the 30 N limit and back; prints what `rosdiagnostic` shows before, during
# and after the fault, then stops everything by PID.
#
# Usage: scripts/ros-demo.sh BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ros-lib.sh
ros_in_netns "$0" "$@"

build=$(realpath "${1:-build}")
work="$build/ros-demo"
rm -rf "$work"
ros_env 11611 "$work"
trap ros_stop_all EXIT

ros_master 11611
ros_aggregator "$work/ament" examples/ros_robodoc/analyzers.yaml
ros_start control "$build/bin/ros_robodoc_control" examples/ros_robodoc/mapping.json
# Fz: 5 N for 3 s, up to 40 N at 5 s, held until 9 s, back to 5 N at 11 s.
ros_start jr3 "$build/bin/ros_robodoc_jr3" --profile 0:5,3:5,5:40,9:40,11:5
start=$(date +%s.%N)
at() { sleep "$(awk -v a="$1" -v s="$start" -v n="$(date +%s.%N)" 'BEGIN { d = a - (n - s); print (d > 0 ? d : 0) }')"; }

echo "== ROBODOC on ROS 1: $(grep -c . examples/ros_robodoc/mapping.json) lines of mapping, the robodoc specs unchanged"
at 2
echo; echo "== t = 2 s, Fz = 5 N: rosdiagnostic -l 0 --filter 'safecass: [A-Z0-9]+$'"
ros_diagnostic -l 0 --filter 'safecass: [A-Z0-9]+$'
at 6.5
echo; echo "== t = 6.5 s, Fz = 40 N (limit 30 N): rosdiagnostic (WARN and above)"
ros_diagnostic
echo; echo "== the same, in detail for CONTROL: rosdiagnostic -d --filter 'CONTROL$'"
ros_diagnostic -d --filter 'CONTROL$'
at 12.5
echo; echo "== t = 12.5 s, Fz back to 5 N: rosdiagnostic -l 0 --filter 'safecass: [A-Z0-9]+$'"
ros_diagnostic -l 0 --filter 'safecass: [A-Z0-9]+$'
ros_stop_all
echo; echo "== what the CONTROL node logged (its loop is chosen by dispatch() on CONTROL's state):"
sed 's/\x1b\[[0-9;]*m//g; s/^\[ INFO\] \[[0-9.]*\]: /  /' "$work/control.log" | head -20
echo; echo "Logs: $work"
