#!/usr/bin/env bash
# SAFECASS across hosts: three network namespaces joined by veth links to a switch on 10.77.0.0/24:
# the robot's coordinator on host a (10.77.0.1), the ui on host b (10.77.0.2), IceStorm and the
# supervisor on host c (10.77.0.3). Every link is mutual TLS with the system's keys (`safecass
# keys`); every process listens on its host's address. Each case makes and removes its own hosts
# and stops its processes by PID. Exit 77 (skipped) where namespaces cannot be made (not root).
#   hosts_test.sh CASE BIN_DIR SOURCE_DIR
set -uo pipefail
case_name=$1
bin=$(realpath "$2")
src=$(realpath "$3")
source "$src/scripts/hosts-lib.sh"
if ! hosts_available; then
  echo "SKIPPED: network namespaces cannot be made here (needs root and iproute2: ip netns add)"
  exit 77
fi
HOSTS_DIR="$bin/../hosts-test/$case_name"
rm -rf "$HOSTS_DIR"; mkdir -p "$HOSTS_DIR"; HOSTS_DIR=$(realpath "$HOSTS_DIR"); cd "$HOSTS_DIR"
system="$src/examples/robodoc/robodoc.json"
failures=0
finish() {
  local down=$SECONDS
  hosts_down
  echo "   hosts removed in $((SECONDS - down)) s (at ${SECONDS} s)"
  if [ $failures -ne 0 ]; then
    for f in "$HOSTS_DIR"/*.log; do echo "---- $f"; tail -15 "$f"; done
    # A retry starts the case again in the same directory: the failed run's logs (the processes'
    # and the brokers') are kept beside it, for the cause.
    local kept="$HOSTS_DIR.failed-$(date +%Y%m%dT%H%M%S)"
    mkdir -p "$kept" && cp "$HOSTS_DIR"/*.log "$kept"/ 2>/dev/null
    for d in "$HOSTS_DIR"/ice*; do [ -f "$d/icebox.log" ] && cp "$d/icebox.log" "$kept/$(basename "$d")-icebox.log"; done
    echo "   this run's logs are kept in $kept"
    exit 1
  fi
  echo "PASS $case_name"
}
trap finish EXIT
trap 'exit 143' INT TERM  # a timeout's SIGTERM too: the EXIT trap removes the hosts
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  # Each line says when it was reached (seconds since the script started), so that a slow run
  # shows where its time went.
  # Each verdict also goes to checks.log, which a failed run keeps beside the processes' logs.
  local verdict="ok"
  "$@" || { verdict="FAILED"; failures=$((failures + 1)); }
  echo "$verdict: $what [${SECONDS} s]" | tee -a "$HOSTS_DIR/checks.log"
}
# retry SECONDS COMMAND...: until COMMAND succeeds, for at most SECONDS.
retry() {
  local until=$((SECONDS + $1))
  shift
  until "$@"; do
    [ $SECONDS -ge $until ] && return 1
    sleep 0.1
  done
}
now_ms() { date +%s%3N; }

"$bin/safecass" keys "$system" --out keys --replace >/dev/null 2>&1 || { echo "keys failed"; exit 1; }
export SAFECASS_KEYS="$HOSTS_DIR/keys"
hosts_up "sc$$" a b c
ice="10.77.0.3:4061"

# The broker and the supervisor on c, the robot on a, the ui on b; or a replicated broker (a
# replica on each host, the registry on c); or one broker on each host, its topics linked to the
# others' (docs/deployment.md "One broker per host").
deployment=single
case $case_name in
  across_hosts_a_replicated_broker_keeps_the_views_true_when_its_master_or_another_hosts_replica_dies) deployment=replicated ;;
  across_hosts_with_a_broker_on_each_host_cutting_any_host_loses_only_that_hosts_processes) deployment=per_host ;;
esac
# ice_for HOST: the --ice of a process on HOST (with a broker per host, its own broker first).
ice_for() { echo "$ice"; }
if [ $deployment = per_host ]; then
  for h in a b c; do
    on "$h" "$src/scripts/start-icestorm" --name "$h" --host "$(hosts_ip "$h")" --port 4061 --publish-port 4064 --dir "$HOSTS_DIR/ice-$h" \
      --trace --env "$HOSTS_DIR/ice-$h.env" >/dev/null 2>>"$HOSTS_DIR/icestorm-start.log" ||
      { echo "start-icestorm on $h failed: $(cat icestorm-start.log)"; exit 1; }
    hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' "ice-$h.env")")
  done
  ice_for() {
    local list="$1=$(hosts_ip "$1"):4061" h
    for h in a b c; do [ "$h" = "$1" ] || list+=",$h=$(hosts_ip "$h"):4061"; done
    echo "$list"
  }
elif [ $deployment = replicated ]; then
  # IceStorm replicated under IceGrid: the registry on c, a node and a replica on each host
  # (replica i on the i-th host: 1 on a, 2 on b, 3 on c). The registry's host waits for the
  # master's election, which needs the nodes of a and b.
  on c "$src/scripts/start-icestorm" --replicas 3 --nodes a=10.77.0.1,b=10.77.0.2,c=10.77.0.3 --host 10.77.0.3 \
    --port 4061 --dir "$HOSTS_DIR/ice" --env "$HOSTS_DIR/ice.env" >/dev/null 2>"$HOSTS_DIR/icestorm-start.log" &
  registry_started=$!
  for h in a b; do
    on "$h" "$src/scripts/start-icestorm" --join "$h" --registry 10.77.0.3:4061 --host "$(hosts_ip "$h")" \
      --dir "$HOSTS_DIR/ice-$h" --env "$HOSTS_DIR/ice-$h.env" --no-wait >/dev/null 2>>"$HOSTS_DIR/icestorm-start.log" ||
      { echo "start-icestorm --join on $h failed: $(cat icestorm-start.log)"; exit 1; }
    hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' "ice-$h.env")")
  done
  wait $registry_started || { echo "start-icestorm --replicas on c failed: $(cat icestorm-start.log)"; exit 1; }
  ice="locator:10.77.0.3:4061"
else
  on c "$src/scripts/start-icestorm" --host 10.77.0.3 --port 4061 --publish-port 4064 --dir "$HOSTS_DIR/ice" --env "$HOSTS_DIR/ice.env" \
    >/dev/null 2>"$HOSTS_DIR/icestorm-start.log" || { echo "start-icestorm on c failed: $(cat icestorm-start.log)"; exit 1; }
fi
[ $deployment = per_host ] || hosts_pids+=("$(sed -n 's/^ICESTORM_PID=//p' ice.env)")
feed="$src/tests/integration/hosts/quiet_feed.json"
[ "$case_name" = across_hosts_a_partitioned_host_is_lost_within_the_bound_and_converges_after_healing ] &&
  feed="$src/tests/integration/hosts/late_fault_feed.json"
echo "   hosts and IceStorm up at ${SECONDS} s"
robot_started=$SECONDS
hosts_start robot a "$bin/safecass" run "$system" --coordinator robot --ice "$(ice_for a)" --listen 10.77.0.1 --duration 280 \
  --scenario "$feed" --allow-write --token-file "$HOSTS_DIR/robot.token"
hosts_start ui b "$bin/safecass" run "$system" --coordinator ui --ice "$(ice_for b)" --listen 10.77.0.2 --duration 280
hosts_start supervisor c "$bin/safecass" supervisor "$system" --ice "$(ice_for c)" --listen 10.77.0.3 --duration 280

console() {  # console HOST ARGS...: the console, on HOST (never longer than 20 s, also on a loaded machine)
  local host=$1
  shift
  on "$host" timeout 20 "$bin/safecass" console --ice "$(ice_for "$host")" --timeout 3000 "$@"
}
# ui_shows PATTERN: the ui's PENDANT.s_R.Status row, read by a console on b, matches. What a try
# that does not match printed goes to ui-query.log (shown when the case fails).
ui_shows() {
  local out
  out=$(console b --coordinator ui -c "state list PENDANT" 2>&1)
  grep -Eq "PENDANT.s_R.Status  $1" <<<"$out" && return 0
  printf '[%s s] %s\n' "$SECONDS" "$out" >>"$HOSTS_DIR/ui-query.log"
  return 1
}
generate() {  # generate EVENT: on the robot's JR3.s_A, from host c, with the robot's token
  console c --coordinator robot --token-file "$HOSTS_DIR/robot.token" --allow-write -c "event generate $1 JR3.s_A" \
    >>generate.log 2>&1
}
# The ui has heard the robot itself (a ui that never did shows its required interface lost anyway,
# but a case must start from a robot that is known alive everywhere).
retry 60 grep -q "coordinator 'robot' proved alive" ui.log && retry 60 grep -q "coordinator 'robot' is up" supervisor.log &&
  retry 40 ui_shows Normal
check "the ui on b follows the robot on a through IceStorm on c, over TLS" test $? -eq 0

case $case_name in
across_hosts_a_fault_propagates_and_clears)
  retry 20 generate EVT_FORCE_ERROR
  check "a console on c writes to the robot on a with its token" test $? -eq 0
  retry 20 ui_shows "Error +EVT_SERVICE_FAILURE"
  check "the fault on a reaches the ui on b" test $? -eq 0
  retry 20 grep -q "\[robot\] .*JR3.s_A Normal -> Error EVT_FORCE_ERROR" supervisor.log
  check "and the supervisor on c" test $? -eq 0
  retry 20 generate /EVT_FORCE_ERROR
  retry 20 ui_shows Normal
  check "its clearing reaches the ui on b" test $? -eq 0
  ;;
across_hosts_a_killed_provider_fails_the_view_safe_within_the_bound)
  start=$(now_ms)
  kill -KILL "$pid_robot"
  retry 10 ui_shows "Error +EVT_COORDINATOR_LOST"
  check "the ui on b shows the robot on a lost (Error, not stale Normal)" test $? -eq 0
  echo "   robot killed -> the ui's console shows Error: $(($(now_ms) - start)) ms (loss bound: 3 heartbeats, 300 ms, plus the console's own round trip)"
  retry 10 grep -q "EVT_COORDINATOR_LOST" supervisor.log
  check "the supervisor on c reports EVT_COORDINATOR_LOST" test $? -eq 0
  hosts_start robot2 a "$bin/safecass" run "$system" --coordinator robot --ice "$ice" --listen 10.77.0.1 --duration 60 \
    --scenario "$src/tests/integration/hosts/quiet_feed.json"
  retry 30 ui_shows Normal
  check "a restarted robot clears it" test $? -eq 0
  ;;
across_hosts_a_partitioned_host_is_lost_within_the_bound_and_converges_after_healing)
  grep -Eq "\[robot\] JR3.s_A .*-> Error" robot.log && { echo "the robot faulted before the partition (a very slow start)"; failures=1; exit 1; }
  echo "   the link is cut $((SECONDS - robot_started)) s after the robot started (its fault comes at 20 s)"
  start=$(now_ms)
  hosts_cut a
  retry 10 ui_shows "Error +EVT_COORDINATOR_LOST"
  check "with a's link down, the ui on b shows the robot lost" test $? -eq 0
  echo "   link down -> the ui's console shows Error: $(($(now_ms) - start)) ms"
  # t = 20 s on the robot: its force crosses the limit on a, unseen by the others.
  retry 60 grep -Eq "\[robot\] JR3.s_A .*-> Error EVT_FORCE_ERROR" robot.log
  check "the robot raised its force fault while cut off" test $? -eq 0
  start=$(now_ms)
  hosts_heal a
  echo "   link a up again in $(($(now_ms) - start)) ms"
  start=$(now_ms)
  retry 30 ui_shows "Error +EVT_SERVICE_FAILURE"
  check "after healing, the ui on b holds the fault raised during the partition" test $? -eq 0
  echo "   link up -> the ui's console shows the robot's fault: $(($(now_ms) - start)) ms"
  retry 10 grep -q "\[ui\] CONTROL.s_P.Status .*-> Error EVT_SERVICE_FAILURE (root JR3.s_A:EVT_FORCE_ERROR)" ui.log
  check "with its root on a" test $? -eq 0
  retry 20 grep -q "EVT_COORDINATOR_LOST" supervisor.log
  check "the supervisor reported the loss" test $? -eq 0
  retry 20 grep -Eq "\[robot\] .*JR3.s_A .*-> Error EVT_FORCE_ERROR" supervisor.log
  check "and, after healing, the fault itself" test $? -eq 0
  ;;
across_hosts_a_replicated_broker_keeps_the_views_true_when_its_master_or_another_hosts_replica_dies)
  master() { hosts_broker_master c "$HOSTS_DIR/ice"; }
  has_master() { [ -n "$(master)" ]; }
  replica_host() { case $1 in 1) echo a ;; 2) echo b ;; 3) echo c ;; esac; }
  kill_replica() {  # kill_replica ID: kill -9 of that replica, on its host (its node starts it again)
    local h
    h=$(replica_host "$1")
    on "$h" pkill -KILL -f "$HOSTS_DIR/ice[-a-z]*/node-$h/data/servers/SafecassIceStorm$1[/]"
  }
  fault=EVT_FORCE_ERROR
  for victim in master 1; do
    retry 30 has_master
    m=$(master)
    check "the three replicas agree on a master ($m) before the kill" test -n "$m"
    [ "$victim" = master ] && id=$m || id=1
    start=$(now_ms)
    kill_replica "$id"
    check "replica $id (on host $(replica_host "$id")) killed" test $? -eq 0
    retry 20 generate "$fault"
    if [ "$fault" = EVT_FORCE_ERROR ]; then retry 20 ui_shows "Error +EVT_SERVICE_FAILURE"; else retry 20 ui_shows Normal; fi
    check "after replica $id's death a fault's change on a ($fault) reaches the ui on b" test $? -eq 0
    echo "   replica $id killed -> the ui's console shows the change: $(($(now_ms) - start)) ms (the console's own connection included)"
    retry 30 has_master
    check "the replicas agree on a master again (replica $id restarted by its node)" test $? -eq 0
    [ "$fault" = EVT_FORCE_ERROR ] && fault=/EVT_FORCE_ERROR || fault=EVT_FORCE_ERROR
  done
  retry 20 ui_shows Normal
  check "the ui's view converges to the robot's (Normal, no loss left)" test $? -eq 0
  retry 20 grep -q "\[robot\] .*JR3.s_A Error -> Normal /EVT_FORCE_ERROR" supervisor.log
  check "the supervisor on c saw the fault clear" test $? -eq 0
  # Host a cut off with the robot and replica 1, which carries every process's messages: the
  # robot is lost (fail-safe), and b and c go on through the other replicas.
  sup_hears_ui() { ! grep -E "coordinator 'ui' (lost|recovered)" supervisor.log | tail -1 | grep -q lost; }
  retry 30 has_master
  losses_before=$(grep -c "coordinator 'robot' lost" ui.log)
  ui_lost_robot() { [ "$(grep -c "coordinator 'robot' lost" ui.log)" -gt "$losses_before" ]; }
  start=$(now_ms)
  hosts_cut a
  retry 10 ui_lost_robot
  check "with host a and its replica cut off, the ui on b raises the robot's loss within 10 s" test $? -eq 0
  # Its view, as a console on b reads it: the console finds the ui through the broker, so only
  # once the replicas left have taken over (below: up to 40 s beside two busy loops).
  retry 50 ui_shows "Error +EVT_COORDINATOR_LOST"
  check "and its view shows the robot lost" test $? -eq 0
  sleep 1
  # A liveness check, not a timing target: each process finds the replicas left once its calls to
  # replica 1 time out (2 s a call, 0.7 s a connection attempt); 3.7 s on an idle machine, 6-16 s
  # beside two busy loops (docs/deployment.md).
  retry 40 sup_hears_ui
  check "the supervisor on c hears the ui on b through the replicas left" test $? -eq 0
  echo "   host a cut -> the supervisor hears the ui again after $(($(now_ms) - start)) ms (at most)"
  hosts_heal a
  retry 30 ui_shows Normal
  check "after healing the ui's view is Normal again" test $? -eq 0
  ;;
