#!/usr/bin/env bash
# Members only at the broker, and mutual TLS across processes (DESIGN §7, docs/security.md), against
# a real IceBox, set up with the one key command (`safecass keys`) and nothing else:
# - IceStorm, robot and ui coordinators, a console and the timeline all on ssl endpoints with the
#   system's CA (found through SAFECASS_KEYS): a fault generated through the console on the robot
#   reaches the ui;
# - a console or an IceStorm administrator without a certificate, or with one of another CA, is
#   refused;
# - a non-loopback endpoint without TLS is refused by every command.
#   tls_test.sh SAFECASS_BIN SOURCE_DIR SCRATCH
set -uo pipefail
bin="$1"; src="$2"; scratch="$3"
rm -rf "$scratch"; mkdir -p "$scratch"; cd "$scratch"
system="$src/examples/robodoc/robodoc.json"
pids=()
icestorm=
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  [ -n "$icestorm" ] && kill "$icestorm" 2>/dev/null
  wait 2>/dev/null
}
trap cleanup EXIT
failures=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; failures=$((failures + 1)); fi
}

"$bin" keys "$system" --out keys --replace >/dev/null 2>&1 || { echo "keys failed"; exit 1; }
"$bin" keys "$system" --out other-system --replace >/dev/null 2>&1 || { echo "keys (other CA) failed"; exit 1; }
export SAFECASS_KEYS="$scratch/keys"
icestorm=$("$src/scripts/start-icestorm" --port 0 --dir ice --env ice.env --replace) || { echo "start-icestorm failed"; exit 1; }
port=$(sed -n 's/^ICESTORM_PORT=//p' ice.env)
grep -q "ssl -h 127.0.0.1 -p $port" ice/icebox.config
check "IceStorm's endpoints are TLS, from the keys alone" test $? -eq 0

"$bin" run "$system" --coordinator robot --ice "127.0.0.1:$port" --duration 120 \
  --scenario "$src/tests/integration/middleware/robot_feed.json" --allow-write --token-file "$scratch/robot.token" \
  > robot.log 2>&1 & pids+=($!)
"$bin" run "$system" --coordinator ui --ice "127.0.0.1:$port" --duration 120 > ui.log 2>&1 & pids+=($!)

console() { "$bin" console --ice "127.0.0.1:$port" --timeout 3000 "$@"; }
# retry SECONDS COMMAND...: runs COMMAND until it succeeds, for at most SECONDS (a loaded machine
# may need more than one try for the processes to start or for a TLS handshake).
retry() {
  local until=$((SECONDS + $1))
  shift
  until "$@"; do
    [ $SECONDS -ge $until ] && return 1
    sleep 0.2
  done
}
ui_shows() { console --coordinator ui -c "state list PENDANT" 2>/dev/null | grep -q "PENDANT.s_R.Status  $1"; }
retry 20 ui_shows Normal
check "the ui answers a console over TLS" test $? -eq 0
retry 20 sh -c '"$0" console --ice "127.0.0.1:$1" --timeout 3000 --coordinator robot --token-file "$2" --allow-write \
  -c "event generate EVT_FORCE_ERROR JR3.s_A" > generate.txt 2>&1' "$bin" "$port" "$scratch/robot.token"
check "a write over TLS is accepted with the token" grep -q "generated EVT_FORCE_ERROR on JR3.s_A" generate.txt
retry 20 ui_shows Error
check "the fault crossed from robot to ui over TLS" test $? -eq 0

retry 20 "$bin" timeline --ice "127.0.0.1:$port" --coordinator ui --html timeline.html > timeline.txt 2>&1
check "timeline --ice draws a live history over TLS" test -s timeline.html

# Without certificates (a key directory holding only the keyring), or with another CA's.
mkdir -p no-certs && chmod 700 no-certs && cp keys/keyring no-certs/
SAFECASS_KEYS="$scratch/no-certs" console --coordinator ui -c "state list PENDANT" > plain.txt 2>&1
check "a console without a certificate is refused" test $? -ne 0
SAFECASS_KEYS="$scratch/other-system" console --coordinator ui -c "state list PENDANT" > wrong.txt 2>&1
check "a console with another CA's certificate is refused" test $? -ne 0
timeout 20 icestormadmin --Ice.Default.Timeout=2000 --Ice.Override.ConnectTimeout=1000 --Ice.RetryIntervals=-1 \
  --IceStormAdmin.TopicManager.Default="SafecassIceStorm/TopicManager:tcp -h 127.0.0.1 -p $port" \
  -e "topics; destroy safecass.heartbeat.robot" > admin.txt 2>&1
check "icestormadmin without a certificate can neither list nor destroy a topic" test $? -ne 0
retry 20 sh -c '"$0" console --ice "127.0.0.1:$1" --timeout 3000 --coordinator robot --token-file "$2" --allow-write \
  -c "event generate /EVT_FORCE_ERROR JR3.s_A" > clear.txt 2>&1' "$bin" "$port" "$scratch/robot.token"
retry 20 ui_shows Normal
check "and the ui still follows the robot" test $? -eq 0

(unset SAFECASS_KEYS; "$src/scripts/start-icestorm" --port 0 --dir ice2 --host 192.0.2.1 > far.txt 2>&1)
check "start-icestorm refuses a non-loopback host without certificates" test $? -eq 2
mkdir -p no-certs-secret && chmod 700 no-certs-secret && cp -p keys/keyring keys/ui.secret keys/supervisor.secret no-certs-secret/
SAFECASS_KEYS="$scratch/no-certs-secret" "$bin" run "$system" --coordinator ui --ice 192.0.2.1:4061 --duration 1 \
  > far-run.txt 2>&1
status=$?
check "run refuses a non-loopback IceStorm without TLS" test $status -eq 2
check "and says how to get it" grep -q -- "safecass keys" far-run.txt
SAFECASS_KEYS="$scratch/no-certs-secret" "$bin" supervisor "$system" --ice 192.0.2.1:4061 --duration 1 > far-sup.txt 2>&1
check "the supervisor refuses it too" test $? -eq 2
SAFECASS_KEYS="$scratch/no-certs" console --coordinator ui --ice 192.0.2.1:4061 -c "state list" > far-console.txt 2>&1
check "the console refuses it too" test $? -ne 0

# A directory an IceBox still uses (its caller killed before it could stop it) is refused, with
# the PID, and taken over with --replace.
"$src/scripts/start-icestorm" --port 0 --dir ice > in-use.txt 2>&1
check "start-icestorm refuses a directory an earlier IceBox still uses" test $? -eq 2
check "and names its PID" grep -q "in use by PID(s) $icestorm " in-use.txt
replaced=$("$src/scripts/start-icestorm" --port 0 --dir ice --env ice.env --replace)
check "--replace stops that IceBox and starts another on the directory" test $? -eq 0
gone() { ! kill -0 "$icestorm" 2>/dev/null || grep -q '^State:.*Z' "/proc/$icestorm/status" 2>/dev/null; }
check "the earlier IceBox is gone" gone
kill "$replaced" 2>/dev/null

if [ $failures -ne 0 ]; then
  echo "--- robot.log"; tail -20 robot.log; echo "--- ui.log"; tail -20 ui.log
  echo "--- plain.txt"; cat plain.txt; echo "--- wrong.txt"; cat wrong.txt; echo "--- admin.txt"; cat admin.txt
  echo "--- far-run.txt"; cat far-run.txt
  exit 1
fi
