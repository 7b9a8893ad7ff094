#!/usr/bin/env bash
# `safecass replay` of a ROS 1 bag through the robodoc specs, unchanged, with the ros_robodoc
# example's mapping file: the bag (written by write_bag with the rosbag C++ API) replays to the
# force error; a truncated bag and a bad message are refused with the bag and the message index.
# Usage: bag_replay_test.sh CASE SAFECASS WRITE_BAG   (run from the source root)
set -u
case_name=$1
safecass=$2
write_bag=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
replay() { "$safecass" replay examples/robodoc/robodoc.json --mapping examples/ros_robodoc/mapping.json --input "$@"; }

case $case_name in
  a_bag_of_the_ros_example_replays_through_the_robodoc_specs_to_the_force_error)
    "$write_bag" "$tmp/robodoc.bag" good || fail "write_bag"
    replay "$tmp/robodoc.bag" >"$tmp/out" 2>"$tmp/err"; code=$?
    [ $code = 0 ] || fail "exit code $code: $(cat "$tmp/err")"
    # 5 → 40 N over 0.2 .. 0.6 s: above 25 N (warning) at 0.43 s, above 30 N (error) at 0.486 s.
    grep -q "^t=0.43[0-9]*  JR3.s_A  Normal -> Warning  EVT_FORCE_HIGH" "$tmp/out" || fail "no warning: $(cat "$tmp/out")"
    grep -q "^t=0.48[0-9]*  JR3.s_A  Warning -> Error  EVT_FORCE_ERROR  \[filter force_limit, JR3.ForceNorm = 30" "$tmp/out" \
      || fail "no force error: $(cat "$tmp/out")"
    grep -q "CONTROL.s_R.ForceData  Normal -> Error  EVT_SERVICE_FAILURE  <- JR3.s_A:EVT_FORCE_ERROR" "$tmp/out" \
      || fail "no propagation: $(cat "$tmp/out")"
    grep -q "JR3.s_A  Error -> Warning" "$tmp/out" || fail "the error does not clear"
    # Signals of the mapping that the specs do not have are said, not fed.
    grep -q "note: .*mapped signal JR3.Torque (/jr3/wrench wrench.torque) is not in the system: not fed" "$tmp/err" \
      || fail "skipped signals not said: $(cat "$tmp/err")"
    grep -q "replayed [0-9]* samples" "$tmp/err" || fail "summary: $(cat "$tmp/err")"
    # --diff on a bag too.
    "$safecass" replay --diff tests/data/replay/robodoc_low_limit.json examples/robodoc/robodoc.json \
      --mapping examples/ros_robodoc/mapping.json --input "$tmp/robodoc.bag" >"$tmp/diff" 2>"$tmp/err"; code=$?
    [ $code = 1 ] || fail "diff: exit code $code: $(cat "$tmp/err")"
    grep -q "^JR3.s_A$" "$tmp/diff" || fail "diff: $(cat "$tmp/diff")"
    ;;
  a_truncated_bag_is_refused_with_the_reason)
    "$write_bag" "$tmp/robodoc.bag" good || fail "write_bag"
    size=$(stat -c %s "$tmp/robodoc.bag")
    head -c $((size / 2)) "$tmp/robodoc.bag" >"$tmp/cut.bag"
    replay "$tmp/cut.bag" >"$tmp/out" 2>"$tmp/err"; code=$?
    [ $code = 2 ] || fail "exit code $code: $(cat "$tmp/err")"
    grep -q "^$tmp/cut.bag: .*\(truncated\|damaged\)" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    [ -s "$tmp/out" ] && fail "something ran: $(cat "$tmp/out")"
    ;;
  a_bad_message_is_refused_with_its_index)
    "$write_bag" "$tmp/wrong.bag" wrong_type || fail "write_bag"
    replay "$tmp/wrong.bag" >"$tmp/out" 2>"$tmp/err"; code=$?
    [ $code = 2 ] || fail "exit code $code: $(cat "$tmp/err")"
    # (rosbag files the Float64 under the topic's WrenchStamped connection: its 8 bytes cannot be read as one.)
    grep -q "^$tmp/wrong.bag: message 1[0-9][0-9] (/jr3/wrench): cannot be read as geometry_msgs/WrenchStamped: byte 8: " "$tmp/err" \
      || fail "message: $(cat "$tmp/err")"
    [ -s "$tmp/out" ] && fail "something ran: $(cat "$tmp/out")"
    "$write_bag" "$tmp/short.bag" short_joint_state || fail "write_bag"
    replay "$tmp/short.bag" >"$tmp/out" 2>"$tmp/err"; code=$?
    # SERVO.Goal is not a signal of the specs: the command topic feeds nothing, so its bad message is not read.
    [ $code = 0 ] || fail "short: exit code $code: $(cat "$tmp/err")"
    ;;
  *) fail "unknown case $case_name" ;;
esac
echo "ok: $case_name"