across_hosts_with_a_broker_on_each_host_cutting_any_host_loses_only_that_hosts_processes)
  # Each host cut off in turn, then healed: the processes of the two other hosts go on hearing
  # each other (their brokers forward to each other directly), so none of them reports the other
  # lost; the cut host's process is reported lost, and back after healing. What must not happen
  # has no condition to wait for: it is watched for 10 s after each cut (the replicated broker's
  # stall, which this deployment avoids, lasted 4-10 s).
  host_of() { case $1 in robot) echo a ;; ui) echo b ;; supervisor) echo c ;; esac; }
  # losses OBSERVER OBSERVED: how often OBSERVER's log reports OBSERVED lost.
  losses() {
    local pattern="coordinator '$2' lost"
    [ "$2" = supervisor ] && pattern="the supervisor is gone"
    grep -c "$pattern" "$1.log"
  }
  # The pairs that watch each other: the supervisor every coordinator, the ui its provider the
  # robot, each coordinator the supervisor.
  pairs="supervisor:robot supervisor:ui ui:robot robot:supervisor ui:supervisor"
  # The supervisor starts every coordinator lost ("not proven alive yet"): "is up" is its first
  # heartbeat believed, and only "recovered" (its state caught up) ends that loss. A host cut
  # before then cut a coordinator the supervisor still held lost, which it cannot report lost again
  # (a CI run, the federation's links still being made at start).
  settled() {  # the supervisor holds both coordinators recovered and the ui's view of the robot is Normal
    local who
    for who in robot ui; do
      grep -E "coordinator '$who' (lost|recovered)" supervisor.log | tail -1 | grep -q "recovered$" || return 1
    done
    ui_shows Normal
  }
  for cut in a b c; do
    retry 40 settled
    check "before host $cut is cut, every process hears the others" test $? -eq 0
    declare -A before=()
    for pair in $pairs; do before[$pair]=$(losses "${pair%%:*}" "${pair##*:}"); done
    hosts_cut "$cut"
    # The cut host's process, as the others report it lost (the supervisor, or for c the robot).
    case $cut in a) lost_pair=supervisor:robot ;; b) lost_pair=supervisor:ui ;; c) lost_pair=robot:supervisor ;; esac
    reported() { [ "$(losses "${lost_pair%%:*}" "${lost_pair##*:}")" -gt "${before[$lost_pair]}" ]; }
    retry 10 reported
    check "host $cut cut off: ${lost_pair%%:*} reports ${lost_pair##*:} lost" test $? -eq 0
    sleep 10
    for pair in $pairs; do
      observer=${pair%%:*} observed=${pair##*:}
      [ "$(host_of "$observer")" = "$cut" ] || [ "$(host_of "$observed")" = "$cut" ] && continue
      check "host $cut cut off: $observer (on $(host_of "$observer")) never reports $observed (on $(host_of "$observed")) lost" \
        test "$(losses "$observer" "$observed")" -eq "${before[$pair]}"
    done
    healed_at=$(($(wc -l <supervisor.log) + 1))
    hosts_heal "$cut"
    retry 40 settled
    check "after host $cut heals every process hears the others again" test $? -eq 0
    # P5 (docs/verify.md): on the way back each address of the supervisor's view changes level at
    # most once. A coordinator lost to it is shown lost (at Error) until it recovers, and the rows
    # it took meanwhile ("while 'X' is lost") change nothing shown; its recovery is one change of
    # each of its addresses, and every other change of a row that the cut caused (rooted in a
    # loss) is another. (A change with another root is the truth changing: on a loaded machine the
    # robot's control loop can overrun its period, EVT_PERIOD_OVERRUN.)
    flapping=$(tail -n +"$healed_at" supervisor.log | awk '
      /^supervisor: coordinator .* recovered$/ { split($0, q, "\x27"); recovered[q[2]] = 1; next }
      /^\[[a-z]+\] [^ ]+ (Normal|Warning|Error) -> / && / \(root [^)]*_LOST\)$/ {
        who = substr($1, 2, length($1) - 2); changes[who " " $2]++; owner[who " " $2] = who
      }
      END {
        for (a in changes) if (changes[a] + (owner[a] in recovered) > 1) print a
      }')
    check "after host $cut heals, no address of the supervisor's view changes level twice${flapping:+ (twice: $flapping)}" \
      test -z "$flapping"
  done
  ;;
across_hosts_no_certificate_another_ca_and_non_members_are_refused)
  mkdir -p no-certs && chmod 700 no-certs && cp keys/keyring no-certs/
  SAFECASS_KEYS="$HOSTS_DIR/no-certs" console b --coordinator ui -c "state list PENDANT" >plain.txt 2>&1
  check "a console on b without a certificate is refused" test $? -ne 0
  "$bin/safecass" keys "$system" --out other-ca --replace >/dev/null 2>&1
  SAFECASS_KEYS="$HOSTS_DIR/other-ca" console b --coordinator ui -c "state list PENDANT" >other.txt 2>&1
  check "a console on b with another CA's certificate is refused" test $? -ne 0
  on b timeout 20 icestormadmin --Ice.Default.Timeout=2000 --Ice.Override.ConnectTimeout=1000 --Ice.RetryIntervals=-1 \
    --IceStormAdmin.TopicManager.Default="SafecassIceStorm/TopicManager:tcp -h 10.77.0.3 -p 4061" \
    -e "topics; destroy safecass.heartbeat.robot" >admin.txt 2>&1
  check "a non-member on b (plain TCP) can neither list nor destroy a topic at the broker on c" test $? -ne 0
  SAFECASS_KEYS="$HOSTS_DIR/no-certs" on b "$bin/safecass" run "$system" --coordinator ui --ice "$ice" \
    --listen 10.77.0.2 --duration 1 >run-plain.txt 2>&1
  check "a coordinator without a certificate refuses to join across hosts" test $? -eq 2
  retry 10 ui_shows Normal
  check "and the ui's view stayed true" test $? -eq 0
  ;;
*)
  echo "unknown case $case_name" >&2
  failures=1
  ;;
esac
