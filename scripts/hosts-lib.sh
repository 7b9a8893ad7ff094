# Hosts in network namespaces, for the multi-host tests and `make cluster-demo` (source it).
# Each host is a namespace with loopback and one veth link to a switch namespace holding a
# bridge: 10.77.0.1 (a), 10.77.0.2 (b), 10.77.0.3 (c), ... on 10.77.0.0/24. Names carry a prefix
# of the caller's PID, so concurrent runs do not meet; hosts_down removes everything it made.
#
#   hosts_available                  0 when namespaces can be made here (root, iproute2)
#   hosts_up PREFIX HOST...          makes the switch and the hosts (hosts_ip HOST gives the address)
#   on HOST CMD...                   runs CMD in HOST's namespace
#   hosts_cut HOST / hosts_heal HOST takes HOST's link down / up (a partition of that host)
#   hosts_start NAME HOST CMD...     starts CMD on HOST in the background, output in $HOSTS_DIR/NAME.log,
#                                    PID in pid_NAME (stopped by hosts_down)
#   hosts_down                       stops what hosts_start started (by PID), removes the namespaces
#   hosts_broker_master HOST DIR     the master replica's id of the replicated IceStorm whose registry
#                                    runs on HOST with data directory DIR, once its three replicas
#                                    agree on it and are all in the normal state (else nothing)

hosts_prefix=
hosts_names=()
hosts_pids=()

hosts_available() {
  command -v ip >/dev/null || return 1
  local probe="scprobe$$"
  ip netns add "$probe" 2>/dev/null || return 1
  ip netns del "$probe"
}

hosts_ip() {
  local i
  for i in "${!hosts_names[@]}"; do
    if [ "${hosts_names[$i]}" = "$1" ]; then echo "10.77.0.$((i + 1))"; return 0; fi
  done
  return 1
}

hosts_ns() { echo "${hosts_prefix}$1"; }

on() {
  local host=$1
  shift
  ip netns exec "$(hosts_ns "$host")" "$@"
}

# Namespaces an earlier run left behind (killed before it could remove them) whose process is
# gone: their prefix is "sc" or "scd" and the PID of the run that made them.
hosts_sweep() {
  local ns pid
  for ns in $(ip netns list 2>/dev/null | awk '{print $1}' | grep -E '^scd?[0-9]+(sw|[a-z])$'); do
    pid=$(echo "$ns" | sed -E 's/^scd?([0-9]+).*/\1/')
    kill -0 "$pid" 2>/dev/null && continue
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null
    ip netns del "$ns" 2>/dev/null || true
  done
}

hosts_up() {
  hosts_sweep
  hosts_prefix=$1
  shift
  local sw="${hosts_prefix}sw" host i=0
  ip netns add "$sw"
  ip -n "$sw" link set lo up
  ip -n "$sw" link add br0 type bridge
  ip -n "$sw" link set br0 up
  for host in "$@"; do
    hosts_names+=("$host")
    ip netns add "$(hosts_ns "$host")"
    ip -n "$(hosts_ns "$host")" link set lo up
    ip -n "$sw" link add "p$host" type veth peer name eth0 netns "$(hosts_ns "$host")"
    ip -n "$sw" link set "p$host" master br0
    ip -n "$sw" link set "p$host" up
    ip -n "$(hosts_ns "$host")" addr add "10.77.0.$((i + 1))/24" dev eth0
    ip -n "$(hosts_ns "$host")" link set eth0 up
    i=$((i + 1))
  done
}

hosts_cut() { ip -n "$(hosts_ns "$1")" link set eth0 down; }
hosts_heal() {
  ip -n "$(hosts_ns "$1")" link set eth0 up
  # The host's IPv4 address comes back with its link; wait (5 s at most, by the clock: each `ip`
  # can take seconds on a loaded machine) until it is usable. Only the IPv4 address counts: the
  # hosts talk over it, and the IPv6 link-local address's duplicate detection, which can stay
  # tentative for long under load, is not waited for.
  local until=$((SECONDS + 5))
  while [ $SECONDS -lt $until ]; do
    ip -n "$(hosts_ns "$1")" -4 -o addr show dev eth0 | grep -q tentative || return 0
    sleep 0.1
  done
}

hosts_start() {
  local name=$1 host=$2
  shift 2
  ip netns exec "$(hosts_ns "$host")" "$@" >"$HOSTS_DIR/$name.log" 2>&1 &
  hosts_pids+=($!)
  eval "pid_${name//[^a-zA-Z0-9_]/_}=$!"
}

# hosts_stop PID: SIGTERM, then SIGKILL after 3 s.
hosts_stop() {
  local pid=$1 _
  kill -TERM "$pid" 2>/dev/null || return 0
  for _ in $(seq 30); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}

hosts_broker_master() {
  on "$1" icestormadmin --Ice.Config="$2/admin.config" -e replica 2>/dev/null |
    awk '/coord:/ {m[$3]++} /state:/ && $3 == "normal" {n++} END {for (k in m) if (m[k] == 3 && n == 3) print k}'
}

hosts_down() {
  local i host
  for ((i = ${#hosts_pids[@]} - 1; i >= 0; i--)); do hosts_stop "${hosts_pids[i]}"; done
  hosts_pids=()
  # What those left running (an IceGrid node's replicas when the node had to be killed) dies
  # with its host: a namespace's processes would outlive its removal.
  for host in "${hosts_names[@]}"; do
    ip netns pids "$(hosts_ns "$host")" 2>/dev/null | xargs -r kill -KILL 2>/dev/null
    ip netns del "$(hosts_ns "$host")" 2>/dev/null || true
  done
  [ -n "$hosts_prefix" ] && ip netns del "${hosts_prefix}sw" 2>/dev/null || true
  hosts_names=()
}
