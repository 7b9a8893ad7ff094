#!/usr/bin/env bash
# `safecass replay` of a ROS 2 bag (rosbag2's sqlite3 store, the wire's CDR) through the robodoc
# specs, unchanged: the bag (written by write_rosbag2 with Cyclone DDS's own serialiser) replays to
# the force error, as a .db3 file and as a bag directory; a damaged store, a topic of another type,
# a message whose CDR is cut short and a JointState without the element a path reads are refused
# with the bag and the message index, and nothing runs.
# Usage: rosbag2_replay_test.sh CASE SAFECASS WRITE_ROSBAG2   (run from the source root)
set -u
case_name=$1
safecass=$2
write=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
replay() { "$safecass" replay examples/robodoc/robodoc.json --mapping tests/integration/dds/replay_mapping.json --input "$@"; }
refused() {  # refused BAG REGEX: exit 2, the message, nothing ran
  replay "$1" >"$tmp/out" 2>"$tmp/err"; local code=$?
  [ $code = 2 ] || fail "$1: exit code $code: $(cat "$tmp/err")"
  grep -Eq -- "$2" "$tmp/err" || fail "$1: message: $(cat "$tmp/err")"
  [ -s "$tmp/out" ] && fail "$1: something ran: $(cat "$tmp/out")"
  return 0
}

case $case_name in
  a_ros2_bag_replays_through_the_robodoc_specs_to_the_force_error)
    "$write" "$tmp/robodoc.db3" good || fail "write_rosbag2"
    for input in "$tmp/robodoc.db3" "$tmp"; do  # the file, and the bag's directory
      replay "$input" >"$tmp/out" 2>"$tmp/err"; code=$?
      [ $code = 0 ] || fail "$input: exit code $code: $(cat "$tmp/err")"
      # 5 → 40 N over 0.2 .. 0.6 s: above 25 N (warning) at 0.43 s, above 30 N (error) at 0.486 s.
      grep -q "^t=0.43[0-9]*  JR3.s_A  Normal -> Warning  EVT_FORCE_HIGH" "$tmp/out" || fail "no warning: $(cat "$tmp/out")"
      grep -q "^t=0.48[0-9]*  JR3.s_A  Warning -> Error  EVT_FORCE_ERROR  \[filter force_limit, JR3.ForceNorm = 30" "$tmp/out" \
        || fail "no force error: $(cat "$tmp/out")"
      grep -q "CONTROL.s_R.ForceData  Normal -> Error  EVT_SERVICE_FAILURE  <- JR3.s_A:EVT_FORCE_ERROR" "$tmp/out" \
        || fail "no propagation: $(cat "$tmp/out")"
      grep -q "JR3.s_A  Error -> Warning" "$tmp/out" || fail "the error does not clear"
      grep -q "SERVO.s_F" "$tmp/out" && fail "SERVO overloaded (its cycle time is 10 % of its period): $(cat "$tmp/out")"
      grep -q "note: .*mapped signal JR3.Torque (/jr3/wrench wrench.torque) is not in the system: not fed" "$tmp/err" \
        || fail "skipped signals not said: $(cat "$tmp/err")"
      grep -q "replayed [0-9]* samples" "$tmp/err" || fail "summary: $(cat "$tmp/err")"
    done
    ;;
  a_damaged_or_foreign_store_is_refused_with_the_reason)
    "$write" "$tmp/robodoc.db3" good || fail "write_rosbag2"
    size=$(stat -c %s "$tmp/robodoc.db3")
    head -c $((size / 2)) "$tmp/robodoc.db3" >"$tmp/cut.db3"
    refused "$tmp/cut.db3" "^$tmp/cut.db3: .*(truncated|damaged|malformed|not a ROS 2 bag)"
    python3 -c "import sqlite3; sqlite3.connect('$tmp/other.db3').execute('CREATE TABLE t(x)')"
    refused "$tmp/other.db3" "^$tmp/other.db3: not a ROS 2 bag \(rosbag2 sqlite3 store with 'messages' and 'topics'\): no such table"
    mkdir "$tmp/empty"
    refused "$tmp/empty" "^$tmp/empty: a ROS 2 bag directory with no .db3 file"
    ;;
  a_bad_message_is_refused_with_its_index)
    "$write" "$tmp/wrong.db3" wrong_type || fail "write_rosbag2"
    refused "$tmp/wrong.db3" "^$tmp/wrong.db3: message 1 \(/jr3/wrench\): a std_msgs/msg/Float64 message; the mapping says geometry_msgs/WrenchStamped$"
    "$write" "$tmp/cut.db3" bad_cdr || fail "write_rosbag2"
    refused "$tmp/cut.db3" "^$tmp/cut.db3: message 1[0-9][0-9] \(/jr3/wrench\): not a geometry_msgs/msg/WrenchStamped in CDR: byte [0-9]+: a 8-byte value runs past the end \(20 bytes\)$"
    "$write" "$tmp/short.db3" short_joint_state || fail "write_rosbag2"
    refused "$tmp/short.db3" "^$tmp/short.db3: message [0-9]+ \(/servo/joints\): position has 0 elements, no \[0\]$"
    ;;
  *) fail "unknown case $case_name" ;;
esac
echo "ok: $case_name"
