#!/usr/bin/env bash
# `make cluster-demo`: ROBODOC on three hosts (network namespaces on 10.77.0.0/24, made and removed
# here; needs root): the robot's coordinator on host a, the ui on host b, the supervisor on host c,
# and a replicated broker, IceStorm under IceGrid (the registry on c, one replica on each host),
# every link mutual TLS with the system's keys. It prints what the supervisor on c reports as the
# robot's force crosses its limit and falls back, then as the master broker replica is killed,
# then as host a is cut off (its link down) and comes back. With --watch, it leaves everything
# running afterwards with `safecass viewer --ice` on host c, reachable from this machine, until
# Ctrl-C.
#
# Usage: scripts/cluster-demo.sh BUILD_DIR [--watch]
set -uo pipefail
cd "$(dirname "$0")/.."
src=$PWD
bin=$(realpath "${1:-build}")/bin
watch=0
[ "${2:-}" = --watch ] && watch=1
source scripts/hosts-lib.sh
if ! hosts_available; then
  echo "cluster-demo: network namespaces cannot be made here (run it as root; it needs iproute2)" >&2
  exit 2
fi
HOSTS_DIR=$(realpath "${1:-build}")/cluster-demo
rm -rf "$HOSTS_DIR"; mkdir -p "$HOSTS_DIR"
trap 'hosts_down; ip link del scdemo0 2>/dev/null' EXIT
trap 'exit 130' INT TERM  # so that the EXIT trap removes the hosts
system=$src/examples/robodoc/robodoc.json
ice=locator:10.77.0.3:4061
start=$SECONDS
say() { printf '\n== t=%3d s  %s\n' $((SECONDS - start)) "$*"; }
# until_line REGEX SECONDS: waits for a new line of the supervisor's output, then prints the new ones.
shown=0
until_line() {
  local i
  for ((i = 0; i < $2 * 10; i++)); do
    tail -n +$((shown + 1)) "$HOSTS_DIR/supervisor.log" | grep -Eq -- "$1" && break
    sleep 0.1
  done
  sleep 0.5
  local lines
  lines=$(tail -n +$((shown + 1)) "$HOSTS_DIR/supervisor.log" |
    grep -E '^(\[(robot|ui)\]|supervisor:) ([A-Z0-9]+ |coordinator )' | sed 's/^/   /')
  echo "${lines:-   (no change: nobody was lost)}"
  shown=$(wc -l <"$HOSTS_DIR/supervisor.log")
}

"$bin/safecass" keys "$system" --out "$HOSTS_DIR/keys" --replace >/dev/null || exit 1
export SAFECASS_KEYS=$HOSTS_DIR/keys
hosts_up "scd$$" a b c
# The broker: the IceGrid registry and replica 3 on c, replica 1 on a, replica 2 on b.
on c scripts/start-icestorm --replicas 3 --nodes a=10.77.0.1,b=10.77.0.2,c=10.77.0.3 --host 10.77.0.3 \
  --port 4061 --dir "$HOSTS_DIR/ice" --env "$HOSTS_DIR/ice.env" >/dev/null &
registry=$!
for h in a b; do
  on $h scripts/start-icestorm --join $h --registry 10.77.0.3:4061 --host "$(hosts_ip $h)" --dir "$HOSTS_DIR/ice-$h" \
    --env "$HOSTS_DIR/ice-$h.env" --no-wait >/dev/null || exit 1
  hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' "$HOSTS_DIR/ice-$h.env")")
done
wait $registry || exit 1
hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' "$HOSTS_DIR/ice.env")")
master() { hosts_broker_master c "$HOSTS_DIR/ice"; }
hosts_start supervisor c "$bin/safecass" supervisor "$system" --ice $ice --listen 10.77.0.3
hosts_start ui b "$bin/safecass" run "$system" --coordinator ui --ice $ice --listen 10.77.0.2
start=$SECONDS
hosts_start robot a "$bin/safecass" run "$system" --coordinator robot --ice $ice --listen 10.77.0.1 \
  --scenario examples/cluster/robot_feed.json

echo "== ROBODOC on three hosts: robot on a (10.77.0.1), ui on b (10.77.0.2), the supervisor on c (10.77.0.3)"
echo "   the broker: IceStorm replicated under IceGrid, a replica on each host, the registry on c"
echo "   every link mutual TLS with the system's keys; below, the component states the supervisor on c reports"
say "the robot's force is 5 N; everything Normal"
until_line "coordinator 'robot' is up" 20
say "the force rises to 40 N (the scenario, from 6 s), over JR3's 30 N limit"
until_line 'JR3.s_A .*-> Error EVT_FORCE_ERROR' 20
say "the force falls back to 5 N (from 11 s)"
until_line 'JR3.s_A Error -> ' 20
sleep 1
m=$(master)
say "the master broker replica ($m, on host c) is killed -9; the others elect a master and carry on"
shown=$(wc -l <"$HOSTS_DIR/supervisor.log")
on c pkill -KILL -f "$HOSTS_DIR/ice/node-c/data/servers/SafecassIceStorm$m[/]"
for _ in $(seq 100); do sleep 0.2; [ -n "$(master)" ] && break; done
echo "   the replicas agree on master $(master) again (the killed one restarted by its node); what the supervisor saw:"
until_line "coordinator '(robot|ui)' recovered" 5
sleep 1
say "host a is cut off (its link down): the robot is lost to everyone else, fail-safe"
echo "   host a also runs replica 1, which every process publishes to: they move to replica 2 once"
echo "   their calls to it time out (a few seconds, in which the others look lost too)"
hosts_cut a
until_line "coordinator 'robot' lost" 10
sleep 6
until_line . 1
say "host a comes back: the robot is heard again and everything converges"
hosts_heal a
until_line "coordinator 'robot' recovered" 30
echo
echo "Logs: $HOSTS_DIR"
if [ $watch = 1 ]; then
  # This machine joins the switch as 10.77.0.254, so a browser here reaches the viewer on c.
  ip link add scdemo0 type veth peer name phere netns "${hosts_prefix}sw"
  ip -n "${hosts_prefix}sw" link set phere master br0
  ip -n "${hosts_prefix}sw" link set phere up
  ip addr add 10.77.0.254/24 dev scdemo0
  ip link set scdemo0 up
  hosts_start viewer c "$bin/safecass" viewer --ice $ice --system "$system" --bind 10.77.0.3 --port 8080
  echo "Watching: open http://10.77.0.3:8080 here (the viewer on host c). Ctrl-C stops everything."
  while sleep 1; do :; done
fi
