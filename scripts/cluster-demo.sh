#!/usr/bin/env bash
# `make cluster-demo`: ROBODOC on three hosts (network namespaces on 10.77.0.0/24, made and removed
# here; needs root): the robot's coordinator on host a, the ui on host b, the supervisor on host c,
# and one broker on each host (IceStorm, its topics linked to the other hosts' brokers), every link
# mutual TLS with the system's keys. It prints what the supervisor on c reports as the robot's
# force crosses its limit and falls back, then as host a and then host b are cut off (their link
# down) and come back: each time only the cut host's process is lost. With --watch, it leaves
# everything running afterwards with `safecass viewer --ice` on host c, reachable from this
# machine, until Ctrl-C.
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
# ice_for HOST: the --ice of a process on HOST: its own host's broker, then the others'.
ice_for() {
  local list="$1=$(hosts_ip "$1"):4061" h
  for h in a b c; do [ "$h" = "$1" ] || list+=",$h=$(hosts_ip "$h"):4061"; done
  echo "$list"
}
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
for h in a b c; do
  on $h scripts/start-icestorm --name $h --host "$(hosts_ip $h)" --port 4061 --publish-port 4064 --dir "$HOSTS_DIR/ice-$h" \
    --env "$HOSTS_DIR/ice-$h.env" >/dev/null || exit 1
  hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' "$HOSTS_DIR/ice-$h.env")")
done
hosts_start supervisor c "$bin/safecass" supervisor "$system" --ice "$(ice_for c)" --listen 10.77.0.3
hosts_start ui b "$bin/safecass" run "$system" --coordinator ui --ice "$(ice_for b)" --listen 10.77.0.2
start=$SECONDS
hosts_start robot a "$bin/safecass" run "$system" --coordinator robot --ice "$(ice_for a)" --listen 10.77.0.1 \
  --scenario examples/cluster/robot_feed.json

echo "== ROBODOC on three hosts: robot on a (10.77.0.1), ui on b (10.77.0.2), the supervisor on c (10.77.0.3)"
echo "   a broker on each host: IceStorm, each topic linked to its namesake at the other hosts' brokers"
echo "   every link mutual TLS with the system's keys; below, the component states the supervisor on c reports"
echo "   (a row marked \"while 'X' is lost\" is what X did out of reach: the supervisor shows X lost until it"
echo "   recovers, once X has heard its own peers again, and then each row changes once)"
say "the robot's force is 5 N; everything Normal"
until_line "coordinator 'robot' is up" 20
say "the force rises to 40 N (the scenario, from 6 s), over JR3's 30 N limit"
until_line 'JR3.s_A .*-> Error EVT_FORCE_ERROR' 20
say "the force falls back to 5 N (from 11 s)"
until_line 'JR3.s_A Error -> ' 20
sleep 1
for h in a b; do
  who=robot
  [ $h = b ] && who=ui
  say "host $h is cut off (its link down): the $who is lost to everyone else, fail-safe; nobody else is"
  echo "   (the other two hosts' brokers forward to each other directly: nothing of theirs passes through $h)"
  hosts_cut $h
  until_line "coordinator '$who' lost" 10
  sleep 5
  until_line . 1
  say "host $h comes back: the $who is heard again and everything converges"
  hosts_heal $h
  until_line "coordinator '$who' recovered" 30
done
echo
echo "Logs: $HOSTS_DIR"
if [ $watch = 1 ]; then
  # This machine joins the switch as 10.77.0.254, so a browser here reaches the viewer on c.
  ip link add scdemo0 type veth peer name phere netns "${hosts_prefix}sw"
  ip -n "${hosts_prefix}sw" link set phere master br0
  ip -n "${hosts_prefix}sw" link set phere up
  ip addr add 10.77.0.254/24 dev scdemo0
  ip link set scdemo0 up
  hosts_start viewer c "$bin/safecass" viewer --ice "$(ice_for c)" --system "$system" --bind 10.77.0.3 --port 8080
  echo "Watching: open http://10.77.0.3:8080 here (the viewer on host c). Ctrl-C stops everything."
  while sleep 1; do :; done
fi
