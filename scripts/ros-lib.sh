# Shell helpers for running a ROS 1 graph on 127.0.0.1 (sourced by scripts/ros-demo.sh and the
# ROS integration tests). Every process started here is remembered by PID and stopped by PID.

# ros_in_netns "$0" "$@": re-runs the calling script in a private network namespace holding only
# loopback (roscpp listens on 0.0.0.0 whatever ROS_IP says). Without unshare rights, stays put.
ros_in_netns() {
  if [ -z "${SAFECASS_ROS_NETNS:-}" ] && command -v unshare >/dev/null && unshare -n true 2>/dev/null; then
    SAFECASS_ROS_NETNS=1 exec unshare -n bash "$@"
  fi
  if [ -n "${SAFECASS_ROS_NETNS:-}" ]; then ip link set lo up; fi
}

# ros_env PORT DIR: the environment of a master on 127.0.0.1:PORT; logs and ROS_HOME under DIR.
ros_env() {
  mkdir -p "$2/log"
  export ROS_MASTER_URI="http://127.0.0.1:$1" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
  export ROS_HOME="$2" ROS_LOG_DIR="$2/log" PYTHONPATH=/usr/lib/python3/dist-packages
  ROS_DIR="$2"
}

ros_pids=()
# ros_start NAME CMD...: starts CMD in the background, output in $ROS_DIR/NAME.log.
ros_start() {
  local name=$1
  shift
  "$@" >"$ROS_DIR/$name.log" 2>&1 &
  ros_pids+=($!)
  eval "pid_${name//[^a-zA-Z0-9_]/_}=$!"
}

# ros_stop PID: SIGINT, then SIGKILL after 3 s; its direct children (roscore's master) likewise.
ros_stop() {
  local pid=$1 children
  children=$(pgrep -P "$pid" 2>/dev/null || true)
  kill -INT "$pid" 2>/dev/null || true
  for _ in $(seq 30); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null || true
  for c in $children; do kill -KILL "$c" 2>/dev/null || true; done
  wait "$pid" 2>/dev/null || true
}

ros_stop_all() {
  local i
  for ((i = ${#ros_pids[@]} - 1; i >= 0; i--)); do ros_stop "${ros_pids[i]}"; done
  ros_pids=()
}

# ros_master PORT: starts roscore and waits (at most 15 s) until it answers.
ros_master() {
  ros_start roscore roscore -p "$1"
  for _ in $(seq 150); do
    if rosparam get /rosdistro >/dev/null 2>&1; then return 0; fi
    sleep 0.1
  done
  echo "ros: roscore on port $1 did not answer within 15 s" >&2
  cat "$ROS_DIR/roscore.log" >&2
  return 1
}

# ros_aggregator PREFIX_DIR ANALYZERS_YAML: Debian's diagnostic_aggregator with a generated plugin index.
ros_aggregator() {
  "$(dirname "${BASH_SOURCE[0]}")/ros-aggregator-prefix.sh" "$1" >/dev/null
  rosparam load "$2" /diagnostic_aggregator
  AMENT_PREFIX_PATH="$1" ros_start aggregator /usr/lib/diagnostic_aggregator/aggregator_node
}

# ros_diagnostic ARGS...: what `rosdiagnostic` prints (one aggregated message).
ros_diagnostic() {
  timeout 10 /usr/bin/python3 -c 'import sys; from rosdiagnostic import rosdiagnosticmain; rosdiagnosticmain(["rosdiagnostic"] + sys.argv[1:])' --nocolor "$@"
}
