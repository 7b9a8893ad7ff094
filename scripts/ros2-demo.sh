#!/usr/bin/env bash
# `make ros2-demo`: ROBODOC on ROS 2 over DDS (Cyclone DDS, no rclcpp). In a private network
# namespace when possible (else on 127.0.0.1 only), it starts:
# - safecass_dds_node with the robodoc specs, unchanged, and examples/dds_robodoc/mapping.json;
# - a /diagnostics reader written from the same IDL, as a ROS 2 tool would see the wire;
# - a simulated JR3 driver publishing geometry_msgs/msg/WrenchStamped on /jr3/wrench, its force
#   ramping through the 30 N limit and back;
# and prints each change of the components' statuses on /diagnostics, then stops everything by PID.
#
# Usage: scripts/ros2-demo.sh BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ros-lib.sh
ros_in_netns "$0" "$@"

build=$(realpath "${1:-build}")
work="$build/ros2-demo"
rm -rf "$work"
mkdir -p "$work"
ROS_DIR=$work
export ROS_DOMAIN_ID=${ROS_DOMAIN_ID:-42}
trap ros_stop_all EXIT

echo "== ROBODOC on ROS 2 (DDS domain $ROS_DOMAIN_ID): the robodoc specs unchanged, $(grep -c . examples/dds_robodoc/mapping.json) lines of mapping"
echo "   Fz: 5 N for 3 s, up to 40 N at 5 s (JR3's limit is 30 N), held until 9 s, back to 5 N at 11 s"
echo "   each line: a status on rt/diagnostics (diagnostic_msgs/msg/DiagnosticArray) whose level or message changed"
echo
ros_start node "$build/bin/safecass_dds_node" examples/robodoc/robodoc.json --mapping examples/dds_robodoc/mapping.json
: >"$work/echo.log"  # before the reader starts, so that tail finds it at once
ros_start echo "$build/bin/dds_diagnostics_echo" --prefix "safecass: "
ros_start jr3 "$build/bin/dds_robodoc_jr3" --profile 0:5,3:5,5:40,9:40,11:5 --seconds 14
# Component-level statuses ("safecass: JR3: ..."), as they come.
tail -n +1 -F "$work/echo.log" 2>/dev/null | grep --line-buffered -E 'safecass: [A-Z0-9]+: ' &
tail_pid=$!
for _ in $(seq 150); do kill -0 "$pid_jr3" 2>/dev/null || break; sleep 0.1; done
sleep 1
kill "$tail_pid" 2>/dev/null || true
wait "$tail_pid" 2>/dev/null || true
ros_stop_all
echo
echo "Logs: $work (node.log, echo.log: every status change, jr3.log)"
